"""The general frame engine (serialspec.runtime.framing) on the framings it was designed for.

DYNAMIXEL 2.0 (stuffing, u16 length over a span, CRC over the stuffed bytes) through the generated package; VESC's
two length forms with a trailer and a big-endian CRC, Modbus RTU's header-less frames sized by their command, and
SLIP-style escaping through engine objects, the way generated codecs describe them.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import pytest
from conftest import examples
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.checksums import crc as crc_module
from serialspec.checksums.crc import crc_function
from serialspec.checksums.sum import sum_function
from serialspec.checksums.xor import xor_function
from serialspec.runtime.errors import ChecksumError, DecodeError, EncodeError
from serialspec.runtime.framing import Element, FrameCodec, FrameStreamParser, Layout, SizeRule, Transparency

dynamixel_p2 = pytest.importorskip("dynamixel_p2")

# Catalogue check values: the CRC of b"123456789" (reveng.sourceforge.io/crc-catalogue).
CATALOGUE = [
    ("CRC-8/MAXIM-DOW", (8, 0x31, 0x00, True, True, 0x00), 0xA1),
    ("CRC-16/UMTS", (16, 0x8005, 0x0000, False, False, 0x0000), 0xFEE8),
    ("CRC-16/MODBUS", (16, 0x8005, 0xFFFF, True, True, 0x0000), 0x4B37),
    ("CRC-16/XMODEM", (16, 0x1021, 0x0000, False, False, 0x0000), 0x31C3),
    ("CRC-16/IBM-3740", (16, 0x1021, 0xFFFF, False, False, 0x0000), 0x29B1),
    ("CRC-16/KERMIT", (16, 0x1021, 0x0000, True, True, 0x0000), 0x2189),
    ("CRC-16/ARC", (16, 0x8005, 0x0000, True, True, 0x0000), 0xBB3D),
    ("CRC-32/ISO-HDLC", (32, 0x04C11DB7, 0xFFFFFFFF, True, True, 0xFFFFFFFF), 0xCBF43926),
]


@pytest.mark.parametrize(("name", "params", "check"), CATALOGUE, ids=[c[0] for c in CATALOGUE])
def test_crc_catalogue_check_values(name: str, params: tuple[int, int, int, bool, bool, int], check: int) -> None:
    assert crc_function(*params)(b"123456789") == check, name


def bitwise_crc(width: int, poly: int, init: int, refin: bool, refout: bool, xorout: int, data: bytes) -> int:
    """The catalogue model's CRC one bit at a time: the reference the table-driven and word-wise forms must match."""
    top, mask = 1 << (width - 1), (1 << width) - 1
    register = init
    for byte in data:
        if refin:
            byte = int(f"{byte:08b}"[::-1], 2)
        register ^= byte << (width - 8)
        for _ in range(8):
            register = ((register << 1) ^ poly if register & top else register << 1) & mask
    if refout:
        register = int(f"{register:0{width}b}"[::-1], 2)
    return register ^ xorout


@pytest.mark.parametrize(("name", "params", "check"), CATALOGUE, ids=[c[0] for c in CATALOGUE])
@settings(max_examples=examples(30), deadline=None)
@given(data=st.binary(max_size=40) | st.binary(min_size=250, max_size=600))
def test_crc_of_any_length_matches_the_bitwise_model(
    name: str, params: tuple[int, int, int, bool, bool, int], check: int, data: bytes
) -> None:
    """Short data, odd lengths, and data past the 16-bit CRCs' precompiled word runs (256 bytes and more); each CRC
    fresh (a 16-bit one goes byte by byte at first) and after it has been fed enough to read two bytes per step."""
    assert bitwise_crc(*params, b"123456789") == check, name  # the reference itself
    assert crc_function(*params)(data) == bitwise_crc(*params, data), name
    assert _fed(params)(data) == bitwise_crc(*params, data), name


@functools.cache
def _fed(params: tuple[int, int, int, bool, bool, int]) -> Callable[[bytes], int]:
    """A CRC function that has been fed enough bytes to have switched to its word table (16-bit CRCs)."""
    function = crc_function(*params)
    function(bytes(crc_module._WORDS_AFTER))
    return function


def test_xor_and_sum_checksums() -> None:
    assert xor_function(8)(bytes([0x01, 0x02, 0x04, 0x08])) == 0x0F
    assert xor_function(16)(bytes([0x12, 0x34, 0x56])) == 0x1234 ^ 0x5600
    assert sum_function(8, True)(bytes([1, 2, 3])) == 0xF9


