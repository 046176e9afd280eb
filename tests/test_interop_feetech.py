"""The vendor's own SDK (ftservo-python-sdk from PyPI, module scservo_sdk) drives our virtual FEETECH servos."""

from __future__ import annotations

import importlib
import time
from collections.abc import Iterator
from typing import Any

import pytest
from serialspec_protocols.feetech_sms.registers import CONTROL_TABLE

scservo_sdk = pytest.importorskip("scservo_sdk")

SUCCESS = scservo_sdk.COMM_SUCCESS
GOAL_POSITION = importlib.import_module("scservo_sdk.sms_sts").SMS_STS_GOAL_POSITION_L
TORQUE_LIMIT = CONTROL_TABLE["torque_limit"].address  # from the spec: the SDK names no constant for it


SIM = ("feetech_sms.yaml", 1, 2, 3)  # the `port` fixture (conftest.py): `serialspec sim` on a pseudo-terminal


@pytest.fixture
def sdk(port: str) -> Iterator[Any]:
    handler = scservo_sdk.PortHandler(port)
    assert handler.openPort()
    yield scservo_sdk.sms_sts(handler)
    handler.closePort()


def test_sdk_pings_present_and_absent_servos(sdk: Any) -> None:
    _, result, error = sdk.ping(1)
    assert (result, error) == (SUCCESS, 0)
    _, result, _ = sdk.ping(9)
    assert result == scservo_sdk.COMM_RX_TIMEOUT


def test_sdk_reads_and_writes_registers(sdk: Any) -> None:
    value, result, error = sdk.read2ByteTxRx(2, TORQUE_LIMIT)
    assert (value, result, error) == (1000, SUCCESS, 0)  # the spec's default
    assert sdk.write2ByteTxRx(2, TORQUE_LIMIT, 640) == (SUCCESS, 0)
    assert sdk.read2ByteTxRx(2, TORQUE_LIMIT)[0] == 640


def test_sdk_moves_a_servo_and_reads_back_its_position(sdk: Any) -> None:
    assert sdk.WritePosEx(1, 2048, 20000, 0) == (SUCCESS, 0)  # acc, position, time 0, speed: 7 bytes from 0x29
    deadline = time.monotonic() + 2
    while sdk.ReadPos(1)[0] != 2048 and time.monotonic() < deadline:
        time.sleep(0.02)
    position, result, error = sdk.ReadPos(1)
    assert (position, result, error) == (2048, SUCCESS, 0)


def test_sdk_sync_write_reaches_every_listed_servo(sdk: Any) -> None:
    for servo, position in ((2, 100), (3, 300)):
        assert sdk.SyncWritePosEx(servo, position, 0, 0)  # speed 0 and time 0: at once
    assert sdk.groupSyncWrite.txPacket() == SUCCESS
    sdk.groupSyncWrite.clearParam()
    assert [sdk.read2ByteTxRx(servo, GOAL_POSITION)[0] for servo in (2, 3)] == [100, 300]
    assert [sdk.ReadPos(servo)[0] for servo in (2, 3)] == [100, 300]


def test_sdk_reg_write_waits_for_action(sdk: Any) -> None:
    assert sdk.RegWritePosEx(3, 777, 0, 0) == (SUCCESS, 0)
    assert sdk.read2ByteTxRx(3, GOAL_POSITION)[0] != 777  # held until ACTION
    assert sdk.RegAction() == SUCCESS  # broadcast: no servo answers, so the SDK only sends
    assert sdk.read2ByteTxRx(3, GOAL_POSITION)[0] == 777
