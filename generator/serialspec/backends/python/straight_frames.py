"""Straight-line frame code: the one generator of the codec's frames, for every framing the language describes.

A frame shape is a description: the engine's layouts (runtime/framing.py's Layout, made from the model by
backends/common/frames.py), one or more per direction. From it this module writes the codec's frame code, in three
layers, each a case of the one before:

1. **Every framing** (`straight_direction`, `decode_lines`, `wrap_parts`, `frame_encoder`): a layout fits the
   straight-line form when its content lies in its one variable part (stuffing, u16 lengths over a span, CRC-16s,
   frames without a header or a length, alternative layouts told apart by their header all do). Each direction
   gets the engine's checks (Layout.unwrap and Layout.wrap) in the engine's order with the engine's messages, but as
   code written for one layout: every offset known when the layout is fixed is a literal, the bytes are unstuffed
   only when a stuffed sequence occurs (a `find` first), a frame's content is decoded in place (no copy) unless it
   was stuffed, and a CRC stored in its own bit order is checked by its residue over the frame. decode() runs the
   checks inline (one call less); encoders of unstuffed frames make their frame inline (`frame_encoder`: the head
   packed with the content's first struct, constant leading bytes as a literal beside the checksummed body). Where a
   layout does not fit (a length after the content, a checksum over bytes inside the stuffed span, ...) the
   direction's two functions call the engine instead, so every layout works and the straight-line form is only ever
   a faster way to the same result (tests/test_straight_frames.py holds them to it).
2. **Frames of one size whose message is one struct's unpack of their content** (`whole_frames`): decode() first
   looks them up by the bytes before the content, checks the rest from the frame's end and unpacks the whole frame.
3. **The length-byte case** (`length_byte_codec_context`): layouts with a header, frame values and a command code
   at fixed offsets, a one-byte length before the content and one checksum at the end, nothing stuffed (the
   model's FrameLayout.classic). Their offsets are known once a frame's first bytes are, so each message of one
   size also gets a whole-frame decoder made from its content decoder's statements (the content size check dropped,
   the cursor made a constant offset), which checks the checksum the cheapest way its algorithm allows
   (checksums/: frame_test, byte_total, byte_table); decode() looks them up by the frame's first bytes
   (`lookup_lines`) before the general checks of layer 1, which take every frame the tables do not. The same
   decoders, at an offset of a buffer (`stream=True`), are the stream parser's (runtime/stream.py's FrameFormat:
   `fixed`, `runs`, `summed`), which takes the length-byte case; the others' stream parser is the engine's
   (runtime/framing.py's FrameStreamParser).

`frames_codec_context` is the codec template's one entry. Positions in layer 1 are expressions over `buf`, the
frame with its stuffed span replaced by the plain bytes (`frame` itself where nothing can be stuffed): an element
before the content at a literal offset, an element after it at `end + k`, where `end` is the content's end. Lengths
and checksums that see wire bytes read `frame`.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from serialspec.backends.common.frames import optional_elements, runtime_layout, runtime_layouts
from serialspec.backends.python.checksum_code import checksum_call, checksum_lines, checksum_name, checksum_setup
from serialspec.backends.python.dispatch import (
    ERROR_REPLY,
    decoder_name,
    direction_dispatch,
    message_function,
    shared_codes,
)
from serialspec.backends.python.frames import checksum_definitions, codec_lines, import_lines
from serialspec.backends.python.ir import (
    RETURN_NONE,
    Advance,
    Block,
    Code,
    ContentSize,
    Expect,
    FrameTest,
    If,
    Literal,
    Loop,
    Pack,
    PackItems,
    ReturnNew,
    Simple,
    Statement,
    TakeRest,
    Unpack,
    lines_of,
    packed_lists,
    raises,
    reads_cursor,
    walk,
)
from serialspec.backends.python.kinds import takes_the_rest
from serialspec.backends.python.optimize import content_unpacked, fuse_unpack
from serialspec.backends.python.simulator import import_order
from serialspec.lang.model import (
    Bytes,
    Checksum,
    Command,
    Direction,
    FrameLayout,
    Message,
    Protocol,
    replies_by_request,
    reply_to,
)
from serialspec.runtime.framing import Element, Layout, Transparency

if TYPE_CHECKING:
    from serialspec.backends.python.content import PackageCode

Lines = list[str]
Structs = Callable[[str], str]  # a struct format -> the name of the module's struct constant for it


def registry(structs: dict[str, str]) -> Structs:
    """A Structs that names each format after its layout (`_F_...`) and keeps it in `structs` (name -> format)."""

    def named(fmt: str) -> str:
        name = _struct_name(fmt)
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
    expected: bool = False
    only: str = ""  # the one content decoder of frames that carry no command code: called directly
    requesting: bool = False  # frames read and made with the request they answer (layouts chosen by command)
    optional: tuple[str, ...] = ()  # the optional elements (`present_if`) the messages carry: the engine's


def straight(layout: Layout) -> bool:
    """Whether the layout fits the straight-line form: one content inside the variable part (the stuffed span, else
    the content), lengths at fixed offsets before it, checksums after it and after what they cover, none of them
    over bytes inside the stuffed span only, multi-byte elements at fixed offsets in one byte order."""
    if layout.content < 0 or not isinstance(layout.transparency, Transparency | None):
        return False  # other transforms than substitution: the engine codes them
    if layout.variants != (layout,):
        return False  # optional elements: the engine's variants
    first, last = _variable(layout)
    if not first <= layout.content <= last:
        return False
    for index, element in enumerate(layout.elements):
        if element.kind == "length" and (index >= first or _inside(layout, *element.span)):
            return False
        if element.kind == "checksum":
            a, b = element.span
            if index <= last or b >= index or _inside(layout, a, b) or element.skip:
                return False  # (a span that leaves out checksums inside it: the engine's covered bytes)
    packed = [e for e in layout.elements if e.kind in ("value", "command", "length") and e.size > 1]
    return len({e.endian for e in packed}) <= 1


def _variable(layout: Layout) -> tuple[int, int]:
    """The elements whose size is known only at run time: the stuffed span, else the content alone."""
    return layout.transparency.span if layout.transparency is not None else (layout.content, layout.content)


def _stuffing(layout: Layout) -> Transparency | None:
    """The layout's substitution, of a straight layout (straight() takes no other transform)."""
    assert isinstance(layout.transparency, Transparency | None)
    return layout.transparency


def _inside(layout: Layout, a: int, b: int) -> bool:
    """Whether elements a..b lie within the stuffed span (all of it, or part): a length or checksum over them sees
    the plain bytes."""
    t = layout.transparency
    return t is not None and t.span[0] <= a and b <= t.span[1]


def _size(elements: tuple[Element, ...]) -> int:
    return sum(e.size for e in elements)


class _Positions:
    """Element positions in `buf` (plain bytes): a literal offset before the content, `end + k` after it; or, for a
    frame known not to be stuffed (`from_end`), in `frame`, counted back from the frame's end after the content."""

    def __init__(self, layout: Layout, from_end: bool = False) -> None:
        self.layout = layout
        self.from_end = from_end
        # the plain bytes: the frame itself where nothing can be stuffed
        self.buf = "frame" if from_end or layout.transparency is None else "buf"
        self.first, self.last = _variable(layout)
        c = layout.content
        self.before = _size(layout.elements[: self.first])  # wire bytes before the variable part
        self.after = _size(layout.elements[self.last + 1 :])  # wire bytes after it
        self.content = _size(layout.elements[:c])  # the content's offset
        self.behind = _size(layout.elements[c + 1 :])  # bytes after the content (plain)
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
                self.before + self.after - _size(elements[a : self.first]) - _size(elements[self.last + 1 : b + 1])
            )
            return _plus("n", adds - outside)
        c = self.layout.content
        if a <= c <= b:  # inside the stuffed span: plain bytes
            return _plus("end", _size(elements[a:c]) + _size(elements[c + 1 : b + 1]) - self.content + adds)
        return str(_size(elements[a : b + 1]) + adds)

    def covered(self, a: int, b: int) -> str:
        """The bytes a checksum over elements a..b sees: wire bytes of `frame` when they hold the variable part."""
        elements = self.layout.elements
        if a <= self.first and self.last <= b:
            begin = _size(elements[:a])
            tail = _size(elements[b + 1 :])
            return f"frame[{begin or ''}:{-tail if tail else ''}]" if begin or tail else "frame"
        return f"{self.buf}[{_start(self.at(a))}:{self.stop(b)}]"


def _message_constant(element: Element, data: str) -> str:
    return f"f\"{element.name} is {{{data}.hex(' ')}}, expected {element.constant.hex(' ')}\""


def decode_lines(
    layout: Layout,
    name: str,
    target: Target,
    checks: dict[int, str],
    transparency: str,
    header_known: bool = False,
    algorithms: dict[int, Checksum] | None = None,
) -> tuple[Lines, Lines]:
    """`def <name>(frame, expect)`: one layout's frame checked in the engine's order, its content decoded; and
    the function's body alone (for decode(), which runs it inline: one call less per frame).

    `checks`: element index -> the checksum function's name; `transparency`: the name of the layout's
    Transparency object (unstuffing, with its error for a frame that is not in stuffed form); `header_known`: the
    caller has matched the header (it chose the layout by it), so it is not compared again; `algorithms`: element
    index -> the checksum (its algorithm may test a whole frame by its byte sum).
    """
    positions = _Positions(layout)
    elements = layout.elements
    lines: Lines = [
        f"def {name}(frame: bytes, expect: type[Message] | None = None) -> Message:",
        f'    """One complete {layout.name} frame, checked and taken apart; its content decoded."""',
        "    n = len(frame)",
    ]
    body: Lines = []
    smallest = positions.before + positions.after
    if smallest:
        body += [
            f"if n < {smallest}:",
            f'    raise DecodeError(f"frame of {{n}} bytes is shorter than the smallest {layout.name} frame '
            f'({layout.overhead})")',
        ]
    t = _stuffing(layout)
    body.append(f"end = n - {positions.behind}" if positions.behind else "end = n")
    if t is not None:
        stop = f"n - {positions.after}" if positions.after else "n"
        found = " or ".join(f"frame.find({s!r}, {positions.before}, {stop}) >= 0" for s in _signs(t.replace))
        body += [
            "buf = frame",
            f"if {found}:  # stuffed: the plain bytes of the span",
            f"    buf = frame[:{positions.before}] + {transparency}.decode(frame[{positions.before} : {stop}])"
            + (f" + frame[{stop} :]" if positions.after else ""),
            f"    end = len(buf) - {positions.behind}" if positions.behind else "    end = len(buf)",
        ]
        fixed = _size(elements[positions.first : positions.last + 1])
        if fixed:
            inner = _plus("end", positions.behind - positions.after - positions.before)
            body += [
                f"if end < {positions.content}:",
                f'    raise DecodeError(f"{layout.name} frame: {{{inner}}} bytes where at least {fixed} belong")',
            ]
    body += _constant_checks(positions, 1 if header_known else 0)
    command = layout.command
    values: list[str] = []
    for index in layout.values:
        element = elements[index]
        value = f"v_{element.name}"
        values.append(value)
        body.append(f"{value} = {positions.read(index)}")
        full = element.minimum <= 0 and element.maximum >= (1 << (8 * element.size)) - 1
        if full:
            continue
        low, high, also = element.minimum, element.maximum, element.also
        shown = f" (or {also})" if also is not None else ""
        if also in (low - 1, high + 1):  # next to the range: one bound of it
            low, high, also = min(low, also), max(high, also), None
        if also is None and low <= 0:  # no value of the element is below it
            refused = f"{value} > {high}"
        elif also is None:
            refused = f"not {low} <= {value} <= {high}"
        else:
            refused = f"not ({low} <= {value} <= {high} or {value} == {also})"
        low, high = element.minimum, element.maximum  # as the engine words it
        body += [
            f"if {refused}:",
            f'    raise DecodeError(f"{element.name} = {{{value}}} is outside its range {low}..{high}{shown}")',
        ]
    for index, element in enumerate(elements):
        if element.kind != "length":
            continue
        counted = positions.counted(*element.span, element.adds)
        body += [
            f"length = {positions.read(index)}",
            f"if length != {counted}:",
            f'    raise DecodeError(f"{element.name} says {{length}} but the frame holds {{{counted}}}")',
        ]
    for index, element in enumerate(elements):
        if element.kind != "checksum":
            continue
        width = 2 + 2 * element.size
        failed = [
            f"check = {checks[index].format(positions.covered(*element.span))}",
            f"stored = {positions.read(index)}",
            "if check != stored:",
            f'    raise ChecksumError(f"bad {element.name}: the frame has {{stored:#0{width}x}}, '
            f'its bytes give {{check:#0{width}x}}")',
        ]
        residue = _residue(element)
        a, b = element.span
        test = frame_sum_test(layout, index, (algorithms or {}).get(index))
        if test is not None:  # the sum of the whole frame, no slice made; the rest only says what is wrong
            body += [f"if {test}:", *(f"    {line}" for line in [*failed[:2], failed[3].strip()])]
        elif residue is not None and b == index - 1 and a <= positions.first:
            # over the covered bytes and the checksum itself, an intact frame's CRC is one constant: no slice, no
            # stored value to read; they are made only to say what is wrong
            whole = positions.covered(a, index)
            body += [f"if {checks[index].format(whole)} != {residue:#0{width}x}:", *(f"    {line}" for line in failed)]
        else:
            body += failed
    if command is not None:
        body.append(f"code = {positions.read(command)}")
    code = "None" if command is None else "code"
    body += _dispatch(target, code, ", ".join([positions.buf, str(positions.content), "end", *values]), nullable=False)
    return lines + [f"    {line}" for line in body], ["n = len(frame)", *body]


