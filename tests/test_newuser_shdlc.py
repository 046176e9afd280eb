"""Sensirion SHDLC, the SPS30's commands (tests/specs/shdlc_sps30.yaml), written from the user docs alone and
checked against sensirion-shdlc-driver: its MOSI frame builder writes our golden requests (byte stuffing of 7E, 7D,
11 and 13 included), its MISO frame builder parses the replies we encode (address, command, state, data), and replies
made with its stuffing and checksum decode to the values it read. The datasheet's frames are the spec's examples.
Read Measured Values answers 40 bytes of floats, 20 bytes of integers, or nothing when there is no new value: three
replies under one code, told apart by their size. A reply whose state has an execution error code carries no data:
the error reply `refused`, marked by the state's `error_bits`."""

from __future__ import annotations

import importlib
import os
import re
import struct
import threading
import tty
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.lang import SpecErrors, load_protocol
from serialspec.runtime.errors import DecodeError, DeviceError, EncodeError

shdlc = pytest.importorskip("sensirion_shdlc_driver.serial_frame_builder")
Mosi = shdlc.ShdlcSerialMosiFrameBuilder
Miso = shdlc.ShdlcSerialMisoFrameBuilder

SPEC = Path(__file__).parent / "specs" / "shdlc_sps30.yaml"
STUFFED = st.sampled_from([0x7E, 0x7D, 0x11, 0x13, 0x00, 0x20, 0xFF])  # the bytes that are escaped, and others
U32 = st.one_of(
    st.integers(0, 2**32 - 1),
    st.lists(STUFFED, min_size=4, max_size=4).map(bytes).map(lambda b: int.from_bytes(b, "big")),
)
F32 = st.floats(width=32, allow_nan=False, allow_infinity=False)


@pytest.fixture(scope="module")
def sp(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("shdlc"), "shdlc_sps30")


def miso_frame(address: int, command: int, state: int, data: bytes) -> bytes:
    """A MISO frame made with the peer's own stuffing and checksum (it has no MISO builder)."""
    content = bytearray([address, command, state, len(data)]) + data
    content.append(Miso._calculate_checksum(content))
    return b"\x7e" + bytes(Mosi._stuff_data_bytes(content)) + b"\x7e"


def peer_reads(frame: bytes) -> tuple[int, int, int, bytes]:
    builder = Miso()
    assert builder.add_data(frame)
    address, command, state, data = builder.interpret_data()
    return address, command, state, bytes(data)


@pytest.mark.parametrize(
    ("command", "data", "name", "fields"),
    [
        (0x00, b"\x01\x03", "StartMeasurementRequest", {"output_format": 3}),
        (0x00, b"\x01\x05", "StartMeasurementRequest", {"output_format": 5}),
        (0x01, b"", "StopMeasurementRequest", {}),
        (0x03, b"", "ReadMeasuredValuesRequest", {}),
        (0x10, b"", "SleepRequest", {}),
        (0x11, b"", "WakeUpRequest", {}),  # 7E 00 7D 31 00 EE 7E: the command 0x11 itself is escaped
        (0x56, b"", "StartFanCleaningRequest", {}),
        (0x80, b"\x00", "ReadAutoCleaningIntervalRequest", {}),  # its checksum 0x7E is sent as 7D 5E
        (0xD0, b"\x03", "DeviceInformationRequest", {"what": 3}),
        (0xD1, b"", "ReadVersionRequest", {}),
        (0xD2, b"\x01", "ReadDeviceStatusRegisterRequest", {"clear": 1}),
        (0xD3, b"", "DeviceResetRequest", {}),
    ],
)
def test_requests_match_the_peers_mosi_frames(
    sp: ModuleType, command: int, data: bytes, name: str, fields: dict[str, int]
) -> None:
    golden = Mosi(0, command, data).to_bytes()
    message = getattr(sp, name)(address=0, **fields)
    assert sp.encode(message) == golden
    assert sp.decode(golden, sp.Direction.REQUEST) == message


@settings(max_examples=examples(25), deadline=None)
@given(address=STUFFED, interval=U32)
def test_stuffed_interval_writes_match_the_peer(sp: ModuleType, address: int, interval: int) -> None:
    golden = Mosi(address, 0x80, b"\x00" + struct.pack(">I", interval)).to_bytes()
    message = sp.WriteAutoCleaningIntervalRequest(address=address, interval=interval)
    assert sp.encode(message) == golden
    assert sp.decode(golden, sp.Direction.REQUEST) == message


