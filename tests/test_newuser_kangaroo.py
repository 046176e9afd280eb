"""Dimension Engineering Kangaroo x2 packet serial (tests/specs/kangaroo.yaml), written from the user docs alone.
No PyPI peer (PyPI's `kangaroo*` packages are unrelated); the peer is Dimension Engineering's own Arduino library
(KangarooCRC, KangarooCommandWriter), whose rules this test implements to make the golden frames: its CRC's residue
over a whole packet is the library's KANGAROO_CRC_GOOD_VALUE (0x307E), so the frames are right.

Three gaps, closed:
1. The CRC runs over the LOW 7 BITS of each byte (`crc ^= byte & 0x7F`, then 7 shifts, reflected, polynomial 0x22F0
   reflected = 0x03D1, init and xorout 0x3FFF): `crc: {..., data_bits: 7}` now.
2. The 14-bit CRC is sent as two 7-bit bytes, low first: `encoding: seven_bit` on the checksum element now.
3. Numbers are bit-packed (the value shifted left with the sign in bit 0, then 6 bits a byte, bit 6 marking more):
   `encoding: varint, varint: {bits: 6, sign: low_bit}` reads them as numbers (test_bit_packed_numbers_as_numbers);
   the spec itself keeps a move's data as bytes, since a limit type and value may follow the number."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

import pytest
from serialspec.lang import load_protocol
from serialspec.runtime.errors import DecodeError

SPEC = Path(__file__).parent / "specs" / "kangaroo.yaml"


def kangaroo_crc(data: bytes) -> int:
    crc = 0x3FFF
    for byte in data:
        crc ^= byte & 0x7F
        for _ in range(7):
            crc = (crc >> 1) ^ 0x22F0 if crc & 1 else crc >> 1
    return crc ^ 0x3FFF


def packet(address: int, command: int, data: bytes) -> bytes:
    body = bytes([address, command, len(data)]) + data
    crc = kangaroo_crc(body)
    return body + bytes([crc & 0x7F, crc >> 7 & 0x7F])


def bit_packed(number: int) -> bytes:
    encoded = (-number << 1 | 1) if number < 0 else number << 1
    out = bytearray()
    while True:
        out.append(encoded & 0x3F | (0x40 if encoded >= 0x40 else 0))
        encoded >>= 6
        if not encoded:
            return bytes(out)


def byte_wise_crc14(data: bytes) -> int:
    """What the spec's catalogue parameters compute (8 bits a byte), for the record."""
    crc = 0x3FFF
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = (crc >> 1) ^ 0x22F0 if crc & 1 else crc >> 1
    return crc ^ 0x3FFF


def test_the_librarys_rules() -> None:
    start = packet(128, 0x20, b"1\x00")
    assert start == bytes.fromhex("80 20 02 31 00 22 44")
    assert kangaroo_crc(start) == 0x307E  # KANGAROO_CRC_GOOD_VALUE: the residue of a good packet
    assert bit_packed(1000) == bytes.fromhex("50 1f") and bit_packed(-1) == bytes.fromhex("03")
    assert byte_wise_crc14(start[:-2]) != kangaroo_crc(start[:-2])  # gap 1: no byte-wise CRC gives it


