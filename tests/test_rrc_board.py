"""The Hiwonder RRC board end to end over real pseudo-terminals: grouped client methods against the generated
virtual board (in-process and as a `serialspec sim` process), status fields, reports, and the spec-language keys
this needs (`status`, device `kinds`)."""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import ROOT
from serialspec.lang import SpecErrors, load_protocol
from serialspec.runtime.errors import DeviceError, RangeError, Timeout
from serialspec_protocols.hiwonder_rrc import (
    BusServoReadPositionResponse,
    BusServoSetPositionsRequest,
    BusServosItem,
    ButtonEvent,
    ImuResponse,
    KeyResponse,
    MotorSetSpeedsRequest,
    MotorsItem,
    ReadResult,
    encode,
)
from serialspec_protocols.hiwonder_rrc.client import HiwonderRrcClient
from serialspec_protocols.hiwonder_rrc.simulator import HiwonderRrcSimulator
from sim_process import serve

TIMEOUT = 1.0  # generous: tests wait for replies, they never time them
EXAMPLES = {e.name: e for e in load_protocol(str(ROOT / "specs" / "hiwonder_rrc.yaml")).examples}


@pytest.fixture
def board() -> Iterator[tuple[HiwonderRrcSimulator, HiwonderRrcClient]]:
    simulator = HiwonderRrcSimulator(ids=[1, 2, 5])
    path = simulator.start()
    with HiwonderRrcClient(path, timeout=TIMEOUT) as client:
        yield simulator, client
    simulator.close()


def test_bus_servo_moves_over_the_duration_and_reads_back(
    board: tuple[HiwonderRrcSimulator, HiwonderRrcClient],
) -> None:
    simulator, client = board
    assert client.bus_servo.read_position(5) == 500  # the simulator's starting position
    client.bus_servo.set_positions(1000, {5: 900})
    time.sleep(0.3)
    halfway = client.bus_servo.read_position(5)
    assert 500 < halfway < 900
    time.sleep(0.8)
    assert client.bus_servo.read_position(5) == 900
    assert client.bus_servo.read_position(1) == 500  # the others stay where they were
    # The mapping became the document's layout: one (servo_id, position) item per entry.
    assert simulator.log[1] == BusServoSetPositionsRequest(duration=1000, bus_servos=(BusServosItem(5, 900),))


def test_set_commands_are_kept_and_read_back(board: tuple[HiwonderRrcSimulator, HiwonderRrcClient]) -> None:
    _, client = board
    client.bus_servo.set_offset(2, -10)
    client.bus_servo.set_position_limit(2, 100, 900)
    client.bus_servo.set_voltage_limit(2, 5000, 9000)
    client.bus_servo.set_temperature_limit(2, 70)
    assert client.bus_servo.read_offset(2) == -10
    limits = client.bus_servo.read_position_limit(2)
    assert (limits.low, limits.high, limits.success) == (100, 900, ReadResult.OK)
    voltage_limits = client.bus_servo.read_voltage_limit(2)
    assert (voltage_limits.low, voltage_limits.high) == (5000, 9000)
    assert client.bus_servo.read_temperature_limit(2) == 70
    assert client.bus_servo.read_offset(1) == 0  # servo 1 keeps its own
    assert client.bus_servo.read_voltage(2) == 7400 and client.bus_servo.read_temperature(2) == 30


def test_pwm_servos_are_their_own_devices(board: tuple[HiwonderRrcSimulator, HiwonderRrcClient]) -> None:
    _, client = board
    client.pwm_servo.set_positions(200, {1: 2500, 2: 500})
    client.pwm_servo.set_offset(1, 7)
    time.sleep(0.35)
    assert client.pwm_servo.read_position(1) == 2500
    assert client.pwm_servo.read_position(2) == 500
    assert client.pwm_servo.read_offset(1) == 7
    assert client.bus_servo.read_offset(1) == 0  # bus servo 1 is another device
    client.bus.timeout = 0.05
    with pytest.raises(Timeout, match="pwm_servo from servo_id=9"):
        client.pwm_servo.read_position(9)  # no such PWM port: the board stays silent


