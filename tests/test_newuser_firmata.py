"""Firmata, the protocol of every Arduino running StandardFirmata (tests/specs/firmata.yaml), written from the README,
the tutorial and the language reference alone, checked against pyfirmata2 2.5.1 (its Board, Pin and Port write our
golden frames; its Board.iterate reads ours; its Board drives `serialspec sim` on a real pseudo-terminal).

MIDI-style framing as two layouts chosen by command: channel and system messages (a command byte, bit 7 set, and as
many data bytes as the command takes) beside sysex (F0, a sysex command, 7-bit data, F7, the trailer ending it).
Every data byte is `encoding: seven_bit` (a u8 of 0..127, a u16 of 14 bits as two bytes, low first), so a command
byte where data belongs is refused, as a Firmata reader would. REPORT_FIRMWARE's name and STRING_DATA are text of
14-bit characters (`encoding: seven_bit` on a string). What the language cannot say is pinned by a strict xfail: a
pin or port number in the low bits of the command byte (the spec has a command per channel instead)."""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from conftest import generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.lang import SpecErrors, load_protocol
from serialspec.runtime.errors import DecodeError, EncodeError
from sim_process import serve

pyfirmata2 = pytest.importorskip("pyfirmata2")
firmata_module = importlib.import_module("pyfirmata2.pyfirmata2")
BOARDS = importlib.import_module("pyfirmata2.boards").BOARDS

SPEC = Path(__file__).parent / "specs" / "firmata.yaml"
NAME = "StandardFirmata.ino"


@pytest.fixture(scope="module")
def fm(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("firmata"), "firmata")


class FakeSerial:
    """What pyfirmata2's Board reads and writes through: each write kept as one frame, reads served from `incoming`."""

    def __init__(self, incoming: bytes = b"") -> None:
        self.writes: list[bytes] = []
        self.incoming = bytearray(incoming)
        self.port = "fake"

    def write(self, data: bytes | bytearray) -> None:
        self.writes.append(bytes(data))

    def read(self, count: int = 1) -> bytes:
        chunk, self.incoming[:count] = bytes(self.incoming[:count]), b""
        return chunk

    def inWaiting(self) -> int:  # noqa: N802 (pyserial's old name, which pyfirmata2 calls)
        return len(self.incoming)

    def close(self) -> None:
        pass


def board(incoming: bytes = b"") -> Any:
    """A pyfirmata2 Board of an Arduino Uno's layout, without its 5 s wait for a reset: built as its own mockup.py
    builds MockupBoard, with our fake port."""
    made = firmata_module.Board.__new__(firmata_module.Board)
    made.sp, made.name, made.samplerThread = FakeSerial(incoming), "fake", None
    made.setup_layout(BOARDS["arduino"])
    return made


def pyfirmata2_session() -> list[bytes]:
    """The frames pyfirmata2 writes for a session of its public calls, one per write."""
    uno = board()
    uno.digital[13].write(1)  # an output pin: DIGITAL_MESSAGE for its port, 1
    uno.get_pin("d:3:p").write(0.5)  # SET_PIN_MODE 3 PWM, then ANALOG_MESSAGE pin 3, 128
    uno.get_pin("a:0:i")  # REPORT_ANALOG 0 on
    uno.get_pin("d:2:i")  # SET_PIN_MODE 2 INPUT, REPORT_DIGITAL port 0 on
    uno.servo_config(9, 544, 2400, 90)  # SERVO_CONFIG, then ANALOG_MESSAGE pin 9, 90 degrees
    uno.setSamplingInterval(19)  # SAMPLING_INTERVAL 19 ms
    uno.send_sysex(firmata_module.REPORT_FIRMWARE, [])  # the firmware query (pyfirmata2 has no method of its own)
    uno.send_sysex(firmata_module.CAPABILITY_QUERY, [])  # as its auto_setup asks
    uno.exit()  # reporting off (REPORT_ANALOG 0, REPORT_DIGITAL port 0), the servo pin back to OUTPUT
    writes: list[bytes] = uno.sp.writes
    return writes


