"""serialspec watch: a live full-screen view of a bus, one row per device and command (and register), built on rich.

It only listens, as `monitor` does: it reads a port (a sniffer's, or any port no other program reads) or follows
the capture file a running `serialspec sim --tap FILE` (or `monitor --save FILE`) writes, and never sends a byte, so
it never takes a reply another program waits for. Each row shows the last values in engineering units, the frames
a second over the last few seconds, the error replies and how long ago the last frame came; the title counts the
frames, the bad frames and the bytes outside any frame.
"""

from __future__ import annotations

import argparse
import collections
import sys
import time
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any, TextIO

from serialspec.cli import capture
from serialspec.cli.frames import Frames, Seen
from serialspec.cli.listening import Stopping, open_port
from serialspec.cli.protocols import SPEC_HELP, open_spec
from serialspec.cli.views import (
    FlagNames,
    engineering,
    message_spec,
    register_view,
    unit_symbols,
    with_unit,
)
from serialspec.lang.model import Protocol, Scalar, TableEntry, TextField, engineering_unit
from serialspec.runtime.errors import PortError, SerialspecError
from serialspec.runtime.message import Message
from serialspec.runtime.text import texts

RATE_WINDOW = 5.0  # seconds over which a row's rate is counted
REFRESH = 0.25  # seconds between redraws
PIPE_WIDTH = 160  # columns of the table printed where the output is not a terminal
NARROW = 100  # columns below which the table's cells have no padding


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help=SPEC_HELP)
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--port", help="device path or pyserial URL to listen on (never written to)")
    source.add_argument(
        "--tap", metavar="FILE", help="follow a capture file as it grows (serialspec sim --tap FILE, monitor --save)"
    )
    parser.add_argument("--baudrate", type=int, metavar="N", help="default: the spec's")
    parser.add_argument("--duration", type=float, metavar="S", help="stop after this many seconds (default: Ctrl-C)")
    parser.add_argument("--raw", action="store_true", help="wire values, not engineering units and enum names")


@dataclass
class Row:
    device: str
    name: str
    direction: str
    values: str = ""
    count: int = 0
    errors: int = 0
    last: float = 0.0
    times: collections.deque[float] = field(default_factory=collections.deque)

    def seen(self, now: float, values: str, error: bool) -> None:
        self.values, self.last = values, now
        self.count += 1
        self.errors += error
        self.times.append(now)

    def rate(self, now: float) -> float:
        while self.times and self.times[0] < now - RATE_WINDOW:
            self.times.popleft()
        return len(self.times) / RATE_WINDOW


