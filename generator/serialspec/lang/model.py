"""The immutable, fully resolved protocol model that every emitter reads.

Everything an emitter needs is computed here once: sizes, offsets, the content length bounds a stream parser
uses to reject stray headers, class names, and which fields are derived (counts, lengths) rather than given.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import field
from functools import cached_property
from typing import Literal

from serialspec.checksums.base import Algorithm
from serialspec.lang import expression
from serialspec.lang.expression import Expr
from serialspec.lang.frozen import frozen
from serialspec.runtime.message import Direction as Direction  # the model and the runtime share it
from serialspec.transforms.base import Transform


@frozen
class ScalarType:
    name: str
    size: int
    struct_char: str
    signed: bool
    is_float: bool
    minimum: float
    maximum: float


SCALARS: dict[str, ScalarType] = {
    "u8": ScalarType("u8", 1, "B", False, False, 0, 0xFF),
    "i8": ScalarType("i8", 1, "b", True, False, -0x80, 0x7F),
    "u16": ScalarType("u16", 2, "H", False, False, 0, 0xFFFF),
    "i16": ScalarType("i16", 2, "h", True, False, -0x8000, 0x7FFF),
    # 3-byte integers (fields only, as the 64-bit types: not frame elements, enums, flags or tables) are read as 3
    # bytes ("3s") and converted, since struct has no format for them
    "u24": ScalarType("u24", 3, "3s", False, False, 0, 0xFFFFFF),
    "i24": ScalarType("i24", 3, "3s", True, False, -0x800000, 0x7FFFFF),
    "u32": ScalarType("u32", 4, "I", False, False, 0, 0xFFFFFFFF),
    "i32": ScalarType("i32", 4, "i", True, False, -0x80000000, 0x7FFFFFFF),
    "u64": ScalarType("u64", 8, "Q", False, False, 0, 0xFFFFFFFFFFFFFFFF),
    "i64": ScalarType("i64", 8, "q", True, False, -0x8000000000000000, 0x7FFFFFFFFFFFFFFF),
    "f32": ScalarType("f32", 4, "f", True, True, -3.4028234663852886e38, 3.4028234663852886e38),
    "f64": ScalarType("f64", 8, "d", True, True, -1.7976931348623157e308, 1.7976931348623157e308),
}


@frozen
class EnumValue:
    name: str
    value: int
    text: str


@frozen
class EnumDef:
    name: str
    class_name: str
    type: ScalarType
    description: str
    values: tuple[EnumValue, ...]


@frozen
class FlagBit:
    name: str
    bit: int
    text: str


@frozen
class FlagsDef:
    name: str
    class_name: str
    type: ScalarType
    description: str
    bits: tuple[FlagBit, ...]


@frozen
class BitField:
    name: str
    high: int
    low: int
    enum: EnumDef | None
    description: str

    @property
    def mask(self) -> int:
        return (1 << (self.high - self.low + 1)) - 1


@frozen
class Common:
    """What every field kind carries."""

    name: str
    description: str
    description_cn: str
    inferred: str


@frozen
class Scalar(Common):
    type: ScalarType
    endian: Literal["<", ">"]
    unit: str
    scale: float | None
    minimum: float
    maximum: float
    const: int | None
    default: float | None
    enum: EnumDef | None
    flags: FlagsDef | None
    bits: tuple[BitField, ...]
    bits_class: str
    sign_magnitude: bool
    # Derived fields are computed on encode and checked on decode, never given by the user:
    # ("count", group) is the number of items of a group; ("size", group, field) the size of bytes in each item.
    derived: tuple[str, ...] = ()
    # A response field reporting success: any value but this one is a device error (the client raises DeviceError).
    status_ok: int | None = None
    # Derived by an expression over the other fields (`byte_count = 2 * count`): computed on encode, checked on decode.
    value: Expr | None = None
    offset: float | None = None  # engineering value = wire value × scale + offset

    @property
    def odd_width(self) -> bool:
        """A 3-byte integer: read as 3 bytes and converted, since struct has no format for it."""
        return self.type.size == 3

    @property
    def hidden(self) -> bool:
        """Not a member of the message: constant or derived."""
        return self.const is not None or bool(self.derived) or self.value is not None


@frozen
class Array(Common):
    item: ScalarType
    endian: Literal["<", ">"]
    count: int
    unit: str
    minimum: float
    maximum: float


@frozen
class List(Common):
    """A list of numbers or bits whose count varies: from a count field, from a byte-size field, or the rest.

    `item` None means bits packed 8 to a byte, the first in the lowest bit, the last byte padded with zeros
    (Modbus coils). The count comes from `count` (a number, `rest`, or a field) or, when that is "", from the
    byte size in the field named by `size`.
    """

    item: ScalarType | None
    endian: Literal["<", ">"]
    count: int | str
    size: str
    unit: str
    minimum: float
    maximum: float
    count_from: str = ""  # a response's: the request field saying how many items are meant (the rest is padding)

    @property
    def bits(self) -> bool:
        return self.item is None

    def byte_size(self, count: int) -> int:
        return -(-count // 8) if self.item is None else count * self.item.size


@frozen
class Packed(Common):
    """A fixed number of integers of `bits` bits each, packed with no gaps (CRSF RC channels: 16 × 11 bits).

    `lsb_first`: the first item starts at the lowest bit of the first byte, each item's lowest bit first (CRSF,
    SBUS; a little-endian u24 array is the same); else the first item starts at the highest bit, its highest bit
    first (a big-endian u24 array is the same). The last byte is padded with zero bits.
    """

    bits: int
    signed: bool
    count: int
    lsb_first: bool
    unit: str
    minimum: float
    maximum: float

    @property
    def byte_size(self) -> int:
        return -(-self.bits * self.count // 8)


@frozen
class Text(Common):
    """Text: NUL-terminated (`size` None; the NUL is not part of the value), or sized like bytes.

    `pad`: a fixed-size text shorter than its size is sent followed by this byte (NUL-padded names), and read
    without the trailing pad bytes; None: the text must fill its size exactly."""

    size: int | str | None  # a number, "rest", a field name, or None for NUL-terminated
    pad: int | None = None

    @property
    def terminated(self) -> bool:
        return self.size is None


@frozen
class Bytes(Common):
    size: int | str  # a number, "rest", or the name of a field holding it
    table: Table | None = None  # when the bytes are a run of registers of this table
    start: str = ""  # the field holding the first register's key: a field of this content, or of the request
    start_in_request: bool = False  # `start: request.<field>`: the field is the request's (the resolver checked it)
    size_from: str = ""  # a response's `rest` bytes: the request field giving their number (`request.<field>`)


@frozen
class Group(Common):
    class_name: str
    count: int | str  # a number, "rest", or the name of a count field
    fields: tuple[Field, ...]
    item_size: int | None  # None when an item holds bytes sized by another field


@frozen
class TableValue(Common):
    table: Table
    key: str


@frozen
class TableBlock(Common):
    table: Table
    class_name: str
    entries: tuple[TableEntry, ...]
    endian: Literal["<", ">"]
    struct_name: str = ""  # the construct struct of the block


Field = Scalar | Array | Packed | List | Text | Bytes | Group | TableValue | TableBlock


@frozen
class TableEntry:
    name: str
    key: int
    type: ScalarType
    name_cn: str
    description: str
    unit: str
    scale: float | None
    minimum: float
    maximum: float
    default: float | str | None
    access: str
    memory: str
    enum: EnumDef | None
    flags: FlagsDef | None
    sign_magnitude: bool
    reserved: bool
    source: str
    sign_bit: int | None = None  # sign_magnitude: the sign's bit (the top bit unless the spec says otherwise)


@frozen
class Table:
    name: str
    title: str
    key_name: str
    description: str
    source: str
    entries: tuple[TableEntry, ...]
    # generated names: the register map (or the table's constant), the switch of its values by key, the name alias
    constant: str = ""
    value_constant: str = ""
    names_class: str = ""

    def entry(self, key: int) -> TableEntry | None:
        for entry in self.entries:
            if entry.key == key:
                return entry
        return None


@frozen
class OptionalWhen:
    """A response the device sends only while one of its parameters (a table entry) compares true with a value."""

    table: str
    entry: str
    key: int
    equals: int  # the value compared with
    op: Literal["==", "!=", ">=", "<="] = "=="

    @property
    def symbol(self) -> str:
        """The comparison as people write it: =, ≠, ≥ or ≤."""
        return {"==": "=", "!=": "≠", ">=": "≥", "<=": "≤"}[self.op]


@frozen
class Message:
    """One direction of a command or sub-command."""

    command: str
    subcommand: str | None
    direction: Direction
    class_name: str
    title: str
    description: str
    fields: tuple[Field, ...]  # content fields in wire order, selector included
    optional: str
    unsolicited: bool
    answers: str
    min_size: int  # content length bounds, for decoding and stream plausibility
    max_size: int | None
    source: str
    optional_when: OptionalWhen | None = None  # a response sent only when a device parameter has a value
    after: str = ""  # a response sent once the request's field of this name (ms) has elapsed
    answered_by: str = ""  # a request answered by another command's response (its key)
    error_reply: bool = False  # the reply a device sends instead of any other (Modbus exceptions: code | flag)
    reply_when: OptionalWhen | None = None  # a request whose reply is sent only when a device parameter has a value
    struct_name: str = ""  # the construct struct of its content
    default_reply: bool = False  # among replies sharing a code: the one a frame is decoded as without its request
    refused_by: tuple[str, ...] = ()  # a request: the commands whose responses refuse it (it raises DeviceError)
    request_code: str = ""  # a response: its field holding the code of the request it answers (u-blox ACK)
    # a content sent without its trailing zero bytes (`truncate: trailing_zeros`): its full size, to which decoding
    # pads it (min_size is then the smallest size sent); None where the frame sends contents whole
    padded: int | None = None

    @property
    def key(self) -> str:
        return f"{self.command}.{self.subcommand}" if self.subcommand else self.command


def sizes_text(message: Message) -> str:
    """A message's content sizes, as people read them: 4 bytes, 0..8 bytes, 2 bytes or more."""
    low, high = message.min_size, message.max_size
    if low == high:
        return f"{low} byte" + ("" if low == 1 else "s")
    return f"{low}..{high} bytes" if high is not None else f"{low} byte{'' if low == 1 else 's'} or more"


