"""The straight-line frame code's view of a layout: which layouts fit the straight-line form (`straight`), where
each element lies in the frame (`Positions`), what a direction's frame functions call (`Target`), and the direction's
layouts with their checksums (`straight_direction`). The other modules of this package write code from these."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from serialspec.backends.common.frames import runtime_layouts
from serialspec.backends.python.checksum_code import checksum_call
from serialspec.backends.python.kinds import struct_tokens
from serialspec.lang.model import (
    Checksum,
    Direction,
    Protocol,
)
from serialspec.runtime.framing import Element, Layout, Transparency

if TYPE_CHECKING:
    pass


Lines = list[str]


Structs = Callable[[str], str]  # a struct format -> the name of the module's struct constant for it


def registry(structs: dict[str, str]) -> Structs:
    """A Structs that names each format after its layout (`_F_...`) and keeps it in `structs` (name -> format)."""

    def named(fmt: str) -> str:
        name = frame_struct_name(fmt)
        structs[name] = fmt
        return name

    return named


@dataclass(frozen=True)
class Target:
    """What the frame functions of one direction call and pass on: the content decoders' table names, the error
    reply's flag (codes with it set are error replies), whether replies are chosen by the expected class."""

    upper: str  # REQUEST / RESPONSE
    value_names: tuple[str, ...]  # the frame values every message of the direction carries, in element order
    error_flag: int = 0
    error_keep: int = 0
    error_status: str = ""  # the status element whose `error_bits` set make a reply the error reply
    error_bits: int = 0
    expected: bool = False
    only: str = ""  # the one content decoder of frames that carry no command code: called directly
    requesting: bool = False  # frames read and made with the request they answer (layouts chosen by command)
    optional: tuple[str, ...] = ()  # the optional elements (`present_if`) the messages carry: the engine's
    refusing: bool = False  # some layout's frames are error replies (an error header): the engine's code asks
    # replies read in the layout of their request, refused in another: class name -> class (`_RESPONSE_REFUSALS`)
    refusals: tuple[str, ...] = ()


def straight(layout: Layout) -> bool:
    """Whether the layout fits the straight-line form: one content inside the variable part (the stuffed span, else
    the content), lengths at fixed offsets before it, checksums after it and after what they cover, none of them
    over bytes inside the stuffed span only, multi-byte elements at fixed offsets in one byte order."""
    if layout.content < 0 or not isinstance(layout.transparency, Transparency | None):
        return False  # other transforms than substitution: the engine codes them
    if layout.variants != (layout,):
        return False  # optional elements: the engine's variants
    if layout.command is not None and layout.elements[layout.command].wire:
        return False  # codes sent as an expression of them (`code:`): the engine translates them
    first, last = variable_span(layout)
    if not first <= layout.content <= last:
        return False
    for index, element in enumerate(layout.elements):
        if element.kind == "length" and (index >= first or inside_span(layout, *element.span)):
            return False
        if element.kind == "checksum":
            a, b = element.span
            if index <= last or b >= index or inside_span(layout, a, b) or element.skip:
                return False  # (a span that leaves out checksums inside it: the engine's covered bytes)
    packed = [e for e in layout.elements if e.kind in ("value", "command", "length") and e.size > 1]
    return len({e.endian for e in packed}) <= 1


def variable_span(layout: Layout) -> tuple[int, int]:
    """The elements whose size is known only at run time: the stuffed span, else the content alone."""
    return layout.transparency.span if layout.transparency is not None else (layout.content, layout.content)


def stuffing_of(layout: Layout) -> Transparency | None:
    """The layout's substitution, of a straight layout (straight() takes no other transform)."""
    assert isinstance(layout.transparency, Transparency | None)
    return layout.transparency


def inside_span(layout: Layout, a: int, b: int) -> bool:
    """Whether elements a..b lie within the stuffed span (all of it, or part): a length or checksum over them sees
    the plain bytes."""
    t = layout.transparency
    return t is not None and t.span[0] <= a and b <= t.span[1]


def size_of(elements: tuple[Element, ...]) -> int:
    return sum(e.size for e in elements)


