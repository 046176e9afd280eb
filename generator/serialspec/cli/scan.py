"""serialspec scan: find the devices on a bus by the spec's presence request (`device.presence`).

For each baud rate (the spec's default; `--baudrate` given several times; `--all-baudrates`: the spec's
`serial.baudrates`) every id of the range gets the presence request and a short wait for a reply; any reply from
that id, an error reply too, is a device. Where every device answers the request sent to the broadcast id
(`presence.broadcast`: DYNAMIXEL's broadcast PING), one request finds them all; the ids are asked one by one only
when bytes came back that made no reply (replies that collided), never after silence. The model is then read where
the spec says (a reply field, or a register read by another request) and named from `device.models`.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from types import ModuleType
from typing import Any

from serialspec.cli import port_options
from serialspec.cli.protocols import SPEC_HELP, open_binary_spec
from serialspec.lang.model import Bytes, Direction, Presence, Protocol, Scalar, replies_by_request, reply_to
from serialspec.runtime.errors import PortError, SerialspecError
from serialspec.runtime.message import Message

#: The wait for a reply, beyond the time its bytes take on the line: a device's turnaround and a USB adapter's
#: latency (an FTDI chip's timer holds received bytes up to 16 ms by default).
SLACK = 0.04
#: The port's read timeout: how late a wait ends after its deadline, at most.
POLL = 0.005


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help=SPEC_HELP)
    parser.add_argument("--port", required=True, help="device path or pyserial URL (socket://, rfc2217://...)")
    parser.add_argument(
        "--ids", metavar="A-B", help="the ids to ask: a range A-B, one id, or a list (1-10,20); default: the spec's"
    )
    parser.add_argument(
        "--baudrate",
        dest="baudrates",
        type=int,
        action="append",
        metavar="N",
        help="a baud rate to scan at (repeat for several; default: the spec's)",
    )
    parser.add_argument(
        "--all-baudrates", action="store_true", help="scan at every rate the spec lists (serial.baudrates)"
    )
    parser.add_argument(
        "--timeout",
        type=float,
        metavar="S",
        help=f"seconds to wait for each id's reply (default: the time 64 characters take at the rate + {SLACK} s)",
    )
    parser.add_argument("--json", action="store_true", help="one JSON object per device found")
    port_options.add_arguments(parser, baudrate=False)


@dataclass(frozen=True)
class Found:
    id: int | None  # None: a protocol without an address (one device per port)
    baudrate: int
    model: str | int | None  # the model's name where the spec names its number, else the value read

    def as_json(self) -> dict[str, Any]:
        return {"id": self.id, "baudrate": self.baudrate, "model": self.model}


def run(args: argparse.Namespace) -> int:
    protocol, package = open_binary_spec(args.spec, "scan")
    presence = protocol.device.presence if protocol.device else None
    if presence is None:
        raise SerialspecError(f"{protocol.name} declares no way to find its devices (device.presence in the spec)")
    ids = _ids(args.ids, presence, protocol)
    rates = _rates(args, protocol)
    if args.timeout is not None and not 0 < args.timeout <= 10:
        raise SerialspecError(f"--timeout {args.timeout}: give seconds in (0, 10]")
    scanner = Scanner(protocol, package, presence)  # refuses a presence request that cannot be encoded
    progress = Progress(len(ids), len(rates)) if sys.stderr.isatty() else None
    found: list[Found] = []
    for rate in rates:
        wait = args.timeout if args.timeout is not None else 64 * 10 / rate + SLACK
        with port_options.open_port(args, package, rate, timeout=POLL) as port:
            for device in scanner.scan(port, ids, rate, wait, progress):
                found.append(device)
                if progress is not None:
                    progress.clear()
                _show(device, args.json)
    if progress is not None:
        progress.clear()
    if not found:
        what = f"ids {_ranges(ids)}" if presence.id_field else "the port"
        print(f"serialspec scan: no device answered on {what} at {', '.join(map(str, rates))} baud", file=sys.stderr)
        return 1
    return 0


def _show(device: Found, as_json: bool) -> None:
    if as_json:
        print(json.dumps(device.as_json(), ensure_ascii=False), flush=True)
    else:
        shown = "-" if device.id is None else str(device.id)
        model = "" if device.model is None else f"  model {device.model}"
        print(f"id {shown:>3}  {device.baudrate} baud{model}", flush=True)


class Scanner:
    """The presence and model requests of one protocol, sent and answered over a raw port."""

    def __init__(self, protocol: Protocol, package: ModuleType, presence: Presence) -> None:
        self.protocol = protocol
        self.package = package
        self.presence = presence
        replies = replies_by_request(protocol.messages())
        classes = {cls.__name__: cls for cls in package.MESSAGE_TYPES}

        def pair(key: str) -> tuple[Any, type[Message] | None]:
            spec = next(m for m in protocol.messages() if m.key == key and m.direction == Direction.REQUEST)
            reply = reply_to(spec, replies)
            return classes[spec.class_name], classes[reply.class_name] if reply else None

        self.request, self.reply = pair(presence.request)
        self.model_request: Any
        self.model_reply: type[Message] | None
        self.model_request, self.model_reply = pair(presence.model_request) if presence.model_field else (None, None)
        self.models = {m.number: m.name for m in protocol.device.models} if protocol.device else {}
        self.gap = 0.0  # seconds of silence before each request, set per baud rate
        # the presence request is checked (types, ranges) before a byte is written
        self.message(self.request, presence.fields, None if not presence.ids else presence.ids[0])

    def message(self, cls: Any, values: dict[str, float], device: int | None) -> Any:
        """The presence (or model) request to `device`, checked as encode will check it: the spec's values (bit fields
        given as `field.bit_field` made into their class), the fields' defaults for the others."""
        given: dict[str, Any] = {}
        for name, value in values.items():
            base, _, bit = name.partition(".")
            if bit:
                given.setdefault(base, {})[bit] = _whole(value)
            else:
                given[base] = _whole(value)
        spec = next(m for m in self.protocol.messages() if m.class_name == cls.__name__)
        layout = self.protocol.framing.layouts[Direction.REQUEST]
        scalars = [f for f in (*layout.value_elements, *spec.fields) if not isinstance(f, Scalar) or not f.hidden]
        for f in scalars:
            if isinstance(f, Scalar) and f.default is not None:
                given.setdefault(f.name, _whole(f.default))
            bits_class = getattr(f, "bits_class", "")
            if bits_class and isinstance(given.get(f.name), dict):
                given[f.name] = getattr(self.package, bits_class).from_fields(given[f.name])
        if device is not None:
            given[self.presence.id_field] = device
        try:
            message = cls(**given)
        except TypeError as exc:
            what = f"device.presence: {cls.COMMAND} cannot be built from the spec's values"
            raise SerialspecError(f"{what}: {exc}") from None
        self.package.encode(message)  # EncodeError/RangeError: one line naming the field, before any byte is sent
        return message

    def scan(self, port: Any, ids: list[int], rate: int, wait: float, progress: Progress | None) -> Iterator[Found]:
        """Each device that answers at this rate, as soon as it has (and its model has been read)."""
        presence = self.presence
        # the silence the protocol needs between frames (Modbus RTU: 3.5 characters), kept before each request
        self.gap = self.package.SERIAL.gap * 11 / rate
        if not presence.id_field:
            if progress is not None:
                progress.step(rate, 0)
            reply = self.ask(port, self.message(self.request, presence.fields, None), None, None, wait)
            if reply is not None:
                yield Found(None, rate, self.model(port, None, reply, wait))
            return
        found: dict[int, Message] = {}
        heard = True
        broadcast = self.protocol.device.broadcast if self.protocol.device else None
        if presence.broadcast and broadcast is not None:
            request = self.message(self.request, presence.fields, broadcast)
            found, heard = self.everyone(port, request, set(ids), wait, len(ids))
        for device in sorted(found):
            yield Found(device, rate, self.model(port, device, found[device], wait))
        # Each id in turn where there is no broadcast, or where bytes came back that made no reply (replies that
        # collided, devices at another rate); a silent line after a broadcast every device answers has nobody on it.
        if not found and heard:
            for number, device in enumerate(ids):
                if progress is not None:
                    progress.step(rate, number)
                reply = self.ask(port, self.message(self.request, presence.fields, device), device, None, wait)
                if reply is not None:
                    yield Found(device, rate, self.model(port, device, reply, wait))
        if progress is not None:
            progress.step(rate, len(ids))

    def ask(self, port: Any, request: Any, device: int | None, expect: type[Message] | None, wait: float) -> Any:
        """The first reply from `device` (of class `expect`, when given) within `wait` seconds, or None."""
        parser = self.parser(expect or self.reply, request)
        if self.gap:
            time.sleep(self.gap)
        port.reset_input_buffer()
        port.write(self.package.encode(request))
        deadline = time.monotonic() + wait
        while (left := deadline - time.monotonic()) > 0:
            for message in parser.feed(self.read(port, left)):
                if message.DIRECTION != Direction.RESPONSE or (expect is not None and message.__class__ is not expect):
                    continue
                if device is None or getattr(message, self.presence.id_field, device) == device:
                    return message
        return None

    def everyone(
        self, port: Any, request: Any, ids: set[int], wait: float, most: int
    ) -> tuple[dict[int, Message], bool]:
        """The replies to a broadcast request, each device in turn: read until `wait` passes without one; and
        whether any byte came at all."""
        parser = self.parser(self.reply, request)
        if self.gap:
            time.sleep(self.gap)
        port.reset_input_buffer()
        port.write(self.package.encode(request))
        found: dict[int, Message] = {}
        heard = False
        deadline = time.monotonic() + wait
        while (left := deadline - time.monotonic()) > 0 and len(found) < most:
            data = self.read(port, left)
            heard = heard or bool(data)
            for message in parser.feed(data):
                device = getattr(message, self.presence.id_field, None)
                if message.DIRECTION == Direction.RESPONSE and device in ids:
                    found[device] = message
                    deadline = time.monotonic() + wait  # the next device answers after this one
        return found, heard

    def model(self, port: Any, device: int | None, reply: Message, wait: float) -> str | int | None:
        presence = self.presence
        if not presence.model_field:
            return None
        if presence.model_request != presence.request or presence.model_fields:
            reply = self.ask(port, self.message(self.model_request, presence.model_fields, device), device, None, wait)
            if reply is None or reply.__class__ is not self.model_reply:
                return None  # there, but it did not say (a refusal, or no reply in time)
        value = getattr(reply, presence.model_field, None)
        register = presence.model_register
        if register is not None and isinstance(value, bytes):
            field = next(f for f in _reply_fields(self.protocol, presence) if f.name == presence.model_field)
            start = presence.model_fields.get(field.start, 0) if isinstance(field, Bytes) else 0
            offset = register.key - int(start)
            raw = value[offset : offset + register.type.size]
            if offset < 0 or len(raw) < register.type.size:
                return None
            value = int.from_bytes(raw, self.protocol.byte_order, signed=register.type.signed)
        if isinstance(value, bool) or not isinstance(value, int | str):
            return None if value is None else str(value)
        return self.models.get(value, value) if isinstance(value, int) else value

    def parser(self, expect: type[Message] | None, request: Any) -> Any:
        """A reply parser told what it waits for: the reply class, and the request it answers (RoboClaw's reply
        checksum starts with the request's address and command)."""
        parser = self.package.StreamParser(Direction.RESPONSE)
        parser.expect(expect, request)
        return parser

    @staticmethod
    def read(port: Any, left: float) -> bytes:
        """What comes within `left` seconds, at most a read timeout (POLL) later: the port's timeout is set once,
        as setting it reconfigures the line (a system call, and one some ports refuse)."""
        try:
            chunk: bytes = port.read(1)
            if chunk and port.in_waiting:
                chunk += port.read(port.in_waiting)
        except OSError as exc:
            raise PortError(f"{port.name}: read failed: {exc}") from None
        return chunk