def replies_by_request(responses: Iterable[Message]) -> dict[str, Message]:
    """Responses by the request they answer: their own command's, or the one they say they `answers`."""
    index: dict[str, Message] = {}
    for response in responses:
        if response.direction == Direction.RESPONSE and not response.unsolicited:
            index.setdefault(response.answers or response.key, response)
    return index


def reply_to(request: Message, replies: dict[str, Message]) -> Message | None:
    """The response that answers a request (from `replies_by_request`), or the one it is `answered_by`."""
    return replies.get(request.answered_by or request.key)


def refusals_of(request: Message, replies: dict[str, Message]) -> tuple[Message, ...]:
    """The responses that refuse a request (its `refused_by`), from `replies_by_request`."""
    return tuple(replies[name] for name in request.refused_by if name in replies)


def reply_condition(request: Message, response: Message | None) -> OptionalWhen | None:
    """The device parameter that switches a request's reply on and off, if any."""
    return request.reply_when or (response.optional_when if response else None)


@frozen
class Selector:
    name: str
    type: ScalarType
    offsets: dict[Direction, int]


@frozen
class Subcommand:
    name: str
    code: int
    title: str
    title_cn: str
    description: str
    request: Message | None
    response: Message | None
    source: str


@frozen
class Command:
    name: str
    code: int | None
    title: str
    title_cn: str
    description: str
    broadcast: str
    source: str
    request: Message | None
    response: Message | None
    selector: Selector | None
    subcommands: tuple[Subcommand, ...]
    group_class: str = ""  # the client's class grouping the sub-commands' methods ("" without sub-commands)
    probe: bool = False  # asks whether a device is there: clients return True/False, never raise Timeout
    response_code: int | None = None  # the code of its response frames, where it differs (HerkuleX: code | 0x40)

    def wire_code(self, direction: Direction) -> int | None:
        """The code its frames of one direction carry: `code`, or in responses the command element's `reply_code`."""
        if direction == Direction.RESPONSE and self.response_code is not None:
            return self.response_code
        return self.code

    def messages(self) -> tuple[Message, ...]:
        found = [m for m in (self.request, self.response) if m]
        for sub in self.subcommands:
            found.extend(m for m in (sub.request, sub.response) if m)
        return tuple(found)


