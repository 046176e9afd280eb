"""Field kinds that struct cannot pack alone: bits packed 8 to a byte, packed integers of any width, and text."""

from __future__ import annotations

import struct
from collections.abc import Callable

from serialspec.encodings import seven_bit, varint
from serialspec.runtime.errors import DecodeError, EncodeError, out_of_range, shown
from serialspec.runtime.message import is_sequence

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any


def unpack_runs(fmt: str, most: int) -> tuple[Callable[[bytes, int], tuple[Any, ...]], ...]:
    """Entry k: unpack_from of a struct reading k items of `fmt` (a byte order and one item, as '>H'), for k up
    to `most`: a list whose count is known only at run time is read without making a format string and looking
    its struct up (about 100 ns a frame)."""
    return tuple(struct.Struct(f"{fmt[0]}{k}{fmt[1:]}").unpack_from for k in range(most + 1))


def unpack_bits(buf: bytes, offset: int, count: int) -> tuple[bool, ...]:
    """`count` bits from buf[offset:], 8 to a byte, the first in the lowest bit of the first byte."""
    return tuple(bool(buf[offset + (i >> 3)] >> (i & 7) & 1) for i in range(count))


def pack_bits(values: tuple[bool, ...] | list[bool], name: str, where: str) -> bytes:
    """Bits 8 to a byte, the first in the lowest bit; the last byte padded with zeros."""
    if not is_sequence(values):
        raise EncodeError(f"{where}: {name} must be a list of bits, got {shown(values)}")
    out = bytearray(-(-len(values) // 8))
    for i, value in enumerate(values):
        if not (value is True or value is False or (value.__class__ is int and value in (0, 1))):
            raise EncodeError(f"{where}: {name}[{i}] must be a bit (true/false or 0/1), got {shown(value)}")
        if value:
            out[i >> 3] |= 1 << (i & 7)
    return bytes(out)


def decode_text(data: bytes, name: str, where: str) -> str:
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise DecodeError(f"{where}: {name} is not UTF-8 text ({exc.reason} at byte {exc.start})") from None


def encode_text(value: str, name: str, where: str, terminated: bool) -> bytes:
    """UTF-8 text; NUL-terminated text may hold no NUL of its own."""
    if not isinstance(value, str):
        raise EncodeError(f"{where}: {name} must be text, got {shown(value)}")
    try:
        data = value.encode("utf-8")
    except UnicodeEncodeError as exc:
        raise EncodeError(f"{where}: {name} is not UTF-8 text ({exc.reason} at character {exc.start})") from None
    if terminated:
        if b"\0" in data:
            raise EncodeError(f"{where}: {name} holds a NUL, which would end it early")
        return data + b"\0"
    return data


def decode_seven_bit_text(data: bytes, name: str, where: str) -> str:
    """Text of 14-bit characters, two 7-bit bytes each, low first (`encoding: seven_bit` on a string)."""
    try:
        return seven_bit.text_of(data)
    except ValueError as exc:
        raise DecodeError(f"{where}: {name} is not text of 14-bit characters: {exc}") from None


def encode_seven_bit_text(value: str, name: str, where: str) -> bytes:
    """The wire bytes of text of 14-bit characters."""
    if not isinstance(value, str):
        raise EncodeError(f"{where}: {name} must be text, got {shown(value)}")
    try:
        return seven_bit.text_bytes(value)
    except ValueError as exc:
        raise EncodeError(f"{where}: {name}: {exc}") from None


def unpack_ints(data: bytes, bits: int, count: int, lsb_first: bool, signed: bool) -> tuple[int, ...]:
    """`count` integers of `bits` bits packed with no gaps in `data`: lsb_first, the first in the lowest bits of the
    first byte (the bytes a little-endian integer); else the first in the highest bits (a big-endian integer)."""
    whole = int.from_bytes(data, "little" if lsb_first else "big")
    mask = (1 << bits) - 1
    if lsb_first:
        values = [(whole >> (i * bits)) & mask for i in range(count)]
    else:
        top = len(data) * 8 - bits
        values = [(whole >> (top - i * bits)) & mask for i in range(count)]
    if signed:
        sign = 1 << (bits - 1)
        return tuple(v - (v & sign) * 2 for v in values)
    return tuple(values)


def pack_ints(values: Any, bits: int, count: int, lsb_first: bool) -> bytes:
    """The inverse of unpack_ints (the values checked already); unused bits of the last byte are 0."""
    mask = (1 << bits) - 1
    size = -(-bits * count // 8)
    whole = 0
    if lsb_first:
        for i, value in enumerate(values):
            whole |= (value & mask) << (i * bits)
        return whole.to_bytes(size, "little")
    top = size * 8 - bits
    for i, value in enumerate(values):
        whole |= (value & mask) << (top - i * bits)
    return whole.to_bytes(size, "big")


def unpad_text(data: bytes, pad: int, name: str, where: str) -> str:
    """Fixed-size text without the pad bytes after it."""
    return decode_text(data.rstrip(bytes((pad,))), name, where)


def pad_text(value: str, size: int, pad: int, name: str, where: str) -> bytes:
    """Text padded to `size` bytes with `pad`; longer text is refused, naming the field and the most it holds."""
    data = encode_text(value, name, where, False)
    if len(data) > size:
        raise EncodeError(f"{where}: {name} takes at most {size} bytes of UTF-8, got {len(data)}")
    return data + bytes((pad,)) * (size - len(data))


def read_varint(
    buf: bytes, at: int, end: int, form: tuple[int, bool, str, int], low: int, high: int, name: str, where: str
) -> tuple[int, int]:
    """(the value, the offset after it) of a varint field (`encoding: varint`); `form` is (bits a byte, highest
    group first, sign, most bytes)."""
    bits, high_first, sign, most = form
    try:
        number, stop = varint.read(buf, at, end, bits, high_first, most)
    except ValueError as exc:
        raise DecodeError(f"{where}: {name} is no varint: {exc}") from None
    value = varint.value_of(number, sign)
    if not low <= value <= high:
        raise DecodeError(f"{where}: {name} is {value}, outside its range {low}..{high}")
    return value, stop


def write_varint(value: int, form: tuple[int, bool, str, int], low: int, high: int, name: str, where: str) -> bytes:
    """The bytes of a varint field's value, refused outside its range or when no integer."""
    if value.__class__ is not int or not low <= value <= high:
        raise out_of_range(where, name, value, low, high)
    bits, high_first, sign, _ = form
    return varint.write(varint.wire(value, sign), bits, high_first)
