"""specs/mavlink_common.yaml against pymavlink, MAVLink's reference implementation (its common dialect, MAVLink 2):
frames it packs, truncated ones included, decode to its values and re-encode byte for byte; it parses every frame we
encode; pymavlink's own connection (mavutil on a real pseudo-terminal) drives `serialspec sim`: heartbeats, a
parameter set and read back, a command acknowledged; and `truncate: trailing_zeros`, the general key MAVLink's
payload truncation needs, refuses the specs it cannot serve, one line each."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import pytest
import serial
from conftest import examples
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.lang import SpecErrors, load_protocol
from serialspec.runtime.errors import DecodeError
from sim_process import serve

os.environ["MAVLINK20"] = "1"  # before pymavlink is imported: MAVLink 2 frames
mavlink2 = pytest.importorskip("pymavlink.dialects.v20.common")
mavutil = pytest.importorskip("pymavlink.mavutil")

from serialspec_protocols import mavlink_common as mav  # noqa: E402
from serialspec_protocols.mavlink_common.client import MavlinkCommonClient  # noqa: E402

SETTINGS = settings(max_examples=examples(25), deadline=None, suppress_health_check=list(HealthCheck))
# pymavlink's message class, our class and direction, by message
PAIRS: dict[str, tuple[Any, Any, str]] = {
    "HEARTBEAT": (mavlink2.MAVLink_heartbeat_message, mav.HeartbeatResponse, "response"),
    "SYS_STATUS": (mavlink2.MAVLink_sys_status_message, mav.SysStatusResponse, "response"),
    "PARAM_REQUEST_READ": (mavlink2.MAVLink_param_request_read_message, mav.ParamRequestReadRequest, "request"),
    "PARAM_VALUE": (mavlink2.MAVLink_param_value_message, mav.ParamValueResponse, "response"),
    "PARAM_SET": (mavlink2.MAVLink_param_set_message, mav.ParamSetRequest, "request"),
    "ATTITUDE": (mavlink2.MAVLink_attitude_message, mav.AttitudeResponse, "response"),
    "GLOBAL_POSITION_INT": (mavlink2.MAVLink_global_position_int_message, mav.GlobalPositionIntResponse, "response"),
    "COMMAND_LONG": (mavlink2.MAVLink_command_long_message, mav.CommandLongRequest, "request"),
    "COMMAND_ACK": (mavlink2.MAVLink_command_ack_message, mav.CommandAckResponse, "response"),
}
INTEGERS = {"B": (0, 255), "b": (-128, 127), "H": (0, 65535), "h": (-32768, 32767), "I": (0, 2**32 - 1)}
INTEGERS["i"] = (-(2**31), 2**31 - 1)


def link(sysid: int = 1, compid: int = 1, seq: int = 0) -> Any:
    sender = mavlink2.MAVLink(None, srcSystem=sysid, srcComponent=compid)
    sender.seq = seq
    return sender


def peer_values(message: Any) -> dict[str, Any]:
    """pymavlink's field values as our messages hold them: text as str (its char arrays are bytes when packed)."""
    values = {}
    for name in message.ordered_fieldnames:
        value = getattr(message, name)
        values[name] = value.decode() if isinstance(value, bytes) else value
    return values


def ours(frame: bytes, direction: str) -> dict[str, Any]:
    fields = mav.decode(frame, direction).to_fields()
    return {k: v for k, v in fields.items() if k not in ("seq", "sysid", "compid", "signature")}


def peer_messages(name: str) -> st.SearchStrategy[Any]:
    """pymavlink messages of one type with random values in its fields' wire types (f32-exact floats), as many zero
    as not, so that many frames end in zero bytes and are truncated."""
    cls = PAIRS[name][0]
    formats = cls.unpacker.format[1:]
    parts: list[st.SearchStrategy[Any]] = []
    for count_text, code in _formats(formats):
        if code == "s":
            text = st.text(st.characters(min_codepoint=0x21, max_codepoint=0x7E), max_size=int(count_text))
            parts.append(text.map(str.encode))
        elif code == "f":
            parts.append(st.one_of(st.just(0.0), st.floats(width=32, allow_nan=False, allow_infinity=False)))
        else:
            low, high = INTEGERS[code]
            parts.append(st.one_of(st.just(0), st.integers(low, high)))
    order = list(cls.ordered_fieldnames)
    names = cls.fieldnames  # the constructor's order (the definition's)

    def build(values: tuple[Any, ...]) -> Any:
        by_name = dict(zip(order, values, strict=True))
        return cls(*(by_name[n] for n in names))

    return st.tuples(*parts).map(build)


def _formats(formats: str) -> list[tuple[str, str]]:
    found, digits = [], ""
    for char in formats:
        if char.isdigit():
            digits += char
        else:
            found.append((digits, char))
            digits = ""
    return found


