"""The device engine: virtual devices' memory, motion and replies, driven by data from the spec (see the package)."""

from __future__ import annotations

import dataclasses
import logging
import math
import struct
import threading
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from serialspec.runtime.device.faults import Fault, FaultInjection
from serialspec.runtime.errors import DecodeError, EncodeError
from serialspec.runtime.message import Message, compare, field_keys, is_sequence, takes_request
from serialspec.runtime.registers import RegisterMap
from serialspec.runtime.stream import StreamParser

LOG = logging.getLogger("serialspec.sim")


@dataclass(frozen=True)
class CountedBlank:
    """The blank of a list, group, bytes or text whose count an expression of earlier fields gives (`count: n + 1`,
    lang/counts.py): as many blank items as the reply's values so far make it (none for a negative count), so that
    the reply the device sends is consistent."""

    count: Callable[[dict[str, Any]], int]
    item: Any  # one item's blank: a number, a group item's values, "00" (bytes, as hex) or " " (text)

    def fill(self, values: dict[str, Any]) -> Any:
        n = max(self.count(values), 0)
        if self.item == "00":
            return " ".join(["00"] * n)
        if self.item == " ":
            return " " * n
        return [self.item] * n


@dataclass(frozen=True)
class EntrySpec:
    """One memory entry (table row)."""

    name: str
    key: int
    default: float
    access: str  # "r", "rw" or "w1c" (a write clears the bits written as 1)
    minimum: float
    maximum: float


@dataclass(frozen=True)
class SpaceSpec:
    """A data space: `size` items (bits, or integers `minimum`..`maximum`) addressed 0..size-1, all 0 at first."""

    name: str
    size: int
    bits: bool
    maximum: int
    access: str = "rw"
    minimum: int = 0  # below 0: signed items, a value written wraps to them as two's complement does


@dataclass(frozen=True)
class RunSpec:
    """A run of a data space from the address in the request field `start`; `count` items for reads; for writes,
    `value(current, fields)` computes what is stored (default: the request field's value). `single`: read into one
    number, the item itself rather than a list of one."""

    space: str
    start: str
    count: str = ""
    value: Callable[[int, dict[str, Any]], int] | None = None
    single: bool = False


@dataclass(frozen=True)
class ErrorSpec:
    """The protocol's error reply, which a device sends instead of a request's own response when it refuses it: its
    class and the member holding the refused request's code (Modbus: function | 0x80). DeviceSpec.errors says what
    else it holds for each reason."""

    response: type[Message]
    code_field: str
    # unwrap(frame) -> (code, frame values) of a whole request frame whose checksum verifies (the frame engine's),
    # for requests the codec cannot decode because their code is unknown
    unwrap: Callable[[bytes], tuple[int | None, tuple[int, ...]]] | None = None
    # told by its status (`error_bits`): the status element's name and its bit fields (name, lowest, highest bit),
    # all 0 but those the reason gives
    status: tuple[str, tuple[tuple[str, int, int], ...]] | None = None


@dataclass(frozen=True)
class CommandSpec:
    """What a device does with one request type."""

    request: type[Message]
    response: type[Message] | None
    reads: tuple[str, ...] = ()
    writes: tuple[str, ...] = ()
    resets: bool = False
    keeps: tuple[str, dict[int, tuple[str, ...]]] | None = None  # resets: request field, its value -> entries kept
    # response field -> the state variable or memory entry it reports, or a function of `get` (a unit conversion)
    reports: dict[str, str | Callable[[Callable[[str], float]], float]] = field(default_factory=dict)
    moves: tuple[str, str, str, str] | None = None  # state, target field, duration field (ms), speed field (/s)
    broadcast_reply: bool = False
    optional_when: tuple[str, int, str] | None = None  # (memory entry, value, comparison): when it is sent
    after: str = ""  # request field: the response is sent after that many ms
    # table fields of the request and response: name -> ("value", key field) or ("block", entry names...)
    tables: dict[str, tuple[str, ...]] = field(default_factory=dict)
    kind: str = ""  # the KindSpec addressed; "" for the default devices
    each: str = ""  # a request group whose items each address one device (item fields override the request's)
    stores: dict[str, str] = field(default_factory=dict)  # request field -> state variable
    sets: dict[str, float] = field(default_factory=dict)  # state variable -> value
    speed_scale: float = 1.0  # moves: state units per second for one unit of the speed field
    move_enabled_by: str = ""  # moves: only while this memory entry (or state variable) is non-zero
    absent: dict[str, float] = field(default_factory=dict)  # response values when no device has the id
    buffered: bool = False  # the writes wait for a command that commits (REG WRITE)
    commits: bool = False  # carries out the buffered writes (ACTION)
    code: int | None = None  # the request's code, for an error reply that refuses it
    # request value -> (lowest, highest, allowed values or ()) the device accepts; for a list, its number of items
    limits: dict[str, tuple[float, float, tuple[int, ...]]] = field(default_factory=dict)
    space_reads: dict[str, RunSpec] = field(default_factory=dict)  # response field -> run of a data space
    space_writes: dict[str, RunSpec] = field(default_factory=dict)  # request field -> run of a data space
    # values a request carries that its message does not hold (counts, byte counts), from its fields: a reply
    # field of the same name echoes them like any other request field
    derived: dict[str, Callable[[dict[str, Any]], int]] = field(default_factory=dict)
    nothing_held: dict[str, float] = field(default_factory=dict)  # commits: reply values when nothing is held
    ramp: tuple[str, str] | None = None  # request fields: acceleration and deceleration time (ms) of the move
    stops: tuple[str, ...] = ()  # state variables whose move stops where it is
    increments: tuple[str, ...] = ()  # state variables (or memory entries) 1 is added to per request carried out
    wraps: dict[str, float] = field(default_factory=dict)  # state variable -> the period it is kept within
    modulo: dict[str, float] = field(default_factory=dict)  # state variable -> period: kept in 0..period-1
    restores: tuple[str, ...] = ()  # memory entries back to their initial values, their moves stopped (a reboot)
    broadcast_ignores: dict[str, float] = field(default_factory=dict)  # request field -> value: broadcast ignored
    # response field -> its value when nothing else gives one, where that is not 0: the empty value of its kind
    # (a list, text, bytes, items), or a function of the request's fields (as many items as the request asks for)
    blanks: dict[str, Any] = field(default_factory=dict)
    echoes: tuple[str, ...] = ()  # response fields that repeat the request's field of the same name
    refused_while_moving: str = ""  # state variable: while it moves, the request is refused ("busy")
    counts: dict[str, tuple[str, float]] = field(default_factory=dict)  # response field -> (state, per)
    every_device: bool = False  # a request without an address reaches every device, not only the first
    held_while: str = ""  # state variable: while it is set, the device holds the request
    releases: str = ""  # state variable: cleared, and the requests held meanwhile carried out
    cancel_when: dict[str, float] = field(default_factory=dict)  # with releases: the values that drop them
    carries: tuple[str, str] | None = None  # (code field, content field): another command's request content
    refusal: type[Message] | None = None  # the reply of another command a refused request gets (`refused_by`)
    final: type[Message] | None = None  # the response that ends each answer, after the reply (text frames' `then`)
    # (request field, code -> request class): the request asks for the command whose code the field holds, and the
    # device acts as on that command's request (`answered_by: {command_in: FIELD}`)
    asks: tuple[str, dict[int, type[Message]]] | None = None
    # moves: where the state goes, a function of `get` (request fields, then memory and state); default: the target
    move_to: Callable[[Callable[[str], float]], float] | None = None
    # request and response fields made of bit fields -> (bit field, lowest bit, highest bit)...: the device keeps
    # such a field in memory or state as one integer (a register), and answers it bit field by bit field
    bit_fields: dict[str, tuple[tuple[str, int, int], ...]] = field(default_factory=dict)


