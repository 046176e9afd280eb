"""Encoding frames in straight-line code, for every framing: the direction's `_wrap_<direction>` function as
Layout.wrap makes the frame (`wrap_parts`, `wrap_lines`), an encoder's frame made inline (`frame_encoder`), and the
length-byte case's encoders (`length_byte_frame`: the head packed with the content, the checksum appended)."""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Protocol as Interface

from serialspec.backends.common.frames import layout_index, length_limits, optional_elements
from serialspec.backends.python.checksum_code import (
    checksum_expression,
    checksum_lines,
)
from serialspec.backends.python.frames.layouts import (
    STRUCT_CHARS,
    Lines,
    Positions,
    StraightLayouts,
    Structs,
    Target,
    plus,
    size_of,
    stuffing_of,
    variable_span,
)
from serialspec.backends.python.ir import (
    Block,
    Code,
    If,
    Literal,
    Pack,
    PackItems,
    Raise,
    Simple,
    packed_lists,
)
from serialspec.backends.python.kinds import (
    byte_order_free,
    fixed_runs,
    is_fixed_run_member,
    one_order,
    run_endian,
    struct_format,
)
from serialspec.backends.python.optimize import field_read
from serialspec.lang.model import (
    Bytes,
    Direction,
    FrameLayout,
    Message,
    Protocol,
)
from serialspec.lang.model import Field as SpecField
from serialspec.runtime.framing import Element, Layout


class PackageCode(Interface):
    """What the frame around a message's content asks of the content's code (content.PackageCode, which calls
    message_frame: this module does not import it)."""

    protocol: Protocol
    structs: dict[str, str]

    def straight(self, direction: Direction) -> StraightLayouts | None: ...

    def struct(self, base_name: str, fmt: str) -> str: ...

    def encode_fields(self, fields: list[SpecField], base: str, obj: str, body: Block, where: str) -> list[str]: ...

    def encode_run_format(
        self, run: list[SpecField], obj: str, siblings: list[SpecField], body: Block, where: str
    ) -> tuple[str, str, list[str]]: ...

    def encode_run(
        self, run: list[SpecField], base: str, obj: str, siblings: list[SpecField], body: Block, where: str
    ) -> str: ...

    def encode_variable(self, f: SpecField, obj: str, body: Block, where: str) -> str: ...


@dataclass
class LayoutEncoding:
    """One layout's encoding, in three parts: `prelude` computes the stuffed span and the lengths, `fits` says
    whether every length fits its element (with the EncodeError a layout raises when one does not), `rest` makes
    and returns the frame."""

    prelude: Lines
    fits: list[tuple[str, str]]  # condition that the length fits, the error when it does not
    rest: Lines


def packed_bytes(
    elements: tuple[Element, ...], indices: list[int], argument: Callable[[int], str], struct: Structs
) -> str:
    """One expression for the bytes of these elements: a Literal, else one struct's Pack (neighbouring constants
    as one `Ns` argument); `argument`: the expression of each non-constant element's value."""
    if not indices:
        return ""
    if all(elements[i].kind == "constant" for i in indices):
        return Literal(b"".join(elements[i].constant for i in indices))
    fmt, arguments = struct_order(elements, indices), []
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
            fmt += STRUCT_CHARS[elements[i].size]
            arguments.append(argument(i))
    return Pack(struct(fmt), arguments)


def struct_order(elements: tuple[Element, ...], indices: list[int]) -> str:
    """The struct byte order of these elements' values (straight() allows one for the multi-byte ones)."""
    multi = {elements[i].endian for i in indices if elements[i].kind != "constant" and elements[i].size > 1}
    return ">" if multi == {"big"} else "<"