def frame_sum_test(layout: Layout, index: int, checksum: Checksum | None, frame: str = "frame") -> str | None:
    """A test, true for a bad frame, of a one-byte checksum (element `index`) as one expression over the sum of the
    whole unstuffed frame `frame`, where its algorithm has one (checksums/: frame_test) and it is the frame's last
    byte and covers all before it but constants (checked before it). None for others."""
    elements = layout.elements
    a, b = elements[index].span
    if checksum is None or layout.transparency is not None or elements[index].size != 1 or elements[index].skip:
        return None
    if index != len(elements) - 1 or b != index - 1 or any(e.kind != "constant" for e in elements[:a]):
        return None
    return checksum.algorithm.frame_test(f"sum({frame})", sum(sum(e.constant) for e in elements[:a]), f"{frame}[-1]")


def _residue(element: Element) -> int | None:
    """The checksum over any bytes followed by their own checksum (as the element stores it), where that is one
    constant: a CRC stored in its own bit order (reflected: low byte first; else high byte first). None for the
    others (sums, a CRC stored the other way round, an XOR of words stored the other way round). Found by computing
    it, not by its parameters: over data of even and odd sizes, so that a checksum whose bytes land on other word
    boundaries than the data's shows that it has none."""
    function = element.checksum
    assert function is not None
    samples = (b"", b"\x00", b"\x01\x02", b"123456789", b"\xff" * 7, bytes(range(1, 18)))
    found = {function(data + element.pack(function(data))) for data in samples}
    if len(found) != 1:
        return None
    residue = found.pop()
    # and only the right checksum gives it: a masked one (HerkuleX `& 0xFE`) gives it for a wrong bit 0 as well
    for data in samples:
        check = function(data)
        for bit in range(8 * element.size):
            if function(data + element.pack(check ^ 1 << bit)) == residue:
                return None
    return residue


def _dispatch(target: Target, code: str, arguments: str, nullable: bool) -> Lines:
    """Lines that decode the content with the decoder of `code` (an expression; "None" where frames carry none):
    an error reply's where the error flag is set, the expected reply's where replies share a code."""
    table = f"_{target.upper}_DECODERS"
    if code == "None" and target.only and not target.expected:
        return [f"return {target.only}({arguments})"]
    lines: Lines = []
    if target.error_flag and code != "None":
        known = f"{code} is not None and " if nullable else ""
        lines += [
            f"if {known}{code} & {target.error_flag:#04x}:  # an error reply: it refuses the request of code & ~flag",
            f"    return {table}[ERROR_REPLY]({arguments}, {code} & {target.error_keep:#04x})",
        ]
    unknown = f'f"unknown command {{{code}:#04x}}"' if code != "None" else '"unknown command None"'
    lines += [
        "try:",
        f"    decoder = {table}[{code}]",
        "except KeyError:",
        f"    raise DecodeError({unknown}) from None",
    ]
    if target.expected:  # (its codes are among the decoders')
        lines += [
            "if expect is not None:",
            f"    expected, alternative = _{target.upper}_EXPECTED.get(expect, (None, None))",
            f"    if alternative is not None and expected {'is' if code == 'None' else '=='} {code}:",
            "        decoder = alternative",
        ]
    return [*lines, f"return decoder({arguments})"]


def _signs(replace: tuple[tuple[bytes, bytes], ...]) -> list[bytes]:
    """The sequences whose absence shows a span is not stuffed (its plain and wire bytes are the same): every
    plain and wire sequence, less those that hold another one (found whenever it is)."""
    every = sorted({s for pair in replace for s in pair}, key=len)
    return [s for i, s in enumerate(every) if not any(o in s for o in every[:i])]


def _constant_checks(positions: _Positions, start: int = 0) -> Lines:
    """Constant elements from `start` on (1: the header is known to match) checked in element order; neighbours
    compared at once, one by one only to say which."""
    layout, buf = positions.layout, positions.buf
    runs: list[list[int]] = []
    for index, element in enumerate(layout.elements):
        if element.kind != "constant" or index < start:
            continue
        if runs and runs[-1][-1] == index - 1:
            runs[-1].append(index)
        else:
            runs.append([index])
    lines: Lines = []
    for run in runs:
        each = [(index, layout.elements[index]) for index in run]
        single: list[tuple[str, str, str]] = []  # condition, message per element
        for index, element in each:
            if element.size == 1:
                condition = f"{buf}[{positions.at(index)}] != {element.constant[0]:#04x}"
                data = f"{buf}[{positions.at(index)}:{positions.stop(index)}]"
            else:
                data = f"{buf}[{_start(positions.at(index))}:{positions.stop(index)}]"
                condition = f"{data} != {element.constant!r}"
            single.append((condition, _message_constant(element, data), element.name))
        if len(each) == 1:
            condition, message, _ = single[0]
            lines += [f"if {condition}:", f"    raise DecodeError({message})"]
            continue
        whole = b"".join(element.constant for _, element in each)
        lines.append(f"if {buf}[{_start(positions.at(run[0]))}:{positions.stop(run[-1])}] != {whole!r}:")
        for condition, message, _ in single[:-1]:
            lines += [f"    if {condition}:", f"        raise DecodeError({message})"]
        lines.append(f"    raise DecodeError({single[-1][1]})")
    return lines


def _start(position: str) -> str:
    return "" if position == "0" else position


@dataclass
class _LayoutEncoding:
    """One layout's encoding, in three parts: `prelude` computes the stuffed span and the lengths, `fits` says
    whether every length fits its element (with the EncodeError a layout raises when one does not), `rest` makes
    and returns the frame."""

    prelude: Lines
    fits: list[tuple[str, str]]  # condition that the length fits, the error when it does not
    rest: Lines


def _packed(elements: tuple[Element, ...], indices: list[int], argument: Callable[[int], str], struct: Structs) -> str:
    """One expression for the bytes of these elements: a Literal, else one struct's Pack (neighbouring constants
    as one `Ns` argument); `argument`: the expression of each non-constant element's value."""
    if not indices:
        return ""
    if all(elements[i].kind == "constant" for i in indices):
        return Literal(b"".join(elements[i].constant for i in indices))
    fmt, arguments = _order(elements, indices), []
    constant = b""
    for i in [*indices, -1]:
        if i >= 0 and elements[i].kind == "constant":
            constant += elements[i].constant
            continue
        if constant:
            fmt += f"{len(constant)}s"
            arguments.append(repr(constant))
            constant = b""
        if i >= 0:
            fmt += _STRUCT_CHARS[elements[i].size]
            arguments.append(argument(i))
    return Pack(struct(fmt), arguments)


def _order(elements: tuple[Element, ...], indices: list[int]) -> str:
    """The struct byte order of these elements' values (straight() allows one for the multi-byte ones)."""
    multi = {elements[i].endian for i in indices if elements[i].kind != "constant" and elements[i].size > 1}
    return ">" if multi == {"big"} else "<"


def _arguments(layout: Layout, code: str, values: list[str]) -> Callable[[int], str]:
    """The expression of each element's value: the command's code, the frame values in element order, lengths in
    `v_<name>` (computed by the wrap's prelude)."""
    value_of = dict(zip(layout.values, values, strict=True))

    def argument(index: int) -> str:
        element = layout.elements[index]
        if element.kind == "command":
            return code
        if element.kind == "length":
            return Simple(f"v_{element.name}")
        return value_of[index]

    return argument


def wrap_parts(
    layout: Layout, target: Target, checks: dict[int, str], transparency: str, struct: Structs
) -> _LayoutEncoding:
    """The frame around `content`, as Layout.wrap makes it. `checks` and `transparency` as for decode_lines;
    `struct` names the struct constants it uses."""
    positions = _Positions(layout)
    elements = layout.elements
    prelude: Lines = []
    argument = _arguments(layout, "code", [f"v_{v}" for v in target.value_names])

    def packed(indices: list[int]) -> str:
        return _packed(elements, indices, argument, struct)

    first, last = positions.first, positions.last
    c = layout.content
    around = (packed(list(range(first, c))), "content", packed(list(range(c + 1, last + 1))))
    variable = " + ".join(p for p in around if p)
    t = _stuffing(layout)
    if t is None:
        wire = variable
    else:
        prelude.append(f"plain = {variable}")
        if len(t.replace) == 1:
            plain, stuffed = t.replace[0]
            prelude.append(f"wire = plain.replace({plain!r}, {stuffed!r})")
        else:
            prelude.append(f"wire = {transparency}.encode(plain)")
        wire = "wire"
    fits: list[tuple[str, str]] = []
    for element in elements:
        if element.kind != "length":
            continue
        a, b = element.span
        if a <= first and last <= b:  # the wire bytes of the variable part and the fixed ones around it
            fixed = _size(elements[a : b + 1]) - _size(elements[first : last + 1])
            value = _plus(f"len({'content' if t is None else 'wire'})", fixed + element.adds)
        elif a <= c <= b:  # inside the stuffed span: plain bytes
            value = _plus("len(content)", _size(elements[a : b + 1]) + element.adds)
        else:
            value = str(_size(elements[a : b + 1]) + element.adds)
        name = f"v_{element.name}"
        limit = 1 << (8 * element.size)
        prelude.append(f"{name} = {value}")
        fits.append(
            (
                f"0 <= {name} < {limit}" if element.adds < 0 else f"{name} < {limit}",
                f'raise EncodeError(f"{layout.name} frame: length {{{name}}} does not fit its '
                f'{element.size}-byte field")',
            )
        )
    frame = " + ".join(p for p in (packed(list(range(first))), wire) if p)
    rest = _closing_lines(layout, frame, checks, packed)
    return _LayoutEncoding(prelude, fits, rest)