@frozen
class Checksum:
    algorithm: Algorithm  # what it computes, with its parameters: one class per algorithm (serialspec/checksums/)
    first: str  # first frame element covered
    last: str  # last frame element covered
    type: ScalarType
    endian: Literal["<", ">"] = "<"
    name: str = ""  # the frame element holding it
    skips: tuple[str, ...] = ()  # elements inside first..last left out: itself, and the checksums strictly inside


VALUE_ROLES = ("address", "status", "value")  # frame elements whose value every message of the frame carries


@frozen
class FrameElement:
    name: str
    role: str  # header, trailer, constant, address, command, status, length, content, checksum
    type: ScalarType | None
    size: int | None  # None for content
    directions: tuple[Direction, ...]
    description: str
    minimum: float
    maximum: float
    broadcast: int | None
    flags: FlagsDef | None
    endian: Literal["<", ">"] = "<"
    constant: bytes = b""  # header, trailer, constant: the bytes in this direction
    bits: tuple[BitField, ...] = ()  # a status (or address, command) made of bit fields
    bits_class: str = ""
    counts: tuple[str, str] = ("", "")  # length: the first and last element counted
    adds: int = 0  # length: added to the counted size
    checksum: Checksum | None = None  # checksum: what it is and what it covers
    sequence: bool = False  # value: a sequence number the client fills in (one more per request, wrapping)
    truncate: bool = False  # content: trailing zero bytes dropped on encode, padded back on decode (MAVLink v2)

    @property
    def fixed(self) -> bool:
        """Constant bytes: a header, a trailer, a reserved byte, or a command's constant in this direction."""
        return self.role in ("header", "trailer", "constant")


