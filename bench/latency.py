"""Family 3: one read transaction over a pseudo-terminal, to a virtual device served by another process.

`serialspec sim specs/<spec>.yaml --id 1 --quiet` runs as a separate process (it prints the pty path first). The
benchmark process then times whole transactions, request written to reply decoded:

- generated: the generated client (Fashion Star `read_angle(1)`, FEETECH `read(1, "present_position")`, and in
  CASES Hiwonder RRC, DYNAMIXEL 2.0, Modbus RTU, VESC); the rows of a protocol appear once it has a virtual device;
- bare: pyserial `write(request)` then `read(len(reply))` with a 1 s timeout, what a user writes: no parsing at
  all, the floor (for Modbus RTU after the 3.5-character silence the protocol requires, as the generated bus);
- vendor SDK: the same read through the vendor's Python SDK (Fashion Star, FEETECH; none is installed for the rest).

Generated and bare alternate in blocks so that noise on the shared machine falls on both alike. Beside the median
and p99 wall time per transaction, the CPU time the benchmark process spent per transaction
(`time.process_time`) shows whether it waits by blocking or by spinning.
"""

from __future__ import annotations

import importlib
import importlib.util
import signal
import statistics
import struct
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import serial

from bench.timing import Table, percentile, times, us, verdict

ROOT = Path(__file__).resolve().parent.parent
TARGET = 1.10  # generated ≤ 1.10 × bare pyserial (median wall time)
CPU_TARGET = 1.2  # generated ≤ 1.2 × bare pyserial (CPU time per transaction): it blocks, never spins
BLOCKS = 40  # short alternating blocks: a burst of load on the shared machine falls on both sides alike
PER_BLOCK = 25
WARMUP = 20
SDK_PUBLIC_ROUNDS = 10  # the Fashion Star SDK's public read always waits out its 100 ms timeout


@dataclass
class Result:
    wall_ns: list[int]
    cpu_seconds: float

    @property
    def cpu_per_call_us(self) -> float:
        return self.cpu_seconds / len(self.wall_ns) * 1e6


class SimUnavailable(Exception):
    """The spec has no virtual device (yet), or the sim did not start."""


@contextmanager
def simulator(spec: str, device_id: int | None) -> Iterator[str]:
    """`serialspec sim` in another process; yields the pty path it prints first; stops it with SIGTERM."""
    name = Path(spec).stem
    if importlib.util.find_spec(f"{name}.simulator") is None:
        raise SimUnavailable(f"generated/{name}/simulator.py does not exist")
    command = [str(Path(sys.executable).parent / "serialspec"), "sim", spec, "--quiet"]
    if device_id is not None:  # None: a protocol without device addresses (VESC)
        command[3:3] = ["--id", str(device_id)]
    process = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert process.stdout is not None and process.stderr is not None
        path = process.stdout.readline().strip()
        if not path.startswith("/dev/"):
            process.wait(5)
            error = process.stderr.read().strip().splitlines()
            raise SimUnavailable(f"`serialspec sim {spec}` did not start: {error[-1] if error else 'no output'}")
        yield path
    finally:
        if process.poll() is None:
            process.send_signal(signal.SIGTERM)
            try:
                process.wait(5)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()


def _time(call: Callable[[], object], count: int, into: Result) -> None:
    perf = time.perf_counter_ns
    cpu_started = time.process_time()
    for _ in range(count):
        started = perf()
        call()
        into.wall_ns.append(perf() - started)
    into.cpu_seconds += time.process_time() - cpu_started


def side_by_side(calls: dict[str, Callable[[], object]]) -> dict[str, Result]:
    results = {name: Result([], 0.0) for name in calls}
    for call in calls.values():
        for _ in range(WARMUP):
            call()
    for _ in range(BLOCKS):
        for name, call in calls.items():
            _time(call, PER_BLOCK, results[name])
    return results


def alone(call: Callable[[], object], count: int) -> Result:
    result = Result([], 0.0)
    call()
    _time(call, count, result)
    return result


