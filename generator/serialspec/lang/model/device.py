"""What a device does: its memory spaces, behaviour, errors, models, unsolicited output and presence query."""

from __future__ import annotations

from dataclasses import field
from typing import Any

from serialspec.lang.expression import Expr
from serialspec.lang.frozen import frozen
from serialspec.lang.model.fields import ScalarType, Table, TableEntry


@frozen
class Motion:
    """A move: the state value goes to the request's target over a duration (ms) or at a speed (units/s)."""

    state: str
    target: str
    duration: str
    speed: str
    speed_scale: float = 1.0  # state units per second for one unit of `speed`
    enabled_by: str = ""  # a memory entry (or state variable): the move happens only while it is non-zero
    accel: str = ""  # request field: acceleration time (ms) at the start
    decel: str = ""  # request field: deceleration time (ms) at the end
    to: Expr | None = None  # where the state goes, from request fields, memory and state (default: the target)


@frozen
class Space:
    """A data space a device keeps: `size` items addressed 0..size-1, bits or integers, all 0 at first."""

    name: str
    item: ScalarType | None  # None: bits
    size: int
    access: str
    description: str


@frozen
class SpaceAccess:
    """A run of a data space from the address in the request field `start` (`count` items, for reads)."""

    space: str
    start: str
    count: str = ""
    value: Expr | None = None  # writes: what is stored, from the request's fields and `current`
    single: bool = False  # reads into a response field that is one number (no array): the item itself


@frozen
class DeviceErrors:
    """How a device refuses a request, by reason: the reply values (response field or field.bit_field -> value),
    sent in the protocol's error reply when it has one, else in the request's own response."""

    # None: not given (an empty mapping: given, the error reply without values, as MSP's `$M!` carries none)
    out_of_space: dict[str, float] | None = None
    out_of_range: dict[str, float] | None = None
    read_only: dict[str, float] | None = None
    unsupported: dict[str, float] | None = None
    busy: dict[str, float] | None = None
    locked: dict[str, float] | None = None

    def by_reason(self) -> dict[str, dict[str, float]]:
        """The reasons given, by name (the device runtime's reasons)."""
        reasons = ("out_of_space", "out_of_range", "read_only", "unsupported", "busy", "locked")
        return {reason: given for reason in reasons if (given := getattr(self, reason)) is not None}


@frozen
class Behaviour:
    """What a device does with one command's request, besides answering it."""

    command: str  # command or command.subcommand
    reads: tuple[str, ...]  # response fields filled from memory (table_value by its key, table_block)
    writes: tuple[str, ...]  # request fields stored in memory
    resets: bool  # memory back to its defaults
    reports: dict[str, Expr]  # response field -> state variable or memory entry, or a conversion of them
    moves: Motion | None
    broadcast_reply: bool  # answers even when addressed by broadcast
    each: str = ""  # a request group whose items each address one device (SYNC WRITE)
    buffered: bool = False  # writes held until a command that commits (REG WRITE)
    commits: bool = False  # carries out the held writes (ACTION)
    kind: str = ""  # the device kind addressed (a `kinds:` entry); "" for the default devices
    stores: dict[str, str] = field(default_factory=dict)  # request field -> state variable
    sets: dict[str, float] = field(default_factory=dict)  # state variable -> value
    absent: dict[str, float] = field(default_factory=dict)  # response values when no device has the id
    space_reads: dict[str, SpaceAccess] = field(default_factory=dict)  # response field -> run read
    space_writes: dict[str, SpaceAccess] = field(default_factory=dict)  # request field -> run written
    keeps: tuple[str, dict[int, tuple[str, ...]]] | None = None  # resets: request field, its value -> entries kept
    stops: tuple[str, ...] = ()  # state variables whose move stops where it is
    increments: tuple[str, ...] = ()  # state variables (or memory entries) 1 is added to when a request is carried out
    wraps: dict[str, float] = field(default_factory=dict)  # state variable -> period it is kept within
    modulo: dict[str, float] = field(default_factory=dict)  # state variable -> period: kept in 0..period-1
    restores: tuple[str, ...] = ()  # memory entries back to their initial values (a reboot's RAM)
    broadcast_ignores: dict[str, float] = field(default_factory=dict)  # request field -> value: broadcast ignored
    refused_while_moving: str = ""  # state variable: while it moves, the request is refused (errors.busy)
    counts: dict[str, tuple[str, float]] = field(default_factory=dict)  # response field -> (state, per)
    every_device: bool = False  # a request without an address reaches every device
    held_while: str = ""  # state variable: while set, the request is held
    releases: str = ""  # state variable: cleared, and the held requests carried out
    cancel_when: dict[str, float] = field(default_factory=dict)  # with releases: field -> value that drops them
    carries: tuple[str, str] | None = None  # (command code field, content field) of a carried request
    carried: tuple[str, ...] = ()  # the commands it can carry (empty: every command with a code)
    nothing_held: dict[str, float] = field(default_factory=dict)  # commits: reply values when nothing is held
    echoes: tuple[str, ...] = ()  # response fields that repeat the request's field of the same name