@frozen
class Transparency:
    """A transform of the bytes of a span of elements (serialspec/transforms/: stuffing, escaping, COBS)."""

    first: str
    last: str
    transform: Transform
    description: str = ""


@frozen
class FrameLayout:
    """The frame in one direction: elements in order with their byte offsets (content's at its start).

    The offsets and the classic fields (length_offset .. covered_to_end) describe frames of the classic shape (a
    header, a one-byte length before the content, one final checksum, no transparency); `classic` says whether this
    layout has it. Every layout is fully described by its elements, `transparency` and `checksums`.
    """

    direction: Direction
    header: bytes
    elements: tuple[FrameElement, ...]
    offsets: dict[str, int]
    overhead: int  # frame size minus content size (on the wire, before stuffing)
    length_offset: int
    length_adds: int
    command_offset: int | None
    checksum_offset_from_end: int
    covered_from: int  # first covered byte
    covered_to_end: int  # bytes after the last covered byte
    value_elements: tuple[FrameElement, ...]  # address/status/value: frame-level values every message carries
    name: str = ""  # the layout's name among alternatives ("" for the one layout)
    transparency: Transparency | None = None
    checksums: tuple[Checksum, ...] = ()
    classic: bool = True

    def index(self, name: str) -> int:
        return next(i for i, e in enumerate(self.elements) if e.name == name)

    @property
    def has_command(self) -> bool:
        """Frames of this direction carry a command code (else every message of it is codeless)."""
        return any(e.role == "command" for e in self.elements)

    @property
    def length(self) -> FrameElement | None:
        return next((e for e in self.elements if e.role == "length"), None)

    @property
    def truncates(self) -> bool:
        """The content is sent without its trailing zero bytes (`truncate: trailing_zeros`)."""
        return any(e.truncate for e in self.elements if e.role == "content")

    @property
    def trailer(self) -> bytes:
        last = self.elements[-1]
        return last.constant if last.role == "trailer" else b""


@frozen
class Framing:
    description: str
    layouts: dict[Direction, FrameLayout]  # the (first) layout of each direction
    checksum: Checksum | None  # the first layout's first checksum
    shared_header: bool
    alternatives: dict[Direction, tuple[FrameLayout, ...]] = field(default_factory=dict)  # every layout, in order
    gap: float = 0.0  # silence between frames, in character times (0: none defined)
    reply_code: str = ""  # the command element's `reply_code`, as shown (`code | 0x40`): see Command.response_code

    @property
    def classic(self) -> bool:
        """Every layout has the classic shape (see FrameLayout): generated codecs use straight-line code."""
        return all(layout.classic for layouts in self.alternatives.values() for layout in layouts)


