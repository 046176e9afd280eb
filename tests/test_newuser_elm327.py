"""ELM327 OBD-II adapters (tests/specs/elm327.yaml), written from the user docs alone. The frames are the ELM327
datasheet's ("Talking to the Vehicle"): `010C` asks for the engine speed and `41 0C 1A F8 ` answers (0x1AF8 / 4 =
1726 rpm), then a blank line and the adapter's `>` prompt. No peer installed (python-OBD, `obd`, pins pint 0.24 for
its units; its decoders are the datasheet's formulas, which this test writes out).

The spec needs three text-frame features, each a test here: a line end per direction (`end: {request: "\\r",
response: "\\r\\r>"}`), a reply under a code of its own (`text: {code: "41 0C"}`: mode 01 answered under 41, the PID
repeated) and integer fields written as hex digits (`base: 16`). The package is generated once."""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType

import pytest
from conftest import package_fixture
from serialspec.lang import load_protocol
from serialspec.lang.errors import SpecErrors

SPEC = Path(__file__).parent / "specs" / "elm327.yaml"
REQUEST, REPLY = b"010C\r", b"41 0C 1A F8 \r\r>"

elm327 = package_fixture(SPEC, "elm327")


def test_the_datasheets_frames() -> None:
    """The golden frames follow the datasheet's rule: mode + 0x40, the PID, and RPM = (256 A + B) / 4."""
    mode, pid, a, b = (int(word, 16) for word in REPLY.split(b"\r")[0].split())
    assert (mode, pid) == (int(REQUEST[:2], 16) + 0x40, int(REQUEST[2:4], 16))
    assert (256 * a + b) / 4 == 1726


def test_what_the_loader_says_to_the_first_draft(tmp_path: Path) -> None:
    """The new user's first draft (its reply code `41` shared by two commands, the PID a `const` field) is refused
    one line a mistake, each naming what to write; its line ends, hex fields and reply code are the language's."""
    draft = SPEC.read_text("utf-8").replace('"41 0C", end: " "', '"41"').replace('"41 0D", end: " "', '"41"')
    draft = draft.replace(
        "a: {type: integer,", "pid: {type: integer, base: 16, const: 0x0C}\n        a: {type: integer,"
    )
    (tmp_path / "elm327.yaml").write_text(draft, "utf-8")
    with pytest.raises(SpecErrors) as caught:
        load_protocol(tmp_path / "elm327.yaml")
    said = str(caught.value).splitlines()
    assert len(said) == 2, said
    assert said[0].endswith(
        "commands.engine_rpm.response.fields.pid.const: `const` does not apply to a integer field in a text frame"
    )
    assert said[1].endswith("commands.vehicle_speed.response.text.code: code '41' is also engine_rpm's")
    load_protocol(SPEC)  # the spec as written now


def test_the_datasheets_frames_decode_and_re_encode(elm327: ModuleType) -> None:
    """The reply decodes to the datasheet's bytes (either case of hex digits) and both frames re-encode byte for
    byte, each with its direction's line end; a reply's code is its own, not its request's."""
    reply = elm327.decode(REPLY, elm327.Direction.RESPONSE)
    assert (reply.a, reply.b) == (0x1A, 0xF8) and (256 * reply.a + reply.b) / 4 == 1726
    assert elm327.decode(REPLY) == reply  # `41 0C` names the reply alone
    assert elm327.decode(b"41 0C 1a f8 \r\r>") == reply  # hex digits in lower case are read too (not codes)
    assert elm327.encode(reply) == REPLY
    assert elm327.encode(elm327.EngineRpmRequest()) == REQUEST
    assert elm327.decode(REQUEST) == elm327.EngineRpmRequest()
    assert elm327.encode(elm327.VehicleSpeedResponse(speed=50)) == b"41 0D 32 \r\r>"


def test_a_monitor_reads_both_directions_in_any_pieces(elm327: ModuleType) -> None:
    """Requests end with CR, replies with CR CR `>`: a stream parser of both directions, fed a byte at a time, tells
    a request's CR from the start of a reply's ending."""
    stream = REQUEST + REPLY + b"010D\r41 0D 32 \r\r>"
    parser = elm327.StreamParser()
    found = [message for i in range(len(stream)) for message in parser.feed(stream[i : i + 1])]
    assert found == [
        elm327.EngineRpmRequest(),
        elm327.decode(REPLY),
        elm327.VehicleSpeedRequest(),
        elm327.VehicleSpeedResponse(speed=50),
    ]
    assert parser.errors == 0


def test_a_client_drives_the_simulated_adapter(elm327: ModuleType) -> None:
    """The generated client against the generated simulator, in this process: each request answered by its reply."""
    simulator = importlib.import_module("elm327.simulator").SIMULATOR()
    path = simulator.start()
    try:
        with elm327.Client(path) as client:
            rpm = client.engine_rpm()
            assert (rpm.a, rpm.b) == (0x1A, 0xF8)
            assert client.vehicle_speed().speed == 0
    finally:
        simulator.close()