# what each frame of pyfirmata2_session is, by message class and fields
SESSION = [
    ("DigitalMessage1Request", {"value": 1 << 5}),
    ("SetPinModeRequest", {"pin": 3, "mode": 3}),
    ("AnalogMessage3Request", {"value": 128}),
    ("ReportAnalog0Request", {"enable": 1}),
    ("SetPinModeRequest", {"pin": 2, "mode": 0}),
    ("ReportDigital0Request", {"enable": 1}),
    ("ServoConfigRequest", {"pin": 9, "min_pulse": 544, "max_pulse": 2400}),
    ("AnalogMessage9Request", {"value": 90}),
    ("SamplingIntervalRequest", {"interval": 19}),
    ("ReportFirmwareRequest", {}),
    ("CapabilityQueryRequest", {}),
    ("ReportAnalog0Request", {"enable": 0}),
    ("ReportDigital0Request", {"enable": 0}),
    ("SetPinModeRequest", {"pin": 9, "mode": 1}),
]


def test_what_pyfirmata2_writes_decodes_and_encodes_back(fm: ModuleType) -> None:
    frames = pyfirmata2_session()
    assert frames[:3] == [bytes.fromhex("91 20 00"), bytes.fromhex("f4 03 03"), bytes.fromhex("e3 00 01")]
    decoded = [fm.decode(frame, fm.Direction.REQUEST) for frame in frames]
    assert decoded == [getattr(fm, name)(**fields) for name, fields in SESSION]
    assert [fm.encode(message) for message in decoded] == frames
    assert decoded[1].mode == fm.PinMode.PWM


def test_what_we_encode_pyfirmata2_reads(fm: ModuleType) -> None:
    """A board's greeting and its reports, from our encoder, through pyfirmata2's Board.iterate: the protocol
    version, the firmware's version and name, an analog pin's value (scaled by pyfirmata2 to 0..1) and a port's
    input pins."""
    uno = board()
    analog = uno.get_pin("a:0:i")
    button = uno.get_pin("d:2:i")
    seen: list[Any] = []
    button.register_callback(seen.append)
    messages = [
        fm.ReportVersionResponse(major=2, minor=5),
        fm.ReportFirmwareResponse(major=2, minor=5, name=NAME),
        fm.AnalogMessage0Response(value=1023),
        fm.DigitalMessage0Response(value=0b100),
    ]
    uno.sp.incoming += b"".join(fm.encode(message) for message in messages)
    while uno.bytes_available():
        uno.iterate()
    assert uno.get_firmata_version() == (2, 5)
    assert (uno.firmware_version, uno.firmware) == ((2, 5), NAME)
    assert analog.value == 1.0
    assert (button.value, seen) == (True, [True])


MESSAGES = st.one_of(
    st.builds(
        lambda a, b: ("ReportVersionResponse", {"major": a, "minor": b}), st.integers(0, 127), st.integers(0, 127)
    ),
    st.builds(lambda n, v: (f"AnalogMessage{n}Response", {"value": v}), st.integers(0, 15), st.integers(0, 16383)),
    st.builds(lambda n, v: (f"DigitalMessage{n}Response", {"value": v}), st.integers(0, 15), st.integers(0, 255)),
    st.builds(
        lambda text: ("StringDataResponse", {"text": text}),
        st.text(st.characters(max_codepoint=0x3FFF, exclude_categories=("Cs",)), max_size=6),
    ),
    st.builds(lambda c: ("AnalogMappingResponseResponse", {"channels": c}), st.lists(st.integers(0, 127), max_size=6)),
)


@settings(max_examples=60, deadline=None)
@given(chosen=st.lists(MESSAGES, min_size=1, max_size=6), cuts=st.lists(st.integers(0, 200), max_size=8))
def test_a_stream_of_mixed_messages_split_anywhere(fm: ModuleType, chosen: list[Any], cuts: list[int]) -> None:
    """Channel messages sized by their command beside sysex messages ended by F7, read in any pieces, between
    bytes no Firmata message starts with (a data byte where a command belongs, a sysex the spec does not have)."""
    messages = []
    for name, fields in chosen:
        messages.append(getattr(fm, name)(**fields))
    stream = b"\x05" + b"".join(fm.encode(m) + bytes.fromhex("f0 6e 01 f7") for m in messages)
    parser = fm.StreamParser(fm.Direction.RESPONSE)
    found = []
    last = 0
    for cut in sorted({min(c, len(stream)) for c in cuts}) + [len(stream)]:
        found += parser.feed(stream[last:cut])
        last = cut
    assert found == messages