@frozen
class ErrorReply:
    """Replies that refuse a request: its code with `flag` set in the command element, laid out as `command`'s
    response (Modbus exception replies: function | 0x80, then an exception code)."""

    flag: int
    element: str  # the command element; the error reply's message carries the refused code under this name
    command: str  # the command whose response is the error reply


@frozen
class Serial:
    baudrate: int
    bytesize: int
    parity: str
    stopbits: float
    notes: str
    baudrates: tuple[int, ...] = ()  # every rate a device can be set to, the default first ((): the default alone)


@frozen
class Example:
    name: str
    source: str
    description: str
    direction: Direction
    printed: str
    frame: bytes
    erratum: str
    command: str
    subcommand: str | None
    request: str
    fields: dict[str, object]
    completed: str = ""  # the document prints no complete frame: how `frame` completes it (not an erratum)
    # bytes of the frame before and after the part the document prints (`printed_span`; (0, 0): the whole frame)
    printed_span: tuple[int, int] = (0, 0)
    position: tuple[int, int] = (1, 1)  # line and column in the spec, for errors found after resolution
    printed_text: bytes | None = None  # `printed_as: text`: the bytes of the printed characters and the trailer

    @property
    def printed_part(self) -> bytes:
        """The bytes of the frame that the document prints."""
        before, after = self.printed_span
        return self.frame[before : len(self.frame) - after]


@frozen
class ErratumCheck:
    kind: str
    frame: bytes | None
    frame_text: str
    direction: Direction | None
    error: str
    command: str
    subcommand: str | None
    fields: dict[str, object]
    claimed: object
    actual: int | None
    examples: tuple[str, ...]


@frozen
class Erratum:
    name: str
    source: str
    printed: str
    correct: str
    check: ErratumCheck
    position: tuple[int, int] = (1, 1)  # line and column of its check in the spec


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
    """A data space a device keeps: `size` items addressed 0..size-1, bits or unsigned integers, all 0 at first."""

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


@frozen
class DeviceErrors:
    """How a device refuses a request, by reason: the reply values (response field or field.bit_field -> value),
    sent in the protocol's error reply when it has one, else in the request's own response."""

    out_of_space: dict[str, float] = field(default_factory=dict)
    out_of_range: dict[str, float] = field(default_factory=dict)
    read_only: dict[str, float] = field(default_factory=dict)
    unsupported: dict[str, float] = field(default_factory=dict)
    busy: dict[str, float] = field(default_factory=dict)
    locked: dict[str, float] = field(default_factory=dict)

    def by_reason(self) -> dict[str, dict[str, float]]:
        """The reasons given, by name (the device runtime's reasons)."""
        reasons = ("out_of_space", "out_of_range", "read_only", "unsupported", "busy", "locked")
        return {reason: getattr(self, reason) for reason in reasons if getattr(self, reason)}


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
    every: int = 0  # period in ms (0: not periodic)
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
    reply: dict[str, float | str]  # response field -> value when no behaviour sets it
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


# --- text frames (framing kind: text) ----------------------------------------------------------------------------


@frozen
class TextField:
    """One field of a text frame (runtime/text.py's TextField, as declared)."""

    name: str
    kind: Literal["decimal", "integer", "angle", "char", "text", "time", "date"]
    description: str = ""
    unit: str = ""
    precision: int = 0
    width: int = 0
    minimum: float | None = None
    maximum: float | None = None
    letters: tuple[tuple[str, str], ...] = ()  # char: (label, letter)
    letters_class: str = ""  # char with letters: the generated Enum's name


@frozen
class TextRepeat:
    """A group of text fields repeated `count` times, or up to `max_count` times at the end of a message."""

    name: str
    fields: tuple[TextField, ...]
    description: str = ""
    count: int = 0
    max_count: int = 0


@frozen
class TextMessage:
    """One direction of a command in a text protocol: chosen by its text code."""

    key: str  # the command's name
    code: str
    title: str
    description: str
    direction: Direction
    class_name: str
    fields: tuple[TextField | TextRepeat, ...]
    unsolicited: bool = False
    source: str = ""