def _closing_lines(layout: Layout, frame: str, checks: dict[int, str], packed: Callable[[list[int]], str]) -> Lines:
    """Lines that return the frame `frame` (an expression: everything up to the variable part's end) with the
    elements after it: constants and values packed, each checksum computed over what is written before it."""
    elements = layout.elements
    last = _variable(layout)[1]
    lines: Lines = []
    pending: list[int] = []  # elements after the variable part not yet in `frame`
    for index in range(last + 1, len(elements)):
        element = elements[index]
        if element.kind != "checksum":
            pending.append(index)
            continue
        if pending:
            frame = f"{frame} + {packed(pending)}"
            pending = []
        a, b = element.span
        begin = _size(elements[:a])
        between = _size(elements[b + 1 : index])
        # all after the variable part: counted back from the end of what is written
        begin_expr = str(-_size(elements[a:index])) if a > last else str(begin) if begin else ""
        covered = f"frame[{begin_expr}:{-between if between else ''}]".replace("[:]", "")
        lines.append(f"frame = {frame}")
        frame = f"frame + {checks[index].format(covered)}.to_bytes({element.size}, {element.endian!r})"
    if pending:
        frame = f"{frame} + {packed(pending)}"
    return [*lines, f"return {frame}"]


def wrap_lines(direction: str, layouts: list[_LayoutEncoding], target: Target) -> Lines:
    """`def _wrap_<direction>(content, code, *values) -> bytes`: the frame in the first layout whose lengths can
    count it (as FrameCodec.wrap chooses), each layout's code inline."""
    parameters = ", ".join(["content: bytes", "code: int | None", *(f"v_{v}: int" for v in target.value_names)])
    doc = "in the first layout whose length can count it" if len(layouts) > 1 else "EncodeError if it cannot be"
    body: Lines = []
    for number, wrap in enumerate(layouts):
        body += wrap.prelude
        if number < len(layouts) - 1 and wrap.fits:  # an earlier layout: taken when its lengths fit
            body.append(f"if {' and '.join(condition for condition, _ in wrap.fits)}:")
            body += [f"    {line}" for line in wrap.rest]
            continue
        for condition, error in wrap.fits:
            body += [f"if not {condition}:", f"    {error}"]
        body += wrap.rest
        break
    return [
        f"def _wrap_{direction}({parameters}) -> bytes:",
        f'    """The {direction} frame around `content`, {doc}."""',
        *(f"    {line}" for line in body),
    ]


_STRUCT_CHARS = {1: "B", 2: "H", 4: "I", 8: "Q"}


def _struct_name(fmt: str) -> str:
    """A struct constant's name from its format, prefixed to stay clear of the content's `_S_` constants."""
    tokens = ["BE" if fmt[0] == ">" else "LE"]
    for count, char in struct_tokens(fmt):
        tokens.append(f"{count}S" if char == "s" else {"B": "U8", "H": "U16", "I": "U32", "Q": "U64"}[char])
    return "_F_" + "_".join(tokens)


def struct_tokens(fmt: str) -> list[tuple[str, str]]:
    """A struct format's (count, code) pairs in order, its byte order left out: "<2sBH" -> ("2", "s"), ("", "B"), ..."""
    found: list[tuple[str, str]] = []
    count = ""
    for char in fmt.lstrip("<>=!@"):
        if char.isdigit():
            count += char
        else:
            found.append((count, char))
            count = ""
    return found


def engine_lines(layouts: tuple[Layout, ...], target: Target) -> tuple[Lines, Lines]:
    """The two functions of a direction whose layouts keep the interpreted engine (FrameCodec)."""
    direction = target.upper.lower()
    frames = f"_{target.upper}_FRAMES"
    values = [f"v_{v}" for v in target.value_names]
    shown = f"({values[0]},)" if len(values) == 1 else f"({', '.join(values)})"
    parameters = ", ".join(["content: bytes", "code: int | None", *(f"{v}: int" for v in values)])
    optional = "".join(f", {name}: bytes | None = None" for name in target.optional)
    extras = ", {" + ", ".join(f"{name!r}: {name}" for name in target.optional) + "}" if target.optional else ""
    if target.requesting:  # the layout by the message's command, the request's bytes for a checksum over them
        wrap = [
            f"def _wrap_{direction}({parameters}, layout: int | None = None, request: Message | None = None"
            f"{optional}) -> bytes:",
            f'    """The {direction} frame around `content` in its layout, made by the frame engine."""',
            f"    return {frames}.wrap(content, code, {shown}, layout, _request_parts(request){extras})",
        ]
        decode = [
            f"def _decode_{direction}(frame: bytes, expect: type[Message] | None = None, "
            "request: Message | None = None) -> Message:",
            f'    """One complete {direction} frame, checked and taken apart by the frame engine (with the request it',
            '    answers, where its layout or checksum needs it); its content decoded."""',
            *(
                ["    if expect is None and request is not None:", "        expect = _REPLY_TO.get(type(request))"]
                if direction == "response"
                else []
            ),
            f"    unwrapped = {frames}.unwrap(frame, expect, _request_parts(request))",
            "    code, content = unwrapped.code, unwrapped.content",
        ]
        return _engine_decode(decode, target), wrap
    wrap = [
        f"def _wrap_{direction}({parameters}{optional}) -> bytes:",
        f'    """The {direction} frame around `content`, made by the frame engine."""',
        f"    return {frames}.wrap(content, code, {shown}{', None, None' + extras if extras else ''})",
    ]
    decode = [
        f"def _decode_{direction}(frame: bytes, expect: type[Message] | None = None) -> Message:",
        f'    """One complete {direction} frame, checked and taken apart by the frame engine; its content decoded."""',
        f"    unwrapped = {frames}.unwrap(frame)",
        "    code, content = unwrapped.code, unwrapped.content",
    ]
    return _engine_decode(decode, target), wrap


def _engine_decode(decode: Lines, target: Target) -> Lines:
    """The engine's decode function, its content dispatched by code (and by the expected class)."""
    arguments = "content, 0, len(content), *unwrapped.values"
    arguments += "".join(f", unwrapped.extras.get({name!r})" for name in target.optional)
    return [*decode, *(f"    {line}" for line in _dispatch(target, "code", arguments, nullable=True))]


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
    layouts = tuple(layout.variants[-1] for layout in full)  # with optional elements: the variant without them
    diverts = tuple(
        (offset, size, endian, mask) for layout in layouts for offset, size, endian, mask, _ in layout.conditions
    )
    names = {tuple(e.name for e in (layout.elements[i] for i in layout.values)) for layout in layouts}
    if not all(straight(layout) for layout in layouts) or len(names) != 1:
        return None
    if protocol.framing.by_command or protocol.framing.from_request:
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


def direction_functions(
    protocol: Protocol,
    direction: Direction,
    target: Target,
    structs: dict[str, str],
    plain: list[tuple[int, int, str, str, str]],
) -> tuple[Lines, Lines]:
    """Module-level code of one direction's frame functions (`_decode_<d>`, `_wrap_<d>` and what they use), and
    the lines of `decode()` that decode a frame `data` of this direction (`plain`: see whole_frames)."""
    found = straight_direction(protocol, direction)
    d = direction.value
    if found is None:
        decode, wrap = engine_lines(runtime_layouts(protocol, direction), target)
        request = ", request" if target.requesting else ""
        return [*decode, "", "", *wrap], [f"return _decode_{d}(bytes(data), expect{request})"]
    layouts = found.layouts
    several = len(layouts) > 1
    lines: Lines = []
    divert: Lines = []
    if found.diverts:  # a frame with an optional element's flag bit set: the engine's (its functions, renamed)
        decode, wrap = engine_lines(runtime_layouts(protocol, direction), target)
        decode[0] = decode[0].replace(f"def _decode_{d}(", f"def _decode_{d}_engine(", 1)
        wrap[0] = wrap[0].replace(f"def _wrap_{d}(", f"def _wrap_{d}_engine(", 1)
        lines += [*decode, "", "", *wrap, "", ""]
        tests = [
            f"frame[{offset}] & {mask:#04x}"
            if size == 1
            else f"int.from_bytes(frame[{offset} : {offset + size}], {endian!r}) & {mask:#x}"
            for offset, size, endian, mask in found.diverts
        ]
        shortest = max(offset + size for offset, size, _, _ in found.diverts)
        divert = [
            f"if len(frame) >= {shortest} and ({' or '.join(tests)}):  # optional elements sent: the frame engine's",
            f"    return _decode_{d}_engine(frame, expect)",
        ]
    wraps: list[_LayoutEncoding] = []
    bodies: list[Lines] = []
    for layout, checks, algorithms in zip(layouts, found.checks, found.algorithms, strict=True):
        suffix = f"_{layout.name}" if several else ""
        stuffing = f"_{target.upper}{suffix.upper()}_TRANSPARENCY"
        t = _stuffing(layout)
        if t is not None:
            pairs = ", ".join(f"({plain!r}, {wire!r})" for plain, wire in t.replace)
            lines += [f"{stuffing} = Transparency({t.span}, ({pairs},))", "", ""]
        # of several layouts, each is decoded once its header has chosen it (_choice)
        function, body = decode_lines(layout, f"_decode_{d}{suffix}", target, checks, stuffing, several, algorithms)
        function = [*function[:2], *(f"    {line}" for line in divert), *function[2:]]
        lines += [*function, "", ""]
        bodies.append(body)
        wraps.append(wrap_parts(layout, target, checks, stuffing, registry(structs)))
    if several:
        choice = _choice(layouts, d)
        lines += [
            f"def _decode_{d}(frame: bytes, expect: type[Message] | None = None) -> Message:",
            f'    """One complete {d} frame, in the layout its header names."""',
            *(f"    {line}" for line in choice),
            "",
            "",
        ]
    # decode() chooses the layout and checks the frame itself: one call less
    table, fast = whole_frames(found, d, plain, structs)
    call = ["frame = data if data.__class__ is bytes else bytes(data)", *divert, *fast, *_choice(layouts, d, bodies)]
    lines += [*table, "", ""] if table else []
    lines += wrap_lines(d, wraps, target)
    return lines, call


def frame_encoder(
    frames: StraightLayouts,
    parts: list[str],
    formats: dict[str, str],
    code: str,
    values: list[str],
    size: int | None,
    struct: Structs,
) -> Block | None:
    """An encoder's last lines, which return its message's frame made inline (no call of `_wrap_<direction>`):
    the head packed with the content's first struct in one call where their byte orders agree.

    `parts`: the content's byte expressions (`formats`: struct constant -> format, for those that are one
    struct's Pack); `code`, `values`: the command code's and the frame values' expressions; `size`: the
    content's size when it has one. None (the wrap function does it) for stuffed frames, and for lengths that
    depend on a size known only at run time."""
    chosen = None
    for layout, checks in zip(frames.layouts, frames.checks, strict=True):
        if layout.transparency is not None:
            return None
        lengths = {}
        for index, element in enumerate(layout.elements):
            if element.kind != "length":
                continue
            a, b = element.span
            lengths[index] = _size(layout.elements[a : b + 1]) + element.adds
            if a <= layout.content <= b:  # it counts the content: known here only for a content of one size
                if size is None:
                    return None
                lengths[index] += size
        if all(0 <= value < 1 << (8 * layout.elements[i].size) for i, value in lengths.items()):
            chosen = (layout, checks, lengths)
            break
    if chosen is None:
        return None  # no layout can count it: the wrap function says so
    layout, checks, lengths = chosen
    lines = _frame_lines(layout, checks, lengths, parts, formats, code, values, struct)
    # the frame is made in the first statement: the one that packs the content's lists
    return [Code(lines[0], lists=packed_lists(parts)), *(Code(line) for line in lines[1:])]


