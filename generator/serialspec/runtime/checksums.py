"""Checksums, described by their parameters so the spec, not the code, says which one a protocol uses."""

from __future__ import annotations

import struct
from binascii import crc_hqx as crc_hqx  # re-exported: generated code calls it directly (crc_in_one_call)
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
    """A CRC function from catalogue parameters (width, poly, init, refin, refout, xorout), widths 8..32.

    The fastest form there is for the parameters: the standard library's C code where it computes the same CRC
    (binascii.crc_hqx: poly 0x1021, unreflected, 16 bits; zlib.crc32: poly 0x04C11DB7, reflected, 32 bits), two
    bytes per step for every other 16-bit CRC (`_crc16_words`), else a table-driven loop over the bytes.
    """
    mask = (1 << width) - 1
    if crc_in_one_call(width, poly, init, refin, refout, xorout) is not None:
        if not xorout:
            return lambda data: crc_hqx(data, init)
        return lambda data: crc_hqx(data, init) ^ xorout
    if width == 32 and poly == 0x04C11DB7 and refin and refout:
        from zlib import crc32  # imported here: a codec that does not need it does not pay for it

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


def crc_in_one_call(width: int, poly: int, init: int, refin: bool, refout: bool, xorout: int) -> str | None:
    """Generated code's expression of the CRC of `{}` where the standard library computes it in one C call
    (binascii.crc_hqx, exported here: poly 0x1021, unreflected, 16 bits), so a codec calls it with no Python
    function between; None for the others, which generated code calls through crc_function's result."""
    if width == 16 and poly == 0x1021 and not refin and not refout:
        call = f"_crc_hqx({{}}, {init:#x})"
        return f"({call} ^ {xorout:#x})" if xorout else call
    return None


# Runs of k 16-bit words (k < _WORD_RUNS) are read by precompiled structs, made at the first CRC's first call.
_WORD_RUNS = 128


@cache
def _unpack_words(order: str) -> tuple[Callable[[bytes], tuple[int, ...]], ...]:
    """unpack_from of a struct reading k words in this byte order, for each k < _WORD_RUNS."""
    return tuple(struct.Struct(f"{order}{k}H").unpack_from for k in range(_WORD_RUNS))


@cache
def _word_table(poly: int, refin: bool) -> tuple[int, ...]:
    """Entry x: the 16-bit register x after two zero bytes. Feeding bytes is linear (XOR) in the register, so entry
    x is the entry of its high byte's part XOR the entry of its low byte's: 65,536 XORs, about 2 ms."""
    table = crc_table(16, poly, refin)
    if refin:  # the low byte goes in first: entry (low) = table[low] >> 8 ^ table[table[low] & 0xFF]
        low = [(t >> 8) ^ table[t & 0xFF] for t in table]
        return tuple([h ^ entry for h in table for entry in low])  # entry (high << 8) is table[high]
    high = [((t << 8) & 0xFFFF) ^ table[t >> 8] for t in table]  # entry (high << 8); entry (low) is table[low]
    return tuple([h ^ entry for h in high for entry in table])


def _crc16_words(poly: int, init: int, refin: bool, refout: bool, xorout: int) -> Callable[[bytes], int]:
    """A 16-bit CRC two bytes per step: the register after two more bytes is table[register ^ those two bytes]
    (the bytes as one word, low byte first when reflected), from a 65,536-entry table made at the first call (a
    few milliseconds, not paid by an import, shared by every CRC of that polynomial); an odd last byte goes through
    the 256-entry table."""
    table = crc_table(16, poly, refin)
    order = "<" if refin else ">"
    unpack: tuple[Callable[[bytes], tuple[int, ...]], ...] = ()
    start = _reflect(init, 16) if refin else init
    pairs: tuple[int, ...] = ()
    plain = refin == refout and not xorout  # the register is the CRC
    longest = 2 * _WORD_RUNS  # bytes: longer data is read by a struct made for it

    def finish(value: int) -> int:
        return (_reflect(value, 16) if refin != refout else value) ^ xorout

    def crc(data: bytes) -> int:
        nonlocal pairs, unpack
        if not pairs:
            pairs, unpack = _word_table(poly, refin), _unpack_words(order)
        value = start
        n = len(data)
        for word in unpack[n >> 1](data) if n < longest else struct.unpack_from(f"{order}{n >> 1}H", data):
            value = pairs[value ^ word]
        if n & 1:  # the last byte alone, as in crc_function's byte loop
            last = data[-1]
            value = (
                (value >> 8) ^ table[(value ^ last) & 0xFF]
                if refin
                else (value & 0xFF) << 8 ^ table[(value >> 8) ^ last]
            )
        return value if plain else finish(value)

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
