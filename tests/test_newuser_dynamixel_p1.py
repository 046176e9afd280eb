"""DYNAMIXEL Protocol 1.0 (tests/specs/dynamixel_p1.yaml), written from the user docs alone and checked against
ROBOTIS's dynamixel-sdk (PacketHandler(1.0)): the SDK's packets are our golden frames and decode to its values, our
encoder writes them byte for byte, and the SDK drives `serialspec sim` over a pseudo-terminal (ping, reads and writes,
REG WRITE + ACTION, SYNC WRITE), as does the generated client."""

from __future__ import annotations

import importlib
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from conftest import generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from sim_process import serve

dxl = pytest.importorskip("dynamixel_sdk")

SPEC = Path(__file__).parent / "specs" / "dynamixel_p1.yaml"
SUCCESS = dxl.COMM_SUCCESS


@pytest.fixture(scope="module")
def d1(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("dynamixel_p1"), "dynamixel_p1")


class Recorder:
    """A stand-in for the SDK's PortHandler that keeps what the SDK writes and answers nothing."""

    def __init__(self) -> None:
        self.written = b""
        self.is_using = False
        self.baudrate = 1000000

    def clearPort(self) -> None:  # noqa: N802 - the SDK's names
        pass

    def writePort(self, packet: list[int]) -> int:  # noqa: N802
        self.written += bytes(packet)
        return len(packet)

    def setPacketTimeout(self, length: int) -> None:  # noqa: N802
        pass

    def readPort(self, length: int) -> list[int]:  # noqa: N802
        return []

    def isPacketTimeout(self) -> bool:  # noqa: N802
        return True


def sdk_packet(send: Any) -> bytes:
    port = Recorder()
    send(dxl.PacketHandler(1.0), port)
    return port.written


def test_the_sdks_requests_decode_and_re_encode(d1: ModuleType) -> None:
    cases = [
        (lambda p, port: p.ping(port, 1), d1.PingRequest(id=1)),
        (lambda p, port: p.readTxRx(port, 3, 36, 2), d1.ReadRequest(id=3, address=36, length=2)),
        (lambda p, port: p.write2ByteTxRx(port, 7, 30, 512), d1.WriteRequest(id=7, address=30, data=b"\x00\x02")),
        (lambda p, port: p.writeTxOnly(port, 1, 24, 1, [1]), d1.WriteRequest(id=1, address=24, data=b"\x01")),
        (
            lambda p, port: p.regWriteTxRx(port, 2, 30, 2, [0xFF, 0x03]),
            d1.RegWriteRequest(id=2, address=30, data=b"\xff\x03"),
        ),
        (lambda p, port: p.action(port, 254), d1.ActionRequest(id=254)),
        (lambda p, port: p.factoryReset(port, 1), d1.FactoryResetRequest(id=1)),
    ]
    for send, message in cases:
        golden = sdk_packet(send)
        assert d1.decode(golden, d1.Direction.REQUEST) == message, golden.hex(" ")
        assert d1.encode(message) == golden


def test_the_sdks_sync_write_decodes_and_re_encodes(d1: ModuleType) -> None:
    param = [1, 0x00, 0x02, 2, 0xFF, 0x03]
    golden = sdk_packet(lambda p, port: p.syncWriteTxOnly(port, 30, 2, param, len(param)))
    message = d1.decode(golden, d1.Direction.REQUEST)
    assert message.address == 30  # the length is derived from the items' data: no field of the message
    assert [(s.id, s.data) for s in message.servos] == [(1, b"\x00\x02"), (2, b"\xff\x03")]
    assert d1.encode(message) == golden


@settings(max_examples=100, deadline=None)
@given(servo=st.integers(0, 253), address=st.integers(0, 255), data=st.binary(min_size=1, max_size=20))
def test_any_write_matches_the_sdk(d1: ModuleType, servo: int, address: int, data: bytes) -> None:
    golden = sdk_packet(lambda p, port: p.writeTxOnly(port, servo, address, len(data), list(data)))
    assert d1.encode(d1.WriteRequest(id=servo, address=address, data=data)) == golden


@pytest.fixture
def sdk(monkeypatch: pytest.MonkeyPatch) -> Iterator[tuple[Any, Any]]:
    # the SDK waits 2 × 16 ms + 2 ms for a reply: too short for a simulator process on a loaded machine
    monkeypatch.setattr("dynamixel_sdk.port_handler.LATENCY_TIMER", 500)
    with serve(str(SPEC), 1, 2) as path:
        handler = dxl.PortHandler(path)
        assert handler.openPort()
        assert handler.setBaudRate(1000000)
        yield handler, dxl.PacketHandler(1.0)
        handler.closePort()


