"""Decoding every framing's frames in straight-line code (layer 1 and 2 of the package docstring): one layout's
checks in the engine's order with the engine's messages (`decode_lines`), the choice of layout by header, decode()'s
table of frames of one size decoded whole (`whole_frames`), and the two functions of a direction that keeps the
interpreted engine (`engine_lines`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from serialspec.lang.model import (
    Checksum,
)
from serialspec.runtime.framing import Element, Layout

if TYPE_CHECKING:
    pass
from serialspec.backends.python.frames.layouts import (
    Lines,
    Positions,
    StraightLayouts,
    Target,
    plus,
    size_of,
    slice_start,
    stuffing_of,
)


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
    positions = Positions(layout)
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
            f'    raise DecodeError(f"frame of {{n}} bytes is shorter than the {layout.overhead} bytes a {layout.name} '
            f'frame has besides its content")',
        ]
    t = stuffing_of(layout)
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
        fixed = size_of(elements[positions.first : positions.last + 1])
        if fixed:
            inner = plus("end", positions.behind - positions.after - positions.before)
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
        for name, low, mask, const in element.fixed:  # as the engine words it (framing._outside)
            got = f"({value} >> {low}) & {mask:#x}" if low else f"{value} & {mask:#x}"
            body += [
                f"if {got} != {const}:",
                f'    raise DecodeError(f"{element.name}.{name} is {{{got}}}, expected {const}")',
            ]
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
        body.append(f"length = {positions.read(index)}")
        if element.limits is not None:  # as the stream parser, which sees no frame there
            low, high = element.limits
            body += [
                f"if not {low} <= length <= {high}:" if low else f"if length > {high}:",
                f'    raise DecodeError(f"{element.name} = {{length}} is outside its range {low}..{high}")',
            ]
        body += [
            f"if length != {counted}:",
            f'    raise DecodeError(f"{element.name} says {{length}} but the frame holds {{{counted}}}")',
        ]
    for index, element in enumerate(elements):
        if element.kind != "checksum":
            continue
        width = 2 + 2 * element.size
        error = (
            f'raise ChecksumError(f"bad {element.name}: the frame has {{stored:#0{width}x}}, '
            f'its bytes give {{check:#0{width}x}}")'
        )
        failed = [
            f"check = {checks[index].format(positions.covered(*element.span))}",
            f"stored = {positions.read(index)}",
            "if check != stored:",
            f"    {error}",
        ]
        residue = crc_residue(element)
        a, b = element.span
        test = frame_sum_test(layout, index, (algorithms or {}).get(index))
        if test is not None:  # the sum of the whole frame, no slice made; the rest only says what is wrong
            body += [f"if {test}:", *(f"    {line}" for line in [*failed[:2], error])]
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
    arguments = ", ".join([positions.buf, str(positions.content), "end", *values])
    if layout.error and command is not None:  # an error header: the error reply, refusing the request of `code`
        body.append(f"return _{target.upper}_DECODERS[ERROR_REPLY]({arguments}, code)")
    else:
        body += dispatch_lines(target, code, arguments, nullable=False, status=f"v_{target.error_status}")
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


def crc_residue(element: Element) -> int | None:
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


def dispatch_lines(target: Target, code: str, arguments: str, nullable: bool, status: str = "") -> Lines:
    """Lines that decode the content with the decoder of `code` (an expression; "None" where frames carry none):
    an error reply's where the error flag is set (or the status, an expression, has `error_bits` set), the expected
    reply's where replies share a code."""
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
    if target.error_bits and code != "None":
        lines += [
            f"if {status} & {target.error_bits:#04x}:  # an error reply: it refuses the request of this code",
            f"    return {table}[ERROR_REPLY]({arguments}, {code})",
        ]
    unknown = (
        f'f"unknown command {{{code}:#04x}}"'
        if code != "None"
        else f'"the protocol has no {target.upper.lower()} without a code"'  # (none of this direction at all)
    )
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


def _constant_checks(positions: Positions, start: int = 0) -> Lines:
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
                data = f"{buf}[{slice_start(positions.at(index))}:{positions.stop(index)}]"
                condition = f"{data} != {element.constant!r}"
            single.append((condition, _message_constant(element, data), element.name))
        if len(each) == 1:
            condition, message, _ = single[0]
            lines += [f"if {condition}:", f"    raise DecodeError({message})"]
            continue
        whole = b"".join(element.constant for _, element in each)
        lines.append(f"if {buf}[{slice_start(positions.at(run[0]))}:{positions.stop(run[-1])}] != {whole!r}:")
        for condition, message, _ in single[:-1]:
            lines += [f"    if {condition}:", f"        raise DecodeError({message})"]
        lines.append(f"    raise DecodeError({single[-1][1]})")
    return lines


