"""pymodbus from PyPI against ours, over real pseudo-terminals, both ways round:
its RTU client drives `serialspec sim specs/modbus_rtu.yaml`, and our client drives its RTU server.

The ports are opened without parity and with 2 stop bits (the serial line specification's alternative to even
parity): some kernels' pseudo-terminals refuse even parity (our client then says so with a PortError)."""

from __future__ import annotations

import asyncio
import threading
from collections.abc import Iterator
from typing import Any

import pytest
from pty_pair import pty_pair
from serialspec.runtime.errors import DeviceError
from serialspec_protocols.modbus_rtu import CoilState
from serialspec_protocols.modbus_rtu.client import ModbusRtuClient
from sim_process import serve

pymodbus = pytest.importorskip("pymodbus")
from pymodbus import FramerType  # noqa: E402
from pymodbus.client import ModbusSerialClient  # noqa: E402
from pymodbus.pdu import ExceptionResponse  # noqa: E402
from pymodbus.server import ModbusSerialServer  # noqa: E402
from pymodbus.simulator import DataType, SimData, SimDevice  # noqa: E402

LINE = {"baudrate": 19200, "parity": "N", "stopbits": 2}
TIMEOUT = 2.0  # generous: nothing here waits for it unless a test expects silence


# --- pymodbus's client against our virtual server ------------------------------------------------------------------


@pytest.fixture(scope="module")
def sim_port() -> Iterator[str]:
    with serve("modbus_rtu.yaml", 1, 2) as path:
        yield path


@pytest.fixture
def peer_client(sim_port: str) -> Iterator[Any]:
    client = ModbusSerialClient(sim_port, framer=FramerType.RTU, timeout=TIMEOUT, retries=0, **LINE)
    assert client.connect()
    yield client
    client.close()


def test_pymodbus_writes_and_reads_registers(peer_client: Any) -> None:
    assert not peer_client.write_registers(10, [1, 2, 0xFFFF], device_id=1).isError()
    reply = peer_client.read_holding_registers(9, count=5, device_id=1)
    assert reply.registers == [0, 1, 2, 0xFFFF, 0]
    assert not peer_client.write_register(10, 77, device_id=1).isError()
    assert peer_client.read_holding_registers(10, count=1, device_id=1).registers == [77]
    assert peer_client.read_holding_registers(10, count=1, device_id=2).registers == [0]  # another server


def test_pymodbus_writes_and_reads_coils(peer_client: Any) -> None:
    bits = [True, False, True, True, False, False, True, True, True, False, True]
    assert not peer_client.write_coils(100, bits, device_id=1).isError()
    assert peer_client.read_coils(100, count=11, device_id=1).bits[:11] == bits
    assert not peer_client.write_coil(200, True, device_id=1).isError()
    assert peer_client.read_coils(199, count=3, device_id=1).bits[:3] == [False, True, False]
    assert peer_client.read_discrete_inputs(0, count=8, device_id=1).bits == [False] * 8
    assert peer_client.read_input_registers(0, count=2, device_id=1).registers == [0, 0]


def test_pymodbus_mask_write_and_read_write(peer_client: Any) -> None:
    peer_client.write_register(4, 0x12, device_id=1)
    assert not peer_client.mask_write_register(address=4, and_mask=0xF2, or_mask=0x25, device_id=1).isError()
    assert peer_client.read_holding_registers(4, count=1, device_id=1).registers == [0x17]
    reply = peer_client.readwrite_registers(
        read_address=300, read_count=3, write_address=301, values=[5, 6], device_id=1
    )
    assert reply.registers == [0, 5, 6]


def test_pymodbus_gets_exceptions(peer_client: Any) -> None:
    beyond = peer_client.read_holding_registers(9998, count=5, device_id=1)
    assert isinstance(beyond, ExceptionResponse) and beyond.exception_code == 2
    coils = peer_client.write_coils(9999, [True, True], device_id=1)
    assert isinstance(coils, ExceptionResponse) and coils.exception_code == 2
    # pymodbus refuses to send an illegal quantity itself; test_modbus_rtu.py sends one (exception 3)
    identification = peer_client.read_device_information(device_id=1)  # function 0x2B: not in the spec
    assert isinstance(identification, ExceptionResponse) and identification.exception_code == 1