def frsky_sport_checksum(data: bytes) -> int:
    """FrSky S.Port's checksum as its firmware computes it (OpenTX/EdgeTX `sportCheckSum`): the carry folded back in
    at each byte, then 0xFF minus the sum."""
    crc = 0
    for byte in data:
        crc += byte
        crc += crc >> 8
        crc &= 0xFF
    return 0xFF - crc


@settings(max_examples=examples(200), deadline=None)
@given(st.binary(max_size=40) | st.lists(st.sampled_from([0x00, 0x01, 0xFE, 0xFF]), max_size=20).map(bytes))
def test_a_sum_with_end_around_carry_is_frsky_sports(data: bytes) -> None:
    assert sum_function(8, True, end_around_carry=True)(data) == frsky_sport_checksum(data)
    total = sum(data)  # a 16-bit one's complement sum: congruent modulo 0xFFFF, 0 only for zeros
    assert sum_function(16, False, end_around_carry=True)(data) == ((total - 1) % 0xFFFF + 1 if total else 0)


# --- DYNAMIXEL: stuffing through the generated package ----------------------------------------------------------

STUFF = bytes.fromhex("ff ff fd")


def reference_stuffing(data: bytes) -> bytes:
    """protocol2 §Packet Process, written out independently: after each FF FF FD, one more FD."""
    out = bytearray()
    for byte in data:
        out.append(byte)
        if bytes(out[-3:]) == STUFF:
            out.append(0xFD)
    return bytes(out)


def reference_write(servo: int, address: int, data: bytes) -> bytes:
    """A WRITE instruction packet built to the e-manual by hand: stuffing, then length, then CRC-16/UMTS."""
    body = reference_stuffing(bytes([0x03]) + address.to_bytes(2, "little") + data)
    head = bytes.fromhex("ff ff fd 00") + bytes([servo]) + (len(body) + 2).to_bytes(2, "little")
    crc = crc_function(16, 0x8005, 0, False, False, 0)(head + body)
    return head + body + crc.to_bytes(2, "little")


def test_stuffed_write_golden_frame() -> None:
    # goal_position -131073 is FF FF FD FF: sent as FF FF FD FD FF, the length counting the extra FD
    frame = bytes.fromhex("FF FF FD 00 01 0A 00 03 74 00 FF FF FD FD FF 23 E5")
    assert reference_write(1, 116, bytes.fromhex("ff ff fd ff")) == frame
    message = dynamixel_p2.decode(frame, "request")
    assert message == dynamixel_p2.WriteRequest(id=1, address=116, data=bytes.fromhex("ff ff fd ff"))
    assert dynamixel_p2.encode(message) == frame


def test_stuffed_status_golden_frame() -> None:
    # a READ of 4 bytes answered with FF FF FD 00 (present_position 0x00FDFFFF): the status packet is stuffed too
    body = reference_stuffing(bytes.fromhex("55 00 ff ff fd 00"))
    head = bytes.fromhex("ff ff fd 00 01") + (len(body) + 2).to_bytes(2, "little")
    frame = head + body + crc_function(16, 0x8005, 0, False, False, 0)(head + body).to_bytes(2, "little")
    assert body == bytes.fromhex("55 00 ff ff fd fd 00")
    reply = dynamixel_p2.decode(frame, "response")
    assert reply.to_fields() == {"id": 1, "error": {"alert": 0, "number": 0}, "data": "ff ff fd 00"}
    assert dynamixel_p2.encode(reply) == frame


def test_unstuffed_frame_is_refused() -> None:
    # what dynamixel_sdk 4.1.0 sends: FF FF FD in the parameters left unstuffed (erratum sdk_tx_stuffing)
    head = bytes.fromhex("ff ff fd 00 01 09 00 03 74 00 ff ff fd ff")
    frame = head + crc_function(16, 0x8005, 0, False, False, 0)(head).to_bytes(2, "little")
    with pytest.raises(DecodeError, match="stuffing"):
        dynamixel_p2.decode(frame, "request")