def _reply_fields(protocol: Protocol, presence: Presence) -> tuple[Any, ...]:
    request = next(
        m for m in protocol.messages() if m.key == presence.model_request and m.direction == Direction.REQUEST
    )
    reply = reply_to(request, replies_by_request(protocol.messages()))
    return reply.fields if reply else ()


class Progress:
    """One line on stderr, rewritten in place: `[######    ] 120/254 ids at 1000000 baud (1 of 3)`."""

    WIDTH = 30

    def __init__(self, ids: int, rates: int) -> None:
        self.ids = ids
        self.total = max(ids * rates, 1)
        self.rates: list[int] = []

    def step(self, rate: int, index: int) -> None:
        if rate not in self.rates:
            self.rates.append(rate)
        done = min((len(self.rates) - 1) * self.ids + index, self.total)
        filled = self.WIDTH * done // self.total
        bar = "#" * filled + " " * (self.WIDTH - filled)
        sys.stderr.write(f"\r[{bar}] {done}/{self.total} at {rate} baud")
        sys.stderr.flush()

    def clear(self) -> None:
        sys.stderr.write("\r" + " " * (self.WIDTH + 40) + "\r")
        sys.stderr.flush()


def _ids(text: str | None, presence: Presence, protocol: Protocol) -> list[int]:
    """The ids to ask, checked against the device's id range before a byte is written."""
    if not presence.id_field:
        if text:
            raise SerialspecError(f"--ids: {protocol.name} has no device ids (one device per port)")
        return [0]
    assert presence.ids is not None
    if not text:
        first, last = presence.ids
        return list(range(first, last + 1))
    from serialspec.cli.sim import id_range

    low, high, broadcast = id_range(protocol)
    ids: list[int] = []
    for part in text.split(","):
        first_text, dash, last_text = part.strip().partition("-")
        try:
            first = int(first_text, 0)
            last = int(last_text, 0) if dash else first
        except ValueError:
            raise SerialspecError(f"--ids {text}: give ids as A-B, N or a list (1-10,20)") from None
        if first > last:
            raise SerialspecError(f"--ids {part.strip()}: the first id is above the last")
        for number in (first, last):
            if not low <= number <= high or number == broadcast:
                raise SerialspecError(
                    f"--ids: {presence.id_field} = {number} is outside the id range {low}..{high}"
                    + (f" (without the broadcast id {broadcast})" if broadcast is not None else "")
                )
        ids += [i for i in range(first, last + 1) if i != broadcast and i not in ids]
    return ids


def _ranges(ids: list[int]) -> str:
    runs: list[str] = []
    start = previous = ids[0]
    for number in [*ids[1:], None]:
        if number is not None and number == previous + 1:
            previous = number
            continue
        runs.append(str(start) if start == previous else f"{start}-{previous}")
        if number is not None:
            start = previous = number
    return ",".join(runs)


def _rates(args: argparse.Namespace, protocol: Protocol) -> list[int]:
    rates = list(args.baudrates or ())
    if args.all_baudrates:
        if not protocol.serial.baudrates:
            raise SerialspecError(f"--all-baudrates: {protocol.name} lists no baud rates (serial.baudrates)")
        rates += [r for r in protocol.serial.baudrates if r not in rates]
    for rate in rates:
        if rate <= 0:
            raise SerialspecError(f"--baudrate {rate}: give a positive number of bits per second")
    return rates or [protocol.serial.baudrate]


def _whole(value: float) -> float:
    """A spec's number as an int where it is whole (a field's value), else as it is."""
    return int(value) if float(value).is_integer() else value
