"""serialspec watch as a person sees it: run in a tmux pane, read back with capture-pane, stopped with Ctrl-C."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from conftest import ROOT
from sim_process import serve
from test_captures import pty_pair

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        shutil.which("tmux") is None, reason="tmux is not installed (make generate installs it where it can)"
    ),
]
SMS = str(ROOT / "specs" / "feetech_sms.yaml")
WAIT = 120.0  # seconds a screen may take to show what is expected before the test gives up (no timing is tested)


class Pane:
    """A tmux server of its own (tests run in parallel), one window of 160 x 40 (or `columns` wide) running a
    command."""

    def __init__(self, name: str) -> None:
        self.socket = f"serialspec-test-{name}-{os.getpid()}"

    def tmux(self, *args: str) -> str:
        # the pane's own size, not one a test runner exports (rich reads COLUMNS and LINES first)
        env = {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "LINES")}
        done = subprocess.run(["tmux", "-L", self.socket, *args], capture_output=True, text=True, timeout=30, env=env)
        assert done.returncode == 0, done.stderr
        return done.stdout

    def start(self, command: list[str], columns: int = 160) -> None:
        shell = " ".join(_quote(word) for word in command)
        # the shell stays after the command ends, so its last screen (the final table) can be read
        size = ["-x", str(columns), "-y", "40"]
        self.tmux("new-session", "-d", *size, "-c", str(ROOT), f"{shell}; echo EXITED $?; sleep 60")

    def screen(self) -> str:
        return self.tmux("capture-pane", "-p")

    def wait_for(self, ready: Callable[[str], bool]) -> str:
        deadline = time.monotonic() + WAIT
        while True:
            text = self.screen()
            if ready(text) or time.monotonic() > deadline:
                return text
            time.sleep(0.2)

    def close(self) -> None:
        subprocess.run(["tmux", "-L", self.socket, "kill-server"], capture_output=True, timeout=30)


def _quote(word: str) -> str:
    return "'" + word.replace("'", "'\\''") + "'"


@contextmanager
def pane(name: str) -> Iterator[Pane]:
    p = Pane(name)
    try:
        yield p
    finally:
        p.close()


def row(screen: str, *words: str) -> str:
    """The line of the screen that holds every word (or "")."""
    return next((line for line in screen.splitlines() if all(w in line for w in words)), "")


def test_watch_follows_a_running_sim_and_shows_each_command_and_register_in_units(tmp_path: Path) -> None:
    tap = tmp_path / "session.capture"
    watch = [sys.executable, "-m", "serialspec", "watch", SMS, "--tap", str(tap)]
    with serve("feetech_sms.yaml", 1, 2, options=["--tap", str(tap)]) as path, pane("tap") as screen:
        screen.start(watch)
        assert "serialspec watch: feetech_sms" in screen.wait_for(lambda s: "0 frames" in s)
        from serialspec_protocols.feetech_sms.client import FeetechSmsClient

        with FeetechSmsClient(path) as servos:  # the program that owns the port: watch takes nothing from it
            assert servos.ping(1) and not servos.ping(7)
            servos.write(1, goal_position=2048, goal_time=500, goal_speed=0)
            assert servos.read(1, "torque_limit") == 1000
            assert servos.read(2, "torque_limit") == 1000
        text = screen.wait_for(lambda s: row(s, " 2 ", "torque_limit") != "")
        assert row(text, " 1 ", "goal_position", "→", "2048"), text
        assert row(text, " 1 ", "goal_time", "500 ms"), text
        assert row(text, " 1 ", "torque_limit", "←", "100.0 %"), text  # 1000 x 0.1 %
        assert row(text, " 2 ", "torque_limit", "←", "100.0 %"), text
        assert row(text, " 7 ", "ping", "→"), text  # asked, never answered: no reply row for 7
        assert not row(text, " 7 ", "reply"), text
        assert row(text, " 1 ", "reply", "←", "error=none"), text
        assert "0 bad" in text
        assert "┃ device" in text  # rich's table, drawn in the pane
        screen.tmux("send-keys", "C-c")
        final = screen.wait_for(lambda s: "EXITED" in s)
        assert "EXITED 0" in final, final
        assert row(final, " 2 ", "torque_limit", "100.0 %"), final  # the last table stays on the terminal


def test_watch_listens_on_a_port_counting_rates_errors_and_bad_frames() -> None:
    # An SMS session as a sniffer hears it: PING 1 and its reply, READ 1 two bytes from 56 and its reply, a reply
    # with the overload error bit, and a frame with a bad checksum.
    session = bytes.fromhex(
        "ff ff 01 02 01 fb  ff ff 01 02 00 fc  ff ff 01 04 02 38 02 be  ff ff 01 04 00 00 08 f2"
        "  ff ff 01 02 20 dc  ff ff 01 02 01 fa"
    )
    with pty_pair() as (controller, path), pane("port") as screen:
        screen.start([sys.executable, "-m", "serialspec", "watch", SMS, "--port", path])
        # the view is drawn once the port is open: bytes written before would be flushed by the open
        assert "0 frames" in screen.wait_for(lambda s: "0 frames" in s)
        os.write(controller, session)
        text = screen.wait_for(lambda s: "1 bad" in s)
        assert "5 frames, 1 bad" in text, text
        assert row(text, " 1 ", "present_position", "←", "2048"), text
        assert row(text, " 1 ", "read", "→", "address=56 length=2"), text
        assert row(text, " 1 ", "reply", "←", "overload"), text
        reply = row(text, " 1 ", "reply", "←").split("│")
        assert [cell.strip() for cell in reply[5:8]][0::2] == ["3", "1"], text  # 3 replies, 1 with an error bit
        screen.tmux("send-keys", "C-c")
        assert "EXITED 0" in screen.wait_for(lambda s: "EXITED" in s)


def test_watch_in_an_80_column_terminal_keeps_each_value_on_its_row(tmp_path: Path) -> None:
    """A terminal's default width: padded cells left the values 6 columns, so `2048 step (0.088°)` took three lines
    and a session's rows ran off the screen."""
    tap = tmp_path / "session.capture"
    tap.write_text(
        "# serialspec capture: feetech_sms\n"
        "2026-11-28T10:04:17.699770+00:00 request ff ff 01 09 03 2a 00 08 f4 01 00 00 cb\n"
        "2026-11-28T10:04:17.700000+00:00 response ff ff 01 02 00 fc\n",
        encoding="utf-8",
    )
    with pane("narrow") as screen:
        screen.start([sys.executable, "-m", "serialspec", "watch", SMS, "--tap", str(tap)], columns=80)
        text = screen.wait_for(lambda s: "goal_time" in s)
        assert row(text, " 1", "goal_position", "→", "2048 step (0.088°)"), text
        assert row(text, " 1", "goal_time", "500 ms"), text
        assert max(len(line) for line in text.splitlines()) <= 80
        screen.tmux("send-keys", "C-c")
        assert "EXITED 0" in screen.wait_for(lambda s: "EXITED" in s)
