"""uModbus from PyPI (a pure-Python Modbus library), unchanged, its RTU client against
`serialspec sim specs/modbus_rtu.yaml` over a real pseudo-terminal.

uModbus builds each request ADU itself, reads exactly as many reply bytes as the request calls for (5 for an
exception reply), checks the CRC and raises its own exception for an exception code. The port is opened without
parity and with 2 stop bits, as in test_interop_modbus.py: some kernels' pseudo-terminals refuse even parity."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
import serial
from sim_process import serve

pytest.importorskip("umodbus")
from umodbus.client.serial import rtu  # noqa: E402
from umodbus.exceptions import IllegalDataAddressError, IllegalDataValueError  # noqa: E402

TIMEOUT = 2.0  # generous: nothing here waits for it


@pytest.fixture(scope="module")
def port() -> Iterator[serial.Serial]:
    with (
        serve("modbus_rtu.yaml", 1, 2) as path,
        serial.Serial(path, 19200, parity=serial.PARITY_NONE, stopbits=2, timeout=TIMEOUT) as opened,
    ):
        yield opened


def call(port: serial.Serial, adu: bytes) -> Any:
    """Send one request ADU the way uModbus's documentation does, and return what it parsed from the reply."""
    return rtu.send_message(adu, port)


def test_registers(port: serial.Serial) -> None:
    assert call(port, rtu.write_multiple_registers(1, 10, [1, 2, 0xFFFF])) == 3
    assert call(port, rtu.read_holding_registers(1, 9, 5)) == [0, 1, 2, 0xFFFF, 0]
    assert call(port, rtu.write_single_register(1, 10, 77)) == 77
    assert call(port, rtu.read_holding_registers(1, 10, 1)) == [77]
    assert call(port, rtu.read_holding_registers(2, 10, 1)) == [0]  # another server
    assert call(port, rtu.read_input_registers(1, 0, 3)) == [0, 0, 0]


def test_coils_and_inputs(port: serial.Serial) -> None:
    bits = [1, 0, 1, 1, 0, 0, 1, 1, 1, 0, 1]
    assert call(port, rtu.write_multiple_coils(1, 100, bits)) == len(bits)
    assert call(port, rtu.read_coils(1, 100, len(bits))) == bits
    assert call(port, rtu.write_single_coil(1, 200, 1)) == 1
    assert call(port, rtu.read_coils(1, 199, 3)) == [0, 1, 0]
    assert call(port, rtu.write_single_coil(1, 200, 0)) == 0
    assert call(port, rtu.read_discrete_inputs(1, 0, 9)) == [0] * 9


def test_exception_replies_raise_umodbus_errors(port: serial.Serial) -> None:
    with pytest.raises(IllegalDataAddressError):
        call(port, rtu.read_holding_registers(1, 9998, 5))  # beyond the 10,000 registers: exception 2
    with pytest.raises(IllegalDataAddressError):
        call(port, rtu.write_multiple_coils(1, 9999, [1, 1]))
    # uModbus refuses to build a bad coil value itself: this frame is built by hand, with uModbus's CRC
    request = bytes([1, 5, 0, 200, 0x12, 0x34])
    with pytest.raises(IllegalDataValueError):
        call(port, request + rtu.get_crc(request))  # neither FF 00 nor 00 00: exception 3
    assert call(port, rtu.read_holding_registers(1, 9998, 2)) == [0, 0]  # and the bus goes on
