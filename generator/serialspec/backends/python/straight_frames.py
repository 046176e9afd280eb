"""Straight-line frame code: stuffing, u16 lengths over a span, CRC-16s, frames without a header or a length,
alternative layouts told apart by their header. decode_lines writes every framing's frame checks and dispatch (the
length-byte codecs' decode() runs them past its whole-frame lookups, length_byte_frames.py); the rest serves the
frames that are not of the length-byte shape.

Each direction gets two functions: `_decode_<direction>(frame, expect)` checks a whole frame and calls the content
decoder on the frame's own bytes, and `_wrap_<direction>(content, code, *values)` puts the frame around a content.
They make the runtime engine's checks (runtime/framing.py, Layout.unwrap and Layout.wrap) in the engine's order with
the engine's messages, but as code written for one layout: every offset known when the layout is fixed is a literal,
the bytes are unstuffed only when a stuffed sequence occurs (a `find` first), and a frame's content is decoded in
place (no copy) unless it was stuffed, and a CRC stored in its own bit order is checked by its residue over the
frame. `decode()` runs the checks inline (one call less), and first looks a frame of one size whose message is its
content as one struct unpacks it up by its first bytes (`whole_frames`: checked from its end, unpacked whole, no
call); encoders of unstuffed frames make their frame inline too (`frame_encoder`: the head packed with the content's
first struct, constant leading bytes as a literal beside the checksummed body). Where a layout does not fit that
form (a length after the content, a checksum over bytes inside the stuffed span, ...) the two functions call the
engine instead, so every layout the language describes works and the straight-line form is only ever a faster way to
the same result (tests/test_straight_frames.py holds them to it).

Positions are expressions over `buf`, the frame with its stuffed span replaced by the plain bytes (`frame` itself
where nothing can be stuffed): an element before the content at a literal offset, an element after it at `end + k`,
where `end` is the content's end. Lengths and checksums that see wire bytes read `frame`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from serialspec.backends.common.frames import runtime_layouts
from serialspec.backends.python.ir import Block, Code, Literal, Pack, PackItems, Simple, packed_lists
from serialspec.lang.model import Checksum, Direction, Protocol
from serialspec.runtime.framing import Element, Layout, Transparency

Lines = list[str]
Structs = Callable[[str], str]  # a struct format -> the name of the module's struct constant for it


def checksum_name(checksum: Checksum) -> str:
    """The codec's module-level name of a checksum's function (backends/python/frames.py defines them)."""
    return f"_CHECK_{checksum.name.upper()}"


def checksum_call(checksum: Checksum) -> str:
    """The expression of a checksum over `{}` (a str.format template), as its algorithm writes it: in line, a C
    function called directly, or the module's checksum function (frames.checksum_definitions defines it)."""
    return checksum.algorithm.python_call(checksum_name(checksum))


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


def straight(layout: Layout) -> bool:
    """Whether the layout fits the straight-line form: one content inside the variable part (the stuffed span, else
    the content), lengths at fixed offsets before it, checksums after it and after what they cover, none of them
    over bytes inside the stuffed span only, multi-byte elements at fixed offsets in one byte order."""
    if layout.content < 0 or not isinstance(layout.transparency, Transparency | None):
        return False  # other transforms than substitution: the engine codes them
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
    if target.requesting:  # the layout by the message's command, the request's bytes for a checksum over them
        wrap = [
            f"def _wrap_{direction}({parameters}, layout: int | None = None, request: Message | None = None) -> bytes:",
            f'    """The {direction} frame around `content` in its layout, made by the frame engine."""',
            f"    return {frames}.wrap(content, code, {shown}, layout, _request_parts(request))",
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
        f"def _wrap_{direction}({parameters}) -> bytes:",
        f'    """The {direction} frame around `content`, made by the frame engine."""',
        f"    return {frames}.wrap(content, code, {shown})",
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
    return [*decode, *(f"    {line}" for line in _dispatch(target, "code", arguments, nullable=True))]


@dataclass(frozen=True)
class StraightLayouts:
    """A direction whose layouts all take straight-line code: the engine's layouts, each with its checksum
    elements' function names (by element index)."""

    layouts: tuple[Layout, ...]
    checks: tuple[dict[int, str], ...]
    algorithms: tuple[dict[int, Checksum], ...]  # the same checksums


def straight_direction(protocol: Protocol, direction: Direction) -> StraightLayouts | None:
    """The direction's layouts, when every one fits the straight-line form (and they carry the same values)."""
    layouts = runtime_layouts(protocol, direction)
    names = {tuple(e.name for e in (layout.elements[i] for i in layout.values)) for layout in layouts}
    if not all(straight(layout) for layout in layouts) or len(names) != 1:
        return None
    if protocol.framing.by_command or protocol.framing.from_request:
        return None  # layouts chosen by command, checksums over the request: the engine's
    algorithms = tuple(
        {index: e.checksum for index, e in enumerate(model.elements) if e.checksum is not None}
        for model in protocol.framing.alternatives[direction]
    )
    checks = tuple({index: checksum_call(checksum) for index, checksum in found.items()} for found in algorithms)
    return StraightLayouts(layouts, checks, algorithms)


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
    call = ["frame = data if data.__class__ is bytes else bytes(data)", *fast, *_choice(layouts, d, bodies)]
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