@settings(max_examples=examples(200), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.lists(st.sampled_from([STUFF, b"\xff", b"\xfd", b"\xff\xff", b"\x00", STUFF + b"\xfd"]), max_size=40),
    st.integers(0, 252),
    st.integers(0, 0xFFFF),
    st.data(),
)
def test_payloads_full_of_the_header_round_trip(
    pieces: list[bytes], servo: int, address: int, data: st.DataObject
) -> None:
    payload = b"".join(pieces)
    write = dynamixel_p2.WriteRequest(id=servo, address=address, data=payload)
    frame = dynamixel_p2.encode(write)
    assert frame == reference_write(servo, address, payload)
    # past the header, every FF FF FD before the CRC is a stuffed one: no second packet start inside
    body = frame[:-2]
    assert all(body[i + 3] == 0xFD for i in range(1, len(body) - 2) if body[i : i + 3] == STUFF)
    assert dynamixel_p2.decode(frame, "request") == write
    reply = dynamixel_p2.StatusResponse(id=servo, error=dynamixel_p2.ErrorBits(alert=0, number=0), data=payload)
    reply_frame = dynamixel_p2.encode(reply)
    assert dynamixel_p2.decode(reply_frame, "response") == reply
    # the stream parser, fed in random pieces with noise between the frames, finds both in order
    stream = b"\xff\xff\xfd" + frame + b"\x00\xff" + frame
    parser = dynamixel_p2.StreamParser("request")
    found = []
    position = 0
    while position < len(stream):
        step = data.draw(st.integers(1, 9))
        found += parser.feed(stream[position : position + step])
        position += step
    assert found == [write, write]


def test_reply_layout_is_chosen_by_the_request() -> None:
    # PING's reply and a 3-byte READ's reply are the same bytes: the request decides
    frame = bytes.fromhex("FF FF FD 00 01 07 00 55 00 06 04 26 65 5D")
    assert isinstance(dynamixel_p2.decode(frame, "response"), dynamixel_p2.StatusResponse)
    ping = dynamixel_p2.decode(frame, "response", dynamixel_p2.PingResponse)
    assert ping.to_fields()["model_number"] == 1030
    parser = dynamixel_p2.StreamParser("response")
    parser.expect(dynamixel_p2.PingResponse)
    assert parser.feed(frame) == [ping]


def test_status_bits_are_encoded_and_refused_out_of_range() -> None:
    reply = dynamixel_p2.StatusResponse(id=1, error=dynamixel_p2.ErrorBits(alert=1, number=7), data=b"")
    assert dynamixel_p2.encode(reply)[8] == 0x87
    with pytest.raises(EncodeError, match="error.number"):
        dynamixel_p2.encode(
            dynamixel_p2.StatusResponse(id=1, error=dynamixel_p2.ErrorBits(alert=0, number=200), data=b"")
        )


# --- VESC: two length forms, a trailer, a big-endian CRC --------------------------------------------------------

XMODEM = crc_function(16, 0x1021, 0, False, False, 0)


def vesc_layout(name: str, start: int, length_size: int) -> Layout:
    return Layout(
        name,
        (
            Element("start", "constant", 1, constant=bytes([start])),
            Element("length", "length", length_size, endian="big", span=(2, 3)),
            Element("command", "command", 1, maximum=255),
            Element("payload", "content"),
            Element("crc", "checksum", 2, endian="big", span=(2, 3), checksum=XMODEM),
            Element("end", "constant", 1, constant=b"\x03"),
        ),
    )


VESC = FrameCodec((vesc_layout("short", 2, 1), vesc_layout("long", 3, 2)), {4: (0, None), 30: (0, 0)})


def test_vesc_short_and_long_forms() -> None:
    alive = VESC.wrap(b"", 30, ())
    assert alive == bytes([0x02, 0x01, 30]) + XMODEM(bytes([30])).to_bytes(2, "big") + b"\x03"
    long_payload = bytes(range(256)) * 2
    frame = VESC.wrap(long_payload, 4, ())
    assert frame[:3] == bytes([0x03, 0x02, 0x01]) and frame[-1] == 0x03  # 513 bytes counted: 02 01 big-endian
    assert VESC.unwrap(frame).content == long_payload
    damaged = frame[:-3] + bytes([frame[-3] ^ 1]) + frame[-2:]
    with pytest.raises(ChecksumError):
        VESC.unwrap(damaged)
    parser = FrameStreamParser((VESC, lambda frame, expect: VESC.unwrap(frame)))  # type: ignore[arg-type,return-value]
    found = parser.feed(b"\x03\x02" + alive + b"\x99" + frame + alive)
    assert [u.code for u in found] == [30, 4, 30]  # type: ignore[attr-defined]


