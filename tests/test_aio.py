"""The generated asyncio clients (`<protocol>.aio`) against `serialspec sim` processes on real pseudo-terminals:
the same methods as the blocking clients, the same checks before a byte is written and the same errors, several
devices on one bus from concurrent tasks, a loop that keeps running while a reply is awaited, cancellation."""

from __future__ import annotations

import asyncio
import importlib
import inspect
from pathlib import Path

import pytest
from conftest import PACKAGES, SHIPPED
from serialspec.cli import capture
from serialspec.runtime.errors import DeviceError, EncodeError, RangeError, Timeout
from sim_process import ROOT, serve

TIMEOUT = 1.0  # generous: tests wait for replies, they never time them
PROTOCOLS = sorted(p.name for p in PACKAGES.iterdir() if (p / "aio.py").is_file())


def clients(protocol: str) -> list[tuple[type, type]]:
    """(blocking class, asyncio class) of every client class of a package: the client and its groups."""
    sync = importlib.import_module(f"{SHIPPED}.{protocol}.client")
    aio = importlib.import_module(f"{SHIPPED}.{protocol}.aio")
    return [(getattr(sync, name.removeprefix("Async")), getattr(aio, name)) for name in aio.__all__]


def test_every_generated_package_has_an_aio_module() -> None:
    assert sorted(p.parent.name for p in PACKAGES.glob("*/client.py")) == PROTOCOLS
    binary = sorted(p.stem for p in (ROOT / "specs").glob("*.yaml") if "kind: text" not in p.read_text("utf-8"))
    assert binary == PROTOCOLS  # every binary spec's package, each with its asyncio client (text ones have none)


@pytest.mark.parametrize("protocol", PROTOCOLS)
def test_the_async_client_mirrors_the_blocking_one(protocol: str) -> None:
    """Every method of the blocking client, by the same name and parameters; those that talk to the device are
    coroutines (or an async iterator: reports), the others stay plain (subscribe, on_<report>)."""
    for sync_class, async_class in clients(protocol):
        methods = [name for name in vars(sync_class) if inspect.isfunction(vars(sync_class)[name])]
        assert {name for name in vars(async_class) if inspect.isfunction(vars(async_class)[name])} == {
            "__aenter__" if name == "__enter__" else name for name in methods
        }
        for name in methods:
            method, twin = getattr(sync_class, name), getattr(async_class, name.replace("__enter__", "__aenter__"))
            assert list(inspect.signature(twin).parameters) == list(inspect.signature(method).parameters), name
            assert [p.default for p in inspect.signature(twin).parameters.values()] == [
                p.default for p in inspect.signature(method).parameters.values()
            ]
            if name == "reports":
                assert inspect.isasyncgenfunction(twin)
            elif name == "__init__" or name.startswith("on_"):  # no I/O: subscribing a callback
                assert not inspect.iscoroutinefunction(twin), name
            else:
                assert inspect.iscoroutinefunction(twin), name


def requests_in(tap: Path) -> list[bytes]:
    with tap.open(encoding="utf-8") as lines:
        return [chunk.data for _, chunk in capture.read(lines) if chunk.direction == "request"]


