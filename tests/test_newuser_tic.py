"""Pololu Tic stepper controllers, serial compact protocol (tests/specs/tic.yaml), written from the user docs alone
and checked against ticlib (PyPI, Julien Phalip's driver): the bytes its TicSerial writes for every 32-bit, 7-bit
and quick command decode and re-encode byte for byte, and its Get Variable reads run against `serialspec sim`.

A 32-bit value is sent as five data bytes (a byte of the four bytes' bit 7s, then their low 7 bits); the language
has no encoding for that, so the spec spells the five bytes as fields (`msbs` with bit fields, `data0..data3`) and
the test joins them: a strict xfail names the gap (one `i32` field with such an encoding). The Pololu protocol form
(0xAA, device number, command with bit 7 cleared; ticlib's `device_number=`) is a layout beside the compact one, its
device number None in a compact frame's message (as tests/test_newuser_maestro.py)."""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.backends.c.build import files as c_files
from serialspec.lang import load_protocol
from serialspec.runtime.errors import DecodeError, EncodeError, RangeError
from sim_process import serve
from test_newuser_maestro import POLOLU_FORM as MAESTRO_FORMS

ticlib = pytest.importorskip("ticlib")

SPEC = Path(__file__).parent / "specs" / "tic.yaml"
THIRTY_TWO = {
    "set_target_position": "SetTargetPositionRequest",
    "set_target_velocity": "SetTargetVelocityRequest",
    "halt_and_set_position": "HaltAndSetPositionRequest",
    "set_max_speed": "SetMaxSpeedRequest",
}
QUICK = ["halt_and_hold", "reset_command_timeout", "deenergize", "energize", "exit_safe_start"]


class CapturingPort:
    def __init__(self) -> None:
        self.written = b""

    def write(self, data: bytes) -> None:
        self.written += data


def written(call: str, *args: int, device_number: int | None = None) -> bytes:
    port = CapturingPort()
    getattr(ticlib.TicSerial(port, device_number=device_number), call)(*args)
    return port.written


@pytest.fixture(scope="module")
def tic(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("tic"), "tic")


def split(value: int) -> dict[str, object]:
    """The five data bytes' fields, from the value's four little-endian bytes (the guide's rule, by hand)."""
    raw = (value & 0xFFFFFFFF).to_bytes(4, "little")
    return {"msbs": {f"b{i}": raw[i] >> 7 for i in range(4)}} | {f"data{i}": raw[i] & 0x7F for i in range(4)}


def joined(message: object) -> int:
    fields = message.to_fields()  # type: ignore[attr-defined]
    raw = bytes(fields[f"data{i}"] | fields["msbs"][f"b{i}"] << 7 for i in range(4))
    return int.from_bytes(raw, "little", signed=True)


@settings(max_examples=examples(30), deadline=None)
@given(command=st.sampled_from(sorted(THIRTY_TWO)), value=st.integers(-(2**31), 2**31 - 1))
def test_32_bit_commands_match_ticlib(tic: ModuleType, command: str, value: int) -> None:
    golden = written(command, value)
    message = tic.decode(golden, tic.Direction.REQUEST)
    assert type(message).__name__ == THIRTY_TWO[command]
    assert joined(message) == value
    assert tic.encode(getattr(tic, THIRTY_TWO[command]).from_fields(split(value))) == golden


def test_7_bit_and_quick_commands_match_ticlib(tic: ModuleType) -> None:
    for call, message in [
        ("go_home", tic.GoHomeRequest(direction=1)),
        ("set_step_mode", tic.SetStepModeRequest(mode=3)),
        ("set_current_limit", tic.SetCurrentLimitRequest(limit=40)),
        *[(name, getattr(tic, f"{name.title().replace('_', '')}Request")()) for name in QUICK],
    ]:
        args = [] if call in QUICK else [next(iter(message.to_fields().values()))]
        golden = written(call, *args)
        assert tic.encode(message) == golden, call
        assert tic.decode(golden, tic.Direction.REQUEST) == message, call


def test_the_guides_position_example(tic: ModuleType) -> None:
    """Guide section 9's worked example: Set Target Position to 100 is E0 00 64 00 00 00; -100 (0xFFFFFF9C) is
    E0 0F 1C 7F 7F 7F (bit 7 of every byte set)."""
    assert tic.encode(tic.SetTargetPositionRequest.from_fields(split(100))) == bytes.fromhex("e0 00 64 00 00 00")
    assert tic.encode(tic.SetTargetPositionRequest.from_fields(split(-100))) == bytes.fromhex("e0 0f 1c 7f 7f 7f")
    with pytest.raises(RangeError, match=r"data0 = 128 is outside its range 0\.\.127"):
        tic.encode(tic.SetTargetPositionRequest.from_fields(split(0) | {"data0": 128}))


def test_ticlib_reads_variables_from_the_sim(tic: ModuleType) -> None:
    """ticlib's own Get Variable calls over a pseudo-terminal: four bytes of current_position, two of vin_voltage,
    one of operation_state, each the bytes of the sim's variables table."""
    import serial

    with serve(str(SPEC)) as path, serial.Serial(path, 9600, timeout=5) as port:
        driver = ticlib.TicSerial(port)
        assert driver.get_current_position() == -1234567
        assert driver.get_vin_voltage() == 12000
        assert driver.get_operation_state() == 10
        assert driver.get_max_speed() == 2000000
    client_module = importlib.import_module("tic.client")
    with serve(str(SPEC)) as path, client_module.TicClient(path, timeout=5) as client:
        assert client.get_variable(0x22, 4) == (-1234567).to_bytes(4, "little", signed=True)


