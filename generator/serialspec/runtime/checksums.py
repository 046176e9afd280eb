"""Checksums, described by their parameters so the spec, not the code, says which one a protocol uses."""

from __future__ import annotations

import struct
from binascii import crc_hqx
from collections.abc import Callable
from zlib import crc32


def _reflect(value: int, width: int) -> int:
    result = 0
    for _ in range(width):
        result = (result << 1) | (value & 1)
        value >>= 1
    return result


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
    """A CRC function from catalogue parameters (width, poly, init, refin, refout, xorout), widths 8..32.

    The fastest form there is for the parameters: the standard library's C code where it computes the same CRC
    (binascii.crc_hqx: poly 0x1021, unreflected, 16 bits; zlib.crc32: poly 0x04C11DB7, reflected, 32 bits), two
    bytes per step for every other 16-bit CRC (`_crc16_words`), else a table-driven loop over the bytes.
    """
    mask = (1 << width) - 1
    if width == 16 and poly == 0x1021 and not refin and not refout:
        return lambda data: crc_hqx(data, init) ^ xorout
    if width == 32 and poly == 0x04C11DB7 and refin and refout:
        start = _reflect(init, width) ^ mask  # crc32 inverts the register before and after

        return lambda data: crc32(data, start) ^ mask ^ xorout
    if width == 16:
        return _crc16_words(poly, init, refin, refout, xorout)
    table = crc_table(width, poly, refin)
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


# Precompiled structs that read a run of k 16-bit words (k < _WORD_RUNS), in either byte order.
_WORD_RUNS = 128
_WORDS = {order: tuple(struct.Struct(f"{order}{k}H") for k in range(_WORD_RUNS)) for order in "<>"}


def _crc16_words(poly: int, init: int, refin: bool, refout: bool, xorout: int) -> Callable[[bytes], int]:
    """A 16-bit CRC two bytes per step: the register after two more bytes is table[register ^ those two bytes]
    (the bytes as one word, low byte first when reflected), from a 65,536-entry table made at the first call (a
    few milliseconds, not paid by an import); an odd last byte goes through the 256-entry table."""
    table = crc_table(16, poly, refin)
    order = "<" if refin else ">"
    words = _WORDS[order]
    start = _reflect(init, 16) if refin else init
    pairs: tuple[int, ...] = ()

    def word_table() -> tuple[int, ...]:
        # entry x: the register x after two zero bytes, one table step each
        if refin:  # x = high << 8 | low; the low byte goes first
            return tuple((t >> 8) ^ table[high ^ (t & 0xFF)] for high in range(256) for t in table)  # t: table[low]
        return tuple(((t << 8) & 0xFFFF) ^ table[(t >> 8) ^ low] for t in table for low in range(256))

    def crc(data: bytes) -> int:
        nonlocal pairs
        if not pairs:
            pairs = word_table()
        value = start
        n = len(data)
        run = n >> 1
        for word in words[run].unpack_from(data) if run < _WORD_RUNS else struct.unpack_from(f"{order}{run}H", data):
            value = pairs[value ^ word]
        if n & 1:
            if refin:
                value = (value >> 8) ^ table[(value ^ data[-1]) & 0xFF]
            else:
                value = ((value & 0xFF) << 8) ^ table[(value >> 8) ^ data[-1]]
        if refin != refout:
            value = _reflect(value, 16)
        return value ^ xorout

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
