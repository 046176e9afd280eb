"""Pololu Maestro servo controllers, compact protocol (tests/specs/maestro.yaml), written from the user docs alone.
No PyPI package speaks the Maestro's serial protocol (`maestro-servo` 0.2.0 and `pymaestro` drive its USB control
transfers, `maestro` is unrelated, `pololu-maestro` does not exist), so the peer is the user's guide (section 5.e,
Serial Servo Commands): its printed bytes are our golden frames, and a raw pyserial session sending the guide's
bytes drives `serialspec sim`, as does our client. A 14-bit value sent as two 7-bit bytes is one field
(`encoding: seven_bit`). The Pololu protocol form of the same commands (0xAA, device number, command with bit 7
cleared) is a layout beside the compact one: its device number, which the compact form does not carry, is None in
a compact frame's message. Replies without a code, of different sizes, in a plain
`framing.elements` spec are taken by the stream parser as the reply awaited (a bug once; the spec names one layout
from every command, which works too)."""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType

import pytest
from conftest import generate_and_import
from serialspec.backends.c.build import files as c_files
from serialspec.lang import load_protocol
from serialspec.runtime.errors import DecodeError, RangeError
from serialspec.runtime.message import Direction
from sim_process import serve

SPEC = Path(__file__).parent / "specs" / "maestro.yaml"

# (guide's bytes, message class, fields) for the compact protocol: section 5.e's commands.
GUIDE_REQUESTS = [
    ("84 02 70 2e", "SetTargetRequest", {"channel": 2, "target": 6000}),  # its example
    ("87 05 0c 01", "SetSpeedRequest", {"channel": 5, "speed": 140}),  # 140 × 0.25 µs/10 ms
    ("89 00 04 00", "SetAccelerationRequest", {"channel": 0, "acceleration": 4}),
    ("90 05", "GetPositionRequest", {"channel": 5}),
    ("93", "GetMovingStateRequest", {}),
    ("a1", "GetErrorsRequest", {}),
    ("a2", "GoHomeRequest", {}),
]


@pytest.fixture(scope="module")
def ma(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("maestro"), "maestro")


@pytest.mark.parametrize(("printed", "name", "fields"), GUIDE_REQUESTS)
def test_the_guides_requests(ma: ModuleType, printed: str, name: str, fields: dict[str, int]) -> None:
    frame = bytes.fromhex(printed)
    message = getattr(ma, name)(**fields)
    assert ma.decode(frame, ma.Direction.REQUEST) == message
    assert ma.encode(message) == frame


def test_the_target_example_is_1500_us(ma: ModuleType) -> None:
    """The guide: 1500 µs is 6000 quarter-microseconds, 01011101110000 in binary, sent low 7 bits first."""
    message = ma.decode(bytes.fromhex("84 02 70 2e"), ma.Direction.REQUEST)
    assert message.target == 6000


def test_a_target_past_14_bits_is_refused_before_encoding(ma: ModuleType) -> None:
    with pytest.raises(ValueError, match=r"target = 16384 is outside its range 0\.\.16383"):
        ma.encode(ma.SetTargetRequest(channel=2, target=16384))


def test_the_guides_bytes_drive_the_sim() -> None:
    """A user's own few lines of pyserial, as the guide's examples are written: Get Position answers two bytes, low
    first; Get Errors two bytes; Get Moving State one; Set Target nothing."""
    import serial

    with serve(str(SPEC)) as path, serial.Serial(path, 9600, timeout=5) as port:
        port.write(bytes.fromhex("84 02 70 2e 90 02"))
        assert port.read(2) == bytes.fromhex("70 17")  # 6000
        port.write(bytes.fromhex("a1"))
        assert port.read(2) == b"\x00\x00"
        port.write(bytes.fromhex("93"))
        assert port.read(1) == b"\x00"


