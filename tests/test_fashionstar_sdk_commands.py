"""Fashion Star commands 11..25 (from fashionstar-uart-sdk, not in 000): the SDK's own frames and calls.

Golden frames: each SDK call's bytes (captured from a fake port) equal our encoding of the same request, and our
encoded replies unpack to the same values in the SDK's handlers. Then the SDK's calls run against `serialspec sim`.
"""

from __future__ import annotations

import struct
import time
from collections.abc import Iterator
from typing import Any

import pytest
import serial
from serialspec.runtime.errors import EncodeError, RangeError
from serialspec_protocols import fashionstar_uart as fs
from serialspec_protocols.fashionstar_uart.client import FashionstarUartClient
from serialspec_protocols.fashionstar_uart.simulator import FashionstarUartSimulator

uservo = pytest.importorskip("fashionstar_uart_sdk.uservo")
pocket = pytest.importorskip("fashionstar_uart_sdk.uart_pocket_handler")


class CapturingPort:
    """Stands in for the SDK's serial port: keeps what it writes, never has anything to read."""

    in_waiting = 0

    def __init__(self) -> None:
        self.written: list[bytes] = []

    def write(self, data: bytes) -> None:
        self.written.append(bytes(data))


def sdk_frame(call: Any) -> bytes:
    port = CapturingPort()
    call(uservo.UartServoManager(port, srv_num=4))
    assert len(port.written) == 1
    return port.written[0]


GOLDEN = [
    (
        lambda sdk: sdk.set_servo_angle(1, 45.0, interval=300, t_acc=40, t_dec=60, power=500),
        fs.MoveByIntervalRequest(servo_id=1, angle=450, interval=300, t_acc=40, t_dec=60, power=500),
    ),
    (
        lambda sdk: sdk.set_servo_angle(2, -30.5, velocity=120.0, t_acc=30, t_dec=20),
        fs.MoveByVelocityRequest(servo_id=2, angle=-305, velocity=1200, t_acc=30, t_dec=20, power=0),
    ),
    (
        lambda sdk: sdk.set_servo_angle(3, 720.0, is_mturn=True, interval=2000, t_acc=100, t_dec=100),
        fs.MoveMturnByIntervalRequest(servo_id=3, angle=7200, interval=2000, t_acc=100, t_dec=100, power=0),
    ),
    (
        lambda sdk: sdk.set_servo_angle(3, -1080.0, is_mturn=True, velocity=300.0),
        fs.MoveMturnByVelocityRequest(servo_id=3, angle=-10800, velocity=3000, t_acc=20, t_dec=20, power=0),
    ),
    (lambda sdk: sdk.reset_multi_turn_angle(4), fs.ResetMturnAngleRequest(servo_id=4)),
    (lambda sdk: sdk.begin_async(), fs.BeginAsyncRequest()),
    (lambda sdk: sdk.end_async(1), fs.EndAsyncRequest(mode=fs.AsyncEnd.CANCEL)),
    (lambda sdk: sdk.set_origin_point(5), fs.SetOriginPointRequest(servo_id=5)),
    (
        lambda sdk: sdk.stop_on_control_mode(6, 0x12, 800),
        fs.StopOnControlModeRequest(servo_id=6, method=fs.StopMethod.DAMPING, power=800),
    ),
    (
        lambda sdk: sdk.send_sync_anglebyinterval(
            11, 2, [struct.pack("<BhHHHH", i, 100 * i, 500, 20, 20, 0) for i in (1, 2)]
        ),
        fs.SyncCommandRequest(
            command=11,
            blocks=tuple(
                fs.BlocksItem(
                    content=fs.encode(fs.MoveByIntervalRequest(servo_id=i, angle=100 * i, interval=500))[4:-1]
                )
                for i in (1, 2)
            ),
        ),
    ),
]