def bare_read(port: serial.Serial, request: bytes, reply_size: int, gap: float = 0.0) -> Callable[[], bytes]:
    """What a user writes with pyserial alone: write the request, read(n) the reply whose size n is known. With
    `gap` (Modbus RTU's 3.5 characters of silence before a frame, in seconds) it first waits that long after the
    last byte read, as the protocol requires and the generated bus does."""
    last = 0.0

    def transact() -> bytes:
        port.write(request)
        reply = port.read(reply_size)
        if len(reply) != reply_size:
            raise RuntimeError(f"bare read got {len(reply)} of {reply_size} bytes")
        return reply

    def transact_after_gap() -> bytes:
        nonlocal last
        wait = last + gap - time.monotonic()
        if wait > 0:
            time.sleep(wait)
        reply = transact()
        last = time.monotonic()
        return reply

    return transact_after_gap if gap else transact


def reply_size(port: serial.Serial, request: bytes) -> int:
    """The size of the device's reply to `request`, by asking once (the bare read needs it to read(n))."""
    port.write(request)
    time.sleep(0.2)
    size = len(port.read(port.in_waiting))
    if not size:
        raise RuntimeError(f"no reply to {request.hex(' ')}")
    return size


def fashionstar(path: str) -> dict[str, Result]:
    fs = importlib.import_module("serialspec_protocols.fashionstar_uart")
    client_module = importlib.import_module("fashionstar_uart.client")
    from fashionstar_uart_sdk import uservo
    from fashionstar_uart_sdk.uart_pocket_handler import PortHandler

    request = fs.encode(fs.ReadAngleRequest(servo_id=1))
    reply_size = len(fs.encode(fs.ReadAngleResponse(servo_id=1, angle=0)))
    results: dict[str, Result] = {}
    with (
        client_module.FashionstarUartClient(path, timeout=1.0) as client,
        serial.Serial(path, fs.BAUDRATE, timeout=1.0) as bare,
    ):
        assert isinstance(client.read_angle(1), int)
        results.update(
            side_by_side({"generated": lambda: client.read_angle(1), "bare": bare_read(bare, request, reply_size)})
        )
    with serial.Serial(path, fs.BAUDRATE, timeout=0) as port:
        manager = uservo.UartServoManager(port, srv_num=4)
        assert manager.query_servo_angle(1) is not None
        results["sdk"] = alone(lambda: manager.query_servo_angle(1), SDK_PUBLIC_ROUNDS)
    handler = PortHandler(path, fs.BAUDRATE)
    handler.openPort()
    try:

        def quick_read() -> object:
            # PortHandler's own pattern for ping/monitor: send, then quick_update returns once a packet is in
            handler.send_request(handler.CODE_QUERY_SERVO_ANGLE, struct.pack("<B", 1))
            if not handler.quick_update(wait_response=True):
                raise RuntimeError("the SDK's quick_update saw no reply")
            return handler.servos[1].angle

        results["sdk_quick"] = alone(quick_read, BLOCKS * PER_BLOCK // 2)
    finally:
        handler.closePort()
    return results


def feetech(path: str) -> tuple[dict[str, Result], str]:
    sms = importlib.import_module("serialspec_protocols.feetech_sms")
    client_module = importlib.import_module("feetech_sms.client")
    from scservo_sdk import PortHandler, sms_sts

    request_message = sms.ReadRequest(id=1, address=0x38, length=2)  # present position, 2 bytes
    request = sms.encode(request_message)
    reply_size = len(sms.encode(sms.ReplyResponse(id=1, error=sms.ErrorStatus(0), data=b"\0\0")))
    results: dict[str, Result] = {}
    with (
        client_module.FeetechSmsClient(path, timeout=1.0) as client,
        serial.Serial(path, sms.BAUDRATE, timeout=1.0) as bare,
    ):
        # the client's read by register name, decoded like scservo_sdk's ReadPos; the bare bus transaction if the
        # client has no such method (its API is still changing)
        how = 'client.read(1, "present_position")'
        read: Callable[[], Any] = lambda: client.read(1, "present_position")  # noqa: E731
        try:
            reply = read()
        except (TypeError, AttributeError):
            how = "client.bus.request(ReadRequest(1, 0x38, 2), ReplyResponse)"
            read = lambda: client.bus.request(request_message, sms.ReplyResponse)  # noqa: E731
            reply = read()
        assert reply is not None
        results.update(side_by_side({"generated": read, "bare": bare_read(bare, request, reply_size)}))
    port = PortHandler(path)
    if not port.openPort():
        raise RuntimeError(f"scservo_sdk could not open {path}")
    try:
        servo = sms_sts(port)
        position, outcome, _ = servo.ReadPos(1)
        if outcome != 0:
            raise RuntimeError(f"scservo_sdk ReadPos failed: {servo.getTxRxResult(outcome)}")
        results["sdk"] = alone(lambda: servo.ReadPos(1), BLOCKS * PER_BLOCK // 2)
    finally:
        port.closePort()
    return results, how


@dataclass(frozen=True)
class Case:
    """A protocol timed against bare pyserial only (no vendor SDK in the bench): its generated client's read."""

    protocol: str
    client_class: str
    how: str  # the call, as shown in the table
    call: Callable[[Any], object]
    request: Callable[[Any], object]  # the same request as a message of the protocol's package
    device_id: int | None = 1  # the virtual device's address; None where frames carry none


CASES = (
    Case(
        "hiwonder_rrc",
        "HiwonderRrcClient",
        "client.bus_servo.read_position(1)",
        lambda client: client.bus_servo.read_position(1),
        lambda rrc: rrc.BusServoReadPositionRequest(servo_id=1),
    ),
    Case(
        "dynamixel_p2",
        "DynamixelP2Client",
        'client.read(1, "present_position")',
        lambda client: client.read(1, "present_position"),
        lambda dxl: dxl.ReadRequest(id=1, address=132, length=4),
    ),
    Case(
        "modbus_rtu",
        "ModbusRtuClient",
        "client.read_holding_registers(1, 0, 2)",
        lambda client: client.read_holding_registers(1, 0, 2),
        lambda mb: mb.ReadHoldingRegistersRequest(unit=1, address=0, count=2),
    ),
    Case(
        "vesc",
        "VescClient",
        "client.get_values()",
        lambda client: client.get_values(),
        lambda vesc: vesc.GetValuesRequest(),
        device_id=None,
    ),
)


def plain(case: Case, path: str) -> tuple[dict[str, Result], int, int, float]:
    """The generated client and bare pyserial side by side; also the request and reply sizes, and the gap."""
    package = importlib.import_module(case.protocol)
    client_class = getattr(importlib.import_module(f"{case.protocol}.client"), case.client_class)
    request = package.encode(case.request(package))
    with (
        client_class(path, timeout=1.0) as client,
        serial.Serial(path, package.BAUDRATE, timeout=1.0) as bare,
    ):
        case.call(client)
        size = reply_size(bare, request)
        gap = client.bus._gap  # the silence the protocol needs before a frame (Modbus RTU), on both sides
        results = side_by_side({"generated": lambda: case.call(client), "bare": bare_read(bare, request, size, gap)})
    return results, len(request), size, gap


def _row(protocol: str, what: str, result: Result, bare: Result | None, target: bool) -> list[str]:
    median = statistics.median(result.wall_ns)
    ratio = median / statistics.median(bare.wall_ns) if bare is not None else None
    cpu_ratio = result.cpu_per_call_us / bare.cpu_per_call_us if bare is not None else None
    verdicts = "—"
    if target and ratio is not None and cpu_ratio is not None:
        verdicts = f"≤ {TARGET}×: {verdict(ratio <= TARGET)}; CPU ≤ {CPU_TARGET}×: {verdict(cpu_ratio <= CPU_TARGET)}"
    return [
        protocol,
        what,
        str(len(result.wall_ns)),
        us(median),
        us(percentile(result.wall_ns, 0.99)),
        f"{result.cpu_per_call_us:.0f}",
        f"{result.cpu_seconds / (sum(result.wall_ns) / 1e9):.0%}",
        times(ratio) if ratio is not None else "—",
        times(cpu_ratio) if cpu_ratio is not None else "—",
        verdicts,
    ]


def run() -> Table:
    rows = []
    notes = []
    with simulator("specs/fashionstar_uart.yaml", 1) as path:
        fs = fashionstar(path)
    rows += [
        _row("fashionstar_uart", "generated client `read_angle(1)`", fs["generated"], fs["bare"], True),
        _row("fashionstar_uart", "bare pyserial write 6 B + read(8)", fs["bare"], fs["bare"], False),
        _row("fashionstar_uart", "SDK `UartServoManager.query_servo_angle(1)`", fs["sdk"], fs["bare"], False),
        _row("fashionstar_uart", "SDK `PortHandler` send_request + quick_update", fs["sdk_quick"], fs["bare"], False),
    ]
    notes.append(
        "Fashion Star SDK 1.3.12: `query_servo_angle` calls `update()`, which polls `in_waiting` until its 100 ms "
        "timeout has passed whatever arrives, so every read takes ≥ 100 ms of spinning; `PortHandler.quick_update` "
        "(used by its ping/monitor) polls the same way but stops at the first valid packet."
    )
    try:
        with simulator("specs/feetech_sms.yaml", 1) as path:
            sms, how = feetech(path)
        rows += [
            _row("feetech_sms", f"generated `{how}`", sms["generated"], sms["bare"], True),
            _row("feetech_sms", "bare pyserial write 8 B + read(8)", sms["bare"], sms["bare"], False),
            _row("feetech_sms", "scservo_sdk `sms_sts.ReadPos(1)`", sms["sdk"], sms["bare"], False),
        ]
        notes.append(
            "scservo_sdk: `rxPacket` polls `read()` on a port opened with timeout=0 until the packet is complete."
        )
    except SimUnavailable as exc:
        notes.append(f"FEETECH SMS rows skipped: {exc}; they appear once `serialspec sim` serves it.")
    for case in CASES:
        try:
            with simulator(f"specs/{case.protocol}.yaml", case.device_id) as path:
                results, sent, size, gap = plain(case, path)
        except SimUnavailable as exc:
            notes.append(f"{case.protocol} rows skipped: {exc}.")
            continue
        silence = f"{gap * 1e6:.0f} µs of silence (3.5 characters) + " if gap else ""
        rows += [
            _row(case.protocol, f"generated `{case.how}`", results["generated"], results["bare"], True),
            _row(
                case.protocol,
                f"bare pyserial {silence}write {sent} B + read({size})",
                results["bare"],
                results["bare"],
                False,
            ),
        ]
        if gap:
            notes.append(
                f"{case.protocol}: both sides wait out the {gap * 1e6:.0f} µs of silence the protocol needs before a "
                f"frame at {importlib.import_module(case.protocol).BAUDRATE} baud (time.sleep), so the wait dominates."
            )
    notes.append(
        f"Generated and bare run side by side: {BLOCKS} alternating blocks of {PER_BLOCK} transactions after "
        f"{WARMUP} warm-up ones. CPU µs/tx: process time of the benchmark process per transaction; CPU share: that "
        "time over the wall time (near 100% means spinning rather than blocking; on a busy machine preemption "
        "lowers the share of a spinner, so read the CPU µs beside it)."
    )
    return Table(
        title="Latency: one read transaction over a pseudo-terminal to `serialspec sim` in another process",
        header=[
            "protocol",
            "transaction",
            "n",
            "median µs",
            "p99 µs",
            "CPU µs/tx",
            "CPU share",
            "÷ bare",
            "CPU ÷ bare",
            "",
        ],
        rows=rows,
        notes=notes,
    )