@dataclass(frozen=True)
class SendSpec:
    """A message a device sends on its own (`device.sends`): every `every` seconds, after a reply to one of the
    `after` requests, or when one of the `changes` values changes; only while `while_` is non-zero (when given).
    `every` may be a function of `get` (state and memory) giving the period in ms, worked out for each period."""

    response: type[Message]
    every: float | Callable[[Callable[[str], float]], float] = 0.0
    after: tuple[type[Message], ...] = ()
    changes: tuple[str, ...] = ()
    while_: str = ""
    # field -> the state variable or memory entry it holds, or a function of `get` (as CommandSpec.reports)
    values: dict[str, str | Callable[[Callable[[str], float]], float]] = field(default_factory=dict)
    blanks: dict[str, Any] = field(default_factory=dict)  # as CommandSpec.blanks
    step: str = ""  # state variable: 1 is added to it before each send
    bit_fields: dict[str, tuple[tuple[str, int, int], ...]] = field(default_factory=dict)  # as CommandSpec's

    @property
    def command(self) -> CommandSpec:
        """The message built as a reply is: its values, then the device's id, `reply` values, blanks."""
        return CommandSpec(
            self.response, self.response, reports=self.values, blanks=self.blanks, bit_fields=self.bit_fields
        )


@dataclass(frozen=True)
class KindSpec:
    """Devices of another kind on the same bus, with ids fixed by the hardware (not by --id)."""

    name: str
    address: str
    ids: tuple[int, ...]
    broadcast: int | None
    state: dict[str, float]


@dataclass(frozen=True)
class TimeoutSpec:
    """The device sets `sets` once none of the `kept_by` requests has come for `after` seconds (VESC releases the
    motor); checked whenever a request arrives, and by Engine.tick()."""

    after: float
    kept_by: tuple[type[Message], ...]
    sets: dict[str, float]


@dataclass(frozen=True)
class ModelSpec:
    """One device model: its factory values and the ranges where they differ from the table's."""

    name: str
    number: int
    values: dict[str, float]  # memory entry or state variable -> value at power-on (and after a reset)
    ranges: dict[str, tuple[float, float]] = field(default_factory=dict)  # memory entry -> its writable range


@dataclass(frozen=True)
class DeviceSpec:
    protocol: str
    address: str
    id_entry: str
    broadcast: int | None
    entries: tuple[EntrySpec, ...]
    state: dict[str, float]
    reply: dict[str, Any]
    commands: tuple[CommandSpec, ...]
    kinds: tuple[KindSpec, ...] = ()
    echo_address: bool = False  # replies carry the id the request named, not the answering device's own
    registers: RegisterMap | None = None  # memory as registers at byte addresses, for run reads/writes
    status: dict[str, str] = field(default_factory=dict)  # response field -> memory entry every reply reports
    spaces: tuple[SpaceSpec, ...] = ()
    error: ErrorSpec | None = None
    timeout: TimeoutSpec | None = None
    # why a request is refused ("out_of_range", "out_of_space", "read_only", "unsupported") -> the reply values
    # saying so, in the error reply when there is one, else in the request's own response; a reason not given
    # is not refused
    errors: dict[str, dict[str, float]] = field(default_factory=dict)
    models: tuple[ModelSpec, ...] = ()  # the first is the default model
    moving: dict[str, tuple[str, int | None]] = field(default_factory=dict)  # entry -> (state variable, bit)
    # command code -> the codec's decoder of that request's content (buf, start, end), for requests carried by another
    carried: dict[int, Callable[[bytes, int, int], Message]] = field(default_factory=dict)
    # memory entry -> what it reads as, a function of `get` (DYNAMIXEL present_position: position + homing_offset)
    derived: dict[str, Callable[[Callable[[str], float]], float]] = field(default_factory=dict)
    locks: dict[str, str] = field(default_factory=dict)  # memory entry -> variable: not writable while non-zero
    sends: tuple[SendSpec, ...] = ()  # what the devices send on their own

    def model(self, name: str | None) -> ModelSpec | None:
        """The model of this name (None: the default one); a ValueError names the known models."""
        if name is None:
            return self.models[0] if self.models else None
        for model in self.models:
            if model.name == name:
                return model
        if not self.models:
            raise ValueError(f"unknown model {name!r}: the spec lists no device models")
        raise ValueError(f"unknown model {name!r} (expected one of: {', '.join(m.name for m in self.models)})")


