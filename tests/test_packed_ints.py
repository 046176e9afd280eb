"""Packed integers of any width (`of: u11`): the runtime against a bit-by-bit reference and a CRSF frame."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st
from serialspec.runtime.packing import pack_ints, unpack_ints

# CRSF RC_CHANNELS_PACKED payload with every channel at 992 (the centre), as the CRSF documentation gives it.
CRSF_CENTRE = bytes.fromhex("E0 03 1F F8 C0 07 3E F0 81 0F 7C E0 03 1F F8 C0 07 3E F0 81 0F 7C")


def reference(data: bytes, bits: int, count: int, lsb_first: bool, signed: bool) -> list[int]:
    """Bit by bit: the stream's bits in wire order (each byte lowest bit first, or highest first), items in turn."""
    stream = [(byte >> (k if lsb_first else 7 - k)) & 1 for byte in data for k in range(8)]
    values = []
    for i in range(count):
        item = stream[i * bits : (i + 1) * bits]
        value = sum(b << (j if lsb_first else bits - 1 - j) for j, b in enumerate(item))
        values.append(value - (1 << bits) if signed and value >> (bits - 1) else value)
    return values


@st.composite
def packed(draw: st.DrawFn) -> tuple[int, int, bool, bool, list[int]]:
    bits = draw(st.integers(1, 64))
    count = draw(st.integers(1, 20))
    signed = draw(st.booleans())
    low, high = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
    return (
        bits,
        count,
        draw(st.booleans()),
        signed,
        draw(st.lists(st.integers(low, high), min_size=count, max_size=count)),
    )


@given(packed())
def test_packing_is_what_the_bit_by_bit_reference_reads(case: tuple[int, int, bool, bool, list[int]]) -> None:
    bits, count, lsb_first, signed, values = case
    data = pack_ints(values, bits, count, lsb_first)
    assert len(data) == -(-bits * count // 8)
    assert reference(data, bits, count, lsb_first, signed) == values
    assert list(unpack_ints(data, bits, count, lsb_first, signed)) == values


def test_crsf_channels_and_24_bit_integers() -> None:
    assert unpack_ints(CRSF_CENTRE, 11, 16, True, False) == (992,) * 16
    assert pack_ints([992] * 16, 11, 16, True) == CRSF_CENTRE
    # u24 items lowest bit first are little-endian 3-byte integers; highest bit first, big-endian ones
    assert unpack_ints(bytes.fromhex("01 02 03 ff ff ff"), 24, 2, True, True) == (0x030201, -1)
    assert unpack_ints(bytes.fromhex("01 02 03 ff ff fe"), 24, 2, False, False) == (0x010203, 0xFFFFFE)
