"""The generated DYNAMIXEL client against the generated virtual X-series servos on a real pseudo-terminal."""

from __future__ import annotations

import time
from collections.abc import Iterator

import pytest
from conftest import Running
from serialspec.runtime.errors import DecodeError, DeviceError, RangeError, Timeout
from serialspec_protocols.dynamixel_p2.client import DynamixelP2Client
from serialspec_protocols.dynamixel_p2.simulator import DynamixelP2Simulator

TIMEOUT = 1.0


SIMULATOR = (DynamixelP2Simulator, [1, 2, 3])  # the `sim` fixture (conftest.py)


@pytest.fixture
def client(sim: Running) -> Iterator[DynamixelP2Client]:
    with DynamixelP2Client(sim.path, timeout=TIMEOUT) as c:
        yield c


def test_ping_returns_model_number_and_firmware(client: DynamixelP2Client) -> None:
    reply = client.ping(1)
    assert (reply.model_number, reply.firmware_version) == (1020, 52)
    client.bus.timeout = 0.05
    with pytest.raises(Timeout):
        client.ping(9)


def test_registers_by_name(client: DynamixelP2Client) -> None:
    assert client.read(2, "velocity_limit") == 200
    assert client.write(2, goal_pwm=-300, goal_current=-5) is True  # one run: 100..103, signed
    assert client.read_many(2, "goal_pwm", "goal_current") == {"goal_pwm": -300, "goal_current": -5}


def test_values_out_of_range_are_refused_before_sending(client: DynamixelP2Client) -> None:
    with pytest.raises(RangeError, match="status_return_level"):
        client.write(1, status_return_level=3)


def test_device_errors_name_the_error_number(client: DynamixelP2Client) -> None:
    # the spec's `errors:`, one reply value per reason
    with pytest.raises(DeviceError, match="access_error"):
        client.write_raw(1, 144, b"\x05\x00")  # present_input_voltage is read-only
    with pytest.raises(DeviceError, match="access_error"):
        client.write_raw(1, 1, b"\x05")  # the second byte of model_number: no whole register
    with pytest.raises(DeviceError, match="data_range_error"):
        client.write_raw(1, 68, b"\x03")  # status_return_level 3: outside 0..2
    assert client.read(1, "status_return_level") == 2  # a refused write changes nothing


def test_homing_offset_and_the_eeprom_lock(client: DynamixelP2Client) -> None:
    # the spec's device rules: present_position = position + homing_offset; EEPROM refused (7) while torque is on
    before = client.read(2, "present_position")
    assert client.write(2, homing_offset=-300) is True
    assert client.read(2, "present_position") == before - 300
    assert client.write(2, torque_enable=1) is True
    with pytest.raises(DeviceError, match="access_error"):
        client.write(2, homing_offset=0)
    with pytest.raises(DeviceError, match="access_error"):
        client.write(2, baud_rate=3)
    assert client.read_many(2, "homing_offset", "baud_rate") == {"homing_offset": -300, "baud_rate": 1}
    assert client.write(2, goal_position=before + 50) is True  # in present_position's terms
    assert client.read(2, "present_position") == before + 50
    assert client.write(2, torque_enable=0) is True
    assert client.write(2, homing_offset=0) is True
    assert client.read(2, "present_position") == before + 350


def test_status_return_level_switches_replies(client: DynamixelP2Client) -> None:
    assert client.write(3, status_return_level=1) is True  # answered: the level was 2 when the write arrived
    assert client.write(3, led=1) is None  # level 1: a WRITE gets no status packet, the client does not wait
    assert client.read(3, "led") == 1  # READ is still answered
    assert client.write(3, status_return_level=0) is None
    client.bus.timeout = 0.1
    with pytest.raises(DecodeError, match="led: 0 bytes read"):  # not Timeout: sent, not waited for
        client.read(3, "led")  # level 0: READ is not answered either (this read's frame was kept: still sent)
    assert client.read_raw(3, 65, 1) is None
    assert client.ping(3).model_number == 1020  # PING always is


def test_goal_position_moves_with_torque_and_profile_velocity(client: DynamixelP2Client) -> None:
    assert client.write(1, torque_enable=1) is True
    assert client.write(1, goal_position=1000) is True
    assert client.read(1, "present_position") == 1000  # profile velocity 0: at once
    assert client.write(1, profile_velocity=100) is True  # 100 x 0.229 rev/min: about 1,560 pulses/s
    assert client.write(1, goal_position=4000) is True
    first = client.read_many(1, "moving", "moving_status")["moving"]
    deadline = time.monotonic() + 6
    while client.read(1, "present_position") != 4000 and time.monotonic() < deadline:
        time.sleep(0.02)
    assert client.read(1, "present_position") == 4000
    assert (first, client.read(1, "moving")) == (1, 0)  # 1 on the way (about 2 s), 0 once there


