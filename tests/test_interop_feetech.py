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


def _sign_magnitude(value: int, sign_bit: int) -> int:
    """LeRobot's encode_sign_magnitude: the magnitude, with the sign in `sign_bit`."""
    return (1 << sign_bit) | -value if value < 0 else value


def _sync_read_positions(sdk: Any, servos: tuple[int, ...]) -> list[int]:
    reader = scservo_sdk.GroupSyncRead(sdk, CONTROL_TABLE["present_position"].address, 2)
    for servo in servos:
        assert reader.addParam(servo)
    assert reader.txRxPacket() == SUCCESS
    return [reader.getData(servo, CONTROL_TABLE["present_position"].address, 2) for servo in servos]


def test_so100_calibration_as_lerobot_does_it(sdk: Any) -> None:
    """LeRobot's FeetechMotorsBus on an SO-100 arm: torque off and EEPROM unlocked, the homing offset reset, the
    present positions read, Homing_Offset = position - 2047 written (sign-magnitude, sign in bit 11), after which
    every joint reads 2047 (Present_Position = Actual_Position - Homing_Offset) and goals are in those terms."""
    servos = (1, 2, 3)
    table = {name: CONTROL_TABLE[name].address for name in ("torque_enable", "lock", "position_offset")}
    for servo, start in zip(servos, (1000, 3000, 2047), strict=True):
        assert sdk.WritePosEx(servo, start, 0, 0) == (SUCCESS, 0)  # speed 0 and time 0: at once
    for servo in servos:  # disable_torque, then reset_calibration
        assert sdk.write1ByteTxRx(servo, table["torque_enable"], 0) == (SUCCESS, 0)
        assert sdk.write1ByteTxRx(servo, table["lock"], 0) == (SUCCESS, 0)
        assert sdk.write2ByteTxRx(servo, table["position_offset"], 0) == (SUCCESS, 0)
    positions = _sync_read_positions(sdk, servos)
    assert positions == [1000, 3000, 2047]
    for servo, position in zip(servos, positions, strict=True):  # set_half_turn_homings
        offset = _sign_magnitude(position - 2047, 11)
        assert sdk.write2ByteTxRx(servo, table["position_offset"], offset) == (SUCCESS, 0)
        assert sdk.read2ByteTxRx(servo, table["position_offset"])[0] == offset
    assert _sync_read_positions(sdk, servos) == [2047, 2047, 2047]
    for servo in servos:
        assert sdk.write1ByteTxRx(servo, table["lock"], 1) == (SUCCESS, 0)
        assert sdk.write1ByteTxRx(servo, table["torque_enable"], 1) == (SUCCESS, 0)
    assert sdk.WritePosEx(1, 2147, 0, 0) == (SUCCESS, 0)  # a goal in calibrated terms
    assert sdk.ReadPos(1)[0] == 2147
    # an offset larger than the position: what the servo reports wraps within one turn
    assert sdk.write2ByteTxRx(1, table["position_offset"], 2000) == (SUCCESS, 0)  # the horn is at 1100
    assert sdk.ReadPos(1)[0] == 1100 - 2000 + 4096
