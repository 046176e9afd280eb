"""The tools around the codec, driven as a user would: `serialspec scan`, `replay`, `ports` and `completion` as real
processes against `serialspec sim` on pseudo-terminals."""

from __future__ import annotations

import datetime
import json
import os
import re
import select
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import serial
from pty_pair import pty_pair
from serialspec.cli import capture
from sim_process import ROOT, serve


def serialspec(*args: str, stdin: str | None = None) -> subprocess.CompletedProcess[str]:
    result = subprocess.run(
        [sys.executable, "-m", "serialspec", *args], capture_output=True, text=True, input=stdin, timeout=120
    )
    assert "Traceback" not in result.stderr, result.stderr
    return result


def scan(*arguments: str) -> subprocess.CompletedProcess[str]:
    """`serialspec scan`, each id waited for 0.3 s: a simulator on a loaded machine may answer later than a servo."""
    return serialspec("scan", *arguments, "--timeout", "0.3")


def spec(name: str) -> str:
    return str(ROOT / "specs" / f"{name}.yaml")


def requests_in(tap: Path) -> list[bytes]:
    return [chunk.data for _, chunk in capture.read(tap.read_text().splitlines()) if chunk.direction == "request"]


# --- scan ---------------------------------------------------------------------------------------------------------


def test_scan_finds_each_servo_and_reads_its_model_register(tmp_path: Path) -> None:
    tap = tmp_path / "bus.tap"
    with serve("feetech_sms.yaml", 1, 5, options=["--model", "5=sm8512bl", "--tap", str(tap)]) as port:
        result = scan(spec("feetech_sms"), "--port", port, "--ids", "0-8")
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines() == [
        "id   1  1000000 baud  model sts3215",
        "id   5  1000000 baud  model sm8512bl",
    ]
    # one PING per id; after each servo's reply, a READ of its model register (0x03, two bytes)
    expected = b""
    for i in range(9):
        expected += bytes([0xFF, 0xFF, i, 2, 1, ~(i + 3) & 0xFF])
        if i in (1, 5):
            expected += bytes([0xFF, 0xFF, i, 4, 2, 3, 2, ~(i + 4 + 2 + 3 + 2) & 0xFF])
    assert b"".join(requests_in(tap)) == expected


def test_scan_finds_roboclaw_controllers_by_their_firmware_version(tmp_path: Path) -> None:
    """RoboClaw's presence is READ FIRMWARE VERSION (command 21) at each packet serial address, from the spec."""
    tap = tmp_path / "bus.tap"
    with serve("roboclaw.yaml", 0x80, 0x83, options=["--tap", str(tap)]) as port:
        result = scan(spec("roboclaw"), "--port", port, "--ids", "128-131")
    assert result.returncode == 0, result.stderr
    assert [line.split()[:2] for line in result.stdout.splitlines()] == [["id", "128"], ["id", "131"]]
    assert requests_in(tap) == [bytes([address, 21]) for address in range(0x80, 0x84)]


def test_scan_finds_a_dynamixel_bus_with_one_broadcast_ping(tmp_path: Path) -> None:
    tap = tmp_path / "bus.tap"
    with serve("dynamixel_p2.yaml", 1, 3, options=["--model", "3=xl330_m288", "--tap", str(tap)]) as port:
        result = scan(spec("dynamixel_p2"), "--port", port, "--json")
    assert result.returncode == 0, result.stderr
    assert [json.loads(line) for line in result.stdout.splitlines()] == [
        {"id": 1, "baudrate": 57600, "model": "xm430_w350"},
        {"id": 3, "baudrate": 57600, "model": "xl330_m288"},
    ]
    # one PING to the broadcast id (the e-manual's example frame), the models in its replies
    assert b"".join(requests_in(tap)) == bytes.fromhex("ff ff fd 00 fe 03 00 01 31 42")