def value_arguments(layout: Layout, code: str, values: list[str]) -> Callable[[int], str]:
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
) -> LayoutEncoding:
    """The frame around `content`, as Layout.wrap makes it. `checks` and `transparency` as for decode_lines;
    `struct` names the struct constants it uses."""
    positions = Positions(layout)
    elements = layout.elements
    prelude: Lines = []
    argument = value_arguments(layout, "code", [f"v_{v}" for v in target.value_names])

    def packed(indices: list[int]) -> str:
        return packed_bytes(elements, indices, argument, struct)

    first, last = positions.first, positions.last
    c = layout.content
    around = (packed(list(range(first, c))), "content", packed(list(range(c + 1, last + 1))))
    variable = " + ".join(p for p in around if p)
    t = stuffing_of(layout)
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
    if layout.codes is not None:  # its command element holds some codes: the others travel in a later layout
        fits.append((f"code in {set(layout.codes)!r}", 'raise EncodeError(f"no layout sends code {code}")'))
    for element in elements:
        if element.kind != "length":
            continue
        a, b = element.span
        if a <= first and last <= b:  # the wire bytes of the variable part and the fixed ones around it
            fixed = size_of(elements[a : b + 1]) - size_of(elements[first : last + 1])
            value = plus(f"len({'content' if t is None else 'wire'})", fixed + element.adds)
        elif a <= c <= b:  # inside the stuffed span: plain bytes
            value = plus("len(content)", size_of(elements[a : b + 1]) + element.adds)
        else:
            value = str(size_of(elements[a : b + 1]) + element.adds)
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
        if element.limits is not None:
            low, high = element.limits
            fits.append(
                (
                    f"{low} <= {name} <= {high}",
                    f'raise EncodeError(f"{layout.name} frame: {element.name} = {{{name}}} is outside its range '
                    f'{low}..{high}")',
                )
            )
    frame = " + ".join(p for p in (packed(list(range(first))), wire) if p)
    rest = closing_lines(layout, frame, checks, packed)
    return LayoutEncoding(prelude, fits, rest)


def closing_lines(layout: Layout, frame: str, checks: dict[int, str], packed: Callable[[list[int]], str]) -> Lines:
    """Lines that return the frame `frame` (an expression: everything up to the variable part's end) with the
    elements after it: constants and values packed, each checksum computed over what is written before it."""
    elements = layout.elements
    last = variable_span(layout)[1]
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
        begin = size_of(elements[:a])
        between = size_of(elements[b + 1 : index])
        # all after the variable part: counted back from the end of what is written
        begin_expr = str(-size_of(elements[a:index])) if a > last else str(begin) if begin else ""
        stop = str(-between) if between else ""
        covered = f"frame[{begin_expr}:{stop}]" if begin_expr or stop else "frame"
        lines.append(f"frame = {frame}")
        frame = f"frame + {checks[index].format(covered)}.to_bytes({element.size}, {element.endian!r})"
    if pending:
        frame = f"{frame} + {packed(pending)}"
    return [*lines, f"return {frame}"]


def wrap_lines(direction: str, layouts: list[LayoutEncoding], target: Target) -> Lines:
    """`def _wrap_<direction>(content, code, *values) -> bytes`: the frame in the first layout whose lengths can
    count it (as FrameCodec.wrap chooses), each layout's code inline."""
    parameters = ", ".join(["content: bytes", "code: int | None", *(f"v_{v}: int" for v in target.value_names)])
    doc = (
        "in the first layout that holds its code and whose length can count it"
        if len(layouts) > 1
        else "EncodeError if it cannot be"
    )
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
            lengths[index] = size_of(layout.elements[a : b + 1]) + element.adds
            if a <= layout.content <= b:  # it counts the content: known here only for a content of one size
                if size is None:
                    return None
                lengths[index] += size
        if all(_holds(layout.elements[i], value) for i, value in lengths.items()):
            chosen = (layout, checks, lengths)
            break
    if chosen is None:
        return None  # no layout can count it: the wrap function says so
    layout, checks, lengths = chosen
    lines = _frame_lines(layout, checks, lengths, parts, formats, code, values, struct)
    # the frame is made in the first statement: the one that packs the content's lists
    return [Code(lines[0], lists=packed_lists(parts)), *(Code(line) for line in lines[1:])]


