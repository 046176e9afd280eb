"""The vendor's own SDK (fashionstar-uart-sdk from PyPI) drives our virtual servo; our client does the same."""

from __future__ import annotations

import struct
import time
from collections.abc import Iterator

import pytest
import serial
from serialspec_protocols.fashionstar_uart.client import FashionstarUartClient

uservo = pytest.importorskip("fashionstar_uart_sdk.uservo")


SIM = ("fashionstar_uart.yaml", 0, 1)  # the `port` fixture (conftest.py): `serialspec sim` on a pseudo-terminal


@pytest.fixture
def sdk(port: str) -> Iterator[object]:
    uart = serial.Serial(port, baudrate=115200, timeout=0)
    yield uservo.UartServoManager(uart, srv_num=4)
    uart.close()


def test_sdk_ping(sdk: object) -> None:
    assert sdk.ping(0) is True  # type: ignore[attr-defined]
    assert sdk.ping(3) is False  # type: ignore[attr-defined]


def test_sdk_reads_and_writes_parameters(sdk: object) -> None:
    assert struct.unpack("<H", sdk.read_data(1, 1))[0] == 7400  # type: ignore[attr-defined]
    assert sdk.query_voltage(1) == pytest.approx(7.4)  # type: ignore[attr-defined]
    assert sdk.write_data(1, 43, struct.pack("<H", 1111)) is True  # type: ignore[attr-defined]
    assert struct.unpack("<H", sdk.read_data(1, 43))[0] == 1111  # type: ignore[attr-defined]
    assert sdk.write_data(1, 1, struct.pack("<H", 1)) is False  # type: ignore[attr-defined]  # read-only


def test_sdk_moves_and_reads_back_the_angle(sdk: object, port: str) -> None:
    # interval=None: the SDK reads the angle, works out the time at mean_dps, and sends ROTATE (cmd 8)
    sdk.set_servo_angle(0, 45.0, interval=None, mean_dps=300.0)  # type: ignore[attr-defined]
    time.sleep(0.3)
    assert sdk.query_servo_angle(0) == pytest.approx(45.0)  # type: ignore[attr-defined]
    with FashionstarUartClient(port) as client:  # our client sees the same servo
        assert client.read_angle(0) == 450


def test_our_client_does_the_same(port: str) -> None:
    with FashionstarUartClient(port, timeout=1.0) as client:
        assert client.ping(0)
        assert client.read_parameter(1, "voltage") == 7400
        assert client.write_parameter(1, "over_current", 1234) == 1
        assert client.read_parameter(1, "over_current") == 1234
        client.rotate(1, -300, 100)
        time.sleep(0.2)
        assert client.read_angle(1) == -300


def test_our_read_returns_before_the_sdk_timeout(sdk: object, port: str) -> None:
    """The SDK waits out its 100 ms timeout on every read; ours returns once the reply is complete."""
    rounds = 5
    started = time.perf_counter()
    for _ in range(rounds):
        sdk.query_servo_angle(1)  # type: ignore[attr-defined]
    vendor = (time.perf_counter() - started) / rounds
    with FashionstarUartClient(port, timeout=0.1) as client:
        started = time.perf_counter()
        for _ in range(rounds):
            client.read_angle(1)
        ours = (time.perf_counter() - started) / rounds
    assert vendor >= 0.1  # it always waits its full timeout
    assert ours < vendor / 2