def test_scan_takes_silence_after_a_broadcast_ping_for_no_device_at_that_rate(tmp_path: Path) -> None:
    # servos at 1 Mbaud: at 57600 the broadcast PING meets silence, which says nobody is there (not 253 more PINGs)
    tap = tmp_path / "bus.tap"
    with serve("dynamixel_p2.yaml", 1, 2, options=["--baudrate", "1000000", "--tap", str(tap)]) as port:
        result = scan(spec("dynamixel_p2"), "--port", port, "--baudrate", "57600", "--baudrate", "1000000", "--json")
    assert [(d["id"], d["baudrate"]) for d in map(json.loads, result.stdout.splitlines())] == [
        (1, 1000000),
        (2, 1000000),
    ]
    assert b"".join(requests_in(tap)) == 2 * bytes.fromhex("ff ff fd 00 fe 03 00 01 31 42")  # one PING per rate


def test_scan_at_several_baud_rates_and_every_rate_of_the_spec() -> None:
    with serve("fashionstar_uart.yaml", 2) as port:
        given = scan(
            spec("fashionstar_uart"),
            "--port",
            port,
            "--ids",
            "1-3",
            "--baudrate",
            "9600",
            "--baudrate",
            "500000",
        )
        every = scan(spec("fashionstar_uart"), "--port", port, "--ids", "2", "--all-baudrates", "--json")
    assert given.stdout.splitlines() == ["id   2  9600 baud  model 1", "id   2  500000 baud  model 1"]
    # a pseudo-terminal takes every rate: the servo answers at each of the seven the spec lists, default first
    rates = [json.loads(line)["baudrate"] for line in every.stdout.splitlines()]
    assert rates == [115200, 9600, 19200, 38400, 57600, 250000, 500000]


def test_scan_finds_devices_set_to_another_rate_at_that_rate_alone() -> None:
    # `sim --baudrate N` hears only a line set to N (250000: not a termios B-constant, set through termios2), as
    # servos set to that rate do: the scan over the spec's seven rates finds both servos at 250000 and nowhere else
    # (their two ids alone: each id that stays silent costs the scan's 0.3 s at each rate)
    with serve("fashionstar_uart.yaml", 2, 5, options=["--baudrate", "250000"]) as port:
        every = scan(spec("fashionstar_uart"), "--port", port, "--ids", "2,5", "--all-baudrates", "--json")
        default = scan(spec("fashionstar_uart"), "--port", port, "--ids", "2,5")
    found = [(d["id"], d["baudrate"]) for d in map(json.loads, every.stdout.splitlines())]
    assert found == [(2, 250000), (5, 250000)]
    assert (default.returncode, default.stdout) == (1, "")
    assert "no device answered" in default.stderr and "115200 baud" in default.stderr


def test_sim_refuses_a_rate_that_is_no_rate() -> None:
    result = serialspec("sim", spec("fashionstar_uart"), "--baudrate", "0")
    assert (result.returncode, result.stderr) == (
        1,
        "serialspec sim: --baudrate 0: give a positive number of bits per second\n",
    )


def test_scan_counts_a_modbus_server_by_its_reply_to_a_register_read() -> None:
    with serve("modbus_rtu.yaml", 1, 17) as port:
        result = scan(spec("modbus_rtu"), "--port", port, "--ids", "1-3,17,30", "--json")
    assert [json.loads(line) for line in result.stdout.splitlines()] == [
        {"id": 1, "baudrate": 19200, "model": None},
        {"id": 17, "baudrate": 19200, "model": None},
    ]


def test_scan_of_a_protocol_without_ids_asks_the_port_once() -> None:
    with serve("vesc.yaml") as port:
        result = scan(spec("vesc"), "--port", port)
    assert result.stdout.splitlines() == ["id   -  115200 baud  model 60"]


