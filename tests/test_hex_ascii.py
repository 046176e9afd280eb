"""The hex-ASCII span encoding (Modbus ASCII), checked against minimalmodbus's own hex helpers."""

from __future__ import annotations

import minimalmodbus
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import DecodeError
from serialspec.transforms.hexascii import HexAscii

SPAN = HexAscii((1, 4))


@given(st.binary(max_size=300))
@settings(max_examples=200, deadline=None)
def test_encode_is_minimalmodbus_hexencode_and_decode_reverses_it(data: bytes) -> None:
    wire = SPAN.encode(data)
    assert wire == minimalmodbus._hexencode(data)
    assert len(wire) == 2 * len(data)
    assert SPAN.decode(wire) == data
    assert SPAN.decode(wire.lower()) == data  # a receiver accepts either case


def test_read_holding_registers_request_of_the_modbus_guide() -> None:
    """MODBUS over Serial Line §2.5.2: unit 1, function 3, address 0, 1 register, LRC FB."""
    assert SPAN.encode(bytes.fromhex("01 03 00 00 00 01 FB")) == b"010300000001FB"


@pytest.mark.parametrize(
    ("wire", "reason"),
    [
        (b"0G", "hex-ASCII: byte 47 at 1 is not a hex digit"),
        (b":01", "hex-ASCII: byte 3A at 0 is not a hex digit"),
        (b"010", "hex-ASCII: 3 hex digits, not whole bytes (an odd count)"),
        (b"01\r\n", "hex-ASCII: byte 0D at 2 is not a hex digit"),
    ],
)
def test_bad_spans_get_one_line_reasons(wire: bytes, reason: str) -> None:
    with pytest.raises(DecodeError) as error:
        SPAN.decode(wire)
    assert str(error.value) == reason
