"""The bus over real pseudo-terminals: fast replies, matching, typed errors after which the bus still works."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
import tty
from collections.abc import Iterator

import pytest
from serialspec.runtime.errors import CorruptReply, PortError, RangeError, Timeout
from serialspec.runtime.message import Message
from serialspec.runtime.transport import Bus
from serialspec_protocols.fashionstar_uart import PingRequest, ReadAngleRequest, ReadAngleResponse, encode
from serialspec_protocols.fashionstar_uart.client import BINDING, FashionstarUartClient
from serialspec_protocols.fashionstar_uart.simulator import FashionstarUartSimulator
from sim_process import ROOT

TIMEOUT = 1.0  # generous: the tests assert that replies come well before it, never an absolute speed


@pytest.fixture
def sim() -> Iterator[tuple[FashionstarUartSimulator, str]]:
    simulator = FashionstarUartSimulator(ids=[1, 2])
    path = simulator.start()
    yield simulator, path
    simulator.close()


def test_read_returns_as_soon_as_the_reply_is_complete(sim: tuple[FashionstarUartSimulator, str]) -> None:
    _, path = sim
    with Bus(path, BINDING, timeout=TIMEOUT) as bus:
        started = time.perf_counter()
        for _ in range(10):
            reply = bus.request(ReadAngleRequest(servo_id=1), ReadAngleResponse)
            assert reply.servo_id == 1
        elapsed = (time.perf_counter() - started) / 10
    assert elapsed < TIMEOUT / 4


def test_timeout_names_command_and_id_and_bus_stays_usable(sim: tuple[FashionstarUartSimulator, str]) -> None:
    _, path = sim
    with Bus(path, BINDING, timeout=0.05) as bus:
        for timeout in (None, 0.03):  # the bus's, then the call's own
            with pytest.raises(Timeout) as failure:
                bus.request(ReadAngleRequest(servo_id=7), ReadAngleResponse, timeout=timeout)
            # the timeout, not what was left of it after the first read (`within -5 ms`, `-0 ms`)
            wanted = 0.05 if timeout is None else timeout
            assert str(failure.value) == f"no reply to read_angle from servo_id=7 within {wanted * 1000:.0f} ms"
            assert failure.value.timeout == wanted
        assert bus.request(ReadAngleRequest(servo_id=2), ReadAngleResponse).servo_id == 2


@pytest.mark.parametrize("fault", ["corrupt", "drop", "late", "garbage"])
def test_faults(sim: tuple[FashionstarUartSimulator, str], fault: str) -> None:
    simulator, path = sim
    seen: list[Message] = []
    with Bus(path, BINDING, timeout=0.2) as bus:
        bus.subscribe(seen.append)
        simulator.inject(fault, delay=0.3)
        if fault == "corrupt":
            with pytest.raises(CorruptReply, match="read_angle"):
                bus.request(ReadAngleRequest(servo_id=1), ReadAngleResponse)
        elif fault in ("drop", "late"):
            with pytest.raises(Timeout):
                bus.request(ReadAngleRequest(servo_id=1), ReadAngleResponse)
        else:  # garbage before the reply: the parser resynchronises
            assert bus.request(ReadAngleRequest(servo_id=1), ReadAngleResponse).servo_id == 1
        if fault == "late":
            time.sleep(0.2)  # let the late reply arrive between transactions
        assert bus.request(ReadAngleRequest(servo_id=2), ReadAngleResponse).servo_id == 2
    if fault == "late":
        assert [m.COMMAND for m in seen] == ["read_angle"]  # the late reply went to subscribers


@pytest.mark.parametrize("fault", ["corrupt", "other_id", "late", "truncate"])
def test_faults_in_a_reply_of_the_size_the_last_one_had(sim: tuple[FashionstarUartSimulator, str], fault: str) -> None:
    """After a reply of a type, a read of its size is decoded at once, without the stream parser: every fault in
    such a read is still caught as the parser would catch it, and the bus goes on."""
    simulator, path = sim
    seen: list[Message] = []
    with Bus(path, BINDING, timeout=0.2) as bus:
        bus.subscribe(seen.append)
        assert bus.request(ReadAngleRequest(servo_id=1), ReadAngleResponse).servo_id == 1  # its size is known now
        simulator.inject(fault, delay=0.3)
        if fault == "corrupt":
            with pytest.raises(CorruptReply, match="corrupt reply to read_angle from servo_id=1"):
                bus.request(ReadAngleRequest(servo_id=1), ReadAngleResponse)
        elif fault == "truncate":
            with pytest.raises(CorruptReply, match="incomplete reply to read_angle"):
                bus.request(ReadAngleRequest(servo_id=1), ReadAngleResponse)
        else:  # another servo's answer of the same size is no reply; a late one comes after the timeout
            with pytest.raises(Timeout, match="servo_id=1"):
                bus.request(ReadAngleRequest(servo_id=1), ReadAngleResponse)
        if fault == "late":
            time.sleep(0.2)  # let the late reply arrive between transactions
        for _ in range(3):
            assert bus.request(ReadAngleRequest(servo_id=1), ReadAngleResponse).servo_id == 1
    expected = {"other_id": [("read_angle", 2)], "late": [("read_angle", 1)]}.get(fault, [])
    assert [(m.COMMAND, getattr(m, "servo_id", None)) for m in seen] == expected


def test_threads_never_interleave(sim: tuple[FashionstarUartSimulator, str]) -> None:
    _, path = sim
    errors: list[BaseException] = []
    with FashionstarUartClient(path, timeout=TIMEOUT) as client:

        def work(servo_id: int) -> None:
            try:
                for _ in range(20):
                    assert client.ping(servo_id)
                    assert client.read_parameter(servo_id, "servo_id") == servo_id
            except BaseException as exc:  # noqa: BLE001 - reported below
                errors.append(exc)

        threads = [threading.Thread(target=work, args=(i,)) for i in (1, 2, 1, 2)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    assert errors == []


def test_range_checked_before_a_byte_is_written(sim: tuple[FashionstarUartSimulator, str]) -> None:
    simulator, path = sim
    with FashionstarUartClient(path, timeout=TIMEOUT) as client:
        with pytest.raises(RangeError, match="servo_id = 300"):
            client.ping(300)
        with pytest.raises(RangeError, match="angle"):
            client.rotate(1, 40000, 100)
        assert client.ping(1)
    assert [type(m).__name__ for m in simulator.log] == ["PingRequest"]


def test_port_error() -> None:
    with pytest.raises(PortError, match="cannot open"):
        Bus("/dev/no-such-serial-port", BINDING)


def test_loop_url_hands_unmatched_frames_to_subscribers() -> None:
    """loop:// echoes requests back: they answer nothing, so they go to subscribers and the request times out."""
    seen: list[Message] = []
    binding = BINDING
    with Bus("loop://", binding, timeout=0.05) as bus:
        bus.subscribe(seen.append)
        bus.send(PingRequest(servo_id=3))
        assert bus.receive(0.05) is None  # a request echoed on a response parser is not a frame for us
    assert seen == []


