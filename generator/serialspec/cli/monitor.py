"""serialspec monitor: decode everything on a port live, one line per frame, bad frames shown as such."""

from __future__ import annotations

import argparse
import datetime
import json
import signal
import sys
import time
from types import FrameType
from typing import Any

import serial

from serialspec.cli.protocols import open_spec
from serialspec.runtime.errors import PortError, SerialspecError

HELP = "print every frame seen on a port (device path or pyserial URL), one line each with a timestamp"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help="the protocol spec (YAML)")
    parser.add_argument("--port", required=True, help="device path or pyserial URL (loop://, socket://, spy://...)")
    parser.add_argument("--baudrate", type=int, help="default: the spec's")
    parser.add_argument(
        "--direction",
        choices=("request", "response"),
        help="only this direction (needed when requests and responses share a header)",
    )
    parser.add_argument("--duration", type=float, help="stop after this many seconds")
    parser.add_argument("--count", type=int, help="stop after this many frames")


def _line(kind: str, text: str) -> None:
    stamp = datetime.datetime.now().isoformat(timespec="microseconds")
    print(f"{stamp} {kind} {text}", flush=True)


def run(args: argparse.Namespace) -> int:
    protocol, package = open_spec(args.spec)
    settings = package.SERIAL
    try:
        parser = package.StreamParser(args.direction)
    except ValueError as exc:
        raise SerialspecError(str(exc)) from None
    try:
        port = serial.serial_for_url(
            args.port,
            baudrate=args.baudrate or settings.baudrate,
            bytesize=settings.bytesize,
            parity={"none": "N", "even": "E", "odd": "O"}.get(settings.parity, "N"),
            stopbits=settings.stopbits,
            timeout=0.5,
        )
    except (serial.SerialException, OSError, ValueError) as exc:
        raise PortError(f"cannot open {args.port}: {exc}") from None
    stopping = False

    def stop(signum: int, frame: FrameType | None) -> None:
        nonlocal stopping
        stopping = True

    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    end = time.monotonic() + args.duration if args.duration else None
    seen = 0
    after_error = False
    print(f"serialspec monitor: {protocol.name} on {args.port}; Ctrl-C to stop", file=sys.stderr, flush=True)
    with port:
        while not stopping and (end is None or time.monotonic() < end) and (args.count is None or seen < args.count):
            port.timeout = 0.5 if end is None else max(0.0, min(0.5, end - time.monotonic()))
            try:
                chunk = port.read(1)
                if chunk and port.in_waiting:
                    chunk += port.read(port.in_waiting)
            except (serial.SerialException, OSError) as exc:
                if stopping:
                    break
                raise PortError(f"{args.port}: {exc}") from None
            if not chunk:
                continue
            errors, garbage = parser.errors, parser.garbage
            for message in parser.feed(chunk):
                seen += 1
                fields: dict[str, Any] = message.to_fields()
                what = message.COMMAND + (f".{message.SUBCOMMAND}" if message.SUBCOMMAND else "")
                _line(
                    message.DIRECTION.value,
                    f"{what} {json.dumps(fields, ensure_ascii=False)} [{package.encode(message).hex(' ')}]",
                )
            if parser.errors > errors:
                after_error = True  # the rest of a bad frame is skipped as garbage: not reported twice
                seen += parser.errors - errors
                _line(
                    "BAD",
                    f"{parser.errors - errors} frame(s) failed their checksum or content check in [{chunk.hex(' ')}]",
                )
            elif parser.garbage > garbage and not after_error:
                _line("BAD", f"{parser.garbage - garbage} byte(s) outside any frame in [{chunk.hex(' ')}]")
            else:
                after_error = False
    print(f"{protocol.name}: {seen} frame(s)", file=sys.stderr)
    return 0