@frozen
class TextExample:
    """A frame as a document prints it (text) and the text of each field it carries."""

    name: str
    source: str
    description: str
    direction: Direction
    printed: str
    command: str
    fields: dict[str, object]
    position: tuple[int, int] = (1, 1)  # line and column in the spec, for errors found after resolution


@frozen
class TextAnswer:
    """How a text device answers one command's request (`device.commands.NAME`): request fields kept in state
    variables, state variables set, and the answer's fields from expressions of the state or from the request."""

    command: str
    description: str = ""
    stores: dict[str, str] = field(default_factory=dict)  # request field -> state variable
    sets: dict[str, float] = field(default_factory=dict)  # state variable -> value
    reports: dict[str, Expr] = field(default_factory=dict)  # response field -> expression of state variables
    echoes: tuple[str, ...] = ()  # response fields that repeat the request's field of the same name


@frozen
class TextDevice:
    """A text protocol's virtual device (`device:`): its state variables, the values every sentence it sends
    carries (`reply`), the sentences it sends on its own, and how it answers requests (`commands`: every command
    with a request and a response is answered, as its entry there says)."""

    description: str
    state: dict[str, float]
    reply: dict[str, str | float]
    sends: tuple[Unsolicited, ...]
    commands: tuple[TextAnswer, ...] = ()


@frozen
class TextFrame:
    """Line-oriented text frames: start + talker + code + separated fields + [marker + checksum as hex] + end."""

    description: str
    start: str
    separator: str
    end: str
    checksum: Algorithm | None
    marker: str
    required: bool
    talker: int  # characters of the talker at the start of the address field (0: none)
    talkers: tuple[str, ...]
    talker_description: str
    max_length: int
    messages: tuple[TextMessage, ...]
    examples: tuple[TextExample, ...] = ()
    digits: int = 2
    device: TextDevice | None = None

    def message(self, key: str, direction: Direction = Direction.RESPONSE) -> TextMessage:
        """The command's message in `direction` (its response by default: what a device sends)."""
        return next(m for m in self.messages if m.key == key and m.direction == direction)

    def request(self, key: str) -> TextMessage | None:
        return next((m for m in self.messages if m.key == key and m.direction == Direction.REQUEST), None)

    def response(self, key: str) -> TextMessage | None:
        return next((m for m in self.messages if m.key == key and m.direction == Direction.RESPONSE), None)

    def letter_sets(self) -> dict[str, tuple[tuple[str, str], ...]]:
        """Each generated letter Enum's name -> its (label, letter) pairs, in order of first use."""
        found: dict[str, tuple[tuple[str, str], ...]] = {}
        for message in self.messages:
            for item in message.fields:
                for f in item.fields if isinstance(item, TextRepeat) else (item,):
                    if f.letters_class:
                        found.setdefault(f.letters_class, f.letters)
        return found


@frozen
class Protocol:
    name: str
    title: str
    description: str
    spec_path: str
    sources: dict[str, str]
    byte_order: Literal["little", "big"]
    serial: Serial
    framing: Framing
    matching: tuple[str, ...]
    matching_description: str
    enums: tuple[EnumDef, ...]
    flags: tuple[FlagsDef, ...]
    tables: tuple[Table, ...]
    commands: tuple[Command, ...]
    examples: tuple[Example, ...]
    errata: tuple[Erratum, ...]
    device: Device | None = None
    client_class: str = ""  # the generated client's and simulator's class names
    simulator_class: str = ""
    error_reply: ErrorReply | None = None
    text: TextFrame | None = None  # framing kind text: its frames and messages (commands is then empty)

    def messages(self) -> tuple[Message, ...]:
        return tuple(m for c in self.commands for m in c.messages())

    def command(self, name: str) -> Command:
        return self._commands_by_name[name]

    @cached_property
    def _commands_by_name(self) -> dict[str, Command]:  # emitters look commands up per message
        return {c.name: c for c in self.commands}


# --- sizes: computed from fields by the resolver and every emitter ----------------------------------------------------