def test_a_command_byte_where_data_belongs_is_no_data(fm: ModuleType) -> None:
    """Every data byte is seven_bit: a SET_PIN_MODE cut short by REPORT_VERSION is refused, and a stream parser
    takes the REPORT_VERSION after it."""
    with pytest.raises(DecodeError, match="bit 7 of a byte of mode"):
        fm.decode(bytes.fromhex("f4 0d f9"), fm.Direction.REQUEST)
    parser = fm.StreamParser(fm.Direction.RESPONSE)
    assert parser.feed(bytes.fromhex("e0 7f f9 02 05")) == [fm.ReportVersionResponse(major=2, minor=5)]


def test_a_frame_no_command_of_its_direction_has_is_refused_by_its_code(fm: ModuleType) -> None:
    """A finding fixed: with layouts chosen by command, a sysex frame was first read in the headerless layout (the
    refusal named code 0xf0, the sysex start), and a code no command of the direction has was "not sent in layout
    'midi'"; now the header's layout is tried first and such a code is an unknown command, as in one layout."""
    with pytest.raises(DecodeError, match=r"^unknown command 0x6a$"):  # ANALOG_MAPPING_RESPONSE, read as a request
        fm.decode(bytes.fromhex("f0 6a 7f f7"), fm.Direction.REQUEST)
    with pytest.raises(DecodeError, match=r"^unknown command 0xf4$"):  # SET_PIN_MODE, read as a response
        fm.decode(bytes.fromhex("f4 0d 01"), fm.Direction.RESPONSE)
    with pytest.raises(DecodeError, match=r"^code 0x79 is not sent in layout 'midi'$"):  # REPORT_FIRMWARE's code
        fm.decode(bytes.fromhex("79"), fm.Direction.REQUEST)


def test_pyfirmata2_asks_the_sim(monkeypatch: pytest.MonkeyPatch) -> None:
    """pyfirmata2's own Board (no 5 s wait for a reset) on the pseudo-terminal `serialspec sim` serves: it asks for
    the protocol version and the firmware, and its iterate() reads the answers."""
    monkeypatch.setattr(firmata_module, "BOARD_SETUP_WAIT_TIME", 0)
    with serve(str(SPEC)) as path:
        uno = firmata_module.Board(path, BOARDS["arduino"], timeout=5)
        try:
            uno.sp.write(bytes([firmata_module.REPORT_VERSION]))
            uno.send_sysex(firmata_module.REPORT_FIRMWARE, [])
            for _ in range(100):  # one byte a call, bounded: a missing answer fails, never hangs
                if uno.firmware is not None:
                    break
                uno.iterate()
            assert (uno.get_firmata_version(), uno.firmware_version, uno.firmware) == ((2, 5), (2, 5), NAME)
        finally:
            uno.exit()


def test_bits_on_a_command_element_are_refused(tmp_path: Path) -> None:
    """A finding fixed: `bits` on the command element (where a new user first puts the pin of 0xE0 | pin) were
    accepted and ignored, so `e3 7f 07` was an unknown command; now the spec is refused in one line at its place."""
    path = tmp_path / "channel.yaml"
    path.write_text(CHANNEL.replace("PIN", "bits: {kind: {bits: [7, 4]}, pin: {bits: [3, 0]}}"), "utf-8")
    with pytest.raises(
        SpecErrors,
        match=r"command\.bits: `bits` belongs to an address, status or value element.*"
        r"leave out the command element and begin each message with its code as a constant bit field",
    ):
        load_protocol(str(path))


CHANNEL = """
protocol: firmata_channel
title: Firmata's ANALOG_MESSAGE, its pin in the command byte
byte_order: little
serial: {baudrate: 57600}
framing:
  elements:
    command: {role: command, type: u8, PIN}
    content: {role: content}
commands:
  analog_message:
    code: 0xE0
    request: {fields: {value: {type: u16, encoding: seven_bit}}}
"""


