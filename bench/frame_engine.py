"""The frame engine's cost against straight-line codecs: `python -m bench.frame_engine`.

DYNAMIXEL 2.0 (byte stuffing, a u16 length over a span, CRC-16) runs on the runtime's general frame engine; FEETECH
(one header, a one-byte length, a final checksum) gets straight-line generated code. Both decode a status reply of a
4-byte (DYNAMIXEL) or 2-byte (FEETECH) register read; best of 3 repeats.
"""

from __future__ import annotations

import timeit
from collections.abc import Callable

import dynamixel_p2
import feetech_sms


def per_frame(action: Callable[[], object], number: int = 20000) -> float:
    return min(timeit.repeat(action, number=number, repeat=3)) / number


def main() -> None:
    dxl = dynamixel_p2.StatusResponse(id=1, error=dynamixel_p2.ErrorBits(alert=0, number=0), data=bytes(4))
    sms = feetech_sms.ReplyResponse(id=1, error=0, data=bytes(2))
    for name, package, message in (("dynamixel_p2", dynamixel_p2, dxl), ("feetech_sms", feetech_sms, sms)):
        frame = package.encode(message)
        encode = per_frame(lambda p=package, m=message: p.encode(m))
        decode = per_frame(lambda p=package, f=frame: p.decode(f, "response"))
        stream = frame * 1000
        feed = per_frame(lambda p=package, s=stream: p.StreamParser("response").feed(s), number=3)
        print(
            f"{name:<13} {len(frame):>2}-byte frame: encode {encode * 1e6:5.2f} µs, decode {decode * 1e6:5.2f} µs, "
            f"stream {len(stream) / feed / 1e6:5.2f} MB/s"
        )


if __name__ == "__main__":
    main()