def _frame_lines(
    layout: Layout,
    checks: dict[int, str],
    lengths: dict[int, int],
    parts: list[str],
    formats: dict[str, str],
    code: str,
    values: list[str],
    struct: Structs,
) -> Lines:
    """frame_encoder's lines, in the layout chosen, whose `lengths` are known (element index -> value)."""
    elements = layout.elements
    argument = _arguments(layout, code, values)

    def constant_or(index: int) -> str:
        return Simple(lengths[index]) if index in lengths else argument(index)

    head = list(range(layout.content))
    prefix = _fixed_prefix(layout, lengths)
    if prefix is not None:  # the checksum covers all after constant bytes: they are a literal, not packed
        head = head[len(prefix[1]) :]
    first = parts[0] if parts and isinstance(parts[0], Pack) else None
    fmt = formats.get(first.struct, "") if first else ""
    order = _order(elements, head)
    packed = None  # (format, arguments) where the frame up to the checksum is one pack of them
    multi = any(elements[i].kind != "constant" and elements[i].size > 1 for i in head)
    if head and first and fmt[:1] in "<>" and (fmt[0] == order or not multi):
        # the head's elements joined to the content's first struct: one pack for both
        fused = _packed(elements, head, constant_or, lambda f: f)  # named by its format
        if isinstance(fused, Pack):
            static, arguments = fmt[0] + fused.struct[1:] + fmt[1:], [*fused.arguments, *first.arguments]
            run = parts[1] if len(parts) > 1 and isinstance(parts[1], PackItems) else None
            if run and run.order == static[0]:  # and a run of numbers after it, in the same byte order
                fstring = repr(static + run.counted_format).replace("'", "f'", 1)
                parts = [f"struct.pack({fstring}, {', '.join(arguments)}, *{run.items})", *parts[2:]]
            else:
                parts = [Pack(struct(static), arguments), *parts[1:]]
                packed = (static, arguments) if len(parts) == 1 else None
        else:  # constants only: a literal
            parts = [f"{fused} + {parts[0]}", *parts[1:]]
    else:
        parts = [p for p in (_packed(elements, head, constant_or, struct), *parts) if p]
    frame = " + ".join(parts) if parts else "b''"
    if prefix is not None:
        # the checksum over what was packed, the constants before it added as they are (no slice to make)
        literal, _, index = prefix
        element = elements[index]
        check = checks[index].format("body")
        after = _packed(elements, list(range(index + 1, len(elements))), constant_or, struct)
        # one join: cheaper than three or four concatenations, each of which makes a bytes object
        pieces = [repr(literal), "body", f"{check}.to_bytes({element.size}, {element.endian!r})"]
        pieces += [after] if after else []
        whole = _repacked(packed, literal, element, check, after)
        if whole is not None:
            # the checksum needs the packed bytes; the frame is then one more pack of the same values, cheaper
            # than joining the pieces
            return [f"body = {frame}", f"return {struct(whole[0])}.pack({whole[1]})"]
        return [f"body = {frame}", f"return b''.join(({', '.join(pieces)}))"]
    return _closing_lines(layout, frame, checks, lambda indices: _packed(elements, indices, constant_or, struct))


_CHECK_CODES = {1: "B", 2: "H", 4: "I"}
_MOST_REPACKED = 4  # values packed a second time into the whole frame; more are joined


def _repacked(
    packed: tuple[str, list[str]] | None, literal: bytes, element: Element, check: str, after: str
) -> tuple[str, str] | None:
    """A struct format and its arguments for a whole frame that is `literal`, then one pack of simple values (the
    bytes the checksum covers; names, attributes, numbers: cheap to give twice), then the checksum and constant
    bytes (`after`, a literal); None for others."""
    if packed is None or not all(isinstance(a, Simple) for a in packed[1]) or element.size not in _CHECK_CODES:
        return None
    if len(packed[1]) > _MOST_REPACKED:
        return None  # each value packed twice: for many, the join is cheaper
    fmt, arguments = packed
    if element.size > 1 and {"big": ">", "little": "<"}.get(element.endian or "") != fmt[0]:
        return None
    tail: bytes = b""
    if after:
        if not isinstance(after, Literal):
            return None
        tail = after.data
    whole = fmt[0] + (f"{len(literal)}s" if literal else "") + fmt[1:] + _CHECK_CODES[element.size]
    values = [repr(literal)] if literal else []
    values += [*arguments, check]
    if after and tail:
        whole += f"{len(tail)}s"
        values.append(after)
    return whole, ", ".join(values)


def _fixed_prefix(layout: Layout, lengths: dict[int, int]) -> tuple[bytes, list[int], int] | None:
    """Where a layout's one checksum covers all from some element to the content's end and only constants and
    lengths known before encoding (`lengths`: index -> value) come before it: their bytes, their indices and the
    checksum's index. None for other layouts."""
    elements = layout.elements
    found = [i for i, e in enumerate(elements) if e.kind == "checksum"]
    if len(found) != 1 or layout.transparency is not None:
        return None
    index = found[0]
    a, b = elements[index].span
    if not (0 < a <= layout.content == b == index - 1):
        return None
    literal = b""
    for i in range(a):
        element = elements[i]
        if element.kind == "constant":
            literal += element.constant
        elif i in lengths:
            literal += element.pack(lengths[i])
        else:
            return None
    return literal, list(range(a)), index


def _choice(layouts: tuple[Layout, ...], d: str, bodies: list[Lines] | None = None) -> Lines:
    """Lines that decode `frame` in the layout its header names (as FrameCodec.layout_of chooses): by a call of
    the layout's function, or by its `bodies` inline. One layout needs no choice."""
    if bodies is not None and len(layouts) == 1:
        return bodies[0]
    lines: Lines = []
    for number, layout in enumerate(layouts):
        lines.append(f"if frame.startswith({layout.header!r}):")
        if bodies is None:
            lines.append(f"    return _decode_{d}_{layout.name}(frame, expect)")
        else:
            lines += [f"    {line}" for line in bodies[number]]
    choices = " or ".join(layout.header.hex(" ") for layout in layouts)
    return [*lines, f"raise DecodeError(f\"frame starts {{frame[:4].hex(' ')}}, expected {choices}\")"]


def whole_frames(
    found: StraightLayouts, d: str, plain: list[tuple[int, int, str, str, str]], structs: dict[str, str]
) -> tuple[Lines, Lines]:
    """decode()'s fast path for frames of one size whose message is their content as one struct unpacks it: a table
    keyed by the bytes before the content (header, length, command code), and lines that check the rest of a frame
    `frame` (constants and checksums after the content, counted from its end) and build the message with no call
    but the unpack: a struct of the whole frame (the bytes around the content skipped as padding), whose unpack
    refuses a frame of another size. A frame that fails any check goes on to the general path, which says why.
    `plain`: (code, content size, class, the content struct's name stem (PackageCode.stems) and its format) of each
    such message; `structs` gets the whole
    frames' structs. ([], []) where the direction's first layout has values or is stuffed, or no message fits."""
    layout, checks = found.layouts[0], found.checks[0]
    elements = layout.elements
    if layout.transparency is not None or any(e.kind == "value" for e in elements):
        return [], []
    positions = _Positions(layout)
    entries: list[tuple[bytes, str, str]] = []
    for code, size, cls, content, fmt in plain:
        head = b""
        for element in elements[: layout.content]:
            if element.kind == "constant":
                head += element.constant
            elif element.kind == "command":
                head += element.pack(code)
            else:  # a length: the bytes it counts, given the content's size
                a, b = element.span
                counted = _size(elements[a : b + 1]) + element.adds + (size if a <= layout.content <= b else 0)
                if not 0 <= counted < 1 << (8 * element.size):
                    break
                head += element.pack(counted)
        else:
            name = f"_F_{d.upper()}_WHOLE_{content}"  # the content's struct in the frame
            structs[name] = f"{fmt[0]}{positions.content}x{fmt[1:]}{positions.behind}x"
            entries.append((head, cls, name))
    if not entries:
        return [], []

    tail = _Positions(layout, from_end=True)  # the elements after the content, counted back from the frame's end
    conditions: Lines = []
    for index, element in enumerate(elements[layout.content + 1 :], layout.content + 1):
        if element.kind == "constant" and element.size == 1:  # constants first: cheaper than a checksum
            conditions.insert(0, f"frame[{tail.at(index)}] == {element.constant[0]:#04x}")
        elif element.kind == "constant":
            stop = tail.stop(index)
            conditions.insert(0, f"frame[{tail.at(index)}:{'' if stop == '0' else stop}] == {element.constant!r}")
        elif element.kind == "checksum":
            residue = _residue(element)
            a, b = element.span
            if residue is not None and b == index - 1:
                call = checks[index].format(tail.covered(a, index))
                conditions.append(f"{call} == {residue:#0{2 + 2 * element.size}x}")
            else:
                call = checks[index].format(tail.covered(a, b))
                conditions.append(f"{call} == {tail.read(index)}")
    table = f"_{d.upper()}_WHOLE"
    definition = [
        f"# {d.capitalize()} frames of one size whose message is their content as one struct unpacks it, by their",
        "# first bytes (up to the content): class, unpack of the whole frame.",
        f"{table}: dict[bytes, tuple[type[Message], Callable[[bytes], tuple[object, ...]]]] = {{",
        *(f"    {key!r}: ({cls}, {name}.unpack)," for key, cls, name in entries),
        "}",
    ]
    lines = [
        f"whole = {table}.get(frame[:{positions.content}])",
        f"if {' and '.join(['whole is not None', *conditions])}:",
        "    try:",
        "        return _new(whole[0], whole[1](frame))",
        "    except struct.error:",
        "        pass  # a frame of another size: the general path says what is wrong",
    ]
    return definition, lines


def _plus(expression: str, k: int) -> str:
    return f"{expression} + {k}" if k > 0 else f"{expression} - {-k}" if k else expression


# --- the length-byte case ---------------------------------------------------------------------------------------


