"""Field kinds that struct cannot pack alone: bits packed 8 to a byte, and text."""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

from serialspec.runtime.errors import DecodeError, EncodeError, shown
from serialspec.runtime.message import is_sequence


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