class Board:
    """What the view shows: rows by (device, command or register, direction), and the totals."""

    def __init__(self, protocol: Protocol, source: str, raw: bool) -> None:
        self.protocol = protocol
        self.source = source
        self.raw = raw
        self.address = protocol.device.address if protocol.device else ""
        self.rows: dict[tuple[str, str, str], Row] = {}
        self.frames = self.bad = self.garbage = 0
        self.requests: dict[Any, Message] = {}  # the last request to each device: what its reply answers
        self.entries: dict[str, TableEntry] = {e.name: e for t in protocol.tables for e in t.entries}
        self.started = time.monotonic()

    def add(self, seen: Seen, now: float) -> None:
        message = seen.message
        if message is None:
            if "outside any frame" in seen.reason:
                self.garbage += int(seen.reason.split()[0])
            else:
                self.bad += int(seen.reason.split()[0])
            return
        self.frames += 1
        fields = message.to_fields()
        device = fields.get(self.address, "-") if self.address else "-"
        direction = message.DIRECTION.value
        name = message.COMMAND + (f".{message.SUBCOMMAND}" if message.SUBCOMMAND else "")
        row = self.row(str(device), name, direction)
        if self.protocol.text is not None:  # a sentence: its fields as the device wrote them, no registers
            row.seen(now, self.sentence(message, fields), False)
            return
        row.seen(now, self.values(message, fields), self.error(message, fields))
        request = self.requests.get(device) if direction == "response" else None
        registers = register_view(self.protocol, message, request)
        for register, value in (registers or {}).items():
            self.row(str(device), register, direction).seen(now, self.register(register, value), False)
        if direction == "request":
            self.requests[device] = message

    def row(self, device: str, name: str, direction: str) -> Row:
        key = (device, name, direction)
        found = self.rows.get(key)
        if found is None:
            found = self.rows[key] = Row(device, name, direction)
        return found

    def values(self, message: Message, fields: dict[str, Any]) -> str:
        symbols = {} if self.raw else unit_symbols(self.protocol, message)
        shown = fields if self.raw else engineering(self.protocol, message, fields)
        words = []
        for name, value in shown.items():
            if name == self.address:
                continue
            text = _text(value)
            words.append(f"{name}={with_unit(text, symbols[name]) if name in symbols else text}")
        return " ".join(words)

    def sentence(self, message: Message, fields: dict[str, Any]) -> str:
        """A text sentence's fields as sent (`latitude=4807.0560 °`), empty ones left out."""
        record: Any = message  # a text record: its frame's descriptor of its code
        assert self.protocol.text is not None
        spec = next(m for m in self.protocol.text.messages if m.class_name == type(message).__name__)
        units = {f.name: f.unit for f in spec.fields if isinstance(f, TextField) and f.unit and not self.raw}
        sent = texts(record.FRAMING.sentence(record.CODE, record.DIRECTION.value), fields)
        return " ".join(
            f"{name}={with_unit(text, units[name]) if name in units else _text(text)}"
            for name, text in sent.items()
            if text not in ("", None, [])
        )

    def register(self, name: str, value: Any) -> str:
        entry = self.entries.get(name)
        if entry is None or self.raw or not isinstance(value, int | float):
            return _text(value)
        if entry.enum is not None:
            return next((v.name.lower() for v in entry.enum.values if v.value == value), str(value))
        shown = round(value * entry.scale, 6) if entry.scale is not None else value
        unit = engineering_unit(entry.unit, entry.scale)
        return with_unit(shown, unit) if unit else str(shown)

    def error(self, message: Message, fields: dict[str, Any]) -> bool:
        """An error reply, a status element that is not 0, or a status field that is not its success value."""
        spec = message_spec(self.protocol, message)
        if spec.error_reply:
            return True
        layout = self.protocol.framing.layouts[message.DIRECTION]
        for element in layout.value_elements:
            if element.role == "status" and _nonzero(fields.get(element.name)):
                return True
        return any(
            isinstance(f, Scalar) and f.status_ok is not None and fields.get(f.name) != f.status_ok for f in spec.fields
        )

    def table(self, now: float, width: int = PIPE_WIDTH) -> Any:
        """The view at a console `width`. Below NARROW columns (an 80-column terminal) the cells lose their padding,
        which leaves the values the room they need (padded, they had 6 columns there, and each row grew a line per
        few characters of its values and pushed the table off the screen)."""
        from rich.table import Table

        title = (
            f"serialspec watch: {self.protocol.name} on {self.source} — {self.frames} frames, {self.bad} bad, "
            f"{self.garbage} bytes outside frames — Ctrl-C to quit"
        )
        narrow = width < NARROW
        table = Table(title=title, title_justify="left", expand=True, padding=(0, 0) if narrow else (0, 1))
        table.add_column("device", justify="right")
        table.add_column("command / register")
        table.add_column("dir")
        table.add_column("last values", ratio=1, min_width=24, overflow="fold")
        table.add_column("frames", justify="right")
        table.add_column("per s", justify="right")
        table.add_column("errors", justify="right")
        table.add_column("age s", justify="right")
        for key in sorted(self.rows, key=_order):
            row = self.rows[key]
            table.add_row(
                row.device,
                row.name,
                "→" if row.direction == "request" else "←",
                row.values,
                str(row.count),
                f"{row.rate(now):.1f}",
                f"[red]{row.errors}[/red]" if row.errors else "0",
                f"{now - row.last:.1f}",
            )
        return table


def _order(key: tuple[str, str, str]) -> tuple[int, str, str, str]:
    device, name, direction = key
    return (int(device) if device.isdigit() else -1, device, name, direction)