@dataclass
class _Motion:
    """A move from start to target over `duration` s: linear, or trapezoidal with ramps up and down (s)."""

    start: float
    target: float
    began: float
    duration: float
    accel: float = 0.0
    decel: float = 0.0

    def active(self, now: float) -> bool:
        return now < self.began + self.duration

    def value(self, now: float) -> float:
        t, total = now - self.began, self.duration
        if total <= 0 or t >= total:
            return self.target
        ramps = self.accel + self.decel
        up, down = (
            (self.accel, self.decel) if ramps <= total else (total * self.accel / ramps, total * self.decel / ramps)
        )
        peak = 1 / (total - up / 2 - down / 2)  # the cruise speed, as a fraction of the distance per second
        if t < up:
            done = peak * t * t / (2 * up)
        elif t <= total - down:
            done = peak * (t - up / 2)
        else:
            done = 1 - peak * (total - t) ** 2 / (2 * down)
        return self.start + (self.target - self.start) * done


class VirtualDevice:
    """One device on the virtual bus: its memory and state variables."""

    def __init__(
        self,
        spec: DeviceSpec,
        device_id: int,
        clock: Callable[[], float] = time.monotonic,
        model: ModelSpec | None = None,
        sizes: dict[str, int] | None = None,
    ) -> None:
        self.spec = spec
        self.clock = clock
        self.model = model
        self.spaces: dict[str, list[int]] = {s.name: [0] * (sizes or {}).get(s.name, s.size) for s in spec.spaces}
        values = model.values if model else {}
        ranges = model.ranges if model else {}
        # The model's factory values and ranges replace the table's where it gives them.
        entries = [
            dataclasses.replace(e, default=values.get(e.name, e.default), minimum=low, maximum=high)
            for e in spec.entries
            for low, high in [ranges.get(e.name, (e.minimum, e.maximum))]
        ]
        self.by_name = {e.name: e for e in entries}
        self.by_key = {e.key: e for e in entries}
        self.memory: dict[int, float] = {}
        self.state: dict[str, float] = {k: values.get(k, v) for k, v in spec.state.items()}
        self.motions: dict[str, _Motion] = {}
        self.buffered: list[tuple[CommandSpec, str, dict[str, Any]]] = []  # writes held until a commit
        self.kept = clock()  # when a request last restarted the timeout
        self.timed_out = False
        self.held: list[tuple[CommandSpec, Message, dict[str, Any]]] = []  # requests held until a release
        self.reset()
        self.id = device_id
        if spec.id_entry in self.by_name:
            self.memory[self.by_name[spec.id_entry].key] = device_id
        elif spec.id_entry in self.state:
            self.state[spec.id_entry] = device_id

    def reset(self, keep: tuple[str, ...] | None = None) -> None:
        """Memory back to its defaults, but for the entries in `keep` (default: the device's id)."""
        if keep is None:
            keep = (self.spec.id_entry,) if self.spec.id_entry in self.by_name else ()
        keys = [self.by_name[n].key for n in keep if n in self.by_name]
        kept = {key: self.memory[key] for key in keys if key in self.memory}
        self.memory = {e.key: e.default for e in self.by_name.values()}
        self.memory.update(kept)

    def get(self, name: str) -> float:
        """A state variable or memory entry, with any motion in progress taken into account; a derived entry is
        what its expression gives."""
        derive = self.spec.derived.get(name)
        if derive is not None:
            return derive(self.get)
        motion = self.motions.get(name)
        if motion is not None:
            value = motion.value(self.clock())
            return round(value)
        value = self.state[name] if name in self.state else self.memory[self.by_name[name].key]
        reports = self.spec.moving.get(name)
        if reports is None:
            return value
        state, bit = reports
        on_its_way = state in self.motions and self.motions[state].active(self.clock())
        if bit is None:
            return float(on_its_way)
        return float(int(value) | 1 << bit if on_its_way else int(value) & ~(1 << bit))

    def set(self, name: str, value: float) -> None:
        self.motions.pop(name, None)
        if name in self.state:
            self.state[name] = value
        else:
            self.memory[self.by_name[name].key] = value

    def move(self, name: str, target: float, duration: float, accel: float = 0.0, decel: float = 0.0) -> None:
        now = self.clock()
        start = self.get(name)
        self.motions[name] = _Motion(start, target, now, max(0.0, duration), max(0.0, accel), max(0.0, decel))
        if name in self.state:
            self.state[name] = target
        else:
            self.memory[self.by_name[name].key] = target

    def store(self, name: str, value: Any) -> None:
        """A request's write of a memory entry: the value kept, or for a write-1-to-clear entry (`access: w1c`) the
        bits written as 1 cleared and the others kept."""
        entry = self.by_name.get(name)
        if entry is not None and entry.access == "w1c":
            value = int(self.get(name)) & ~int(value)
        self.set(name, value)

    def writable(self, entry: EntrySpec | None, value: Any) -> bool:
        return not self.refusal(entry, value)

    def refusal(self, entry: EntrySpec | None, value: Any) -> str:
        """Why a write is refused: "out_of_space" (no such entry), "read_only", "out_of_range", or "" (it is not)."""
        if entry is None:
            return "out_of_space"
        if entry.access == "r":
            return "read_only"
        locker = self.spec.locks.get(entry.name)
        if locker and self.get(locker):
            return "locked"
        if not isinstance(value, int | float):
            return "out_of_range"
        return "" if entry.minimum <= value <= entry.maximum else "out_of_range"