@pytest.mark.parametrize("name", sorted(PAIRS))
def test_frames_pymavlink_packs_decode_to_its_values_and_reencode(name: str) -> None:
    _, cls, direction = PAIRS[name]

    @SETTINGS
    @given(peer_messages(name), st.integers(0, 255), st.integers(1, 255), st.integers(0, 255))
    def check(message: Any, seq: int, sysid: int, compid: int) -> None:
        frame = bytes(message.pack(link(sysid, compid, seq)))
        decoded = mav.decode(frame, direction)
        assert type(decoded) is cls
        assert (decoded.seq, decoded.sysid, decoded.compid) == (seq, sysid, compid)
        assert ours(frame, direction) == peer_values(message)
        assert mav.encode(decoded) == frame  # truncated the same way, to the same byte
        parser = mav.StreamParser(direction)
        assert [m for byte in b"\x00\xfd" + frame for m in parser.feed(bytes([byte]))] == [decoded]

    check()


def test_pymavlink_truncates_and_so_do_we() -> None:
    """The cut frames: COMMAND_LONG without its zero confirmation, ATTITUDE without a zero yawspeed, a
    PARAM_REQUEST_READ without its name's NUL padding, an all-zero payload down to one byte."""
    cases = [
        (mavlink2.MAVLink_command_long_message(1, 1, 400, 0, 1, 0, 0, 0, 0, 0, 0), 33, 32),
        (mavlink2.MAVLink_attitude_message(5, 0.5, 0, 0, 0, 0, 0), 28, 8),
        (mavlink2.MAVLink_param_request_read_message(1, 1, b"SYSID", -1), 20, 9),
        (mavlink2.MAVLink_heartbeat_message(0, 0, 0, 0, 0, 0), 9, 1),
    ]
    for message, full, sent in cases:
        frame = bytes(message.pack(link()))
        assert frame[1] == sent and len(frame) == 12 + sent
        _, _, direction = PAIRS[message.get_type()]
        decoded = mav.decode(frame, direction)
        assert ours(frame, direction) == peer_values(message)
        assert mav.encode(decoded) == frame
        # the same payload sent whole (as MAVLink 1 peers and some senders do): decoded alike, re-encoded cut
        head, payload = bytes([0xFD, full]) + frame[2:10], frame[10:-2] + bytes(full - sent)
        crc = mavlink2.x25crc(head[1:] + payload)
        crc.accumulate(bytes((message.crc_extra,)))
        assert mav.decode(head + payload + crc.crc.to_bytes(2, "little"), direction) == decoded


@pytest.mark.parametrize("name", sorted(PAIRS))
def test_the_c_reads_and_truncates_the_frames_pymavlink_packs(name: str) -> None:
    """generated/c/mavlink_common against pymavlink: its frames, unsigned and signed (truncated ones included, and
    the same payload sent whole), decode in C to the Python codec's values (the 13 signature bytes as `signature`),
    re-encode byte for byte and come out of the C stream parser back to back, in any split."""
    import json

    from test_c_backend import GCC, driver
    from test_mavlink_signing import signer

    if GCC is None:
        pytest.skip("gcc is not installed")
    cls = PAIRS[name][0]
    direction = PAIRS[name][2]
    kind = f"{name.lower()}_{direction}"
    run = driver("mavlink_common")  # built before hypothesis runs: a failed build is one failure, not one per example

    def c_json(frame: bytes) -> dict[str, Any]:
        decoded = mav.decode(frame, direction)
        expected = {"command": decoded.COMMAND, "subcommand": None, "direction": direction}
        expected["fields"] = decoded.to_fields()
        (answer,) = run.ask(f"dec {direction} {frame.hex()} {kind}")
        assert answer.startswith("ok ") and json.loads(answer[3:]) == expected, answer
        (answer,) = run.ask(f"rt {direction} {frame.hex()} {kind}")
        assert answer == f"ok {frame.hex()}"  # cut where pymavlink cuts it, signed as it was
        return expected

    @SETTINGS
    @given(
        peer_messages(name),
        st.integers(0, 255),
        st.integers(1, 255),
        st.integers(0, 255),
        st.integers(0, 255),
        st.integers(0, 2**48 - 1),
        st.lists(st.integers(1, 40), min_size=1, max_size=4),
    )
    def check(message: Any, seq: int, sysid: int, compid: int, link_id: int, stamp: int, sizes: list[int]) -> None:
        frame = bytes(message.pack(link(sysid, compid, seq)))
        expected = c_json(frame)
        signed = bytes(message.pack(signer(sysid, compid, seq, link_id, stamp)))
        expected_signed = c_json(signed)
        assert expected_signed["fields"]["signature"] == signed[-13:].hex(" ")
        full = cls.unpacker.size
        head, payload = bytes([0xFD, full]) + frame[2:10], frame[10:-2] + bytes(full - frame[1])
        crc = mavlink2.x25crc(head[1:] + payload)
        crc.accumulate(bytes((message.crc_extra,)))
        whole = head + payload + crc.crc.to_bytes(2, "little")
        (answer,) = run.ask(f"rt {direction} {whole.hex()} {kind}")
        assert answer == f"ok {frame.hex()}"  # sent whole: read alike, written cut
        stream = b"\x00\xfd" + whole + signed + frame + signed
        answers = run.ask(f"stream {direction} {','.join(map(str, sizes))} {stream.hex()}")
        messages = [json.loads(a[4:]) for a in answers if a.startswith("msg ")]
        assert messages == [expected, expected_signed, expected, expected_signed]

    check()