def one_layout_spec(tmp_path: Path) -> Path:
    """The spec as a new user first wrote it: `framing.elements` (no layouts) and `default: true` on Get Position's
    reply, the others chosen by their request, as the `default` key's description says."""
    text = SPEC.read_text("utf-8").replace("protocol: maestro", "protocol: maestro_elements")
    start, end = text.index("framing:"), text.index("fields:")
    text = text[:start] + ELEMENTS + text[end:]
    text = text.replace("    layout: compact\n", "").replace("      fields:\n        position:", DEFAULT_POSITION)
    path = tmp_path / "maestro_elements.yaml"
    path.write_text(text, "utf-8")
    return path


ELEMENTS = """framing:
  elements:
    command: {role: command, type: u8, directions: [request]}
    content: {role: content}
"""
DEFAULT_POSITION = "      default: true\n      fields:\n        position:"


def test_the_stream_parser_takes_an_awaited_codeless_reply(tmp_path: Path) -> None:
    """A bug fixed: one layout's code-less replies of different sizes, which nothing in the frame sizes, are read
    as the reply awaited (Framing.codeless_replies), byte by byte too; unawaited, their bytes are garbage; `decode`
    alone gives the default reply. The C reads them the same way (p_parser_expect; it refused such a spec once).
    One generation for all of it: the test that decoded a reply alone is folded in here."""
    path = one_layout_spec(tmp_path)
    module = generate_and_import(path, tmp_path / "out", "maestro_elements")
    parser = module.StreamParser(module.Direction.RESPONSE)
    parser.expect(module.GetPositionResponse, module.GetPositionRequest(channel=2))
    assert parser.feed(bytes.fromhex("70 17")) == [module.GetPositionResponse(position=6000)]
    parser.expect(module.GetMovingStateResponse, module.GetMovingStateRequest())
    assert [m for byte in b"\x01" for m in parser.feed(bytes([byte]))] == [module.GetMovingStateResponse(moving=1)]
    parser.expect(None)
    assert parser.feed(bytes.fromhex("70 17")) == []
    assert module.decode(bytes.fromhex("70 17"), module.Direction.RESPONSE) == module.GetPositionResponse(6000)
    protocol = load_protocol(path)
    assert protocol.framing.by_request(Direction.RESPONSE)
    assert not load_protocol(SPEC).framing.codeless_replies  # layouts chosen by command: by_command says it
    c_source = next(text for path, text in c_files(protocol).items() if path.endswith("maestro_elements.c"))
    assert "maestro_elements__reply_layout(expect)" in c_source  # (refused once: the matrix case runs it)


def test_the_generated_client_asks_the_sim(ma: ModuleType) -> None:
    client_module = importlib.import_module("maestro.client")
    with serve(str(SPEC)) as path, client_module.MaestroClient(path, timeout=5) as maestro:
        maestro.set_target(2, 6000)
        assert maestro.get_position(2) == 6000
        assert maestro.get_moving_state() == 0
        assert maestro.get_errors() == ma.ErrorsBits(**dict.fromkeys(ma.ErrorsBits.__match_args__, 0))


SEVEN_BIT = """
protocol: maestro7
title: Maestro Set Target with a 14-bit target
byte_order: little
serial: {baudrate: 9600}
framing:
  elements:
    command: {role: command, type: u8, directions: [request]}
    content: {role: content}
commands:
  set_target:
    code: 0x84
    request:
      fields:
        channel: u8
        target: {type: u16, encoding: seven_bit, range: [0, 16383]}
"""


def test_a_14_bit_value_in_two_7_bit_bytes(tmp_path: Path) -> None:
    """`encoding: seven_bit` (a language gap once): one field holding 6000 for 70 2E; a byte with bit 7 set is no
    such value, and a value past 14 bits is refused before a byte is written."""
    path = tmp_path / "maestro7.yaml"
    path.write_text(SEVEN_BIT, "utf-8")
    module = generate_and_import(path, tmp_path / "out", "maestro7")
    message = module.SetTargetRequest(channel=2, target=6000)
    assert module.encode(message) == bytes.fromhex("84 02 70 2e")
    assert module.decode(bytes.fromhex("84 02 70 2e"), module.Direction.REQUEST) == message
    with pytest.raises(DecodeError, match="bit 7 of a byte of target"):
        module.decode(bytes.fromhex("84 02 f0 2e"), module.Direction.REQUEST)
    with pytest.raises(RangeError, match=r"target = 16384 is outside its range 0\.\.16383"):
        module.encode(module.SetTargetRequest(channel=2, target=16384))