class Engine(FaultInjection):
    """Several virtual devices on one bus: feed request bytes, get reply bytes (with their send times)."""

    def __init__(
        self,
        spec: DeviceSpec,
        ids: Iterable[int],
        *,
        encode: Callable[..., bytes],
        parser: Callable[[], StreamParser],
        clock: Callable[[], float] = time.monotonic,
        model: str | Mapping[int, str] | None = None,
        sizes: dict[str, int] | None = None,
    ) -> None:
        """`model`: the model of every device (a name of `spec.models`), or id -> name (others: the default)."""
        self.spec = spec
        self.encode = encode
        # a codec whose replies are made with the request they answer (layouts chosen by command, a reply checksum
        # over request bytes) takes it: the request being answered is given to it
        self._requests = takes_request(encode)
        self._request: Message | None = None
        self.clock = clock
        self.parser = parser()
        self._new_parser = parser
        unknown_spaces = set(sizes or {}) - {s.name for s in spec.spaces}
        if unknown_spaces:
            known = ", ".join(s.name for s in spec.spaces) or "none"
            raise ValueError(f"unknown data space(s) {', '.join(sorted(unknown_spaces))} (this device has: {known})")
        ids = list(ids)
        per_id: Mapping[int, str] = model if isinstance(model, Mapping) else {}
        every = None if isinstance(model, Mapping) else model
        unknown = set(per_id) - set(ids)
        if unknown:
            raise ValueError(f"a model is given for id {min(unknown)}, which is not on the bus")
        self.devices: dict[int, VirtualDevice] = {
            i: VirtualDevice(spec, i, clock, spec.model(per_id.get(i, every)), sizes) for i in ids
        }
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
        # sends: (device, index) -> when the next periodic one is due, and the watched values last sent with (by
        # the device itself, whose id a request may change)
        self._next_send: dict[tuple[VirtualDevice, int], float] = {}
        self._watched: dict[tuple[VirtualDevice, int], tuple[float | None, ...]] = {}
        for device in self.devices.values():
            for index, send in enumerate(spec.sends):
                self._watched[device, index] = tuple(self._value(device, n) for n in send.changes)
        FaultInjection.__init__(self)

    # --- requests -------------------------------------------------------------------------------------------------

    def feed(self, data: bytes) -> list[tuple[float, bytes]]:
        """Handle request bytes; returns (send time, bytes) for every reply they cause, faults applied."""
        out: list[tuple[float, bytes]] = []
        with self._lock:
            requests = self.parser.feed(data)
            if not requests:
                refused = self._unsupported(data)
                if refused:
                    self.parser = self._new_parser()  # the bytes were that frame: nothing of them is pending
                out.extend(refused)
            for request in requests:
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

    # --- messages sent on the device's own initiative ---------------------------------------------------------------

    def due(self) -> list[tuple[float, bytes]]:
        """The messages the devices send on their own now (`sends`): periodic ones whose time has come (one per
        call, however many periods went by), and those whose watched values changed since they were last sent."""
        out: list[tuple[float, bytes]] = []
        with self._lock:
            now = self.clock()
            for device in list(self.devices.values()):
                for index, send in enumerate(self.spec.sends):
                    key = (device, index)
                    sending = False
                    if send.every:
                        next_time = self._next_send.get(key, now)
                        if next_time <= now:
                            period = self._period(device, send)
                            if period is None:  # no period now (a rate of 0): looked at again in 10 ms
                                self._next_send[key] = now + 0.01
                            else:
                                sending = True
                                # the next one a period on, or a period from now when the clock jumped further
                                following = next_time + period
                                self._next_send[key] = following if following > now else now + period
                    if send.changes:
                        values = tuple(self._value(device, n) for n in send.changes)
                        if values != self._watched.get(key):
                            self._watched[key] = values
                            sending = True
                    frame = self._sent(device, send) if sending else None
                    if frame is not None:
                        out.append((now, frame))
        return out

    @staticmethod
    def _period(device: VirtualDevice, send: SendSpec) -> float | None:
        """The period of a periodic message in seconds: `every`, or what its expression gives now (in ms); None
        where that has no value (a division by a rate written as 0) or is not positive."""
        if not callable(send.every):
            return send.every
        try:
            period = send.every(device.get) / 1000
        except (ZeroDivisionError, ValueError):
            return None
        return period if period > 0 else None

    def _value(self, device: VirtualDevice, name: str) -> float | None:
        """A watched value; None where an expression of the spec has none (a division by a value written as 0)."""
        try:
            return device.get(name)
        except (ZeroDivisionError, ValueError):
            return None

    def _sent(self, device: VirtualDevice, send: SendSpec) -> bytes | None:
        """The message a device sends on its own, if `while_` lets it; where an expression of the spec has no value
        (a division by a value written as 0), nothing is sent and one line says why, as for a reply."""
        try:
            if send.while_ and not device.get(send.while_):
                return None
            if send.step:
                device.set(send.step, device.get(send.step) + 1)
            return self._reply(device, send.command, {}, "")
        except (ZeroDivisionError, ValueError) as exc:
            LOG.warning(
                "simulator: no %s sent: a value of the spec has no value here (%s)", send.response.__name__, exc
            )
            return None

    def next_due(self) -> float | None:
        """When due() next has something periodic to send (None: nothing is periodic); watched values are polled
        every 10 ms."""
        times = [t for t in self._next_send.values()]
        if any(
            s.every and (d, n) not in self._next_send
            for n, s in enumerate(self.spec.sends)
            for d in self.devices.values()
        ):
            times.append(self.clock())
        if any(s.changes for s in self.spec.sends):
            times.append(self.clock() + 0.01)
        return min(times) if times else None

    def _sent_after(self, device: VirtualDevice, request: Message) -> list[bytes]:
        """The messages a device sends on its own after answering this request (`sends: after`)."""
        frames = []
        for send in self.spec.sends:
            frame = self._sent(device, send) if isinstance(request, send.after) else None
            frames += [frame] if frame is not None else []
        return frames

    def tick(self) -> None:
        """Let the timeout of every device expire that is due (requests do this too, as they arrive)."""
        timeout = self.spec.timeout
        if timeout is None:
            return
        now = self.clock()
        for device in self.devices.values():
            if not device.timed_out and now - device.kept > timeout.after:
                device.timed_out = True
                for name, value in timeout.sets.items():
                    device.set(name, value)

    def handle(self, request: Message) -> list[tuple[float, bytes]]:
        self._request = request
        timeout = self.spec.timeout
        if timeout is not None:
            self.tick()
            if isinstance(request, timeout.kept_by):
                for device in self.devices.values():
                    device.kept, device.timed_out = self.clock(), False
        command = self.commands.get(type(request))
        if command is None:
            return []
        spec = self._kind_specs[command.kind] if command.kind else self.spec
        devices = self.kinds[command.kind] if command.kind else self.devices
        fields = request.to_fields()
        # `each`: every item of the group addresses its own device, with the item's fields over the request's.
        items = [{**fields, **item} for item in fields[command.each]] if command.each else [fields]
        replies = []
        if command.asks:  # it asks for another command's reply: the devices act on that command's request
            asked = self._asked(fields, *command.asks)
            return self.handle(asked) if asked is not None else []
        if command.carries:  # each item holds another command's request: the devices act on that one
            for given in items:
                carried = self._carried(given, *command.carries)
                replies.extend(self.handle(carried) if carried is not None else [])
            return replies
        for given in items:
            address = given.get(spec.address)
            broadcast = address is not None and address == spec.broadcast
            if broadcast and any(given.get(k) == v for k, v in command.broadcast_ignores.items()):
                continue
            if address is None:
                targets = list(devices.values()) if command.every_device else list(devices.values())[:1]
            elif broadcast:
                targets = list(devices.values())
            else:
                targets = [devices[address]] if address in devices else []
            frames = [self._acted(device, command, request, given) for device in targets]
            if not targets and command.absent:
                frames = [self._absent(command, given)]
            for frame in frames:
                if frame is not None and (not broadcast or command.broadcast_reply):
                    delay = float(given.get(command.after, 0)) / 1000 if command.after else 0.0
                    replies.append((self.clock() + delay, frame))
            if self.spec.sends and not command.kind:
                at = max((when for when, _ in replies), default=self.clock())
                replies += [(at, frame) for device in targets for frame in self._sent_after(device, request)]
        return replies

    def _acted(
        self, device: VirtualDevice, command: CommandSpec, request: Message, given: dict[str, Any]
    ) -> bytes | None:
        """act(), where an expression of the spec with no value for what came off the wire (a division by a value
        written as 0, a negative shift) answers nothing and logs one line, as a frame the device cannot act on."""
        try:
            return self.act(device, command, request, given)
        except (ZeroDivisionError, ValueError) as exc:
            LOG.warning(
                "simulator: no reply to %s: a value of the spec has no value here (%s)", type(request).__name__, exc
            )
            return None

    def _carried(self, given: dict[str, Any], code_field: str, content_field: str) -> Message | None:
        """The request a sync command carries for one device: its content parsed as that command's request."""
        decoder = self.spec.carried.get(int(given[code_field]))
        if decoder is None:
            return None  # a command the device does not know: ignored, as a frame of an unknown command would be
        data = given[content_field]
        content = bytes.fromhex(data) if isinstance(data, str) else bytes(data)
        try:
            return decoder(content, 0, len(content))
        except (DecodeError, ValueError, struct.error):
            return None  # a block that does not parse as that request is ignored, like a bad frame

    def _asked(self, given: dict[str, Any], code_field: str, requests: dict[int, type[Message]]) -> Message | None:
        """The request a request for another command stands for: that command's, with the frame values (address,
        ...) the asking request carries; None for a code the device does not know, or whose request needs content
        (the device ignores it, as it would a frame it cannot act on)."""
        request = requests.get(int(given[code_field]))
        if request is None:
            return None
        names = field_keys(request)
        try:
            return request.from_fields({name: given[name] for name in names if name in given})  # type: ignore[attr-defined, no-any-return]
        except (EncodeError, TypeError, ValueError, KeyError):
            return None

    def _absent(self, command: CommandSpec, given: dict[str, Any]) -> bytes | None:
        """The reply a bus master gives for an id no device has: the request's fields, `absent` values, else 0."""
        if command.response is None:
            return None
        values = {name: command.absent.get(name, given.get(name, 0)) for name in field_keys(command.response)}
        return self._encode_reply(command.response, values)

    def _encode_reply(self, response: type[Message], values: dict[str, Any]) -> bytes | None:
        if self._answering_as is not None and isinstance(values.get(self.spec.address), int | float):
            address = int(values[self.spec.address])
            values = {**values, self.spec.address: self._answering_as.other_id(address, self.spec.broadcast)}
        values = _whole(values)
        if getattr(self._request, "unchecked", False) and hasattr(response, "unchecked"):
            values["unchecked"] = True  # asked without its optional checksum: answered without one (ODrive)
        try:
            reply = response.from_fields(values)  # type: ignore[attr-defined]
            if self._requests and self._request is not None:
                return self.encode(reply, self._request)
            return self.encode(reply)
        except (EncodeError, TypeError, ValueError, KeyError) as exc:
            # never silent: the reply is not sent, and one line says why
            LOG.warning("simulator: no %s reply: %s", response.__name__, str(exc).splitlines()[0] if str(exc) else exc)
            return None

    def act(
        self, device: VirtualDevice, command: CommandSpec, request: Message, given: dict[str, Any] | None = None
    ) -> bytes | None:
        """Carry out a request on one device (`given`: its fields, an `each` item's merged in); the reply or None."""
        given = request.to_fields() if given is None else given
        if command.held_while and device.get(command.held_while):
            device.held.append((command, request, given))  # carried out (or dropped) by a command that releases
            return None
        if command.releases:
            device.set(command.releases, 0)
            waiting, device.held = device.held, []
            if not any(given.get(name) == value for name, value in command.cancel_when.items()):
                for waiting_command, waiting_request, waiting_given in waiting:
                    self.act(device, waiting_command, waiting_request, waiting_given)
        if command.derived:
            given = dict(given)
            for name, derive in command.derived.items():
                given[name] = derive(given)
        # Whether an optional reply is due is decided on the switch as the request finds it (a write that turns
        # replies off is still answered), which is also what a client that remembers the switch expects.
        switch = command.optional_when
        answers = switch is None or compare(device.get(switch[0]), switch[2], switch[1])
        if command.limits or command.space_reads or command.space_writes or command.refused_while_moving:
            refusal = self._refusal(device, command, given)
            if refusal is not None:
                if self.spec.error is not None:
                    return self._error_reply(device, command, refusal)
                return self._reply(device, command, given, refusal) if answers else None
        refused = ""
        if command.resets:
            field_name, kept = command.keeps or ("", {})
            device.reset(kept.get(int(given.get(field_name, -1)), None) if command.keeps else None)
        written: set[str] = set()
        if command.buffered:
            device.buffered.extend((command, name, given) for name in command.writes)
        else:
            for name in command.writes:
                reason = self._write(device, command, name, given, written)
                refused = refused or reason
        if command.commits:
            if not device.buffered and command.nothing_held:
                refused = refused or "held"
            buffered, device.buffered = device.buffered, []
            for held_command, name, held in buffered:
                self._write(device, held_command, name, held, written)
        for name, run in command.space_writes.items():
            self._write_space(device, run, given[name], given)
        if command.moves and (not command.move_enabled_by or device.get(command.move_enabled_by)):
            self._move(device, command, given, written)
        for name, state in command.stores.items():
            device.set(state, packed(command.bit_fields.get(name), given[name]))
        for state, value in command.sets.items():
            device.set(state, value)
        for state in command.stops:
            device.set(state, device.get(state))
        for state in command.increments if not refused else ():
            device.set(state, device.get(state) + 1)
        for state, period in command.wraps.items():
            device.set(state, math.fmod(device.get(state), period))
        for state, period in command.modulo.items():
            device.set(state, device.get(state) % period)
        for name in command.restores:
            device.set(name, device.by_name[name].default)
        if command.restores:
            device.buffered = []  # held writes live in the memory a restore clears
        id_entry = device.spec.id_entry
        if id_entry in device.by_name or id_entry in device.state:
            new_id = int(device.get(id_entry))
            if new_id != device.id and new_id not in self.devices:
                del self.devices[device.id]
                device.id = new_id
                self.devices[new_id] = device
        return self._reply(device, command, given, refused) if answers else None

    def _reply(self, device: VirtualDevice, command: CommandSpec, given: dict[str, Any], refused: str) -> bytes | None:
        """The response to a request carried out (or refused: `refused` says why) on one device."""
        response = command.refusal if refused and command.refusal is not None else command.response
        if response is None:
            return None
        values: dict[str, Any] = {}
        for name in field_keys(response):
            if name in command.space_reads and not refused:
                values[name] = self._read_space(device, command.space_reads[name], given)
            elif name in command.reads and not refused:
                value = self._read(device, command, name, given)
                if value is None:
                    return None  # an unknown key: a device stays silent
                values[name] = value
            elif name in command.reports:
                source = command.reports[name]
                values[name] = source(device.get) if callable(source) else device.get(source)
            elif name in command.counts:
                state, per = command.counts[name]
                values[name] = int(device.get(state) / per)
            elif name == device.spec.address and not device.spec.echo_address:
                # a device answers with its own id, also to a broadcast; to a request in a form without an address
                # (None: the Pololu compact form's), in the form without one
                values[name] = None if name in given and given[name] is None else device.id
            elif name in device.spec.status:
                values[name] = device.get(device.spec.status[name])
            elif any(key.startswith(name + ".") for key in (*self.spec.reply, *device.spec.status)):
                blank = command.blanks.get(name)  # bit fields, filled in below; those not named stay 0
                values[name] = dict(blank) if isinstance(blank, dict) else {}
            elif command.tables.get(name, ())[:1] == ("run",):
                values[name] = b""  # a run of registers in a reply holds what was read: nothing here
            elif name in given and name in command.echoes:
                values[name] = given[name]
            elif name in self.spec.reply:
                values[name] = self.spec.reply[name]
            elif name in device.by_name or name in device.state:
                values[name] = device.get(name)  # the device's own value, never the request's
            else:
                blank = command.blanks.get(name, 0)
                if isinstance(blank, CountedBlank):
                    values[name] = blank.fill(values)
                else:
                    values[name] = blank(given) if callable(blank) else blank
        for name, layout in command.bit_fields.items():
            if name in values:
                values[name] = unpacked(layout, values[name])
        nest(values, {k: v for k, v in self.spec.reply.items() if "." in k})
        nest(values, {k: int(bool(device.get(e))) for k, e in device.spec.status.items() if "." in k})
        nest(values, command.nothing_held if refused == "held" else self.spec.errors.get(refused, {}))
        reply = self._encode_reply(response, values)
        if reply is not None and command.final is not None and response is command.response:
            # the answer's end (an AT command's OK): its fields the device's `reply` values, else their blanks
            ending = self._encode_reply(
                command.final,
                {name: self.spec.reply.get(name, command.blanks.get(name)) for name in field_keys(command.final)},
            )
            if ending is not None:  # (one that cannot be encoded is logged; the reply still goes)
                reply += ending
        return reply

    # --- data spaces and error replies ------------------------------------------------------------------------------

    def _refusal(self, device: VirtualDevice, command: CommandSpec, given: dict[str, Any]) -> str | None:
        """Why the device refuses a request before it acts, or None: values outside what the device accepts first,
        then runs beyond their data space, then writes to a read-only space; a move in progress that the command
        waits for ("busy")."""
        moving = device.motions.get(command.refused_while_moving)
        if moving is not None and moving.active(self.clock()):
            return "busy"
        for name, (low, high, allowed) in command.limits.items():
            value = given.get(name)
            value = len(value) if is_sequence(value) else value
            if isinstance(value, int | float) and (not low <= value <= high or (allowed and value not in allowed)):
                return "out_of_range"
        spaces = {s.name: s for s in self.spec.spaces}
        runs = [(run, int(given[run.count]) if run.count else 1) for run in command.space_reads.values()]
        runs += [(run, _items(given[name])) for name, run in command.space_writes.items()]
        for run, count in runs:
            start = int(given[run.start])
            if start + count > len(device.spaces[run.space]):
                return "out_of_space"
        for run in command.space_writes.values():
            if spaces[run.space].access == "r":
                return "read_only"
        return None

    def _unsupported(self, data: bytes) -> list[tuple[float, bytes]]:
        """Bytes that arrived together and that the parser took for no frame: if they are one whole request whose
        checksum verifies but whose code no command has, the addressed device refuses it (Modbus exception 1; MSP's
        `$M!`)."""
        error = self.spec.error
        if error is None or "unsupported" not in self.spec.errors or error.unwrap is None:
            return []
        try:
            code, values = error.unwrap(data)
        except ValueError:  # DecodeError: not a whole frame
            return []
        known = {c.code for c in self.spec.commands}
        if code is None or code in known:
            return []
        if self.spec.address:
            device = self.devices.get(values[0]) if values else None
        else:  # frames without an address: the one device on the line answers (MSP's flight controller)
            device = next(iter(self.devices.values()), None)
        if device is None:
            return []  # another device's, or broadcast: no reply
        refusal = CommandSpec(error.response, None, code=code)
        frame = self._error_reply(device, refusal, "unsupported")
        return [] if frame is None else self._spoil(self.clock(), frame)

    def _error_reply(self, device: VirtualDevice, command: CommandSpec, reason: str) -> bytes | None:
        """The protocol's error reply refusing a request for `reason`; None (silence) for a reason not given."""
        error = self.spec.error
        if error is None or reason not in self.spec.errors:
            return None
        values: dict[str, Any] = {error.code_field: command.code or 0}
        if error.status is not None:  # the status says why: its bit fields 0 but those the reason gives
            name, bits = error.status
            values[name] = unpacked(bits, 0) if bits else 0
        nest(values, self.spec.errors[reason])
        if self.spec.address:
            values[self.spec.address] = device.id
        return self._encode_reply(error.response, values)

    def _read_space(self, device: VirtualDevice, run: RunSpec, given: dict[str, Any]) -> Any:
        start = int(given[run.start])
        items = device.spaces[run.space][start : start + (int(given[run.count]) if run.count else 1)]
        space = next(s for s in self.spec.spaces if s.name == run.space)
        read = [bool(v) for v in items] if space.bits else list(items)
        return read[0] if run.single else read

    def _write_space(self, device: VirtualDevice, run: RunSpec, value: Any, given: dict[str, Any]) -> None:
        space = next(s for s in self.spec.spaces if s.name == run.space)
        items = device.spaces[run.space]
        start = int(given[run.start])
        values = list(value) if is_sequence(value) else [value]
        for offset, item in enumerate(values):
            current = items[start + offset]
            stored = run.value(current, given) if run.value is not None else int(item)
            span = space.maximum - space.minimum + 1  # the items' bits: a value wraps as it would on the wire
            items[start + offset] = (
                (1 if stored else 0) if space.bits else (stored - space.minimum) % span + space.minimum
            )

    def _move(self, device: VirtualDevice, command: CommandSpec, given: dict[str, Any], written: set[str]) -> None:
        """Start a move to the target: a request field, or a memory entry this command has just written.

        With a ramp, the speed rises over the acceleration time and falls over the deceleration time; a move at a
        speed then lasts distance / speed plus half of each ramp, so that it cruises at that speed.
        """
        assert command.moves is not None
        state, target, duration_name, speed_name = command.moves
        ramp, speed_scale = command.ramp, command.speed_scale
        if target not in given and target not in written:
            return

        def value(name: str) -> float:
            return float(given[name] if name in given else device.get(name))

        accel, decel = (value(ramp[0]) / 1000, value(ramp[1]) / 1000) if ramp else (0.0, 0.0)
        goal = command.move_to(value) if command.move_to is not None else value(target)
        if duration_name and value(duration_name):
            duration = value(duration_name) / 1000
        elif speed_name and value(speed_name):
            duration = abs(goal - device.get(state)) / (value(speed_name) * speed_scale) + (accel + decel) / 2
        else:
            duration = 0.0
        device.move(state, goal, duration, accel, decel)

    def _read(self, device: VirtualDevice, command: CommandSpec, name: str, given: dict[str, Any]) -> Any:
        table = command.tables.get(name, ())
        if table[:1] == ("run",) and self.spec.registers is not None:
            start = int(given[table[1]])
            if table[2] in given:
                return self._read_run(device, self.spec.registers, start, int(given[table[2]]))
            # the request does not say how many bytes: the entry at the start (none: nothing)
            register = self.spec.registers.by_address.get(start)
            return self._read_run(device, self.spec.registers, start, register.size if register else 0)
        if table[:1] == ("value",):
            entry = device.by_key.get(int(given[table[1]]))
            return None if entry is None else device.get(entry.name)
        if table[:1] == ("block",):
            return {n: device.get(n) for n in table[1:]}
        if table[:1] == ("group",):
            return self._read_items(device, command, table[1:], given)
        return device.get(name)

    def _read_items(
        self, device: VirtualDevice, command: CommandSpec, names: tuple[str, ...], given: dict[str, Any]
    ) -> list[dict[str, Any]] | None:
        """A group of table values read by key: an item for each item of the request's group that names a key (its
        fields the reply's items share copied), else for every entry of the memory; None for an unknown key."""
        keyed = {n: command.tables[n][1] for n in names if command.tables.get(n, ())[:1] == ("value",)}
        keys = set(keyed.values())
        asked = next(
            (v for v in given.values() if isinstance(v, list) and v and isinstance(v[0], dict) and keys <= set(v[0])),
            None,
        )
        if asked is None:  # every entry, by its key
            (key,) = keys if len(keys) == 1 else (None,)
            asked = [{key: entry.key} for entry in device.by_key.values()] if key else []
        items = []
        for request_item in asked:
            item: dict[str, Any] = {}
            for n in names:
                if n in keyed:
                    entry = device.by_key.get(int(request_item[keyed[n]]))
                    if entry is None:
                        return None  # an unknown key: a device stays silent
                    item[n] = device.get(entry.name)
                else:
                    item[n] = request_item.get(n, 0)
            items.append(item)
        return items

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
            data += registers.to_wire(register, int(device.get(register.name)), checked=False)
            address += register.size
        return bytes(data[:size])

    def _write_run(
        self, device: VirtualDevice, registers: RegisterMap, start: int, data: bytes, written: set[str]
    ) -> str:
        """Store bytes written from register `start` on; refused whole (the reason) unless every register is
        writable and in range."""
        try:
            values = registers.split(start, data)
        except EncodeError:
            return "out_of_space"  # not whole registers
        reasons = [device.refusal(device.by_name.get(name), value) for name, value in values.items()]
        if any(reasons):
            return next((r for r in reasons if r and r != "out_of_range"), "out_of_range")
        for name, value in values.items():
            device.store(name, value)
        written.update(values)
        return ""

    def _write(
        self,
        device: VirtualDevice,
        command: CommandSpec,
        name: str,
        given: dict[str, Any],
        written: set[str] | None = None,
    ) -> str:
        """Store one request field in memory; why it was refused (VirtualDevice.refusal), or "" when it was not."""
        table = command.tables.get(name, ())
        if table[:1] == ("run",) and self.spec.registers is not None:
            start = int(given[table[1]])
            data = given[name]  # a message's to_fields() gives bytes as hex text
            data = bytes.fromhex(data) if isinstance(data, str) else bytes(data)
            return self._write_run(device, self.spec.registers, start, data, set() if written is None else written)
        if table[:1] == ("value",):
            entry = device.by_key.get(int(given[table[1]]))
            reason = device.refusal(entry, given[name])
            if reason:
                return reason
            assert entry is not None
            device.store(entry.name, given[name])
            return ""
        if table[:1] == ("block",):
            block = given[name]
            reasons = [device.refusal(device.by_name.get(n), block[n]) for n in table[1:]]
            reasons = [r for r in reasons if r and r != "read_only"]  # a block's read-only entries are skipped
            if not reasons:
                for n in table[1:]:
                    if device.by_name[n].access != "r":
                        device.store(n, block[n])
            return next((r for r in reasons if r != "out_of_range"), reasons[0] if reasons else "")
        device.store(name, packed(command.bit_fields.get(name), given[name]))
        return ""