@settings(max_examples=examples(25), deadline=None)
@given(values=st.lists(F32, min_size=10, max_size=10), address=STUFFED)
def test_measured_values_replies_are_read_by_the_peer(sp: ModuleType, values: list[float], address: int) -> None:
    ok = sp.StateBits(error=0, code=0)
    message = sp.ReadMeasuredValuesResponse(address, ok, *values)
    frame = sp.encode(message)
    got_address, command, state, data = peer_reads(frame)
    assert (got_address, command, state) == (address, 0x03, 0)
    assert struct.unpack(">10f", data) == tuple(values)
    assert frame == miso_frame(address, 0x03, 0, data)
    assert sp.decode(frame, sp.Direction.RESPONSE) == message


@settings(max_examples=examples(15), deadline=None)
@given(interval=U32, state=st.sampled_from([0, 0x80]))  # bit 7 alone: an execution error code carries no data
def test_interval_replies_both_ways(sp: ModuleType, interval: int, state: int) -> None:
    golden = miso_frame(0, 0x80, state, struct.pack(">I", interval))
    message = sp.decode(golden, sp.Direction.RESPONSE)
    assert message.interval == interval
    assert (message.state.error, int(message.state.code)) == (state >> 7, state & 0x7F)
    assert sp.encode(message) == golden
    assert peer_reads(sp.encode(message))[3] == struct.pack(">I", interval)


def test_device_information_and_version(sp: ModuleType) -> None:
    """Product type "00080000" (a NUL-terminated string) and the version reply, both ways."""
    golden = miso_frame(0, 0xD0, 0, b"00080000\x00")
    ok = sp.StateBits(error=0, code=0)
    assert sp.decode(golden, sp.Direction.RESPONSE) == sp.DeviceInformationResponse(0, ok, "00080000")
    assert sp.encode(sp.DeviceInformationResponse(0, ok, "00080000")) == golden
    version = miso_frame(0, 0xD1, 0, bytes([2, 2, 0, 7, 0, 2, 0]))
    message = sp.decode(version, sp.Direction.RESPONSE)
    assert (message.firmware_major, message.firmware_minor, message.hardware_revision) == (2, 2, 7)
    assert sp.encode(message) == version


def test_the_stream_parser_reads_stuffed_replies_in_pieces(sp: ModuleType) -> None:
    frames = [miso_frame(0, 0x80, 0, b"\x00\x11\x7e\x13"), miso_frame(0, 0xD1, 0, bytes([2, 2, 0, 7, 0, 2, 0]))]
    stream = b"\x7e\x7e\x00" + frames[0] + frames[0][:-3] + frames[1]  # a stray start, a frame cut short
    parser = sp.StreamParser(sp.Direction.RESPONSE)
    seen = [m for i in range(0, len(stream), 3) for m in parser.feed(stream[i : i + 3])]
    assert [type(m).__name__ for m in seen] == ["ReadAutoCleaningIntervalResponse", "ReadVersionResponse"]
    assert seen[0].interval == 0x00117E13


def test_a_bad_checksum_is_refused(sp: ModuleType) -> None:
    frame = bytearray(miso_frame(0, 0xD1, 0, bytes([2, 2, 0, 7, 0, 2, 0])))
    frame[-2] ^= 0x01
    with pytest.raises(DecodeError, match="checksum"):
        sp.decode(bytes(frame), sp.Direction.RESPONSE)