def test_feetech_servos_registers_errors_and_checks_before_a_byte(tmp_path: Path) -> None:
    from serialspec_protocols.feetech_sms.aio import AsyncFeetechSmsClient

    tap = tmp_path / "session.capture"

    async def session(path: str) -> None:
        async with AsyncFeetechSmsClient(path, timeout=TIMEOUT) as servos:
            assert await servos.ping(1) is True
            assert await servos.read(1, "torque_limit") == 1000  # the spec's default
            assert await servos.read(1, "model_number") == 777
            assert await servos.write(1, goal_position=2048, goal_time=0, goal_speed=0) is True
            assert await servos.read_many(1, "goal_position", "goal_time") == {"goal_position": 2048, "goal_time": 0}
            await servos.sync_write({1: {"goal_position": 100}, 2: {"goal_position": 300}})
            assert await servos.sync_read([1, 2], "goal_position") == {
                1: {"goal_position": 100},
                2: {"goal_position": 300},
            }
            assert await servos.reg_write(2, goal_position=1000, goal_time=0, goal_speed=0) is True
            assert await servos.action(254) is None  # broadcast: no reply, no wait
            assert await servos.read(2, "goal_position") == 1000
            written = len(requests_in(tap))
            with pytest.raises(RangeError, match="torque_limit = 1001 is outside its range 0..1000"):
                await servos.write(1, torque_limit=1001)
            with pytest.raises(RangeError, match="id = 255"):
                await servos.read(255, "present_position")
            with pytest.raises(EncodeError, match="unknown register 'speed'"):
                await servos.read(1, "speed")  # type: ignore[arg-type]
            assert len(requests_in(tap)) == written  # nothing of them reached the bus
            servos.bus.timeout = 0.05
            assert await servos.ping(7) is False
            with pytest.raises(Timeout, match="read from id=7"):
                await servos.read_raw(7, 0x38, 2)

    with serve("feetech_sms.yaml", 1, 2, options=["--tap", str(tap)]) as path:
        asyncio.run(session(path))


def test_concurrent_tasks_on_one_bus_each_get_their_own_devices_replies() -> None:
    """Three servos with different positions, read by 3 x 40 tasks at once: every task gets its own servo's value
    (one lock per bus: a transaction's request and reply are never split by another task's)."""
    from serialspec_protocols.feetech_sms.aio import AsyncFeetechSmsClient

    async def session(path: str) -> None:
        async with AsyncFeetechSmsClient(path, timeout=TIMEOUT) as servos:
            for servo in (1, 2, 3):
                await servos.write(servo, torque_limit=100 * servo)

            async def read(servo: int) -> tuple[int, int]:
                await asyncio.sleep(0)
                return servo, await servos.read(servo, "torque_limit")

            results = await asyncio.gather(*(read(servo) for _ in range(40) for servo in (1, 2, 3)))
            assert len(results) == 120
            assert all(value == 100 * servo for servo, value in results), results

    with serve("feetech_sms.yaml", 1, 2, 3) as path:
        asyncio.run(session(path))


def test_the_loop_runs_while_a_reply_is_awaited_and_a_cancelled_read_leaves_the_bus_ready() -> None:
    from serialspec_protocols.dynamixel_p2.aio import AsyncDynamixelP2Client

    async def session(path: str) -> None:
        async with AsyncDynamixelP2Client(path, timeout=TIMEOUT) as servos:
            silent = asyncio.create_task(servos.read(9, "present_position"))  # no servo 9: waits out the timeout
            await asyncio.sleep(0)  # the read has written its request and waits for the reply
            await asyncio.sleep(0)
            assert not silent.done()  # ... without holding the loop: this task runs meanwhile
            silent.cancel()
            with pytest.raises(asyncio.CancelledError):
                await silent
            assert (await servos.ping(1)).model_number == 1020  # the bus is free and clean again
            with pytest.raises(TimeoutError):
                async with asyncio.timeout(0.05):
                    await servos.read(9, "present_position")
            assert await servos.read(1, "present_position") == await servos.read(1, "present_position")
            assert (await servos.ping(2)).model_number == 1020

    with serve("dynamixel_p2.yaml", 1, 2) as path:
        asyncio.run(session(path))


def test_modbus_exceptions_and_broadcast() -> None:
    from serialspec_protocols.modbus_rtu.aio import AsyncModbusRtuClient

    async def session(path: str) -> None:
        # no parity and 2 stop bits: some kernels' pseudo-terminals refuse the default even parity
        async with AsyncModbusRtuClient(path, timeout=TIMEOUT, parity="N", stopbits=2) as client:
            assert await client.write_registers(1, 10, [7, 8, 9]) == 3
            assert await client.read_holding_registers(1, 9, 5) == [0, 7, 8, 9, 0]
            assert await client.write_coils(2, 0, [True, False, True]) == 3
            assert await client.read_coils(2, 0, 3) == [True, False, True]
            with pytest.raises(DeviceError, match="read_holding_registers: .* illegal_data_address \\(2\\)"):
                await client.read_holding_registers(1, 199, 2)
            with pytest.raises(RangeError, match="count = 126"):
                await client.read_holding_registers(1, 0, 126)
            assert await client.write_register(0, 5, 99) is None  # broadcast: both servers, no reply
            assert await asyncio.gather(
                client.read_holding_registers(1, 5, 1), client.read_holding_registers(2, 5, 1)
            ) == [[99], [99]]

    with serve("modbus_rtu.yaml", 1, 2, options=["--size", "holding_registers=200"]) as path:
        asyncio.run(session(path))