def length_byte_codec_context(protocol: Protocol, code: PackageCode) -> dict[str, Any]:
    """The codec template's part for frames of the length-byte shape: decode()'s tables of whole frames, the
    whole-frame decoders and the straight-line frame checks."""
    assert protocol.framing.checksum is not None
    checksum = protocol.framing.checksum
    assert checksum is not None  # length-byte frames have one
    checksum_imports, definitions = checksum_setup(checksum)
    directions = []
    dispatchers = []
    frame_functions: list[dict[str, Any]] = []
    whole_functions: list[dict[str, Any]] = []
    whole_pickers: list[dict[str, Any]] = []
    decoder_bodies = {name: (returns, extra, body) for name, returns, extra, body in code.decoders}
    size_dispatchers: list[dict[str, Any]] = []
    for direction, layout in protocol.framing.layouts.items():
        table = direction_dispatch(protocol, direction)
        dispatchers += table.dispatchers
        size_dispatchers += table.size_dispatchers
        dispatch, sizes = table.dispatch, table.sizes
        fixed = fixed_frames(protocol, layout, decoder_bodies, code)
        runs = [(key, function["run"]["name"]) for key, _, function in fixed if function.get("run")]
        sub_functions, pickers, sub_entries = subcommand_frames(protocol, layout, decoder_bodies, code)
        whole = length_byte_whole_frames(layout, [*fixed, *sub_entries])
        rests = rest_frames(protocol, layout, decoder_bodies, code) if whole or fixed else []
        stream_rests = rest_frames(protocol, layout, decoder_bodies, code, stream=True)
        whole_functions += stream_rests
        whole_functions += rests
        sub_rests = subcommand_rest_frames(protocol, layout, decoder_bodies) if whole else []
        whole_functions += sub_rests
        if whole:  # decode() looks frames up by their first bytes
            whole_functions += [f | {"whole_lines": fuse_unpack(f["whole_lines"])} for f in sub_functions]
            whole_pickers += pickers
        range_checks = value_range_checks(layout, protocol.byte_order)
        # decode() looks these frames up before any other check: where each decoder refuses a frame of another size
        # itself (struct.error from an unpack of the whole frame), decode() need not compare sizes first
        whole_size = max(layout.length_offset, layout.command_offset or 0) + 1
        content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
        exact = bool(whole) and not sub_entries and not rests and not sub_rests and not range_checks
        bodies = {f["whole_name"]: fuse_unpack(f["whole_lines"]) for _, _, f in fixed}
        if exact:
            bodies = {
                name: exact_whole(body, size, whole_size, code)
                for (_, size, f), (name, body) in zip(fixed, bodies.items(), strict=True)
            }
            whole = [
                (
                    key,
                    size,
                    name,
                    None if plain is None else (plain[0], exact_struct(plain[1], size, content_offset, code)),
                )
                for key, size, name, plain in whole
            ]
        frame_functions += [
            f | {"lines": fuse_unpack(f["lines"]), "whole_lines": bodies[f["whole_name"]], "exact": exact}
            for _, _, f in fixed
        ]
        slice_key = None if whole else key_slice(layout)
        # past the lookups, a frame is checked and dispatched as every framing's is (straight_frames.py)
        straight = straight_direction(protocol, direction)
        assert straight is not None and len(straight.layouts) == 1  # a length-byte layout is straight-line
        only = dispatch[0][1] if layout.command_offset is None and len(dispatch) == 1 else ""
        frames = Target(direction.name, tuple(e.name for e in layout.value_elements), only=only)
        engine, checks, algorithms = straight.layouts[0], straight.checks[0], straight.algorithms[0]
        _, general = decode_lines(engine, f"_decode_{direction.value}", frames, checks, "", algorithms=algorithms)
        directions.append(
            {
                "slice_key": slice_key,
                "slice_fixed": [(slice_bytes(layout, key), size, f["whole_name"]) for key, size, f in fixed],
                "slice_rests": [slice_rest(layout, r) for r in rests],
                "accepted": [inside for _, inside, _ in range_checks],
                "exact": exact,
                "fixed": [(key, size, function["name"]) for key, size, function in fixed],
                # before the frames of one size: where a length byte names both, those keep their decoder
                "stream_rests": [rest_key(layout, r, False) for r in stream_rests],
                "runs": runs,
                "summed": stream_sum(protocol, layout) if runs else None,
                "fixed_whole": [(key, size, function["whole_name"]) for key, size, function in fixed],
                "rest_keys": [rest_key(layout, r, bool(whole)) for r in rests],
                # before the frames of one size: where a length byte names both, those keep their decoder
                "sub_rest_keys": [rest_key(layout, r, True) for r in sub_rests],
                "whole_frames": whole,
                "unpacked": any(plain for *_, plain in whole),
                "whole_check": whole_frame_test(protocol, layout),
                "content_offset": content_offset,
                "whole_size": whole_size,
                "key": frame_key(layout, "data"),
                "name": direction.value,
                "upper": direction.name,
                "header": repr(layout.header),
                "header_hex": layout.header.hex(" "),
                "header_size": len(layout.header),
                "overhead": layout.overhead,
                "length_offset": layout.length_offset,
                "length_adds": layout.length_adds,
                "command_offset": layout.command_offset,
                "value_ranges": value_ranges(layout, protocol.byte_order),
                "range_checks": [
                    line for refused, _, error in range_checks for line in (f"if {refused}:", f"    raise {error}")
                ],
                "dispatch": dispatch,
                "sizes": sizes,
                "general": general,
                "at": frame_decode_lines(protocol, layout, dispatch),
            }
        )
        directions[-1]["call"] = [
            *lookup_lines(directions[-1]),
            "frame = data if data.__class__ is bytes else bytes(data)",
            *general,
        ]
        directions[-1]["headers"] = [repr(layout.header)]
    layouts = protocol.framing.layouts
    header_choices = " or ".join(layouts[d].header.hex(" ") for d in Direction)
    either = f"give the direction: requests and responses share the header {layouts[Direction.REQUEST].header.hex(' ')}"
    width = len(layouts[Direction.REQUEST].header)
    for function in frame_functions:
        function["lines"], function["whole_lines"] = lines_of(function["lines"]), lines_of(function["whole_lines"])
    for function in whole_functions:
        function["whole_lines"] = lines_of(function["whole_lines"])
    for picker in whole_pickers:
        picker["lines"] = lines_of(picker["lines"])
    imports = import_lines(checksum_imports)
    name = checksum_name(checksum)
    if name in checksum.algorithm.python_call(name):
        # the general path calls the checksum's function (as every framing's does): defined with what it needs
        imports, definitions = checksum_definitions(protocol)
    return {
        "length_byte_frames": True,
        "requesting": False,
        "reply_to": [],
        "checksum_imports": imports,
        "checksum_definitions": definitions,
        "directions": directions,
        "frame_functions": frame_functions,
        "runs": any(d["runs"] for d in directions),
        "whole_functions": whole_functions,
        "whole_pickers": whole_pickers,
        "dispatchers": dispatchers,
        "size_dispatchers": size_dispatchers,
        "header_choices": header_choices,
        "either": either if protocol.framing.shared_header else "",
        "no_header": f"f\"header is {{data[:{width}].hex(' ')}}, expected {header_choices}\"",
    }


def frame_key(layout: FrameLayout, buf: str, start: str = "") -> str:
    """The expression of a frame's size key (command code and length byte) as the stream parser's tables use it."""
    at = f"{start} + " if start else ""
    length = f"{buf}[{at}{layout.length_offset}]"
    if layout.command_offset is None:
        return length
    return f"{buf}[{at}{layout.command_offset}] << 8 | {length}"


def key_slice(layout: FrameLayout) -> str | None:
    """Where a frame's command code and length byte are neighbours after its header (FEETECH: an id between): the
    slice of `data` holding them, decode()'s key for its whole frames (a short frame's is shorter: it matches
    none, so the lookup comes before any check). None where they are not neighbours."""
    if layout.command_offset is None:
        return None
    low = min(layout.command_offset, layout.length_offset)
    if max(layout.command_offset, layout.length_offset) != low + 1 or low < len(layout.header):
        return None
    return f"data[{low}:{low + 2}]"


def slice_bytes(layout: FrameLayout, key: str) -> str:
    """A size key (command code << 8 | length byte, as fixed_frames makes it) as the bytes key_slice reads."""
    value = int(key, 16)
    assert layout.command_offset is not None  # key_slice holds it
    by_offset = {layout.command_offset: value >> 8, layout.length_offset: value & 0xFF}
    return repr(bytes(by_offset[o] for o in sorted(by_offset)))


def slice_rest(layout: FrameLayout, rest: dict[str, Any]) -> dict[str, Any]:
    """rest_key's entries as the bytes key_slice reads: the key's expression in the length byte `n`."""
    assert layout.command_offset is not None  # key_slice holds it
    by_offset = {layout.command_offset: f"{rest['code'] or 0:#04x}", layout.length_offset: "n"}
    key = f"bytes(({', '.join(by_offset[o] for o in sorted(by_offset))}))"
    low, high = rest["lengths"]
    return {"key": key, "low": low, "high": high, "adds": rest["adds"], "name": rest["whole_name"]}


def rest_key(layout: FrameLayout, rest: dict[str, Any], by_bytes: bool) -> dict[str, Any]:
    """decode()'s table entries of a frame that takes the rest (rest_frames), one per length byte `n`: the key's
    expression in `n` (first bytes as whole_frames makes them, or the size key as frame_key), the range of `n`,
    and the frame size less `n`."""
    code = rest["code"] or 0
    if by_bytes:  # header, then command code and length byte in offset order
        key = " + ".join(
            [
                repr(layout.header),
                *(
                    "bytes((n,))" if o == layout.length_offset else repr(bytes([code]))
                    for o in sorted(o for o in (layout.command_offset, layout.length_offset) if o is not None)
                ),
            ]
        )
    else:
        key = f"{code:#04x} << 8 | n" if layout.command_offset is not None else "n"
    low, high = rest["lengths"]
    return {"key": key, "low": low, "high": high, "adds": rest["adds"], "name": rest["whole_name"]}


def length_byte_whole_frames(
    layout: FrameLayout, fixed: list[tuple[str, int, dict[str, Any]]]
) -> list[tuple[str, int, str, tuple[str, str] | None]]:
    """decode()'s table of the frames decoded whole, keyed by their first bytes when those are the header, command
    code and length byte (one slice, one lookup, and the header is checked with them); [] where they are not."""
    width = len(layout.header)
    offsets = sorted(o for o in (layout.command_offset, layout.length_offset) if o is not None)
    if offsets != list(range(width, width + len(offsets))):
        return []
    entries = []
    for key, size, function in fixed:
        value = int(key, 16)
        bytes_at = {layout.length_offset: value & 0xFF}
        if layout.command_offset is not None:
            bytes_at[layout.command_offset] = value >> 8
        key_bytes = repr(layout.header + bytes(bytes_at[o] for o in offsets))
        entries.append((key_bytes, size, function["whole_name"], function.get("plain")))
    return entries


def fixed_frames(
    protocol: Protocol, layout: FrameLayout, bodies: dict[str, tuple[str, str, Block]], code: PackageCode
) -> list[tuple[str, int, dict[str, Any]]]:
    """Whole-frame decoders for the frames of one size whose content is one run of fixed fields: (size key, frame
    size, function). Each checks the checksum, unpacks the content in one call and builds the message: no
    dispatch, no size checks (the key is the command code and length byte, so the size is known), one call per
    frame. It returns None for a frame whose checksum fails, so callers word the error (decode) or count it (the
    stream parser); it raises nothing. Frames of any other kind keep the general path."""
    found = []
    for command in protocol.commands:
        message = command.request if layout.direction == Direction.REQUEST else command.response
        if command.selector is not None or message is None:
            continue
        made = frame_function(protocol, layout, command, message, bodies, code)
        if made is not None:
            key, size, function = made
            found.append((f"{key:#06x}", size, function))
    return found


def subcommand_frames(
    protocol: Protocol, layout: FrameLayout, bodies: dict[str, tuple[str, str, Block]], code: PackageCode
) -> tuple[list[dict[str, Any]], list[dict[str, Any]], list[tuple[str, int, dict[str, Any]]]]:
    """decode()'s whole-frame decoders of sub-command frames of one size (as fixed_frames, the sub-command's check
    dropped: its code picks the decoder) and, per command and frame size, the function that picks one by the
    sub-command byte: (decoders, pickers, decode's table entries of the pickers, as fixed_frames gives them)."""
    content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    functions: list[dict[str, Any]] = []
    pickers: list[dict[str, Any]] = []
    entries = []
    for command in protocol.commands:
        if command.selector is None or layout.direction not in command.selector.offsets:
            continue
        by_size: dict[tuple[int, int], list[tuple[int, dict[str, Any]]]] = {}
        for sub in command.subcommands:
            message = sub.request if layout.direction == Direction.REQUEST else sub.response
            if message is None:
                continue
            made = frame_function(protocol, layout, command, message, bodies, code, command.selector.name)
            if made is not None:
                key, size, function = made
                by_size.setdefault((key, size), []).append((sub.code, function))
        at = content_offset + command.selector.offsets[layout.direction]
        for (key, size), subs in by_size.items():
            picker = {
                "whole_name": f"_whole_{command.name}_{layout.direction.value}_{size}",
                "table": f"_{command.name.upper()}_{layout.direction.name}_WHOLE_{size}",
                "size": size,
                "where": f"{command.name} {layout.direction.value}",
                "entries": [(f"{c:#04x}", f["whole_name"]) for c, f in subs],
            }
            lines = picked_inline(subs, at)
            if lines is None:  # each sub-command's own decoder, from a table
                functions += [f for _, f in subs]
                lines = [
                    Code(f"whole = {picker['table']}.get(buf[{at}])"),
                    Code("return None if whole is None else whole(buf)"),
                ]
            else:
                picker["entries"] = []
            pickers.append(picker | {"lines": lines})
            entries.append((f"{key:#06x}", size, picker))
    return functions, pickers, entries