@pytest.fixture(scope="module")
def kangaroo(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    from conftest import generate_afresh

    return generate_afresh(SPEC, tmp_path_factory, "kangaroo")


@pytest.mark.parametrize(
    ("frame", "name", "fields"),
    [
        (packet(128, 0x20, b"1\x00"), "StartRequest", {"address": 128, "channel": ord("1"), "flags": 0}),
        (
            packet(129, 0x24, b"2\x00\x01" + bit_packed(1000)),
            "MoveRequest",
            {"address": 129, "channel": ord("2"), "flags": 0, "motion": 1, "values": bit_packed(1000)},
        ),
        (
            packet(135, 0x24, b"D\x00\x02" + bit_packed(-1)),
            "MoveRequest",
            {"address": 135, "channel": ord("D"), "flags": 0, "motion": 2, "values": bit_packed(-1)},
        ),
        (
            packet(128, 0x23, b"1\x00\x01"),
            "StatusRequest",
            {"address": 128, "channel": ord("1"), "flags": 0, "query": 1},
        ),
    ],
)
def test_the_librarys_packets_decode_and_re_encode(
    kangaroo: ModuleType, frame: bytes, name: str, fields: dict[str, object]
) -> None:
    message = kangaroo.decode(frame, kangaroo.Direction.REQUEST)
    assert message == getattr(kangaroo, name)(**fields)
    assert kangaroo.encode(message) == frame


def test_a_reply_decodes_and_a_bad_crc_or_a_high_bit_is_refused(kangaroo: ModuleType) -> None:
    from serialspec.runtime.errors import ChecksumError

    frame = packet(128, 0x43, b"1\x00\x01" + bit_packed(-1))
    reply = kangaroo.decode(frame, kangaroo.Direction.RESPONSE)
    assert (reply.address, reply.channel, reply.query, reply.value) == (128, ord("1"), 1, bit_packed(-1))
    assert kangaroo.encode(reply) == frame
    for bad in (frame[:-1] + bytes([frame[-1] ^ 0x01]), frame[:-1] + bytes([frame[-1] | 0x80])):
        with pytest.raises(ChecksumError):
            kangaroo.decode(bad, kangaroo.Direction.RESPONSE)


def test_the_stream_parser_finds_packets_among_noise(kangaroo: ModuleType) -> None:
    frames = [packet(128, 0x20, b"1\x00"), packet(130, 0x24, b"T\x00\x02" + bit_packed(-300))]
    parser = kangaroo.StreamParser(kangaroo.Direction.REQUEST)
    got = []
    for byte in b"\x7f\x01" + frames[0] + b"\x00" + frames[1]:
        got += parser.feed(bytes([byte]))
    assert [kangaroo.encode(m) for m in got] == frames


BIT_PACKED = "{type: i32, encoding: varint, varint: {bits: 6, sign: low_bit},"


def test_bit_packed_numbers_as_numbers(tmp_path: Path) -> None:
    """Gap 3, closed: `encoding: varint` with 6 bits a byte and the sign in bit 0 reads the library's bit-packed
    numbers as numbers and writes them byte for byte (the spec keeps bytes: a move's data may go on with a limit)."""
    from serialspec.backends import emitters
    from serialspec.backends.python.memory import imported

    text = SPEC.read_text("utf-8").replace("values: {type: bytes, size: rest,", "values: " + BIT_PACKED)
    text = text.replace("value: {type: bytes, size: rest,", "value: " + BIT_PACKED).replace('"50 1f"', "1000")
    path = tmp_path / "kangaroo.yaml"
    path.write_text(text, "utf-8")
    protocol = load_protocol(path)
    python = next(e for e in emitters() if e.name == "python")
    files = {path.split("/", 1)[1]: code for path, code in python.files(protocol).items() if path.count("/") == 1}
    with imported("kangaroo", files, "the Kangaroo varint test") as k:
        for number in (0, 1, -1, 31, 32, -32, 1000, -300, 4095, 2**31 - 1, -(2**31)):
            frame = packet(129, 0x24, b"2\x00\x01" + bit_packed(number))
            message = k.decode(frame, k.Direction.REQUEST)
            assert message == k.MoveRequest(address=129, channel=ord("2"), flags=0, motion=1, values=number)
            assert k.encode(message) == frame
        reply = k.decode(packet(128, 0x43, b"1\x00\x01" + bit_packed(-1)), k.Direction.RESPONSE)
        assert reply.value == -1
        too_long = packet(128, 0x43, b"1\x00\x01" + b"\x40" * 6)  # a 7th byte to come: more than an i32 takes
        with pytest.raises(DecodeError, match="more than 6 bytes"):
            k.decode(too_long, k.Direction.RESPONSE)
        with pytest.raises(DecodeError, match="expected 4..9"):  # longer contents are refused by their size
            k.decode(packet(128, 0x43, b"1\x00\x01" + b"\x40" * 6 + b"\x00"), k.Direction.RESPONSE)
        with pytest.raises(DecodeError, match="bits above bit 6"):
            k.decode(packet(128, 0x43, b"1\x00\x01\x80"), k.Direction.RESPONSE)


@pytest.mark.parametrize(
    ("old", "new", "said"),
    [
        ("check: 0x1D66, data_bits: 7", "check: 0x1D66", "these parameters give 0x2669 for '123456789'"),
        ("      encoding: seven_bit\n", "", "a 14-bit CRC does not fill a u16"),
        ("width: 14,", "width: 16,", "a 16-bit CRC does not fill the 14 bits of a u16 sent 7 bits a byte"),
        ("data_bits: 7", "data_bits: 9", "data_bits: 9 is outside 1..8"),
        ("{role: length, type: u8}", "{role: length, type: u8, encoding: seven_bit}", "`encoding` belongs to a chec"),
    ],
)
def test_a_mistake_is_one_line(tmp_path: Path, old: str, new: str, said: str) -> None:
    from conftest import spec_error

    text = SPEC.read_text("utf-8")
    assert old in text
    assert said in spec_error(text.replace(old, new), tmp_path)


def test_fletcher_is_not_sent_seven_bits_a_byte(tmp_path: Path) -> None:
    from conftest import spec_error

    text = SPEC.read_text("utf-8")
    start, end = text.index("      algorithm: crc\n"), text.index("      covers:")
    text = text[:start] + "      algorithm: fletcher\n" + text[end:]
    assert "whole bytes: not 7 bits a byte" in spec_error(text, tmp_path)
