"""The generated FEETECH client against the generated virtual servos on a real pseudo-terminal: registers by name."""

from __future__ import annotations

import time
from collections.abc import Iterator

import pytest
from conftest import Running
from serialspec.runtime.errors import DeviceError, EncodeError, RangeError, Timeout
from serialspec_protocols.feetech_sms.client import FeetechSmsClient
from serialspec_protocols.feetech_sms.registers import CONTROL_TABLE
from serialspec_protocols.feetech_sms.simulator import FeetechSmsSimulator

TIMEOUT = 1.0


SIMULATOR = (FeetechSmsSimulator, [1, 2, 3])  # the `sim` fixture (conftest.py)


@pytest.fixture
def client(sim: Running) -> Iterator[FeetechSmsClient]:
    with FeetechSmsClient(sim.path, timeout=TIMEOUT) as c:
        yield c


def test_ping(client: FeetechSmsClient) -> None:
    assert client.ping(1) is True
    client.bus.timeout = 0.05
    assert client.ping(9) is False


def test_a_command_with_an_empty_reply_raises_timeout_when_none_comes(client: FeetechSmsClient) -> None:
    """WRITE, REG WRITE, ACTION and RESET are answered by a status packet that carries nothing else: they returned
    False to an absent servo, as if it had refused. Only PING (`probe: true` in the spec) says False; every other
    command whose reply is due raises Timeout, and one whose reply is not due (broadcast) returns None."""
    client.bus.timeout = 0.05
    for call in (
        lambda: client.write(9, goal_position=2048),
        lambda: client.write_raw(9, 0x2A, b"\x00\x08"),
        lambda: client.reg_write(9, goal_position=2048),
        lambda: client.action(9),
        lambda: client.reset(9),
    ):
        with pytest.raises(Timeout, match="from id=9 within 50 ms"):
            call()
    assert client.write(1, goal_position=2048) is True
    assert client.action(254) is None  # broadcast: no reply due, none waited for


def test_registers_by_name(client: FeetechSmsClient) -> None:
    assert client.read(2, "torque_limit") == 1000  # the spec's default
    assert client.write(2, torque_limit=640) is True
    assert client.read(2, "torque_limit") == 640
    assert client.read(3, "torque_limit") == 1000  # other servos keep theirs
    assert client.read_many(2, "present_voltage", "present_temperature") == {
        "present_voltage": 74,
        "present_temperature": 30,
    }


def test_a_read_by_name_sent_again_is_still_checked_before_a_byte(client: FeetechSmsClient, sim: Running) -> None:
    # the first read of (device, register) is checked and encoded; the next ones send that frame as it was
    assert client.read(1, "present_position") == client.read(1, "present_position")
    sent = len(sim.device.log)
    for bad in (True, 1.0):  # equal to 1 and hashed alike, yet not a device id
        with pytest.raises(EncodeError, match="id"):
            client.read(bad, "present_position")  # type: ignore[arg-type]
    with pytest.raises(RangeError, match="id = 255"):
        client.read(255, "present_position")
    with pytest.raises(EncodeError, match="unknown register 'speed'"):
        client.read(1, "speed")  # type: ignore[arg-type]
    time.sleep(0.05)
    assert len(sim.device.log) == sent
    assert client.read(2, "torque_limit") == 1000  # another device's read: checked and encoded afresh


def test_sign_magnitude_registers_keep_their_sign_bit(client: FeetechSmsClient) -> None:
    assert client.write(1, position_offset=-100) is True  # sign in bit 11, not 15
    assert client.read_raw(1, CONTROL_TABLE["position_offset"].address, 2) == (100 | 1 << 11).to_bytes(2, "little")
    assert client.read(1, "position_offset") == -100


def test_write_moves_the_servo_over_goal_time(client: FeetechSmsClient) -> None:
    assert client.write(1, goal_position=2048, goal_time=300, goal_speed=0) is True
    time.sleep(0.1)
    assert 0 < client.read(1, "present_position") < 2048  # on the way
    time.sleep(0.3)
    assert client.read(1, "present_position") == 2048


def test_reg_write_waits_for_action(client: FeetechSmsClient) -> None:
    assert client.reg_write(2, goal_position=500, goal_time=0, goal_speed=0) is True
    assert client.read(2, "goal_position") == 0
    assert client.action(254) is None  # broadcast: no servo answers
    assert client.read(2, "goal_position") == 500
    assert client.read(2, "present_position") == 500


def test_sync_write_by_register_name(client: FeetechSmsClient, sim: Running) -> None:
    client.sync_write({1: {"goal_position": 100}, 3: {"goal_position": 300}})
    assert [client.read(servo, "goal_position") for servo in (1, 2, 3)] == [100, 0, 300]
    frame = sim.device.log[-4]  # the SYNC WRITE itself, before the three reads
    assert type(frame).__name__ == "SyncWriteRequest"


def test_sync_read_collects_every_listed_servo(client: FeetechSmsClient) -> None:
    client.sync_write({1: {"torque_limit": 100}, 2: {"torque_limit": 200}, 3: {"torque_limit": 300}})
    values = client.sync_read([3, 1], "torque_limit", "lock")
    assert values == {3: {"torque_limit": 300, "lock": 0}, 1: {"torque_limit": 100, "lock": 0}}
    client.bus.timeout = 0.05
    with pytest.raises(Timeout, match="id=9"):
        client.sync_read([1, 9], "torque_limit")
    client.bus.timeout = TIMEOUT
    assert client.read(1, "torque_limit") == 100  # the bus is usable again


def test_bad_arguments_are_refused_before_a_byte_is_written(client: FeetechSmsClient, sim: Running) -> None:
    sent = len(sim.device.log)
    with pytest.raises(RangeError, match=r"torque_limit = 1001 is outside its range 0\.\.1000"):
        client.write(1, torque_limit=1001)
    with pytest.raises(EncodeError, match="present_position is read-only"):
        client.write(1, present_position=5)
    with pytest.raises(EncodeError, match="not adjacent registers"):
        client.write(1, goal_position=5, torque_limit=100)
    with pytest.raises(EncodeError, match="unknown register 'speed'"):
        client.write(1, speed=5)
    with pytest.raises(EncodeError, match="the same registers"):
        client.sync_write({1: {"goal_position": 1}, 2: {"goal_speed": 1}})
    with pytest.raises(EncodeError, match="broadcast"):
        client.read(254, "present_position")
    time.sleep(0.05)
    assert len(sim.device.log) == sent


def test_status_bits_raise_device_error(client: FeetechSmsClient, sim: Running) -> None:
    sim.device.devices[1].set("status", 1 << 2)  # the status register the device reports in every reply's error byte
    with pytest.raises(DeviceError, match="overheat"):
        client.read(1, "present_position")
    sim.device.devices[1].set("status", 0)
    assert client.read(1, "present_position") == 0  # the bus is usable again


def test_response_level_switches_replies_off(client: FeetechSmsClient, sim: Running) -> None:
    assert client.write(3, response_level=0) is True  # this reply still comes: the level changes after it
    started = time.monotonic()
    assert client.write(3, torque_limit=300) is None  # the client knows the servo stays silent: no wait
    assert time.monotonic() - started < TIMEOUT / 2
    assert client.read(3, "torque_limit") == 300  # READ is always answered
    assert client.ping(3) is True