PICKED = """
protocol: firmata_channel
title: Firmata's channel messages, the pin in the command byte's low bits
byte_order: little
serial: {baudrate: 57600}
framing:
  elements:
    content: {role: content}
commands:
  analog_message:
    request: {fields: {kind: {type: u4, const: 0xE}, pin: u4, value: {type: u16, encoding: seven_bit}}}
  report_analog:
    request: {fields: {kind: {type: u4, const: 0xC}, pin: u4, enable: {type: u8, range: [0, 1]}}}
  report_version:
    request: {fields: {kind: {type: u8, const: 0xF9}}}
"""


def test_a_pin_in_the_command_byte(tmp_path: Path) -> None:
    """What the refusal above points to: no command element, each message beginning with its command bits (a u4 or
    a u8 constant: a prefix code) and the pin after them; each sized by its own fields (2, 3 or 1 byte)."""
    path = tmp_path / "channel.yaml"
    path.write_text(PICKED, "utf-8")
    module = generate_and_import(path, tmp_path / "out", "firmata_channel")
    message = module.decode(bytes.fromhex("e3 7f 07"), module.Direction.REQUEST)
    assert message == module.AnalogMessageRequest(pin=3, value=1023)
    assert module.encode(module.ReportAnalogRequest(pin=5, enable=1)) == bytes.fromhex("c5 01")
    with pytest.raises(DecodeError, match=r"unknown kind 0xa0 .* nor a response \(the protocol has no response "):
        module.decode(bytes.fromhex("a0 00 00"))  # (it said "unknown command None" of the responses)
    stream = bytes.fromhex("f9 c5 01 e3 7f 07 f9")
    parser = module.StreamParser(module.Direction.REQUEST)
    found = [m for byte in stream for m in parser.feed(bytes([byte]))]
    assert [type(m).__name__ for m in found] == [
        "ReportVersionRequest",
        "ReportAnalogRequest",
        "AnalogMessageRequest",
        "ReportVersionRequest",
    ]


TEXT14 = """
protocol: firmata_text14
title: Firmata's STRING_DATA as text
byte_order: little
serial: {baudrate: 57600}
framing:
  elements:
    start: {role: header, value: F0}
    command: {role: command, type: u8}
    content: {role: content}
    end: {role: trailer, value: F7}
commands:
  string_data:
    code: 0x71
    response: {fields: {text: {type: string, size: rest, encoding: seven_bit}}}
"""


def test_an_encoding_on_text_is_refused(tmp_path: Path) -> None:
    """A finding fixed: an encoding on a string was accepted and ignored (F0 71 48 00 69 00 F7 decoded as
    'H\\x00i\\x00'); now seven_bit is text of 14-bit characters, and an encoding that makes no sense for text, or
    seven_bit on text it cannot size, is refused in one line at its place."""
    path = tmp_path / "firmata_text14.yaml"
    path.write_text(TEXT14.replace("seven_bit", "sign_magnitude"), "utf-8")
    with pytest.raises(
        SpecErrors, match=r"text\.encoding: `encoding` is how an integer is stored: a string takes only"
    ):
        load_protocol(str(path))
    path.write_text(TEXT14.replace("size: rest", "size: 3"), "utf-8")
    with pytest.raises(SpecErrors, match=r"text\.encoding: size 3: text of 14-bit characters is two bytes a"):
        load_protocol(str(path))
    path.write_text(TEXT14.replace("type: string, size: rest", "type: cstring"), "utf-8")
    with pytest.raises(SpecErrors, match=r"text\.encoding: encoding seven_bit on text needs `size: rest`"):
        load_protocol(str(path))


def test_text_of_14_bit_characters(tmp_path: Path) -> None:
    path = tmp_path / "firmata_text14.yaml"
    path.write_text(TEXT14, "utf-8")
    module = generate_and_import(path, tmp_path / "out", "firmata_text14")
    message = module.decode(bytes.fromhex("f0 71 48 00 69 00 f7"), module.Direction.RESPONSE)
    assert message.text == "Hi"
    assert module.encode(module.StringDataResponse(text="é\u3fff")) == bytes.fromhex("f0 71 69 01 7f 7f f7")
    with pytest.raises(EncodeError, match=r"text: character 0 \(.*, 0x1f600\) is not a 14-bit character"):
        module.encode(module.StringDataResponse(text="\U0001f600"))
    with pytest.raises(DecodeError, match="text is not text of 14-bit characters: 3 bytes: an odd count"):
        module.decode(bytes.fromhex("f0 71 48 00 69 f7"), module.Direction.RESPONSE)
