"""serialspec monitor: decode everything on a port live, one line per frame, bad frames shown as such."""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any, TextIO

import serial

from serialspec.cli import capture
from serialspec.cli.frames import Frames, Seen
from serialspec.cli.listening import Stopping, open_port
from serialspec.cli.protocols import SPEC_HELP, open_spec
from serialspec.cli.views import engineering, unit_symbols, with_unit
from serialspec.lang.model import Protocol
from serialspec.runtime.errors import PortError, SerialspecError
from serialspec.runtime.text import texts

COLOURS = {"request": "\033[36m", "response": "\033[32m", "BAD": "\033[31m"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help=SPEC_HELP)
    parser.add_argument("--port", required=True, help="device path or pyserial URL (loop://, socket://, spy://...)")
    parser.add_argument("--baudrate", type=int, metavar="N", help="default: the spec's")
    parser.add_argument(
        "--direction",
        choices=("request", "response"),
        help="only this direction (default: both; where they share a header, replies are paired with requests)",
    )
    parser.add_argument("--duration", type=float, metavar="S", help="stop after this many seconds")
    parser.add_argument("--count", type=int, metavar="N", help="stop after this many frames")
    parser.add_argument("--save", metavar="FILE", help="also write every chunk read to a capture file")
    parser.add_argument("--units", action="store_true", help="engineering units (with symbols) and enum names")
    parser.add_argument("--command", dest="commands", action="append", metavar="NAME", help="only this command")
    parser.add_argument("--id", dest="ids", type=int, action="append", metavar="N", help="only this device id")
    parser.add_argument(
        "--color", choices=("auto", "always", "never"), default="auto", help="colour lines (auto: on a terminal)"
    )


class Printer:
    """One line per frame, filtered by command and id, coloured on a terminal."""

    def __init__(self, args: argparse.Namespace, protocol: Protocol, out: TextIO = sys.stdout) -> None:
        self.args = args
        self.protocol = protocol
        self.out = out
        self.colour = args.color == "always" or (args.color == "auto" and out.isatty())
        self.address = protocol.device.address if protocol.device else None

    def wanted(self, seen: Seen) -> bool:
        message = seen.message
        if message is None:
            return not (self.args.commands or self.args.ids)
        if self.args.direction and message.DIRECTION.value != self.args.direction:
            return False
        if self.args.commands and not {message.COMMAND, f"{message.COMMAND}.{message.SUBCOMMAND}"} & set(
            self.args.commands
        ):
            return False
        return not self.args.ids or message.to_fields().get(self.address or "") in self.args.ids

    def line(self, seen: Seen) -> None:
        message = seen.message
        if message is None:
            kind, text = "BAD", f"{seen.reason} in [{seen.data.hex(' ')}]"
        else:
            kind = message.DIRECTION.value
            fields: dict[str, Any] = message.to_fields()
            if self.args.units:
                symbols = unit_symbols(self.protocol, message)
                fields = {
                    name: with_unit(value, symbols[name]) if name in symbols else value
                    for name, value in engineering(self.protocol, message, fields).items()
                }
            what = message.COMMAND + (f".{message.SUBCOMMAND}" if message.SUBCOMMAND else "")
            if self.protocol.text is not None:  # a sentence: its fields as the texts sent, and the line itself
                record: Any = message  # a text record: its frame's descriptor of its code
                fields = texts(record.FRAMING.sentence(record.CODE, record.DIRECTION.value), fields)
                ending = self.protocol.text.end_of(message.DIRECTION)
                line = seen.data.decode("latin-1").removesuffix(ending).rstrip("\r\n")
                text = f"{what} {json.dumps(fields, ensure_ascii=False)} {line}"
            else:
                text = f"{what} {json.dumps(fields, ensure_ascii=False)} [{seen.data.hex(' ')}]"
        label = f"{COLOURS[kind]}{kind}\033[0m" if self.colour else kind
        print(f"{capture.stamp()} {label} {text}", file=self.out, flush=True)


def run(args: argparse.Namespace) -> int:
    protocol, package = open_spec(args.spec)
    if protocol.text is not None and (args.units or args.ids):
        raise SerialspecError("--units and --id are for binary frames: a text protocol's sentences carry no device id")
    settings = package.SERIAL
    address = protocol.device.address if protocol.device else None
    frames = Frames(package, args.direction, address)
    port = open_port(args.port, args.baudrate, settings, 0.5)
    try:
        save = open(args.save, "w", encoding="utf-8") if args.save else None  # noqa: SIM115 (closed below)
    except OSError as exc:
        raise SerialspecError(f"cannot write {args.save}: {exc.strerror}") from None
    writer = capture.Writer(save, protocol.name) if save else None
    stopping = Stopping()
    end = time.monotonic() + args.duration if args.duration else None
    printer = Printer(args, protocol)
    seen = 0
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
            if writer is not None:
                writer.write(args.direction, chunk)
            for item in frames.feed(chunk):
                if printer.wanted(item):
                    seen += 1
                    printer.line(item)
                    if seen == args.count:  # exactly that many, however many frames one read brought
                        break
    for item in frames.finish() if args.count is None or seen < args.count else ():  # bytes nothing came after
        if printer.wanted(item):
            printer.line(item)
    if save is not None:
        save.close()
    print(f"{protocol.name}: {seen} frame(s)", file=sys.stderr)
    return 0