def test_scan_refuses_bad_ids_and_rates_before_writing_a_byte(tmp_path: Path) -> None:
    tap = tmp_path / "bus.tap"
    with serve("feetech_sms.yaml", 1, options=["--tap", str(tap)]) as port:
        cases = {
            ("--ids", "250-254"): "serialspec scan: --ids: id = 254 is outside the id range 0..253 "
            "(without the broadcast id 254)",
            ("--ids", "x"): "serialspec scan: --ids x: give ids as A-B, N or a list (1-10,20)",
            ("--ids", "9-2"): "serialspec scan: --ids 9-2: the first id is above the last",
            ("--baudrate", "0"): "serialspec scan: --baudrate 0: give a positive number of bits per second",
            ("--timeout", "0"): "serialspec scan: --timeout 0.0: give seconds in (0, 10]",
        }
        for options, message in cases.items():
            result = serialspec("scan", spec("feetech_sms"), "--port", port, *options)
            assert (result.returncode, result.stderr.strip()) == (1, message), options
        vesc = serialspec("scan", spec("vesc"), "--port", port, "--all-baudrates")
        rrc = serialspec("scan", spec("hiwonder_rrc"), "--port", port)
    assert requests_in(tap) == []
    assert vesc.stderr.strip() == "serialspec scan: --all-baudrates: vesc lists no baud rates (serial.baudrates)"
    assert rrc.stderr.strip() == (
        "serialspec scan: hiwonder_rrc declares no way to find its devices (device.presence in the spec)"
    )


def test_scan_with_no_device_says_so_and_exits_1() -> None:
    with serve("feetech_sms.yaml", 9) as port:
        result = scan(spec("feetech_sms"), "--port", port, "--ids", "1-3")
    assert (result.returncode, result.stdout, result.stderr.strip()) == (
        1,
        "",
        "serialspec scan: no device answered on ids 1-3 at 1000000 baud",
    )


def test_scan_shows_a_progress_bar_on_a_terminal_only() -> None:
    """stderr on a pseudo-terminal gets the bar, rewritten in place; stdout keeps only the devices."""
    controller, terminal = os.openpty()
    with serve("feetech_sms.yaml", 2) as port:
        process = subprocess.Popen(
            [sys.executable, "-m", "serialspec", "scan", spec("feetech_sms"), "--port", port, "--ids", "0-4"]
            + ["--timeout", "0.3"],
            stdout=subprocess.PIPE,
            stderr=terminal,
            text=True,
        )
        os.close(terminal)
        seen = b""
        while True:
            ready, _, _ = select.select([controller], [], [], 30)
            if not ready:
                break
            try:
                chunk = os.read(controller, 4096)
            except OSError:  # the process has closed its end
                break
            if not chunk:
                break
            seen += chunk
        out, _ = process.communicate(timeout=30)
    os.close(controller)
    assert out.splitlines() == ["id   2  1000000 baud  model sts3215"]
    text = seen.decode()
    assert "\r[" + " " * 30 + "] 0/5 at 1000000 baud" in text
    assert "] 5/5 at 1000000 baud" in text
    assert text.endswith("\r")  # the bar is cleared at the end
    with serve("feetech_sms.yaml", 2) as port:
        piped = scan(spec("feetech_sms"), "--port", port, "--ids", "0-4")
    assert piped.stderr == ""  # not a terminal: no bar


# --- replay -------------------------------------------------------------------------------------------------------


def session_capture(tmp_path: Path) -> Path:
    """A real session recorded by `sim --tap`: three reads by the client, 0.2 s apart."""
    from serialspec_protocols.feetech_sms.client import FeetechSmsClient

    tap = tmp_path / "session.tap"
    with serve("feetech_sms.yaml", 1, options=["--tap", str(tap)]) as port, FeetechSmsClient(port) as client:
        client.ping(1)
        client.read(1, "model_number")
        client.read(1, "present_position")
    # the recorded moments, moved 0.2 s apart (a capture of a slower session)
    lines = tap.read_text().splitlines()
    start = datetime.datetime(2026, 11, 22, 9, 40, tzinfo=datetime.UTC)
    rewritten, step = [], -1
    for line in lines:
        if line.startswith("#"):
            rewritten.append(line)
            continue
        _, direction, data = line.split(" ", 2)
        step += direction == "request"
        moment = start + datetime.timedelta(seconds=0.2 * step, milliseconds=1 if direction == "response" else 0)
        rewritten.append(f"{moment.isoformat(timespec='microseconds')} {direction} {data}")
    tap.write_text("\n".join(rewritten) + "\n")
    return tap