@pytest.mark.xfail(
    strict=True,
    raises=AssertionError,
    reason="language gap: Pololu's 32-bit data (Tic, Jrk, Simple Motor Controller): five bytes, first one holding "
    "bit 7 of each of the value's four bytes in bits 0..3, then the four bytes with bit 7 cleared; `encoding: "
    "seven_bit` is 7 bits a byte (an i32 holds a 28-bit two's complement value in 4 bytes, not Pololu's 5)",
)
def test_a_32_bit_target_as_one_field(tmp_path: Path) -> None:
    text = SPEC.read_text("utf-8").replace(
        "      fields: {msbs: msbs, data0: data0, data1: data1, data2: data2, data3: data3}\n  set_target_velocity",
        "      fields: {target: {type: i32, encoding: seven_bit}}\n  set_target_velocity",
        1,
    )
    path = tmp_path / "tic.yaml"
    path.write_text(text.replace("protocol: tic", "protocol: tic32"), "utf-8")
    load_protocol(path)
    module = generate_and_import(path, tmp_path / "out", "tic32")
    assert module.encode(module.SetTargetPositionRequest(target=-100)) == written("set_target_position", -100)


# the Maestro's Pololu protocol layout, the same for the Tic
POLOLU_FORM = MAESTRO_FORMS[MAESTRO_FORMS.index("    pololu:") : MAESTRO_FORMS.index("commands:")]


def test_the_pololu_protocol_form(tmp_path: Path) -> None:
    """ticlib's `device_number=` (a language gap once): the Pololu form (AA, device number, command & 0x7F) beside
    the compact form, every command sent in either (no `layout:`: the layouts are told apart by their header, the
    code-less replies read as the reply awaited). ticlib's frames of device 14 and of none decode and encode back;
    ticlib reads the sim in either form; the client sends the form of the device number it is given."""
    import serial

    text = SPEC.read_text("utf-8").replace(
        "        content: {role: content}\n", "        content: {role: content}\n" + POLOLU_FORM, 1
    )
    text = text.replace("    layout: compact\n", "").replace(", layout: compact", "")
    path = tmp_path / "tic.yaml"
    path.write_text(text.replace("protocol: tic", "protocol: tic_pololu"), "utf-8")
    module = generate_and_import(path, tmp_path / "out", "tic_pololu")
    for device in (14, None):
        golden = written("set_target_position", 100, device_number=device)  # AA 0E 60 00 64 00 00 00 for 14
        message = module.decode(golden, module.Direction.REQUEST)
        assert message == module.SetTargetPositionRequest.from_fields(split(100) | {"device": device})
        assert module.encode(message) == golden
        assert module.encode(module.EnergizeRequest(device=device)) == written("energize", device_number=device)
    simulator = importlib.import_module("tic_pololu.simulator").TicPololuSimulator(ids=[14])
    try:
        port_path = simulator.start()
        with serial.Serial(port_path, 9600, timeout=5) as port:
            assert ticlib.TicSerial(port, device_number=14).get_current_position() == -1234567
            assert ticlib.TicSerial(port).get_vin_voltage() == 12000
        with importlib.import_module("tic_pololu.client").TicPololuClient(port_path, timeout=5) as client:
            assert client.get_variable(14, "current_position") == -1234567
            assert client.get_variable_raw(None, 0x33, 2) == (12000).to_bytes(2, "little")
    finally:
        simulator.close()


def test_a_raw_read_is_sized_by_its_request(tic: ModuleType) -> None:
    """A bug fixed: a reply of `size: rest` bytes, `size_from: request.length`, in a layout with no length, was
    never taken by the stream parser (nothing sized it: the client timed out on every Get Variable), and decode
    took any number of bytes. The reply awaited is now sized by its request's field, and decode (encode, given the
    request) refuses a reply of another size in one line; so does the C."""
    request = tic.GetVariableRequest(offset=0x22, length=4)
    parser = tic.StreamParser(tic.Direction.RESPONSE)
    parser.expect(tic.GetVariableResponse, request)
    assert parser.feed(bytes.fromhex("79 29")) == []
    assert parser.feed(bytes.fromhex("ed ff")) == [tic.GetVariableResponse(data=bytes.fromhex("79 29 ed ff"))]
    parser.expect(tic.GetVariableResponse, tic.GetVariableRequest(offset=0, length=1))
    assert parser.feed(bytes.fromhex("0a")) == [tic.GetVariableResponse(data=b"\x0a")]
    with pytest.raises(DecodeError, match=r"3 content bytes, where its request asks for 4 \(length = 4\)"):
        tic.decode(bytes.fromhex("79 29 ed"), tic.Direction.RESPONSE, None, request)
    with pytest.raises(EncodeError, match=r"2 content bytes, where its request asks for 4 \(length = 4\)"):
        tic.encode(tic.GetVariableResponse(data=b"\x79\x29"), request)
    # the C parser sizes it too: p_parser_expect_reply keeps the request's length (refused once; the matrix case
    # "a code-less reply sized by its request" runs it against Python)
    source = next(text for path, text in c_files(load_protocol(SPEC)).items() if path.endswith("tic.c"))
    assert "parser->asked = (long)request->u.get_variable_request.length;" in source


def test_an_examples_bytes_may_be_written_in_any_hex_form() -> None:
    """Found writing this spec: `fields: {data: 7929edff}` in an example was refused (`data is '79 29 ed ff', not
    '7929edff'`), though `frame:` and `printed:` take any hex form people write; recorded values are now compared as
    the message's JSON writes them."""
    from serialspec.backends.python.package import emit_package
    from serialspec.backends.python.verify import verify

    protocol = load_protocol(SPEC)
    [example] = [e for e in protocol.examples if e.name == "position_reply"]
    assert example.fields == {"data": "7929edff"}
    assert verify(protocol, emit_package(protocol)) == []
