"""Modbus ASCII: two masters from PyPI, unchanged, drive `serialspec sim specs/modbus_ascii.yaml` over a real
pseudo-terminal: minimalmodbus (MODE_ASCII) and pymodbus (its ASCII framer). Both check every reply (the ':' and
CR LF, the hex digits, the LRC, the echoed fields) and raise otherwise, so each call is also a check of our virtual
server's frames; the stream parser and the codec of `method: hex_ascii` read theirs.

The ports are opened as in test_interop_modbus.py (no parity, 2 stop bits): some kernels' pseudo-terminals refuse
even parity."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from serialspec.runtime.errors import DeviceError
from serialspec_protocols.modbus_ascii import CoilState
from serialspec_protocols.modbus_ascii.client import ModbusAsciiClient
from sim_process import serve

minimalmodbus = pytest.importorskip("minimalmodbus")
pymodbus = pytest.importorskip("pymodbus")
from pymodbus import FramerType  # noqa: E402
from pymodbus.client import ModbusSerialClient  # noqa: E402
from pymodbus.pdu import ExceptionResponse  # noqa: E402

LINE = {"baudrate": 19200, "bytesize": 8, "parity": "N", "stopbits": 2}  # 8 bits: pseudo-terminals refuse 7
TIMEOUT = 2.0  # generous: nothing here waits for it unless a test expects silence


@pytest.fixture(scope="module")
def sim_port() -> Iterator[str]:
    with serve("modbus_ascii.yaml", 1, 2) as path:
        yield path


# --- minimalmodbus, MODE_ASCII -------------------------------------------------------------------------------------


def instrument(path: str, unit: int) -> Any:
    device = minimalmodbus.Instrument(path, unit, mode=minimalmodbus.MODE_ASCII)
    device.serial.apply_settings(LINE)
    device.serial.timeout = TIMEOUT
    return device


def test_minimalmodbus_registers(sim_port: str) -> None:
    server = instrument(sim_port, 1)
    server.write_register(10, 77)  # function 16 by default
    assert server.read_register(10) == 77
    server.write_register(11, 0xFFFF, functioncode=6)
    assert server.read_register(11) == 0xFFFF
    server.write_registers(20, [1, 2, 3, 0xABCD])
    assert server.read_registers(19, 6) == [0, 1, 2, 3, 0xABCD, 0]
    server.write_registers(1000, list(range(123)))  # the most one request may write: the longest ASCII frames
    assert server.read_registers(1000, 125) == [*range(123), 0, 0]
    assert server.read_registers(0, 3, functioncode=4) == [0, 0, 0]  # input registers, another table
    server.write_long(30, 0x12345678)
    assert server.read_long(30) == 0x12345678
    assert instrument(sim_port, 2).read_register(10) == 0  # the other server has its own tables


def test_minimalmodbus_bits(sim_port: str) -> None:
    server = instrument(sim_port, 1)
    server.write_bit(5, 1)  # Write Single Coil (FF 00)
    assert server.read_bit(5, functioncode=1) == 1
    server.write_bits(40, [1, 0, 1, 1, 0, 0, 1, 1, 1, 0])
    assert server.read_bits(39, 12, functioncode=1) == [0, 1, 0, 1, 1, 0, 0, 1, 1, 1, 0, 0]
    assert server.read_bits(0, 8, functioncode=2) == [0] * 8  # discrete inputs


def test_minimalmodbus_gets_exceptions(sim_port: str) -> None:
    server = instrument(sim_port, 1)
    with pytest.raises(minimalmodbus.IllegalRequestError):  # exception 2: beyond the 10,000 registers
        server.read_registers(9998, 5)
    with pytest.raises(minimalmodbus.IllegalRequestError):
        server.write_bit(10000, 1)
    server.write_register(10, 78)
    assert server.read_register(10) == 78  # the server still answers


# --- pymodbus, ASCII framer ---------------------------------------------------------------------------------------


@pytest.fixture
def peer_client(sim_port: str) -> Iterator[Any]:
    client = ModbusSerialClient(sim_port, framer=FramerType.ASCII, timeout=TIMEOUT, retries=0, **LINE)
    assert client.connect()
    yield client
    client.close()


def test_pymodbus_writes_and_reads_registers(peer_client: Any) -> None:
    assert not peer_client.write_registers(110, [1, 2, 0xFFFF], device_id=1).isError()
    reply = peer_client.read_holding_registers(109, count=5, device_id=1)
    assert reply.registers == [0, 1, 2, 0xFFFF, 0]
    assert not peer_client.write_register(110, 77, device_id=1).isError()
    assert peer_client.read_holding_registers(110, count=1, device_id=1).registers == [77]
    assert peer_client.read_holding_registers(110, count=1, device_id=2).registers == [0]  # another server
    assert peer_client.read_input_registers(0, count=2, device_id=1).registers == [0, 0]


def test_pymodbus_writes_and_reads_coils(peer_client: Any) -> None:
    bits = [True, False, True, True, False, False, True, True, True, False, True]
    assert not peer_client.write_coils(100, bits, device_id=1).isError()
    assert peer_client.read_coils(100, count=11, device_id=1).bits[:11] == bits
    assert not peer_client.write_coil(200, True, device_id=1).isError()
    assert peer_client.read_coils(199, count=3, device_id=1).bits[:3] == [False, True, False]
    assert peer_client.read_discrete_inputs(0, count=8, device_id=1).bits == [False] * 8


def test_pymodbus_mask_write_and_read_write(peer_client: Any) -> None:
    peer_client.write_register(4, 0x12, device_id=1)
    assert not peer_client.mask_write_register(address=4, and_mask=0xF2, or_mask=0x25, device_id=1).isError()
    assert peer_client.read_holding_registers(4, count=1, device_id=1).registers == [0x17]
    reply = peer_client.readwrite_registers(
        read_address=300, read_count=3, write_address=301, values=[5, 6], device_id=1
    )
    assert reply.registers == [0, 5, 6]


def test_pymodbus_gets_exceptions(peer_client: Any) -> None:
    # its own register: under xdist another process may have run the test that wrote 110 (a sim each)
    assert not peer_client.write_register(111, 78, device_id=1).isError()
    beyond = peer_client.read_holding_registers(9998, count=5, device_id=1)
    assert isinstance(beyond, ExceptionResponse) and beyond.exception_code == 2
    coil = peer_client.read_coils(10000, count=1, device_id=1)
    assert isinstance(coil, ExceptionResponse) and coil.exception_code == 2
    assert peer_client.read_holding_registers(111, count=1, device_id=1).registers == [78]  # still answering


# --- our generated client against the same server ---------------------------------------------------------------


def test_our_client_over_the_pty(sim_port: str) -> None:
    with ModbusAsciiClient(sim_port, timeout=TIMEOUT, **LINE) as client:
        assert client.write_registers(1, 500, (7, 8, 9)) == 3
        assert client.read_holding_registers(1, 499, 5) == [0, 7, 8, 9, 0]
        client.write_coil(1, 600, CoilState.ON)
        assert client.read_coils(1, 600, 1) == [True]
        with pytest.raises(DeviceError):
            client.read_holding_registers(1, 9999, 2)
