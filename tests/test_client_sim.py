"""The generated client against a real `serialspec sim` process: every behaviour the spec's device section gives."""

from __future__ import annotations

import time
from collections.abc import Iterator

import pytest
from serialspec.runtime.errors import EncodeError, Timeout
from serialspec_protocols.fashionstar_uart import ResponseSwitch, Result, UserData
from serialspec_protocols.fashionstar_uart.client import FashionstarUartClient

TIMEOUT = 1.0


SIM = ("fashionstar_uart.yaml", 1, 2, 3)  # the `port` fixture (conftest.py): `serialspec sim` on a pseudo-terminal


@pytest.fixture
def client(port: str) -> Iterator[FashionstarUartClient]:
    with FashionstarUartClient(port, timeout=TIMEOUT) as c:
        yield c


def test_ping(client: FashionstarUartClient) -> None:
    assert client.ping(1) is True
    client.bus.timeout = 0.05
    assert client.ping(9) is False


def test_parameters_by_name(client: FashionstarUartClient) -> None:
    assert client.read_parameter(2, "voltage") == 7400
    assert client.read_parameter(2, "baudrate") == 5  # the table default
    assert client.write_parameter(2, "over_current", 1200) == Result.SUCCESS
    assert client.read_parameter(2, "over_current") == 1200
    assert client.read_parameter(3, "over_current") == 1500  # other servos keep theirs
    with pytest.raises(EncodeError, match="read-only"):
        client.write_parameter(2, "voltage", 1)
    with pytest.raises(EncodeError, match="unknown entry"):
        client.read_parameter(2, "no_such_parameter")


def test_user_block_is_a_dataclass(client: FashionstarUartClient) -> None:
    block = client.read_batch_data(3)
    assert isinstance(block, UserData)
    assert block.servo_id == 3 and block.accel_switch == 1


def test_move_and_read_back(client: FashionstarUartClient) -> None:
    assert client.rotate(1, 0, 0) is None  # response switch 0: no reply, no waiting
    time.sleep(0.05)
    assert client.read_angle(1) == 0
    client.rotate(1, 900, 400)
    time.sleep(0.2)
    halfway = client.read_angle(1)
    assert halfway is not None and 0 < halfway < 900
    time.sleep(0.3)
    assert client.read_angle(1) == 900


def test_optional_replies_follow_the_response_switch(client: FashionstarUartClient) -> None:
    assert client.write_parameter(3, "response_switch", ResponseSwitch.QUEUED_WITH_RESPONSE) == Result.SUCCESS
    started = time.perf_counter()
    assert client.rotate(3, -450, 200) == Result.SUCCESS  # answers once the move is over
    assert time.perf_counter() - started >= 0.15
    assert client.read_angle(3) == -450
    assert client.damping(3, 500) == Result.SUCCESS
    assert client.write_parameter(3, "response_switch", 0) == Result.SUCCESS
    assert client.damping(3, 500) is None


def test_broadcast_does_not_wait(client: FashionstarUartClient) -> None:
    started = time.perf_counter()
    assert client.damping(255, 300) is None
    assert time.perf_counter() - started < TIMEOUT / 4
    assert client.ping(2)  # and nothing answered the broadcast


def test_the_device_can_say_no(client: FashionstarUartClient) -> None:
    client.bus.timeout = 0.1
    with pytest.raises(Timeout, match="read_data from servo_id=2"):
        client.read_data(2, 99)  # no such data_id: the servo stays silent
