"""minimalmodbus from PyPI (the most used Modbus RTU master after pymodbus), unchanged, against
`serialspec sim specs/modbus_rtu.yaml` over a real pseudo-terminal.

minimalmodbus checks every reply byte for byte (server address, function code, byte count, echoed address and
value, CRC) and raises its own exceptions otherwise, so each call below is also a check of our virtual server's
frames. The port is opened without parity and with 2 stop bits, as in test_interop_modbus.py: some kernels'
pseudo-terminals refuse even parity."""

from __future__ import annotations

from typing import Any

import pytest

minimalmodbus = pytest.importorskip("minimalmodbus")

TIMEOUT = 2.0  # generous: nothing here waits for it unless a test expects silence


def instrument(path: str, unit: int) -> Any:
    """A minimalmodbus Instrument for `unit` on the sim's port (minimalmodbus shares one port per path)."""
    device = minimalmodbus.Instrument(path, unit, mode=minimalmodbus.MODE_RTU)
    device.serial.baudrate = 19200
    device.serial.parity = "N"
    device.serial.stopbits = 2
    device.serial.timeout = TIMEOUT
    return device


SIM = ("modbus_rtu.yaml", 1, 2)  # the `port` fixture (conftest.py): `serialspec sim` on a pseudo-terminal


@pytest.fixture
def server(port: str) -> Any:
    return instrument(port, 1)


def test_single_registers(server: Any) -> None:
    server.write_register(10, 77)  # function 16 by default
    assert server.read_register(10) == 77
    server.write_register(11, 0xFFFF, functioncode=6)
    assert server.read_register(11) == 0xFFFF
    server.write_register(12, -2, signed=True, functioncode=6)
    assert server.read_register(12, signed=True) == -2
    assert server.read_register(12) == 0xFFFE
    server.write_register(13, 123.4, number_of_decimals=1)
    assert server.read_register(13) == 1234
    assert server.read_register(13, functioncode=4) == 0  # the input registers are another table


def test_many_registers(server: Any) -> None:
    server.write_registers(20, [1, 2, 3, 0xABCD])
    assert server.read_registers(19, 6) == [0, 1, 2, 3, 0xABCD, 0]
    server.write_registers(1000, list(range(123)))  # the most one request may write
    assert server.read_registers(1000, 125) == [*range(123), 0, 0]  # the most one request may read
    assert server.read_registers(9990, 10, functioncode=4) == [0] * 10


def test_bits(server: Any) -> None:
    server.write_bit(5, 1)  # Write Single Coil (FF 00)
    server.write_bit(6, 1, functioncode=15)  # Write Multiple Coils with one coil
    assert server.read_bit(5, functioncode=1) == 1
    server.write_bit(5, 0)
    assert server.read_bits(4, 4, functioncode=1) == [0, 0, 1, 0]
    bits = [1, 0, 1, 1, 0, 0, 1, 1, 1, 0, 1]
    server.write_bits(100, bits)
    assert server.read_bits(100, len(bits), functioncode=1) == bits
    assert server.read_bits(100, len(bits), functioncode=2) == [0] * len(bits)  # discrete inputs: untouched


def test_long_and_float_over_two_registers(server: Any) -> None:
    server.write_long(40, -123456, signed=True)
    assert server.read_long(40, signed=True) == -123456
    assert server.read_registers(40, 2) == [0xFFFE, 0x1DC0]  # big-endian, high word first
    server.write_long(42, 0x01020304, byteorder=minimalmodbus.BYTEORDER_LITTLE_SWAP)
    assert server.read_registers(42, 2) == [0x0304, 0x0102]
    server.write_float(50, 3.25)
    assert server.read_float(50) == 3.25
    assert server.read_registers(50, 2) == [0x4050, 0x0000]  # IEEE 754 single precision
    server.write_float(52, -1.5e300, number_of_registers=4)
    assert server.read_float(52, number_of_registers=4) == -1.5e300
    server.write_string(60, "serialspec", 5)
    assert server.read_string(60, 5) == "serialspec"


def test_exception_replies_raise_minimalmodbus_exceptions(server: Any) -> None:
    # minimalmodbus reads as many bytes as the normal reply would have, so it takes the 5-byte exception reply
    # when its timeout ends: a shorter timeout keeps this test short (the reply itself comes at once)
    server.serial.timeout = 1.0
    with pytest.raises(minimalmodbus.IllegalRequestError, match="illegal data address"):
        server.read_registers(9998, 5)  # beyond the 10,000 holding registers: exception 2
    with pytest.raises(minimalmodbus.IllegalRequestError, match="illegal data address"):
        server.write_bits(9999, [1, 1])
    with pytest.raises(minimalmodbus.IllegalRequestError, match="illegal data address"):
        server.read_register(10000, functioncode=4)
    server.write_registers(9998, [5, 6])  # the last two are there, and the bus goes on
    assert server.read_registers(9998, 2) == [5, 6]


def test_broadcast_write_gets_no_reply_and_reaches_every_server(port: str) -> None:
    everyone = instrument(port, 0)  # minimalmodbus sends to address 0 and reads no reply
    everyone.write_register(500, 4242)
    everyone.write_registers(501, [7, 8])
    everyone.write_bit(600, 1)
    for unit in (1, 2):
        server = instrument(port, unit)
        assert server.read_registers(500, 3) == [4242, 7, 8]
        assert server.read_bit(600, functioncode=1) == 1
    assert everyone.serial.in_waiting == 0  # nobody answered the broadcasts


def test_other_addresses_are_ignored(port: str) -> None:
    stranger = instrument(port, 3)  # the sim serves units 1 and 2 only
    stranger.serial.timeout = 0.3  # silence is expected: no need to wait the full timeout
    with pytest.raises(minimalmodbus.NoResponseError):
        stranger.read_register(0)
