"""The engine of generated virtual devices: memory, motion, replies and faults, driven by data from the spec.

A generated `simulator.py` holds only data (a `DeviceSpec` built from the spec's `device:` section, its tables and
its commands); everything a device does is here and is the same for every protocol:

- memory: the spec's table, initialised from its defaults (and the device section's `initial` values);
- a request whose address is a device's id is answered by that device, one whose address is the broadcast value is
  obeyed by every device, which stay silent unless the command says `broadcast_reply`;
- a response is built field by field: `reads` from memory, `reports` of a state variable or memory entry,
  then the request's field of the same name, then the device section's `reply` values, then 0;
- a response with `optional_when` is sent only while that parameter holds the value, and one with `after`
  once the request's field of that name (ms) has elapsed;
- `moves` makes a state variable go linearly from where it is to the request's target, over a duration or at a
  speed; reading it meanwhile gives the value on the way;
- faults can be injected for the next replies: drop, corrupt (checksum), late, garbage.
"""

from __future__ import annotations

import dataclasses
import heapq
import os
import random
import select
import threading
import time
import tty
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

from serialspec.runtime.errors import EncodeError
from serialspec.runtime.message import Message
from serialspec.runtime.stream import StreamParser


@dataclass(frozen=True)
class EntrySpec:
    """One memory entry (table row)."""

    name: str
    key: int
    default: float
    access: str  # "r" or "rw"
    minimum: float
    maximum: float


@dataclass(frozen=True)
class CommandSpec:
    """What a device does with one request type."""

    request: type[Message]
    response: type[Message] | None
    reads: tuple[str, ...] = ()
    writes: tuple[str, ...] = ()
    resets: bool = False
    reports: dict[str, str] = field(default_factory=dict)
    moves: tuple[str, str, str, str] | None = None  # state, target field, duration field (ms), speed field (/s)
    broadcast_reply: bool = False
    optional_when: tuple[int, int] | None = None  # (memory key, value) with which the response is sent
    after: str = ""  # request field: the response is sent after that many ms
    # table fields of the request and response: name -> ("value", key field) or ("block", entry names...)
    tables: dict[str, tuple[str, ...]] = field(default_factory=dict)


@dataclass(frozen=True)
class DeviceSpec:
    protocol: str
    address: str
    id_entry: str
    broadcast: int | None
    entries: tuple[EntrySpec, ...]
    state: dict[str, float]
    reply: dict[str, float]
    refused: dict[str, float]
    commands: tuple[CommandSpec, ...]


@dataclass
class _Motion:
    start: float
    target: float
    began: float
    duration: float

    def value(self, now: float) -> float:
        if self.duration <= 0 or now >= self.began + self.duration:
            return self.target
        return self.start + (self.target - self.start) * (now - self.began) / self.duration


class VirtualDevice:
    """One device on the virtual bus: its memory and state variables."""

    def __init__(self, spec: DeviceSpec, device_id: int, clock: Callable[[], float] = time.monotonic) -> None:
        self.spec = spec
        self.clock = clock
        self.by_name = {e.name: e for e in spec.entries}
        self.by_key = {e.key: e for e in spec.entries}
        self.memory: dict[int, float] = {}
        self.state: dict[str, float] = dict(spec.state)
        self.motions: dict[str, _Motion] = {}
        self.reset()
        self.id = device_id
        if spec.id_entry:
            self.memory[self.by_name[spec.id_entry].key] = device_id

    def reset(self) -> None:
        keep = self.memory.get(self.by_name[self.spec.id_entry].key) if self.spec.id_entry else None
        self.memory = {e.key: e.default for e in self.spec.entries}
        if keep is not None:
            self.memory[self.by_name[self.spec.id_entry].key] = keep

    def get(self, name: str) -> float:
        """A state variable or memory entry, with any motion in progress taken into account."""
        motion = self.motions.get(name)
        if motion is not None:
            value = motion.value(self.clock())
            return round(value)
        if name in self.state:
            return self.state[name]
        return self.memory[self.by_name[name].key]

    def set(self, name: str, value: float) -> None:
        self.motions.pop(name, None)
        if name in self.state:
            self.state[name] = value
        else:
            self.memory[self.by_name[name].key] = value

    def move(self, name: str, target: float, duration: float) -> None:
        now = self.clock()
        start = self.get(name)
        self.motions[name] = _Motion(start, target, now, max(0.0, duration))
        if name in self.state:
            self.state[name] = target
        else:
            self.memory[self.by_name[name].key] = target

    def writable(self, entry: EntrySpec | None, value: Any) -> bool:
        return (
            entry is not None
            and entry.access != "r"
            and isinstance(value, int | float)
            and entry.minimum <= value <= entry.maximum
        )