def _text(value: Any) -> str:
    if isinstance(value, FlagNames):
        return str(value)
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}={_text(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list) and value and all(isinstance(v, bool) for v in value):  # bits: 8 to a group
        bits = "".join("1" if v else "0" for v in value)
        return " ".join(bits[i : i + 8] for i in range(0, len(bits), 8))
    if isinstance(value, list):
        return "[" + ", ".join(_text(v) for v in value) + "]"
    return str(value)


def _nonzero(value: Any) -> bool:
    if isinstance(value, dict):
        return any(_nonzero(v) for v in value.values())
    return bool(value)


class PortSource:
    """Bytes as a port gives them: both directions in one stream (paired where they share a header)."""

    def __init__(self, args: argparse.Namespace, package: ModuleType, address: str | None) -> None:
        import serial

        self.name = args.port
        self.frames = Frames(package, None, address)
        self.port = open_port(args.port, args.baudrate, package.SERIAL, REFRESH)
        self.errors: tuple[type[BaseException], ...] = (serial.SerialException, OSError)

    def read(self) -> list[Seen]:
        try:
            chunk = self.port.read(1)
            if chunk and self.port.in_waiting:
                chunk += self.port.read(self.port.in_waiting)
        except self.errors as exc:
            raise PortError(f"{self.name}: {exc}") from None
        # a quiet line settles the bad bytes so far: the view counts them now, not when the next frame comes
        return self.frames.feed(chunk) if chunk else self.frames.finish()

    def close(self) -> None:
        self.port.close()


class TapSource:
    """A capture file followed as it grows (tail -f): each direction's bytes split into frames."""

    def __init__(self, path: str, package: ModuleType, address: str | None) -> None:
        self.name = path
        self.package, self.address = package, address
        self.stream: TextIO = capture.open_text(path)
        self.partial = ""
        self.streams: dict[str | None, Frames] = {}

    def read(self) -> list[Seen]:
        text = self.stream.read()
        if not text:  # nothing new: the bad bytes so far are settled (see PortSource.read)
            time.sleep(REFRESH / 2)
            return [seen for frames in self.streams.values() for seen in frames.finish()]
        text = self.partial + text
        lines = text.split("\n")
        self.partial = lines.pop()  # a line still being written
        found = []
        try:
            for _, chunk in capture.read(lines):
                frames = self.streams.get(chunk.direction)
                if frames is None:
                    frames = self.streams[chunk.direction] = Frames(self.package, chunk.direction, self.address)
                found += frames.feed(chunk.data)
        except ValueError as exc:
            raise SerialspecError(f"{self.name}: {exc}") from None
        return found

    def close(self) -> None:
        self.stream.close()


def run(args: argparse.Namespace) -> int:
    from rich.console import Console
    from rich.live import Live

    protocol, package = open_spec(args.spec)
    address = protocol.device.address if protocol.device else None
    source: PortSource | TapSource = (
        PortSource(args, package, address) if args.port else TapSource(args.tap, package, address)
    )
    board = Board(protocol, source.name, args.raw)
    stopping = Stopping()
    console = Console()
    end = time.monotonic() + args.duration if args.duration else None
    try:
        if console.is_terminal:
            first = board.table(time.monotonic(), console.width)
            with Live(first, console=console, screen=True, auto_refresh=False) as live:
                drawn = 0.0
                while not stopping and (end is None or time.monotonic() < end):
                    listen(source, board)
                    now = time.monotonic()
                    if now - drawn >= REFRESH:
                        live.update(board.table(now, console.width), refresh=True)
                        drawn = now
        else:  # not a terminal (a pipe, a file): the table once, at the end
            while not stopping and (end is None or time.monotonic() < end):
                listen(source, board)
        # on a terminal its width; elsewhere (a pipe, a file) a width that keeps rows on one line
        width = console.width if console.is_terminal else PIPE_WIDTH
        Console(file=sys.stdout, width=width).print(board.table(time.monotonic(), width))
    finally:
        source.close()
    return 0


def listen(source: PortSource | TapSource, board: Board) -> None:
    now = time.monotonic()
    for seen in source.read():
        board.add(seen, now)