@pytest.mark.parametrize("name", sorted(PAIRS))
def test_pymavlink_parses_every_frame_we_encode(name: str) -> None:
    _, cls, direction = PAIRS[name]

    @SETTINGS
    @given(peer_messages(name), st.integers(0, 255), st.integers(1, 255), st.integers(0, 255))
    def check(message: Any, seq: int, sysid: int, compid: int) -> None:
        ours_message = cls.from_fields({**peer_values(message), "seq": seq, "sysid": sysid, "compid": compid})
        frame = mav.encode(ours_message)
        receiver = mavlink2.MAVLink(None)
        (parsed,) = receiver.parse_buffer(frame)
        assert parsed.get_type() == name
        assert (parsed.get_seq(), parsed.get_srcSystem(), parsed.get_srcComponent()) == (seq, sysid, compid)
        assert peer_values(parsed) == peer_values(message)
        assert bytes(parsed.get_msgbuf()) == frame  # pymavlink's own frame of what it parsed: ours, byte for byte

    check()


def test_an_unknown_incompat_flag_is_refused_in_one_line() -> None:
    """A receiver refuses a frame with an incompatibility flag it does not know (bit 0, signed, it knows:
    tests/test_mavlink_signing.py)."""
    frame = bytearray(mavlink2.MAVLink_heartbeat_message(2, 12, 81, 0, 3, 3).pack(link()))
    frame[2] = 0x02
    with pytest.raises(DecodeError) as refused:
        mav.decode(bytes(frame), "response")
    assert "\n" not in str(refused.value) and "incompat_flags is 02, expected 00" in str(refused.value)


def test_pymavlink_drives_the_virtual_autopilot() -> None:
    """mavutil on the sim's pseudo-terminal: two heartbeats one after the other (numbered by the device), a
    parameter set and read back, an arm command acknowledged."""
    with serve("mavlink_common.yaml") as path:
        connection = mavutil.mavlink_connection(
            path, baud=57600, source_system=255, source_component=190, dialect="common"
        )
        assert mavutil.mavlink.WIRE_PROTOCOL_VERSION == "2.0"  # MAVLINK20 was set before the import
        try:
            beats = [connection.recv_match(type="HEARTBEAT", blocking=True, timeout=10) for _ in range(2)]
            assert all(b is not None for b in beats)
            first, second = beats
            assert (first.type, first.autopilot, first.system_status, first.mavlink_version) == (2, 12, 3, 3)
            assert (first.get_srcSystem(), first.get_srcComponent()) == (1, 1)
            assert second.get_seq() == (first.get_seq() + 1) % 256
            connection.mav.param_set_send(1, 1, b"MPC_XY_VEL_MAX", 12.5, 9)
            value = connection.recv_match(type="PARAM_VALUE", blocking=True, timeout=10)
            assert value is not None
            assert (value.param_id, value.param_value, value.param_type) == ("MPC_XY_VEL_MAX", 12.5, 9)
            connection.mav.param_request_read_send(1, 1, b"MPC_XY_VEL_MAX", -1)
            value = connection.recv_match(type="PARAM_VALUE", blocking=True, timeout=10)
            assert value is not None and (value.param_id, value.param_value) == ("MPC_XY_VEL_MAX", 12.5)
            connection.mav.command_long_send(1, 1, 400, 0, 1, 0, 0, 0, 0, 0, 0)  # arm
            ack = connection.recv_match(type="COMMAND_ACK", blocking=True, timeout=10)
            assert ack is not None and (ack.command, ack.result) == (400, 0)
        finally:
            connection.close()


