"""The device engine: virtual devices' memory, motion and replies, driven by data from the spec (see the package)."""

from __future__ import annotations

import dataclasses
import logging
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

from serialspec.runtime.device.faults import Fault, FaultInjection
from serialspec.runtime.errors import EncodeError
from serialspec.runtime.message import Message
from serialspec.runtime.registers import RegisterMap
from serialspec.runtime.stream import StreamParser

LOG = logging.getLogger("serialspec.sim")


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
    optional_when: tuple[str, int] | None = None  # (memory entry, value) with which the response is sent
    after: str = ""  # request field: the response is sent after that many ms
    # table fields of the request and response: name -> ("value", key field) or ("block", entry names...)
    tables: dict[str, tuple[str, ...]] = field(default_factory=dict)
    kind: str = ""  # the KindSpec addressed; "" for the default devices
    each: str = ""  # a request group whose items each address one device (item fields override the request's)
    stores: dict[str, str] = field(default_factory=dict)  # request field -> state variable
    sets: dict[str, float] = field(default_factory=dict)  # state variable -> value
    absent: dict[str, float] = field(default_factory=dict)  # response values when no device has the id
    buffered: bool = False  # the writes wait for a command that commits (REG WRITE)
    commits: bool = False  # carries out the buffered writes (ACTION)


@dataclass(frozen=True)
class KindSpec:
    """Devices of another kind on the same bus, with ids fixed by the hardware (not by --id)."""

    name: str
    address: str
    ids: tuple[int, ...]
    broadcast: int | None
    state: dict[str, float]


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
    kinds: tuple[KindSpec, ...] = ()
    echo_address: bool = False  # replies carry the id the request named, not the answering device's own
    registers: RegisterMap | None = None  # memory as registers at byte addresses, for run reads/writes
    status: dict[str, str] = field(default_factory=dict)  # response field -> memory entry every reply reports


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
        self.buffered: list[tuple[CommandSpec, str, dict[str, Any]]] = []  # writes held until a commit
        self.reset()
        self.id = device_id
        if spec.id_entry in self.by_name:
            self.memory[self.by_name[spec.id_entry].key] = device_id
        elif spec.id_entry in self.state:
            self.state[spec.id_entry] = device_id

    def reset(self) -> None:
        keep = self.memory.get(self.by_name[self.spec.id_entry].key) if self.spec.id_entry in self.by_name else None
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


