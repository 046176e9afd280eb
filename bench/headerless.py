"""Header-less and trailer framings on the frame engine: per-frame codec times and the Modbus stream parser.

`.venv/bin/python -m bench.headerless` prints one line per figure (not part of `make bench`'s tables). Modbus RTU
frames have no header and no length, so every byte is a candidate frame start; VESC packets run on the engine too.
"""

from __future__ import annotations

import random
import time
from collections.abc import Callable

from serialspec.runtime.message import field_names
from serialspec_protocols import modbus_rtu as mb
from serialspec_protocols import vesc

ROUNDS = 20000


def per_call(function: Callable[[], object], rounds: int = ROUNDS) -> float:
    """Microseconds per call, the best of three runs."""
    best = float("inf")
    for _ in range(3):
        started = time.perf_counter()
        for _ in range(rounds):
            function()
        best = min(best, (time.perf_counter() - started) / rounds)
    return best * 1e6


def main() -> None:
    registers = bytes.fromhex("01 03 06 02 2B 00 00 00 64 05 7A")
    request = mb.ReadHoldingRegistersRequest(unit=1, address=0, count=10)
    values = vesc.GetValuesResponse.from_fields(dict.fromkeys(field_names(vesc.GetValuesResponse), 0))
    packet = vesc.encode(values)
    decode_modbus = per_call(lambda: mb.decode(registers, "response"))
    print(f"modbus decode, read_holding_registers reply of 3 registers: {decode_modbus:.1f} µs")
    print(f"modbus encode, read_holding_registers request: {per_call(lambda: mb.encode(request)):.1f} µs")
    decode_vesc = per_call(lambda: vesc.decode(packet, "response"))
    print(f"vesc decode, get_values reply ({len(packet)}-byte packet): {decode_vesc:.1f} µs")
    rng = random.Random(1)
    pool = [
        registers,
        bytes.fromhex("01 10 00 01 00 02 10 08"),
        bytes.fromhex("01 81 02 C1 91"),
        bytes.fromhex("01 01 03 CD 6B 05 42 82"),
    ]
    stream = b"".join(rng.choice(pool) for _ in range(20000))
    parser = mb.StreamParser("response")
    found = 0
    started = time.perf_counter()
    for offset in range(0, len(stream), 64):
        found += len(parser.feed(stream[offset : offset + 64]))
    elapsed = time.perf_counter() - started
    print(
        f"modbus stream parser, {found} back-to-back replies in 64-byte reads: {len(stream) / elapsed / 1e6:.2f} MB/s, "
        f"{found / elapsed / 1000:.0f}k frames/s"
    )


if __name__ == "__main__":
    main()