def test_our_client_numbers_its_requests_and_gets_the_answers() -> None:
    """The generated client: `seq` filled in (0, 1, 2 ...), PARAM_VALUE and COMMAND_ACK matched among heartbeats."""
    with serve("mavlink_common.yaml") as path, MavlinkCommonClient(path, timeout=5.0) as client:
        value = client.param_set(255, 190, 3.0, 1, 1, "SYSID_THISMAV", mav.MavParamType.INT32)
        assert (value.param_id, value.param_value, value.seq) == ("SYSID_THISMAV", 3.0, 0)
        value = client.param_request_read(255, 190, -1, 1, 1, "SYSID_THISMAV")
        assert (value.param_value, value.param_type, value.seq) == (3.0, mav.MavParamType.INT32, 1)
        ack = client.command_long(255, 190, 1, 0, 0, 0, 0, 0, 0, mav.MavCmd.COMPONENT_ARM_DISARM, 1, 1, 0)
        assert (ack.command, ack.result, ack.seq) == (mav.MavCmd.COMPONENT_ARM_DISARM, mav.MavResult.ACCEPTED, 2)
        beat = next(client.reports(timeout=5.0))
        assert isinstance(beat, mav.HeartbeatResponse) and beat.sysid == 1


def test_the_sim_sends_frames_pymavlink_parses_on_a_plain_port() -> None:
    with serve("mavlink_common.yaml") as path, serial.Serial(path, 57600, timeout=0.2) as port:
        receiver = mavlink2.MAVLink(None)
        got: list[Any] = []
        while len(got) < 2:
            got += [m for m in receiver.parse_buffer(port.read(64)) or [] if m.get_type() == "HEARTBEAT"]
        assert all(m.get_type() == "HEARTBEAT" and m.custom_mode == 0 for m in got)


# --- truncate: trailing_zeros, as a user gets it wrong ---------------------------------------------------------

SPEC = """
protocol: cut
title: Truncated contents
byte_order: little
serial: {baudrate: 9600}
framing:
  elements:
    start: {role: header, value: "AA"}
    length: {role: length, type: u8}
    code: {role: command, type: u8}
    payload: {role: content, truncate: trailing_zeros}
    sum: {role: checksum, type: u8, algorithm: sum, covers: [length, payload]}
commands:
  fixed:
    code: 1
    request: {fields: {a: u16, b: u8}}
"""


def refused(tmp_path: Path, text: str) -> list[str]:
    spec = tmp_path / "cut.yaml"
    spec.write_text(text, encoding="utf-8")
    with pytest.raises(SpecErrors) as raised:
        load_protocol(str(spec))
    return [line.split(": ", 1)[1] for line in str(raised.value).splitlines()]


def test_truncate_refuses_what_it_cannot_pad(tmp_path: Path) -> None:
    varying = SPEC + "  more:\n    code: 2\n    request: {fields: {n: u8, data: {type: bytes, size: rest}}}\n"
    assert refused(tmp_path, varying) == [
        "commands.more.request.fields: a truncated content (`truncate: trailing_zeros`) has one size; this one's size"
        " varies"
    ]
    no_length = SPEC.replace("    length: {role: length, type: u8}\n", "")
    no_length = no_length.replace("covers: [length, payload]", "covers: [code, payload]")
    assert refused(tmp_path, no_length) == [
        "framing.elements.payload.truncate: a truncated content needs a length element: the frame must say how much"
        " of it was sent"
    ]
    on_length = SPEC.replace("role: length, type: u8}", "role: length, type: u8, truncate: trailing_zeros}")
    assert refused(tmp_path, on_length) == ["framing.elements.length.truncate: `truncate` belongs to a content element"]


def test_truncated_frames_of_a_small_spec(tmp_path: Path) -> None:
    """Without MAVLink: the length says what was sent, a short content is padded, a long one refused."""
    from serialspec.backends import emitters
    from serialspec.backends.python.memory import imported
    from serialspec.lang.loader import load_text
    from serialspec.lang.resolve import resolve

    protocol = resolve(load_text(SPEC, "cut.yaml"))
    files = next(e for e in emitters() if e.name == "python").files(protocol)
    modules = {p.split("/", 1)[1]: t for p, t in files.items() if p.startswith("cut/")}
    with imported("cut", modules, "test_mavlink") as cut:
        assert cut.encode(cut.FixedRequest(a=0x0102, b=0)) == bytes.fromhex("aa 02 01 02 01 06")
        assert cut.encode(cut.FixedRequest(a=0, b=0)) == bytes.fromhex("aa 01 01 00 02")
        assert cut.decode(bytes.fromhex("aa 01 01 07 09"), "request") == cut.FixedRequest(a=7, b=0)
        assert cut.decode(bytes.fromhex("aa 03 01 00 00 05 09"), "request") == cut.FixedRequest(a=0, b=5)
        with pytest.raises(DecodeError, match="content"):
            cut.decode(bytes.fromhex("aa 04 01 00 00 05 01 0b"), "request")