@dataclass
class Fault:
    kind: str  # drop, corrupt, late, garbage
    delay: float = 0.0


@dataclass(order=True)
class _Scheduled:
    when: float
    seq: int
    data: bytes = field(compare=False)


class Simulator:
    """Several virtual devices on one bus: feed request bytes, get reply bytes (with their send times)."""

    def __init__(
        self,
        spec: DeviceSpec,
        ids: Iterable[int],
        *,
        encode: Callable[[Message], bytes],
        parser: Callable[[], StreamParser],
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.spec = spec
        self.encode = encode
        self.clock = clock
        self.parser = parser()
        self.devices: dict[int, VirtualDevice] = {i: VirtualDevice(spec, i, clock) for i in ids}
        self.commands = {c.request: c for c in spec.commands}
        self.faults: list[Fault] = []
        self.log: list[Message] = []  # every request received, in order
        self._lock = threading.Lock()
        self._outbox: list[_Scheduled] = []
        self._seq = 0
        self._wake_r, self._wake_w = os.pipe()
        self._stop = threading.Event()

    # --- fault injection ------------------------------------------------------------------------------------------

    def inject(self, kind: str, count: int = 1, delay: float = 0.5) -> None:
        """Spoil the next `count` replies: drop, corrupt (bad checksum), late (by `delay` s), garbage (before it)."""
        if kind not in ("drop", "corrupt", "late", "garbage"):
            raise ValueError(f"unknown fault {kind!r} (expected drop, corrupt, late or garbage)")
        with self._lock:
            self.faults.extend(Fault(kind, delay) for _ in range(count))

    # --- requests -------------------------------------------------------------------------------------------------

    def feed(self, data: bytes) -> list[tuple[float, bytes]]:
        """Handle request bytes; returns (send time, bytes) for every reply they cause, faults applied."""
        out: list[tuple[float, bytes]] = []
        with self._lock:
            for request in self.parser.feed(data):
                self.log.append(request)
                for when, frame in self.handle(request):
                    out.extend(self._spoil(when, frame))
        return out

    def handle(self, request: Message) -> list[tuple[float, bytes]]:
        command = self.commands.get(type(request))
        if command is None:
            return []
        address = getattr(request, self.spec.address, None)
        broadcast = address is not None and address == self.spec.broadcast
        if address is None:
            targets = list(self.devices.values())[:1]
        elif broadcast:
            targets = list(self.devices.values())
        else:
            targets = [self.devices[address]] if address in self.devices else []
        replies = []
        for device in targets:
            frame = self.act(device, command, request)
            if frame is not None and (not broadcast or command.broadcast_reply):
                delay = float(getattr(request, command.after, 0)) / 1000 if command.after else 0.0
                replies.append((self.clock() + delay, frame))
        return replies

    def act(self, device: VirtualDevice, command: CommandSpec, request: Message) -> bytes | None:
        """Carry out a request on one device; the reply frame, or None for silence."""
        given = request.to_fields()
        refused = False
        if command.resets:
            device.reset()
        for name in command.writes:
            refused |= not self._write(device, command, name, given)
        if command.moves:
            state, target, duration_field, speed_field = command.moves
            goal = float(given[target])
            if duration_field:
                duration = float(given[duration_field]) / 1000
            elif speed_field and float(given[speed_field]):
                duration = abs(goal - device.get(state)) / float(given[speed_field])
            else:
                duration = 0.0
            device.move(state, goal, duration)
        if self.spec.id_entry and self.spec.id_entry in device.by_name:
            new_id = int(device.memory[device.by_name[self.spec.id_entry].key])
            if new_id != device.id and new_id not in self.devices:
                del self.devices[device.id]
                device.id = new_id
                self.devices[new_id] = device
        if command.response is None:
            return None
        if command.optional_when is not None:
            key, value = command.optional_when
            if device.memory.get(key) != value:
                return None
        values: dict[str, Any] = {}
        for attribute in dataclasses.fields(command.response):  # type: ignore[arg-type]
            name = attribute.name
            if name in command.reads:
                value = self._read(device, command, name, given)
                if value is None:
                    return None  # an unknown key: a device stays silent
                values[name] = value
            elif name in command.reports:
                values[name] = device.get(command.reports[name])
            elif name in given:
                values[name] = given[name]
            elif name in self.spec.reply:
                values[name] = self.spec.reply[name]
            else:
                values[name] = 0
        if refused:
            values.update(self.spec.refused)
        values = {k: int(v) if isinstance(v, float) and v.is_integer() else v for k, v in values.items()}
        try:
            reply = command.response.from_fields(values)  # type: ignore[attr-defined]
            return self.encode(reply)
        except EncodeError:
            return None

    def _read(self, device: VirtualDevice, command: CommandSpec, name: str, given: dict[str, Any]) -> Any:
        table = command.tables.get(name, ())
        if table[:1] == ("value",):
            entry = device.by_key.get(int(given[table[1]]))
            return None if entry is None else device.get(entry.name)
        if table[:1] == ("block",):
            return {n: device.get(n) for n in table[1:]}
        return device.get(name)

    def _write(self, device: VirtualDevice, command: CommandSpec, name: str, given: dict[str, Any]) -> bool:
        table = command.tables.get(name, ())
        if table[:1] == ("value",):
            entry = device.by_key.get(int(given[table[1]]))
            if not device.writable(entry, given[name]):
                return False
            assert entry is not None
            device.set(entry.name, given[name])
            return True
        if table[:1] == ("block",):
            block = given[name]
            ok = all(
                device.writable(device.by_name.get(n), block[n]) or device.by_name[n].access == "r" for n in table[1:]
            )
            if ok:
                for n in table[1:]:
                    if device.by_name[n].access != "r":
                        device.set(n, block[n])
            return ok
        device.set(name, given[name])
        return True

    def _spoil(self, when: float, frame: bytes) -> list[tuple[float, bytes]]:
        if not self.faults:
            return [(when, frame)]
        fault = self.faults.pop(0)
        if fault.kind == "drop":
            return []
        if fault.kind == "corrupt":
            return [(when, frame[:-1] + bytes([(frame[-1] + 1) & 0xFF]))]
        if fault.kind == "late":
            return [(when + fault.delay, frame)]
        garbage = bytes(random.randrange(256) for _ in range(7))
        return [(when, garbage + frame)]

    # --- serving on a file descriptor (a pseudo-terminal) ---------------------------------------------------------

    def serve(self, fd: int) -> None:
        """Answer requests read from `fd` until stop(); replies are written at their time (no polling)."""
        while not self._stop.is_set():
            now = self.clock()
            while self._outbox and self._outbox[0].when <= now:
                os.write(fd, heapq.heappop(self._outbox).data)
            wait = max(0.0, self._outbox[0].when - now) if self._outbox else None
            readable, _, _ = select.select([fd, self._wake_r], [], [], wait)
            if self._wake_r in readable:
                os.read(self._wake_r, 64)
            if fd in readable:
                try:
                    data = os.read(fd, 4096)
                except OSError:  # the other side closed (EIO on a pty): wait for a new peer
                    data = b""
                if not data:
                    self._stop.wait(0.01)
                    continue
                for when, frame in self.feed(data):
                    self._seq += 1
                    heapq.heappush(self._outbox, _Scheduled(when, self._seq, frame))

    def stop(self) -> None:
        self._stop.set()
        os.write(self._wake_w, b"x")

    def open_pty(self) -> tuple[int, str]:
        """A pseudo-terminal pair in raw mode: the controller fd this simulator serves and the device path."""
        controller, device = os.openpty()
        tty.setraw(device)
        tty.setraw(controller)
        path = os.ttyname(device)
        self._device_fd = device  # kept open so the pty survives clients that come and go
        return controller, path

    def start(self) -> str:
        """Serve on a new pseudo-terminal from a background thread; returns the device path."""
        controller, path = self.open_pty()
        self._thread = threading.Thread(target=self.serve, args=(controller,), daemon=True, name="serialspec-sim")
        self._thread.start()
        return path

    def close(self) -> None:
        self.stop()
        thread = getattr(self, "_thread", None)
        if thread is not None:
            thread.join(2)