@pytest.mark.parametrize(("call", "request_"), GOLDEN, ids=[type(r).__name__ for _, r in GOLDEN])
def test_the_sdks_frame_is_our_encoding(call: Any, request_: fs.Message) -> None:
    frame = sdk_frame(call)
    assert frame == fs.encode(request_)
    assert fs.decode(frame, fs.Direction.REQUEST) == request_


@pytest.mark.filterwarnings("ignore::DeprecationWarning")  # the SDK calls its own deprecated update()
def test_the_multi_turn_move_without_ramps_is_command_13() -> None:
    """Without an interval the SDK works one out from its last known angle and sends command 13 (no ramps)."""
    port = CapturingPort()
    sdk = uservo.UartServoManager(port, srv_num=4)
    sdk.servos[1].set_angle(0.0)
    sdk.update = lambda **_: False  # the angle query would wait 100 ms for nothing
    sdk.set_servo_angle(1, 90.0, is_mturn=True, mean_dps=90.0)
    assert port.written[-1] == fs.encode(fs.MoveMturnRequest(servo_id=1, angle=900, interval=1000, power=0))


def test_the_sync_monitor_frame_and_its_replies() -> None:
    port = CapturingPort()
    sdk = uservo.UartServoManager(port, srv_num=4)
    sdk.monitor_update = lambda ids, timeout=0.1: {i: True for i in ids}
    sdk.send_sync_servo_monitor([1, 2])
    blocks = tuple(fs.BlocksItem(content=bytes([i])) for i in (1, 2))
    assert port.written[0] == fs.encode(fs.SyncCommandRequest(command=22, blocks=blocks))
    assert fs.decode(port.written[0], fs.Direction.REQUEST).to_fields()["blocks"] == [
        {"content": "01"},
        {"content": "02"},
    ]


def test_our_replies_unpack_in_the_sdks_handlers() -> None:
    sdk = uservo.UartServoManager(CapturingPort(), srv_num=4)
    monitor = fs.MonitorResponse(
        servo_id=2,
        voltage=7400,
        current=120,
        power=880,
        temperature=2048,
        status=fs.ServoStatus.EXECUTING,
        angle=-7215,
        turns=-2,
    )
    code, content = uservo.Packet.unpack(fs.encode(monitor))
    assert code == 22
    sdk.response_query_servo_monitor(content)
    info = sdk.servos[2]
    assert (info.voltage, info.current, info.power, info.status, info.angle, info.turn) == (
        7400,
        120,
        880,
        1,
        -721.5,
        -2,
    )
    assert info.temp == pytest.approx(25.0)  # 2048 of 4096 is the NTC at 25 °C
    code, content = uservo.Packet.unpack(fs.encode(fs.ReadMturnAngleResponse(servo_id=3, angle=36005, turns=10)))
    sdk.response_query_servo_angle_mturn(content)
    assert (code, sdk.servos[3].angle) == (16, 3600.5)


# --- the SDK against `serialspec sim` -----------------------------------------------------------------------------


SIM = ("fashionstar_uart.yaml", 0, 1, 2, 3)  # the `port` fixture (conftest.py): `serialspec sim` on a pseudo-terminal


@pytest.fixture
def sdk(port: str) -> Iterator[Any]:
    uart = serial.Serial(port, baudrate=115200, timeout=0)
    yield uservo.UartServoManager(uart, srv_num=4)
    uart.close()


def settle(read: Any, expected: float, seconds: float = 3.0) -> float:
    """Poll until the value is reached (moves take their time) or the deadline passes; the last value read."""
    deadline = time.monotonic() + seconds
    value = read()
    while value != pytest.approx(expected) and time.monotonic() < deadline:
        time.sleep(0.05)
        value = read()
    return float(value)


def test_sdk_moves_by_interval_and_by_velocity(sdk: Any) -> None:
    sdk.set_servo_angle(0, 45.0, interval=300)
    assert settle(lambda: sdk.query_servo_angle(0), 45.0) == pytest.approx(45.0)
    sdk.set_servo_angle(0, -30.0, velocity=300.0, t_acc=50, t_dec=50)
    assert settle(lambda: sdk.query_servo_angle(0), -30.0) == pytest.approx(-30.0)