def test_sync_read_and_write_by_name(client: DynamixelP2Client) -> None:
    client.sync_write({1: {"profile_acceleration": 7}, 2: {"profile_acceleration": 8}})
    assert client.sync_read([1, 2], "profile_acceleration") == {
        1: {"profile_acceleration": 7},
        2: {"profile_acceleration": 8},
    }


def test_id_change_moves_the_servo(client: DynamixelP2Client) -> None:
    client.bus.timeout = 0.2
    assert client.write(2, id=12) is True  # the status packet comes from id 12: matched by it
    assert client.ping(12).model_number == 1020
    with pytest.raises(Timeout):
        client.ping(2)
    # raw bytes into the register named `id`: the raw method does not know they change the id, and waits for a
    # status packet from id 12 that comes from id 13
    with pytest.raises(Timeout, match="no reply to write from id=12 within 200 ms"):
        client.write_raw(12, 7, bytes([13]))
    assert client.ping(13).model_number == 1020
    # no servo 9: the read of its status_return_level goes unanswered too, as it would at level 0, where a WRITE
    # gets no status packet: not waited for. Told that replies are on, the client waits, and times out.
    assert client.write(9, led=1) is None
    client.optional_replies = True
    with pytest.raises(Timeout, match=r"^no reply to write from id=9 within 200 ms$"):
        client.write(9, led=1)
    with pytest.raises(Timeout, match=r"^no reply to write from id=9 \(as id=10\) within 200 ms$"):
        client.write(9, id=10)


def test_bulk_read_and_write_by_name(client: DynamixelP2Client) -> None:
    client.bulk_write({1: {"position_p_gain": 850}, 2: {"led": 1}})
    assert client.bulk_read({1: "position_p_gain", 2: ("led",), 3: ("model_number", "model_information")}) == {
        1: {"position_p_gain": 850},
        2: {"led": 1},
        3: {"model_number": 1020, "model_information": 0},
    }


def test_action_without_reg_write_is_an_instruction_error(client: DynamixelP2Client) -> None:
    with pytest.raises(DeviceError, match="instruction_error"):
        client.action(2)
    assert client.reg_write(2, led=1) is True
    assert client.action(2) is True


def test_clear_keeps_the_position_within_one_turn(client: DynamixelP2Client) -> None:
    assert client.write(1, torque_enable=1) is True
    assert client.write(1, goal_position=10000) is True  # profile velocity 0: there at once, 2 turns and 1808
    assert client.clear(1, 1) is True
    assert client.read(1, "present_position") == 1808
    assert client.write(1, goal_position=-5000) is True
    assert client.clear(1, 1) is True
    assert client.read(1, "present_position") == 3192  # -5000 + 2 x 4096: within 0..4095, not toward zero
    assert client.write(1, profile_velocity=1, goal_position=100000) is True  # about 16 pulses/s: hours away
    with pytest.raises(DeviceError, match="result_fail"):
        client.clear(1, 1)  # only while stopped
    assert client.read(1, "moving") == 1  # the move goes on


def test_reboot_restores_ram_and_keeps_eeprom(client: DynamixelP2Client) -> None:
    assert client.write(2, return_delay_time=5) is True  # EEPROM
    assert client.write(2, torque_enable=1, led=1) is True  # RAM
    assert client.write(2, goal_position=5000) is True  # profile velocity 0: there at once
    assert client.read(2, "present_position") == 5000
    assert client.reg_write_raw(2, 65, b"\x01") is True  # led = 1 on ACTION; the reboot drops it
    assert client.write(2, led=0) is True
    assert client.reboot(2) is True
    with pytest.raises(DeviceError, match="instruction_error"):
        client.action(2)  # nothing held any more
    ram = client.read_many(2, "torque_enable", "led", "goal_position", "present_position")
    assert ram == {"torque_enable": 0, "led": 0, "goal_position": 0, "present_position": 5000 - 4096}
    assert client.read(2, "return_delay_time") == 5
    assert client.read(3, "led") == 0 and client.read(3, "return_delay_time") == 250  # another servo: untouched


def test_broadcast_factory_reset_of_everything_is_ignored(client: DynamixelP2Client) -> None:
    for servo in (1, 2):
        assert client.write(servo, return_delay_time=7) is True
    assert client.factory_reset(client.BROADCAST, 0xFF) is None  # ignored, and nobody answers a broadcast
    assert client.ping(2).model_number == 1020  # every id kept
    assert [client.read(s, "return_delay_time") for s in (1, 2)] == [7, 7]
    assert client.factory_reset(client.BROADCAST, 0x01) is None  # all but the id: carried out
    assert [client.read(s, "return_delay_time") for s in (1, 2)] == [250, 250]