def test_read_measured_values_replies_by_size(sp: ModuleType) -> None:
    """Read Measured Values (0x03) answers 40 bytes of floats, 20 of integers (after Start Measurement with format 5)
    or none (no new values): three replies under one code, told apart by their size without the request, by decode
    and by the stream parser however the bytes are split."""
    ok = sp.StateBits(error=0, code=0)
    floats = sp.ReadMeasuredValuesResponse(0, ok, *[float(i) for i in range(10)])
    integers = sp.MeasuredValuesU16Response(0, ok, *range(100, 110))
    empty = sp.NoNewValuesResponse(0, ok)
    frames = [
        miso_frame(0, 3, 0, struct.pack(">10f", *range(10))),
        miso_frame(0, 3, 0, struct.pack(">10H", *range(100, 110))),
        miso_frame(0, 3, 0, b""),
    ]
    for frame, message in zip(frames, [floats, integers, empty], strict=True):
        assert sp.decode(frame, sp.Direction.RESPONSE) == message
        assert sp.encode(message) == frame
    stream = b"".join(frames[::-1] + frames)
    for step in (1, 5):
        parser = sp.StreamParser(sp.Direction.RESPONSE)
        seen = [m for i in range(0, len(stream), step) for m in parser.feed(stream[i : i + step])]
        assert seen == [empty, integers, floats, floats, integers, empty]
    with pytest.raises(DecodeError, match="fits none"):
        sp.decode(miso_frame(0, 3, 0, b"\x00" * 2), sp.Direction.RESPONSE)


def test_the_client_returns_whichever_reply_comes(sp: ModuleType) -> None:
    """The client's read_measured_values() returns the reply the device sends, whole, whichever of the three; an
    empty reply whose state says an error (7E 00 03 43 00 B9 7E) raises DeviceError naming it."""
    controller, device = os.openpty()
    tty.setraw(controller)
    tty.setraw(device)
    sizes = [struct.pack(">10H", *range(10)), b"", struct.pack(">10f", *range(10))]
    states = [0, 0, 0, 0x43]  # then 7E 00 03 43 00 B9 7E: no data, the state a refusal

    def device_side() -> None:
        for data, state in zip([*sizes, b""], states, strict=True):
            asked = b""
            while asked.count(b"\x7e") < 2:
                asked += os.read(controller, 64)
            assert sp.decode(asked, sp.Direction.REQUEST) == sp.ReadMeasuredValuesRequest(address=0)
            os.write(controller, miso_frame(0, 3, state, data))

    thread = threading.Thread(target=device_side, daemon=True)
    thread.start()
    try:
        with importlib.import_module(f"{sp.__name__}.client").ShdlcSps30Client(
            os.ttyname(device), timeout=2.0
        ) as client:
            replies = [client.read_measured_values(0) for _ in sizes]
            with pytest.raises(DeviceError, match="command_not_allowed_in_current_state") as refused:
                client.read_measured_values(0)
    finally:
        thread.join(2.0)
        os.close(controller)
        os.close(device)
    assert [type(r).__name__ for r in replies] == [
        "MeasuredValuesU16Response",
        "NoNewValuesResponse",
        "ReadMeasuredValuesResponse",
    ]
    assert replies[0].typical_particle_size == 9
    assert isinstance(refused.value.reply, sp.RefusedResponse)  # the state's error bits: the error reply


def test_replies_of_one_size_under_one_code_are_refused(tmp_path: Path) -> None:
    """Two replies under 0x03 that a content of 40 bytes fits, neither `default`: one line, naming both."""
    text = SPEC.read_text().replace("{type: u16,", "{type: f32,")  # the integers as floats: 40 bytes too
    spec = tmp_path / "tie.yaml"
    spec.write_text(text)
    with pytest.raises(SpecErrors) as refused:
        load_protocol(spec)
    said = str(refused.value)
    assert said.count("\n") == 0, said
    assert "tie.yaml:" in said and "'read_measured_values'" in said and "measured_values_u16" in said
    assert "a content of 40 bytes fits both" in said