def test_replay_sends_a_captures_requests_with_their_timing(tmp_path: Path) -> None:
    recorded = session_capture(tmp_path)
    again = tmp_path / "again.tap"
    with serve("feetech_sms.yaml", 1, options=["--tap", str(again)]) as port:
        result = serialspec("replay", str(recorded), "--port", port, "--speed", "2")
    assert result.returncode == 0, result.stderr
    assert b"".join(requests_in(again)) == b"".join(requests_in(recorded))
    assert result.stderr.startswith("serialspec replay: 3 request chunk(s), 22 byte(s) sent to ")
    # the requests spread over the capture's 0.4 s / 2 (sent all at once, they would come within milliseconds); the
    # bound is loose: the simulator's reads, which stamp them, may come late under load
    moments = [
        datetime.datetime.fromisoformat(chunk.when).timestamp()
        for _, chunk in capture.read(again.read_text().splitlines())
        if chunk.direction == "request"
    ]
    assert moments[-1] - moments[0] >= 0.1, moments


def test_replay_splits_chunks_of_unknown_direction_by_the_spec(tmp_path: Path) -> None:
    """A monitor capture of both directions (`-`): the spec the capture names tells requests from replies."""
    recorded = session_capture(tmp_path)
    mixed = tmp_path / "monitor.cap"
    lines = recorded.read_text().splitlines()
    mixed.write_text("\n".join(line.replace(" request ", " - ").replace(" response ", " - ") for line in lines) + "\n")
    again = tmp_path / "again.tap"
    with serve("feetech_sms.yaml", 1, options=["--tap", str(again)]) as port:
        result = serialspec("replay", str(mixed), "--port", port, "--speed", "0")
    assert result.returncode == 0, result.stderr
    assert b"".join(requests_in(again)) == b"".join(requests_in(recorded))  # no pauses: they may come as one read
    # without a protocol to split them by, the bytes are not sent
    unnamed = tmp_path / "unnamed.cap"
    unnamed.write_text("\n".join(lines[1:]).replace(" request ", " - ") + "\n")
    with serve("feetech_sms.yaml", 1) as port:
        refused = serialspec("replay", str(unnamed), "--port", port)
    assert (refused.returncode, refused.stderr.strip()) == (
        1,
        "serialspec replay: the capture has bytes of unknown direction ('-') and names no protocol: give --spec SPEC",
    )


def test_replay_plays_the_device_side_to_a_host(tmp_path: Path) -> None:
    recorded = session_capture(tmp_path)
    replies = b"".join(
        chunk.data for _, chunk in capture.read(recorded.read_text().splitlines()) if chunk.direction == "response"
    )
    with pty_pair() as (host, device), serial.Serial(host, timeout=5) as listener:
        result = serialspec("replay", str(recorded), "--port", device, "--direction", "response", "--speed", "0")
        heard = listener.read(len(replies))
    assert result.returncode == 0, result.stderr
    assert heard == replies


def test_replay_refuses_what_it_cannot_play(tmp_path: Path) -> None:
    bad = tmp_path / "bad.cap"
    bad.write_text("2026-11-22T09:40:01+00:00 request 12 zz\n")
    empty = tmp_path / "empty.cap"
    empty.write_text("# serialspec capture: feetech_sms\n2026-11-22T09:40:01+00:00 response ff ff 01 02 00 fc\n")
    with serve("feetech_sms.yaml", 1) as port:
        cases = {
            (str(bad),): "serialspec replay: ",
            (str(empty),): f"serialspec replay: {empty} holds no request bytes",
            (str(empty), "--speed", "-1"): "serialspec replay: --speed -1.0: give a number ≥ 0 (0: no pauses)",
            (str(tmp_path / "none.cap"),): f"serialspec replay: cannot read {tmp_path / 'none.cap'}: No such file",
        }
        for options, message in cases.items():
            result = serialspec("replay", *options, "--port", port)
            assert result.returncode == 1 and result.stderr.startswith(message), (options, result.stderr)
            assert len(result.stderr.strip().splitlines()) == 1


