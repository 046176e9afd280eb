"""serialspec replay: send the frames of one direction of a capture to a port, with the capture's timing.

A capture (monitor --save, sim --tap; see serialspec.cli.capture) holds chunks of bytes with their time and
direction. Replay writes the chunks of one direction (requests by default: the capture's host, played to a device;
`--direction response` plays the device to a host) at the moments the capture gives, divided by `--speed`. Chunks
whose direction is not known (`-`: a monitor capture of both directions) are split into frames by the spec
(`--spec`, else the protocol the capture names, if installed) and each frame sent by its own direction.
"""

from __future__ import annotations

import argparse
import datetime
import sys
import time
from typing import Any

from serialspec.cli import capture, port_options
from serialspec.runtime.errors import PortError, SerialspecError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("capture", help="a capture file (monitor --save, sim --tap); - for stdin")
    parser.add_argument("--port", required=True, help="device path or pyserial URL (loop://, socket://, spy://...)")
    parser.add_argument(
        "--direction",
        choices=("request", "response"),
        default="request",
        help="the frames to send (default: request, the host's side)",
    )
    parser.add_argument(
        "--speed",
        type=float,
        metavar="X",
        default=1.0,
        help="time scale: 2 plays twice as fast, 0.5 at half speed, 0 with no pauses (default: 1, as captured)",
    )
    parser.add_argument(
        "--spec",
        help="the spec (file or protocol name) that tells requests from responses in chunks of unknown direction, "
        "and gives the port's settings (default: the protocol the capture names, if installed)",
    )
    port_options.add_arguments(parser)


def run(args: argparse.Namespace) -> int:
    if args.speed < 0 or args.speed != args.speed or args.speed == float("inf"):
        raise SerialspecError(f"--speed {args.speed}: give a number ≥ 0 (0: no pauses)")
    lines = _lines(args.capture)
    named = next((line.split(":", 1)[1].strip() for line in lines if line.startswith("# serialspec capture:")), None)
    try:
        chunks = [(number, chunk) for number, chunk in capture.read(lines)]
    except ValueError as exc:
        raise SerialspecError(f"{args.capture}: {exc}") from None
    unknown = any(chunk.direction is None for _, chunk in chunks)
    package, address = _package(args.spec or named, required=args.spec is not None or unknown)
    plan = _plan(chunks, args.direction, package, address, args.capture)
    if not plan:
        print(f"serialspec replay: {args.capture} holds no {args.direction} bytes", file=sys.stderr)
        return 1
    import serial

    port = port_options.open_port(args, package, timeout=0)
    started = time.monotonic()
    first = plan[0][0]
    sent = 0
    with port:
        for moment, data in plan:
            if args.speed and moment is not None and first is not None:
                delay = (moment - first) / args.speed - (time.monotonic() - started)
                if delay > 0:
                    time.sleep(delay)
            try:
                port.write(data)
                port.flush()
                if port.in_waiting:  # replies are not wanted: read so that the other side never blocks
                    port.read(port.in_waiting)
            except (serial.SerialException, OSError) as exc:
                raise PortError(f"{args.port}: {exc}") from None
            sent += len(data)
    print(
        f"serialspec replay: {len(plan)} {args.direction} chunk(s), {sent} byte(s) sent to {args.port}", file=sys.stderr
    )
    return 0


def _lines(path: str) -> list[str]:
    if path == "-":
        return sys.stdin.readlines()
    with capture.open_text(path) as stream:
        return stream.readlines()


def _package(spec: str | None, required: bool) -> tuple[Any, str | None]:
    """The protocol package (for splitting and port settings) and its address field, or (None, None)."""
    if spec is None:
        if required:
            raise SerialspecError(
                "the capture has bytes of unknown direction ('-') and names no protocol: give --spec SPEC"
            )
        return None, None
    from serialspec.cli.protocols import open_spec

    try:
        protocol, package = open_spec(spec)
    except SerialspecError:
        if required:
            raise
        return None, None
    return package, protocol.device.address if protocol.device else None


def _plan(
    chunks: list[tuple[int, capture.Chunk]], direction: str, package: Any, address: str | None, name: str
) -> list[tuple[float | None, bytes]]:
    """(seconds since the epoch or None, bytes) to send, in the capture's order."""
    from serialspec.cli.frames import Frames

    plan: list[tuple[float | None, bytes]] = []
    both = Frames(package, None, address) if package is not None else None
    for number, chunk in chunks:
        moment = _moment(chunk.when, number, name)
        if chunk.direction is not None:
            if chunk.direction == direction:
                plan.append((moment, chunk.data))
            continue
        assert both is not None  # _package refused a capture with unknown directions and no spec
        data = b"".join(
            seen.data
            for seen in both.feed(chunk.data)
            if seen.message is not None and seen.message.DIRECTION.value == direction
        )
        if data:
            plan.append((moment, data))
    return plan


def _moment(when: str, number: int, name: str) -> float | None:
    if not when:
        return None
    try:
        return datetime.datetime.fromisoformat(when).timestamp()
    except ValueError:
        raise SerialspecError(f"{name}: line {number}: {when!r} is not an ISO 8601 time") from None