def rest_frames(
    protocol: Protocol,
    layout: FrameLayout,
    bodies: dict[str, tuple[str, str, Block]],
    code: PackageCode,
    stream: bool = False,
) -> list[dict[str, Any]]:
    """decode()'s whole-frame decoders of the frames whose content is fixed fields then bytes to its end (FEETECH
    WRITE: an address, then the data): any length byte from the smallest such content up names one, so decode()'s
    table holds a key per length byte. Each checks the checksum, reads the fields at constant offsets and the bytes
    up to the frame's tail: no dispatch, no content decoder's call. Others keep the general path.

    `stream`: the same decoders for the stream parser's table of frames decoded whole (FrameFormat.fixed), of the
    frame at buf[start:] (its end from its length byte), also for contents of any size (FEETECH's reply: an
    error byte in the frame, then the data), which have no size check to drop: one call per frame."""
    checksum = protocol.framing.checksum
    length = layout.length
    if checksum is None or length is None or length.type is None:
        return []
    content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    tail = layout.overhead - content_offset  # bytes after the content
    found = []
    shared = shared_codes(protocol, layout.direction)
    for command in protocol.commands:
        if command.wire_code(layout.direction) in shared:
            continue  # its length bytes may name a request of the same code: its size dispatch picks
        message = command.request if layout.direction == Direction.REQUEST else command.response
        if command.selector is not None or message is None or message.max_size is not None or not message.fields:
            continue
        if not (isinstance(message.fields[-1], Bytes) and takes_the_rest(message.fields[-1])):
            continue
        returns, extra, decoder = bodies[decoder_name(message)]
        if decoder and isinstance(decoder[0], ContentSize) and decoder[0].high is None:
            statements = decoder[1:]  # the size check: the key implies it
        elif stream and not message.min_size and not any(isinstance(s, ContentSize) for s in walk(decoder)):
            statements = decoder
        else:
            continue

        def at(offset: int) -> str:
            return f"start + {offset}" if stream else str(offset)

        offset, body = content_offset, []
        for statement in statements:
            if isinstance(statement, Advance) and statement.size.isdigit():
                offset += int(statement.size)
                continue
            if isinstance(statement, Unpack) and statement.at == "o":
                statement = replace(statement, at=at(offset))
            elif isinstance(statement, TakeRest):
                statement = replace(statement, start=at(offset), stop=f"stop - {tail}" if stream else f"-{tail}")
            if raises([statement]) or any(reads_cursor(s) for s in walk([statement])):
                break  # checked beyond its size, or read at a cursor: the general path
            body.append(statement)
        else:
            values = [Code(f"{e.name} = buf[{at(layout.offsets[e.name])}]") for e in layout.value_elements]
            lowest = (message.min_size or 0) + layout.length_adds
            check = stream_rest_check(protocol, layout) if stream else rest_check(protocol, layout)
            found.append(
                {
                    "whole_name": message_function("stream" if stream else "whole", message),
                    "stream": stream,
                    "returns": returns,
                    "where": f"{message.key} {message.direction.value}",
                    "whole_lines": fuse_unpack([*check, *values, *body]),
                    "code": command.wire_code(layout.direction),
                    "lengths": (lowest, length.type.maximum),
                    "adds": layout.overhead - layout.length_adds,  # frame size = length byte + this
                }
            )
    return found


def subcommand_rest_frames(
    protocol: Protocol, layout: FrameLayout, bodies: dict[str, tuple[str, str, Block]]
) -> list[dict[str, Any]]:
    """decode()'s whole-frame decoders of the sub-command frames of more than one size (a list its count sizes), one
    per command: any length byte from the smallest such content up names it (a key per length byte, as rest_frames).
    Each checks the checksum, then picks the sub-command by its byte and runs that sub-command's content decoder's
    statements in place: no dispatch and no call. It returns None where the checksum fails or no such sub-command has
    the code (decode()'s general path then says why); a frame its statements refuse raises what the general path
    raises, as that path, with the same checks passed, runs the same statements."""
    checksum = protocol.framing.checksum
    length = layout.length
    if checksum is None or length is None or length.type is None or layout.value_elements:
        return []
    content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    tail = layout.overhead - content_offset  # bytes after the content
    found = []
    for command in protocol.commands:
        if command.selector is None or layout.direction not in command.selector.offsets:
            continue
        at = command.selector.offsets[layout.direction]
        subs = []
        for sub in command.subcommands:
            message = sub.request if layout.direction == Direction.REQUEST else sub.response
            if message is None or message.min_size == message.max_size:
                continue  # none, or of one size (subcommand_frames)
            returns, extra, body = bodies[decoder_name(message)]
            if not extra:
                subs.append((sub.code, message, body))
        if not subs:
            continue
        lines: Block = [*rest_check(protocol, layout), Code(f"sub = buf[{content_offset + at}]")]
        for sub_code, _, body in subs:
            cursor = Code(f"o, end = {content_offset}, len(buf) - {tail}")
            lines.append(If(f"sub == {sub_code:#04x}", (cursor, *body)))
        smallest = min(message.min_size or 0 for _, message, _ in subs)
        sizes = [message.max_size for _, message, _ in subs]
        largest = length.type.maximum if None in sizes else max(s for s in sizes if s is not None) + layout.length_adds
        found.append(
            {
                "whole_name": f"_whole_{command.name}_{layout.direction.value}",
                "returns": "Message",
                "where": f"{command.name} {layout.direction.value}",
                "whole_lines": [*lines, RETURN_NONE],
                "code": command.wire_code(layout.direction),
                # the sub-command's byte lies within the content: no smaller content reaches the picker
                "lengths": (max(smallest, at + 1) + layout.length_adds, min(largest, length.type.maximum)),
                "adds": layout.overhead - layout.length_adds,  # frame size = length byte + this
            }
        )
    return found


def rest_check(protocol: Protocol, layout: FrameLayout) -> Block:
    """The checksum test of a whole frame of any size (`buf` is the frame), returning None when it fails."""
    checksum = protocol.framing.checksum
    assert checksum is not None  # length-byte frames have one
    size = layout.checksum_offset_from_end
    stored = "buf[-1]" if size == 1 else f"int.from_bytes(buf[-{size}:], 'little')"
    header = layout.header[: layout.covered_from]
    test = checksum.algorithm.frame_test("sum(buf)", sum(header), "buf[-1]")
    if test is not None and size == 1 == layout.covered_to_end and len(header) == layout.covered_from:
        return [FrameTest(test, test)]
    covered = f"buf[{layout.covered_from}:-{layout.covered_to_end}]"
    check = [Code(line) for line in checksum_lines(checksum, covered, "expected")]
    return [*check, If(f"expected != {stored}", (RETURN_NONE,))]


def stream_rest_check(protocol: Protocol, layout: FrameLayout) -> Block:
    """The checksum test of the frame of any size at buf[start:], its end (`stop`) from its length byte, returning
    None when it fails."""
    checksum = protocol.framing.checksum
    assert checksum is not None  # length-byte frames have one
    size = layout.checksum_offset_from_end
    stored = "buf[stop - 1]" if size == 1 else f"int.from_bytes(buf[stop - {size} : stop], 'little')"
    first = f"start + {layout.covered_from}" if layout.covered_from else "start"
    covered = f"buf[{first} : stop - {layout.covered_to_end}]"
    adds = layout.overhead - layout.length_adds  # frame size = length byte + this
    check = [Code(line) for line in checksum_lines(checksum, covered, "expected")]
    stop = Code(f"stop = start + {adds} + buf[start + {layout.length_offset}]")
    return [stop, *check, If(f"expected != {stored}", (RETURN_NONE,))]


def failed_check(body: Block) -> int | None:
    """The index of a whole-frame decoder's checksum test (the first `if ...: return None`), or None."""
    return next((i for i, s in enumerate(body) if isinstance(s, If | FrameTest) and returns_none(s)), None)


def returns_none(statement: If | FrameTest) -> bool:
    return isinstance(statement, FrameTest) or statement.body == (RETURN_NONE,)


def picked_inline(subs: list[tuple[int, dict[str, Any]]], at: int) -> Block | None:
    """One function's statements for the sub-command frames of one size, where their checksum does not depend on
    their fields (a sum or CRC over the bytes, the same statements for all, given the key): the check once, then each
    sub-command's unpacking under an `if` on its code. None where the check is made from the unpacked values."""
    first: Block = subs[0][1]["whole_lines"]
    index = failed_check(first)
    if index is None:
        return None
    checks = first[: index + 1]
    if any(isinstance(s, Unpack) for s in walk(checks)):
        return None
    if any(f["whole_lines"][: len(checks)] != checks for _, f in subs):
        return None
    lines: Block = [*checks, Code(f"sub = buf[{at}]")]
    for sub_code, f in subs:
        lines.append(If(f"sub == {sub_code:#04x}", tuple(fuse_unpack(f["whole_lines"][len(checks) :]))))
    return [*lines, RETURN_NONE]


def frame_function(
    protocol: Protocol,
    layout: FrameLayout,
    command: Command,
    message: Message,
    bodies: dict[str, tuple[str, str, Block]],
    code: PackageCode,
    selector: str | None = None,
) -> tuple[int, int, dict[str, Any]] | None:
    """The whole-frame decoders of one message (see fixed_frames): size key, frame size, function; None where the
    message's frames need the general path. `selector`: the sub-command field, whose check the key makes."""
    checksum = protocol.framing.checksum
    if checksum is None or message.min_size != message.max_size:
        return None  # length-byte frames have a checksum
    content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    returns, extra, decoder = bodies[decoder_name(message)]
    if not (decoder and isinstance(decoder[0], ContentSize) and decoder[0].exact):
        return None
    body = decoder[1:]  # the content size check: the key implies the size
    if selector is not None:  # the sub-command's check: the picker chose this decoder by it
        at = next((i for i, s in enumerate(body) if isinstance(s, Expect) and s.name == f"v_{selector}"), None)
        if at is None:
            return None
        body = body[:at] + body[at + 1 :]
    unpacks = [s for s in walk(body) if isinstance(s, Unpack) and s.at == "o"]
    cursor = any(reads_cursor(s) for s in walk(body) if not isinstance(s, Unpack))
    if len(unpacks) > 1 or cursor or raises(body):
        return None  # content read at a moving cursor, or checked beyond its size: the general path
    size = layout.overhead + (message.min_size or 0)
    length_byte = (message.min_size or 0) + layout.length_adds
    known = dict(enumerate(layout.header)) | {layout.length_offset: length_byte}
    if layout.command_offset is not None:
        known[layout.command_offset] = command.wire_code(layout.direction) or 0

    def statements(at: Callable[[int], str], whole: bool) -> tuple[Block, bool]:
        """The decoder's statements with frame offsets `at` (buf[start:] or all of buf: `whole`), and whether its
        checksum is checked from the unpacked values (sum_from_values)."""
        values: Block = [
            Code(f"{e.name} = buf[{at(layout.offsets[e.name])}]", reads=(layout.offsets[e.name],))
            for e in layout.value_elements
        ]
        summed = sum_from_values(
            protocol, layout, command.wire_code(layout.direction), length_byte, size, body, code, at
        )
        if summed is not None:
            return [*values, *summed, *body[1:]], True
        check = whole_frame_check(protocol, layout, size, known, at) if whole else None
        if check is None:
            check = frame_check(checksum, layout, size, at)
        return [*check, *values, *at_offset(body, at(content_offset))], False

    lines, summed = statements(lambda offset: f"start + {offset}", False)
    function: dict[str, Any] = {
        "name": message_function("frame", message),
        "whole_name": message_function("whole", message),
        "returns": returns,
        "where": f"{message.key} {message.direction.value}",
        "lines": lines,
        "whole_lines": statements(str, True)[0],
    }
    # built in decode() where its whole-frame decoder sums the frame's bytes (one from the values is quicker yet)
    plain = unpacked_frame(protocol, layout, body)
    function["plain"] = plain if not summed else None
    function["run"] = run_frames(layout, message, size, plain, code)
    key = (
        length_byte if layout.command_offset is None else (command.wire_code(layout.direction) or 0) << 8 | length_byte
    )
    return key, size, function


def at_offset(body: Block, at: str) -> Block:
    """A content decoder's statements with the unpack at the cursor made at `at` (a frame offset)."""
    return [replace(s, at=at) if isinstance(s, Unpack) and s.at == "o" else s for s in body]