class Engine(FaultInjection):
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
        # Each further kind: its devices, built from a DeviceSpec holding that kind's address and state.
        self.kinds: dict[str, dict[int, VirtualDevice]] = {}
        self._kind_specs: dict[str, DeviceSpec] = {}
        for kind in spec.kinds:
            kind_spec = dataclasses.replace(
                spec, address=kind.address, id_entry="", broadcast=kind.broadcast, entries=(), state=kind.state
            )
            self._kind_specs[kind.name] = kind_spec
            self.kinds[kind.name] = {i: VirtualDevice(kind_spec, i, clock) for i in kind.ids}
        self.commands = {c.request: c for c in spec.commands}
        self.log: list[Message] = []  # every request received, in order
        self._lock = threading.Lock()
        self._answering_as: Fault | None = None  # an other_id fault while the reply it spoils is built
        FaultInjection.__init__(self)

    # --- requests -------------------------------------------------------------------------------------------------

    def feed(self, data: bytes) -> list[tuple[float, bytes]]:
        """Handle request bytes; returns (send time, bytes) for every reply they cause, faults applied."""
        out: list[tuple[float, bytes]] = []
        with self._lock:
            for request in self.parser.feed(data):
                self.log.append(request)
                # Answering as another id changes what the reply says, so it applies while the reply is built.
                if self.faults and self.faults[0].kind == "other_id":
                    self._answering_as = self.faults.pop(0)
                try:
                    replies = self.handle(request)
                finally:
                    answered_as, self._answering_as = self._answering_as, None
                if answered_as is not None and not replies:
                    self.faults.insert(0, answered_as)  # no reply to spoil: keep the fault for the next one
                for when, frame in replies:
                    out.extend([(when, frame)] if answered_as is not None else self._spoil(when, frame))
        return out

    def handle(self, request: Message) -> list[tuple[float, bytes]]:
        command = self.commands.get(type(request))
        if command is None:
            return []
        spec = self._kind_specs[command.kind] if command.kind else self.spec
        devices = self.kinds[command.kind] if command.kind else self.devices
        fields = request.to_fields()
        # `each`: every item of the group addresses its own device, with the item's fields over the request's.
        items = [{**fields, **item} for item in fields[command.each]] if command.each else [fields]
        replies = []
        for given in items:
            address = given.get(spec.address)
            broadcast = address is not None and address == spec.broadcast
            if address is None:
                targets = list(devices.values())[:1]
            elif broadcast:
                targets = list(devices.values())
            else:
                targets = [devices[address]] if address in devices else []
            frames = [self.act(device, command, request, given) for device in targets]
            if not targets and command.absent:
                frames = [self._absent(command, given)]
            for frame in frames:
                if frame is not None and (not broadcast or command.broadcast_reply):
                    delay = float(getattr(request, command.after, 0)) / 1000 if command.after else 0.0
                    replies.append((self.clock() + delay, frame))
        return replies

    def _absent(self, command: CommandSpec, given: dict[str, Any]) -> bytes | None:
        """The reply a bus master gives for an id no device has: the request's fields, `absent` values, else 0."""
        if command.response is None:
            return None
        values = {
            a.name: command.absent.get(a.name, given.get(a.name, 0))
            for a in dataclasses.fields(command.response)  # type: ignore[arg-type]
        }
        return self._encode_reply(command.response, values)

    def _encode_reply(self, response: type[Message], values: dict[str, Any]) -> bytes | None:
        if self._answering_as is not None and isinstance(values.get(self.spec.address), int | float):
            address = int(values[self.spec.address])
            values = {**values, self.spec.address: self._answering_as.other_id(address, self.spec.broadcast)}
        values = {k: int(v) if isinstance(v, float) and v.is_integer() else v for k, v in values.items()}
        try:
            return self.encode(response.from_fields(values))  # type: ignore[attr-defined]
        except (EncodeError, TypeError, ValueError, KeyError) as exc:
            # never silent: the reply is not sent, and one line says why
            LOG.warning("simulator: no %s reply: %s", response.__name__, str(exc).splitlines()[0] if str(exc) else exc)
            return None

    def act(
        self, device: VirtualDevice, command: CommandSpec, request: Message, given: dict[str, Any] | None = None
    ) -> bytes | None:
        """Carry out a request on one device (`given`: its fields, an `each` item's merged in); the reply or None."""
        given = request.to_fields() if given is None else given
        refused = False
        # Whether an optional reply is due is decided on the switch as the request finds it (a write that turns
        # replies off is still answered), which is also what a client that remembers the switch expects.
        switch = command.optional_when
        answers = switch is None or device.get(switch[0]) == switch[1]
        if command.resets:
            device.reset()
        written: set[str] = set()
        if command.buffered:
            device.buffered.extend((command, name, given) for name in command.writes)
        else:
            for name in command.writes:
                refused |= not self._write(device, command, name, given, written)
        if command.commits:
            buffered, device.buffered = device.buffered, []
            for held_command, name, held in buffered:
                self._write(device, held_command, name, held, written)
        if command.moves:
            self._move(device, command.moves, given, written)
        for name, state in command.stores.items():
            device.set(state, given[name])
        for state, value in command.sets.items():
            device.set(state, value)
        id_entry = device.spec.id_entry
        if id_entry in device.by_name or id_entry in device.state:
            new_id = int(device.get(id_entry))
            if new_id != device.id and new_id not in self.devices:
                del self.devices[device.id]
                device.id = new_id
                self.devices[new_id] = device
        if command.response is None:
            return None
        if not answers:
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
            elif name == device.spec.address and not device.spec.echo_address:
                values[name] = device.id  # a device answers with its own id, also to a broadcast
            elif name in device.spec.status:
                values[name] = device.get(device.spec.status[name])
            elif command.tables.get(name, ())[:1] == ("run",):
                values[name] = b""  # a run of registers in a reply holds what was read: nothing here
            elif name in given:
                values[name] = given[name]
            elif name in self.spec.reply:
                values[name] = self.spec.reply[name]
            else:
                values[name] = 0
        if refused:
            values.update(self.spec.refused)
        return self._encode_reply(command.response, values)

    def _move(
        self, device: VirtualDevice, moves: tuple[str, str, str, str], given: dict[str, Any], written: set[str]
    ) -> None:
        """Start a move to the target: a request field, or a memory entry this command has just written."""
        state, target, duration_name, speed_name = moves
        if target not in given and target not in written:
            return

        def value(name: str) -> float:
            return float(given[name] if name in given else device.get(name))

        goal = value(target)
        if duration_name and value(duration_name):
            duration = value(duration_name) / 1000
        elif speed_name and value(speed_name):
            duration = abs(goal - device.get(state)) / value(speed_name)
        else:
            duration = 0.0
        device.move(state, goal, duration)

    def _read(self, device: VirtualDevice, command: CommandSpec, name: str, given: dict[str, Any]) -> Any:
        table = command.tables.get(name, ())
        if table[:1] == ("run",) and self.spec.registers is not None:
            return self._read_run(device, self.spec.registers, int(given[table[1]]), int(given[table[2]]))
        if table[:1] == ("value",):
            entry = device.by_key.get(int(given[table[1]]))
            return None if entry is None else device.get(entry.name)
        if table[:1] == ("block",):
            return {n: device.get(n) for n in table[1:]}
        return device.get(name)

    def _read_run(self, device: VirtualDevice, registers: RegisterMap, start: int, size: int) -> bytes:
        """`size` bytes of memory from register `start` on; bytes of no register read as 0."""
        data = bytearray()
        address = start
        while address < start + size:
            register = registers.by_address.get(address)
            if register is None:
                data.append(0)
                address += 1
                continue
            data += registers.to_wire(register, int(device.get(register.name)))
            address += register.size
        return bytes(data[:size])

    def _write_run(
        self, device: VirtualDevice, registers: RegisterMap, start: int, data: bytes, written: set[str]
    ) -> bool:
        """Store bytes written from register `start` on; refused whole unless every register is writable, in range."""
        try:
            values = registers.split(start, data)
        except EncodeError:
            return False
        if not all(device.writable(device.by_name.get(name), value) for name, value in values.items()):
            return False
        for name, value in values.items():
            device.set(name, value)
        written.update(values)
        return True

    def _write(
        self,
        device: VirtualDevice,
        command: CommandSpec,
        name: str,
        given: dict[str, Any],
        written: set[str] | None = None,
    ) -> bool:
        table = command.tables.get(name, ())
        if table[:1] == ("run",) and self.spec.registers is not None:
            start = int(given[table[1]])
            data = given[name]  # a message's to_fields() gives bytes as hex text
            data = bytes.fromhex(data) if isinstance(data, str) else bytes(data)
            return self._write_run(device, self.spec.registers, start, data, set() if written is None else written)
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
