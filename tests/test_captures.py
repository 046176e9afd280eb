"""Watching and recording sessions: monitor (both directions, filters, colour), sim logs and taps, spy:// clients."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tty
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from conftest import ROOT
from serialspec.cli.frames import Frames
from serialspec.cli.protocols import open_spec

SMS = str(ROOT / "specs" / "feetech_sms.yaml")
FS = str(ROOT / "specs" / "fashionstar_uart.yaml")
# An SMS session: PING 1 and its reply, PING 3 (nobody answers), READ 1 two bytes from 56 and its reply.
SESSION = "ff ff 01 02 01 fb  ff ff 01 02 00 fc  ff ff 03 02 01 f9  ff ff 01 04 02 38 02 be  ff ff 01 04 00 00 00 fa"


def test_shared_header_frames_are_told_apart_by_pairing_replies_with_requests() -> None:
    protocol, package = open_spec(SMS)
    frames = Frames(package, None, protocol.device.address if protocol.device else None)
    data = bytes.fromhex(SESSION)
    seen = [s for i in range(0, len(data), 5) for s in frames.feed(data[i : i + 5])]  # in pieces, as a port gives
    assert [(s.message.DIRECTION.value, s.message.COMMAND) for s in seen if s.message] == [
        ("request", "ping"),
        ("response", "reply"),
        ("request", "ping"),
        ("request", "read"),
        ("response", "reply"),
    ]
    assert b"".join(s.data for s in seen) == data
    assert frames.feed(bytes.fromhex("ff ff 01 02 01 fa"))[-1].reason.startswith("1 frame(s) failed")


@contextmanager
def pty_pair() -> Iterator[tuple[int, str]]:
    controller, device = os.openpty()
    tty.setraw(device)
    tty.setraw(controller)
    try:
        yield controller, os.ttyname(device)
    finally:
        os.close(controller)
        os.close(device)


def monitor(spec: str, data: str, *args: str) -> list[str]:
    """Run `serialspec monitor` on a pseudo-terminal, write `data` to it, return its stdout lines (piped)."""
    with pty_pair() as (controller, path):
        process = subprocess.Popen(
            [sys.executable, "-m", "serialspec", "monitor", spec, "--port", path, *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert process.stderr is not None
        assert "Ctrl-C to stop" in process.stderr.readline()
        os.write(controller, bytes.fromhex(data))
        out, err = process.communicate(timeout=20)
    assert process.returncode == 0, err
    return out.splitlines()


def test_monitor_shows_both_directions_of_a_shared_header_session_without_colour_when_piped() -> None:
    lines = monitor(SMS, SESSION, "--count", "5")
    assert [line.split()[1:3] for line in lines] == [
        ["request", "ping"],
        ["response", "reply"],
        ["request", "ping"],
        ["request", "read"],
        ["response", "reply"],
    ]
    assert not any("\033[" in line for line in lines)


def test_monitor_filters_by_command_and_id_and_prints_unit_symbols() -> None:
    # READ_ANGLE replies from servos 0 and 1 (90.2° and 90.2°), and a PING request; only servo 1's angle is wanted
    frames = "05 1c 0a 03 00 86 03 b7  05 1c 0a 03 01 86 03 b8  12 4c 01 01 03 63"
    lines = monitor(FS, frames, "--count", "1", "--command", "read_angle", "--id", "1", "--units")
    assert len(lines) == 1
    assert '"servo_id": 1' in lines[0] and '"angle": "90.2°"' in lines[0]


def test_monitor_colours_on_request() -> None:
    lines = monitor(FS, "12 4c 01 01 03 63", "--count", "1", "--color", "always")
    assert "\033[36mrequest\033[0m" in lines[0]


def test_sim_logs_requests_unless_quiet() -> None:
    spec = ROOT / "specs" / "fashionstar_uart.yaml"
    for quiet in (False, True):
        args = [sys.executable, "-m", "serialspec", "sim", str(spec), "--id", "1", *(["--quiet"] if quiet else [])]
        process = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        assert process.stdout is not None
        path = process.stdout.readline().strip()
        import fashionstar_uart.client as fsc

        with fsc.FashionstarUartClient(path) as client:
            assert client.ping(1)
        process.terminate()
        _, err = process.communicate(timeout=10)
        assert ("request  ping" in err) is not quiet


def test_a_spy_client_logs_what_it_receives_too(tmp_path: Path) -> None:
    import fashionstar_uart.client as fsc
    import fashionstar_uart.simulator as fss

    simulator = fss.SIMULATOR([1])
    path = simulator.start()
    log = tmp_path / "spy.txt"
    try:
        with fsc.FashionstarUartClient(f"spy://{path}?file={log}") as client:
            assert client.ping(1)
    finally:
        simulator.close()
    text = log.read_text(encoding="utf-8")
    assert "TX" in text and "RX" in text
    assert "05 1C 01 01 01" in text.upper()  # the reply's bytes, as received


def test_a_newly_generated_package_imports_at_once_in_the_project() -> None:
    # `make generate` puts generated/ on the environment's path (a .pth file), so no reinstall is needed
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    code = "import sys; print(any(p.rstrip('/').endswith('/generated') for p in sys.path))"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd="/")
    assert result.stdout.strip() == "True"


def test_decode_reads_hex_lines_from_stdin_and_refuses_no_frames() -> None:
    cli = [sys.executable, "-m", "serialspec", "decode", FS]
    result = subprocess.run(
        [*cli, "-", "--json"], input="12 4c 01 01 03 63\n\n05 1c 01 01 03 26\n", capture_output=True, text=True
    )
    assert [json.loads(line)["direction"] for line in result.stdout.splitlines()] == ["request", "response"]
    nothing = subprocess.run(cli, capture_output=True, text=True)
    assert nothing.returncode == 1 and "give frames as hex arguments" in nothing.stderr


@pytest.mark.parametrize("bad", ["2026-11-22T09:00:00+00:00 request zz", "12 4c 0g"])
def test_decode_file_names_the_line_that_does_not_parse(tmp_path: Path, bad: str) -> None:
    capture = tmp_path / "bad.capture"
    capture.write_text(f"# serialspec capture: fashionstar_uart\n{bad}\n", encoding="utf-8")
    result = subprocess.run(
        [sys.executable, "-m", "serialspec", "decode", FS, "--file", str(capture)], capture_output=True, text=True
    )
    assert result.returncode == 1 and "line 2" in result.stderr and "Traceback" not in result.stderr
