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
    # reported once nothing held back can join the bad bytes: here at the end
    bad = frames.feed(bytes.fromhex("ff ff 01 02 01 fa")) + frames.finish()
    assert bad[-1].reason.startswith("1 frame(s) failed")


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
        import serialspec_protocols.fashionstar_uart.client as fsc

        with fsc.FashionstarUartClient(path) as client:
            assert client.ping(1)
        process.terminate()
        _, err = process.communicate(timeout=10)
        assert ("request  ping" in err) is not quiet


def test_a_spy_client_logs_what_it_receives_too(tmp_path: Path) -> None:
    import serialspec_protocols.fashionstar_uart.client as fsc
    import serialspec_protocols.fashionstar_uart.simulator as fss

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


TINY = str(ROOT / "tests" / "hostile" / "tiny.yaml")
MOVE = "aa 55 01 01 05 64 00 01 0a 00 76"  # a valid move request of the tiny spec


def test_garbage_in_a_capture_is_counted_once_on_its_own_line(tmp_path: Path) -> None:
    """`de ad` then a valid frame on the next line reported `1 byte(s) outside any frame in [de ad]` and then
    `1 byte(s) outside any frame in [<the valid frame>]`: the byte held back (it might have begun a header) was
    blamed on the line that completed it. Bad bytes are now shown themselves, once, under the line they are on."""
    capture = tmp_path / "noisy.capture"
    lines = ["de ad", MOVE, "01 aa", MOVE[3:].replace("76", "77") + " ff", "aa"]
    capture.write_text(
        "".join(f"2026-11-22T09:40:0{i}.000000+00:00 request {line}\n" for i, line in enumerate(lines)), "utf-8"
    )
    result = subprocess.run(
        [sys.executable, "-m", "serialspec", "decode", TINY, "--file", str(capture), "--json"],
        capture_output=True,
        text=True,
    )
    assert [json.loads(line)["command"] for line in result.stdout.splitlines()] == ["move"]
    assert result.stderr.splitlines() == [
        "serialspec decode: line 1: 2 byte(s) outside any frame in [de ad]",
        "serialspec decode: line 3: 1 frame(s) failed their checksum or content check in "
        "[01 aa 55 01 01 05 64 00 01 0a 00 77 ff]",
        f"serialspec decode: {capture} ends inside a frame: [aa]",
    ]


@pytest.mark.parametrize("seed", range(20))
def test_every_byte_of_a_noisy_stream_is_a_frame_or_reported_bad_once_whatever_the_reads(seed: int) -> None:
    """Frames and bad bytes, in stream order, are the stream itself, however it is cut into chunks; each bad byte is
    reported under the chunk it came from."""
    import random

    protocol, package = open_spec(FS)
    rng = random.Random(seed)
    frames_in = [
        package.encode(package.ReadAngleResponse(servo_id=rng.randrange(255), angle=rng.randrange(-1800, 1800)))
        for _ in range(30)
    ]
    stream = b"".join(
        bytes(rng.randrange(256) for _ in range(rng.choice([0, 0, 1, 2, 5]))) + frame for frame in frames_in
    )
    frames = Frames(package, "response", protocol.device.address if protocol.device else None)
    seen = []
    chunks = []
    position = 0
    while position < len(stream):
        size = rng.randint(1, 12)
        chunks.append((position, position + size))
        seen += frames.feed(stream[position : position + size], len(chunks) - 1)
        position += size
    seen += frames.finish()
    assert b"".join(s.data for s in seen) + frames.pending() == stream
    assert [s.message for s in seen if s.message] == [package.decode(f) for f in frames_in][
        : sum(1 for s in seen if s.message)
    ]
    offset = 0
    for s in seen:  # each piece's origin is the chunk its first byte came from
        start, stop = chunks[s.origin]  # type: ignore[index]
        assert start <= offset < stop
        offset += len(s.data)


def test_a_spy_log_replays_with_register_names_from_the_request_before(tmp_path: Path) -> None:
    """pyserial's spy:// log, which the README names beside captures, could not be decoded (`'000000.000' is not a
    hex byte`), and a replayed READ reply showed `data 09 03`, not `model_number 777`, though its request is the
    frame before: a reply is shown with the request it answers, in a capture and in a spy log alike."""
    from serialspec_protocols.feetech_sms.client import FeetechSmsClient
    from serialspec_protocols.feetech_sms.simulator import FeetechSmsSimulator

    simulator = FeetechSmsSimulator(ids=[1])
    path = simulator.start()
    log = tmp_path / "spy.log"
    try:
        with FeetechSmsClient(f"spy://{path}?file={log}", optional_replies=True) as client:
            assert client.read(1, "model_number") == 777
            client.ping(1)  # a reply that answers no READ: shown without registers
    finally:
        simulator.close()
    assert log.read_text(encoding="utf-8").startswith("000000.")
    capture = tmp_path / "read.capture"
    capture.write_text(
        "2026-11-22T09:40:00.000000+00:00 request ff ff 01 04 02 03 02 f3\n"
        "2026-11-22T09:40:00.001000+00:00 response ff ff 01 04 00 09 03 ee\n",
        encoding="utf-8",
    )
    for replayed in (log, capture):
        result = subprocess.run(
            [sys.executable, "-m", "serialspec", "decode", SMS, "--file", str(replayed), "--json"],
            capture_output=True,
            text=True,
        )
        assert result.returncode == 0 and result.stderr == "", result.stderr
        decoded = [json.loads(line) for line in result.stdout.splitlines()]
        assert [(d["direction"], d["command"]) for d in decoded][:2] == [("request", "read"), ("response", "reply")]
        assert decoded[1]["registers"] == {"model_number": 777}
        assert all("registers" not in d for d in decoded[2:] if d["direction"] == "response")


def test_a_capture_pairs_each_reply_read_with_its_request(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """RoboClaw: a read's reply carries no code and its CRC covers the request's address and command. `decode
    --file` gave its bytes as "outside any frame" (the replies' stream never knew the request), then, once it did,
    stopped on re-encoding the reply without it; each reply is read with the request seen before it."""
    from serialspec.cli import main as serialspec_main

    capture = tmp_path / "roboclaw.capture"
    when = "2026-11-22T09:40:01.123456+00:00"
    lines = [("request", "80 18"), ("response", "00 78"), ("response", "c8 65"), ("request", "81 18")]
    capture.write_text("".join(f"{when} {d} {data}\n" for d, data in lines), encoding="utf-8")
    assert serialspec_main(["decode", str(ROOT / "specs" / "roboclaw.yaml"), "--file", str(capture), "--json"]) == 0
    shown = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [(s["direction"], s["command"], s["fields"]) for s in shown] == [
        ("request", "read_main_battery", {"address": 128}),
        ("response", "read_main_battery", {"voltage": 120}),
        ("request", "read_main_battery", {"address": 129}),
    ]