def _holds(element: Element, value: int) -> bool:
    """A length element can send `value`: its bytes hold it and its `range` (if any) takes it."""
    return 0 <= value < 1 << (8 * element.size) and not element.length_outside(value)


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
    argument = value_arguments(layout, code, values)

    def constant_or(index: int) -> str:
        return Simple(lengths[index]) if index in lengths else argument(index)

    head = list(range(layout.content))
    prefix = _fixed_prefix(layout, lengths)
    if prefix is not None:  # the checksum covers all after constant bytes: they are a literal, not packed
        head = head[len(prefix[1]) :]
    first = parts[0] if parts and isinstance(parts[0], Pack) else None
    fmt = formats.get(first.struct, "") if first else ""
    order = struct_order(elements, head)
    packed = None  # (format, arguments) where the frame up to the checksum is one pack of them
    multi = any(elements[i].kind != "constant" and elements[i].size > 1 for i in head)
    if head and first and fmt[:1] in "<>" and (fmt[0] == order or not multi):
        # the head's elements joined to the content's first struct: one pack for both
        fused = packed_bytes(elements, head, constant_or, lambda f: f)  # named by its format
        if isinstance(fused, Pack):
            static, arguments = fmt[0] + fused.struct[1:] + fmt[1:], [*fused.arguments, *first.arguments]
            run = parts[1] if len(parts) > 1 and isinstance(parts[1], PackItems) else None
            if run and run.order == static[0]:  # and a run of numbers after it, in the same byte order
                fstring = "f" + repr(static + run.counted_format)
                parts = [f"struct.pack({fstring}, {', '.join(arguments)}, *{run.items})", *parts[2:]]
            else:
                parts = [Pack(struct(static), arguments), *parts[1:]]
                packed = (static, arguments) if len(parts) == 1 else None
        else:  # constants only: a literal
            parts = [f"{fused} + {parts[0]}", *parts[1:]]
    else:
        parts = [p for p in (packed_bytes(elements, head, constant_or, struct), *parts) if p]
    frame = " + ".join(parts) if parts else "b''"
    if prefix is not None:
        # the checksum over what was packed, the constants before it added as they are (no slice to make)
        literal, _, index = prefix
        element = elements[index]
        check = checks[index].format("body")
        after = packed_bytes(elements, list(range(index + 1, len(elements))), constant_or, struct)
        # one join: cheaper than three or four concatenations, each of which makes a bytes object
        pieces = [repr(literal), "body", f"{check}.to_bytes({element.size}, {element.endian!r})"]
        pieces += [after] if after else []
        whole = _repacked(packed, literal, element, check, after)
        if whole is not None:
            # the checksum needs the packed bytes; the frame is then one more pack of the same values, cheaper
            # than joining the pieces
            return [f"body = {frame}", f"return {struct(whole[0])}.pack({whole[1]})"]
        return [f"body = {frame}", f"return b''.join(({', '.join(pieces)}))"]
    return closing_lines(layout, frame, checks, lambda indices: packed_bytes(elements, indices, constant_or, struct))


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


# --- the length-byte case's encoders and every encoder's frame ------------------------------------------------------