def test_an_error_state_reply_without_data(sp: ModuleType) -> None:
    """7E 00 D1 43 00 EB 7E: Read Version refused (command not allowed in this state), no data: the status's
    `error_bits: 0x7F` make it the error reply `refused`, carrying the refused code; the stream parser sizes it by its
    own bytes between a normal reply's; encode makes it again and refuses a reply whose state contradicts its kind."""
    frame = miso_frame(0, 0xD1, 0x43, b"")
    assert frame == bytes.fromhex("7E 00 D1 43 00 EB 7E")
    message = sp.decode(frame, sp.Direction.RESPONSE)
    assert isinstance(message, sp.RefusedResponse)
    assert int(message.state.code) == 0x43 and message.command == 0xD1 and message.address == 0
    example = next(e for e in load_protocol(SPEC).examples if e.name == "read_version_refused")  # the spec's own
    assert (example.frame, example.command) == (frame, "refused")
    assert sp.RefusedResponse.from_fields(example.fields) == message
    assert sp.encode(message) == frame
    version = miso_frame(0, 0xD1, 0x80, bytes([2, 1, 0, 7, 0, 2, 0]))  # bit 7 (device error) alone: a normal reply
    normal = sp.decode(version, sp.Direction.RESPONSE)
    assert isinstance(normal, sp.ReadVersionResponse) and normal.hardware_revision == 7
    parser = sp.StreamParser(sp.Direction.RESPONSE)
    stream = frame + version + frame
    assert [m for b in stream for m in parser.feed(bytes([b]))] == [message, normal, message]
    with pytest.raises(EncodeError, match="state has error bits 0x7f set"):
        sp.encode(sp.ReadVersionResponse(0, message.state, 2, 1, 7, 2, 0))
    with pytest.raises(EncodeError, match="one of the error bits 0x7f"):
        sp.encode(sp.RefusedResponse(address=0, state=normal.state, command=0xD1))


@pytest.mark.parametrize(
    ("old", "new", "said"),
    [
        (
            "error_bits: 0x7F",
            "error_bits: 0x180",
            "the error bits must be a non-zero bit mask that fits the status's 8",
        ),
        ("error_bits: 0x7F", "error_bits: 0", "the error bits must be a non-zero bit mask"),
        (
            "command: {role: command, type: u8}",
            "command: {role: command, type: u8, error_bits: 1}",
            "goes on the status",
        ),
        ("command: {role: command, type: u8}", "command: {role: command, type: u8, error_flag: 0x80}", "give either"),
        (
            "  refused:\n",
            "  refused_not:\n",
            "`error_bits` needs a command whose response is marked `error_reply: true`",
        ),
    ],
)
def test_error_bits_misused_is_one_line(tmp_path: Path, old: str, new: str, said: str) -> None:
    """`error_bits` elsewhere than on the status, a mask that does not fit it, beside `error_flag`, or without an
    `error_reply`: one line with file:line:column each."""
    text = SPEC.read_text()
    assert old in text
    spec = tmp_path / "bad.yaml"
    text = text.replace(old, new)
    text = text[: text.index("device:\n")] + text[text.index("examples:\n") :]  # its errors need the error reply
    if new.startswith("  refused_not"):  # the command gone, not only its mark
        text = text[: text.index("  refused_not:")] + text[text.index("  device_reset:") :]
        text = text[: text.index("  read_version_refused:")]  # and its example
    spec.write_text(text)
    with pytest.raises(SpecErrors) as refused:
        load_protocol(spec)
    lines = str(refused.value).splitlines()
    assert len(lines) == 1 and said in lines[0], lines
    assert re.match(r"\S*bad\.yaml:\d+:\d+: framing\.elements\.\w+\.error_", lines[0]), lines


def test_the_simulator_refuses_an_unknown_command_in_the_state_byte(sp: ModuleType) -> None:
    """A request of code 0x44 (no command has it) is answered as a real SPS30 does: no data, state 0x02 (unknown
    command), the request's code in the command byte; the peer's MISO reader takes the frame apart the same way."""
    simulator = importlib.import_module(f"{sp.__name__}.simulator").ShdlcSps30Simulator(ids=[0])
    ((_, frame),) = simulator.feed(Mosi(0, 0x44, b"").to_bytes())
    assert frame == miso_frame(0, 0x44, 0x02, b"")
    assert peer_reads(frame) == (0, 0x44, 0x02, b"")
    reply = sp.decode(frame, sp.Direction.RESPONSE)
    assert isinstance(reply, sp.RefusedResponse) and reply.command == 0x44
    assert reply.state.code == sp.ExecutionError.UNKNOWN_COMMAND


def test_the_c_reads_the_state_byte_error_reply(tmp_path: Path) -> None:
    """The C (strict flags) decodes every example, the refused Read Version (7E 00 D1 43 00 EB 7E) among them, encodes
    it back and finds it with its parser fed byte by byte (check_vectors, through the stuffed frame engine)."""
    from test_c_backend import GCC, check_vectors

    if GCC is None:
        pytest.skip("no C compiler")
    assert check_vectors(SPEC, "shdlc_sps30", tmp_path) == "shdlc_sps30: 5 vectors, 0 refused frames, 0 failed\n"