def test_sdk_multi_turn_angle_turns_and_reset(sdk: Any) -> None:
    # The SDK's reads wait a fixed 100 ms and keep the last value they saw, so each is polled until it holds the
    # expected value (a reply that came late is taken by the next read).
    sdk.set_servo_angle(1, 740.5, is_mturn=True, interval=200)
    assert settle(lambda: sdk.query_servo_mturn_angle(1), 740.5) == pytest.approx(740.5)
    assert settle(lambda: sdk.query_servo_monitor(1, realtime=True).turn, 2) == 2
    info = sdk.servos[1]
    assert (info.angle_monitor, info.turn, info.voltage) == (740.5, 2, 7400)
    sdk.reset_multi_turn_angle(1)
    assert settle(lambda: sdk.query_servo_mturn_angle(1), 20.5) == pytest.approx(20.5)  # less two whole turns
    sdk.set_origin_point(1)
    assert settle(lambda: sdk.query_servo_mturn_angle(1), 0.0) == 0.0


def test_sdk_async_holds_moves_until_end_and_cancel_drops_them(sdk: Any, port: str) -> None:
    with FashionstarUartClient(port, timeout=1.0) as client:  # reads that wait for their reply
        start = client.read_angle(2)
        sdk.begin_async()
        sdk.set_servo_angle(2, 10.0, interval=50)
        time.sleep(0.2)
        assert client.read_angle(2) == start  # held
        sdk.end_async(0)
        assert settle(lambda: client.read_angle(2), 100) == 100
        sdk.begin_async()
        sdk.set_servo_angle(2, 20.0, interval=50)
        sdk.end_async(1)  # cancel
        time.sleep(0.2)
        assert client.read_angle(2) == 100


def test_sdk_sync_monitor_gets_one_reply_per_servo(sdk: Any) -> None:
    sdk.set_servo_angle(3, -12.5, interval=20)
    settle(lambda: sdk.query_servo_angle(3), -12.5)
    assert settle(lambda: sdk.send_sync_servo_monitor([0, 3], realtime=True)[3].angle_monitor, -12.5) == -12.5
    assert (sdk.servos[0].voltage, sdk.servos[3].voltage) == (7400, 7400)


def test_sdk_sync_move_reaches_every_listed_servo(port: str) -> None:
    arm = pocket.PortHandler(port, 115200)
    arm.openPort()
    try:
        options = {
            name: pocket.SyncPositionControlOptions(servo, target, 100, 0, 20, 20)
            for name, servo, target in (("base", 0, 1200), ("shoulder", 1, -900))
        }
        # sync command 25 carrying command 14 (multi-turn by interval); the SDK indexes its lists by servo id, so
        # it works only for ids 0..n-1
        arm.SyncPositionControl_EX(options)
        assert settle(lambda: arm.query_servo_mturn_angle(0), 120.0) == pytest.approx(120.0)
        assert settle(lambda: arm.query_servo_mturn_angle(1), -90.0) == pytest.approx(-90.0)
    finally:
        arm.closePort()


def test_sdk_stop_on_control_mode_stops_where_it_is(sdk: Any, port: str) -> None:
    with FashionstarUartClient(port, timeout=1.0) as client:
        sdk.set_servo_angle(2, 0.0, interval=20)
        settle(lambda: client.read_angle(2), 0)
        sdk.set_servo_angle(2, 170.0, interval=20000)
        time.sleep(0.2)
        sdk.stop_on_control_mode(2, 0x11, 500)
        stopped = client.read_angle(2)
        time.sleep(0.2)
        assert client.read_angle(2) == stopped
        assert 0 < stopped < 1700


