"""ROBOTIS's own SDK (dynamixel-sdk from PyPI, module dynamixel_sdk) drives our virtual DYNAMIXEL X-series servos.

Register addresses come from the spec (CONTROL_TABLE), the SDK's packets are its own. dynamixel_sdk 4.1.0 sends
unstuffed packets when a parameter holds FF FF FD (erratum sdk_tx_stuffing): no test writes such a value through it.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import pytest
from serialspec_protocols import dynamixel_p2
from serialspec_protocols.dynamixel_p2.registers import CONTROL_TABLE
from sim_process import serve

dxl = pytest.importorskip("dynamixel_sdk")

SUCCESS = dxl.COMM_SUCCESS
ADDRESS = {r.name: r.address for r in CONTROL_TABLE.by_address.values()}


SIM = ("dynamixel_p2.yaml", 1, 2, 3)  # the `port` fixture (conftest.py): `serialspec sim` on a pseudo-terminal


@pytest.fixture(autouse=True)
def patient_sdk(monkeypatch: pytest.MonkeyPatch) -> None:
    """The SDK waits twice its LATENCY_TIMER (16 ms, a USB adapter's) and the bytes' time for a status packet: on a
    loaded machine the simulator can take longer (a reset once failed so under a load of 6 on 2 cores)."""
    monkeypatch.setattr("dynamixel_sdk.port_handler.LATENCY_TIMER", 250)


@pytest.fixture
def sdk(port: str) -> Iterator[tuple[Any, Any]]:
    handler = dxl.PortHandler(port)
    assert handler.openPort()
    assert handler.setBaudRate(57600)
    yield handler, dxl.PacketHandler(2.0)
    handler.closePort()


def test_sdk_crc_agrees_with_the_spec() -> None:
    # the SDK's CRC table against the e-manual's PING frame and the spec's stuffed WRITE (CRC over stuffed bytes)
    handler = dxl.PacketHandler(2.0)
    for frame in ("FF FF FD 00 01 03 00 01 19 4E", "FF FF FD 00 01 0A 00 03 74 00 FF FF FD FD FF 23 E5"):
        data = bytes.fromhex(frame)
        assert handler.updateCRC(0, list(data[:-2]), len(data) - 2) == int.from_bytes(data[-2:], "little")


def test_ping_reports_the_model_number(sdk: tuple[Any, Any]) -> None:
    handler, packet = sdk
    model, result, error = packet.ping(handler, 1)
    assert (model, result, error) == (1020, SUCCESS, 0)  # XM430-W350, the simulator's default
    _, result, _ = packet.ping(handler, 9)
    assert result == dxl.COMM_RX_TIMEOUT


def test_broadcast_ping_finds_every_servo(sdk: tuple[Any, Any]) -> None:
    handler, packet = sdk
    found, result = packet.broadcastPing(handler)
    assert result == SUCCESS
    assert sorted(found) == [1, 2, 3]
    assert all(found[i][0] == 1020 for i in found)


def test_reads_and_writes_of_1_2_and_4_bytes(sdk: tuple[Any, Any]) -> None:
    handler, packet = sdk
    assert packet.read1ByteTxRx(handler, 2, ADDRESS["status_return_level"]) == (2, SUCCESS, 0)
    assert packet.read2ByteTxRx(handler, 2, ADDRESS["velocity_p_gain"]) == (100, SUCCESS, 0)
    assert packet.read4ByteTxRx(handler, 2, ADDRESS["velocity_limit"]) == (200, SUCCESS, 0)
    assert packet.write1ByteTxRx(handler, 2, ADDRESS["led"], 1) == (SUCCESS, 0)
    assert packet.write2ByteTxRx(handler, 2, ADDRESS["position_p_gain"], 900) == (SUCCESS, 0)
    assert packet.write4ByteTxRx(handler, 2, ADDRESS["profile_velocity"], 50) == (SUCCESS, 0)
    assert packet.read1ByteTxRx(handler, 2, ADDRESS["led"])[0] == 1
    assert packet.read2ByteTxRx(handler, 2, ADDRESS["position_p_gain"])[0] == 900
    assert packet.read4ByteTxRx(handler, 2, ADDRESS["profile_velocity"])[0] == 50
    assert packet.write4ByteTxRx(handler, 2, ADDRESS["profile_velocity"], 0) == (SUCCESS, 0)


def test_errors_come_back_in_the_status_packet(sdk: tuple[Any, Any]) -> None:
    handler, packet = sdk
    result, error = packet.write2ByteTxRx(handler, 3, ADDRESS["present_input_voltage"], 5)  # read-only
    assert (result, error) == (SUCCESS, 7)  # access error
    result, error = packet.write1ByteTxRx(handler, 3, ADDRESS["status_return_level"], 9)  # range 0..2
    assert (result, error) == (SUCCESS, 4)  # data range error


def test_goal_position_moves_present_position_with_torque_on(sdk: tuple[Any, Any]) -> None:
    handler, packet = sdk
    assert packet.write4ByteTxRx(handler, 1, ADDRESS["goal_position"], 1000) == (SUCCESS, 0)
    assert packet.read4ByteTxRx(handler, 1, ADDRESS["present_position"])[0] == 0  # torque off: no move
    assert packet.write1ByteTxRx(handler, 1, ADDRESS["torque_enable"], 1) == (SUCCESS, 0)
    assert packet.write4ByteTxRx(handler, 1, ADDRESS["goal_position"], 2048) == (SUCCESS, 0)
    assert packet.read4ByteTxRx(handler, 1, ADDRESS["present_position"]) == (2048, SUCCESS, 0)  # velocity 0: at once
    assert packet.write1ByteTxRx(handler, 1, ADDRESS["torque_enable"], 0) == (SUCCESS, 0)


def test_reg_write_waits_for_action(sdk: tuple[Any, Any]) -> None:
    handler, packet = sdk
    assert packet.regWriteTxRx(handler, 3, ADDRESS["led"], 1, [1]) == (SUCCESS, 0)
    assert packet.read1ByteTxRx(handler, 3, ADDRESS["registered_instruction"])[0] == 1
    assert packet.read1ByteTxRx(handler, 3, ADDRESS["led"])[0] == 0
    assert packet.action(handler, 3) == SUCCESS
    deadline = time.monotonic() + 2
    while packet.read1ByteTxRx(handler, 3, ADDRESS["led"])[0] != 1 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert packet.read1ByteTxRx(handler, 3, ADDRESS["led"])[0] == 1
    assert packet.read1ByteTxRx(handler, 3, ADDRESS["registered_instruction"])[0] == 0
    assert packet.write1ByteTxRx(handler, 3, ADDRESS["led"], 0) == (SUCCESS, 0)


def test_group_sync_write_and_read(sdk: tuple[Any, Any]) -> None:
    handler, packet = sdk
    writer = dxl.GroupSyncWrite(handler, packet, ADDRESS["profile_acceleration"], 4)
    for servo, value in ((1, 11), (2, 22), (3, 33)):
        assert writer.addParam(servo, list(value.to_bytes(4, "little")))
    assert writer.txPacket() == SUCCESS
    reader = dxl.GroupSyncRead(handler, packet, ADDRESS["profile_acceleration"], 4)
    for servo in (1, 2, 3):
        assert reader.addParam(servo)
    assert reader.txRxPacket() == SUCCESS
    values = [reader.getData(s, ADDRESS["profile_acceleration"], 4) for s in (1, 2, 3)]
    assert values == [11, 22, 33]


def test_group_bulk_write_and_read(sdk: tuple[Any, Any]) -> None:
    handler, packet = sdk
    writer = dxl.GroupBulkWrite(handler, packet)
    assert writer.addParam(1, ADDRESS["position_d_gain"], 2, [5, 0])
    assert writer.addParam(2, ADDRESS["led"], 1, [1])
    assert writer.txPacket() == SUCCESS
    reader = dxl.GroupBulkRead(handler, packet)
    assert reader.addParam(1, ADDRESS["position_d_gain"], 2)
    assert reader.addParam(2, ADDRESS["led"], 1)
    assert reader.addParam(3, ADDRESS["model_number"], 2)
    assert reader.txRxPacket() == SUCCESS
    assert reader.getData(1, ADDRESS["position_d_gain"], 2) == 5
    assert reader.getData(2, ADDRESS["led"], 1) == 1
    assert reader.getData(3, ADDRESS["model_number"], 2) == 1020
    assert packet.write1ByteTxRx(handler, 2, ADDRESS["led"], 0) == (SUCCESS, 0)


def test_reboot_and_factory_reset(port: str) -> None:
    with serve("dynamixel_p2.yaml", 7) as own:  # a servo of its own: the reset must not disturb the others
        handler = dxl.PortHandler(own)
        assert handler.openPort()
        packet = dxl.PacketHandler(2.0)
        try:
            assert packet.reboot(handler, 7) == (SUCCESS, 0)
            assert packet.write2ByteTxRx(handler, 7, ADDRESS["position_p_gain"], 123) == (SUCCESS, 0)
            assert packet.write1ByteTxRx(handler, 7, ADDRESS["baud_rate"], 3) == (SUCCESS, 0)
            assert packet.factoryReset(handler, 7, 0x02) == (SUCCESS, 0)  # all but id and baud rate
            assert packet.read2ByteTxRx(handler, 7, ADDRESS["position_p_gain"]) == (800, SUCCESS, 0)
            assert packet.read1ByteTxRx(handler, 7, ADDRESS["baud_rate"]) == (3, SUCCESS, 0)
            assert packet.factoryReset(handler, 7, 0x01) == (SUCCESS, 0)  # all but id
            assert packet.read1ByteTxRx(handler, 7, ADDRESS["baud_rate"]) == (1, SUCCESS, 0)
        finally:
            handler.closePort()


def test_models_by_id_report_their_numbers_and_limits() -> None:
    # `serialspec sim --model`: XM430-W350 by default, other models per id, each with its factory values
    with serve("dynamixel_p2.yaml", 1, 2, 3, options=["--model", "2=xl430_w250", "--model", "3=xl330_m288"]) as path:
        handler = dxl.PortHandler(path)
        assert handler.openPort()
        packet = dxl.PacketHandler(2.0)
        try:
            found, result = packet.broadcastPing(handler)
            assert result == SUCCESS
            assert {servo: model for servo, (model, _) in found.items()} == {1: 1020, 2: 1060, 3: 1200}
            assert packet.read2ByteTxRx(handler, 3, ADDRESS["current_limit"]) == (1750, SUCCESS, 0)
            assert packet.read1ByteTxRx(handler, 2, ADDRESS["temperature_limit"]) == (72, SUCCESS, 0)
            # a model's own range: 1500 is within the XL330's current limit range, not the XM430's
            assert packet.write2ByteTxRx(handler, 3, ADDRESS["current_limit"], 1500) == (SUCCESS, 0)
            assert packet.write2ByteTxRx(handler, 1, ADDRESS["current_limit"], 1500) == (SUCCESS, 4)
        finally:
            handler.closePort()


def test_the_sdk_sends_unstuffed_packets(sdk: tuple[Any, Any]) -> None:
    # erratum sdk_tx_stuffing: goal_position -131073 is FF FF FD FF; dynamixel_sdk 4.1.0 sends it unstuffed, which
    # no servo can take for a packet (the simulator, like a servo, finds no valid packet and stays silent)
    handler, packet = sdk
    assert packet.write1ByteTxRx(handler, 2, ADDRESS["torque_enable"], 0) == (SUCCESS, 0)
    result, _ = packet.write4ByteTxRx(handler, 2, ADDRESS["goal_position"], (-131073) & 0xFFFFFFFF)
    assert result == dxl.COMM_RX_TIMEOUT
    assert packet.read4ByteTxRx(handler, 2, ADDRESS["goal_position"])[0] != (-131073) & 0xFFFFFFFF


class _CapturingPort:
    """Just enough of a PortHandler for the SDK to send a packet: the bytes it writes are kept."""

    is_using = False

    def __init__(self) -> None:
        self.written = b""

    def clearPort(self) -> None:
        pass

    def writePort(self, packet: list[int]) -> int:
        self.written += bytes(packet)
        return len(packet)

    def setPacketTimeout(self, length: int) -> None:
        pass


def test_fast_sync_read_packet_is_the_sdks() -> None:
    port = _CapturingPort()
    group = dxl.GroupSyncRead(port, dxl.PacketHandler(2.0), ADDRESS["present_position"], 4)
    for servo in (1, 2):
        assert group.addParam(servo)
    assert group.fastSyncReadTxPacket() == SUCCESS
    request = dynamixel_p2.FastSyncReadRequest(
        id=254, address=132, length=4, servo_ids=(dynamixel_p2.ServoIdsItem(id=1), dynamixel_p2.ServoIdsItem(id=2))
    )
    assert port.written == dynamixel_p2.encode(request)
    assert dynamixel_p2.decode(port.written, "request") == request


# LeRobot's Koch arm (koch_follower): XL430-W250 at the shoulder and elbow, XL330-M288 at the wrist and gripper.
KOCH = {1: "xl430_w250", 2: "xl430_w250", 3: "xl430_w250", 4: "xl330_m288", 5: "xl330_m288", 6: "xl330_m288"}
HALF_TURN = 2047  # LeRobot: (4096 - 1) // 2, the position every joint reads after half-turn homing


def sync_write(handler: Any, packet: Any, name: str, size: int, values: dict[int, int]) -> None:
    writer = dxl.GroupSyncWrite(handler, packet, ADDRESS[name], size)
    for servo, value in values.items():
        assert writer.addParam(servo, list((value & (1 << 8 * size) - 1).to_bytes(size, "little")))
    assert writer.txPacket() == SUCCESS


def sync_read(handler: Any, packet: Any, name: str, size: int, servos: list[int]) -> dict[int, int]:
    reader = dxl.GroupSyncRead(handler, packet, ADDRESS[name], size)
    for servo in servos:
        assert reader.addParam(servo)
    assert reader.txRxPacket() == SUCCESS
    values = {servo: reader.getData(servo, ADDRESS[name], size) for servo in servos}
    return {servo: value - (1 << 8 * size) if value >> (8 * size - 1) else value for servo, value in values.items()}


def test_koch_arm_calibration_as_lerobot_does_it() -> None:
    # DynamixelMotorsBus's calibration: torque off, homing offsets reset, Present_Position read, Homing_Offset =
    # half turn - position, Present_Position read back at half turn; the e-manual's rules the spec's device states:
    # present position = actual position + homing offset, and EEPROM items refused (error 7) while torque is on.
    options = [arg for servo, model in KOCH.items() for arg in ("--model", f"{servo}={model}")]
    with serve("dynamixel_p2.yaml", *KOCH, options=options) as path:
        handler = dxl.PortHandler(path)
        assert handler.openPort()
        packet = dxl.PacketHandler(2.0)
        servos = list(KOCH)
        try:
            # someone has put the arm in some pose: the joints are where they happen to be
            pose = {1: 1024, 2: 3000, 3: 150, 4: 2500, 5: 4000, 6: 2047}
            sync_write(handler, packet, "torque_enable", 1, dict.fromkeys(servos, 1))
            sync_write(handler, packet, "goal_position", 4, pose)  # profile_velocity 0: there at once
            # an EEPROM item under torque: access error 7, and the value stays
            assert packet.write4ByteTxRx(handler, 1, ADDRESS["homing_offset"], 100) == (SUCCESS, 7)
            assert packet.write1ByteTxRx(handler, 2, ADDRESS["operating_mode"], 4) == (SUCCESS, 7)
            assert packet.read4ByteTxRx(handler, 1, ADDRESS["homing_offset"]) == (0, SUCCESS, 0)
            assert packet.read1ByteTxRx(handler, 2, ADDRESS["operating_mode"]) == (3, SUCCESS, 0)
            # calibrate: disable_torque, reset_calibration, set_half_turn_homings
            sync_write(handler, packet, "torque_enable", 1, dict.fromkeys(servos, 0))
            for servo in servos:
                assert packet.write4ByteTxRx(handler, servo, ADDRESS["homing_offset"], 0) == (SUCCESS, 0)
                assert packet.write4ByteTxRx(handler, servo, ADDRESS["min_position_limit"], 0) == (SUCCESS, 0)
                assert packet.write4ByteTxRx(handler, servo, ADDRESS["max_position_limit"], 4095) == (SUCCESS, 0)
            actual = sync_read(handler, packet, "present_position", 4, servos)
            assert actual == pose
            offsets = {servo: HALF_TURN - position for servo, position in actual.items()}
            for servo, offset in offsets.items():
                assert packet.write4ByteTxRx(handler, servo, ADDRESS["homing_offset"], offset & 0xFFFFFFFF) == (
                    SUCCESS,
                    0,
                )
            assert sync_read(handler, packet, "present_position", 4, servos) == dict.fromkeys(servos, HALF_TURN)
            assert sync_read(handler, packet, "homing_offset", 4, servos) == offsets
            # with torque on again, a goal is in present_position's terms (offset included)
            sync_write(handler, packet, "torque_enable", 1, dict.fromkeys(servos, 1))
            sync_write(handler, packet, "goal_position", 4, dict.fromkeys(servos, HALF_TURN + 100))
            assert sync_read(handler, packet, "present_position", 4, servos) == dict.fromkeys(servos, HALF_TURN + 100)
            assert packet.write4ByteTxRx(handler, 3, ADDRESS["homing_offset"], 0) == (SUCCESS, 7)
        finally:
            handler.closePort()
