"""The general frame engine: any byte-oriented frame the spec language describes, as data.

A frame is an ordered list of elements: constant parts (headers, reserved bytes, trailers), frame-level values
(address, command, status), at most one content, lengths counting a span of elements, checksums covering a span,
and an optional transparency rule (byte stuffing or escaping) over a span. Alternative layouts of one direction
are told apart by their leading constant. Generated codecs describe their frames with these classes: the stream
parser sizes frames with them, and they are the reference the codecs' straight-line frame code (written from the
same layouts by backends/python/frames/) agrees with, check for check and message for message; a layout
that code cannot take (a checksum inside the stuffed span) is coded by Layout.wrap and Layout.unwrap themselves.

Rules (the spec language's, see the generated docs): lengths and checksums outside the transparency span see the
wire bytes, checksums inside it the bytes before the rewrite; a span either holds the whole transparency span or
lies inside it or outside it.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping

from serialspec.runtime import import_module
from serialspec.runtime.errors import ChecksumError, DecodeError, EncodeError
from serialspec.runtime.message import Message
from serialspec.runtime.stream import StreamParser
from serialspec.runtime.values import dataclass, field, replace

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any, Literal

    from serialspec.transforms.base import SpanTransform

    # generated code imports it from here; at run time __getattr__ imports it (a codec without transparency does not)
    from serialspec.transforms.replace import Transparency as Transparency

# optional: bytes sent only when a bit of an earlier (flag) element is set; a Layout holding one hands each frame
# to its variants (`Layout.variants`), plain layouts in which it is an `extra` (fixed bytes) or left out.
if TYPE_CHECKING:
    ElementKind = Literal["constant", "value", "command", "length", "content", "checksum", "optional", "extra"]
else:
    ElementKind = str  # what it is at run time (typing's Literal is not imported)


@dataclass(frozen=True)
class Element:
    """One element of a frame layout; `span` indexes the layout's elements (inclusive)."""

    name: str
    kind: ElementKind
    size: int = 0  # 0 for the content
    endian: Literal["little", "big"] = "little"
    constant: bytes = b""
    span: tuple[int, int] = (0, 0)  # length: the elements counted; checksum: the elements covered
    adds: int = 0  # length: added to the counted size
    checksum: Callable[[bytes], int] | None = None
    minimum: int = 0  # value/command: plausible values (a stray byte out of range is no frame start)
    maximum: int = 0
    also: int | None = None  # value: one more value allowed (an address's broadcast)
    skip: tuple[int, ...] = ()  # checksum: elements inside the span left out (itself, other checksums)
    request: tuple[str, ...] = ()  # checksum (of a reply): the request's elements whose bytes it takes in first
    flag: int = -1  # optional: the index of the element whose bit `mask` says it is sent
    mask: int = 0
    need: tuple[int, int] = (0, 0)  # value (in a variant): (mask, bits) the value must have under the mask
    wire: tuple[tuple[int, int], ...] = ()  # command: (code, code sent) where the layout sends an expression of it
    # length: the inclusive range its value must lie in (`range:`), None for any value its bytes hold; a candidate
    # whose length is outside it is no frame, and encode refuses a frame that would need one
    limits: tuple[int, int] | None = None
    # value: its constant bit fields, (name, lowest bit, mask, constant) each; folded into `need` by the generator
    fixed: tuple[tuple[str, int, int, int], ...] = ()
    # length: a one-byte length's long form (`extended:`), (marker, wider size, the long form's adds, lowest and
    # highest value of the one-byte form, of the wider one); a Layout holding one hands each frame to its two
    # variants (see `_extended`)
    extended: tuple[int, int, int, int, int, int, int] | None = None
    lead: int = 0  # length (a long form's variant): the marker above the value read (marker << 8 * wider size)

    def pack(self, value: int) -> bytes:
        return value.to_bytes(self.size, self.endian)

    def unpack(self, data: bytes) -> int:
        return int.from_bytes(data, self.endian)

    def plausible(self, value: int) -> bool:
        return (self.minimum <= value <= self.maximum or value == self.also) and value & self.need[0] == self.need[1]

    def length_outside(self, value: int) -> str:
        """Why a length's value is refused ("" when its range, if any, holds it)."""
        limits = self.limits
        if limits is None or limits[0] <= value <= limits[1]:
            return ""
        lead = self.lead
        if lead and value >> 8 * (self.size - 1) != lead >> 8 * (self.size - 1):
            return (
                f"{self.name} form is {value >> 8 * (self.size - 1):#04x}, expected {lead >> 8 * (self.size - 1):#04x}"
            )
        return f"{self.name} = {value - lead} is outside its range {limits[0] - lead}..{limits[1] - lead}"