def test_pymodbus_broadcast_reaches_both_servers(peer_client: Any) -> None:
    peer_client.write_register(500, 4242, device_id=0, no_response_expected=True)
    assert peer_client.read_holding_registers(500, count=1, device_id=1).registers == [4242]
    assert peer_client.read_holding_registers(500, count=1, device_id=2).registers == [4242]


# --- our client against pymodbus's server --------------------------------------------------------------------------


class PeerServer:
    """pymodbus's RTU server for unit 17 on one end of a pty pair, in its own thread and event loop."""

    def __init__(self, path: str) -> None:
        self.device = SimDevice(
            17,
            simdata=(
                [SimData(0, values=[False] * 100, datatype=DataType.BITS)],
                [SimData(0, values=[i % 3 == 0 for i in range(100)], datatype=DataType.BITS)],
                [SimData(0, values=list(range(100)), datatype=DataType.REGISTERS)],
                [SimData(0, values=list(range(1000, 1100)), datatype=DataType.REGISTERS)],
            ),
        )
        self.path = path
        self.ready = threading.Event()
        self.loop: asyncio.AbstractEventLoop | None = None
        self.server: Any = None
        self.thread = threading.Thread(target=lambda: asyncio.run(self._main()), daemon=True)
        self.thread.start()
        assert self.ready.wait(10), "pymodbus's server did not start"

    async def _main(self) -> None:
        self.loop = asyncio.get_running_loop()
        self.server = ModbusSerialServer(
            [self.device], framer=FramerType.RTU, port=self.path, broadcast_enable=True, **LINE
        )
        listening = asyncio.ensure_future(self.server.serve_forever())
        await asyncio.sleep(0.2)  # it opens the port inside serve_forever
        self.ready.set()
        await listening

    def stop(self) -> None:
        assert self.loop is not None
        asyncio.run_coroutine_threadsafe(self.server.shutdown(), self.loop).result(10)
        self.thread.join(10)


@pytest.fixture(scope="module")
def ours() -> Iterator[ModbusRtuClient]:
    with pty_pair() as (server_path, client_path):
        server = PeerServer(server_path)
        try:
            with ModbusRtuClient(client_path, timeout=TIMEOUT, parity="N", stopbits=2) as client:
                yield client
        finally:
            server.stop()


def test_our_client_reads_pymodbus_registers(ours: ModbusRtuClient) -> None:
    assert ours.read_holding_registers(17, 5, 4) == [5, 6, 7, 8]
    assert ours.read_input_registers(17, 0, 3) == [1000, 1001, 1002]
    assert ours.read_discrete_inputs(17, 0, 7) == [True, False, False, True, False, False, True]


def test_our_client_writes_pymodbus_registers_and_coils(ours: ModbusRtuClient) -> None:
    assert ours.write_register(17, 20, 0xABCD) is True  # the echo came back
    assert ours.write_registers(17, 21, [1, 2, 3]) == 3
    assert ours.read_holding_registers(17, 20, 4) == [0xABCD, 1, 2, 3]
    ours.write_coils(17, 3, [True, True, False, True])
    ours.write_coil(17, 9, CoilState.ON)
    assert ours.read_coils(17, 0, 10) == [False, False, False, True, True, False, True, False, False, True]


def test_our_client_raises_pymodbus_exceptions(ours: ModbusRtuClient) -> None:
    # pymodbus 3.16's SimDevice answers an address it lacks, and a unit it does not serve, with exception 4
    # (a KeyError inside it; earlier versions answered 2 for the address)
    refused = r"exception_code = (illegal_data_address \(2\)|server_device_failure \(4\))"
    with pytest.raises(DeviceError, match=refused):
        ours.read_holding_registers(17, 200, 5)
    with pytest.raises(DeviceError, match=refused):
        ours.read_holding_registers(18, 0, 1)
    assert ours.read_holding_registers(17, 5, 1) == [5]  # and the bus goes on


def test_our_broadcast_reaches_pymodbus_and_waits_for_nothing(ours: ModbusRtuClient) -> None:
    assert ours.write_register(0, 30, 4321) is None  # broadcast: no reply is due
    assert ours.read_holding_registers(17, 30, 1) == [4321]
