"""User-space instructions per read transaction (valgrind cachegrind), generated client against bare pyserial.

A steadier proxy for the latency family's CPU ratio on a shared machine: `python -m bench.instructions [protocol
...]` runs, for each protocol with a virtual device, one process per side under `valgrind --tool=cachegrind` twice
(100 and 1,100 transactions after 30 warm-up ones, against `serialspec sim` in another process, which valgrind does
not follow) and prints the difference over 1,000: instructions per transaction, imports and start-up cancelled out.
Not part of `make bench` (it needs valgrind and takes ~10 s per protocol and side).
"""

from __future__ import annotations

import importlib
import re
import subprocess
import sys
from collections.abc import Callable
from typing import Any

from bench import latency

FIRST, SECOND = 100, 1100


def _read(protocol: str) -> tuple[str, Callable[[Any], object], Any, int | None]:
    """The generated client's class name, its read, the request message and the simulator's device id."""
    package = importlib.import_module(protocol)
    if protocol == "feetech_sms":
        return "FeetechSmsClient", lambda c: c.read(1, "present_position"), package.ReadRequest(1, 0x38, 2), 1
    if protocol == "fashionstar_uart":
        return "FashionstarUartClient", lambda c: c.read_angle(1), package.ReadAngleRequest(servo_id=1), 1
    case = next(c for c in latency.CASES if c.protocol == protocol)
    return case.client_class, case.call, case.request(package), case.device_id


def transactions(protocol: str, side: str, count: int) -> None:
    """`count` transactions of one side (generated or bare) after 30 warm-up ones (what runs under valgrind)."""
    import serial

    package = importlib.import_module(protocol)
    client_class, call, request_message, device = _read(protocol)
    request = package.encode(request_message)
    client_type = getattr(importlib.import_module(f"{protocol}.client"), client_class)
    with (
        latency.simulator(f"specs/{protocol}.yaml", device) as path,
        client_type(path, timeout=1.0) as client,
        serial.Serial(path, package.BAUDRATE, timeout=1.0) as bare,
    ):
        call(client)
        size = latency.reply_size(bare, request)
        gap = client.bus._gap
        run = (lambda: call(client)) if side == "generated" else latency.bare_read(bare, request, size, gap)
        for _ in range(30 + count):
            run()


def count(protocol: str, side: str, transactions: int) -> int:
    command = ["valgrind", "--tool=cachegrind", "--cache-sim=no", "--cachegrind-out-file=/dev/null"]
    command += [sys.executable, "-m", "bench.instructions", "--run", protocol, side, str(transactions)]
    output = subprocess.run(command, capture_output=True, text=True, check=True).stderr
    found = re.search(r"I\s+refs:\s+([\d,]+)", output)
    if found is None:
        raise RuntimeError(f"no instruction count from valgrind: {output[-300:]}")
    return int(found.group(1).replace(",", ""))


def main(argv: list[str]) -> None:
    if argv[:1] == ["--run"]:
        transactions(argv[1], argv[2], int(argv[3]))
        return
    protocols = argv or ["fashionstar_uart", "feetech_sms", *(c.protocol for c in latency.CASES)]
    print("| protocol | generated | bare | ratio |\n| --- | --- | --- | --- |")
    for protocol in protocols:
        per = {
            side: (count(protocol, side, SECOND) - count(protocol, side, FIRST)) / (SECOND - FIRST)
            for side in ("generated", "bare")
        }
        print(f"| {protocol} | {per['generated']:,.0f} | {per['bare']:,.0f} | {per['generated'] / per['bare']:.2f} |")


if __name__ == "__main__":
    main(sys.argv[1:])