@dataclass(frozen=True)
class Layout:
    """One frame layout of one direction."""

    name: str
    elements: tuple[Element, ...]
    transparency: SpanTransform | None = None
    codes: tuple[int, ...] | None = None  # the command codes sent in this layout (layouts chosen by command)
    present: frozenset[str] = frozenset()  # a variant's optional elements sent (see `variants`)
    conditions: tuple[tuple[int, int, Literal["little", "big"], int, int], ...] = ()  # a variant's flag bits:
    # (offset, size, byte order, mask, bits) of each flag element, which a frame must match to be read in it
    error: bool = False  # its frames refuse their request (an error header): their code is ERROR_REPLY's
    # a variant's bytes a frame must not have to be read in it: (offset, byte) each (an extended length's one-byte
    # form, whose marker byte says the long form)
    unless: tuple[tuple[int, int], ...] = ()
    # derived in __post_init__
    content: int = field(init=False, default=-1)
    values: tuple[int, ...] = field(init=False, default=())
    command: int | None = field(init=False, default=None)
    length: int | None = field(init=False, default=None)

    def __post_init__(self) -> None:
        kinds = [e.kind for e in self.elements]
        object.__setattr__(self, "content", kinds.index("content") if "content" in kinds else -1)
        object.__setattr__(self, "values", tuple(i for i, k in enumerate(kinds) if k == "value"))
        object.__setattr__(self, "command", kinds.index("command") if "command" in kinds else None)
        object.__setattr__(self, "length", kinds.index("length") if "length" in kinds else None)
        optional = [i for i, k in enumerate(kinds) if k == "optional"]
        extended = [i for i, e in enumerate(self.elements) if e.kind == "length" and e.extended is not None]
        found = self._variants(optional[0]) if optional else self._extended(extended[0]) if extended else (self,)
        object.__setattr__(self, "_found", found)
        # a command element whose frames carry an expression of the code (`code:`): the codes sent, both ways
        wire = self.elements[self.command].wire if self.command is not None else ()
        object.__setattr__(self, "to_wire", dict(wire))
        object.__setattr__(self, "from_wire", {sent: code for code, sent in wire})
        # How unwrap cuts a frame, worked out once: fixed slices before and after the variable part, then the
        # variable part's own elements (fixed but for the content); the checks by kind, in element order.
        first, last = self._inner()
        head, position = [], 0
        for index in range(first):
            head.append((index, position, position + self.elements[index].size))
            position += self.elements[index].size
        tail, position = [], 0
        for index in range(len(self.elements) - 1, last, -1):
            tail.append((index, position + self.elements[index].size, position))
            position += self.elements[index].size
        inner = self.elements[first : last + 1] if first <= last else ()
        plan: dict[str, Any] = {
            "before": sum(e.size for e in self.elements[:first]),
            "after": position,
            "head": tuple(head),
            "tail": tuple(tail),
            "inner_fixed": sum(e.size for e in inner),
            "variable": self.content - first if first <= self.content <= last else -1,
            "inner": tuple((first + i, e.size) for i, e in enumerate(inner)),
            "constants": tuple((i, e) for i, e in enumerate(self.elements) if e.kind == "constant"),
            "lengths": tuple((i, e) for i, e in enumerate(self.elements) if e.kind == "length"),
            "checksums": tuple((i, e) for i, e in enumerate(self.elements) if e.kind == "checksum"),
            "template": tuple(e.constant if e.kind == "constant" else bytes(e.size) for e in self.elements),
            "extras": tuple(i for i, k in enumerate(kinds) if k == "extra"),
        }
        t = self.transparency
        inside = tuple(
            (i, e) for i, e in plan["checksums"] if t is not None and t.span[0] <= e.span[0] and e.span[1] <= t.span[1]
        )
        plan["inner_checksums"] = inside
        plan["outer_checksums"] = tuple(c for c in plan["checksums"] if c not in inside)
        counted_inside = tuple(
            (i, e) for i, e in plan["lengths"] if t is not None and t.span[0] <= e.span[0] and e.span[1] <= t.span[1]
        )
        plan["inner_lengths"] = counted_inside  # made before the span is transformed: they count plain bytes
        plan["outer_lengths"] = tuple(c for c in plan["lengths"] if c not in counted_inside)
        # What FrameCodec.probe reads, worked out once: the fixed elements before the variable part with their
        # offsets, and the length element's offset, size, byte order, adds and the sizes around what it counts.
        probe_head, position = [], 0
        for element in self.elements[:first]:
            probe_head.append((element, position, position + element.size))
            position += element.size
        plan["probe_head"] = tuple(probe_head)
        plan["probe_length"] = None
        plan["probe_inner"] = None  # a length of plain bytes inside the transformed span: read through the transform
        if self.length is not None and self.length in dict(counted_inside):
            length = self.elements[self.length]
            a, b = length.span
            in_span = self.length >= first  # else at a fixed offset before the span
            at = sum(e.size for e in self.elements[first : self.length]) if in_span else self.offset(self.length)
            counted_fixed = sum(e.size for e in self.elements[a : b + 1])
            uncounted = sum(e.size for e in self.elements[first : last + 1]) - counted_fixed
            plan["probe_inner"] = (in_span, at, length, uncounted, counted_fixed)
        elif self.length is not None:
            length = self.elements[self.length]
            offset = self.offset(self.length)
            a, b = length.span
            counted = sum(e.size for e in self.elements[a : b + 1])
            plan["probe_length"] = (offset, length, self.overhead - counted, counted)
        plan["prefix"] = self.prefix()
        object.__setattr__(self, "_plan", plan)

    @property
    def variants(self) -> tuple[Layout, ...]:
        """The plain layouts (no optional element) that frames of this layout are read and written in: itself alone,
        or, with optional elements, one for each choice of them sent or not (see `_variants`)."""
        found: tuple[Layout, ...] = self._found  # type: ignore[attr-defined]
        return found

    @property
    def header(self) -> bytes:
        first = self.elements[0]
        return first.constant if first.kind == "constant" else b""

    @property
    def trailer(self) -> bytes:
        last = self.elements[-1]
        return last.constant if last.kind == "constant" and len(self.elements) > 1 else b""

    def _inner(self) -> tuple[int, int]:
        """The elements whose wire positions are known only relative to each other (the transparency span)."""
        if self.transparency is None:
            return (self.content, self.content) if self.content >= 0 else (len(self.elements), len(self.elements) - 1)
        return self.transparency.span

    @property
    def overhead(self) -> int:
        return sum(e.size for e in self.elements)

    def prefix(self) -> int:
        """Wire bytes before the variable part (the transparency span, else the content)."""
        first, _ = self._inner()
        return sum(e.size for e in self.elements[:first])

    def suffix(self) -> int:
        _, last = self._inner()
        return sum(e.size for e in self.elements[last + 1 :])

    def offset(self, index: int) -> int | None:
        """Wire offset of an element from the frame start, when fixed (before the variable part)."""
        first, _ = self._inner()
        return sum(e.size for e in self.elements[:index]) if index < first else None

    def _variants(self, k: int) -> tuple[Layout, ...]:
        """The plain layouts of a layout with optional elements, handing over to copies of itself: the first optional
        element sent (an `extra`, its flag bit set) or left out (its flag bit clear, the spans after it moved up),
        each copy doing the same with the next one. Every variant has a fixed head that tells it apart."""
        element = self.elements[k]
        flag = self.elements[element.flag]
        offset = self.offset(element.flag)
        assert offset is not None  # the spec language keeps the flag before anything variable
        mask = element.mask
        if flag.kind == "constant":
            set_flag = replace(flag, constant=flag.pack(flag.unpack(flag.constant) | mask))
            clear_flag = flag
        else:
            set_flag = replace(flag, need=(flag.need[0] | mask, flag.need[1] | mask))
            clear_flag = replace(flag, need=(flag.need[0] | mask, flag.need[1]))
        condition = (offset, flag.size, flag.endian)
        sent = list(self.elements)
        sent[element.flag], sent[k] = set_flag, replace(element, kind="extra")
        with_it = Layout(
            self.name,
            tuple(sent),
            self.transparency,
            self.codes,
            self.present | {element.name},
            (*self.conditions, (*condition, mask, mask)),
            self.error,
        )

        def moved(index: int) -> int:
            return index - 1 if index > k else index

        left: list[Element] = []
        for index, each in enumerate(self.elements):
            if index == k:
                continue
            each = clear_flag if index == element.flag else each
            left.append(
                replace(
                    each,
                    span=(moved(each.span[0]), moved(each.span[1])),
                    skip=tuple(moved(i) for i in each.skip),
                    flag=moved(each.flag),
                )
            )
        without = Layout(
            self.name,
            tuple(left),
            self.transparency,
            self.codes,
            self.present,
            (*self.conditions, (*condition, mask, 0)),
            self.error,
        )
        return (*with_it.variants, *without.variants)

    def _extended(self, k: int) -> tuple[Layout, ...]:
        """The plain layouts of a layout whose length has a long form (`extended:`): the one-byte form (its values
        less the marker; a frame with the marker byte there is not read in it), then the long form, read as one
        big-endian length of 1 + wider size bytes whose top byte is the marker: the marker shifted above the value
        goes into its adds and limits, so every reader of lengths (sizing, checks, encode) takes it as it is."""
        element = self.elements[k]
        assert element.extended is not None
        marker, size, adds, short_low, short_high, long_low, long_high = element.extended
        offset = self.offset(k)
        assert offset is not None  # the spec language keeps it before anything variable
        lead = marker << 8 * size
        short = replace(element, extended=None, limits=(short_low, short_high))
        long = replace(
            element,
            extended=None,
            size=1 + size,
            endian="big",
            adds=adds + lead,
            limits=(lead + long_low, lead + long_high),
            lead=lead,
        )

        def form(each: Element, **changes: Any) -> Layout:
            elements = self.elements[:k] + (each,) + self.elements[k + 1 :]
            return Layout(self.name, elements, self.transparency, self.codes, self.present, error=self.error, **changes)

        return (
            form(short, conditions=self.conditions, unless=((offset, marker),)),
            form(long, conditions=(*self.conditions, (offset, 1, "big", 0xFF, marker))),
        )

    def admits(self, frame: bytes) -> bool:
        """Whether `frame` has this variant's flag bits (a plain layout admits every frame)."""
        for offset, size, endian, mask, bits in self.conditions:
            if len(frame) < offset + size or int.from_bytes(frame[offset : offset + size], endian) & mask != bits:
                return False
        return all(len(frame) > offset and frame[offset] != byte for offset, byte in self.unless)

    def variant(self, frame: bytes) -> Layout:
        """The plain layout `frame` is read in: the variant whose flag bits it has (DecodeError: none)."""
        for variant in self.variants:
            if variant.admits(frame):
                return variant
        smallest = min(v.overhead for v in self.variants)
        raise DecodeError(
            f"frame of {len(frame)} bytes is shorter than the {smallest} bytes a {self.name} frame has besides its "
            "content"
        )

    # --- encoding -------------------------------------------------------------------------------------------------

    def wrap(
        self,
        content: bytes,
        code: int | None,
        values: tuple[int, ...],
        request: Mapping[str, bytes] | None = None,
        extras: Mapping[str, bytes | None] | None = None,
    ) -> bytes:
        """The frame around `content`; EncodeError when a value does not fit its element (the length, say).
        `request`: the bytes of the request's elements by name, for a checksum that takes some in first; `extras`:
        the optional elements' bytes by name (None or left out: not sent)."""
        if self.variants[0] is not self:
            sending = self._sending(values, extras)
            for variant in sending[:-1]:  # an extended length's one-byte form first: the long form if it does not fit
                try:
                    return variant.wrap(content, code, values, request, extras)
                except EncodeError:
                    pass
            return sending[-1].wrap(content, code, values, request, extras)
        plan: dict[str, Any] = self._plan  # type: ignore[attr-defined]
        elements = self.elements
        plain: list[bytes] = list(plan["template"])  # constants in place, zeros for what is computed below
        if self.content >= 0:
            plain[self.content] = content
        if self.command is not None:
            to_wire: dict[int, int] = self.to_wire  # type: ignore[attr-defined]
            if to_wire:
                if code not in to_wire:
                    raise EncodeError(f"code {code} is not sent in the {self.name} frame")
                code = to_wire[code]
            plain[self.command] = _pack(elements[self.command], code or 0)
        for index, value in zip(self.values, values, strict=True):
            plain[index] = _pack(elements[index], value)
        for index in plan["extras"]:
            given = (extras or {}).get(elements[index].name)
            if given is not None and not isinstance(given, bytes | bytearray):
                raise EncodeError(f"{elements[index].name} must be bytes or None, got {type(given).__name__}")
            if given is None or len(given) != elements[index].size:
                shown = "none" if given is None else f"{len(given)}"
                raise EncodeError(f"{elements[index].name}: {shown} bytes, expected {elements[index].size}")
            plain[index] = bytes(given)
        wire: dict[int, bytes] = {}
        t = self.transparency
        for index, element in plan["inner_lengths"]:  # inside the transformed span: the plain bytes
            value = sum(len(part) for part in plain[element.span[0] : element.span[1] + 1]) + element.adds
            _fits(self, element, value)
            plain[index] = element.pack(value)
        for index, element in plan["inner_checksums"]:  # inside the stuffed span: over the bytes before stuffing
            plain[index] = self._checksum(element, b"".join(plain[element.span[0] : element.span[1] + 1]))
        if t is not None:
            first, last = t.span
            wire[first] = t.encode(b"".join(plain[first : last + 1]))
        for index, element in plan["outer_lengths"]:
            value = len(self._wire(plain, wire, *element.span)) + element.adds
            _fits(self, element, value)
            plain[index] = element.pack(value)
        for index, element in plan["outer_checksums"]:
            covered = self._covered(plain, wire, element)
            if element.request:
                covered = _requested(element, request, EncodeError) + covered
            plain[index] = self._checksum(element, covered)
        return self._wire(plain, wire, 0, len(elements) - 1)

    def _sending(self, values: tuple[int, ...], extras: Mapping[str, bytes | None] | None) -> tuple[Layout, ...]:
        """The variants that send the optional elements given in `extras` (one, or an extended length's two forms);
        EncodeError where a value flag element's bit (the message's own value) says otherwise."""
        given = frozenset(name for name, data in (extras or {}).items() if data is not None)
        flags = dict(zip(self.values, values, strict=True))
        for element in self.elements:
            if element.kind == "optional" and element.flag in flags:
                flag = self.elements[element.flag]
                if bool(flags[element.flag] & element.mask) != (element.name in given):
                    sent = "given" if element.name in given else "not given"
                    state = "set" if flags[element.flag] & element.mask else "clear"
                    raise EncodeError(
                        f"{element.name} is {sent} but {flag.name} = {flags[element.flag]} has bit "
                        f"{element.mask:#04x} {state}"
                    )
        known = {e.name for e in self.elements if e.kind == "optional"}
        return tuple(v for v in self.variants if v.present == given & known)

    def _covered(self, plain: list[bytes], wire: dict[int, bytes], element: Element) -> bytes:
        """The bytes a checksum covers: its span's, less the elements it skips (which lie outside any stuffing)."""
        if not element.skip:
            return self._wire(plain, wire, *element.span)
        first, last = element.span
        return b"".join(plain[i] for i in range(first, last + 1) if i not in element.skip)

    def _wire(self, plain: list[bytes], wire: dict[int, bytes], first: int, last: int) -> bytes:
        """Wire bytes of elements first..last (plain bytes when the transparency span is not in play)."""
        t = self.transparency
        if t is None or last < t.span[0] or first > t.span[1]:
            return b"".join(plain[first : last + 1])
        if t.span[0] <= first and last <= t.span[1]:
            return b"".join(plain[first : last + 1])  # inside the span: the bytes before the rewrite
        return b"".join(plain[first : t.span[0]]) + wire[t.span[0]] + b"".join(plain[t.span[1] + 1 : last + 1])

    @staticmethod
    def _checksum(element: Element, covered: bytes) -> bytes:
        assert element.checksum is not None
        return element.pack(element.checksum(covered))

    # --- decoding -------------------------------------------------------------------------------------------------

    def unwrap(self, frame: bytes, request: Mapping[str, bytes] | None = None) -> Unwrapped:
        """Check a complete frame (constants, lengths, stuffing, checksums) and take it apart. `request`: the
        bytes of the request's elements by name, for a checksum that takes some in first."""
        if self.variants[0] is not self:
            return self.variant(frame).unwrap(frame, request)
        plan: dict[str, Any] = self._plan  # type: ignore[attr-defined]
        before, after = plan["before"], plan["after"]
        n = len(frame)
        if n < before + after:
            raise DecodeError(
                f"frame of {n} bytes is shorter than the {self.overhead} bytes a {self.name} frame has besides its "
                "content"
            )
        elements = self.elements
        plain: list[bytes] = [b""] * len(elements)
        for index, start, stop in plan["head"]:
            plain[index] = frame[start:stop]
        for index, start, stop in plan["tail"]:
            plain[index] = frame[n - start : n - stop]
        wire: dict[int, bytes] = {}
        middle = frame[before : n - after]
        if self.transparency is not None:
            wire[self.transparency.span[0]] = middle
            middle = self.transparency.decode(middle)
        if not plan["inner"] and middle:  # no content, no span: the frame is its fixed elements alone
            raise DecodeError(f"frame of {n} bytes is longer than the {self.name} frame ({self.overhead})")
        if plan["inner"]:
            fixed, variable = plan["inner_fixed"], plan["variable"]
            if variable < 0 and len(middle) != fixed or len(middle) < fixed:
                raise DecodeError(f"{self.name} frame: {len(middle)} bytes where at least {fixed} belong")
            position = 0
            for offset, (index, size) in enumerate(plan["inner"]):
                if offset == variable:
                    size = len(middle) - fixed
                plain[index] = middle[position : position + size]
                position += size
        for index, element in plan["constants"]:
            if plain[index] != element.constant:
                data = plain[index]
                raise DecodeError(f"{element.name} is {data.hex(' ')}, expected {element.constant.hex(' ')}")
        command = self.command
        code = elements[command].unpack(plain[command]) if command is not None else None
        from_wire: dict[int, int] = self.from_wire  # type: ignore[attr-defined]
        if from_wire and code is not None:
            if code not in from_wire:
                raise DecodeError(f"{elements[command or 0].name} = {code:#04x} is no code of the {self.name} frame")
            code = from_wire[code]
        values = tuple(elements[i].unpack(plain[i]) for i in self.values)
        for i, value in zip(self.values, values, strict=True):
            if not elements[i].plausible(value):  # as the stream parser, which sees no frame there
                raise DecodeError(_outside(elements[i], value))
        for index, element in plan["lengths"]:
            counted = len(self._wire(plain, wire, *element.span)) + element.adds
            value = element.unpack(plain[index])
            outside = element.length_outside(value)
            if outside:  # as the stream parser, which sees no frame there
                raise DecodeError(outside)
            if value != counted:
                raise DecodeError(
                    f"{element.name} says {value - element.lead} but the frame holds {counted - element.lead}"
                )
        for index, element in plan["checksums"]:
            covered = self._covered(plain, wire, element)
            if element.request:
                covered = _requested(element, request, DecodeError) + covered
            expected = element.checksum(covered)
            stored = element.unpack(plain[index])
            if expected != stored:
                raise ChecksumError(
                    f"bad {element.name}: the frame has {stored:#0{2 + 2 * element.size}x}, "
                    f"its bytes give {expected:#0{2 + 2 * element.size}x}"
                )
        content = plain[self.content] if self.content >= 0 else b""
        extras = {elements[i].name: plain[i] for i in plan["extras"]}
        return Unwrapped(self, code, values, content, tuple(plain), extras)


