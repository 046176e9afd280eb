"""A text device that answers requests, as a user writes one: a command's request and response share its code
(`#LVL,50` asked, `#LVL,50` answered), `device.commands` says what the device does with each request. Generated and
served with the command line (`serialspec generate`, `serialspec sim` on a real pseudo-terminal), driven by the
generated typed client; decode takes the direction; monitor pairs a request with the answer after it."""

from __future__ import annotations

import importlib
import json
import os
import shutil
import subprocess
import sys
import tty
from collections.abc import Iterator
from decimal import Decimal
from pathlib import Path
from typing import Any

import pytest
from conftest import ROOT
from hypothesis import given, settings
from hypothesis import strategies as st

CLI = [sys.executable, "-m", "serialspec"]
SPEC = ROOT / "examples" / "textlamp" / "textlamp.yaml"


@pytest.fixture(scope="module")
def lamp(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Path, object]]:
    folder = tmp_path_factory.mktemp("textlamp")
    spec = folder / "textlamp.yaml"
    shutil.copy(SPEC, spec)
    done = subprocess.run([*CLI, "generate", str(spec), "--out", str(folder)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    sys.path.insert(0, str(folder))
    try:
        yield spec, importlib.import_module("textlamp")
    finally:
        sys.path.remove(str(folder))


def test_the_sim_answers_the_typed_client_under_the_request_s_code(lamp: tuple[Path, object]) -> None:
    spec, package = lamp
    sim = subprocess.Popen([*CLI, "sim", str(spec)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert sim.stdout is not None
        path = sim.stdout.readline().strip()
        assert path.startswith("/dev/"), sim.stderr.read() if sim.stderr else ""
        with package.Client(path) as client:  # type: ignore[attr-defined]
            assert client.read_temperature().temperature == pytest.approx(21.5)
            assert client.set_level(40).level == 40
            assert client.read_temperature().temperature == pytest.approx(25.5)  # 21.5 + 40 / 10
            with pytest.raises(ValueError, match="level = 101 is outside its range 0..100"):
                client.set_level(101)  # refused before a byte is written
            assert client.blink() is None  # not answered: nothing to wait for
            assert client.set_level(0).level == 0
    finally:
        sim.terminate()
        sim.wait(10)
    log = sim.stderr.read() if sim.stderr else ""
    assert 'request  set_level {"level": 40}' in log and "response #LVL,40*" in log, log


def test_decode_needs_the_direction_only_for_a_shared_code(lamp: tuple[Path, object]) -> None:
    spec, package = lamp
    asked = subprocess.run([*CLI, "decode", str(spec), "#LVL,50*7F", "--json"], capture_output=True, text=True)
    assert asked.returncode == 1 and "--direction" in asked.stderr and "Traceback" not in asked.stderr
    for direction in ("request", "response"):
        done = subprocess.run(
            [*CLI, "decode", str(spec), "#LVL,50*7F", "--json", "--direction", direction],
            capture_output=True,
            text=True,
        )
        assert done.returncode == 0, done.stderr
        result = json.loads(done.stdout)
        assert (result["command"], result["direction"], result["fields"]) == ("set_level", direction, {"level": "50"})
    assert package.decode("#LVL,50*7F", "request") == package.SetLevelRequest(level=50)  # type: ignore[attr-defined]


def test_monitor_pairs_each_answer_with_the_request_before_it(lamp: tuple[Path, object]) -> None:
    spec, package = lamp
    session = b"".join(
        package.encode(m)  # type: ignore[attr-defined]
        for m in (
            package.SetLevelRequest(level=30),  # type: ignore[attr-defined]
            package.SetLevelResponse(level=30),  # type: ignore[attr-defined]
            package.ReadTemperatureRequest(),  # type: ignore[attr-defined]
            package.ReadTemperatureResponse(temperature=24.5, changes=1),  # type: ignore[attr-defined]
        )
    )
    controller, device = os.openpty()
    tty.setraw(controller)
    tty.setraw(device)
    try:
        monitor = subprocess.Popen(
            [*CLI, "monitor", str(spec), "--port", os.ttyname(device), "--count", "4"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert monitor.stderr is not None
        monitor.stderr.readline()  # "serialspec monitor: ... Ctrl-C to stop": the port is open
        os.write(controller, session)
        out, err = monitor.communicate(timeout=60)
    finally:
        os.close(controller)
        os.close(device)
    kinds = [line.split()[1:3] for line in out.splitlines()]
    assert kinds == [
        ["request", "set_level"],
        ["response", "set_level"],
        ["request", "read_temperature"],
        ["response", "read_temperature"],
    ], out + err


BENCH_SUPPLY = """\
protocol: bench_supply
title: A bench supply
description: Lines `CODE=value` ended by CR LF; no start character, no checksum.
serial: {baudrate: 9600}
framing:
  kind: text
  separator: "="
  end: "\\r\\n"
  max_length: 40
commands:
  voltage:
    code: V
    title: Output voltage
    request: {}
    response:
      fields:
        volts: {type: decimal, precision: 2, unit: V, range: [0, 30]}
  set_voltage:
    code: SV
    title: Set the output voltage
    request:
      fields:
        volts: {type: decimal, precision: 2, unit: V, range: [0, 30]}
    response:
      fields:
        volts: {type: decimal, precision: 2, unit: V, range: [0, 30]}
examples:
  reading:
    source: made up
    printed: "V=12.10"
    direction: response
    command: voltage
    fields: {volts: "12.10"}
device:
  state: {volts: 5}
  commands:
    set_voltage: {stores: {volts: volts}, reports: {volts: volts}}
    voltage: {reports: {volts: volts}}
"""


@pytest.fixture(scope="module")
def supply(tmp_path_factory: pytest.TempPathFactory) -> Iterator[object]:
    folder = tmp_path_factory.mktemp("bench_supply")
    spec = folder / "bench_supply.yaml"
    spec.write_text(BENCH_SUPPLY, encoding="utf-8")
    done = subprocess.run([*CLI, "generate", str(spec), "--out", str(folder)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    sys.path.insert(0, str(folder))
    try:
        yield importlib.import_module("bench_supply")
    finally:
        sys.path.remove(str(folder))


def test_lines_without_a_start_character_are_frames_answered_by_the_sim(supply: Any) -> None:
    assert supply.encode(supply.VoltageRequest()) == b"V\r\n"
    assert supply.encode(supply.SetVoltageRequest(volts=12.5)) == b"SV=12.50\r\n"
    device = importlib.import_module("bench_supply.simulator").SIMULATOR()
    path = device.start()
    try:
        with supply.Client(path) as client:
            assert client.voltage().volts == 5
            assert client.set_voltage(12.5).volts == Decimal("12.50")
            assert client.voltage().volts == Decimal("12.50")
    finally:
        device.close()


@given(st.data())
@settings(max_examples=150, deadline=None)
def test_lines_without_a_start_character_resynchronise_however_the_bytes_are_split(supply: Any, data: Any) -> None:
    """Garbage lines, empty lines, an over-long line and a CR LF where a line ends: the same frames whatever the
    reads, and every good line comes back."""
    readings = data.draw(st.lists(st.integers(0, 3000), min_size=1, max_size=6))
    noise = [b"garbage\r\n", b"\r\n", b"X" * 70 + b"\r\n", b"\n", b"=\r\n"]
    stream, expected = b"", []
    for centivolts in readings:
        stream += data.draw(st.sampled_from(noise))
        message = supply.VoltageResponse(volts=Decimal(centivolts) / 100)
        stream += supply.encode(message)
        expected.append(message)
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=12)))
    parser, got, last = supply.StreamParser("response"), [], 0
    for cut in [*cuts, len(stream)]:
        got += parser.feed(stream[last:cut])
        last = cut
    assert got == expected


def test_the_asyncio_client_awaits_answers_and_iterates_over_what_the_device_sends(supply: Any) -> None:
    import asyncio

    from serialspec_protocols import nmea0183

    device = importlib.import_module("bench_supply.simulator").SIMULATOR()
    path = device.start()

    async def session() -> list[Any]:
        async with supply.AsyncClient(path) as client:
            first = await client.voltage()
            answer = await client.set_voltage(7.25)
            with pytest.raises(ValueError, match="volts"):
                await client.set_voltage(31)  # refused before a byte is written
            return [first.volts, answer.volts, (await client.voltage()).volts]

    try:
        assert asyncio.run(session()) == [5, Decimal("7.25"), Decimal("7.25")]
    finally:
        device.close()
    gps = importlib.import_module("serialspec_protocols.nmea0183.simulator").SIMULATOR()
    gps_path = gps.start()

    async def fixes() -> list[Any]:
        seen: list[Any] = []
        async with nmea0183.AsyncClient(gps_path) as client:
            client.on(seen.append, nmea0183.RmcResponse)
            got = []
            async for message in client.messages(timeout=10):
                got.append(message)
                if len(got) >= 3:
                    break
        return [got, seen]

    try:
        got, seen = asyncio.run(fixes())
    finally:
        gps.close()
    assert len(got) == 3 and {type(m) for m in got} <= {nmea0183.GgaResponse, nmea0183.RmcResponse}
    rmcs = [m for m in got if isinstance(m, nmea0183.RmcResponse)]
    assert seen[: len(rmcs)] == rmcs  # called as read: a read may bring more than the loop took


CODELESS = """
protocol: odrive_ascii
title: ODrive's ASCII protocol
description: Commands are lines `CODE arg arg` then LF; a read is answered by a line of its values alone.
serial: {baudrate: 115200}
framing:
  kind: text
  separator: " "
  end: "\\n"
commands:
  feedback:
    code: f
    title: Read position and velocity
    request:
      fields:
        motor: {type: integer, range: [0, 1]}
    response:
      values_only: true
      fields:
        position: {type: decimal, precision: 4, unit: turn}
        velocity: {type: decimal, precision: 4, unit: turn/s}
  position:
    code: p
    title: Set a position (no reply)
    request:
      fields:
        motor: {type: integer, range: [0, 1]}
        position: {type: decimal, precision: 4, unit: turn}
device:
  state: {where: 1.5}
  commands:
    feedback:
      reports: {position: where, velocity: "0"}
    position:
      stores: {position: where}
"""


@pytest.fixture(scope="module")
def odrive(tmp_path_factory: pytest.TempPathFactory) -> Any:
    from conftest import generate_and_import

    folder = tmp_path_factory.mktemp("odrive")
    spec = folder / "odrive_ascii.yaml"
    spec.write_text(CODELESS, encoding="utf-8")
    return generate_and_import(spec, folder / "out", "odrive_ascii")


def test_a_reply_of_values_alone_is_read_with_its_request(odrive: Any) -> None:
    """A language gap once (ODrive's ASCII protocol: `f 0` answered by `1.2340 0.5000`; SCPI: `MEAS:VOLT?` answered
    by `+1.234E+00`): `values_only: true` on the response. Read with the request (or the reply class awaited), it
    decodes; alone, it is refused in one line that says to give the request."""
    request = odrive.FeedbackRequest(motor=0)
    assert odrive.encode(request) == b"f 0\n"
    reply = odrive.decode(b"1.2340 0.5000\n", "response", odrive.FeedbackResponse, request)
    assert (reply.position, reply.velocity) == (Decimal("1.2340"), Decimal("0.5000"))
    assert odrive.decode(b"1.2340 0.5000\n", "response", None, request) == reply
    assert odrive.encode(reply) == b"1.2340 0.5000\n"
    from serialspec.runtime.errors import DecodeError

    with pytest.raises(DecodeError, match="a reply of values alone is read with the request it answers"):
        odrive.decode(b"1.2340 0.5000\n", "response")


def test_a_stream_reads_a_reply_of_values_alone_after_its_request(odrive: Any) -> None:
    """Both directions in one stream (a monitor's): the line after `f 0` is its reply; a stream of replies alone
    reads one as the answer while a request awaits it (`expect`, as the client does), and only then."""
    both = odrive.StreamParser()
    stream = b"f 0\n1.0 2.0\nf 1\nf 1\n3.0 4.0\n"  # the second `f 1` after one that got no reply
    got = [m for byte in stream for m in both.feed(bytes([byte]))]
    names = [type(m).__name__.removeprefix("Feedback") for m in got]
    assert names == ["Request", "Response", "Request", "Request", "Response"]
    assert (got[4].position, got[4].velocity) == (Decimal("3.0"), Decimal("4.0"))
    replies = odrive.StreamParser("response")
    assert replies.feed(b"1.0 2.0\n") == [] and replies.errors == 1  # no request awaits it: no message
    replies.expect("f")
    assert [m.position for m in replies.feed(b"5.5 0.0\n")] == [Decimal("5.5")]
    assert replies.feed(b"6.5 0.0\n") == [] and replies.errors == 2  # answered: the next line is no reply


def test_the_client_gets_a_reply_of_values_alone_from_the_sim(odrive: Any) -> None:
    """The simulator answers `f` with its values alone and keeps what `p` (a request without a reply) sends; the
    client reads each answer as the reply to its request (both on a real pseudo-terminal, the sim in its own
    process)."""
    from sim_process import serve

    spec = Path(odrive.__file__).parent.parent.parent / "odrive_ascii.yaml"
    with serve(str(spec)) as path, odrive.Client(path) as client:
        first = client.request(odrive.FeedbackRequest(motor=0), timeout=5)
        client.send(odrive.PositionRequest(motor=0, position=Decimal("2.5")))
        second = client.request(odrive.FeedbackRequest(motor=0), timeout=5)
    assert (first.position, second.position) == (Decimal("1.5000"), Decimal("2.5000"))


def test_values_only_is_for_a_text_response(tmp_path: Path) -> None:
    from serialspec.lang import SpecErrors
    from serialspec.lang.loader import load_text
    from serialspec.lang.resolve import resolve

    def errors(text: str) -> list[str]:
        with pytest.raises(SpecErrors) as caught:
            resolve(load_text(text, "odrive.yaml"))
        return str(caught.value).splitlines()

    on_request = CODELESS.replace(
        "    request:\n      fields:\n        motor",
        "    request:\n      values_only: true\n      fields:\n        motor",
        1,
    )
    assert any("`values_only` belongs to a response" in line for line in errors(on_request))
    unsolicited = CODELESS.replace("      values_only: true", "      values_only: true\n      unsolicited: true")
    assert any("it is not unsolicited" in line for line in errors(unsolicited))


def test_decode_reads_a_reply_of_values_alone_given_its_request(
    odrive: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    from serialspec.cli import main as serialspec_main

    spec = str(Path(odrive.__file__).parent.parent.parent / "odrive_ascii.yaml")
    assert serialspec_main(["decode", spec, "1.2340 0.5000", "--request", "f 0", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["fields"] == {"position": "1.2340", "velocity": "0.5000"}
    assert serialspec_main(["decode", spec, "1.2340 0.5000"]) == 1
    assert capsys.readouterr().err.rstrip().endswith("give the request (--request SENTENCE)")
    # a request given whose reply is not values alone (`p` gets none): no hint to give the request already given
    assert serialspec_main(["decode", spec, "1.2340 0.5000", "--request", "p 0 1.0"]) == 1
    assert capsys.readouterr().err.rstrip().endswith("unknown text code '1.2340' (expected one of f, p)")


def test_the_sim_logs_a_request_with_a_decimal(odrive: Any) -> None:
    """Found with `values_only`: the simulator's log line of a request with a decimal field raised TypeError (JSON
    has no Decimal) and stopped the simulator."""
    from serialspec.cli.sim import _text

    assert _text(odrive.PositionRequest(motor=0, position=Decimal("2.5000"))) == (
        'position {"motor": 0, "position": "2.5000"}'
    )


def test_a_capture_reads_each_reply_of_values_alone_after_its_request(
    odrive: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`decode --file`: each direction's bytes are joined and split on their own; the request seen in one stream
    makes the next line of the other its reply, however the reply's bytes are cut into chunks."""
    from serialspec.cli import main as serialspec_main

    spec = str(Path(odrive.__file__).parent.parent.parent / "odrive_ascii.yaml")
    capture = tmp_path / "odrive.capture"
    chunks = [("request", b"f 0\n"), ("response", b"1.5 0.0\n"), ("request", b"f 1\n"), ("response", b"2.5")]
    chunks.append(("response", b"000 0.0\n"))
    when = "2026-11-22T09:40:01.123456+00:00"
    capture.write_text("".join(f"{when} {d} {data.hex(' ')}\n" for d, data in chunks), encoding="utf-8")
    assert serialspec_main(["decode", spec, "--file", str(capture), "--json"]) == 0
    shown = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [(s["direction"], s["fields"]) for s in shown] == [
        ("request", {"motor": "0"}),
        ("response", {"position": "1.5", "velocity": "0.0"}),
        ("request", {"motor": "1"}),
        ("response", {"position": "2.5000", "velocity": "0.0"}),
    ]