def frame_check(checksum: Checksum, layout: FrameLayout, size: int, at: Callable[[int], str]) -> Block:
    """A whole frame's checksum test, returning None when it fails: the checksum over the covered bytes compared
    with the stored one (frame offsets `at`)."""
    reads: tuple[int, ...] = ()
    if layout.checksum_offset_from_end == 1:
        stored, reads = f"buf[{at(size - 1)}]", (size - 1,)
    else:
        stored, reads = f"int.from_bytes(buf[{at(size - layout.checksum_offset_from_end)} : {at(size)}], 'little')", ()
    covered = f"buf[{at(layout.covered_from)} : {at(size - layout.covered_to_end)}]"
    check = [Code(line) for line in checksum_lines(checksum, covered, "expected")]
    return [*check, If(f"expected != {stored}", (RETURN_NONE,), reads=reads)]


_MOST_UNROLLED = 12  # CRC-8 steps written out one by one in a whole-frame decoder; more take a loop


def whole_frame_check(
    protocol: Protocol, layout: FrameLayout, size: int, known: dict[int, int], at: Callable[[int], str]
) -> Block | None:
    """decode()'s version of a whole-frame decoder's checksum test, where it is cheaper than frame_check's: `buf` is
    exactly the frame (decode checked its size), so a checksum that is a sum over all but a constant header is
    tested on the sum of the whole frame (no slice is made: the algorithm's frame_test); one computed by table steps
    starts from its state after the covered bytes that the frame's key fixes (`known`: offset -> byte; header,
    command code, length byte), and a few steps are written out. None where neither applies."""
    checksum = protocol.framing.checksum
    assert checksum is not None  # length-byte frames have one
    steps = checksum.algorithm.byte_table(checksum_name(checksum), "expected")
    if steps is not None:
        state = steps.start
        first, stop = layout.covered_from, size - layout.covered_to_end
        while first in known and first < stop - 1:
            state = steps.entries[state ^ known[first]]
            first += 1
        stepped: Block
        if stop - first > _MOST_UNROLLED:
            stepped = [
                Code(f"expected = {state:#x}"),
                Loop(f"for byte in buf[{first} : {stop}]", (Code(f"expected = {steps.table}[expected ^ byte]"),)),
            ]
        else:  # a few bytes: one table step each, no slice and no loop
            stepped = [Code(f"expected = {steps.table}[{state:#x} ^ buf[{first}]]", reads=(first,))]
            stepped += [
                Code(f"expected = {steps.table}[expected ^ buf[{offset}]]", reads=(offset,))
                for offset in range(first + 1, stop)
            ]
        stepped += [Code(line) for line in steps.finish]
        return [*stepped, frame_check(checksum, layout, size, at)[-1]]
    header = layout.header[: layout.covered_from]
    test = checksum.algorithm.frame_test("sum(buf)", sum(header), f"buf[{size - 1}]")
    whole = layout.checksum_offset_from_end == 1 and layout.covered_to_end == 1 and len(header) == layout.covered_from
    if test is None or not whole:
        return None
    return [FrameTest(test, checksum.algorithm.frame_test("sum(buf)", sum(header), "buf[-1]") or test)]


def exact_struct(name: str, size: int, content_offset: int, code: PackageCode) -> str:
    """A struct of a whole frame of `size` bytes that unpacks what struct `name` unpacks at the content's offset,
    the bytes around it skipped: its unpack refuses (struct.error) a frame of any other size."""
    fmt = code.structs[name]
    after = size - content_offset - struct.calcsize(fmt)
    whole = f"{fmt[0]}{content_offset}x{fmt[1:]}" + (f"{after}x" if after else "")
    exact = f"{name}_IN_{size}"
    code.structs[exact] = whole
    return exact


def exact_whole(body: Block, size: int, known: int, code: PackageCode) -> Block:
    """A whole-frame decoder that refuses a frame of another size than `size` by itself: its one unpack made of the
    whole frame (struct.error), a sum's check byte read from the end; else a size check first, returning None.
    `known`: the bytes decode() has matched (its key), which any frame it is given holds."""
    body = [replace(s, condition=s.from_end) if isinstance(s, FrameTest) else s for s in body]
    unpacks = [i for i, s in enumerate(body) if _unpack_at_offset(s) is not None]
    before = body[: unpacks[0] if unpacks else len(body)]
    if len(unpacks) != 1 or any(offset >= known for offset in _constant_reads(before)):
        return [If(f"len(buf) != {size}", (RETURN_NONE,)), *body]
    found = body[unpacks[0]]
    unpack = _unpack_at_offset(found)
    assert unpack is not None
    whole = replace(unpack, struct=exact_struct(unpack.struct, size, int(unpack.at), code), at="")
    body[unpacks[0]] = replace(found, unpacked=whole) if isinstance(found, ReturnNew) else whole
    return body


def _unpack_at_offset(statement: Statement) -> Unpack | None:
    """The struct unpack a statement makes at a constant offset of the frame, if any."""
    if isinstance(statement, ReturnNew):
        unpack = statement.unpacked
    else:
        unpack = statement if isinstance(statement, Unpack) else None
    return unpack if unpack is not None and not unpack.indexed and unpack.at.isdigit() else None


def _constant_reads(body: Block) -> list[int]:
    """The constant offsets of `buf` that statements read (an unpack's struct aside)."""
    reads: list[int] = []
    for statement in walk(body):
        if isinstance(statement, Code | If):
            reads += statement.reads
        elif isinstance(statement, Unpack) and statement.indexed and statement.at.isdigit():
            reads.append(int(statement.at))
    return reads


def stream_sum(protocol: Protocol, layout: FrameLayout) -> str | None:
    """The stream parser's `summed`: (first byte covered, inverted) where the checksum is an 8-bit sum of every byte
    from there to the last, which it is; None for other checksums."""
    checksum = protocol.framing.checksum
    inverted = checksum.algorithm.summed() if checksum is not None else None
    if inverted is None or whole_frame_test(protocol, layout) is None:
        return None
    return f"({layout.covered_from}, {inverted})"


def whole_frame_test(protocol: Protocol, layout: FrameLayout) -> str | None:
    """decode()'s test that a whole frame `data` (its size known) holds its checksum, where it is one expression
    over the frame's bytes (straight_frames.frame_sum_test, as every framing's checks make it). None for others."""
    engine = runtime_layout(layout)
    test = frame_sum_test(engine, len(engine.elements) - 1, protocol.framing.checksum, "data")
    return None if test is None else f"not {test}"


def run_frames(
    layout: FrameLayout, message: Message, size: int, plain: tuple[str, str] | None, code: PackageCode
) -> dict[str, str] | None:
    """The stream parser's decoder of a run of a plain frame (unpacked_frame), checked already, laid end to end with
    their headers left out: one struct over the bytes after the header (the command code, length byte and checksum
    skipped as padding) and a message built from each tuple it unpacks. None where the content is not the whole of
    the frame between those."""
    if plain is None:
        return None
    cls, content = plain
    fmt = code.structs[content]
    width = len(layout.header)
    content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    if content_offset < width or content_offset + struct.calcsize(fmt) != size - 1:
        return None
    lead = content_offset - width
    after = fmt[0] + (f"{lead}x" if lead else "") + fmt[1:] + "x"
    frames = code.struct(code.stems[content] + "_after_header", after)
    names = [f.name for f in message.fields]
    return {
        "name": message_function("run", message),
        "build": code.build_all(cls, names, f"{frames}.iter_unpack(frames)"),
        "returns": cls,
        "where": f"{message.key} {message.direction.value}",
    }


def unpacked_frame(protocol: Protocol, layout: FrameLayout, body: Block) -> tuple[str, str] | None:
    """(class, struct) of a frame whose message is the tuple one struct unpacks from its content, as it is, and
    whose checksum decode() tests in one expression (whole_frame_test): decode() builds it itself, with no call.
    None for others (frame values, conversions, checks)."""
    plain = content_unpacked(body)
    if plain is None or layout.value_elements or whole_frame_test(protocol, layout) is None:
        return None
    return plain


_BYTES_OF = {"B": 1, "b": 1, "H": 2, "h": 2, "I": 4, "i": 4, "Q": 8, "q": 8}
_MOST_TERMS = 4  # byte terms of a checksum computed from the values; beyond it the frame's bytes are summed


def sum_from_values(
    protocol: Protocol,
    layout: FrameLayout,
    command: int | None,
    length_byte: int,
    size: int,
    body: Block,
    code: PackageCode,
    at: Callable[[int], str],
) -> Block | None:
    """For an 8-bit sum checksum right after integer-only content: statements that unpack the content and the
    checksum in one call (at frame offsets `at`) and check the sum from the values (a byte sum does not depend on
    byte order), so no slice of the frame is made and summed. The frame's other covered bytes must be the header,
    command code and length byte (constants, given the key) and one-byte frame values. None where the frame is not
    like that."""
    checksum = protocol.framing.checksum
    unpack = body[0] if body else None
    if checksum is None or checksum.algorithm.summed() is None:
        return None
    if not isinstance(unpack, Unpack) or unpack.at != "o" or unpack.tuple_target:
        return None
    if layout.checksum_offset_from_end != 1:
        return None
    fmt = code.structs[unpack.struct]
    targets = unpack.targets
    if len(targets) != len(fmt) - 1 or any(c not in _BYTES_OF for c in fmt[1:]):
        return None
    content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    if content_offset + sum(_BYTES_OF[c] for c in fmt[1:]) != size - 1:
        return None  # the checksum does not follow the content
    constant = 0
    terms = []
    for offset in range(layout.covered_from, size - layout.covered_to_end):
        if offset < len(layout.header):
            constant += layout.header[offset]
        elif offset == layout.command_offset:
            constant += command or 0
        elif offset == layout.length_offset:
            constant += length_byte
        elif content_offset <= offset < size - 1:
            continue  # the content's values, below
        else:
            element = next((e for e in layout.value_elements if layout.offsets[e.name] == offset and e.size == 1), None)
            if element is None:
                return None
            terms.append(element.name)
    for target, char in zip(targets, fmt[1:], strict=True):
        width = _BYTES_OF[char]
        if width == 1:
            terms.append(target if char == "B" else f"({target} & 0xff)")
        else:
            terms += [f"({target} & 0xff)", *(f"({target} >> {8 * i} & 0xff)" for i in range(1, width))]
    if len(terms) > _MOST_TERMS:
        return None  # summing a slice of the frame in C is cheaper than this many terms in Python
    with_check = code.struct(code.stems[unpack.struct] + "_and_check", fmt + "B")
    total = checksum.algorithm.byte_total(" + ".join([f"{constant:#x}", *terms]))
    assert total is not None  # an 8-bit byte sum's
    return [
        Unpack((*targets, "check"), with_check, at=at(content_offset)),
        If(f"{total} != check", (RETURN_NONE,)),
    ]


def frame_decode_lines(protocol: Protocol, layout: FrameLayout, dispatch: list[tuple[str, str]]) -> Lines:
    """Checksum check, then dispatch to the content decoder, of a frame buf[start:stop] whose header and length the
    stream parser has checked (decode() checks whole frames as every framing does: straight_frames.decode_lines)."""
    size = layout.checksum_offset_from_end
    offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    after = layout.overhead - offset

    def at(position: int) -> str:
        return f"buf[start + {position}]"

    checksum = protocol.framing.checksum
    assert checksum is not None  # length-byte frames have one
    first = f"start + {layout.covered_from}" if layout.covered_from else "start"
    covered = f"buf[{first} : stop - {layout.covered_to_end}]"
    stored = "buf[stop - 1]" if size == 1 else f"int.from_bytes(buf[stop - {size} : stop], 'little')"
    content = f"start + {offset}, stop - {after}"
    args = f"buf, {content}" + "".join(f", {at(layout.offsets[e.name])}" for e in layout.value_elements)
    lines = [f"check = {stored}"]  # read once: the sum and the comparison both use it
    lines += checksum_lines(checksum, covered, "expected")
    lines += [
        "if expected != check:",
        # as wide as the checksum: a u16 that reads 0 is 0x0000
        f'    raise ChecksumError(f"bad checksum: the frame has {{check:#0{2 + 2 * size}x}}, '
        f'its bytes give {{expected:#0{2 + 2 * size}x}}")',
    ]
    if layout.command_offset is None:  # the one codeless command of this direction, if any
        if not dispatch:
            return [*lines, f'raise DecodeError("no {layout.direction.value} is defined")']
        return [*lines, f"return {dispatch[0][1]}({args})"]
    code = at(layout.command_offset)
    return [
        *lines,
        f"decoder = _{layout.direction.name}_DECODERS.get({code})",
        "if decoder is None:",
        f'    raise DecodeError(f"unknown command {{{code}:#04x}}")',
        f"return decoder({args})",
    ]