def _code_at(layout: Layout, frame: bytes) -> int | None:
    """The code at the command element's fixed offset in `frame`, where it has one and the frame reaches it."""
    offset = None if layout.command is None else layout.offset(layout.command)
    if offset is None or layout.command is None:
        return None
    element = layout.elements[layout.command]
    data = frame[offset : offset + element.size]
    if len(data) != element.size:
        return None
    from_wire: dict[int, int] = layout.from_wire  # type: ignore[attr-defined]
    return from_wire.get(element.unpack(data), -1) if from_wire else element.unpack(data)


def _class_name(cls: Any) -> Any:
    """A reply class's name, the key of a codec's `replies` (None stays None)."""
    return None if cls is None else getattr(cls, "__name__", cls)


def _requested(element: Element, request: Mapping[str, bytes] | None, error: type[Exception]) -> bytes:
    """The request's bytes a reply checksum takes in first; the error (one line) when the request is not known."""
    if request is None:
        names = " and ".join(element.request)
        raise error(f"{element.name} covers the request's {names}: give the request this reply answers")
    return b"".join(request[name] for name in element.request)


def _fits(layout: Layout, element: Element, value: int) -> None:
    """EncodeError for a length `value` its field cannot hold or its range refuses."""
    if not 0 <= value < 1 << (8 * element.size):
        raise EncodeError(f"{layout.name} frame: length {value} does not fit its {element.size}-byte field")
    outside = element.length_outside(value)
    if outside:
        raise EncodeError(f"{layout.name} frame: {outside}")