def engine_lines(layouts: tuple[Layout, ...], target: Target, suffix: str = "") -> tuple[Lines, Lines]:
    """The two functions of a direction whose layouts keep the interpreted engine (FrameCodec), their names ending
    in `suffix` (`_engine`: beside straight-line functions, for the frames those leave to the engine)."""
    direction = target.upper.lower()
    frames = f"_{target.upper}_FRAMES"
    values = [f"v_{v}" for v in target.value_names]
    shown = f"({values[0]},)" if len(values) == 1 else f"({', '.join(values)})"
    parameters = ", ".join(["content: bytes", "code: int | None", *(f"{v}: int" for v in values)])
    optional = "".join(f", {name}: bytes | None = None" for name in target.optional)
    extras = ", {" + ", ".join(f"{name!r}: {name}" for name in target.optional) + "}" if target.optional else ""
    if target.requesting:  # the layout by the message's command, the request's bytes for a checksum over them
        wrap = [
            f"def _wrap_{direction}{suffix}({parameters}, layout: int | None = None, request: Message | None = None"
            f"{optional}) -> bytes:",
            f'    """The {direction} frame around `content` in its layout, made by the frame engine."""',
            f"    return {frames}.wrap(content, code, {shown}, layout, _request_parts(request){extras})",
        ]
        decode = [
            f"def _decode_{direction}{suffix}(frame: bytes, expect: type[Message] | None = None, "
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
            *([f"    {frames}.asked(expect, content, request)"] if direction == "response" else []),
        ]
        return _engine_decode(decode, target), wrap
    wrap = [
        f"def _wrap_{direction}{suffix}({parameters}{optional}) -> bytes:",
        f'    """The {direction} frame around `content`, made by the frame engine."""',
        f"    return {frames}.wrap(content, code, {shown}{', None, None' + extras if extras else ''})",
    ]
    decode = [
        f"def _decode_{direction}{suffix}(frame: bytes, expect: type[Message] | None = None) -> Message:",
        f'    """One complete {direction} frame, checked and taken apart by the frame engine; its content decoded."""',
        f"    unwrapped = {frames}.unwrap(frame)",
        "    code, content = unwrapped.code, unwrapped.content",
    ]
    return _engine_decode(decode, target), wrap


def _engine_decode(decode: Lines, target: Target) -> Lines:
    """The engine's decode function, its content dispatched by code (and by the expected class)."""
    arguments = "content, 0, len(content), *unwrapped.values"
    arguments += "".join(f", unwrapped.extras.get({name!r})" for name in target.optional)
    refusing = (
        [
            "    if unwrapped.layout.error:  # an error header: the error reply, refusing the request of `code`",
            f"        return _{target.upper}_DECODERS[ERROR_REPLY]({arguments}, code)",
        ]
        if target.refusing
        else []
    )
    if target.refusals:  # the frame engine read a reply refusing the request in that reply's own layout
        refusing += [
            "    if unwrapped.reply:  # a reply that refuses the request (`refused_by`), in its own layout",
            f"        expect = _{target.upper}_REFUSALS[unwrapped.reply]",
        ]
    status = f"unwrapped.values[{target.value_names.index(target.error_status)}]" if target.error_status else ""
    dispatched = dispatch_lines(target, "code", arguments, nullable=True, status=status)
    return [*decode, *refusing, *(f"    {line}" for line in dispatched)]


def choice_lines(layouts: tuple[Layout, ...], d: str, bodies: list[Lines] | None = None) -> Lines:
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
    positions = Positions(layout)
    entries: list[tuple[bytes, str, str]] = []
    for code, size, cls, content, fmt in plain:
        if layout.codes is not None and code not in layout.codes:
            continue  # sent in another layout
        head = b""
        for element in elements[: layout.content]:
            if element.kind == "constant":
                head += element.constant
            elif element.kind == "command":
                head += element.pack(code)
            else:  # a length: the bytes it counts, given the content's size
                a, b = element.span
                counted = size_of(elements[a : b + 1]) + element.adds + (size if a <= layout.content <= b else 0)
                if not 0 <= counted < 1 << (8 * element.size):
                    break
                head += element.pack(counted)
        else:
            name = f"_F_{d.upper()}_WHOLE_{content}"  # the content's struct in the frame
            structs[name] = f"{fmt[0]}{positions.content}x{fmt[1:]}{positions.behind}x"
            entries.append((head, cls, name))
    if not entries:
        return [], []

    tail = Positions(layout, from_end=True)  # the elements after the content, counted back from the frame's end
    conditions: Lines = []
    for index, element in enumerate(elements[layout.content + 1 :], layout.content + 1):
        if element.kind == "constant" and element.size == 1:  # constants first: cheaper than a checksum
            conditions.insert(0, f"frame[{tail.at(index)}] == {element.constant[0]:#04x}")
        elif element.kind == "constant":
            stop = tail.stop(index)
            conditions.insert(0, f"frame[{tail.at(index)}:{'' if stop == '0' else stop}] == {element.constant!r}")
        elif element.kind == "checksum":
            residue = crc_residue(element)
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