def value_ranges(layout: FrameLayout, byte_order: str) -> str:
    """The frame-level values whose declared range is narrower than their type (an address 0..253, broadcast 254),
    as FrameFormat.value_ranges: (offset, size, byte order, signed, low, high, also allowed); a stream candidate
    holding a value outside its range is no frame."""
    ranges = [
        f"({layout.offsets[e.name]}, {e.type.size}, {byte_order!r}, {e.type.signed}, {int(e.minimum)}, "
        f"{int(e.maximum)}, {e.broadcast})"
        for e in layout.value_elements
        if e.type is not None and not e.type.is_float and (e.minimum, e.maximum) != (e.type.minimum, e.type.maximum)
    ]
    return "(" + ", ".join(ranges) + ("," if len(ranges) == 1 else "") + ")"


def value_range_checks(layout: FrameLayout, byte_order: str) -> list[tuple[str, str, str]]:
    """`decode`'s tests of the frame-level values whose declared range is narrower than their type, as the stream
    parser (value_ranges) makes them; decode checks the header before them. Each: the condition that the value is
    outside its range, the condition that it is inside, and the error raised for it."""
    checks = []
    for e in layout.value_elements:
        if e.type is None or e.type.is_float or (e.minimum, e.maximum) == (e.type.minimum, e.type.maximum):
            continue
        offset, size = layout.offsets[e.name], e.type.size
        indexed = size == 1 and not e.type.signed
        value = (
            f"data[{offset}]"
            if indexed
            else f"int.from_bytes(data[{offset}:{offset + size}], {byte_order!r}, signed={e.type.signed})"
        )
        low, high = int(e.minimum), int(e.maximum)
        shown = f" (or {e.broadcast})" if e.broadcast is not None else ""
        lowest, highest = low, high
        if e.broadcast in (low - 1, high + 1):  # next to the range: one comparison
            lowest, highest = min(low, e.broadcast), max(high, e.broadcast)
        also = f" or {value} == {e.broadcast}" if e.broadcast is not None and lowest == low and highest == high else ""
        if lowest <= e.type.minimum and not also:  # no value of the type is below it
            refused = f"{value} > {highest}"
            inside = f"{value} <= {highest}" if indexed else f"not {refused}"
        elif highest >= e.type.maximum and not also:
            refused = f"{value} < {lowest}"
            inside = f"{value} >= {lowest}" if indexed else f"not {refused}"
        else:
            inside = f"({lowest} <= {value} <= {highest}{also})"
            refused = f"not {inside}"
        error = f'DecodeError(f"{e.name} = {{{value}}} is outside its range {low}..{high}{shown}")'
        checks.append((refused, inside, error))
    return checks


# --- the codec's frames: one entry for every shape ---------------------------------------------------------------


def straight_codec_context(protocol: Protocol, code: PackageCode) -> dict[str, Any]:
    """Frames of any other shape: straight-line frame functions per direction where the layouts allow them (see
    straight_frames.py), else the runtime's frame engine; one FrameCodec per direction either way (the stream parser's),
    decoders by code (and by class)."""
    # layouts chosen by command, checksums over request bytes: the engine's code only (no straight-line checks)
    engine_only = protocol.framing.by_command or protocol.framing.from_request
    imports, definitions = checksum_definitions(protocol, straight=not engine_only)
    directions: list[dict[str, Any]] = []
    dispatchers = []
    size_dispatchers: list[dict[str, Any]] = []
    frame_structs: dict[str, str] = {}
    # the runtime.framing names the codec uses: the FrameCodecs' (the straight-line functions' Transparency objects are
    # those of the same layouts) and ERROR_REPLY where error replies are told by their flag
    names = {"EngineFormat"}
    for direction, layout in protocol.framing.layouts.items():
        table = direction_dispatch(protocol, direction)
        dispatchers += table.dispatchers
        size_dispatchers += table.size_dispatchers
        dispatch, sizes, single, expected = table.dispatch, table.sizes, table.single, table.expected
        only = dispatch[0][1] if not layout.has_command and len(dispatch) == 1 and not expected else ""
        values = tuple(e.name for e in layout.value_elements)
        requesting = protocol.framing.by_command or protocol.framing.from_request
        optional = tuple(e.name for e in optional_elements(protocol, direction))
        frames = Target(
            direction.name, values, expected=bool(expected), only=only, requesting=requesting, optional=optional
        )
        if protocol.error_reply is not None and direction == Direction.RESPONSE:
            element = next(e for e in layout.elements if e.name == protocol.error_reply.element)
            assert element.type is not None
            mask = (1 << (8 * element.type.size)) - 1
            flag = protocol.error_reply.flag
            frames = replace(frames, error_flag=flag, error_keep=mask & ~flag)
        plain = unpacked_messages(single, code) if not expected and not frames.error_flag else []
        functions, call = direction_functions(protocol, direction, frames, frame_structs, plain)
        names |= {ERROR_REPLY} if frames.error_flag else set()
        if protocol.framing.by_request(direction):  # content sizes and size rules by reply class
            answering = [m for m in protocol.messages() if m.direction == direction]
            sizes = [(repr(m.class_name), m.min_size, m.max_size) for m in answering]
            single = {repr(m.class_name): m for m in answering}
        frame_codec, used = codec_lines(protocol, direction, sizes, single)
        names |= used
        directions.append(
            {
                "name": direction.value,
                "upper": direction.name,
                "dispatch": dispatch,
                "expected": expected,
                "frames": frame_codec,
                "functions": functions,
                "call": call,
                "headers": sorted({layout.header for layout in protocol.framing.alternatives[direction]}),
            }
        )
    headers = [h for d in directions for h in d["headers"]]
    shared = {cls for d in directions for cls, _, _ in d["expected"]}
    replies = replies_by_request(protocol.messages())
    reply_layouts = [
        (m.class_name, reply.class_name)
        for m in protocol.messages()
        if m.direction == Direction.REQUEST
        and (reply := reply_to(m, replies)) is not None
        and reply.class_name in shared
        and not reply.default_reply
    ]
    code.structs.update(frame_structs)  # listed with the content's structs (common_codec_context)
    by_header = all(headers) and len(set(headers)) == len(headers)
    requesting = protocol.framing.by_command or protocol.framing.from_request
    return {
        "length_byte_frames": False,
        "requesting": requesting,
        "reply_to": [
            (m.class_name, reply.class_name)
            for m in protocol.messages()
            if m.direction == Direction.REQUEST and (reply := reply_to(m, replies)) is not None
        ]
        if requesting
        else [],
        "reply_layouts": reply_layouts,
        "framing_imports": sorted(names, key=import_order),
        # the straight-line frame checks raise it (the engine raises its own)
        "checksum_error": any(
            element.kind == "checksum"
            for direction in protocol.framing.layouts
            if (straight := code.straight(direction)) is not None
            for layout in straight.layouts
            for element in layout.elements
        ),
        "checksum_imports": imports,
        "checksum_definitions": definitions,
        "directions": directions,
        "dispatchers": dispatchers,
        "size_dispatchers": size_dispatchers,
        "by_header": by_header,
        "either": ""
        if by_header
        else "give the direction: requests and responses cannot be told apart by their first bytes",
        "no_header": "f\"frame starts {data[:4].hex(' ')}, which is neither a request nor a response header\"",
    }


def unpacked_messages(single: dict[str, Message], code: PackageCode) -> list[tuple[int, int, str, str, str]]:
    """(code, content size, class, struct's name stem, its format) of the messages of one size whose decoder, past its
    size check, is one struct's unpack of the content as their message (straight_frames.whole_frames decodes them
    whole)."""
    bodies = {name: body for name, _, _, body in code.decoders}
    found = []
    for key, message in single.items():
        body = bodies[decoder_name(message)]
        if key in ("None", ERROR_REPLY) or message.min_size != message.max_size or len(body) < 2:
            continue
        if not (isinstance(body[0], ContentSize) and body[0].exact):
            continue
        unpacked = content_unpacked(body[1:])
        if unpacked is not None:
            cls, struct = unpacked
            found.append((int(key, 16), message.min_size or 0, cls, code.stems[struct], code.structs[struct]))
    return found


def frames_codec_context(protocol: Protocol, code: PackageCode) -> dict[str, Any]:
    """The codec template's frames part: each direction's frame checks, dispatch and encoders' wraps; with the
    length-byte case's tables where every layout has that shape."""
    if protocol.framing.classic:
        return length_byte_codec_context(protocol, code)
    return straight_codec_context(protocol, code)


def lookup_lines(d: dict[str, Any]) -> Lines:
    """decode()'s lines, for one direction of the length-byte case, that look a frame `data` up in its table of
    frames decoded whole (by its first bytes, or its command code and length byte) before the general checks; a
    frame the table does not take, or whose decoder refuses it, goes on to them, which say why."""
    accepted = "".join(f" and {c}" for c in d["accepted"])
    early = d["whole_frames"] and not d["range_checks"]
    table, size = f"_{d['upper']}_WHOLE", d["whole_size"]
    by_first_bytes = f"fixed = {table}.get(data[:{size}])  # no key is shorter: a short frame matches none"
    decoded = [
        "    message = fixed[1](data)",
        "    if message is not None:",
        "        return message",
    ]
    if early and d["unpacked"] and d["exact"]:
        return [
            by_first_bytes,
            "if fixed is not None:",
            "    _, whole, unpack, cls = fixed",
            "    try:  # each unpacks the whole frame, so one of another size raises struct.error: no size compared"
            " here",
            "        if unpack is None:",
            "            message = whole(data)",
            "            if message is not None:",
            "                return message",
            f"        elif {d['whole_check']}:  # its message is its content as unpacked: built here, no call",
            "            return _new(cls, unpack(data))",
            "    except struct.error:",
            "        pass  # not the size its first bytes say: the checks below say what is wrong",
        ]
    if early and d["unpacked"]:
        return [
            by_first_bytes,
            "if fixed is not None and fixed[0] == len(data):",
            "    _, whole, unpack, cls = fixed",
            "    if unpack is None:",
            "        message = whole(data)",
            "        if message is not None:",
            "            return message",
            f"    elif {d['whole_check']}:  # its message is its content as unpacked: built here, no call",
            f"        return _new(cls, unpack(data, {d['content_offset']}))",
        ]
    if early:
        return [by_first_bytes, "if fixed is not None and fixed[0] == len(data):", *decoded]
    if d["whole_frames"]:
        return [by_first_bytes, f"if fixed is not None and fixed[0] == len(data){accepted}:", *decoded]
    if d["fixed"] and d["slice_key"]:
        return [
            f"fixed = {table}.get({d['slice_key']})  # a short frame's slice is shorter: it matches none",
            f"if fixed is not None and fixed[0] == len(data) and data[:{d['header_size']}] == {d['header']}{accepted}:",
            *decoded,
        ]
    if d["fixed"]:
        return [
            f"fixed = {table}.get({d['key']}) if len(data) >= {d['overhead']} else None",
            f"if fixed is not None and fixed[0] == len(data) and data[:{d['header_size']}] == {d['header']}{accepted}:",
            *decoded,
        ]
    return []