def _outside(element: Element, value: int) -> str:
    for name, low, mask, const in element.fixed:
        if (value >> low) & mask != const:
            return f"{element.name}.{name} is {(value >> low) & mask}, expected {const}"
    also = f" (or {element.also})" if element.also is not None else ""
    return f"{element.name} = {value} is outside its range {element.minimum}..{element.maximum}{also}"


def _pack(element: Element, value: int) -> bytes:
    try:
        return element.pack(value)
    except OverflowError:
        raise EncodeError(f"{element.name} = {value} does not fit {element.size} byte(s)") from None


def _inner_size(
    layout: Layout, plan: dict[str, Any], buffer: bytes, start: int, end: int, low: int, high: int | None
) -> int | None:
    """probe() for a layout whose length counts plain bytes inside the transformed span (XBee API mode 2: escaped
    itself, counting the plain bytes): its value read (through the transform where it lies inside the span), then
    as many plain bytes of the span as it says."""
    t = layout.transparency
    assert t is not None
    inside, at, element, uncounted, counted_fixed = plan["probe_inner"]
    begin = start + plan["prefix"]
    try:
        if inside:
            head = t.plain_prefix(buffer, begin, end, at + element.size)
            if head is None:
                return None
            if len(head[0]) < at + element.size:
                return -1
            value = element.unpack(head[0][at:])
        elif end - start < at + element.size:
            return None
        else:
            value = element.unpack(buffer[start + at : start + at + element.size])
        if element.length_outside(value):
            return -1
        counted = value - element.adds
        content = counted - counted_fixed  # the length counts the content (lang/passes/framing.py)
        if content < low or (high is not None and content > high):
            return -1
        whole = t.plain_prefix(buffer, begin, end, uncounted + counted)
    except DecodeError:
        return -1
    if whole is None:
        return None
    if len(whole[0]) < uncounted + counted:
        return -1
    prefix: int = plan["prefix"]
    return prefix + whole[1] + layout.suffix()


def _terminated(layout: Layout, buffer: bytes, start: int, end: int, low: int, high: int | None) -> int | None:
    """probe() for a frame ended by its trailer with nothing else to size it (no length, no transform, no size
    rule): the first occurrence of the trailer at which the frame checks (constants, checksums), so a trailer byte
    inside the content or a checksum does not end it; None while none has come, -1 past the largest content."""
    trailer = layout.trailer
    largest = None if high is None else layout.overhead + high
    position = buffer.find(trailer, start + layout.overhead + low - len(trailer), end)
    while position >= 0:
        size = position + len(trailer) - start
        if largest is not None and size > largest:
            return -1
        try:
            layout.unwrap(buffer[start : start + size])
        except DecodeError:
            position = buffer.find(trailer, position + 1, end)
            continue
        return size
    return -1 if largest is not None and end - start > largest else None


def _to_trailer(layout: Layout, buffer: bytes, begin: int, start: int, end: int) -> int | None:
    """probe() for a frame whose transformed span (from `begin` on) runs to its trailer: where a transform can tell
    where its span ends (`span_end`, hex-ASCII: at the first byte that is no hex digit), the trailer must follow
    right there, else no frame starts at `start`; otherwise the frame ends at the first trailer. None: wait."""
    trailer = layout.trailer
    span_end: Callable[[bytes, int, int], int | None] | None = getattr(layout.transparency, "span_end", None)
    if span_end is None:
        stop = buffer.find(trailer, begin)
        return None if stop < 0 else stop + len(trailer) - start
    ended = span_end(buffer, begin, end)
    if ended is None:
        return None
    if buffer.startswith(trailer, ended, end):
        return ended + len(trailer) - start
    return None if end - ended < len(trailer) and trailer.startswith(buffer[ended:end]) else -1


@dataclass(frozen=True)
class Unwrapped:
    layout: Layout
    code: int | None
    values: tuple[int, ...]
    content: bytes
    parts: tuple[bytes, ...] = ()  # every element's bytes, unstuffed
    extras: Mapping[str, bytes] = field(default_factory=dict)  # the optional elements sent, by name
    reply: str = ""  # replies read in the layout of their request: the class of a refusal read in its own layout

    def named(self) -> dict[str, bytes]:
        """Every element's bytes by its name (what a reply checksum over the request takes in)."""
        return {element.name: part for element, part in zip(self.layout.elements, self.parts, strict=True)}


# A content size rule for frames without a length: content_size(code, buffer, start, end) -> the content's size,
# None when more bytes are needed to tell, or -1 when no content of that command starts there.
ContentSize = Callable[[int | None, bytes, int, int], int | None]


@dataclass(frozen=True)
class SizeRule:
    """A content size that follows from the content itself: fixed bytes plus factor × a count field's value."""

    fixed: int
    terms: tuple[tuple[int, int, Literal["little", "big"], int], ...] = ()  # (offset, size, endian, factor)
    nul: int = -1  # the offset of a NUL-terminated text that ends the content: sized by its NUL (fixed: before it)
    # a reply's last bytes as many as a field of the request it answers says (`size_from: request.length`: the Tic's
    # and the Maestro's raw reads): the size needs that request, and with none there is no such reply
    request: str = ""
    # messages that share a code (or carry none) picked by a leading constant, each of its own size (Kondo ICS): the
    # constant read as (bytes, byte order, shift, mask), and each run of its values (lowest, highest, that one's rule)
    lead: tuple[int, Literal["little", "big"], int, int] = (0, "big", 0, 0)
    picks: tuple[tuple[int, int, SizeRule], ...] = ()

    def size(self, buffer: bytes, start: int, end: int, asked: Any = None) -> int | None:
        if self.picks:
            width, endian, shift, mask = self.lead
            if end - start < width:
                return None
            value = int.from_bytes(buffer[start : start + width], endian) >> shift & mask
            rule = next((rule for low, high, rule in self.picks if low <= value <= high), None)
            return -1 if rule is None else rule.size(buffer, start, end, asked)
        if self.request:
            wanted = getattr(asked, self.request, None)
            return self.fixed + wanted if isinstance(wanted, int) else -1
        if self.nul >= 0:
            found = buffer.find(0, start + self.nul, end)
            return None if found < 0 else found + 1 - start
        total = self.fixed
        for offset, size, endian, factor in self.terms:
            if start + offset + size > end:
                return None
            total += factor * int.from_bytes(buffer[start + offset : start + offset + size], endian)
        return total


# The key of the error reply's content sizes and size rule: a frame whose command code has the error flag set
# (Modbus: function | 0x80) is an error reply, whatever the code of the request it refuses.
ERROR_REPLY = -1


# A command element after a content of one size per code: its place from the frame's end (start, stop), its byte
# order, and each (frame size, code), smallest first.
_TrailingCodes = tuple[int, int, "Literal['little', 'big']", tuple[tuple[int, int], ...]]


def _by_trailing_code(trailing: _TrailingCodes, buffer: bytes, start: int, end: int) -> int | None:
    """Size of a frame whose command element follows a content of one size per code (TFmini's configuration
    frames): the smallest frame with the code of its size in the command element; None while a candidate size
    needs more bytes than have come, -1 if none fits."""
    first, stop, endian, sizes = trailing
    for size, code in sizes:
        if end - start < size:
            return None
        if int.from_bytes(buffer[start + size - first : start + size - stop], endian) == code:
            return size
    return -1