def message_frame(package: PackageCode, message: Message, frame_values: list[str], body: Block, where: str) -> Block:
    """An encoder's statements after its frame values' range checks (`body`, which it extends): the content's
    bytes (PackageCode's field code) and the frame around them. `frame_values`: the frame values' expressions."""
    layout = package.protocol.layout(message)
    error = package.protocol.error_reply if message.error_reply else None
    fields = list(message.fields)
    command_code = package.protocol.command(message.command).wire_code(message.direction)
    if not package.protocol.framing.classic:
        # every other framing: the frame made inline, else by the direction's wrap
        parts = package.encode_fields(fields, message.class_name, "m", body, where)
        content = parts[0] if len(parts) == 1 else f"b''.join(({', '.join(parts)},))" if parts else "b''"
        if message.padded is not None:  # truncate: trailing_zeros, at least one byte kept
            body.append(Code(f"content = {content}.rstrip(b'\\x00') or b'\\x00'", lists=packed_lists(parts)))
            content, parts = "content", ["content"]
        code: str = Simple(f"{command_code:#04x}" if command_code is not None and layout.has_command else "None")
        if error is not None:
            code = field_read("m", error.element) + (f" | {error.flag:#04x}" if error.flag else "")
        frames = package.straight(message.direction)
        refusing = error is not None and error.by_header  # under the error header: its layouts alone
        if frames:
            kept = [
                i
                for i, layout in enumerate(frames.layouts)
                if layout.error == refusing
                and (refusing or layout.codes is None or command_code is None or command_code in layout.codes)
            ]
            frames = replace(
                frames,
                layouts=tuple(frames.layouts[i] for i in kept),
                checks=tuple(frames.checks[i] for i in kept),
                algorithms=tuple(frames.algorithms[i] for i in kept),
            )
        size = message.min_size if message.min_size == message.max_size and message.padded is None else None
        name = f"frame_{message.class_name}"
        inline = frames and frame_encoder(
            frames, parts, package.structs, code, frame_values, size, lambda fmt: package.struct(name, fmt)
        )
        optional = optional_elements(package.protocol, message.direction)
        extras = "".join(f", {e.name}=m.{e.name}" for e in optional)
        guard: Block = []
        if frames and optional:  # straight-line frames: one with optional elements' bytes is the engine's
            given = " or ".join(f"m.{e.name} is not None" for e in optional)
            engine = Code(
                f"return _wrap_{message.direction.value}_engine({', '.join([content, code, *frame_values])}{extras})",
                lists=packed_lists(parts),
            )
            guard, extras = [If(given, (engine,))], ""
        if inline:  # the frame made here: no call of the direction's wrap
            return [*body, *guard, *inline]
        body += guard
        arguments = ", ".join([content, code, *frame_values])
        framing = package.protocol.framing
        if refusing and frames:  # the error header's wrap
            body.append(Code(f"return _wrap_response_error({arguments})", lists=packed_lists(parts)))
            return body
        if refusing:  # the engine's, in the error header's layout
            values = f"({', '.join(frame_values)},)" if frame_values else "()"
            index = layout_index(package.protocol, message)
            wrap = f"return _RESPONSE_FRAMES.wrap({content}, {code}, {values}, {index})"
            body.append(Code(wrap, lists=packed_lists(parts)))
            return body
        if framing.requesting:  # its layout, and the request a reply answers
            index = layout_index(package.protocol, message)
            if asked_size(message):  # as many last bytes as the request asks for: refused otherwise
                body.append(Code(f"_RESPONSE_FRAMES.asked({message.class_name}, {content}, request, EncodeError)"))
            first = framing.layouts[message.direction]
            if [e.name for e in layout.value_elements] != [e.name for e in first.value_elements]:
                # layouts chosen by command with values of their own: the engine takes this layout's
                values = f"({', '.join(frame_values)},)" if frame_values else "()"
                wrap = f"return _{message.direction.name}_FRAMES.wrap({content}, {code}, {values}, {index}, "
                body.append(Code(f"{wrap}_request_parts(request){extras})", lists=packed_lists(parts)))
                return body
            arguments += f", {index}, request"
        arguments += extras
        body.append(Code(f"return _wrap_{message.direction.value}({arguments})", lists=packed_lists(parts)))
        return body
    code = str(command_code if command_code is not None else 0)
    if all(is_fixed_run_member(f) for f in fields) and one_order(fields):
        # one fixed size: the whole frame but its checksum is one struct, the length byte a constant
        endian, content_format, args = package.encode_run_format(fields, "m", fields, body, where)
        head = head_struct(package, layout, endian, code, message.min_size + layout.length_adds, frame_values)
        if head is not None:
            head_format, head_args = head
            name = package.struct(f"frame_{message.class_name}", endian + head_format + content_format)
            body.append(Code(f"body = {name}.pack({', '.join([*head_args, *args])})"))
            body.extend(checksum_append(package, layout, "body"))
            return body
        parts = []
        if fields:
            name = package.struct(f"{message.class_name}_{fields[0].name}", endian + content_format)
            parts.append(Pack(name, args))
    else:
        runs = list(fixed_runs(fields))
        if len(runs) > 1 and isinstance(runs[0], list):
            # a leading run of fixed fields is packed with the frame's head: one struct call and one bytes
            # object less per frame (the head is little-endian, so the run must be too, or all single bytes)
            endian = run_endian(runs[0])
            if endian == "<" or byte_order_free(struct_format("", runs[0])):
                _, run_format, run_args = package.encode_run_format(runs[0], "m", fields, body, where)
                rest = [
                    package.encode_run(item, message.class_name, "m", fields, body, where)
                    if isinstance(item, list)
                    else package.encode_variable(item, "m", body, where)
                    for item in runs[1:]
                ]
                content = rest[0] if len(rest) == 1 else f"b''.join(({', '.join(rest)},))"
                body.append(Code(f"content = {content}", lists=packed_lists(rest)))
                body.extend(length_byte_lines(package, layout, code, frame_values, (run_format, run_args)))
                return body
        parts = package.encode_fields(fields, message.class_name, "m", body, where)
    content = parts[0] if len(parts) == 1 else f"b''.join(({', '.join(parts)},))"
    body.append(Code(f"content = {content if parts else repr(b'')}", lists=packed_lists(parts)))
    body.extend(length_byte_lines(package, layout, code, frame_values))
    return body


