"""serialspec plot: values of named fields over time, in their units, one panel per field (matplotlib).

From a capture (`monitor --save`, `sim --tap`), or live from a port for `--duration` seconds. A field is named as the
spec names it (`angle`), or as `command.field` to take it from one command only; a register read through a
control table (`present_position`) counts as a field of the reply that holds it. Each panel has one line per
command, direction and device id; values are wire values times the spec's scale, with its unit on the axis.
"""

from __future__ import annotations

import argparse
import datetime
import sys
import time
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any, assert_never

from serialspec.cli import capture
from serialspec.cli.frames import Frames
from serialspec.cli.protocols import SPEC_HELP, open_spec
from serialspec.cli.views import message_spec, register_view
from serialspec.lang.model import Bytes, Protocol, Scalar, Table, TableValue, TextField, TextFrame, engineering_unit
from serialspec.runtime.errors import PortError, SerialspecError
from serialspec.runtime.message import Message

FORMATS = (".png", ".svg")
MISSING = "plotting needs matplotlib, an optional extra: pip install 'serialspec[plot]'"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("capture", nargs="?", metavar="CAPTURE", help="a capture file (monitor --save, sim --tap)")
    parser.add_argument(
        "--field",
        dest="fields",
        action="append",
        required=True,
        metavar="NAME",
        help="a field (or command.field) to plot, one panel each (repeat)",
    )
    parser.add_argument("--out", required=True, metavar="FILE", help="the picture to write: FILE.png or FILE.svg")
    parser.add_argument("--spec", help=f"{SPEC_HELP} (default: the protocol the capture names)")
    parser.add_argument("--port", help="plot live from this port (device path or pyserial URL) instead of a capture")
    parser.add_argument(
        "--duration", type=float, default=10.0, metavar="S", help="with --port: seconds to record (default 10)"
    )
    parser.add_argument("--baudrate", type=int, metavar="N", help="with --port: default the spec's")
    parser.add_argument("--id", dest="ids", type=int, action="append", metavar="N", help="only this device id")


@dataclass
class Series:
    """One line of a panel: the values of one field from one command, direction and device."""

    times: list[float] = field(default_factory=list)
    values: list[float] = field(default_factory=list)


@dataclass
class Panel:
    name: str
    unit: str = ""
    lines: dict[str, Series] = field(default_factory=lambda: defaultdict(Series))


def run(args: argparse.Namespace) -> int:
    out = Path(args.out)
    if out.suffix.lower() not in FORMATS:
        raise SerialspecError(f"--out {args.out}: give a .png or .svg file")
    if bool(args.capture) == bool(args.port):
        raise SerialspecError("give a capture file, or --port URL to plot live")
    if args.capture and Path(args.capture).suffix.lower() in (".yaml", ".yml"):  # as the other verbs take a spec
        raise SerialspecError(
            f"{args.capture} is a spec, not a capture: give the capture (monitor --save, sim --tap) and the spec"
            f" with --spec (serialspec plot CAPTURE --spec {args.capture} --field NAME --out FILE)"
        )
    pyplot = _pyplot()  # before anything is read: a missing matplotlib is said at once
    if args.port:
        if not args.spec:
            raise SerialspecError("--port needs --spec SPEC (the protocol on the port)")
        protocol, package = open_spec(args.spec)
        chunks = record(args.port, package, args.baudrate, args.duration)
        source = args.port
    else:
        chunks = read_capture(args.capture)
        protocol, package = open_spec(args.spec or _named_protocol(args.capture))
        source = Path(args.capture).name
    panels = collect(protocol, package, chunks, args.fields, set(args.ids or ()))
    draw(pyplot, panels, f"{protocol.name}: {source}", out)
    count = sum(len(s.values) for p in panels for s in p.lines.values())
    values = f"{count} value{'s' * (count != 1)}"
    fields = f"{len(panels)} field{'s' * (len(panels) != 1)}"
    print(f"serialspec plot: {values} of {fields} in {out}")
    return 0


def _pyplot() -> ModuleType:
    try:
        import matplotlib

        matplotlib.use("Agg")  # files only: no display needed
        import matplotlib.pyplot as pyplot
    except ImportError:
        raise SerialspecError(MISSING) from None
    return pyplot


def read_capture(path: str) -> list[capture.Chunk]:
    try:
        with capture.open_text(path) as lines:
            return [chunk for _, chunk in capture.read(lines)]
    except ValueError as exc:
        raise SerialspecError(f"{path}: {exc}") from None


def _named_protocol(path: str) -> str:
    """The protocol a capture's first line names (`# serialspec capture: NAME`)."""
    with capture.open_text(path) as lines:
        first = lines.readline()
    name = first.removeprefix("# serialspec capture:").strip() if first.startswith("# serialspec capture:") else ""
    if not name:
        raise SerialspecError(f"{path} names no protocol on its first line: give --spec SPEC")
    return name


def record(url: str, package: ModuleType, baudrate: int | None, duration: float) -> list[capture.Chunk]:
    """What a port shows for `duration` seconds, as capture chunks (direction unknown: both are split by frames)."""
    import serial

    from serialspec.cli.listening import open_port

    port = open_port(url, baudrate, package.SERIAL, 0.1)
    print(f"serialspec plot: recording {url} for {duration:g} s", file=sys.stderr, flush=True)
    chunks = []
    end = time.monotonic() + duration
    with port:
        while (left := end - time.monotonic()) > 0:
            port.timeout = min(0.1, left)
            try:
                data = port.read(max(1, port.in_waiting))
            except (serial.SerialException, OSError) as exc:
                raise PortError(f"{url}: {exc}") from None
            if data:
                chunks.append(capture.Chunk(capture.stamp(), None, data))
    return chunks