def test_the_sdk_pings_and_reads_the_sim(sdk: tuple[Any, Any]) -> None:
    handler, packet = sdk
    assert packet.ping(handler, 1) == (12, SUCCESS, 0)  # an AX-12A: model number 12
    assert packet.ping(handler, 9)[1] == dxl.COMM_RX_TIMEOUT
    assert packet.read2ByteTxRx(handler, 2, 0) == (12, SUCCESS, 0)
    assert packet.read1ByteTxRx(handler, 2, 3) == (2, SUCCESS, 0)
    assert packet.read2ByteTxRx(handler, 1, 8) == (1023, SUCCESS, 0)
    assert packet.readTxRx(handler, 1, 0, 10) == ([12, 0, 24, 1, 1, 250, 0, 0, 0xFF, 3], SUCCESS, 0)


def test_the_sdk_writes_the_sim(sdk: tuple[Any, Any]) -> None:
    handler, packet = sdk
    assert packet.write1ByteTxRx(handler, 1, 25, 1) == (SUCCESS, 0)
    assert packet.read1ByteTxRx(handler, 1, 25) == (1, SUCCESS, 0)
    assert packet.write2ByteTxRx(handler, 1, 34, 800) == (SUCCESS, 0)
    assert packet.read2ByteTxRx(handler, 1, 34) == (800, SUCCESS, 0)


def test_reg_write_waits_for_action(sdk: tuple[Any, Any]) -> None:
    handler, packet = sdk
    assert packet.regWriteTxRx(handler, 2, 26, 1, [5]) == (SUCCESS, 0)
    assert packet.read1ByteTxRx(handler, 2, 26) == (1, SUCCESS, 0)
    assert packet.action(handler, 254) == SUCCESS
    assert packet.read1ByteTxRx(handler, 2, 26) == (5, SUCCESS, 0)


def test_sync_write_reaches_each_servo(sdk: tuple[Any, Any]) -> None:
    handler, packet = sdk
    group = dxl.GroupSyncWrite(handler, packet, 27, 1)
    assert group.addParam(1, [7]) and group.addParam(2, [9])
    assert group.txPacket() == SUCCESS
    assert packet.read1ByteTxRx(handler, 1, 27) == (7, SUCCESS, 0)
    assert packet.read1ByteTxRx(handler, 2, 27) == (9, SUCCESS, 0)


def test_the_generated_client_against_the_sim(d1: ModuleType) -> None:
    client_module = importlib.import_module("dynamixel_p1.client")
    with serve(str(SPEC), 1, 2) as path, client_module.DynamixelP1Client(path) as servos:
        assert servos.ping(1) is True and servos.ping(5) is False
        assert servos.read(1, "model_number") == 12
        servos.write(2, led=1)
        assert servos.read(2, "led") == 1
        with pytest.raises(Exception, match="outside its range"):
            servos.write(2, goal_position=1024)


def test_writes_of_a_field_that_is_no_memory_entry_and_no_registers_is_a_spec_error(tmp_path: Path) -> None:
    """Found writing this spec: `writes: [data]` on a group item's plain bytes passed `serialspec check`, and the
    simulator died with KeyError 'data' at the first SYNC WRITE. It is now one line at the spec's position."""
    from serialspec.lang import SpecErrors, load_protocol

    text = SPEC.read_text("utf-8").replace(
        "data: {type: bytes, size: length, table: control_table, start: address}", "data: {type: bytes, size: length}"
    )
    spec = tmp_path / "dynamixel_p1.yaml"
    spec.write_text(text, "utf-8")
    with pytest.raises(SpecErrors) as caught:
        load_protocol(str(spec), "dynamixel_p1.yaml")
    lines = str(caught.value).splitlines()
    assert len(lines) == 1, lines
    assert "device.commands.sync_write.writes: sync_write writes 'data'" in lines[0]
    assert "holds no registers" in lines[0]


def test_the_docs_say_a_size_field_becomes_derived() -> None:
    """The SYNC WRITE message had no `length` attribute, which language.md did not say (it did for group counts)."""
    docs = (Path(__file__).parent.parent / "docs" / "language.md").read_text("utf-8")
    assert "or the name of an earlier integer field, which becomes derived" in docs