def test_every_tool_says_in_words_why_a_port_does_not_open(tmp_path: Path) -> None:
    # one line, the reason once: not pyserial's `[Errno 2] could not open port X: [Errno 2] No such file ...: 'X'`
    capture_file = tmp_path / "one.capture"
    capture_file.write_text("# serialspec capture: feetech_sms\n2026-11-22T09:40:01+00:00 request ff ff 01 02 01 fb\n")
    missing = str(tmp_path / "ttyNONE")
    feetech = spec("feetech_sms")
    verbs = {
        "monitor": ["monitor", feetech, "--port", missing],
        "watch": ["watch", feetech, "--port", missing, "--duration", "1"],
        "scan": ["scan", feetech, "--port", missing],
        "replay": ["replay", str(capture_file), "--port", missing],
        "plot": ["plot", "--port", missing, "--spec", feetech, "--field", "x", "--out", str(tmp_path / "p.png")],
    }
    for verb, arguments in verbs.items():
        result = serialspec(*arguments)
        assert (result.returncode, result.stderr) == (
            1,
            f"serialspec {verb}: cannot open {missing}: No such file or directory\n",
        ), verb


# --- ports and completion -------------------------------------------------------------------------------------------


def test_ports_lists_what_pyserial_finds() -> None:
    from serial.tools import list_ports

    every = {port.device: port for port in list_ports.comports()}
    listed = serialspec("ports", "--all", "--json")
    assert listed.returncode == 0
    shown = [json.loads(line) for line in listed.stdout.splitlines()]
    assert [port["device"] for port in shown] == sorted(every)
    for port in shown:
        found = every[port["device"]]
        assert port["description"] == found.description
        assert port["serial_number"] == found.serial_number
        assert port["vid_pid"] == (None if found.vid is None else f"{found.vid:04x}:{found.pid:04x}")
    # by default, ports with nothing behind them (n/a: a legacy UART with no device) are left out
    plain = serialspec("ports", "--json")
    assert [json.loads(line)["device"] for line in plain.stdout.splitlines()] == sorted(
        device for device, port in every.items() if port.vid is not None or port.description != "n/a"
    )


@pytest.mark.parametrize("shell", ["bash", "zsh", "fish"])
def test_completion_completes_verbs_and_options_in_a_real_shell(shell: str, tmp_path: Path) -> None:
    result = serialspec("completion", shell)
    assert result.returncode == 0
    script = result.stdout
    for word in ("scan", "replay", "decode", "all-baudrates", "direction"):
        assert word in script, word
    if shell != "bash" or shutil.which("bash") is None:
        return
    # bash: the script loads, and completing `serialspec sc` and `serialspec scan x --all-` gives the words
    path = tmp_path / "serialspec.bash"
    path.write_text(script)
    probe = (
        f"source {path}\n"
        'complete_words() { COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1)); COMP_LINE="$*"; '
        'COMP_POINT=${#COMP_LINE}; COMPREPLY=(); _shtab_serialspec; echo "${COMPREPLY[@]}"; }\n'
        "complete_words serialspec sc\n"
        "complete_words serialspec scan x --all-\n"
        "complete_words serialspec completion ''\n"
    )
    shown = subprocess.run(["bash", "-c", probe], capture_output=True, text=True, timeout=30)
    assert shown.stdout.splitlines() == ["scan", "--all-baudrates", "bash zsh fish"], shown.stderr


# --- the README's examples, as printed ----------------------------------------------------------------------------