class FrameCodec:
    """One direction's frames: its layouts (alternatives, tried in order on encode), the content decoders' codes;
    `error_flag`: codes with these bits set are error replies (their sizes under ERROR_REPLY); `error_status`: the
    status element, and its bits, whose being set makes a frame an error reply (the code that of the request)."""

    def __init__(
        self,
        layouts: Iterable[Layout],
        content_sizes: dict[Any, tuple[int, int | None]],
        size_rules: dict[Any, SizeRule] | None = None,
        error_flag: int = 0,
        replies: dict[Any, int] | None = None,
        refusals: dict[str, tuple[str, ...]] | None = None,
        error_status: tuple[str, int] | None = None,
        partial: bool = False,
    ) -> None:
        """`replies`: frames that carry no code, in layouts chosen by command: each reply class's layout (by index),
        read only with the request's reply class given; content_sizes and size_rules are then by reply class (all
        three keyed by the class's name, so the construct structs hold them without the message classes).
        `refusals`: with `replies`, reply class -> the classes of the replies that may refuse its request instead
        (`refused_by`), each read in its own layout when the frame is not the reply awaited (BNO055: `EE status`
        for a read answered by `BB length data`). `partial`: layouts told apart by their header carry different
        frame values (the Pololu form's device number beside the compact form): values are the direction's, in
        order of first appearance, None for one a frame's layout does not carry; a message is sent in the layout
        carrying exactly the values it gives."""
        self.layouts = tuple(layouts)
        self.by_header = tuple(sorted(self.layouts, key=lambda each: not each.header))  # the headerless one last
        # the plain layouts the stream parser sizes frames in (a layout with optional elements: its variants), and
        # the index of the layout each comes from
        self.variants = tuple(variant for layout in self.layouts for variant in layout.variants)
        self._origin = {id(v): i for i, layout in enumerate(self.layouts) for v in layout.variants}
        self.replies = replies or {}
        self.refusals = refusals or {}
        self.content_sizes = content_sizes  # content size bounds by code (plain bytes)
        self.size_rules = size_rules or {}
        self.error_flag = error_flag
        self.error_status = error_status
        self._trailing_cache: dict[int, _TrailingCodes | None] = {}  # by id() of a layout of self.variants
        # probe() for each layout, its plan read once into a closure (what the stream parser calls per candidate)
        self.sizers = tuple(self._sizer(layout) for layout in self.variants)
        names = [tuple(layout.elements[i].name for i in layout.values) for layout in self.layouts]
        self.value_names = tuple(dict.fromkeys(name for each in names for name in each))
        self._carried = {
            id(layout): tuple(self.value_names.index(name) for name in own)
            for layout, own in zip(self.layouts, names, strict=True)
        }
        self.partial = partial

    @property
    def requests(self) -> bool:
        """Its frames are read with the request they answer (`replies`, or a checksum over request bytes)."""
        return bool(self.replies) or any(e.request for layout in self.layouts for e in layout.elements)

    def wrap(
        self,
        content: bytes,
        code: int | None,
        values: tuple[int, ...],
        layout: int | None = None,
        request: Mapping[str, bytes] | None = None,
        extras: Mapping[str, bytes | None] | None = None,
    ) -> bytes:
        """The frame in the first layout that can hold it; `layout`: in that one (layouts chosen by command);
        `extras`: the optional elements' bytes by name. With `partial` values, a layout carrying exactly the values
        given (not None)."""
        given = {i for i, value in enumerate(values) if value is not None} if self.partial else set()
        if layout is not None and not (self.partial and set(self._carried[id(self.layouts[layout])]) != given):
            return self.layouts[layout].wrap(content, code, self._own(self.layouts[layout], values), request, extras)
        problem: EncodeError | None = None
        for candidate in self.layouts:
            if (candidate.codes is not None and code not in candidate.codes) or candidate.error:
                continue  # (an error header's layout: only for the error reply, sent in it by its index)
            if self.partial and set(self._carried[id(candidate)]) != given:
                continue  # the layout carrying exactly the frame values given
            try:
                return candidate.wrap(content, code, self._own(candidate, values), request, extras)
            except EncodeError as exc:
                problem = exc
        if problem is None and self.partial:
            shown = ", ".join(name for i, name in enumerate(self.value_names) if i in given) or "no frame value"
            raise EncodeError(f"no layout sends code {code} with {shown} given")
        if problem is None:
            raise EncodeError(f"no layout sends code {code}")
        raise problem

    def _own(self, layout: Layout, values: tuple[int, ...]) -> tuple[int, ...]:
        """A layout's own frame values of the direction's (those it carries)."""
        if not self.partial:
            return values
        return tuple(values[i] for i in self._carried[id(layout)])

    def spread(self, unwrapped: Unwrapped) -> Unwrapped:
        """A frame's values as the direction's: None for those its layout does not carry."""
        if not self.partial:
            return unwrapped
        values: list[int | None] = [None] * len(self.value_names)
        layout = self.layouts[self._origin[id(unwrapped.layout)]]  # (a variant's: its layout's)
        for i, value in zip(self._carried[id(layout)], unwrapped.values, strict=True):
            values[i] = value
        return replace(unwrapped, values=tuple(values))  # type: ignore[arg-type]

    def layout_of(self, frame: bytes) -> Layout:
        """The layout whose header the frame starts with; the one headerless layout beside them takes the rest."""
        if len(self.layouts) == 1:
            return self.layouts[0]
        for layout in self.by_header:
            if frame.startswith(layout.header):
                return layout
        choices = " or ".join(layout.header.hex(" ") for layout in self.layouts)
        raise DecodeError(f"frame starts {frame[:4].hex(' ')}, expected {choices}")

    def asked(self, expect: Any, content: bytes, request: Any, error: type[Exception] = DecodeError) -> None:
        """A reply whose last bytes are as many as a field of its request says (a SizeRule with `request`): refused
        (`error`: DecodeError, or EncodeError on encode) when it holds another number of them (a reply cut short,
        or one to another request)."""
        rule = self.size_rules.get(_class_name(expect))
        if rule is None or not rule.request or request is None:
            return
        wanted = rule.size(b"", 0, 0, request)
        if wanted is not None and wanted != len(content):
            raise error(
                f"{_class_name(expect)}: {len(content)} content bytes, where its request asks for {wanted} "
                f"({rule.request} = {getattr(request, rule.request)})"
            )

    def unwrap(self, frame: bytes, expect: Any = None, request: Mapping[str, bytes] | None = None) -> Unwrapped:
        """Check a frame and take it apart: in the layout its header names, in the layout of its code (layouts
        chosen by command), or, for replies that carry no code, in the layout of `expect` (the reply class); its
        values those of the direction (None for one its layout does not carry)."""
        return self.spread(self._unwrap(frame, expect, request))

    def _unwrap(self, frame: bytes, expect: Any, request: Mapping[str, bytes] | None) -> Unwrapped:
        if self.replies:
            if expect is None and len(self.layouts) > 1:
                raise DecodeError(
                    "a reply without a command code is read in the layout of the request it answers: give the request"
                )
            name = _class_name(expect)
            index = self.replies.get(name)
            if index is None and expect is None and len(self.layouts) == 1:
                return self.layouts[0].unwrap(frame, request)  # one layout: the frame alone, its default reply
            if index is None:
                raise DecodeError(f"{getattr(expect, '__name__', expect)} is no reply of these frames")
            for refusal in self.refusals.get(name, ()):  # a reply refusing the request, in a layout of its own
                layout = self.layouts[self.replies[refusal]]
                if frame.startswith(layout.header) and not frame.startswith(self.layouts[index].header):
                    return replace(layout.unwrap(frame, request), reply=refusal)
            return self.layouts[index].unwrap(frame, request)
        if any(layout.codes is not None for layout in self.layouts):
            # the refusal of the layout that sends the frame's code first, then any layout's, then a code sent in
            # another layout
            problem: DecodeError | None = None
            elsewhere: DecodeError | None = None
            for layout in self.by_header:  # a header's layout first: F0 starts a sysex, not a headerless code F0
                if not frame.startswith(layout.header):
                    continue
                try:
                    unwrapped = layout.unwrap(frame, request)
                except DecodeError as exc:
                    if layout.codes is not None and _code_at(layout, frame) in layout.codes:
                        raise
                    problem = problem or exc
                    continue
                if layout.codes is None or unwrapped.code in layout.codes:
                    return unwrapped
                code = "no code" if unwrapped.code is None else f"code {unwrapped.code:#04x}"
                if not any(other.codes is None or unwrapped.code in other.codes for other in self.layouts):
                    elsewhere = elsewhere or DecodeError(f"unknown command {unwrapped.code:#04x}")  # as one layout's
                elsewhere = elsewhere or DecodeError(f"{code} is not sent in layout {layout.name!r}")
            problem = problem or elsewhere
            if problem is None:
                choices = " or ".join(layout.header.hex(" ") for layout in self.layouts)
                problem = DecodeError(f"frame starts {frame[:4].hex(' ')}, expected {choices}")
            raise problem
        return self.layout_of(frame).unwrap(frame, request)

    def probe(
        self, layout: Layout, buffer: bytes, start: int, end: int, expect: Any = None, asked: Any = None
    ) -> int | None:
        """Size of a plausible frame of `layout` at buffer[start:], None when more bytes are needed, -1 if none.
        `expect`: the reply class awaited, for replies read in the layout of their request (`replies`); `asked`:
        the request it answers (a reply sized by a request field)."""
        reading = self._reading(layout, expect) if self.replies else None
        if self.replies and reading is None:
            return -1  # no reply awaited, or one of another layout
        plan: dict[str, Any] = layout._plan  # type: ignore[attr-defined]
        available = end - start
        code: int | None = None
        refused = False  # the status's error bits set (`error_status`)
        for element, first, stop in plan["probe_head"]:  # the fixed part before anything variable
            if available < stop:
                return None
            data = buffer[start + first : start + stop]
            kind = element.kind
            if kind == "constant":
                if data != element.constant:
                    return -1
            elif kind == "command":
                value = int.from_bytes(data, element.endian)
                if element.wire:
                    from_wire: dict[int, int] = layout.from_wire  # type: ignore[attr-defined]
                    if value not in from_wire:
                        return -1
                    value = from_wire[value]
                code = ERROR_REPLY if layout.error or value & self.error_flag else value
                if code not in self.content_sizes or (layout.codes is not None and code not in layout.codes):
                    if self.error_status is None:
                        return -1
                    code = -2  # none: unless the status says this is an error reply (any code's)
            elif kind == "value":
                value = int.from_bytes(data, element.endian)
                if not element.plausible(value):
                    return -1
                if self.error_status is not None and element.name == self.error_status[0]:
                    refused = bool(value & self.error_status[1])
        if self.error_status is not None and code is not None:
            if refused:
                code = ERROR_REPLY
            elif code == -2:
                return -1
        if layout.command is None:
            code = reading  # type: ignore[assignment]  # (replies' content sizes are by class name)
            if code not in self.content_sizes:
                return -1
        if layout.content < 0 and layout.transparency is None:
            return layout.overhead  # its fixed elements alone (a bare acknowledgement)
        if code is None:
            trailing = self._trailing_codes(layout)
            if trailing is not None:
                return _by_trailing_code(trailing, buffer, start, end)
        low, high = self.content_sizes.get(code, (0, None))
        if plan["probe_inner"] is not None:
            return _inner_size(layout, plan, buffer, start, end, low, high)
        length: tuple[int, Element, int, int] | None = plan["probe_length"]
        if length is not None:
            offset, element, outside, inside_fixed = length
            counted = element.unpack(buffer[start + offset : start + offset + element.size])
            if element.limits is not None and not element.limits[0] <= counted <= element.limits[1]:
                return -1
            counted -= element.adds
            content = counted - inside_fixed  # wire bytes of the content (stuffed, if it is)
            if content < low or (layout.transparency is None and high is not None and content > high):
                return -1
            return outside + counted
        if layout.trailer and layout.transparency is not None:
            return _to_trailer(layout, buffer, start + plan["before"], start, end)
        rule = self.size_rules.get(code)
        if rule is None:
            return _terminated(layout, buffer, start, end, low, high) if layout.trailer else -1
        content_size = rule.size(buffer, start + plan["prefix"], end, asked)
        if content_size is None:
            return None
        if content_size < low or (high is not None and content_size > high):
            return -1
        return layout.overhead + content_size

    def _reading(self, layout: Layout, expect: Any) -> str | None:
        """The reply class a frame of `layout` is read as: the one awaited if this is its layout, else a refusal of
        its request whose layout this is (None: neither)."""
        name = _class_name(expect)
        index = self._origin[id(layout)]
        if self.replies.get(name) == index:
            return str(name)
        return next((r for r in self.refusals.get(name, ()) if self.replies[r] == index), None)

    def _trailing(self, layout: Layout) -> tuple[int, int] | None:
        """Where a command element after the content sits, counted from the frame's end (start, stop), for a
        layout that has no length, terminator or stuffing to size its frames by; None otherwise."""
        plan: dict[str, Any] = layout._plan  # type: ignore[attr-defined]
        if layout.transparency is not None or layout.trailer or plan["probe_length"] is not None:
            return None
        return next(((a, b) for index, a, b in plan["tail"] if index == layout.command), None)

    def _trailing_codes(self, layout: Layout) -> _TrailingCodes | None:
        """For a layout whose command element follows the content (see _trailing): where that element sits, and each
        code's frame size, smallest first; worked out once per layout."""
        key = id(layout)
        if key not in self._trailing_cache:
            place = self._trailing(layout)
            if place is None:
                self._trailing_cache[key] = None
            else:
                to_wire: dict[int, int] = layout.to_wire  # type: ignore[attr-defined]
                sizes = sorted(
                    (layout.overhead + low, to_wire.get(code, code))
                    for code, (low, high) in self.content_sizes.items()
                    if isinstance(code, int)
                    and code >= 0
                    and low == high
                    and (layout.codes is None or code in layout.codes)
                    and (not to_wire or code in to_wire)
                )
                element = layout.elements[layout.command or 0]
                self._trailing_cache[key] = (*place, element.endian, tuple(sizes))
        return self._trailing_cache[key]

    def verifier(self, layout: Layout) -> Callable[[bytes, int, int], bool] | None:
        """Whether the checksum of the frame buffer[start:stop] of `layout` holds, without decoding it (no exception
        to raise and catch for the many candidates that fail): for a layout with one checksum after its content,
        covering elements from its fixed head on, no stuffing. None for other layouts (decoding decides)."""
        plan: dict[str, Any] = layout._plan  # type: ignore[attr-defined]
        if layout.transparency is not None or len(plan["checksums"]) != 1:
            return None
        index, element = plan["checksums"][0]
        if element.skip or element.request:
            return None
        head = {i: begin for i, begin, _ in plan["head"]}
        tail = {i: (begin, finish) for i, begin, finish in plan["tail"]}
        first, last = element.span
        if index not in tail or first not in head or last + 1 not in tail or element.checksum is None:
            return None
        begin, covered_end, (stored, stored_end) = head[first], tail[last + 1][0], tail[index]
        checksum, endian = element.checksum, element.endian

        def verify(buffer: bytes, start: int, stop: int) -> bool:
            value = int.from_bytes(buffer[stop - stored : stop - stored_end], endian)
            return bool(checksum(buffer[start + begin : stop - covered_end]) == value)

        return verify

    def first_byte(self, layout: Layout) -> int | None:
        """The byte every frame of `layout` begins with (the first of a constant its head starts with), or None."""
        plan: dict[str, Any] = layout._plan  # type: ignore[attr-defined]
        head: tuple[tuple[Element, int, int], ...] = plan["probe_head"]
        for element, first, _ in head:
            if first == 0 and element.kind == "constant" and element.constant:
                return element.constant[0]
        return None

    def head_pattern(self, layout: Layout) -> bytes | None:
        """A regular expression for where a plausible frame of `layout` can start: each byte of its fixed head that
        the sizer checks (constants, one-byte commands and values) as the class of the bytes it allows, a head the
        buffer ends in matching as far as it goes (the sizer then waits for more). b"" when any byte can start one;
        None when no frame of the layout is plausible. The stream parser finds its candidates with it, in C."""
        if layout.command is None and None not in self.content_sizes and not self.replies:
            return None
        plan: dict[str, Any] = layout._plan  # type: ignore[attr-defined]
        classes: list[bytes] = []
        for element, first, stop in plan["probe_head"]:
            allowed: list[list[int]] = [list(range(256))] * (stop - first)
            if element.kind == "constant":
                allowed = [[byte] for byte in element.constant]
            elif element.kind == "command" and stop == first + 1 and self.error_status is None:
                # (error replies told by their status may carry any code: every byte)
                codes = self.content_sizes
                from_wire: dict[int, int] = layout.from_wire  # type: ignore[attr-defined]
                allowed = [
                    [
                        v
                        for v in range(256)
                        if (not from_wire or v in from_wire)
                        and (ERROR_REPLY if layout.error or v & self.error_flag else from_wire.get(v, v)) in codes
                        and (layout.codes is None or from_wire.get(v, v) in layout.codes)
                    ]
                ]
            elif element.kind == "value" and stop == first + 1:
                allowed = [[v for v in range(256) if element.plausible(v)]]
            for values in allowed:
                if not values:
                    return None
                whole = len(values) == 256
                classes.append(b"." if whole else b"[" + b"".join(re.escape(bytes([v])) for v in values) + b"]")
        while classes and classes[-1] == b".":
            classes.pop()
        pattern = b""
        for each in reversed(classes):  # each byte, or the end of the buffer before it
            pattern = each + (b"(?:" + pattern + b"|\\Z)" if pattern else b"")
        return pattern

    def _sizer(self, layout: Layout) -> Callable[[bytes, int, int], int | None]:
        """probe(layout, ...) as a closure over what it reads of the layout's plan, worked out once.

        Where the candidate's fixed head has all come (the usual case), its checks are made with no test of the bytes
        available: which one fails first then makes no difference (each says no frame). Otherwise probe() decides, so
        the answer is always probe()'s: tests/test_frame_sizers.py draws candidates and holds the two to it.
        """
        plan: dict[str, Any] = layout._plan  # type: ignore[attr-defined]
        if plan["probe_inner"] is not None:  # sized by reading into the transformed span: probe() decides
            return lambda buffer, start, end: self.probe(layout, buffer, start, end)
        wire = layout.command is not None and layout.elements[layout.command].wire
        if layout.codes is not None or layout.content < 0 or self._trailing(layout) is not None or wire:
            # layouts chosen by command, fixed frames, a command element after the content, codes sent as an
            # expression of them: probe()
            return lambda buffer, start, end: self.probe(layout, buffer, start, end)
        head: tuple[tuple[Element, int, int], ...] = plan["probe_head"]
        need = max((stop for _, _, stop in head), default=0)
        constants = tuple((first, e.constant) for e, first, _ in head if e.kind == "constant")
        commands = tuple((first, stop, e.endian) for e, first, stop in head if e.kind == "command")
        values = tuple(
            (first, stop, e.endian, e.minimum, e.maximum, e.also, *e.need)
            for e, first, stop in head
            if e.kind == "value"
        )
        content_sizes, size_rules, error_flag = self.content_sizes, self.size_rules, self.error_flag
        refusing = layout.error
        if self.error_status is not None:  # error replies told by their status: probe() decides
            return lambda buffer, start, end: self.probe(layout, buffer, start, end)
        codeless = layout.command is None
        if codeless and None not in content_sizes:
            return lambda buffer, start, end: self.probe(layout, buffer, start, end)
        if len(commands) > 1 or (codeless and commands):  # probe() decides
            return lambda buffer, start, end: self.probe(layout, buffer, start, end)
        command = commands[0] if commands else None  # none: after the head (stuffed), so no code is read here
        length: tuple[int, Element, int, int] | None = plan["probe_length"]
        measured = None  # the length element read in place: offset, stop, byte order, adds, sizes around it
        if length is not None:
            offset, element, outside, inside_fixed = length
            low_length, high_length = element.limits or (0, (1 << 8 * element.size) - 1)
            measured = (offset, offset + element.size, element.endian, element.adds, outside, inside_fixed)
        trailer = layout.trailer if layout.trailer and layout.transparency is not None else b""
        terminated = bool(layout.trailer)
        before, prefix, overhead, bounded = plan["before"], plan["prefix"], layout.overhead, layout.transparency is None

        def sizer(buffer: bytes, start: int, end: int) -> int | None:
            if end - start < need:
                return self.probe(layout, buffer, start, end)
            for first, constant in constants:
                if not buffer.startswith(constant, start + first):
                    return -1
            code: int | None = None
            if command is not None:
                first, stop, endian = command
                value = (
                    buffer[start + first]
                    if stop - first == 1
                    else int.from_bytes(buffer[start + first : start + stop], endian)
                )
                code = ERROR_REPLY if refusing or value & error_flag else value
                if code not in content_sizes:
                    return -1
            for first, stop, endian, minimum, maximum, also, mask, bits in values:
                value = (
                    buffer[start + first]
                    if stop - first == 1
                    else int.from_bytes(buffer[start + first : start + stop], endian)
                )
                if (not minimum <= value <= maximum and value != also) or value & mask != bits:
                    return -1
            low, high = content_sizes.get(code, (0, None))
            if measured is not None:
                offset, stop, endian, adds, outside, inside_fixed = measured
                counted = int.from_bytes(buffer[start + offset : start + stop], endian)
                if not low_length <= counted <= high_length:
                    return -1
                counted -= adds
                content = counted - inside_fixed
                if content < low or (bounded and high is not None and content > high):
                    return -1
                return outside + counted
            if trailer:
                return _to_trailer(layout, buffer, start + before, start, end)
            rule = size_rules.get(code)
            if rule is None:
                return _terminated(layout, buffer, start, end, low, high) if terminated else -1
            content_size = rule.size(buffer, start + prefix, end)
            if content_size is None:
                return None
            if content_size < low or (high is not None and content_size > high):
                return -1
            return overhead + content_size

        return sizer


