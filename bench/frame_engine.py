"""The general-framing codecs against a classic one: `python -m bench.frame_engine`.

DYNAMIXEL 2.0 (byte stuffing, a u16 length over a span, CRC-16) and Modbus RTU (no header, no length, CRC-16) are
not of the classic shape (one header, a one-byte length, a final checksum); FEETECH is. Each decodes a status reply
of a register read (DYNAMIXEL: 4 bytes, FEETECH: 2 bytes, Modbus: 3 holding registers): encode and decode of one
frame, and the generated `StreamParser` over 1,000 of them back to back (MB/s); best of 3 repeats.
"""

from __future__ import annotations

import timeit
from collections.abc import Callable
from typing import Any

from serialspec.runtime.message import Message
from serialspec_protocols import dynamixel_p2, feetech_sms, modbus_rtu


def per_frame(action: Callable[[], object], number: int = 20000) -> float:
    return min(timeit.repeat(action, number=number, repeat=3)) / number


def main() -> None:
    cases: tuple[tuple[str, Any, Message], ...] = (
        (
            "dynamixel_p2",
            dynamixel_p2,
            dynamixel_p2.StatusResponse(id=1, error=dynamixel_p2.ErrorBits(alert=0, number=0), data=bytes(4)),
        ),
        ("modbus_rtu", modbus_rtu, modbus_rtu.ReadHoldingRegistersResponse(unit=1, registers=(1, 2, 3))),
        ("feetech_sms", feetech_sms, feetech_sms.ReplyResponse(id=1, error=0, data=bytes(2))),
    )
    for name, package, message in cases:
        frame = package.encode(message)
        encode = per_frame(lambda p=package, m=message: p.encode(m))
        decode = per_frame(lambda p=package, f=frame: p.decode(f, "response"))
        stream = frame * 1000
        assert len(package.StreamParser("response").feed(stream)) == 1000, name
        feed = per_frame(lambda p=package, s=stream: p.StreamParser("response").feed(s), number=3)
        print(
            f"{name:<13} {len(frame):>2}-byte frame: encode {encode * 1e6:5.2f} µs, decode {decode * 1e6:5.2f} µs, "
            f"stream {len(stream) / feed / 1e6:5.2f} MB/s"
        )


if __name__ == "__main__":
    main()