# --- Modbus RTU: no header, no length; sizes from the function and a byte count inside --------------------------

MODBUS_CRC = crc_function(16, 0x8005, 0xFFFF, True, True, 0)
MODBUS_LAYOUT = Layout(
    "response",
    (
        Element("address", "value", 1, minimum=1, maximum=247, also=0),
        Element("function", "command", 1, maximum=255),
        Element("data", "content"),
        Element("crc", "checksum", 2, span=(0, 2), checksum=MODBUS_CRC),
    ),
)
MODBUS_REQUESTS = FrameCodec((MODBUS_LAYOUT,), {3: (4, 4), 6: (4, 4)}, {3: SizeRule(4), 6: SizeRule(4)})
MODBUS_RESPONSES = FrameCodec((MODBUS_LAYOUT,), {3: (1, 251)}, {3: SizeRule(1, ((0, 1, "big", 1),))})


def test_modbus_golden_request_and_back_to_back_frames() -> None:
    frame = MODBUS_REQUESTS.wrap(bytes.fromhex("00 00 00 0a"), 3, (1,))
    assert frame == bytes.fromhex("01 03 00 00 00 0A C5 CD")  # the Modbus specification's example
    parser = FrameStreamParser((MODBUS_REQUESTS, lambda f, e: MODBUS_REQUESTS.unwrap(f)))  # type: ignore[arg-type,return-value]
    other = MODBUS_REQUESTS.wrap(bytes.fromhex("00 01 00 03"), 6, (17,))
    found = []
    stream = b"\xff" + frame + other + frame
    for byte in stream:  # one byte at a time
        found += parser.feed(bytes([byte]))
    assert [(u.code, u.values) for u in found] == [(3, (1,)), (6, (17,)), (3, (1,))]  # type: ignore[attr-defined]


def test_modbus_response_sized_by_its_byte_count() -> None:
    frame = MODBUS_RESPONSES.wrap(bytes.fromhex("04 00 0a 01 02"), 3, (1,))
    parser = FrameStreamParser((MODBUS_RESPONSES, lambda f, e: MODBUS_RESPONSES.unwrap(f)))  # type: ignore[arg-type,return-value]
    assert parser.feed(frame[:5]) == [] and parser.pending() == frame[:5]
    (found,) = parser.feed(frame[5:] + frame[:2])
    assert found.content == bytes.fromhex("04 00 0a 01 02")  # type: ignore[attr-defined]


# --- SLIP-style escaping: no length, a trailer, a checksum inside the escaped span -----------------------------

SLIP = Layout(
    "frame",
    (
        Element("command", "command", 1, maximum=255),
        Element("data", "content"),
        Element("fcs", "checksum", 1, span=(0, 1), checksum=sum_function(8, False)),
        Element("end", "constant", 1, constant=b"\xc0"),
    ),
    Transparency((0, 2), ((b"\xc0", b"\xdb\xdc"), (b"\xdb", b"\xdb\xdd"))),
)


@settings(max_examples=examples(100), deadline=None)
@given(st.binary(max_size=30), st.integers(0, 255))
def test_escaped_frames_round_trip(data: bytes, code: int) -> None:
    frame = SLIP.wrap(data, code, ())
    assert b"\xc0" not in frame[:-1]  # the end byte appears only at the end
    unwrapped = SLIP.unwrap(frame)
    assert (unwrapped.code, unwrapped.content) == (code, data)


def test_lone_escape_is_refused() -> None:
    with pytest.raises(DecodeError, match="stuffing"):
        SLIP.unwrap(b"\x01\xdb\x00\x01\xc0")


def test_monitor_pairs_requests_with_the_reply_layout_they_get() -> None:
    from serialspec.cli.frames import Frames

    frames = Frames(dynamixel_p2, None, "id")  # both directions in one stream, shared header: paired
    ping, reply = (
        bytes.fromhex("FF FF FD 00 01 03 00 01 19 4E"),
        bytes.fromhex("FF FF FD 00 01 07 00 55 00 06 04 26 65 5D"),
    )
    read = bytes.fromhex("FF FF FD 00 01 07 00 02 84 00 04 00 1D 15")
    status = bytes.fromhex("FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0")
    seen = frames.feed(ping + reply + read[:5]) + frames.feed(read[5:] + status)
    assert [type(s.message).__name__ for s in seen] == ["PingRequest", "PingResponse", "ReadRequest", "StatusResponse"]
