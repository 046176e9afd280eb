"""Every way a transaction can fail, against a virtual Fashion Star servo on a real pseudo-terminal.

Each fault must give its typed exception within the timeout + 10% (plus a little scheduling slack: a robustness
bound, not a speed target), and the next transaction on the same bus must succeed. A reply that comes too late must
never be taken for the answer to a later request: it goes to subscribers.

Then 8 threads share one client, each writing and reading back its own servo's values: every reply must be the
answer to its own request. `SERIALSPEC_STRESS_TRANSACTIONS` sets the transactions per thread: 1,000 by default
(a few seconds), 5,000 under `make stress`.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import serial
from serialspec.runtime.errors import CorruptReply, PortError, Timeout, TransportError
from serialspec.runtime.message import Message
from serialspec.runtime.transport import Bus
from serialspec_protocols.fashionstar_uart import (
    ReadAngleRequest,
    ReadAngleResponse,
    ReadDataRequest,
    ReadDataResponse,
    Result,
)
from serialspec_protocols.fashionstar_uart.client import BINDING, PARAMETERS, FashionstarUartClient
from serialspec_protocols.fashionstar_uart.simulator import FashionstarUartSimulator
from sim_process import serve

TIMEOUTS = [0.05, 0.2]
SLACK = 0.02  # scheduling slack on a loaded machine, on top of the 10%
TRANSACTIONS = int(os.environ.get("SERIALSPEC_STRESS_TRANSACTIONS", "1000"))  # per thread


def within_bound(elapsed: float, timeout: float) -> bool:
    return elapsed <= timeout * 1.1 + SLACK


class Servo:
    """A simulator on a pseudo-terminal, reached through a symlink (as /dev/serial/by-id/... reaches a device)."""

    def __init__(self, link: Path) -> None:
        self.link = link
        self.simulator: FashionstarUartSimulator
        self.plug_in()

    def plug_in(self) -> None:
        """A new simulator on a new pseudo-terminal behind the same path: the device unplugged and back."""
        self.simulator = FashionstarUartSimulator(ids=[1, 2])
        target = self.simulator.start()
        temporary = self.link.with_suffix(".new")
        temporary.symlink_to(target)
        temporary.replace(self.link)

    def unplug(self) -> None:
        self.simulator.close()


@pytest.fixture
def servo(tmp_path: Path) -> Iterator[Servo]:
    device = Servo(tmp_path / "servo")
    yield device
    device.unplug()


def read_angle(bus: Bus, servo_id: int, timeout: float | None = None) -> ReadAngleResponse:
    return bus.request(ReadAngleRequest(servo_id=servo_id), ReadAngleResponse, timeout=timeout)


def timed(action: Callable[[], Any]) -> tuple[BaseException | None, float]:
    """The exception `action` raised (None if it returned) and how long it took."""
    started = time.monotonic()
    try:
        action()
    except BaseException as exc:  # noqa: BLE001 - returned for the caller to check
        return exc, time.monotonic() - started
    return None, time.monotonic() - started


@pytest.mark.parametrize("timeout", TIMEOUTS)
@pytest.mark.parametrize(
    ("fault", "expected"),
    [
        ("drop", Timeout),
        ("late", Timeout),
        ("other_id", Timeout),  # the answer of servo 2 answers nothing: it goes to subscribers
        ("corrupt", CorruptReply),
        ("truncate", CorruptReply),  # half a reply: "incomplete reply" at the deadline
        ("garbage", None),  # garbage before the reply: the parser resynchronises and the reply is returned
    ],
)
def test_each_fault_gives_its_exception_in_time_and_the_bus_recovers(
    servo: Servo, fault: str, expected: type[TransportError] | None, timeout: float
) -> None:
    seen: list[Message] = []
    with Bus(str(servo.link), BINDING, timeout=timeout) as bus:
        bus.subscribe(seen.append)
        assert read_angle(bus, 1).servo_id == 1
        servo.simulator.inject(fault, delay=timeout * 1.5)
        error, elapsed = timed(lambda: read_angle(bus, 1))
        if expected is None:
            assert error is None
        else:
            assert isinstance(error, expected), repr(error)
            assert "read_angle from servo_id=1" in str(error)
        assert within_bound(elapsed, timeout), f"{fault}: {elapsed * 1000:.1f} ms for a {timeout * 1000:.0f} ms timeout"
        if expected is Timeout:
            assert elapsed >= timeout  # never gives up early
        if fault == "late":
            time.sleep(timeout)  # the late reply is now waiting on the port
        assert read_angle(bus, 1).servo_id == 1  # the next transaction succeeds...
        assert read_angle(bus, 2).servo_id == 2
    # ...and only the replies that answered nothing went to subscribers
    strays = {"late": [("read_angle", 1)], "other_id": [("read_angle", 2)]}.get(fault, [])
    assert [(m.COMMAND, getattr(m, "servo_id", None)) for m in seen] == strays


def test_a_late_reply_waiting_on_the_port_is_not_the_answer_to_the_next_request(servo: Servo) -> None:
    """The same command to the same servo again: only the bytes that arrive after the request may answer it."""
    timeout = 0.1
    key = PARAMETERS["over_current"]
    seen: list[Message] = []
    with FashionstarUartClient(str(servo.link), timeout=timeout) as client:
        client.subscribe(seen.append)
        servo.simulator.inject("late", delay=timeout * 2)
        with pytest.raises(Timeout):
            client.read_data(1, key)  # answered late with the value 1500
        assert client.write_data(1, key, 1600) == Result.SUCCESS
        time.sleep(timeout * 1.5)  # the late 1500 is waiting on the port now
        assert client.read_data(1, key) == 1600
    assert [(type(m), m.data) for m in seen if isinstance(m, ReadDataResponse)] == [(ReadDataResponse, 1500)]


def test_a_late_reply_arriving_during_the_next_transaction_goes_to_subscribers(servo: Servo) -> None:
    timeout = 0.1
    seen: list[Message] = []
    with Bus(str(servo.link), BINDING, timeout=timeout) as bus:
        bus.subscribe(seen.append)
        servo.simulator.inject("late", delay=timeout * 2)  # servo 1's reply comes at 0.2 s
        servo.simulator.inject("late", delay=timeout * 2)  # servo 2's at 0.1 + 0.2 s: servo 1's comes first
        with pytest.raises(Timeout):
            read_angle(bus, 1)
        assert read_angle(bus, 2, timeout=timeout * 5).servo_id == 2
    assert [(m.COMMAND, getattr(m, "servo_id", None)) for m in seen] == [("read_angle", 1)]


def test_the_device_going_away_is_a_port_error_and_the_bus_reopens_it_when_it_is_back(servo: Servo) -> None:
    timeout = 0.2
    with Bus(str(servo.link), BINDING, timeout=timeout) as bus:
        assert read_angle(bus, 1).servo_id == 1
        servo.simulator.inject("drop")
        unplug = threading.Timer(timeout / 4, servo.unplug)  # while the bus waits for the reply
        unplug.start()
        error, elapsed = timed(lambda: read_angle(bus, 1))
        unplug.join()
        assert isinstance(error, PortError), repr(error)
        assert within_bound(elapsed, timeout)
        error, _ = timed(lambda: read_angle(bus, 1))  # still away: reopening fails, in one line
        assert isinstance(error, PortError) and "cannot reopen" in str(error), repr(error)
        servo.plug_in()
        assert read_angle(bus, 1).servo_id == 1
        assert read_angle(bus, 2).servo_id == 2


def test_the_port_closed_under_a_waiting_transaction_is_a_port_error_and_the_next_one_reopens_it(
    servo: Servo,
) -> None:
    timeout = 0.2
    port = serial.Serial(str(servo.link), BINDING.serial.baudrate, timeout=timeout)
    with Bus(port, BINDING, timeout=timeout) as bus:
        servo.simulator.inject("drop")
        close = threading.Timer(timeout / 4, port.close)  # another thread closes the port while the bus waits
        close.start()
        error, elapsed = timed(lambda: read_angle(bus, 1))
        close.join()
        assert isinstance(error, PortError) and "closed" in str(error), repr(error)
        assert within_bound(elapsed, timeout)
        assert read_angle(bus, 1).servo_id == 1
    error, elapsed = timed(lambda: read_angle(bus, 1))  # the bus itself closed: it stays closed
    assert isinstance(error, PortError) and "the bus is closed" in str(error), repr(error)
    assert not port.is_open


@pytest.fixture(scope="module")
def eight_servos() -> Iterator[str]:
    with serve("fashionstar_uart.yaml", *range(1, 9)) as path:
        yield path


def test_threads_sharing_one_client_each_get_their_own_replies(eight_servos: str) -> None:
    """8 threads, each writing values only it writes to its own servo and reading them back."""
    key = PARAMETERS["over_current"]
    errors: list[BaseException] = []
    with FashionstarUartClient(eight_servos, timeout=1.0) as client:

        def work(servo_id: int) -> None:
            try:
                for i in range(TRANSACTIONS // 2):  # a write and a read each time
                    value = servo_id * 5000 + i % 5000
                    assert client.write_data(servo_id, key, value) == Result.SUCCESS
                    got = client.read_data(servo_id, key)
                    assert got == value, f"servo {servo_id} read {got} after writing {value}"
            except BaseException as exc:  # noqa: BLE001 - reported below
                errors.append(exc)

        threads = [threading.Thread(target=work, args=(servo_id,)) for servo_id in range(1, 9)]
        started = time.monotonic()
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        elapsed = time.monotonic() - started
        replies = [client.bus.request(ReadDataRequest(servo_id=i, data_id=key), ReadDataResponse) for i in range(1, 9)]
    assert errors == []
    assert [r.data for r in replies] == [i * 5000 + (TRANSACTIONS // 2 - 1) % 5000 for i in range(1, 9)]
    print(f"\nthreads: 8 x {TRANSACTIONS // 2 * 2} transactions on one bus in {elapsed:.1f} s, every reply its own")