def readme_command(verb: str) -> tuple[list[str], list[str]]:
    """The README's console example of `serialspec VERB`: its arguments and the lines it prints."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    for block in re.findall(r"```console\n(.*?)```", text, flags=re.S):
        lines = block.splitlines()
        if lines[0].startswith(f"$ .venv/bin/serialspec {verb} "):
            return shlex.split(lines[0][2:])[2:], lines[1:]
    raise AssertionError(f"no console example of {verb} in README.md")


README_PORT = "/dev/pts/5"


def test_the_readme_scan_prints_what_the_readme_shows() -> None:
    arguments, printed = readme_command("scan")
    with serve("feetech_sms.yaml", 1, 2) as port:  # the README's session: `sim specs/feetech_sms.yaml --id 1 --id 2`
        result = subprocess.run(
            [sys.executable, "-m", "serialspec", "scan", *(port if a == README_PORT else a for a in arguments)],
            capture_output=True,
            text=True,
            cwd=ROOT,
        )
    assert result.stdout.splitlines() == printed


def test_the_readme_replay_prints_what_the_readme_shows(tmp_path: Path) -> None:
    arguments, printed = readme_command("replay")
    shutil.copy(session_capture(tmp_path), tmp_path / "session.capture")  # ping, and two register reads
    with serve("feetech_sms.yaml", 1, 2) as port:
        result = subprocess.run(
            [sys.executable, "-m", "serialspec", "replay", *(port if a == README_PORT else a for a in arguments)],
            capture_output=True,
            text=True,
            cwd=tmp_path,
        )
    assert result.stderr.replace(port, README_PORT).splitlines() == printed


# --- generate by protocol name ----------------------------------------------------------------------------------------


def test_generate_takes_a_shipped_protocol_by_name_outside_any_project(tmp_path: Path) -> None:
    # a wheel user has no specs/ folder: `generate fashionstar_uart --target wireshark` uses the spec the package ships
    result = subprocess.run(
        [sys.executable, "-m", "serialspec", "generate", "fashionstar_uart", "--target", "wireshark", "--out", "ws"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert (result.returncode, result.stdout) == (0, "1 file generated in ws, 1 changed, 0 removed\n"), result.stderr
    written = (tmp_path / "ws" / "fashionstar_uart" / "fashionstar_uart.lua").read_text().splitlines()
    shipped = (ROOT / "generated" / "serialspec_protocols" / "fashionstar_uart" / "fashionstar_uart.lua").read_text()
    assert written[0].startswith("-- Generated by serialspec from fashionstar_uart/spec.yaml;")
    assert written[1:] == shipped.splitlines()[1:]
    missing = subprocess.run(
        [sys.executable, "-m", "serialspec", "generate", "fashionstar_uatr", "--target", "wireshark", "--out", "ws"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert (missing.returncode, missing.stderr) == (
        1,
        "fashionstar_uatr:1:1: no such spec file, nor a generated protocol package of that name\n",
    )


def test_every_option_says_what_it_takes_and_what_it_does() -> None:
    # `--timeout S`, `--speed X`, `--port PORT`: never argparse's `--timeout TIMEOUT`, nor an option without help
    from serialspec.cli.arguments import VERBS, build_parser

    _, verbs = build_parser(VERBS)
    unnamed = []
    for verb, parser in verbs.items():
        for action in parser._actions:
            if not action.option_strings or action.help == "show this help message and exit":
                continue
            if not action.help:
                unnamed.append(f"{verb} {action.option_strings[0]}: no help")
            takes_value = action.nargs != 0 and action.choices is None
            if takes_value and action.metavar is None and action.type not in (None, str):
                unnamed.append(f"{verb} {action.option_strings[0]} {action.dest.upper()}")
    assert unnamed == []


# --- docs -------------------------------------------------------------------------------------------------------------


def test_docs_of_a_shipped_protocol_by_name_and_a_folder_it_cannot_write(tmp_path: Path) -> None:
    pytest.importorskip("mkdocs")
    # by name: the spec the package ships, found without importing the old top-level name (which warns)
    env = dict(os.environ, PYTHONWARNINGS="error::DeprecationWarning")
    built = subprocess.run(
        [sys.executable, "-m", "serialspec", "docs", "vesc", "--out", "site"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert (built.returncode, built.stderr) == (0, "")
    shipped = ROOT / "generated" / "serialspec_protocols" / "vesc" / "spec.yaml"
    assert (tmp_path / "site" / "specs" / "vesc.yaml").read_text() == shipped.read_text()
    # the page's commands are the reader's to type: `scan vesc`, not the package's copy vesc/spec.yaml
    page = (tmp_path / "site" / "protocols" / "vesc.html").read_text(encoding="utf-8")
    assert "<code>serialspec scan vesc --port PORT</code>" in page and "spec.yaml" not in page
    assert '<a href="../specs/vesc.yaml"><code>vesc</code></a>' in page
    (tmp_path / "a-file").write_text("")
    refused = serialspec("docs", "vesc", "--out", str(tmp_path / "a-file" / "site"))
    assert (refused.returncode, refused.stderr) == (
        1,
        f"serialspec docs: cannot write the site to {tmp_path / 'a-file' / 'site'}: Not a directory\n",
    )