@frozen
class Unsolicited:
    """A message the device sends on its own: a command's response, every `every` ms, after some requests, or when
    a value changes; only while `while_` (a state variable or memory entry) is non-zero, when it is given."""

    command: str  # command (or command.subcommand) key whose response is sent
    every: int | Expr = 0  # period in ms, or an expression of state and memory giving it (0: not periodic)
    after: tuple[str, ...] = ()  # request keys after whose reply it is sent
    changes: tuple[str, ...] = ()  # state variables or memory entries: sent when one of them changes
    while_: str = ""
    values: dict[str, Expr] = field(default_factory=dict)  # response field -> expression of state and memory
    description: str = ""
    step: str = ""  # state variable: 1 is added to it before each send


@frozen
class DeviceTimeout:
    """The device gives up (sets state variables) when none of `kept_by` arrives for `after` ms."""

    after: int
    kept_by: tuple[str, ...]
    sets: dict[str, float]
    description: str = ""


@frozen
class DeviceKind:
    """Devices of another kind behind the same port, with their own ids and state (a board's PWM servo ports)."""

    name: str
    description: str
    address: str
    ids: tuple[int, ...]
    broadcast: int | None
    state: dict[str, float]


@frozen
class ModelEntry:
    """Where one model's memory entry differs from the table: its range, unit, scale or description."""

    name: str
    minimum: float
    maximum: float
    unit: str
    scale: float | None
    description: str


@frozen
class DeviceModel:
    """One model of the device: its model number, its factory values and where its table differs."""

    name: str
    number: int
    title: str
    description: str
    source: str
    initial: dict[str, float]  # memory entry or state variable -> this model's value (over the device's initial)
    entries: tuple[ModelEntry, ...] = ()

    def entry(self, name: str) -> ModelEntry | None:
        return next((e for e in self.entries if e.name == name), None)


@frozen
class Presence:
    """How to find the devices on a bus (`serialspec scan`): a request every device answers, and its model."""

    request: str  # the command key (command or command.subcommand) of the request
    fields: dict[str, float]  # request field -> value, besides the id
    id_field: str  # the request field holding the id ("": one device per port, no id)
    ids: tuple[int, int] | None  # first and last id asked by default (None: no id)
    broadcast: bool  # every device answers the request sent to the broadcast id
    model_request: str = ""  # the command whose reply holds the model ("": no model)
    model_fields: dict[str, float] = field(default_factory=dict)
    model_field: str = ""  # the reply field holding it
    model_register: TableEntry | None = None  # when that field is a run of registers: the entry holding the model
    description: str = ""


@frozen
class Device:
    """How a device behaves, for the simulator (and the address/broadcast rule, for the client)."""

    description: str
    memory: Table | None
    initial: dict[str, float]  # memory entry -> value, where the table gives no default
    address: str  # the field holding the device id in every message
    id_entry: str  # the memory entry holding the device's own id
    broadcast: int | None
    state: dict[str, float]  # state variables beyond memory -> initial value
    # response field -> value when no behaviour sets it: a number, text, or a list field's items (numbers, or a
    # group's items as mappings of its fields)
    reply: dict[str, float | str | tuple[Any, ...]]
    behaviours: tuple[Behaviour, ...]
    status: dict[str, str] = field(default_factory=dict)  # response field -> memory entry every reply reports
    kinds: tuple[DeviceKind, ...] = ()
    echo_address: bool = False  # replies carry the id the request named, not the answering device's own
    ids: tuple[int, ...] = (0,)  # the ids the simulator serves by default
    spaces: tuple[Space, ...] = ()
    errors: DeviceErrors | None = None
    timeout: DeviceTimeout | None = None
    models: tuple[DeviceModel, ...] = ()  # the first is the default model
    moving: dict[str, tuple[str, int | None]] = field(default_factory=dict)  # entry -> (state variable, bit)
    model_entry: str = ""  # the memory entry holding the model number
    presence: Presence | None = None  # how `serialspec scan` finds devices
    derived: dict[str, Expr] = field(default_factory=dict)  # memory entry -> what it reads as (of others)
    locks: dict[str, str] = field(default_factory=dict)  # memory entry -> variable: not writable while non-zero
    sends: tuple[Unsolicited, ...] = ()  # what the device sends on its own

    def behaviour(self, key: str) -> Behaviour | None:
        return next((b for b in self.behaviours if b.command == key), None)