class Positions:
    """Element positions in `buf` (plain bytes): a literal offset before the content, `end + k` after it; or, for a
    frame known not to be stuffed (`from_end`), in `frame`, counted back from the frame's end after the content."""

    def __init__(self, layout: Layout, from_end: bool = False) -> None:
        self.layout = layout
        self.from_end = from_end
        # the plain bytes: the frame itself where nothing can be stuffed
        self.buf = "frame" if from_end or layout.transparency is None else "buf"
        self.first, self.last = variable_span(layout)
        c = layout.content
        self.before = size_of(layout.elements[: self.first])  # wire bytes before the variable part
        self.after = size_of(layout.elements[self.last + 1 :])  # wire bytes after it
        self.content = size_of(layout.elements[:c])  # the content's offset
        self.behind = size_of(layout.elements[c + 1 :])  # bytes after the content (plain)
        self.starts: list[tuple[bool, int]] = []  # (after the content, offset from 0 or from end)
        position = 0
        for index, element in enumerate(layout.elements):
            if index < c:
                self.starts.append((False, position))
                position += element.size
            elif index == c:
                self.starts.append((False, position))
                position = 0
            else:
                self.starts.append((True, position))
                position += element.size

    def at(self, index: int, extra: int = 0) -> str:
        """The position of byte `extra` of element `index`."""
        behind, offset = self.starts[index]
        offset += extra
        if not behind:
            return str(offset)
        if self.from_end:
            return str(offset - self.behind)
        return f"end + {offset}" if offset else "end"

    def stop(self, index: int) -> str:
        """The position just after element `index`."""
        if index == self.layout.content:
            return str(-self.behind) if self.from_end else "end"
        return self.at(index, self.layout.elements[index].size)

    def read(self, index: int) -> str:
        """The element's value, read from `buf`."""
        element = self.layout.elements[index]
        at = [self.at(index, i) for i in range(element.size)]
        buf = self.buf
        if element.size == 1:
            return f"{buf}[{at[0]}]"
        if element.size == 2:
            high, low = (at[0], at[1]) if element.endian == "big" else (at[1], at[0])
            return f"{buf}[{high}] << 8 | {buf}[{low}]"
        return f"int.from_bytes({buf}[{at[0]}:{self.stop(index)}], {element.endian!r})"

    def counted(self, a: int, b: int, adds: int = 0) -> str:
        """Bytes of elements a..b as a length counts them (wire bytes, but plain ones inside the stuffed span),
        plus `adds`."""
        elements = self.layout.elements
        if a <= self.first and self.last <= b:  # holds the variable part: the wire frame minus what lies outside
            outside = (
                self.before + self.after - size_of(elements[a : self.first]) - size_of(elements[self.last + 1 : b + 1])
            )
            return plus("n", adds - outside)
        c = self.layout.content
        if a <= c <= b:  # inside the stuffed span: plain bytes
            return plus("end", size_of(elements[a:c]) + size_of(elements[c + 1 : b + 1]) - self.content + adds)
        return str(size_of(elements[a : b + 1]) + adds)

    def covered(self, a: int, b: int) -> str:
        """The bytes a checksum over elements a..b sees: wire bytes of `frame` when they hold the variable part."""
        elements = self.layout.elements
        if a <= self.first and self.last <= b:
            begin = size_of(elements[:a])
            tail = size_of(elements[b + 1 :])
            return f"frame[{begin or ''}:{-tail if tail else ''}]" if begin or tail else "frame"
        return f"{self.buf}[{slice_start(self.at(a))}:{self.stop(b)}]"


def slice_start(position: str) -> str:
    return "" if position == "0" else position


STRUCT_CHARS = {1: "B", 2: "H", 4: "I", 8: "Q"}


def frame_struct_name(fmt: str) -> str:
    """A struct constant's name from its format, prefixed to stay clear of the content's `_S_` constants."""
    tokens = ["BE" if fmt[0] == ">" else "LE"]
    for count, char in struct_tokens(fmt):
        tokens.append(f"{count}S" if char == "s" else {"B": "U8", "H": "U16", "I": "U32", "Q": "U64"}[char])
    return "_F_" + "_".join(tokens)


@dataclass(frozen=True)
class StraightLayouts:
    """A direction whose layouts all take straight-line code: the engine's layouts, each with its checksum
    elements' function names (by element index)."""

    layouts: tuple[Layout, ...]
    checks: tuple[dict[int, str], ...]
    algorithms: tuple[dict[int, Checksum], ...]  # the same checksums
    # layouts with optional elements (`present_if`): the straight-line code takes their frames without them (the
    # variants with every flag bit clear); a frame with a flag bit set (offset, size, byte order, mask) goes to the
    # frame engine, and so does a message that has an optional element's bytes
    diverts: tuple[tuple[int, int, str, int], ...] = ()


def straight_direction(protocol: Protocol, direction: Direction) -> StraightLayouts | None:
    """The direction's layouts, when every one fits the straight-line form (and they carry the same values)."""
    full = runtime_layouts(protocol, direction)
    if any(e.extended is not None for layout in full for e in layout.elements):
        return None  # a length with a long form (`extended:`): the engine's variants, told apart by its marker
    layouts = tuple(layout.variants[-1] for layout in full)  # with optional elements: the variant without them
    diverts = tuple(
        (offset, size, endian, mask) for layout in layouts for offset, size, endian, mask, _ in layout.conditions
    )
    names = {tuple(e.name for e in (layout.elements[i] for i in layout.values)) for layout in layouts}
    if not all(straight(layout) for layout in layouts) or len(names) != 1:
        return None
    if len(layouts) > 1 and not all(layout.header for layout in layouts):
        return None  # a headerless layout beside headed ones, tried last: the engine's
    if protocol.framing.requesting:
        return None  # layouts chosen by command, checksums over the request: the engine's
    algorithms = tuple(
        {
            index: checksum
            for index, e in enumerate(layout.elements)
            if (checksum := next((m.checksum for m in model.elements if m.name == e.name), None)) is not None
        }
        for layout, model in zip(layouts, protocol.framing.alternatives[direction], strict=True)
    )
    checks = tuple({index: checksum_call(checksum) for index, checksum in found.items()} for found in algorithms)
    return StraightLayouts(layouts, checks, algorithms, diverts)


def plus(expression: str, k: int) -> str:
    return f"{expression} + {k}" if k > 0 else f"{expression} - {-k}" if k else expression
