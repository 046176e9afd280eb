"""Checksums, described by their parameters so the spec, not the code, says which one a protocol uses."""

from __future__ import annotations

from collections.abc import Callable
from functools import cache


def _reflect(value: int, width: int) -> int:
    result = 0
    for _ in range(width):
        result = (result << 1) | (value & 1)
        value >>= 1
    return result


@cache  # a table is computed once per CRC (generating a spec asks for its table many times)
def crc_table(width: int, poly: int, refin: bool) -> tuple[int, ...]:
    """The 256-entry table of a CRC in the Rocksoft/catalogue model (reflected table when refin)."""
    mask = (1 << width) - 1
    table = []
    for byte in range(256):
        if refin:
            crc = byte
            reflected_poly = _reflect(poly, width)
            for _ in range(8):
                crc = (crc >> 1) ^ reflected_poly if crc & 1 else crc >> 1
        else:
            crc = byte << (width - 8)
            top = 1 << (width - 1)
            for _ in range(8):
                crc = ((crc << 1) ^ poly) if crc & top else crc << 1
        table.append(crc & mask)
    return tuple(table)


def crc_function(width: int, poly: int, init: int, refin: bool, refout: bool, xorout: int) -> Callable[[bytes], int]:
    """A CRC function from catalogue parameters (width, poly, init, refin, refout, xorout), widths 8..32."""
    table = crc_table(width, poly, refin)
    mask = (1 << width) - 1
    if refin:
        start = _reflect(init, width)

        def crc(data: bytes) -> int:
            value = start
            for byte in data:
                value = table[(value ^ byte) & 0xFF] ^ (value >> 8)
            if not refout:
                value = _reflect(value, width)
            return (value ^ xorout) & mask

    else:
        shift = width - 8

        def crc(data: bytes) -> int:
            value = init
            for byte in data:
                value = table[((value >> shift) ^ byte) & 0xFF] ^ ((value << 8) & mask)
            if refout:
                value = _reflect(value, width)
            return (value ^ xorout) & mask

    return crc


def sum_function(width: int, invert: bool) -> Callable[[bytes], int]:
    """Sum of the bytes modulo 2**width, optionally bitwise inverted."""
    mask = (1 << width) - 1
    if invert:
        return lambda data: ~sum(data) & mask
    return lambda data: sum(data) & mask


def xor_function(width: int) -> Callable[[bytes], int]:
    """XOR of the bytes (width 8), or of the data taken as big-endian words of width / 8 bytes."""
    if width == 8:

        def xor8(data: bytes) -> int:
            value = 0
            for byte in data:
                value ^= byte
            return value

        return xor8
    size = width // 8

    def xor(data: bytes) -> int:
        value = 0
        padded = data + bytes(-len(data) % size)
        for i in range(0, len(padded), size):
            value ^= int.from_bytes(padded[i : i + size], "big")
        return value

    return xor


# Each byte value as a one-byte bytes object: appending a 1-byte checksum is an index, not a bytes((x,)) call.
BYTE_VALUES: tuple[bytes, ...] = tuple(bytes((value,)) for value in range(256))