def test_set_speeds_takes_a_mapping(board: tuple[HiwonderRrcSimulator, HiwonderRrcClient]) -> None:
    simulator, client = board
    client.motor.set_speeds({1: -1.0, 2: 2.0})
    client.motor.set_speeds((MotorsItem(motor_id=1, speed=-1.0), MotorsItem(motor_id=2, speed=2.0)))
    assert client.bus_servo.read_position(1) == 500  # a round trip: both requests have been handled
    first, second = simulator.log[:2]
    assert first == second
    assert isinstance(first, MotorSetSpeedsRequest)
    assert encode(first) == EXAMPLES["ex07_motor_speeds"].frame  # the document's example 7, byte for byte
    motors = simulator.kinds["motor"]
    assert (motors[1].get("speed"), motors[2].get("speed"), motors[0].get("speed")) == (-1.0, 2.0, 0)
    client.motor.stop(2)
    client.bus_servo.read_position(1)
    assert motors[2].get("speed") == 0


def test_a_failed_read_raises_device_error(board: tuple[HiwonderRrcSimulator, HiwonderRrcClient]) -> None:
    _, client = board
    with pytest.raises(DeviceError, match=r"bus_servo.read_position to servo_id=7: .* success = failed \(-1\)") as err:
        client.bus_servo.read_position(7)  # no servo 7: the board answers for it, with success -1
    assert isinstance(err.value.reply, BusServoReadPositionResponse)
    assert err.value.reply.success == ReadResult.FAILED
    assert client.bus_servo.read_position(5) == 500  # and the bus is fine


def test_set_id_renumbers_and_read_id_answers_a_broadcast() -> None:
    simulator = HiwonderRrcSimulator(ids=[3])
    path = simulator.start()
    try:
        with HiwonderRrcClient(path, timeout=TIMEOUT) as client:
            assert client.bus_servo.read_id() == 3  # sent to 0xFE, answered by the only servo
            client.bus_servo.set_id(3, 4)
            assert client.bus_servo.read_id() == 4
            assert client.bus_servo.read_position(4) == 500
            with pytest.raises(DeviceError):
                client.bus_servo.read_position(3)
    finally:
        simulator.close()


def test_reports_as_iterator_and_callbacks(board: tuple[HiwonderRrcSimulator, HiwonderRrcClient]) -> None:
    simulator, client = board
    keys: list[KeyResponse] = []
    imus: list[ImuResponse] = []
    client.on_key(keys.append)
    stop_imu = client.on_imu(imus.append)
    imu = ImuResponse(accel_x=0.5, accel_y=0.0, accel_z=9.75, gyro_x=0.0, gyro_y=-1.5, gyro_z=0.25)
    simulator.emit(KeyResponse(button_id=1, event=ButtonEvent.CLICK))
    simulator.emit(imu)
    reports = client.reports(TIMEOUT)  # returns each report as it comes; the timeout only bounds the wait
    received = [next(reports), next(reports)]
    assert received == [KeyResponse(button_id=1, event=ButtonEvent.CLICK), imu]
    assert keys == [received[0]] and imus == [imu]
    stop_imu()
    simulator.emit(imu)
    simulator.emit(KeyResponse(button_id=2, event=ButtonEvent.PRESSED))
    assert client.bus_servo.read_position(1) == 500  # reports arriving around a request reach the callbacks
    assert [k.button_id for k in keys] == [1, 2] and imus == [imu]
    assert [type(m).__name__ for m in client.reports(0.05)] == ["ImuResponse", "KeyResponse"]  # already read


