"""How a message is framed on the wire: elements, layouts, checksums, transparency and transforms; serial settings."""

from __future__ import annotations

from dataclasses import field
from typing import Literal

from serialspec.checksums.base import Algorithm
from serialspec.lang.frozen import frozen
from serialspec.lang.model.fields import BitField, FlagsDef, ScalarType
from serialspec.runtime.message import Direction
from serialspec.transforms.base import Transform


@frozen
class Checksum:
    algorithm: Algorithm  # what it computes, with its parameters: one class per algorithm (serialspec/checksums/)
    first: str  # first frame element covered
    last: str  # last frame element covered
    type: ScalarType
    endian: Literal["<", ">"] = "<"
    name: str = ""  # the frame element holding it
    skips: tuple[str, ...] = ()  # elements inside first..last left out: itself, and the checksums strictly inside
    from_request: tuple[str, ...] = ()  # a reply's: request elements whose bytes it takes in first (RoboClaw)
    # The name its function goes by in generated code where it is not the element's: alternative layouts that hold
    # different algorithms under one element name (MSP v1's XOR and v2's CRC-8, both `checksum`) get the layout's
    # name after the element's.
    function: str = ""


@frozen
class ExtendedLength:
    """A one-byte length's long form (`extended:`): the byte `marker`, then the size as `size` big-endian bytes."""

    marker: int  # the short form's value that says the wider length follows (Xsens MT: 0xFF; MQTT-SN: 0x01)
    size: int  # bytes of the wider length
    adds: int  # the long form's `adds` (a length that counts itself counts its wider bytes too)
    short: tuple[int, int]  # the values the one-byte form holds (the range's, less the marker)
    long: tuple[int, int]  # the values the wider one holds (the range's)


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
    ok: tuple[int, ...] = ()  # status: the values that mean success (none given: 0, every bit field 0)
    truncate: bool = False  # content: trailing zero bytes dropped on encode, padded back on decode (MAVLink v2)
    present_if: tuple[str, int] = ("", 0)  # optional: (flag element, mask): sent when flag & mask (MAVLink signature)
    # command: the code this layout's frames carry, as an expression of the command's `code` (`code & 0x7F`), as
    # shown; `wire` holds each command's (code, code sent), computed when the commands are read
    code: str = ""
    wire: tuple[tuple[int, int], ...] = ()
    digit: bool = False  # `type: u4`: one hex digit of a hex-ASCII span (a byte 0..15 in the plain bytes)
    extended: ExtendedLength | None = None  # length: a long form after a marker value (`extended:`)

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
    # a response layout whose frames refuse their request (the header's `error_value`): each is the `error_reply`
    # message, the command element carrying the refused code
    error: bool = False

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
    def optional(self) -> tuple[FrameElement, ...]:
        """The elements sent only when their `present_if` flag is set (messages carry their bytes, or None)."""
        return tuple(e for e in self.elements if e.role == "optional")

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
    turnaround: float = 0.0  # seconds the client waits after a request no device answers (a broadcast)
    reply_code: str = ""  # the command element's `reply_code`, as shown (`code | 0x40`): see Command.response_code
    by_command: bool = False  # a command names its layout (`layout:`): layouts are chosen by command, not by header
    # one layout's replies carry no code, differ in size, and nothing in the frame sizes them (no length element, no
    # terminator, no transform): each is read as the reply awaited, as replies in layouts chosen by command are
    codeless_replies: bool = False

    def layout_of(self, direction: Direction, name: str) -> FrameLayout:
        """The layout of a direction by its name ("": the first), where layouts are chosen by command."""
        return next((layout for layout in self.alternatives[direction] if layout.name == name), self.layouts[direction])

    def partial_values(self, direction: Direction) -> frozenset[str]:
        """The frame values of a direction that some alternative layout does not carry (the Pololu form's device
        number beside the compact form): a message holds None for them when its frame's layout has no such element,
        and is sent in the layout carrying exactly the values it gives."""
        layouts = self.alternatives.get(direction, ())
        if self.by_command:  # each message carries its own layout's values
            return frozenset()
        return frozenset(
            e.name
            for e in (layouts[0].value_elements if layouts else ())
            if any(all(x.name != e.name for x in layout.elements) for layout in layouts)
        )

    @property
    def from_request(self) -> bool:
        """Some reply's checksum takes in bytes of its request: decoding it needs the request."""
        return any(c.from_request for layout in self.alternatives.get(Direction.RESPONSE, ()) for c in layout.checksums)

    def by_request(self, direction: Direction) -> bool:
        """Frames of this direction are read in the layout of the request they answer (they carry no code): layouts
        chosen by command, or one layout's code-less replies that only the awaited reply sizes (`codeless_replies`)."""
        layouts = self.alternatives.get(direction, ())
        return (
            (self.by_command or self.codeless_replies)
            and direction == Direction.RESPONSE
            and not any(lay.has_command for lay in layouts)
        )

    @property
    def requesting(self) -> bool:
        """Decoding a reply can take the request it answers: its layout (`by_request`) or its checksum need it."""
        return self.by_command or self.from_request or self.by_request(Direction.RESPONSE)

    @property
    def classic(self) -> bool:
        """Every layout has the classic shape (see FrameLayout): generated codecs use straight-line code (not where
        a frame value is in some layouts only: the frame engine's, which gives None for it in the others)."""
        return all(layout.classic for layouts in self.alternatives.values() for layout in layouts) and not any(
            self.partial_values(direction) for direction in self.alternatives
        )


@frozen
class ErrorReply:
    """Replies that refuse a request: its code with `flag` set in the command element (Modbus exception replies:
    function | 0x80, then an exception code), or its code under another header (`header`, the header element's
    `error_value`: MSP's `$M!`, in the response layout named `layout`), or its code with any of `bits` set in the
    status element named `status` (`error_bits`: SHDLC's state byte), laid out as `command`'s response."""

    flag: int  # 0: told by the header or the status
    element: str  # the command element; the error reply's message carries the refused code under this name
    command: str  # the command whose response is the error reply
    header: bytes = b""
    layout: str = ""
    status: str = ""  # the status element whose `bits` mark an error reply ("": none)
    bits: int = 0

    @property
    def by_header(self) -> bool:
        """Told by the header (`error_value`): every frame of its layout is an error reply."""
        return bool(self.layout)


@frozen
class Serial:
    baudrate: int
    bytesize: int
    parity: str
    stopbits: float
    notes: str
    baudrates: tuple[int, ...] = ()  # every rate a device can be set to, the default first ((): the default alone)