def head_struct(
    package: PackageCode, layout: FrameLayout, endian: str, code: str, length: int | str, values: list[str]
) -> tuple[str, list[str]] | None:
    """Struct format (no byte order) and arguments of the frame elements before the content.

    None when the head cannot share the content's struct: a multi-byte frame element in a big-endian content
    (frame elements are little-endian), or a constant length that does not fit its element.
    """
    assert [e.role for e in layout.elements[-2:]] == ["content", "checksum"]  # the resolver checks both
    chars: list[str] = []
    args: list[str] = []
    remaining = iter(values)
    for element in layout.elements[:-2]:
        if element.role == "header":
            chars.append(f"{len(layout.header)}s")
            args.append(repr(layout.header))
            continue
        assert element.type is not None
        if element.type.size > 1 and endian != "<":
            return None
        chars.append(element.type.struct_char)
        if element.role == "command":
            args.append(code)
        elif element.role == "length":
            if isinstance(length, int) and not element.minimum <= length <= element.maximum:
                return None  # (its range refused by length_byte_lines)
            args.append(str(length))
        else:  # address, status: the message's frame values, in element order
            args.append(next(remaining))
    return "".join(chars), args


def checksum_append(package: PackageCode, layout: FrameLayout, body: str) -> Block:
    """Statements that return `body` (the frame without its checksum) with its checksum appended."""
    covered = f"{body}[{layout.covered_from}:]" if layout.covered_from else body
    size = layout.checksum_offset_from_end
    checksum = package.protocol.framing.checksum
    assert checksum is not None  # length-byte frames have one
    value = checksum_expression(checksum, covered)
    skipped = layout.header[: layout.covered_from]
    less = checksum.algorithm.byte_total(f"sum({body}) - {sum(skipped):#x}")
    if less is not None and layout.covered_from and len(skipped) == layout.covered_from:
        # the bytes before the covered ones are the header, a constant: the sum less it, no slice made
        value = less
    lines: Block = []
    if value is None:  # computed by statements into `check`; else the one expression is appended directly
        lines, value = [Code(line) for line in checksum_lines(checksum, covered, "check")], "check"
    tail = f"_BYTES[{value}]" if size == 1 else f"({value}).to_bytes({size}, 'little')"
    return [*lines, Code(f"return {body} + {tail}")]


def length_byte_lines(
    package: PackageCode, layout: FrameLayout, code: str, values: list[str], prefix: tuple[str, list[str]] | None = None
) -> Block:
    """Statements that return the frame around the bytes in `content`: inline in each encoder, not a call per
    frame. `prefix`: struct format (little-endian) and arguments of the content's first fields, packed with the
    head."""
    prefix_format, prefix_args = prefix or ("", [])
    adds = layout.length_adds + struct.calcsize("<" + prefix_format)
    body: Block = [Code(f"n = len(content) + {adds}" if adds else "n = len(content)")]
    length = next(e for e in layout.elements if e.role == "length")
    assert length.type is not None
    size = f"n - {layout.length_adds}" if layout.length_adds else "n"
    error = f"EncodeError(f'content of {{{size}}} bytes does not fit the length field')"
    body.append(If(f"n > {int(length.type.maximum)}", (Raise(error),)))
    limits = length_limits(length)
    if limits is not None:
        low, high = limits
        shown = f"{layout.direction.value} frame: {length.name} = {{n}} is outside its range {low}..{high}"
        body.append(If(f"not {low} <= n <= {high}", (Raise(f'EncodeError(f"{shown}")'),)))
    head = head_struct(package, layout, "<", code, "n", values)
    assert head is not None  # little-endian and a length computed at run time: always possible
    head_format, head_args = head
    base = f"head_{layout.direction.value}" + (f"_{prefix_format}" if prefix_format else "")
    name = package.struct(base, "<" + head_format + prefix_format)
    body.append(Code(f"body = {name}.pack({', '.join([*head_args, *prefix_args])}) + content"))
    body.extend(checksum_append(package, layout, "body"))
    return body


def asked_size(message: Message) -> bool:
    """A reply whose last bytes are as many as a field of its request says (`size_from`), in frames without a
    length (the runtime's SizeRule with `request`)."""
    last = message.fields[-1] if message.fields else None
    return message.direction == Direction.RESPONSE and isinstance(last, Bytes) and bool(last.size_from)