POLOLU_FORM = """
protocol: maestro_pololu
title: Maestro, compact and Pololu protocol forms
byte_order: little
serial: {baudrate: 9600}
framing:
  layouts:
    compact:
      elements:
        command: {role: command, type: u8, directions: [request]}
        content: {role: content}
    pololu:
      elements:
        start: {role: header, value: AA, directions: [request]}
        device: {role: address, type: u8, range: [0, 127], directions: [request]}
        command: {role: command, type: u8, directions: [request], code: "code & 0x7F"}
        content: {role: content}
commands:
  set_target:
    code: 0x84
    request:
      fields: {channel: u8, target_low: u8, target_high: u8}
  get_position:
    code: 0x90
    request:
      fields: {channel: u8}
    response:
      fields: {position: u16}
device:
  reply: {position: 6000}
"""


def test_the_pololu_protocol_form(tmp_path: Path) -> None:
    """The guide's Pololu protocol (a language gap once): AA, the device number, the command with bit 7 cleared,
    beside the compact form, which carries no device number. A message holds `device` None in the compact form;
    encode sends the layout carrying what the message gives (a device number: the Pololu form); the client sends
    the form of the device number it is given (None: the compact one), the sim answers a Pololu frame of its own
    number only and every compact frame; the C refuses the spec in one line (a struct's integer holds no None)."""
    import serial
    from serialspec.backends import Unsupported

    path = tmp_path / "maestro_pololu.yaml"
    path.write_text(POLOLU_FORM, "utf-8")
    module = generate_and_import(path, tmp_path / "out", "maestro_pololu")
    request = module.Direction.REQUEST
    pololu = module.SetTargetRequest(device=12, channel=2, target_low=0x70, target_high=0x2E)
    compact = module.SetTargetRequest(channel=2, target_low=0x70, target_high=0x2E)
    assert module.decode(bytes.fromhex("aa 0c 04 02 70 2e"), request) == pololu  # the guide's example
    assert module.decode(bytes.fromhex("84 02 70 2e"), request) == compact
    assert compact.device is None
    assert module.encode(pololu) == bytes.fromhex("aa 0c 04 02 70 2e")
    assert module.encode(compact) == bytes.fromhex("84 02 70 2e")
    assert module.SetTargetRequest.from_fields(pololu.to_fields()) == pololu
    assert module.SetTargetRequest.from_fields(compact.to_fields()) == compact
    with pytest.raises(RangeError, match=r"device = 128 is outside its range 0\.\.127"):
        module.encode(module.SetTargetRequest(device=128, channel=2, target_low=0, target_high=0))
    parser = module.StreamParser(request)
    assert parser.feed(bytes.fromhex("aa 0c 04 02 70 2e 84 02 70 2e aa 0c")) == [pololu, compact]
    assert parser.feed(bytes.fromhex("04 02 70 2e")) == [pololu]
    with pytest.raises(Unsupported, match=r"^a frame value that some alternative layout does not carry \(device"):
        c_files(load_protocol(path))
    simulator = importlib.import_module("maestro_pololu.simulator").MaestroPololuSimulator(ids=[12])
    client_class = importlib.import_module("maestro_pololu.client").MaestroPololuClient
    try:
        port_path = simulator.start()
        with serial.Serial(port_path, 9600, timeout=0.5) as port:
            port.write(bytes.fromhex("aa 0d 10 02 aa 0c 10 03 90 04"))  # device 13's (silence), 12's, compact
            assert port.read(6) == bytes.fromhex("70 17 70 17")
        with client_class(port_path, timeout=5) as maestro:
            maestro.set_target(12, 2, 0x70, 0x2E)
            assert maestro.get_position(12, 2) == 6000
            assert maestro.get_position(None, 2) == 6000
    finally:
        simulator.close()