def packed(layout: tuple[tuple[str, int, int], ...] | None, value: Any) -> Any:
    """A field's value as the device keeps it: bit fields (a mapping) as the one integer they make up."""
    if layout is None or not isinstance(value, Mapping):
        return value
    return sum((int(value.get(name, 0)) & ((1 << (high - low + 1)) - 1)) << low for name, low, high in layout)


def unpacked(layout: tuple[tuple[str, int, int], ...], value: Any) -> Any:
    """An integer the device keeps as the bit fields of a reply field made of them."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return value
    whole = int(value)
    return {name: (whole >> low) & ((1 << (high - low + 1)) - 1) for name, low, high in layout}


def _items(value: Any) -> int:
    """How many items of a data space a written value covers: a list's length, else one."""
    return len(value) if is_sequence(value) else 1


def nest(values: dict[str, Any], overlay: dict[str, Any]) -> None:
    """Apply reply values, where `field.bit_field` names one bit field of a field made of bit fields."""
    for key, value in overlay.items():
        name, _, bit = key.partition(".")
        if not bit:
            values[name] = value
        elif isinstance(values.get(name), dict):
            values[name] = {**values[name], bit: value}


def _whole(value: Any) -> Any:
    """State and memory hold floats; a reply's integer fields (bit fields and items too) take whole numbers as ints."""
    if isinstance(value, float) and value.is_integer():
        return int(value)
    if isinstance(value, dict):
        return {k: _whole(v) for k, v in value.items()}
    if is_sequence(value):
        return [_whole(v) for v in value]
    return value
