"""decode()'s whole-frame decoders: frames picked by their first bytes and decoded in one function must be refused
exactly as the general path refuses them (the whole-frame decoder returns None, and the general path says why)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st
from serialspec.runtime.errors import ChecksumError, DecodeError
from serialspec.runtime.message import Direction
from serialspec_protocols import feetech_sms as sms
from serialspec_protocols import hiwonder_rrc as rrc


@given(st.binary(max_size=40), st.integers(0, 253), st.integers(0, 255))
def test_a_frame_taking_the_rest_decodes_at_any_size(data: bytes, ident: int, address: int) -> None:
    message = sms.WriteRequest(id=ident, address=address, data=data)
    frame = sms.encode(message)
    assert sms.decode(frame, Direction.REQUEST) == message == sms.decode(frame, "request")
    damaged = frame[:-1] + bytes([frame[-1] ^ 0x80])
    with pytest.raises(ChecksumError):
        sms.decode(damaged, Direction.REQUEST)


def test_a_length_byte_that_disagrees_with_the_frame_is_refused_by_the_general_path() -> None:
    frame = bytearray(sms.encode(sms.WriteRequest(id=1, address=42, data=b"\x01\x02\x03")))
    frame[3] += 1  # the length byte says one byte more than the frame holds
    frame[-1] = ~sum(frame[2:-1]) & 0xFF  # with a checksum that fits
    with pytest.raises(DecodeError, match="length says"):
        sms.decode(bytes(frame), Direction.REQUEST)


def test_a_sub_command_no_frame_of_that_size_has_is_refused_by_the_general_path() -> None:
    frame = bytearray(rrc.encode(rrc.BusServoReadPositionResponse(servo_id=1, success=0, position=300)))
    assert rrc.decode(bytes(frame), Direction.RESPONSE) == rrc.decode(bytes(frame), "response")
    frame[5] = 0x7E  # a sub-command code that no bus_servo response has
    crc = 0
    for byte in frame[2:-1]:  # CRC-8/MAXIM, reflected poly 0x8C
        crc ^= byte
        for _ in range(8):
            crc = (crc >> 1) ^ 0x8C if crc & 1 else crc >> 1
    frame[-1] = crc
    with pytest.raises(DecodeError, match="unknown sub-command 0x7e"):
        rrc.decode(bytes(frame), Direction.RESPONSE)