def test_board_groups_and_reports_as_an_async_iterator() -> None:
    from serialspec_protocols.hiwonder_rrc.aio import AsyncHiwonderRrcClient
    from serialspec_protocols.hiwonder_rrc.messages import KeyResponse
    from serialspec_protocols.hiwonder_rrc.simulator import HiwonderRrcSimulator

    simulator = HiwonderRrcSimulator(ids=[1, 2])
    path = simulator.start()

    async def session() -> None:
        async with AsyncHiwonderRrcClient(path, timeout=TIMEOUT) as board:
            assert await board.bus_servo.read_position(1) == 500
            keys: list[KeyResponse] = []
            board.on_key(keys.append)
            simulator.emit(KeyResponse(button_id=1, event=1))
            reports = [report async for report in board.reports(0.2)]
            assert [type(r).__name__ for r in reports] == ["KeyResponse"] and keys == reports
            with pytest.raises(RangeError, match="servo_id = 300"):
                await board.bus_servo.read_position(300)

    try:
        asyncio.run(session())
    finally:
        simulator.close()
    assert [type(m).__name__ for m in simulator.log] == ["BusServoReadPositionRequest"]


def test_the_readme_asyncio_session_runs_as_printed() -> None:
    import contextlib
    import io
    import re

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    code = next(b for b in re.findall(r"```python\n(.*?)```", text, flags=re.S) if "AsyncFeetechSmsClient" in b)
    output = io.StringIO()
    with serve("feetech_sms.yaml", 1, 2) as port, contextlib.redirect_stdout(output):
        exec(compile(code.replace("/dev/pts/5", port), "README.md", "exec"), {})
    assert output.getvalue().splitlines() == ["True False", "[777, 1000]"]


def test_a_port_without_a_descriptor_for_the_loop_reads_in_a_worker_thread() -> None:
    """socket:// (no POSIX serial port to watch): the same client over a TCP bridge to the sim's pseudo-terminal."""
    import os
    import select
    import socket
    import threading

    from serialspec_protocols.modbus_rtu.aio import AsyncModbusRtuClient

    with serve("modbus_rtu.yaml", 1) as path, socket.create_server(("127.0.0.1", 0)) as server:
        device = os.open(path, os.O_RDWR | os.O_NOCTTY)
        stop = threading.Event()

        def bridge() -> None:
            connection, _ = server.accept()
            with connection:
                while not stop.is_set():
                    ready, _, _ = select.select([connection, device], [], [], 0.05)
                    if connection in ready:
                        data = connection.recv(4096)
                        if not data:
                            return
                        os.write(device, data)
                    if device in ready:
                        connection.sendall(os.read(device, 4096))

        thread = threading.Thread(target=bridge, daemon=True)
        thread.start()

        async def session() -> None:
            url = f"socket://127.0.0.1:{server.getsockname()[1]}"
            async with AsyncModbusRtuClient(url, timeout=TIMEOUT) as client:
                assert await client.write_registers(1, 10, [7, 8]) == 2
                assert await asyncio.gather(
                    client.read_holding_registers(1, 10, 2), client.read_holding_registers(1, 11, 1)
                ) == [[7, 8], [8]]
                client.bus.timeout = 0.05
                with pytest.raises(Timeout):
                    await client.read_holding_registers(2, 0, 1)

        try:
            asyncio.run(session())
        finally:
            stop.set()
            thread.join(5)
            os.close(device)