def test_monitor_prints_frames_and_bad_frames() -> None:
    controller, device = os.openpty()
    tty.setraw(device)
    tty.setraw(controller)
    path = os.ttyname(device)
    args = [
        sys.executable,
        "-m",
        "serialspec",
        "monitor",
        str(ROOT / "specs" / "fashionstar_uart.yaml"),
        "--port",
        path,
        "--count",
        "3",
        "--duration",
        "10",
    ]
    process = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert process.stderr is not None
    assert "monitor" in process.stderr.readline()  # the port is open
    good = encode(ReadAngleRequest(servo_id=1))
    reply = encode(ReadAngleResponse(servo_id=1, angle=902))
    bad = reply[:-1] + bytes([reply[-1] ^ 0xFF])
    os.write(controller, good)
    time.sleep(0.05)
    os.write(controller, bad)
    time.sleep(0.05)
    os.write(controller, reply)
    out, err = process.communicate(timeout=10)
    os.close(controller)
    os.close(device)
    lines = out.splitlines()
    assert len(lines) == 3, (out, err)
    assert " request read_angle " in lines[0] and good.hex(" ") in lines[0]
    assert " BAD " in lines[1]
    assert " response read_angle " in lines[2] and '"angle": 902' in lines[2]


def test_a_refused_setting_is_a_port_error_naming_it() -> None:
    """A driver that refuses a setting makes pyserial raise termios.error: the bus says which setting instead."""
    import serial

    serial.protocol_handler_packages.append("refusing_ports")
    controller, device = os.openpty()
    try:
        path = os.ttyname(device)
        with pytest.raises(PortError, match=r"refusing://.*: the port refuses parity = even \(.*Invalid argument"):
            Bus(f"refusing://{path}", BINDING, parity="E")
        with Bus(f"refusing://{path}", BINDING, parity="O") as bus:  # every other setting is taken
            assert bus.port_name
    finally:
        serial.protocol_handler_packages.remove("refusing_ports")
        os.close(controller)
        os.close(device)


def test_a_value_out_of_range_is_one_error_not_two_chained(sim: tuple[FashionstarUartSimulator, str]) -> None:
    """The tutorial's last step printed its RangeError twice, joined by "During handling of the above exception,
    another exception occurred": the fast encoder's error, then encode's own, raised inside its handler."""
    _, path = sim
    with Bus(path, BINDING, timeout=0.2) as bus:
        with pytest.raises(RangeError) as failure:
            bus.request(ReadAngleRequest(servo_id=300), ReadAngleResponse)
        assert str(failure.value) == "read_angle request: servo_id = 300 is outside its range 0..254"
        assert failure.value.__context__ is None and failure.value.__cause__ is None
        assert bus.request(ReadAngleRequest(servo_id=1), ReadAngleResponse).servo_id == 1
