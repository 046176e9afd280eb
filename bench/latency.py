"""Family 3: one read transaction over a pseudo-terminal, to a virtual device served by another process.

`serialspec sim specs/<spec>.yaml --id 1 --quiet` runs as a separate process (it prints the pty path first). The
benchmark process then times whole transactions, request written to reply decoded:

- generated: the generated client (Fashion Star `read_angle(1)`, Hiwonder RRC `bus_servo.read_position(1)`,
  FEETECH `read(1, "present_position")`); the rows of a protocol appear once its spec has a virtual device;
- bare: pyserial `write(request)` then `read(len(reply))` with a 1 s timeout: no parsing at all, the floor;
- vendor SDK: the same read through the vendor's Python SDK (Fashion Star, FEETECH; none is installed for RRC).

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
def simulator(spec: str, device_id: int) -> Iterator[str]:
    """`serialspec sim` in another process; yields the pty path it prints first; stops it with SIGTERM."""
    name = Path(spec).stem
    if importlib.util.find_spec(f"{name}.simulator") is None:
        raise SimUnavailable(f"generated/{name}/simulator.py does not exist")
    command = [str(Path(sys.executable).parent / "serialspec"), "sim", spec, "--id", str(device_id), "--quiet"]
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


def bare_read(port: serial.Serial, request: bytes, reply_size: int) -> Callable[[], bytes]:
    def transact() -> bytes:
        port.write(request)
        reply = port.read(reply_size)
        if len(reply) != reply_size:
            raise RuntimeError(f"bare read got {len(reply)} of {reply_size} bytes")
        return reply

    return transact


def fashionstar(path: str) -> dict[str, Result]:
    fs = importlib.import_module("fashionstar_uart")
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
    sms = importlib.import_module("feetech_sms")
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


def hiwonder(path: str) -> dict[str, Result]:
    rrc = importlib.import_module("hiwonder_rrc")
    client_module = importlib.import_module("hiwonder_rrc.client")
    request = rrc.encode(rrc.BusServoReadPositionRequest(servo_id=1))
    reply_size = len(rrc.encode(rrc.BusServoReadPositionResponse(servo_id=1, success=0, position=0)))
    with (
        client_module.HiwonderRrcClient(path, timeout=1.0) as client,
        serial.Serial(path, rrc.BAUDRATE, timeout=1.0) as bare,
    ):
        assert isinstance(client.bus_servo.read_position(1), int)
        return side_by_side(
            {"generated": lambda: client.bus_servo.read_position(1), "bare": bare_read(bare, request, reply_size)}
        )


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
        with simulator("specs/hiwonder_rrc.yaml", 1) as path:
            rrc = hiwonder(path)
        rows += [
            _row("hiwonder_rrc", "generated `client.bus_servo.read_position(1)`", rrc["generated"], rrc["bare"], True),
            _row("hiwonder_rrc", "bare pyserial write 7 B + read(10)", rrc["bare"], rrc["bare"], False),
        ]
    except SimUnavailable as exc:
        notes.append(f"Hiwonder RRC rows skipped: {exc}.")
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