def test_our_client_has_typed_methods_for_the_new_commands(port: str) -> None:
    with FashionstarUartClient(port, timeout=1.0) as client:
        client.move_mturn(1, -7250, 10)
        assert settle(lambda: client.read_mturn_angle(1).angle, -7250) == -7250
        reply = client.read_mturn_angle(1)
        assert (reply.angle, reply.turns) == (-7250, -2)
        monitor = client.monitor(1)
        assert (monitor.voltage, monitor.temperature, monitor.angle, monitor.turns) == (7400, 2048, -7250, -2)
        with pytest.raises(RangeError, match="velocity"):
            client.move_by_velocity(1, 0, 0)  # below the SDK's 1.0 °/s


def test_a_ramped_move_starts_and_ends_slowly() -> None:
    now = [0.0]
    simulator = FashionstarUartSimulator([1], clock=lambda: now[0])
    simulator.handle(fs.MoveByIntervalRequest(servo_id=1, angle=1000, interval=1000, t_acc=250, t_dec=250))
    device = simulator.devices[1]

    def at(t: float) -> float:
        now[0] = t
        return device.get("angle")

    assert at(0.125) == 42  # a quarter of the way through the ramp: 1/3 of a linear move's 125
    assert at(0.5) == 500
    assert at(0.875) == 958
    assert at(1.0) == 1000
    simulator.handle(fs.MoveByVelocityRequest(servo_id=1, angle=0, velocity=2000, t_acc=100, t_dec=100))
    now[0] = 1.0 + 0.5 + 0.1  # 1000 at 2000/s is 0.5 s, plus half of each ramp
    assert device.get("angle") == 0
    now[0] = 1.3
    assert 0 < device.get("angle") < 1000


def test_our_client_carries_typed_requests_in_one_sync_command(port: str) -> None:
    with FashionstarUartClient(port, timeout=1.0) as client:
        moves = [fs.MoveByIntervalRequest(servo_id=i, angle=-100 * i, interval=20) for i in (0, 1)]
        assert client.sync_command_of(moves) == []  # moves answer only when the response switch is on
        for i in (0, 1):
            assert settle(lambda i=i: client.read_angle(i), -100 * i) == -100 * i
        replies = client.sync_command_of([fs.MonitorRequest(servo_id=i) for i in (1, 0)])
        assert [(r.servo_id, r.angle) for r in replies] == [(1, -100), (0, 0)]  # type: ignore[attr-defined]
        with pytest.raises(EncodeError, match="one type"):
            client.sync_command_of([moves[0], fs.MonitorRequest(servo_id=1)])
        with pytest.raises(EncodeError, match="PingRequest cannot be carried"):
            client.sync_command_of([fs.PingRequest(servo_id=1)])


def test_the_executing_bit_is_set_while_the_servo_moves() -> None:
    now = [0.0]
    simulator = FashionstarUartSimulator([1], clock=lambda: now[0])
    device = simulator.devices[1]
    simulator.handle(fs.RotateRequest(servo_id=1, angle=900, interval=1000))
    now[0] = 0.5
    assert device.get("servo_status") == fs.ServoStatus.EXECUTING
    now[0] = 1.0
    assert device.get("servo_status") == 0


def test_a_sync_command_block_that_is_not_a_carried_request_is_ignored() -> None:
    simulator = FashionstarUartSimulator([1])
    short = fs.SyncCommandRequest(command=11, blocks=(fs.BlocksItem(content=b"\x01\x02"),))  # 2 of 11 bytes
    ping = fs.SyncCommandRequest(command=1, blocks=(fs.BlocksItem(content=b"\x01"),))  # not one it carries
    assert simulator.handle(short) == [] and simulator.handle(ping) == []
    assert simulator.devices[1].get("angle") == 0
    monitor = fs.SyncCommandRequest(command=22, blocks=(fs.BlocksItem(content=b"\x01"),))
    assert [fs.decode(frame, "response").COMMAND for _, frame in simulator.handle(monitor)] == ["monitor"]