def test_a_report_is_the_documents_frame_on_the_wire() -> None:
    simulator = HiwonderRrcSimulator(ids=[1])
    path = simulator.start()
    port = os.open(path, os.O_RDWR | os.O_NOCTTY)
    try:
        simulator.emit(KeyResponse(button_id=1, event=ButtonEvent.PRESSED))
        expected = EXAMPLES["t_key_pressed"].frame  # AA 55 06 02 01 01 DC, 002 §2.2 2
        data = b""
        deadline = time.monotonic() + TIMEOUT
        while len(data) < len(expected) and time.monotonic() < deadline:
            data += os.read(port, 64)
        assert data == expected
    finally:
        os.close(port)
        simulator.close()


def test_arguments_are_refused_before_a_byte_is_written(board: tuple[HiwonderRrcSimulator, HiwonderRrcClient]) -> None:
    simulator, client = board
    with pytest.raises(RangeError, match="position = 1500 is outside its range 0..1000"):
        client.bus_servo.set_positions(1000, {1: 1500})
    with pytest.raises(RangeError, match="pulse = 3000"):
        client.pwm_servo.set_position(100, 1, 3000)
    with pytest.raises(RangeError, match="offset = 126"):
        client.bus_servo.set_offset(1, 126)  # -125..125 (erratum bus_offset_range)
    with pytest.raises(RangeError, match="servo_id = 300"):
        client.bus_servo.read_position(300)
    assert client.bus_servo.read_position(1) == 500
    assert [type(m).__name__ for m in simulator.log] == ["BusServoReadPositionRequest"]


def test_against_a_serialspec_sim_process() -> None:
    with serve("hiwonder_rrc.yaml", 1, 2) as path, HiwonderRrcClient(path, timeout=TIMEOUT) as client:
        client.bus_servo.set_positions(1000, {1: 0, 2: 1000})
        time.sleep(0.2)
        assert 0 < client.bus_servo.read_position(1) < 500 < client.bus_servo.read_position(2) < 1000
        time.sleep(0.9)
        assert (client.bus_servo.read_position(1), client.bus_servo.read_position(2)) == (0, 1000)
        with pytest.raises(DeviceError, match="success = failed"):
            client.bus_servo.read_temperature(3)
        client.pwm_servo.set_position(0, 4, 1000)
        assert client.pwm_servo.read_position(4) == 1000


# --- the spec language: status fields and device kinds ------------------------------------------------------------

TINY = """\
protocol: tiny
title: Tiny
byte_order: little
serial: {baudrate: 9600}
framing:
  elements:
    header: {role: header, value: "AA 55"}
    code: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: sum, covers: [code, content]}
commands:
  read:
    code: 1
    request: {fields: {servo_id: u8}}
    response: {fields: {servo_id: u8, ok: {type: i8, status: {ok: 0}}, value: u16}}
device:
  address: servo_id
  state: {value: 0}
  commands:
    read: {reports: {value: value}}
"""


def load_tiny(tmp_path: Path, text: str) -> None:
    spec = tmp_path / "tiny.yaml"
    spec.write_text(text, encoding="utf-8")
    load_protocol(str(spec), "tiny.yaml")


def test_status_and_kinds_are_checked(tmp_path: Path) -> None:
    load_tiny(tmp_path, TINY)  # valid as it stands
    mistakes = {
        "request: {fields: {servo_id: u8}}": "request: {fields: {servo_id: {type: u8, status: {ok: 0}}}}",
        "status: {ok: 0}}, value": "status: {ok: 300}}, value",
        "read: {reports: {value: value}}": "read: {reports: {value: value}, kind: wheels, absent: {nothing: -1}}",
    }
    with pytest.raises(SpecErrors) as failure:
        load_tiny(tmp_path, _replace_all(TINY, mistakes))
    text = str(failure.value)
    assert "a status is reported in a response" in text
    assert "300 is outside the field's range -128..127" in text
    assert "unknown device kind 'wheels'" in text
    assert "read has no response field 'nothing'" in text
    assert "Traceback" not in text and len(text.splitlines()) == 4


def _replace_all(text: str, changes: dict[str, str]) -> str:
    for old, new in changes.items():
        assert old in text, old
        text = text.replace(old, new)
    return text