def collect(
    protocol: Protocol, package: ModuleType, chunks: list[capture.Chunk], names: list[str], ids: set[int]
) -> list[Panel]:
    """One panel per requested field, each line the field's values over time (seconds from the first chunk)."""
    address = protocol.device.address if protocol.device else None
    panels = [Panel(name) for name in names]
    streams: dict[str | None, Frames] = {}
    start: datetime.datetime | None = None
    last_request: Message | None = None
    seen_fields: set[str] = set()
    for index, chunk in enumerate(chunks):
        when = _moment(chunk.when)
        if when is not None and start is None:
            start = when
        at = (when - start).total_seconds() if when is not None and start is not None else float(index)
        frames = streams.get(chunk.direction) or streams.setdefault(
            chunk.direction, Frames(package, chunk.direction, address)
        )
        for seen in frames.feed(chunk.data):
            message = seen.message
            if message is None:
                continue
            if message.DIRECTION.value == "request":
                last_request = message
            device = message.to_fields().get(address or "")
            if ids and device not in ids:
                continue
            values = field_values(protocol, message, last_request)
            seen_fields.update(values)
            what = message.COMMAND + (f".{message.SUBCOMMAND}" if message.SUBCOMMAND else "")
            label = f"{what} {message.DIRECTION.value}" + (f", {address} {device}" if device is not None else "")
            for panel in panels:
                command, _, name = panel.name.rpartition(".")
                if name not in values or (command and command != what):
                    continue
                value, panel.unit = values[name]
                line = panel.lines[label]
                line.times.append(at)
                line.values.append(value)
    for panel in panels:
        if not panel.lines:
            known = ", ".join(sorted(seen_fields)) or "none"
            raise SerialspecError(f"no frame has a number named {panel.name!r} (numbers seen: {known})")
    return panels


def _moment(text: str) -> datetime.datetime | None:
    try:
        return datetime.datetime.fromisoformat(text) if text else None
    except ValueError:
        return None


def field_values(protocol: Protocol, message: Message, request: Message | None) -> dict[str, tuple[float, str]]:
    """name -> (value in the spec's units, unit symbol) of every plain number a message holds: its fields (scaled),
    and the registers of a reply that carries a run of them. Enums, flags, texts and lists are left out."""
    if protocol.text is not None:
        return _text_values(protocol.text, message)
    fields = message.to_fields()
    found: dict[str, tuple[float, str]] = {}
    for f in message_spec(protocol, message).fields:
        value = fields.get(f.name)
        if isinstance(value, bool) or not isinstance(value, int | float):
            continue
        if isinstance(f, Scalar) and not (f.enum or f.flags or f.bits):
            found[f.name] = _scaled(value, f.scale) + (f.offset or 0), engineering_unit(f.unit, f.scale)
        elif isinstance(f, TableValue):
            entry = f.table.entry(fields.get(f.key, -1))
            if entry is not None and entry.enum is None and entry.flags is None:
                found[f.name] = _scaled(value, entry.scale), engineering_unit(entry.unit, entry.scale)
    registers = register_view(protocol, message, request)
    table = _register_table(protocol, message)
    for name, value in (registers or {}).items():
        entry = next((e for e in table.entries if e.name == name), None) if table else None
        if entry is None or entry.enum or entry.flags or not isinstance(value, int | float):
            continue
        found[name] = _scaled(value, entry.scale), engineering_unit(entry.unit, entry.scale)
    return found


def _text_values(text: TextFrame, message: Message) -> dict[str, tuple[float, str]]:
    """name -> (value, unit) of every number a text sentence holds: decimals and integers as sent, angles in decimal
    degrees (unsigned: the hemisphere is a field of its own); empty fields, letters, texts, times and dates left out."""
    spec = next((m for m in text.messages if m.class_name == type(message).__name__), None)
    values = message.to_fields()
    found: dict[str, tuple[float, str]] = {}
    for f in spec.fields if spec is not None else ():
        if not isinstance(f, TextField):
            continue  # a repeated group: a list, left out as lists of binary frames are
        value = values.get(f.name)
        if value is None:
            continue
        match f.kind:
            case "decimal" | "integer":
                found[f.name] = float(value), f.unit
            case "angle":
                found[f.name] = round(value.value, 9), f.unit or "°"
            case "char" | "text" | "time" | "date":
                pass
            case unknown:
                assert_never(unknown)
    return found


def _register_table(protocol: Protocol, message: Message) -> Table | None:
    return next(
        (f.table for f in message_spec(protocol, message).fields if isinstance(f, Bytes) and f.table is not None),
        None,
    )


def _scaled(value: float, scale: float | None) -> float:
    return round(value * scale, 6) if scale is not None else value


def draw(pyplot: Any, panels: list[Panel], title: str, out: Path) -> None:
    figure, axes = pyplot.subplots(
        len(panels), 1, sharex=True, figsize=(10, 1.2 + 2.4 * len(panels)), squeeze=False, layout="constrained"
    )
    for panel, ax in zip(panels, axes[:, 0], strict=True):
        for label, line in panel.lines.items():
            ax.plot(line.times, line.values, marker=".", linewidth=1.2, label=label)
        ax.ticklabel_format(axis="y", useOffset=False)  # 48.1174°, not +4.8117e1 and 0.0004 on the axis
        ax.set_ylabel(f"{panel.name} ({panel.unit})" if panel.unit else panel.name)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize="small")
    axes[-1, 0].set_xlabel("time (s)")
    figure.suptitle(title)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        figure.savefig(out, dpi=100)
    except OSError as exc:
        raise SerialspecError(f"cannot write {out}: {exc.strerror}") from None
    finally:
        pyplot.close(figure)