Decode = Callable[..., Message]  # (frame, expected reply class[, request])
Verify = Callable[[bytes, int, int], bool]


def _finder(formats: Iterable[tuple[FrameCodec, Decode]]) -> re.Pattern[bytes] | None:
    """Where a candidate of any layout can start (FrameCodec.head_pattern), as one pattern; None: at every byte."""
    patterns = [codec.head_pattern(layout) for codec, _ in formats for layout in codec.variants]
    found = [pattern for pattern in patterns if pattern is not None]
    if not found or not all(found):  # a layout any byte can start (or none at all): every byte is a candidate
        return None
    return re.compile(b"(?=" + b"|".join(b"(?:" + pattern + b")" for pattern in found) + b")", re.DOTALL)


class FrameStreamParser(StreamParser):
    """Splits a byte stream into messages for frames of any layout (see `FrameCodec`).

    A StreamParser to those who hold one (the bus), with its own scanning: it does not call StreamParser.__init__.

    Every header occurrence (every byte, for frames without a header) is a candidate frame start. A candidate must
    be plausible (constants, values in range, a known command, a length its command allows) before its size is
    trusted, and must decode (stuffing, checksums, content) before it is accepted; a candidate that fails costs one
    byte. The rule of runtime/stream.py decides between overlapping candidates, whatever the reads: the frame that
    completes first wins (of two ending on the same byte, the first), so a candidate, complete or still waiting for
    bytes, never hides a valid frame that starts inside it and ends before it. Where several layouts fit at one
    position, the one that completes first and decodes is its frame (one that fails leaves the next its chance).
    """

    def __init__(self, *formats: tuple[FrameCodec, Decode]) -> None:
        if not formats:
            raise ValueError("a stream parser needs at least one frame format")
        self._formats = formats
        # every layout's sizer with its format's decoder, in the order candidates try them
        # and a checksum test before a candidate is decoded, where the layout allows one (FrameCodec.verifier)
        self._sizers = tuple(
            (self._by_request(codec, layout) if codec.replies else sizer, decode, codec.verifier(layout))
            for codec, decode in formats
            for sizer, layout in zip(codec.sizers, codec.variants, strict=True)
        )
        # replies read with the request they answer: the pending request, given to the decoder (see expect)
        self._requests = any(codec.requests for codec, _ in formats)
        self.request: Message | None = None
        # by a candidate's first byte, the sizers of the layouts that can start with it (a layout whose head begins
        # with a constant answers -1 for every other byte: it is not asked)
        firsts = [codec.first_byte(layout) for codec, _ in formats for layout in codec.variants]
        self._sizers_by_first = tuple(
            tuple(entry for entry, first in zip(self._sizers, firsts, strict=True) if first is None or first == byte)
            for byte in range(256)
        )
        self._pending = b""
        headers = [layout.header for codec, _ in formats for layout in codec.variants]
        self._headers = bool(all(headers))
        self._keep = max((len(h) for h in headers), default=1) - 1
        # no frame is shorter than its layout's fixed elements and the smallest content any command allows
        self._smallest = max(
            1,
            min(
                layout.overhead + min((low for low, _ in codec.content_sizes.values()), default=0)
                for codec, _ in formats
                for layout in codec.variants
            ),
        )
        self._finder = _finder(formats)
        self.errors = 0
        self.garbage = 0
        self.expected: type[Message] | None = None

    def _by_request(self, codec: FrameCodec, layout: Layout) -> Callable[[bytes, int, int], int | None]:
        """The sizer of a layout of replies read in the layout of their request: the awaited reply class's."""
        return lambda buffer, start, end: codec.probe(layout, buffer, start, end, self.expected, self.request)

    def expect(self, cls: type[Message] | None, request: Message | None = None) -> None:
        """The reply class the next frames answer, where several reply layouts share a code (PING's vs READ's),
        and the request they answer, where replies are read with it (layouts chosen by command, a reply checksum
        over request bytes). Without one such replies are not taken: their bytes count as garbage."""
        self.expected = cls
        if self._requests:
            self.request = request

    def feed(self, data: bytes | bytearray | memoryview) -> list[Message]:
        """One pass over the candidates from the last frame taken on: the valid frame that ends first (then starts
        first) among them is the next one taken, and no candidate after it needs a look once none can end before it.
        A corrupt candidate counts as an error when the byte-by-byte scan would have decided it before taking that
        frame: when it and every candidate before it had all their bytes by the time that frame ended (a layout that
        says no frame only from a byte after it left its candidate undecided then: _late)."""
        buffer = self._pending + bytes(data)
        end = len(buffer)
        found: list[Message] = []
        search = self._finder.search if self._finder is not None else None
        smallest, expected, request = self._smallest, self.expected, self.request
        start = 0
        ahead = -1  # the candidate the last search found (a match of the pattern does not depend on where it began)
        while True:
            best: tuple[Message, int, int] | None = None
            bound = end + 1  # where the best frame so far ends: a frame must end before it to win
            seen: list[tuple[int, int, bool]] = []  # candidates before it: (start, end or end + 1, corrupt)
            displaced: list[tuple[int, int, bool]] = []  # frames taken for best, then beaten by one ending first
            refused: list[int] = []  # candidates no frame or corrupt where a layout said no frame (see _late)
            waiting = False
            position = start
            while True:
                if search is not None:
                    if ahead < position:  # the next candidate from `position` on is not known yet
                        match = search(buffer, position)
                        ahead = end + 1 if match is None else match.start()
                    if ahead > end:
                        break
                    position = ahead
                # no frame from here can end before the best one (or, none found, in the bytes there are, once one
                # candidate is known to be waiting for more)
                if position >= end or (position + smallest >= bound and (best is not None or waiting)):
                    break
                # the layouts that fit here, the one that completes first first: the first of them that decodes is
                # the candidate's frame; one that fails leaves the next its chance (RPLIDAR: a 5-byte measurement
                # that fails before the 7-byte scan descriptor at the same place)
                outcome: tuple[int, bool] | None = None  # where the candidate is decided (end + 1: waiting), corrupt
                sizes = self._sizes(buffer, position, end)
                for stop, decode, verify in sizes:
                    if decode is None:  # still waiting for bytes
                        outcome = (end + 1, False)
                        waiting = True
                        break
                    if stop >= bound:
                        outcome = (stop, False)
                        break
                    message = None
                    # the checksum first (no message built when it fails), but for the candidate the scan
                    # starts at, usually a frame: decoding it checks the checksum once
                    if verify is None or position == start or verify(buffer, position, stop):
                        try:
                            message = (
                                decode(buffer[position:stop], expected)
                                if request is None
                                else decode(buffer[position:stop], expected, request)
                            )
                        except DecodeError:
                            message = None
                    if message is not None:
                        if best is not None:  # a frame that completes first, inside the best one so far: that
                            displaced.append((best[1], best[2], False))  # one is undecided when this one ends
                        best, bound, outcome = (message, position, stop), stop, None
                        break
                    outcome = (stop, True)
                if outcome is not None:
                    seen.append((position, *outcome))
                if (outcome is None or outcome[1]) and len(sizes) < len(self._sizers_by_first[buffer[position]]):
                    refused.append(position)  # (a layout said no frame: perhaps from bytes after the frame taken)
                position += 1
            first, last = (best[1], best[2]) if best is not None else (end + 1, end)
            hold = -1
            if displaced:
                seen = sorted(seen + displaced)
            late = self._late(buffer, refused, first, last) if refused and best is not None else first
            for position, stop, corrupt in seen:
                if position >= first or position >= late:
                    break
                if stop > last:  # undecided when the frame taken ended (or the bytes ran out)
                    hold = position
                    break
                self.errors += corrupt
            if best is None:
                break
            message, first, stop = best
            found.append(message)
            self.garbage += first - start
            start = stop
        if hold >= 0:
            cut = hold
        elif self._headers:
            cut = max(start, end - self._keep)
        else:
            cut = end
        self.garbage += cut - start
        self._pending = buffer[cut:]
        return found

    def _late(self, buffer: bytes, refused: list[int], first: int, last: int) -> int:
        """The first of the `refused` candidates before the frame taken (at first..last) still waiting for bytes when
        it ended, else `first`. A layout that says no frame from a byte after that frame (RPLIDAR: a reply's
        unknown data type, the byte after a measurement inside its descriptor) left the candidate undecided then, as
        the byte-by-byte scan finds it: no corrupt candidate after it is counted before that frame."""
        for position in refused:
            if position >= first:
                break
            if any(decode is None for _, decode, _ in self._sizes(buffer, position, last)):
                return position
        return first

    def _sizes(self, buffer: bytes, position: int, end: int) -> list[tuple[int, Decode | None, Verify | None]]:
        """The layouts that fit the candidate at `position`, the one that completes first first (of two ending
        together, the first layout): (where it ends, its decoder and checksum test), the decoder None while it must
        wait for bytes (its size not known yet: it ends past `end` anyway; or it ends past `end`)."""
        found: list[tuple[int, Decode | None, Verify | None]] = []
        for sizer, decode, verify in self._sizers_by_first[buffer[position]]:
            size = sizer(buffer, position, end)
            if size is None:
                found.append((end + 1, None, None))
            elif size > 0:  # (a reply sized 0 by its request: no bytes, no frame in a stream)
                stop = position + size
                found.append((stop, decode, verify) if stop <= end else (stop, None, None))
        if len(found) > 1:
            found.sort(key=lambda sized: sized[0])
        return found

    def gap(self) -> None:
        """The line went idle: the bytes held are dropped as garbage (StreamParser.gap)."""
        self.garbage += len(self._pending)
        self._pending = b""

    def pending(self) -> bytes:
        return self._pending


@dataclass(frozen=True)
class EngineFormat:
    """One direction's frames as code that splits a stream of both directions reads them (serialspec monitor)."""

    codec: FrameCodec
    decode: Decode

    @property
    def header(self) -> bytes:
        return self.codec.layouts[0].header

    def size(self, buffer: bytes, position: int) -> int | None:
        """The size of a plausible frame at `position`; None if none starts there; past the buffer: wait."""
        waiting = False
        for layout in self.codec.variants:
            size = self.codec.probe(layout, buffer, position, len(buffer))
            if size is None:
                waiting = True
            elif size >= 0:
                return size
        return len(buffer) - position + 1 if waiting else None

    def decode_at(self, buffer: bytes, start: int, stop: int, expect: type[Message] | None = None) -> Message:
        return self.decode(buffer[start:stop], expect)


def __getattr__(name: str) -> Any:
    # each transform's runtime class (serialspec/transforms/), imported from here by generated code, loaded when asked
    if name.startswith("__"):  # `from ... import` asks for __path__: not a transform (the registry imports pkgutil)
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from serialspec.transforms import runtime_classes

    found = runtime_classes().get(name)
    if found is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(import_module(found[0]), found[1])