def fixed_size(field: Field) -> int | None:
    if isinstance(field, Scalar):
        return field.type.size
    if isinstance(field, Array):
        return field.item.size * field.count
    if isinstance(field, Packed):
        return field.byte_size
    if isinstance(field, Bytes | Text):
        return field.size if isinstance(field.size, int) else None
    if isinstance(field, List):
        return field.byte_size(field.count) if isinstance(field.count, int) else None
    if isinstance(field, Group):
        if isinstance(field.count, int) and field.item_size is not None:
            return field.count * field.item_size
        return None
    if isinstance(field, TableBlock):
        return sum(e.type.size for e in field.entries)
    return None


def sum_sizes(fields: tuple[Field, ...]) -> int | None:
    total = 0
    for item in fields:
        size = fixed_size(item)
        if size is None:
            return None
        total += size
    return total


def content_bounds(fields: tuple[Field, ...]) -> tuple[int, int | None]:
    """Smallest and largest content size (None: unbounded) the fields allow."""
    low = 0
    high: int | None = 0
    by_name = {f.name: f for f in fields}
    for item in fields:
        size = fixed_size(item)
        if size is not None:
            low += size
            high = None if high is None else high + size
            continue
        if isinstance(item, TableValue):
            sizes = [e.type.size for e in item.table.entries if not e.reserved]
            low += min(sizes)
            high = None if high is None else high + max(sizes)
        elif isinstance(item, Group) and isinstance(item.count, str) and item.count != "rest" and item.item_size:
            counter = by_name.get(item.count)
            most = int(counter.maximum) if isinstance(counter, Scalar) else None
            high = None if high is None or most is None else high + most * item.item_size
        elif isinstance(item, List) and (item.size or item.count not in ("", "rest")):
            counter = by_name.get(item.size or str(item.count))
            most = int(counter.maximum) if isinstance(counter, Scalar) else None
            high = None if high is None or most is None else high + (most if item.size else item.byte_size(most))
        elif isinstance(item, Text) and item.terminated:
            low += 1
            high = None
        elif isinstance(item, Bytes | Text) and isinstance(item.size, str) and item.size != "rest":
            counter = by_name.get(item.size)
            most = int(counter.maximum) if isinstance(counter, Scalar) else None
            high = None if high is None or most is None else high + most
        else:
            high = None
    return low, high


def byte_size_expression(item: List) -> Expr | None:
    """The size in bytes of a list counted by a field, as an expression of that field (ceil(n / 8), n * 2)."""
    if not isinstance(item.count, str) or item.count in ("", "rest"):
        return None
    count = expression.Name(item.count)
    if item.item is None:
        return expression.Ceil(count, expression.Const(8))
    return count if item.item.size == 1 else expression.BinOp("*", expression.Const(item.item.size), count)


def size_terms(fields: tuple[Field, ...]) -> tuple[int, tuple[tuple[int, int, str, int], ...]] | None:
    """A content's size from its own leading fields, for frames that carry no length (Modbus RTU): fixed bytes
    plus, for each part sized by an earlier field at a fixed offset, (offset, size, byte order, bytes per unit).
    None when the size cannot be told that way (a part that takes the rest, a NUL-terminated text)."""
    fixed = 0
    terms: list[tuple[int, int, str, int]] = []
    offsets: dict[str, tuple[int, Scalar]] = {}
    offset: int | None = 0
    for item in fields:
        if isinstance(item, Scalar) and offset is not None:
            offsets[item.name] = (offset, item)
        size = fixed_size(item)
        if size is not None:
            fixed += size
            offset = None if offset is None else offset + size
            continue
        offset = None
        sizer: str = ""
        factor = 1
        if isinstance(item, List):
            wanted = byte_size_expression(item)
            same = next((name for name, (_, f) in offsets.items() if wanted is not None and f.value == wanted), "")
            sizer = item.size or same
            if not sizer and isinstance(item.count, str) and item.count not in ("", "rest") and item.item is not None:
                sizer, factor = item.count, item.item.size
        elif isinstance(item, Bytes | Text) and isinstance(item.size, str) and item.size != "rest":
            sizer = item.size
        elif isinstance(item, Group) and isinstance(item.count, str) and item.count != "rest" and item.item_size:
            sizer, factor = item.count, item.item_size
        if sizer not in offsets:
            return None
        where, scalar = offsets[sizer]
        terms.append((where, scalar.type.size, "big" if scalar.endian == ">" else "little", factor))
    return fixed, tuple(terms)
