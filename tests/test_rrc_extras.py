"""Hiwonder RRC beyond the documents, from the vendor's board SDK (ros_robot_controller_sdk.py): the battery report,
OLED and RGB functions, motor duty, bus-servo stop and torque read, the other key events and the gamepad bits; and
the documents' disagreements the spec settles (offset range, voltage limits)."""

from __future__ import annotations

import json
import struct
import subprocess
import sys
import time
from collections.abc import Iterator

import pytest
from conftest import ROOT
from serialspec.checksums.crc import crc_function
from serialspec.runtime.errors import RangeError
from serialspec_protocols import hiwonder_rrc as rrc
from serialspec_protocols.hiwonder_rrc.client import HiwonderRrcClient
from serialspec_protocols.hiwonder_rrc.simulator import HiwonderRrcSimulator

BATTERY = "AA 55 00 03 04 1C 25 AB"
# The SDK's table-driven checksum_crc8: the reflected 0x31 table, init 0, no final XOR (CRC-8/MAXIM).
crc8_maxim = crc_function(8, 0x31, 0x00, True, True, 0x00)


def sdk_frame(function: int, data: bytes) -> bytes:
    """A frame as the SDK's Board.buf_write builds it: AA 55, function, length, data, CRC-8 of function..data."""
    body = bytes([function, len(data)]) + data
    return b"\xaa\x55" + body + bytes([crc8_maxim(body)])


def test_the_battery_report_decodes() -> None:
    message = rrc.decode(bytes.fromhex(BATTERY), rrc.Direction.RESPONSE)
    assert message == rrc.SystemBatteryResponse(voltage=9500)  # 0x251C mV
    result = subprocess.run(
        [sys.executable, "-m", "serialspec", "decode", str(ROOT / "specs" / "hiwonder_rrc.yaml"), BATTERY, "--json"]
        + ["--direction", "response"],
        capture_output=True,
        text=True,
        timeout=30,
    )
    decoded = json.loads(result.stdout)
    assert (decoded["command"], decoded["subcommand"], decoded["fields"]) == ("system", "battery", {"voltage": 9500})


@pytest.mark.parametrize(
    ("message", "function", "data"),
    [
        (rrc.OledRequest(line=1, text=b"SSID:HW-ABC123"), 10, bytes([1, 14]) + b"SSID:HW-ABC123"),
        (
            rrc.RgbSetPixelsRequest(pixels=(rrc.PixelsItem(0, 0, 0, 255), rrc.PixelsItem(1, 255, 128, 0))),
            11,
            bytes([0x01, 2]) + struct.pack("<BBBB", 0, 0, 0, 255) + struct.pack("<BBBB", 1, 255, 128, 0),
        ),
        (
            rrc.MotorSetDutiesRequest(duties=(rrc.DutiesItem(0, -50.0), rrc.DutiesItem(1, 50.0))),
            3,
            bytes([0x05, 2]) + struct.pack("<Bf", 0, -50.0) + struct.pack("<Bf", 1, 50.0),
        ),
        (
            rrc.BusServoStopRequest(servos=(rrc.ServosItem(1), rrc.ServosItem(2))),
            5,
            bytes([0x03, 2, 1, 2]),
        ),
        (rrc.BusServoReadTorqueRequest(servo_id=3), 5, bytes([0x0D, 3])),
    ],
    ids=["oled", "rgb", "motor_duty", "bus_servo_stop", "read_torque"],
)
def test_frames_are_the_sdks_packing(message: rrc.Message, function: int, data: bytes) -> None:
    frame = sdk_frame(function, data)
    assert rrc.encode(message) == frame
    assert rrc.decode(frame, rrc.Direction.REQUEST) == message


def test_the_torque_report_unpacks_like_the_sdk() -> None:
    frame = rrc.encode(rrc.BusServoReadTorqueResponse(servo_id=3, success=rrc.ReadResult.OK, torque=1))
    assert struct.unpack("<BBbb", frame[4:-1]) == (3, 0x0D, 0, 1)  # Board.bus_servo_read_torque_state


def test_key_events_and_gamepad_buttons_from_the_sdk() -> None:
    triple = rrc.decode(sdk_frame(6, bytes([1, 0x80])), rrc.Direction.RESPONSE)
    assert triple == rrc.KeyResponse(button_id=1, event=rrc.ButtonEvent.TRIPLE_CLICK)
    released = rrc.decode(sdk_frame(6, bytes([2, 0x08])), rrc.Direction.RESPONSE)
    assert released.event == rrc.ButtonEvent.RELEASE_FROM_LONG_PRESS  # type: ignore[attr-defined]
    pad = rrc.decode(sdk_frame(8, struct.pack("<HB4b", 0x4000 | 0x0100 | 0x0008, 9, 0, 0, 0, 0)), "response")
    assert pad.buttons == rrc.GamepadButtons.L1 | rrc.GamepadButtons.CROSS | rrc.GamepadButtons.START  # type: ignore[attr-defined]


def test_bus_offset_range_is_the_bus_servos() -> None:
    for offset in (-125, 125):
        assert rrc.encode(rrc.BusServoSetOffsetRequest(servo_id=1, offset=offset))
    with pytest.raises(RangeError, match="-125..125"):
        rrc.encode(rrc.BusServoSetOffsetRequest(servo_id=1, offset=-126))
    with pytest.raises(RangeError, match="-100..100"):  # the PWM servos keep theirs
        rrc.encode(rrc.PwmServoSetOffsetRequest(servo_id=1, offset=-101))


def test_voltage_limits_are_inclusive() -> None:
    assert rrc.encode(rrc.BusServoSetVoltageLimitRequest(servo_id=1, low=4500, high=14000))
    for low, high in ((4499, 14000), (4500, 14001)):
        with pytest.raises(RangeError):
            rrc.encode(rrc.BusServoSetVoltageLimitRequest(servo_id=1, low=low, high=high))


@pytest.fixture
def board() -> Iterator[tuple[HiwonderRrcSimulator, HiwonderRrcClient]]:
    simulator = HiwonderRrcSimulator(ids=[1, 2])
    path = simulator.start()
    with HiwonderRrcClient(path, timeout=1.0) as client:
        yield simulator, client
    simulator.close()


def test_stop_and_torque_state_on_the_virtual_board(board: tuple[HiwonderRrcSimulator, HiwonderRrcClient]) -> None:
    simulator, client = board
    assert client.bus_servo.read_torque(1) == 1
    client.bus_servo.unload(1)
    assert client.bus_servo.read_torque(1) == 0
    client.bus_servo.set_positions(20000, {1: 900, 2: 100})
    time.sleep(0.2)
    client.bus_servo.stop([1])  # a plain list of ids for a group of single-field items
    stopped = client.bus_servo.read_position(1)
    time.sleep(0.2)
    assert client.bus_servo.read_position(1) == stopped and 500 < stopped < 900
    assert client.bus_servo.read_position(2) < 500  # still on its way
    client.motor.set_duties({0: -50.0, 3: 25.0})
    client.oled(2, b"IP:192.168.149.1")
    client.rgb.set_pixels((rrc.PixelsItem(0, 1, 2, 3),))
    assert client.bus_servo.read_torque(2) == 1  # answered after the three requests before it: all handled
    assert [simulator.kinds["motor"][i].get("duty") for i in range(4)] == [-50.0, 0, 0, 25.0]
    simulator.emit(rrc.SystemBatteryResponse(voltage=7800))
    assert [m for m in client.reports(1.0)][:1] == [rrc.SystemBatteryResponse(voltage=7800)]
