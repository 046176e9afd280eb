"""The C99 target: one folder per protocol with `<p>.h`, `<p>.c` (types, encoders, decoders, checksums, the
incremental parser) and `<p>_json.h`, `<p>_json.c` (a formatter for hosts, logs and tests).

Everything comes from the resolved model. The frame layouts become static const tables that a small frame engine
(engine.py, the runtime's framing.py as C) walks to encode and to take stuffed frames apart; a layout without byte
stuffing is also sized and taken apart by straight-line code (files.py), so a build that only parses and decodes
carries no table; each message's content becomes straight-line code. Features the
C target cannot generate yet raise Unsupported naming the feature (`serialspec generate --target c` refuses the spec).
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, assert_never

from serialspec.backends import Unsupported
from serialspec.backends.c import packed
from serialspec.backends.c.checksums import c_checksum
from serialspec.backends.common.text import collapse
from serialspec.checksums.base import CCode
from serialspec.encodings import bit_run, varint
from serialspec.lang import counts, expression
from serialspec.lang.expression import Expr
from serialspec.lang.model import (
    SCALARS,
    Array,
    BitField,
    Bytes,
    Checksum,
    Counted,
    Direction,
    Field,
    FrameLayout,
    Group,
    List,
    Message,
    Packed,
    Protocol,
    Scalar,
    ScalarType,
    TableBlock,
    TableValue,
    Text,
    Varint,
    fixed_bits,
)
from serialspec.transforms.replace import Replace

#: Default capacities where the spec sets no smaller bound (each overridable with #define before the header).
DEFAULT_MAX_BYTES = 256  # bytes, text, per field
DEFAULT_MAX_ITEMS = 32  # items of a group, per field
DEFAULT_MAX_FRAME = 1024  # the parser's buffer and the encoder's scratch, when the spec allows bigger frames

C_KEYWORDS = frozenset(
    [
        "auto",
        "break",
        "case",
        "char",
        "const",
        "continue",
        "default",
        "do",
        "double",
        "else",
        "enum",
        "extern",
        "float",
        "for",
        "goto",
        "if",
        "inline",
        "int",
        "long",
        "register",
        "restrict",
        "return",
        "short",
        "signed",
        "sizeof",
        "static",
        "struct",
        "switch",
        "typedef",
        "union",
        "unsigned",
        "void",
        "volatile",
        "while",
        "bool",
        "true",
        "false",
        "class",
        "new",
        "delete",
        "this",
        "template",
        "typename",
        "private",
        "public",
        "protected",
        "operator",
        "friend",
        "virtual",
    ]
)


def ident(name: str) -> str:
    """A spec name as a C identifier (a keyword of C or C++ gets a trailing underscore)."""
    text = "".join(ch if ch.isalnum() or ch == "_" else "_" for ch in name)
    if text[:1].isdigit():
        text = "_" + text
    return text + "_" if text in C_KEYWORDS else text


def comment(text: str) -> str:
    """Spec text inside a C comment: one line, no comment end, no trigraph (`??/` at a line's end splices it)."""
    return collapse(text).replace("*/", "* /").replace("/*", "/ *").replace("??", "? ?")


I32 = ScalarType("i32", 4, "i", True, False, -0x80000000, 0x7FFFFFFF)


def value_type(f: Scalar) -> ScalarType:
    """The C type a scalar's value takes: its own, or a signed 32-bit one for sign-magnitude numbers."""
    return I32 if f.sign_magnitude else f.type


def ctype(t: ScalarType) -> str:
    """The C type holding a scalar's value: 3-byte integers in 32 bits, f64 as double."""
    if t.is_float:
        return "double" if t.size == 8 else "float"
    bits = {1: 8, 2: 16, 3: 32, 4: 32, 8: 64}[t.size]
    return f"{'int' if t.signed else 'uint'}{bits}_t"


def wide(t: ScalarType) -> bool:
    """A scalar read and written as 64 bits (uint64_t on the wire side)."""
    return t.size == 8


def cint(value: float, t: ScalarType) -> str:
    """A literal of a scalar's type (float bounds as float literals, integers with their suffix)."""
    if t.is_float and wide(t):
        return f"{float(value)!r}"
    if t.is_float:
        return f"{float(value)!r}f" if abs(value) < 3.4e38 else ("3.40282347e+38f" if value > 0 else "-3.40282347e+38f")
    v = int(value)
    if wide(t):
        if t.signed:
            return f"({v + 1}LL - 1LL)" if v == -(1 << 63) else f"{v}LL"
        return f"{v}ULL"
    if t.signed:
        return f"({v + 1}L - 1L)" if v == -0x80000000 else f"{v}L"
    return f"{v}UL" if v > 0xFFFF else f"{v}u"


@dataclass
class Ctx:
    """What one protocol's generation collects: its names and the C text of each part."""

    protocol: Protocol
    p: str
    P: str
    checks: list[tuple[Checksum, CCode]] = field(default_factory=list)
    caps: list[str] = field(default_factory=list)  # #ifndef capacity defaults for the header
    structs: list[str] = field(default_factory=list)
    helpers: set[str] = field(default_factory=set)
    cap_defaults: dict[str, int] = field(default_factory=dict)  # capacity macro -> its default
    json_writers: set[str] = field(default_factory=set)  # the JSON writer functions called (wu, wi, wf, ...)

    counters: set[int] = field(default_factory=set)  # the loop depths the function being written counts with

    def counter(self, depth: int) -> str:
        """The loop counter of nesting `depth` (i1, i2, ...), which the function being written then declares."""
        self.counters.add(depth)
        return f"i{depth}"

    def loop(self, pad: str, depth: int, count: str) -> str:
        """The head of a loop over `count` items with the counter of nesting `depth`."""
        i = self.counter(depth)
        return f"{pad}for ({i} = 0u; {i} < {count}; {i}++) {{"

    def counter_locals(self) -> list[str]:
        """The declarations of the counters the function's loops used (and a fresh start for the next function)."""
        declared = [f"    size_t i{d};" for d in sorted(self.counters)]
        self.counters.clear()
        return declared

    def writer(self, name: str) -> str:
        """The JSON writer function `name` (p__wu, p__wbytes, ...), which its file then defines."""
        self.json_writers.add(name)
        return f"{self.p}__{name}"

    struct_members: dict[str, list[Any]] = field(default_factory=dict)  # item and block struct -> its Members
    message_members: dict[str, list[Any]] = field(default_factory=dict)  # message id -> its struct's Members
    # a spec with optional frame elements: the spec itself (`protocol` has the plain variants of its layouts in their
    # place) and each direction's variants (optional.py)
    original: Protocol | None = None
    variants: dict[Direction, tuple[Any, ...]] = field(default_factory=dict)

    def check_index(self, checksum: Checksum) -> int:
        for i, (known, _) in enumerate(self.checks):
            if (known.algorithm, known.type) == (checksum.algorithm, checksum.type):
                return i
        made = c_checksum(self.p, checksum)
        if any(made.name == c.name and made.definition != c.definition for _, c in self.checks):
            raise Unsupported(f"checksum {checksum.name}: two {checksum.algorithm.name} checksums that differ")
        self.checks.append((checksum, made))
        return len(self.checks) - 1


def const_wire(f: Scalar) -> int:
    """A field's constant as the wire bits the C reads and writes (get/put): a negative one in two's complement, or
    as sign and size (`sign_magnitude`); the C compared -3 with the bits read as -3UL (never equal)."""
    assert isinstance(f.const, int)
    bits = 8 * f.type.size
    if f.const < 0 and f.sign_magnitude:
        return (1 << (bits - 1)) | -f.const
    return f.const & ((1 << bits) - 1)


# --- what the C target can do --------------------------------------------------------------------------------------


def refuse_unsupported(protocol: Protocol) -> None:
    """Raise Unsupported naming the first feature of a binary spec the C target cannot generate yet (a text spec's:
    text.refuse)."""
    refuse_by_request(protocol)
    for command in protocol.commands:
        if command.selector is not None and command.selector.type.size > 4:
            raise Unsupported(f"sub-command selectors of more than four bytes (command {command.name})")
    for layouts in protocol.framing.alternatives.values():
        for layout in layouts:
            refuse_layout(layout)
    for message in protocol.messages():
        refuse_fields(message.fields, message.key)
    refuse_wide_values(protocol)


def refuse_by_request(protocol: Protocol) -> None:
    """Unsupported for frames the C decoder cannot read alone. Layouts chosen by command (`layout:`) generate where
    every frame still says how to read it (a header, or a code sent in one layout alone)."""
    framing = protocol.framing
    if framing.from_request and (framing.classic or any(layout.transparency for layout in every_layout(protocol))):
        raise Unsupported("a reply checksum over bytes of its request (`from_request`) in a classic or stuffed frame")
    for message in protocol.messages():
        sized = message.fields[-1] if message.fields else None
        if (
            isinstance(sized, Bytes)
            and sized.size_from
            and framing.layout_of(message.direction, message.layout).length is None
            and not framing.by_request(message.direction)
        ):
            raise Unsupported(  # the Python stream parser sizes it by the request awaited (runtime SizeRule.request)
                "a reply sized by a field of its request in a frame without a length, whose replies carry a code "
                f"({message.class_name}: `size_from`)"
            )
    if not framing.by_command:
        return
    for direction, layouts in framing.alternatives.items():
        if any(layout.transparency is not None or layout.optional for layout in layouts):
            raise Unsupported(
                f"layouts chosen by command with a frame transform or optional elements ({direction.value} frames)"
            )


def every_layout(protocol: Protocol) -> list[FrameLayout]:
    return [layout for layouts in protocol.framing.alternatives.values() for layout in layouts]


def refuse_layout(layout: FrameLayout) -> None:
    where = f"the {layout.direction.value} frame{' ' + layout.name if layout.name else ''}"
    elements = layout.elements
    for e in elements:
        if e.type is not None and (e.type.size > 4 or e.type.signed or e.type.is_float):
            raise Unsupported(f"{where}: element {e.name} of type {e.type.name}")
    t = layout.transparency
    if t is not None and t.transform.c_refusal():
        raise Unsupported(f"{where}: {t.transform.c_refusal()}")
    names = [e.name for e in elements]
    content = next((i for i, e in enumerate(elements) if e.role == "content"), -1)
    first = names.index(t.first) if t else content if content >= 0 else len(elements)
    last = names.index(t.last) if t else content if content >= 0 else len(elements) - 1
    length = next((i for i, e in enumerate(elements) if e.role == "length"), -1)
    inner = length >= 0 and t is not None and first <= length <= last
    code = t.transform.c_code("p") if t is not None else None
    readable = t is not None and (isinstance(t.transform, Replace) or (code is not None and bool(code.plain_prefix)))
    if t is not None and inner and (not readable or not plain_span(layout)):
        # (counting plain bytes of the span, under a substitution or a transform whose C has plain_prefix: the
        # engine reads it through them)
        raise Unsupported(f"{where}: a length inside the transformed span")
    if length >= 0 and length >= first and not inner:
        raise Unsupported(f"{where}: a length after the variable part of the frame")
    for i, e in enumerate(elements):
        if e.checksum is not None and e.checksum.skips and t is not None:
            raise Unsupported(
                f"{where}: checksum {e.name} over a span that leaves out {', '.join(e.checksum.skips)}, "
                "beside a transform"
            )
        if e.role == "checksum" and t is not None and e.checksum is not None:
            a, b = names.index(e.checksum.first), names.index(e.checksum.last)
            inside = first <= i <= last
            if inside and not (first <= a and b <= last):
                raise Unsupported(f"{where}: checksum {e.name} inside the stuffed span over bytes outside it")


def plain_span(layout: FrameLayout) -> bool:
    """The layout's length counts elements inside its transformed span (their plain bytes)."""
    t, length = layout.transparency, layout.length
    if t is None or length is None:
        return False
    names = [e.name for e in layout.elements]
    first, last = names.index(t.first), names.index(t.last)
    return first <= names.index(length.counts[0]) and names.index(length.counts[1]) <= last


def refuse_fields(fields: tuple[Field, ...], where: str, nested: bool = False) -> None:
    for f in fields:
        match f:
            case Scalar():
                if f.value is not None and nested:
                    raise Unsupported(f"{where}: {f.name}: a value computed by an expression inside a group")
                if f.sign_magnitude and wide(f.type):
                    raise Unsupported(f"{where}: {f.name}: sign-magnitude {f.type.name}")
            case Varint():
                if why := varint.c_problem(f.minimum, f.maximum, f.sign):
                    raise Unsupported(f"{where}: {f.name}: {why}")
            case Array() | Packed():
                pass
            case List():
                if f.item is not None and f.item.size not in (1, 2, 4, 8):
                    raise Unsupported(f"{where}: {f.name}: lists of {f.item.name}")
                if f.item is not None and f.item.is_float:
                    raise Unsupported(f"{where}: {f.name}: lists of floats")
            case Text() | Bytes():
                pass
            case Group():
                refuse_fields(f.fields, where, True)
            case TableValue() | TableBlock():
                entries = f.entries if isinstance(f, TableBlock) else f.table.entries
                for e in entries:
                    if e.type.is_float or e.sign_magnitude:
                        raise Unsupported(f"{where}: {f.name}: table entry {e.name} ({e.type.name}, sign-magnitude)")
            case _:
                assert_never(f)


# --- names -------------------------------------------------------------------------------------------------------


def msg_id(message: Message) -> str:
    return ident(f"{message.key.replace('.', '_')}_{message.direction.value}")


def messages(protocol: Protocol) -> list[Message]:
    return list(protocol.messages())


def value_elements(protocol: Protocol, message: Message) -> tuple[tuple[str, ScalarType], ...]:
    """The frame values a message's struct holds: its own layout's (layouts chosen by command may each have others),
    in the order the frame engine reads them into `values[]`."""
    layout = protocol.layout(message)
    return tuple((e.name, e.type) for e in layout.value_elements if e.type is not None)


def error_element(protocol: Protocol, message: Message) -> tuple[str, ScalarType] | None:
    """An error reply's extra member: the refused request's code, from the command element."""
    error = protocol.error_reply
    if not message.error_reply or error is None:
        return None
    element = next(e for e in protocol.framing.layouts[message.direction].elements if e.name == error.element)
    assert element.type is not None
    return error.element, element.type


# --- sizes and capacities ------------------------------------------------------------------------------------------


def frame_max(protocol: Protocol, direction: Direction) -> int | None:
    """The largest wire frame of a direction (None: unbounded), from the length element's range."""
    most = 0
    for layout in protocol.framing.alternatives[direction]:
        length = layout.length
        if length is None or length.type is None:
            return None
        a, b = layout.index(length.counts[0]), layout.index(length.counts[1])
        counted_fixed = sum(e.size or 0 for e in layout.elements[a : b + 1])
        top = (1 << (8 * length.type.size)) - 1
        most = max(most, layout.overhead - counted_fixed + top - length.adds)
    return most


def content_max(protocol: Protocol, direction: Direction) -> int:
    """The largest content a frame of this direction can hold (for capacities), capped for the default build."""
    most = frame_max(protocol, direction)
    overhead = min(layout.overhead for layout in protocol.framing.alternatives[direction])
    return min(DEFAULT_MAX_FRAME, most - overhead if most is not None else DEFAULT_MAX_FRAME)


# --- the header's types ------------------------------------------------------------------------------------------


@dataclass
class Member:
    """One member of a C struct for a visible field."""

    name: str
    decl: str
    doc: str
    ctype: str = ""  # its C type (of one item, for an array), and how many: a number or a capacity macro, and
    count: int | str = 1  # how many items beyond that (a text's NUL); what readme.py sizes the structs from
    extra: int = 0

    @property
    def dimension(self) -> str:
        """How many items, as the declaration writes it ("" for one)."""
        if self.count == 1 and not self.extra:
            return ""
        return f"[{self.count} + {self.extra}]" if self.extra else f"[{self.count}]"


def cap_macro(ctx: Ctx, path: str, default: int) -> str:
    macro = f"{ctx.P}_{path.upper()}_MAX"
    ctx.caps.append(f"#ifndef {macro}\n#define {macro} {default}u\n#endif")
    ctx.cap_defaults[macro] = default
    return macro


def field_doc(f: Field) -> str:
    parts = [comment(f.description)] if f.description else []
    if isinstance(f, Scalar | Array | List) and f.unit:
        parts.append(f"unit: {comment(f.unit)}")
    if isinstance(f, Scalar) and f.scale:
        parts.append(f"scale: {f.scale:g} per unit")
    if isinstance(f, Scalar) and f.offset:
        parts.append(f"offset: {f.offset:+g}")
    if isinstance(f, Scalar | Array) and not (isinstance(f, Scalar) and f.type.is_float):
        parts.append(f"range {f.minimum:g}..{f.maximum:g}")
    if isinstance(f, Scalar) and f.enum:
        parts.append(f"enum {f.enum.name}")
    if isinstance(f, Scalar) and f.bits:
        parts.append("bits " + ", ".join(f"{b.name} [{b.high}:{b.low}]" for b in f.bits))
    if f.description and len(parts) > 1:  # "First address to write; range 0..255", not "write.; range"
        parts[0] = parts[0].removesuffix(".")
    return "; ".join(parts)


def members(ctx: Ctx, fields: tuple[Field, ...], path: str, room: int) -> list[Member]:
    """The struct members of the visible fields (path: the capacity macros' stem; room: the content's max bytes)."""
    found: list[Member] = []
    for f in fields:
        name = ident(f.name)
        doc = field_doc(f)
        match f:
            case Scalar():
                if not f.hidden:
                    t = ctype(value_type(f))
                    found.append(Member(name, f"{t} {name};", doc, t))
            case Array():
                found.append(Member(name, f"{ctype(f.item)} {name}[{f.count}];", doc, ctype(f.item), f.count))
            case Bytes():
                if isinstance(f.size, int):
                    found.append(Member(name, f"uint8_t {name}[{f.size}];", doc, "uint8_t", f.size))
                else:
                    macro = cap_macro(ctx, f"{path}_{f.name}", min(room, DEFAULT_MAX_BYTES))
                    found.append(Member(name, f"uint8_t {name}[{macro}];", doc, "uint8_t", macro))
                    found.append(Member(f"{name}_len", f"size_t {name}_len;", f"bytes in {f.name}", "size_t"))
            case Text():
                size = f.size if isinstance(f.size, int) else min(room, DEFAULT_MAX_BYTES)
                if f.seven_bit:  # two wire bytes a character, up to three bytes of UTF-8 each
                    size = size // 2 * 3
                macro = cap_macro(ctx, f"{path}_{f.name}", size)
                text_doc = f"{doc} (in C: UTF-8, NUL-terminated)"  # the spec's description, then how C holds it
                found.append(Member(name, f"char {name}[{macro} + 1u];", text_doc, "char", macro, 1))
                found.append(Member(f"{name}_len", f"size_t {name}_len;", f"bytes of text in {f.name}", "size_t"))
            case Group():
                item = f"{ctx.p}_{path}_{f.name}_item_t"
                inner = members(ctx, f.fields, f"{path}_{f.name}", room)
                body = "\n".join(f"    {m.decl}{'  /* ' + m.doc + ' */' if m.doc else ''}" for m in inner)
                ctx.structs.append(
                    f"/* One item of {f.name}. */\ntypedef struct {{\n{body or '    uint8_t unused_;'}\n}} {item};\n"
                )
                ctx.struct_members[item] = inner or [Member("unused_", "uint8_t unused_;", "", "uint8_t")]
                if isinstance(f.count, int):
                    found.append(Member(name, f"{item} {name}[{f.count}];", doc, item, f.count))
                else:
                    size = f.item_size or 1
                    macro = cap_macro(ctx, f"{path}_{f.name}", max(1, min(room // size, DEFAULT_MAX_ITEMS)))
                    found.append(Member(name, f"{item} {name}[{macro}];", doc, item, macro))
                    found.append(Member(f"{name}_count", f"size_t {name}_count;", f"items in {f.name}", "size_t"))
            case TableValue():
                table_doc = doc + f"; its type is the {f.table.name} entry {f.key} names"
                found.append(Member(name, f"int64_t {name};", table_doc, "int64_t"))
            case TableBlock():
                block = f"{ctx.p}_{path}_{f.name}_t"
                body = "\n".join(
                    f"    {ctype(e.type)} {ident(e.name)};  /* {e.key}: {comment(e.description)[:80]} */"
                    for e in f.entries
                )
                ctx.structs.append(f"/* {comment(f.description)} */\ntypedef struct {{\n{body}\n}} {block};\n")
                ctx.struct_members[block] = [Member(ident(e.name), "", e.description, ctype(e.type)) for e in f.entries]
                found.append(Member(name, f"{block} {name};", doc, block))
            case List():
                if f.item is None:  # bits, 8 to a byte, the first in the lowest bit (as on the wire)
                    macro = cap_macro(ctx, f"{path}_{f.name}", max(1, min(room, DEFAULT_MAX_BYTES)))
                    bits_doc = doc + "; bits, 8 to a byte"
                    found.append(Member(name, f"uint8_t {name}[{macro}];", bits_doc, "uint8_t", macro))
                    found.append(Member(f"{name}_count", f"size_t {name}_count;", f"bits in {f.name}", "size_t"))
                else:
                    most = max(1, min(room // f.item.size, DEFAULT_MAX_BYTES))
                    macro = cap_macro(ctx, f"{path}_{f.name}", most)
                    found.append(Member(name, f"{ctype(f.item)} {name}[{macro}];", doc, ctype(f.item), macro))
                    found.append(Member(f"{name}_count", f"size_t {name}_count;", f"items in {f.name}", "size_t"))
            case Packed():
                t = ctype(packed.item_type(f))
                found.append(Member(name, f"{t} {name}[{f.count}];", doc, t, f.count))
            case Varint():
                found.append(Member(name, f"{ctype(f.type)} {name};", doc, ctype(f.type)))
            case _:
                assert_never(f)
    return found


# --- content decoders ----------------------------------------------------------------------------------------------


@dataclass
class Scope:
    """Names readable while decoding or encoding fields: hidden values in locals, visible ones in the struct."""

    target: str  # C expression of the struct being filled or read, with its member operator ("m->", "it->")
    names: dict[str, str]  # field name -> C expression of its value
    parent: Scope | None = None

    def lookup(self, name: str) -> str:
        scope: Scope | None = self
        while scope is not None:
            if name in scope.names:
                return scope.names[name]
            scope = scope.parent
        raise Unsupported(f"a size or count from field {name}, which the C target cannot reach")


def as_size(ctx: Ctx, pad: str, value: str, out: list[str]) -> str:
    """A size or count read from a field, as size_t: a value size_t cannot hold (a 64-bit one on a 32-bit target) is
    refused first, never cut to its low bits."""
    out.append(f"{pad}if ((uint64_t)(size_t)({value}) != (uint64_t)({value})) {{ return {ctx.P}_E_LENGTH; }}")
    return f"(size_t)({value})"


def count_size(
    ctx: Ctx, pad: str, count: str | Counted, scope: Scope, out: list[str], fields: tuple[Field, ...]
) -> str:
    """A count or size read from a field, or worked out by its expression over earlier fields (lang/counts.py), as
    size_t: a negative one is refused (P_E_CONTENT), one size_t cannot hold too (as_size)."""
    if isinstance(count, str):
        return as_size(ctx, pad, scope.lookup(count), out)
    value = count_expression(ctx, count, scope.lookup, fields)
    if count.low < 0:
        out.append(f"{pad}if ({value} < 0) {{ return {ctx.P}_E_CONTENT; }} /* a negative count: {count} */")
    return as_size(ctx, pad, value, out)


def count_expression(ctx: Ctx, count: Counted, name: Callable[[str], str], fields: tuple[Field, ...]) -> str:
    """A count's expression in C (int64_t) over the values `name` gives (its fields: no len(), no division by a field,
    no value beyond int64_t: refuse_wide_counts)."""
    return render_c(count.expr, name, c_length(fields, ""), math_of(ctx, fields))


def get_raw(ctx: Ctx, t: ScalarType, endian: str, at: str) -> str:
    """A scalar's wire bits: uint32_t, or uint64_t for 8-byte types (built with shifts, whatever the host)."""
    if wide(t):
        ctx.helpers.add("get64")
        return f"{ctx.p}__get64({at}, {1 if endian == '>' else 0}u)"
    ctx.helpers.add("get")
    return f"{ctx.p}__get({at}, {t.size}u, {1 if endian == '>' else 0}u)"


def put_call(ctx: Ctx, t: ScalarType, endian: str, at: str, value: str) -> str:
    """The statement writing a scalar's wire bits (scalar_bits) at `at`."""
    if wide(t):
        ctx.helpers.add("put64")
        return f"{ctx.p}__put64({at}, {1 if endian == '>' else 0}u, {value});"
    return f"{ctx.p}__put({at}, {t.size}u, {1 if endian == '>' else 0}u, {value});"


def read_scalar(ctx: Ctx, t: ScalarType, endian: str, at: str) -> str:
    raw = get_raw(ctx, t, endian, at)
    if t.is_float:
        ctx.helpers.add(f"f{t.size * 8}")
        return f"{ctx.p}__f{t.size * 8}({raw})"
    if t.signed:
        ctx.helpers.add(f"s{t.size * 8}")
        return f"{ctx.p}__s{t.size * 8}({raw})"
    return raw if t.size in (3, 4, 8) else f"({ctype(t)}){raw}"


def hidden_type(f: Scalar) -> str:
    """The local holding a hidden value's wire bits while decoding (a signed one's value)."""
    if f.type.signed:
        return "int64_t" if wide(f.type) else "int32_t"
    return "uint64_t" if wide(f.type) else "uint32_t"


def decode_fields(ctx: Ctx, fields: tuple[Field, ...], scope: Scope, out: list[str], depth: int) -> None:
    pad = "    " * depth
    for f in fields:
        name = ident(f.name)
        tgt = f"{scope.target}{name}"
        out.append(f"{pad}/* {f.name}{': ' + comment(f.description)[:90] if f.description else ''} */")
        match f:
            case Scalar():
                size = f.type.size
                place = f.bit_place
                if place is None or place.first:
                    run = size if place is None else place.size
                    out.append(f"{pad}if (n - o < {run}u) {{ return {ctx.P}_E_LENGTH; }}")
                # a hidden value keeps its wire bits, a signed one its value (as Python compares it); a constant
                # only its bits: no helper is written that nothing calls
                needs_value = f.const is None and (not f.hidden or f.type.signed) and not f.sign_magnitude
                needs_value = needs_value and f.low_bits is None
                value = read_scalar(ctx, f.type, f.endian, "c + o") if needs_value and place is None else ""
                if place is not None:  # a member of a bit run: its bits of the run (encodings/bit_run.py)
                    w = bit_run.c_width(place.bits)
                    ctx.helpers |= {f"bits{w}", f"sx{w}"} if f.type.signed else {f"bits{w}"}
                    raw = bit_run.c_decode(ctx.p, "c + o", place.bits, place.shift, place.size, False)
                    signed = bit_run.c_decode(ctx.p, "c + o", place.bits, place.shift, place.size, f.type.signed)
                    value = f"({ctype(f.type)}){signed}"
                    if f.const is not None:
                        out.append(f"{pad}if ({raw} != {f.const & place.mask}u) {{ return {ctx.P}_E_CONTENT; }}")
                    elif f.hidden:
                        local = f"d{depth}_{name}"
                        out.append(f"{pad}{local} = {signed if f.type.signed else raw};")
                        scope.names[f.name] = local
                    else:
                        out.append(f"{pad}{tgt} = {value};")
                        unsigned = not (wide(f.type) or f.type.signed)
                        scope.names[f.name] = f"(uint32_t){tgt}" if unsigned else tgt
                    if place.last:
                        out.append(f"{pad}o += {place.size}u;")
                    continue
                if (encoding := f.low_bits) is not None:  # a few bits a byte, the bits above them clear
                    raw = get_raw(ctx, f.type, f.endian, "c + o")
                    marks = encoding.marks(size)
                    out.append(f"{pad}if (({raw} & 0x{marks:x}UL) != 0u) {{ return {ctx.P}_E_CONTENT; }}")
                    value = f"({ctype(f.type)}){encoding.c_decode(raw, size, f.type.signed)}"
                if f.sign_magnitude:  # the top bit is the sign, the rest the magnitude
                    top = 1 << (8 * size - 1)
                    raw = f"{ctx.p}__get(c + o, {size}u, {1 if f.endian == '>' else 0}u)"
                    value = f"{ctx.p}__sm({raw}, 0x{top:x}UL)"
                    ctx.helpers |= {"sm", "get"}
                if f.const is not None:
                    out.append(
                        f"{pad}if ({get_raw(ctx, f.type, f.endian, 'c + o')} != "
                        f"{const_wire(f)}{'ULL' if wide(f.type) else 'UL'}) {{ return {ctx.P}_E_CONTENT; }}"
                    )
                elif f.hidden:
                    local = f"d{depth}_{name}"
                    read = value if f.type.signed else get_raw(ctx, f.type, f.endian, "c + o")
                    out.append(f"{pad}{local} = {read};")
                    scope.names[f.name] = local
                else:
                    out.append(f"{pad}{tgt} = {value};")
                    mask, bits = fixed_bits(f.bits)
                    if mask:  # constant bit fields, as Python's decode refuses
                        out.append(f"{pad}if (({tgt} & {mask}u) != {bits}u) {{ return {ctx.P}_E_CONTENT; }}")
                    # (a signed field keeps its sign: an expression of it, `n >> s`, sees the value, not its bits)
                    unsigned = not (f.type.is_float or wide(f.type) or f.type.signed)
                    scope.names[f.name] = f"(uint32_t){tgt}" if unsigned else tgt
                out.append(f"{pad}o += {size}u;")
            case Array():
                total = f.count * f.item.size
                out.append(f"{pad}if (n - o < {total}u) {{ return {ctx.P}_E_LENGTH; }}")
                out.append(ctx.loop(pad, depth, f"{f.count}u"))
                value = read_scalar(ctx, f.item, f.endian, f"c + o + i{depth} * {f.item.size}u")
                out.append(f"{pad}    {tgt}[i{depth}] = {value};")
                out.append(f"{pad}}}")
                out.append(f"{pad}o += {total}u;")
            case Bytes() | Text():
                terminated = isinstance(f, Text) and f.terminated
                if terminated:
                    out.append(f"{pad}for (k = o; k < n && c[k] != 0u; k++) {{ }}")
                    out.append(f"{pad}if (k >= n) {{ return {ctx.P}_E_CONTENT; }}")
                    out.append(f"{pad}len = k - o;")
                elif isinstance(f.size, int):
                    out.append(f"{pad}len = {f.size}u;")
                elif f.size == "rest":
                    out.append(f"{pad}len = n - o;")
                elif f.size is not None:
                    out.append(f"{pad}len = {count_size(ctx, pad, f.size, scope, out, fields)};")
                if not terminated:
                    out.append(f"{pad}if (n - o < len) {{ return {ctx.P}_E_LENGTH; }}")
                if isinstance(f, Text) and f.pad is not None:  # the text without the pad bytes after it
                    out.append(f"{pad}for (k = len; k > 0u && c[o + k - 1u] == 0x{f.pad:02x}u; k--) {{ }}")
                    out.append(f"{pad}if (k > sizeof({tgt}) - 1u) {{ return {ctx.P}_E_CAPACITY; }}")
                    out.append(f"{pad}if (!{ctx.p}__utf8(c + o, k)) {{ return {ctx.P}_E_CONTENT; }}")
                    ctx.helpers.add("utf8")
                    out.append(f"{pad}memcpy({tgt}, c + o, k);")
                    out.append(f"{pad}{tgt}[k] = '\\0';")
                    out.append(f"{pad}{tgt}_len = k;")
                    out.append(f"{pad}o += len;")
                elif isinstance(f, Text) and f.seven_bit:  # 14-bit characters, two 7-bit bytes each, to UTF-8
                    get = f"{ctx.p}__text14_get({tgt}, sizeof({tgt}), &{tgt}_len, c + o, len)"
                    out.append(f"{pad}if (!{get}) {{ return {ctx.P}_E_CONTENT; }}")
                    ctx.helpers.add("text14_get")
                    out.append(f"{pad}o += len;")
                elif isinstance(f, Text):
                    out.append(f"{pad}if (len > sizeof({tgt}) - 1u) {{ return {ctx.P}_E_CAPACITY; }}")
                    out.append(f"{pad}if (!{ctx.p}__utf8(c + o, len)) {{ return {ctx.P}_E_CONTENT; }}")
                    ctx.helpers.add("utf8")
                    out.append(f"{pad}{ctx.p}__copy({tgt}, c + o, len);")
                    ctx.helpers.add("copy")
                    out.append(f"{pad}{tgt}[len] = '\\0';")
                    out.append(f"{pad}{tgt}_len = len;")
                    out.append(f"{pad}o += len{' + 1u' if terminated else ''};")
                else:
                    if not isinstance(f.size, int):
                        out.append(f"{pad}if (len > sizeof({tgt})) {{ return {ctx.P}_E_CAPACITY; }}")
                    out.append(f"{pad}{ctx.p}__copy({tgt}, c + o, len);")
                    ctx.helpers.add("copy")
                    if not isinstance(f.size, int):
                        out.append(f"{pad}{tgt}_len = len;")
                    out.append(f"{pad}o += len;")
            case Group():
                i = f"i{depth}"
                item_scope = Scope(f"{tgt}[{i}].", {}, scope)
                body: list[str] = []
                hidden = [x for x in f.fields if isinstance(x, Scalar) and x.hidden and x.const is None]
                for h in hidden:
                    body.append(f"{pad}    {hidden_type(h)} d{depth + 1}_{ident(h.name)};")
                decode_fields(ctx, f.fields, item_scope, body, depth + 1)
                capacity = f"(sizeof({tgt}) / sizeof({tgt}[0]))"
                if isinstance(f.count, int) or f.count != "rest":
                    count = (
                        f"{f.count}u" if isinstance(f.count, int) else count_size(ctx, pad, f.count, scope, out, fields)
                    )
                    if not isinstance(f.count, int):
                        out.append(f"{pad}if ({count} > {capacity}) {{ return {ctx.P}_E_CAPACITY; }}")
                        out.append(f"{pad}{tgt}_count = {count};")
                    out.append(ctx.loop(pad, depth, count))
                    out.extend(body)
                    out.append(f"{pad}}}")
                elif f.item_size is not None:
                    out.append(f"{pad}if ((n - o) % {f.item_size}u != 0u) {{ return {ctx.P}_E_LENGTH; }}")
                    out.append(f"{pad}if ((n - o) / {f.item_size}u > {capacity}) {{ return {ctx.P}_E_CAPACITY; }}")
                    out.append(f"{pad}{tgt}_count = (n - o) / {f.item_size}u;")
                    out.append(ctx.loop(pad, depth, f"{tgt}_count"))
                    out.extend(body)
                    out.append(f"{pad}}}")
                else:
                    out.append(f"{pad}{tgt}_count = 0u;")
                    out.append(f"{pad}for ({ctx.counter(depth)} = 0u; o < n; {i}++) {{")
                    out.append(f"{pad}    if ({i} >= {capacity}) {{ return {ctx.P}_E_CAPACITY; }}")
                    out.extend(body)
                    out.append(f"{pad}    {tgt}_count = {i} + 1u;")
                    out.append(f"{pad}}}")
            case TableValue():
                key = scope.lookup(f.key)
                out.append(f"{pad}switch ({key}) {{")
                for e in f.table.entries:
                    if e.reserved:
                        continue
                    size = e.type.size
                    value = read_scalar(ctx, e.type, f"{'>' if ctx.protocol.byte_order == 'big' else '<'}", "c + o")
                    out.append(f"{pad}case {e.key}u: /* {e.name} */")
                    out.append(f"{pad}    if (n - o < {size}u) {{ return {ctx.P}_E_LENGTH; }}")
                    out.append(f"{pad}    {tgt} = (int64_t){value};")
                    out.append(f"{pad}    o += {size}u;")
                    out.append(f"{pad}    break;")
                out.append(f"{pad}default:")
                out.append(f"{pad}    return {ctx.P}_E_CONTENT; /* a key the table does not define */")
                out.append(f"{pad}}}")
            case TableBlock():
                total = sum(e.type.size for e in f.entries)
                out.append(f"{pad}if (n - o < {total}u) {{ return {ctx.P}_E_LENGTH; }}")
                for e in f.entries:
                    value = read_scalar(ctx, e.type, f.endian, "c + o")
                    out.append(f"{pad}{tgt}.{ident(e.name)} = {value}; /* {e.key} */")
                    out.append(f"{pad}o += {e.type.size}u;")
            case List():
                item = f.item.size if f.item is not None else 0
                if f.size:  # sized in bytes by a field
                    out.append(f"{pad}len = {as_size(ctx, pad, scope.lookup(f.size), out)};")
                    if item > 1:
                        out.append(f"{pad}if (len % {item}u != 0u) {{ return {ctx.P}_E_LENGTH; }}")
                    count = "len * 8u" if not item else "len" if item == 1 else f"len / {item}u"
                elif f.count == "rest":
                    out.append(f"{pad}len = n - o;")
                    if item > 1:
                        out.append(f"{pad}if (len % {item}u != 0u) {{ return {ctx.P}_E_LENGTH; }}")
                    count = "len * 8u" if not item else "len" if item == 1 else f"len / {item}u"
                else:
                    number = (
                        f"{f.count}u" if isinstance(f.count, int) else count_size(ctx, pad, f.count, scope, out, fields)
                    )
                    out.append(f"{pad}{tgt}_count = {number};")
                    out.append(
                        f"{pad}len = ({tgt}_count + 7u) / 8u;" if not item else f"{pad}len = {tgt}_count * {item}u;"
                    )
                    count = ""
                out.append(f"{pad}if (n - o < len) {{ return {ctx.P}_E_LENGTH; }}")
                if count:
                    out.append(f"{pad}{tgt}_count = {count};")
                capacity = f"sizeof({tgt})" if not item else f"(sizeof({tgt}) / sizeof({tgt}[0]))"
                out.append(
                    f"{pad}if ({'len' if not item else tgt + '_count'} > {capacity}) {{ return {ctx.P}_E_CAPACITY; }}"
                )
                if f.item is None:
                    out.append(f"{pad}{ctx.p}__copy({tgt}, c + o, len);")
                    ctx.helpers.add("copy")
                else:
                    out.append(ctx.loop(pad, depth, f"{tgt}_count"))
                    value = read_scalar(ctx, f.item, f.endian, f"c + o + i{depth} * {item}u")
                    out.append(f"{pad}    {tgt}[i{depth}] = {value};")
                    out.append(f"{pad}}}")
                out.append(f"{pad}o += len;")
            case Packed():
                out.extend(packed.decode(ctx.p, ctx.P, f, tgt, pad, ctx.counter(depth), ctx.helpers))
            case Varint():  # as many bytes as its value needs (encodings/varint.py)
                form = f"{f.bits}u, {int(f.high_first)}u, {f.most_bytes}u"
                out.append(f"{pad}len = {ctx.p}__varint_get(c + o, n - o, {form}, &vn);")
                out.append(f"{pad}if (len == 0u) {{ return {ctx.P}_E_CONTENT; }}")
                ctx.helpers.add("varint_get")
                held = SCALARS["i64" if f.type.signed else "u64"]
                value = varint.c_value("vn", f.sign)
                if f.type.signed:
                    out.append(f"{pad}vs = {value};")
                test = range_test(f.minimum, f.maximum, held, "vs" if f.type.signed else "vn")
                if test:
                    out.append(f"{pad}if ({test}) {{ return {ctx.P}_E_CONTENT; }}")
                out.append(f"{pad}{tgt} = ({ctype(f.type)}){'vs' if f.type.signed else 'vn'};")
                out.append(f"{pad}o += len;")
            case _:
                assert_never(f)


@dataclass
class CMath:
    """What rendering an expression in C needs to compute exactly what Python computes: the helpers' prefix, the set
    of helpers used (floor division and modulo, shifts of any count; files.helper_functions writes them), and the
    values each field can hold (its type's: from the wire, or computed and range-checked), which prove an operand
    not negative where C's own operator then gives Python's result."""

    p: str
    helpers: set[str]
    spans: dict[str, expression.Bounds]

    def span(self, expr: Expr) -> expression.Bounds:
        return expression.bounds(expr, self.spans)

    def helper(self, name: str) -> str:
        self.helpers.add(name)
        return f"{self.p}__{name}"


def math_of(ctx: Ctx, fields: tuple[Field, ...]) -> CMath:
    return CMath(ctx.p, ctx.helpers, value_spans(fields))


def value_spans(fields: tuple[Field, ...]) -> dict[str, expression.Bounds]:
    """The values each integer field an expression can name can hold: its type's (a decoder reads any wire value;
    an encoder range-checks a computed one before an expression reads it)."""
    return {
        f.name: (int(f.type.minimum), int(f.type.maximum))
        for f in fields
        if isinstance(f, Scalar) and not f.type.is_float
    }


INT64 = (-(1 << 63), (1 << 63) - 1)


def wider_than_int64(expr: Expr, spans: dict[str, expression.Bounds]) -> Expr | None:
    """The first part of the expression (inner parts first) some value of which, for some values of its fields'
    types, does not fit int64_t, the type C computes in; None when every value fits (C computes what Python does)."""
    parts: list[Expr] = []
    match expr:
        case expression.BinOp():
            parts = [expr.left, expr.right]
        case expression.Invert():
            parts = [expr.operand]
        case expression.Ceil():
            parts = [expr.numerator, expr.denominator, expression.BinOp("-", expression.Const(0), expr.numerator)]
        case expression.MinMax():
            parts = list(expr.args)
        case expression.Const() | expression.Name() | expression.Length():
            pass
        case _:
            assert_never(expr)
    for part in parts:
        found = wider_than_int64(part, spans)
        if found is not None:
            return found
    low, high = expression.bounds(expr, spans)
    return expr if low < INT64[0] or high > INT64[1] else None


def refuse_wide_values(protocol: Protocol) -> None:
    """A `value:` expression some intermediate value of which cannot fit int64_t (the Python codec's are exact up to
    512 bits): the C target refuses the spec, naming the place, rather than computing another value."""
    for message in protocol.messages():
        spans = value_spans(message.fields)
        for f in message.fields:
            if isinstance(f, Scalar) and f.value is not None:
                wide = wider_than_int64(f.value, spans)
                if wide is not None:
                    line, column = f.value_at
                    raise Unsupported(
                        f"{protocol.spec_path}:{line}:{column}: {message.key} {message.direction.value}: {f.name}: "
                        f"{collapse(expression.show(wide))} can exceed 64 bits for some values of its fields "
                        "(C computes in int64_t)"
                    )
        refuse_wide_counts(message.fields, spans, f"{message.key} {message.direction.value}")


def refuse_wide_counts(fields: tuple[Field, ...], spans: dict[str, expression.Bounds], where: str) -> None:
    """A count by expression some value of which cannot fit int64_t (a u64 field's): refused, as refuse_wide_values."""
    for f in fields:
        count = counts.counted(f)
        wide = None if count is None else wider_than_int64(count.expr, spans)
        if wide is not None:
            raise Unsupported(
                f"{where}: {f.name}: {collapse(expression.show(wide))} can exceed 64 bits (C computes in int64_t)"
            )
        if isinstance(f, Group):
            refuse_wide_counts(f.fields, value_spans(f.fields), where)


def c_length(fields: tuple[Field, ...], target: str) -> Callable[[str], str]:
    """`len(field)` of a value expression in C: a list's or group's item count, the bytes of bytes, a fixed array's
    count (the language refuses it of text)."""
    by_name = {f.name: f for f in fields}

    def length(name: str) -> str:
        match by_name.get(name):
            case Bytes(size=int() as size) | Array(count=size) | Packed(count=size) | Group(count=int() as size):
                return str(size)
            case Bytes():
                return f"{target}{ident(name)}_len"
            case _:
                return f"{target}{ident(name)}_count"

    return length


def render_c(expr: Expr, name: Callable[[str], str], length: Callable[[str], str], math: CMath) -> str:
    """An expression of the spec in C, over int64_t: `name(field)` and `length(list)` give the operands. It computes
    exactly what Python computes (refuse_wide_values has ruled out any value beyond int64_t, no_value a division by
    0 or a negative shift): `/` and `%` floor and ceil rounds up as Python's do, on either sign, shifts of 64 or more
    give Python's result; C's own operator where the operands are proved not negative."""

    def c(e: Expr) -> str:
        return render_c(e, name, length, math)

    def natural(e: Expr) -> bool:
        return math.span(e)[0] >= 0

    def positive(e: Expr) -> bool:
        return math.span(e)[0] > 0

    match expr:
        case expression.Const():
            return f"(int64_t){expr.value}"
        case expression.Name():
            return f"(int64_t){name(expr.name)}"
        case expression.Length():
            return f"(int64_t){length(expr.name)}"
        case expression.BinOp():
            a, b = c(expr.left), c(expr.right)
            if expr.op in ("/", "%") and not (natural(expr.left) and positive(expr.right)):
                return f"{math.helper('fdiv' if expr.op == '/' else 'fmod')}({a}, {b})"
            if expr.op in ("<<", ">>") and not (natural(expr.left) and math.span(expr.right)[1] < 63):
                return f"{math.helper('shl' if expr.op == '<<' else 'shr')}({a}, {b})"
            return f"({a} {expr.op} {b})"
        case expression.Invert():
            return f"(~{c(expr.operand)})"
        case expression.Ceil():
            a, b = c(expr.numerator), c(expr.denominator)
            if natural(expr.numerator) and positive(expr.denominator):
                return f"({a} / {b} + ({a} % {b} != 0))"
            return f"(-{math.helper('fdiv')}(-{a}, {b}))"
        case expression.MinMax():
            args = [c(a) for a in expr.args]
            result = args[0]
            for arg in args[1:]:
                pick = "<" if expr.function == "min" else ">"
                result = f"({result} {pick} {arg} ? {result} : {arg})"
            return result
        case _:
            assert_never(expr)


def no_value(expr: Expr, name: Callable[[str], str], length: Callable[[str], str], math: CMath) -> list[str]:
    """C conditions under which the expression has no value (a division by 0, a negative shift): undefined in C,
    so tested first, inner ones before outer ones (each may use what those ruled out); [] where none can happen
    (expression.fails)."""
    if not expression.fails(expr):
        return []
    match expr:
        case expression.BinOp():
            found = no_value(expr.left, name, length, math) + no_value(expr.right, name, length, math)
            right = render_c(expr.right, name, length, math)
            low, high = math.span(expr.right)  # a test that cannot hold is left out (gcc: always false)
            if expr.op in ("/", "%") and low <= 0 <= high:
                found.append(f"{right} == 0")
            if expr.op in ("<<", ">>") and low < 0:
                found.append(f"{right} < 0")
            return found
        case expression.Ceil():
            found = no_value(expr.numerator, name, length, math) + no_value(expr.denominator, name, length, math)
            low, high = math.span(expr.denominator)
            return [*found, f"{render_c(expr.denominator, name, length, math)} == 0"] if low <= 0 <= high else found
        case expression.Invert():
            return no_value(expr.operand, name, length, math)
        case expression.MinMax():
            return [c for arg in expr.args for c in no_value(arg, name, length, math)]
        case expression.Const() | expression.Name() | expression.Length():
            return []
        case _:
            assert_never(expr)


def value_checks(ctx: Ctx, fields: tuple[Field, ...], scope: Scope) -> list[str]:
    """Decode: every value the spec computes by an expression recomputed from the frame's fields, and compared (a
    frame where it has no value, a division by a 0 from the wire, does not decode)."""
    lines = []
    for f in fields:
        narrow = isinstance(f, Scalar) and (f.minimum, f.maximum) != (f.type.minimum, f.type.maximum)
        if isinstance(f, Scalar) and (f.value is not None or f.derived) and narrow:
            # a computed value outside its declared range (a count of 0 where 1..123 are allowed), as Python refuses
            wide, suffix = ("int64_t", "LL") if f.type.signed else ("uint64_t", "ULL")
            value = f"({wide}){scope.lookup(f.name)}"
            low, high = f"{int(f.minimum)}{suffix}", f"{int(f.maximum)}{suffix}"
            test = f"{value} < {low} || {value} > {high}" if f.minimum > f.type.minimum else f"{value} > {high}"
            if f.maximum == f.type.maximum:
                test = f"{value} < {low}"
            lines.append(f"    if ({test}) {{ return {ctx.P}_E_CONTENT; }} /* {f.name}: out of its range */")
        if isinstance(f, Scalar) and f.value is not None:
            length = c_length(fields, scope.target)
            math = math_of(ctx, fields)
            computed = render_c(f.value, scope.lookup, length, math)
            for condition in no_value(f.value, scope.lookup, length, math):
                lines.append(f"    if ({condition}) {{ return {ctx.P}_E_CONTENT; }} /* {f.name}: no value */")
            held = scope.lookup(f.name)
            differs = f"(int64_t){held} != {computed}"
            if f.type.size == 8 and not f.type.signed:  # above INT64_MAX it is no int64_t; a negative value no u64
                differs = f"{computed} < 0 || {held} != (uint64_t){computed}"
            lines.append(f"    if ({differs}) {{ return {ctx.P}_E_CONTENT; }} /* {f.name} */")
    return lines


def uses(fields: tuple[Field, ...], kinds: tuple[type, ...]) -> bool:
    for f in fields:
        if isinstance(f, kinds):
            return True
        if isinstance(f, Group) and uses(f.fields, kinds):
            return True
    return False


def bit_lists(fields: tuple[Field, ...]) -> bool:
    """A list of bits at any depth (a group's item's too): the encoder's `len`, its bytes."""
    return any(
        (isinstance(f, List) and f.item is None) or (isinstance(f, Group) and bit_lists(f.fields)) for f in fields
    )


def uses_k(fields: tuple[Field, ...]) -> bool:
    """A text whose end is found by a scan (NUL-terminated, or padded) at any depth: the decoder's `k`."""
    return any(
        (isinstance(f, Text) and (f.terminated or f.pad is not None)) or (isinstance(f, Group) and uses_k(f.fields))
        for f in fields
    )


def signed_varints(fields: tuple[Field, ...]) -> bool:
    """A signed varint at any depth: the decoder's `vs`, its value."""
    return any(
        (isinstance(f, Varint) and f.type.signed) or (isinstance(f, Group) and signed_varints(f.fields)) for f in fields
    )


def decoder(ctx: Ctx, message: Message) -> str:
    mid = msg_id(message)
    ctx.counters.clear()
    scope = Scope("m->", {})
    body: list[str] = []
    decode_fields(ctx, message.fields, scope, body, 1)
    locals_ = ["    size_t o = 0u;"]
    if uses(message.fields, (Bytes, Text, List, Varint)):
        locals_.append("    size_t len;")
    if uses(message.fields, (Varint,)):  # a varint's number, and its value when signed (encodings/varint.py)
        locals_.append("    uint64_t vn;")
    if signed_varints(message.fields):
        locals_.append("    int64_t vs;")
    if uses_k(message.fields):
        locals_.append("    size_t k;")
    locals_ += ctx.counter_locals()
    for f in message.fields:
        if isinstance(f, Scalar) and f.hidden and f.const is None:
            locals_.append(f"    {hidden_type(f)} d1_{ident(f.name)};")
    low, high = message.min_size, message.max_size
    size_check = (
        f"    if (n != {low}u) {{ return {ctx.P}_E_LENGTH; }}"
        if low == high
        else f"    if (n < {low}u) {{ return {ctx.P}_E_LENGTH; }}"
        if low
        else "    (void)n;"
    )
    if message.padded is not None:  # sent without its trailing zero bytes: padded back to its one size
        full = message.padded
        locals_.append(f"    uint8_t z[{full}u];")
        size_check = "\n".join(
            [
                f"    if (n < {full}u) {{ /* truncate: trailing_zeros: the bytes not sent are zeros */",
                "        for (o = 0u; o < n; o++) { z[o] = c[o]; }",
                f"        for (; o < {full}u; o++) {{ z[o] = 0u; }}",
                "        c = z;",
                f"        n = {full}u;",
                "        o = 0u;",
                "    }",
                f"    if (n != {full}u) {{ return {ctx.P}_E_LENGTH; }}",
            ]
        )
    return "\n".join(
        [
            f"/* The content of {message.key} ({message.direction.value}): fields in wire order. */",
            f"static int {ctx.p}__dec_{mid}(const uint8_t *c, size_t n, {ctx.p}_{mid}_t *m)",
            "{",
            *locals_,
            "    (void)c;",
            "    (void)m;",
            size_check,
            *body,
            f"    if (o != n) {{ return {ctx.P}_E_LENGTH; }}",
            *value_checks(ctx, message.fields, scope),
            f"    return {ctx.P}_OK;",
            "}",
            "",
        ]
    )


# --- content encoders ----------------------------------------------------------------------------------------------


def scalar_bits(ctx: Ctx, t: ScalarType, expr: str) -> str:
    """The wire value of a scalar as uint32_t, uint64_t for 8-byte types (two's complement for signed, IEEE bits
    for floats)."""
    if t.is_float:
        ctx.helpers.add(f"f{t.size * 8}bits")
        return f"{ctx.p}__f{t.size * 8}bits({expr})"
    if wide(t):
        return f"(uint64_t)({expr})"
    if t.signed:
        mask = (1 << (8 * t.size)) - 1
        return f"((uint32_t)(int32_t)({expr}) & 0x{mask:x}u)"
    return f"(uint32_t)({expr})"


def range_test(f_min: float, f_max: float, t: ScalarType, expr: str) -> str | None:
    """A C test true when expr is outside [f_min, f_max]; None when the type cannot hold such a value."""
    if t.is_float:
        return f"!({expr} >= {cint(f_min, t)} && {expr} <= {cint(f_max, t)})"
    parts = []
    if f_min > t.minimum:
        parts.append(f"{expr} < {cint(f_min, t)}")
    if f_max < t.maximum:
        parts.append(f"{expr} > {cint(f_max, t)}")
    return " || ".join(parts) or None


def check_fields(ctx: Ctx, fields: tuple[Field, ...], scope: Scope, out: list[str], depth: int) -> None:
    """Range checks of every value before a byte is written (encode refuses with P_E_RANGE)."""
    pad = "    " * depth
    for f in fields:
        name = ident(f.name)
        tgt = f"{scope.target}{name}"
        counted = counts.counted(f)
        if counted is not None:  # as many items or bytes as its expression gives (lang/counts.py)
            held = f"{tgt}_count" if isinstance(f, List | Group) else f"{tgt}_len"
            value = count_expression(ctx, counted, lambda other: f"{scope.target}{ident(other)}", fields)
            out.append(f"{pad}if ((int64_t){held} != {value}) {{ return {ctx.P}_E_RANGE; }} /* {f.name}: {counted} */")
        match f:
            case Scalar():
                if f.hidden:
                    continue
                test = range_test(f.minimum, f.maximum, value_type(f), tgt)
                if test:
                    out.append(f"{pad}if ({test}) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
                mask, bits = fixed_bits(f.bits)
                if mask:  # constant bit fields
                    out.append(f"{pad}if (({tgt} & {mask}u) != {bits}u) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
            case Array():
                test = range_test(f.minimum, f.maximum, f.item, f"{tgt}[i{depth}]")
                if test:
                    out.append(ctx.loop(pad, depth, f"{f.count}u"))
                    out.append(f"{pad}    if ({test}) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
                    out.append(f"{pad}}}")
            case Bytes():
                if not isinstance(f.size, int):
                    out.append(f"{pad}if ({tgt}_len > sizeof({tgt})) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
            case Text() if f.seven_bit:  # UTF-8 of 14-bit characters, as many as its size holds
                out.append(f"{pad}if ({tgt}_len > sizeof({tgt}) - 1u) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
                wire = f"{ctx.p}__text14_put(NULL, {tgt}, {tgt}_len)"
                fits = f" != {f.size}u" if isinstance(f.size, int) else " == (size_t)-1"
                out.append(f"{pad}if ({wire}{fits}) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
                ctx.helpers.add("text14_put")
            case Text():
                out.append(f"{pad}if ({tgt}_len > sizeof({tgt}) - 1u) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
                if isinstance(f.size, int):
                    fits = ">" if f.pad is not None else "!="  # padded: at most its size, else exactly
                    out.append(f"{pad}if ({tgt}_len {fits} {f.size}u) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
                ctx.helpers.add("utf8")
                nul = f" || memchr({tgt}, 0, {tgt}_len) != NULL" if f.terminated else ""
                out.append(
                    f"{pad}if (!{ctx.p}__utf8((const uint8_t *){tgt}, {tgt}_len){nul}) {{ return {ctx.P}_E_RANGE; }}"
                )
            case Group():
                i = f"i{depth}"
                count = f"{f.count}u" if isinstance(f.count, int) else f"{tgt}_count"
                inner: list[str] = []
                check_fields(ctx, f.fields, Scope(f"{tgt}[{i}].", {}, scope), inner, depth + 1)
                if not isinstance(f.count, int):
                    out.append(f"{pad}if ({count} > sizeof({tgt}) / sizeof({tgt}[0])) {{ return {ctx.P}_E_RANGE; }}")
                if inner:
                    out.append(ctx.loop(pad, depth, count))
                    out.extend(inner)
                    out.append(f"{pad}}}")
            case TableValue():
                out.append(f"{pad}switch ({scope.target}{ident(f.key)}) {{ /* {f.name}: the range of its entry */")
                for e in f.table.entries:
                    if e.reserved:
                        continue
                    low, high = int(e.minimum), int(e.maximum)
                    out.append(
                        f"{pad}case {e.key}u: if ({tgt} < ({low + 1}LL - 1LL) || {tgt} > {high}LL) "
                        f"{{ return {ctx.P}_E_RANGE; }} break;"
                    )
                out.append(f"{pad}default: return {ctx.P}_E_RANGE; /* a key the table does not define */")
                out.append(f"{pad}}}")
            case TableBlock():
                for e in f.entries:
                    test = range_test(e.minimum, e.maximum, e.type, f"{tgt}.{ident(e.name)}")
                    if test:
                        out.append(f"{pad}if ({test}) {{ return {ctx.P}_E_RANGE; }} /* {f.name}.{e.name} */")
            case List():
                capacity = f"sizeof({tgt}) * 8u" if f.item is None else f"sizeof({tgt}) / sizeof({tgt}[0])"
                out.append(f"{pad}if ({tgt}_count > {capacity}) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
                if isinstance(f.count, int):
                    out.append(f"{pad}if ({tgt}_count != {f.count}u) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
                if f.item is not None:
                    test = range_test(f.minimum, f.maximum, f.item, f"{tgt}[i{depth}]")
                    if test:
                        out.append(ctx.loop(pad, depth, f"{tgt}_count"))
                        out.append(f"{pad}    if ({test}) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
                        out.append(f"{pad}}}")
            case Packed():
                test = range_test(f.minimum, f.maximum, packed.item_type(f), f"{tgt}[i{depth}]")
                if test:
                    out.append(ctx.loop(pad, depth, f"{f.count}u"))
                    out.append(f"{pad}    if ({test}) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
                    out.append(f"{pad}}}")
            case Varint():
                test = range_test(f.minimum, f.maximum, f.type, tgt)
                if test:
                    out.append(f"{pad}if ({test}) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
            case _:
                assert_never(f)


def derived_value(
    ctx: Ctx, f: Scalar, fields: tuple[Field, ...], scope: Scope, out: list[str], pad: str, depth: int
) -> str:
    """C statements computing a derived count or size into a local; returns the local's name."""
    local = f"v{depth}_{ident(f.name)}"
    kind, target = f.derived[0], f.derived[1]
    by_name = {x.name: x for x in fields}
    if kind == "count":
        group = by_name.get(target)
        if isinstance(group, Group | List) and not isinstance(group.count, int):
            out.append(f"{pad}{local} = (uint32_t){scope.target}{ident(target)}_count;")
        else:
            raise Unsupported(f"{f.name}: a count of {target}")
    elif kind == "size":
        sized = by_name.get(target)
        if isinstance(sized, Bytes | Text):
            out.append(f"{pad}{local} = (uint32_t){scope.target}{ident(target)}_len;")
        else:
            group = next((g for g in fields if isinstance(g, Group) and any(x.name == target for x in g.fields)), None)
            if group is None or isinstance(group.count, int):
                raise Unsupported(f"{f.name}: the size of {target}")
            g = f"{scope.target}{ident(group.name)}"
            member = ident(target)
            out.append(f"{pad}{local} = {g}_count ? (uint32_t){g}[0].{member}_len : 0u;")
            out.append(f"{pad}for (j = 0u; j < {g}_count; j++) {{")
            out.append(f"{pad}    if ((uint32_t){g}[j].{member}_len != {local}) {{ return {ctx.P}_E_RANGE; }}")
            out.append(f"{pad}}}")
            ctx.helpers.add("j")
    else:
        raise Unsupported(f"{f.name}: derived {kind}")
    test = range_test(f.minimum, f.maximum, ScalarType("u32", 4, "I", False, False, 0, 0xFFFFFFFF), local)
    if test:
        out.append(f"{pad}if ({test}) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
    scope.names[f.name] = local
    return local


def encode_fields(ctx: Ctx, fields: tuple[Field, ...], scope: Scope, out: list[str], depth: int) -> None:
    pad = "    " * depth
    for f in fields:
        name = ident(f.name)
        tgt = f"{scope.target}{name}"
        match f:
            case Scalar():
                size = f.type.size
                if f.const is not None:
                    value = f"{const_wire(f)}{'ULL' if wide(f.type) else 'UL'}"
                elif f.derived:
                    value = scope.lookup(f.name)
                elif f.value is not None:
                    value = f"(uint{64 if wide(f.type) else 32}_t){scope.lookup(f.name)}"
                else:
                    value = scalar_bits(ctx, f.type, tgt)
                    if f.sign_magnitude:
                        top = 1 << (8 * size - 1)
                        value = f"({tgt} < 0 ? ((uint32_t)(-(int32_t){tgt}) | 0x{top:x}UL) : (uint32_t){tgt})"
                    if f.low_bits is not None:
                        value = f.low_bits.c_encode(tgt, size)
                place = f.bit_place
                if place is not None:  # a member of a bit run: its bits into the run (encodings/bit_run.py)
                    if place.first:
                        out.append(f"{pad}if (cap - o < {place.size}u) {{ return {ctx.P}_E_BUFFER; }}")
                        out.append(f"{pad}memset(c + o, 0, {place.size}u);")
                    ctx.helpers.add(f"setbits{bit_run.c_width(place.bits)}")
                    write = bit_run.c_encode(ctx.p, "c + o", place.bits, place.shift, place.size, value)
                    out.append(f"{pad}{write} /* {f.name} */")
                    if place.last:
                        out.append(f"{pad}o += {place.size}u;")
                    continue
                out.append(f"{pad}if (cap - o < {size}u) {{ return {ctx.P}_E_BUFFER; }}")
                out.append(f"{pad}{put_call(ctx, f.type, f.endian, 'c + o', value)} /* {f.name} */")
                out.append(f"{pad}o += {size}u;")
            case Array():
                total = f.count * f.item.size
                out.append(f"{pad}if (cap - o < {total}u) {{ return {ctx.P}_E_BUFFER; }}")
                out.append(ctx.loop(pad, depth, f"{f.count}u"))
                value = scalar_bits(ctx, f.item, f"{tgt}[i{depth}]")
                out.append(f"{pad}    {put_call(ctx, f.item, f.endian, f'c + o + i{depth} * {f.item.size}u', value)}")
                out.append(f"{pad}}}")
                out.append(f"{pad}o += {total}u;")
            case Bytes() | Text():
                length = f"{f.size}u" if isinstance(f, Bytes) and isinstance(f.size, int) else f"{tgt}_len"
                extra = " + 1u" if isinstance(f, Text) and f.terminated else ""
                if isinstance(f.size, str) and f.size != "rest" and f.size not in scope.names:
                    pass  # sized by a field of an outer scope: the derived check made every item agree
                if isinstance(f, Text) and f.seven_bit:  # checked to be 14-bit characters (check_fields)
                    wire = f"{ctx.p}__text14_put(NULL, {tgt}, {tgt}_len)"
                    out.append(f"{pad}if (cap - o < {wire}) {{ return {ctx.P}_E_BUFFER; }}")
                    out.append(f"{pad}o += {ctx.p}__text14_put(c + o, {tgt}, {tgt}_len); /* {f.name} */")
                    ctx.helpers.add("text14_put")
                    continue
                if isinstance(f, Text) and f.pad is not None:  # the text, then pad bytes up to its size
                    out.append(f"{pad}if (cap - o < {f.size}u) {{ return {ctx.P}_E_BUFFER; }}")
                    out.append(f"{pad}memcpy(c + o, {tgt}, {length}); /* {f.name} */")
                    out.append(f"{pad}memset(c + o + {length}, 0x{f.pad:02x}, {f.size}u - {length});")
                    out.append(f"{pad}o += {f.size}u;")
                    continue
                out.append(f"{pad}if (cap - o < {length}{extra}) {{ return {ctx.P}_E_BUFFER; }}")
                out.append(f"{pad}memcpy(c + o, {tgt}, {length}); /* {f.name} */")
                out.append(f"{pad}o += {length};")
                if extra:
                    out.append(f"{pad}c[o++] = 0u;")
            case Group():
                i = f"i{depth}"
                count = f"{f.count}u" if isinstance(f.count, int) else f"{tgt}_count"
                item_scope = Scope(f"{tgt}[{i}].", {}, scope)
                inner: list[str] = []
                for h in f.fields:
                    if isinstance(h, Scalar) and h.derived:
                        inner.append(f"{pad}    uint32_t v{depth + 1}_{ident(h.name)};")
                for h in f.fields:
                    if isinstance(h, Scalar) and h.derived:
                        derived_value(ctx, h, f.fields, item_scope, inner, pad + "    ", depth + 1)
                encode_fields(ctx, f.fields, item_scope, inner, depth + 1)
                out.append(ctx.loop(pad, depth, count))
                out.extend(inner)
                out.append(f"{pad}}}")
            case TableValue():
                big = 1 if ctx.protocol.byte_order == "big" else 0
                out.append(f"{pad}switch ({scope.target}{ident(f.key)}) {{ /* {f.name} */")
                for e in f.table.entries:
                    if e.reserved:
                        continue
                    size = e.type.size
                    mask = (1 << (8 * size)) - 1
                    out.append(f"{pad}case {e.key}u:")
                    out.append(f"{pad}    if (cap - o < {size}u) {{ return {ctx.P}_E_BUFFER; }}")
                    out.append(
                        f"{pad}    {ctx.p}__put(c + o, {size}u, {big}u, (uint32_t)((uint64_t){tgt} & 0x{mask:x}u));"
                    )
                    out.append(f"{pad}    o += {size}u;")
                    out.append(f"{pad}    break;")
                out.append(f"{pad}default:")
                out.append(f"{pad}    return {ctx.P}_E_RANGE;")
                out.append(f"{pad}}}")
            case TableBlock():
                total = sum(e.type.size for e in f.entries)
                big = 1 if f.endian == ">" else 0
                out.append(f"{pad}if (cap - o < {total}u) {{ return {ctx.P}_E_BUFFER; }}")
                for e in f.entries:
                    value = scalar_bits(ctx, e.type, f"{tgt}.{ident(e.name)}")
                    out.append(f"{pad}{put_call(ctx, e.type, f.endian, 'c + o', value)} /* {e.key} */")
                    out.append(f"{pad}o += {e.type.size}u;")
            case List():
                if f.item is None:
                    out.append(f"{pad}len = ({tgt}_count + 7u) / 8u;")
                    out.append(f"{pad}if (cap - o < len) {{ return {ctx.P}_E_BUFFER; }}")
                    out.append(f"{pad}memcpy(c + o, {tgt}, len); /* {f.name} */")
                    out.append(f"{pad}if ({tgt}_count % 8u != 0u) {{ /* the last byte's unused bits are 0 */")
                    out.append(
                        f"{pad}    c[o + len - 1u] = (uint8_t)(c[o + len - 1u] & ((1u << ({tgt}_count % 8u)) - 1u));"
                    )
                    out.append(f"{pad}}}")
                    out.append(f"{pad}o += len;")
                else:
                    size = f.item.size
                    big = 1 if f.endian == ">" else 0
                    out.append(f"{pad}if ((cap - o) / {size}u < {tgt}_count) {{ return {ctx.P}_E_BUFFER; }}")
                    out.append(ctx.loop(pad, depth, f"{tgt}_count"))
                    value = scalar_bits(ctx, f.item, f"{tgt}[i{depth}]")
                    out.append(f"{pad}    {put_call(ctx, f.item, f.endian, 'c + o', value)} /* {f.name} */")
                    out.append(f"{pad}    o += {size}u;")
                    out.append(f"{pad}}}")
            case Packed():
                out.extend(packed.encode(ctx.p, ctx.P, f, tgt, pad, ctx.counter(depth), ctx.helpers))
            case Varint():  # as many bytes as its value needs (encodings/varint.py)
                wire, form = varint.c_wire(tgt, f.sign), f"{f.bits}u, {int(f.high_first)}u"
                out.append(
                    f"{pad}if (cap - o < {ctx.p}__varint_put(NULL, {wire}, {form})) {{ return {ctx.P}_E_BUFFER; }}"
                )
                out.append(f"{pad}o += {ctx.p}__varint_put(c + o, {wire}, {form}); /* {f.name} */")
                ctx.helpers.add("varint_put")
            case _:
                assert_never(f)


def computed_values(ctx: Ctx, fields: tuple[Field, ...], scope: Scope, out: list[str]) -> None:
    """Encode: the values the spec computes by an expression, in field order, each range-checked."""
    for f in fields:
        if isinstance(f, Scalar) and f.value is not None:
            local = f"v1_{ident(f.name)}"
            length = c_length(fields, scope.target)
            math = math_of(ctx, fields)
            computed = render_c(f.value, scope.lookup, length, math)
            for condition in no_value(f.value, scope.lookup, length, math):  # a division by a 0 given: refused
                out.append(f"    if ({condition}) {{ return {ctx.P}_E_RANGE; }} /* {f.name}: no value */")
            out.append(f"    {local} = {computed};")
            # int64_t holds the value: a bound beyond it (u64's top, i64's ends) is no test, and no literal
            tests = [f"{local} < {int(f.minimum)}LL"] if f.minimum > INT64[0] else []
            tests += [f"{local} > {int(f.maximum)}LL"] if f.maximum < INT64[1] else []
            if tests:
                out.append(f"    if ({' || '.join(tests)}) {{ return {ctx.P}_E_RANGE; }} /* {f.name} */")
            scope.names[f.name] = local


def encoder(ctx: Ctx, message: Message) -> str:
    mid = msg_id(message)
    ctx.counters.clear()
    scope = Scope("m->", {})
    checks: list[str] = []
    check_fields(ctx, message.fields, scope, checks, 1)
    derived: list[str] = []
    ctx.helpers.discard("j")
    for f in message.fields:
        if isinstance(f, Scalar) and f.derived:
            derived_value(ctx, f, message.fields, scope, derived, "    ", 1)
    for name in [x.name for x in message.fields if not (isinstance(x, Scalar) and x.hidden)]:
        scope.names.setdefault(name, f"m->{ident(name)}")
    computed_values(ctx, message.fields, scope, derived)
    uses_j = "j" in ctx.helpers
    ctx.helpers.discard("j")
    body: list[str] = []
    encode_fields(ctx, message.fields, scope, body, 1)
    locals_ = ["    size_t o = 0u;"]
    locals_ += ctx.counter_locals()
    if uses_j:
        locals_.append("    size_t j;")
    for f in message.fields:
        if isinstance(f, Scalar) and f.derived:
            locals_.append(f"    uint32_t v1_{ident(f.name)};")
        elif isinstance(f, Scalar) and f.value is not None:
            locals_.append(f"    int64_t v1_{ident(f.name)};")
    if bit_lists(message.fields):
        locals_.append("    size_t len;")
    parameters, ending = "uint8_t *c, size_t cap", ["    *n = o;"]
    if message.padded is not None:  # made whole in z, sent without its trailing zero bytes (at least one)
        full = message.padded
        parameters = "uint8_t *out, size_t room"
        locals_ += [f"    uint8_t z[{full}u];", "    uint8_t *c = z;", f"    const size_t cap = {full}u;"]
        ending = [
            "    while (o > 1u && z[o - 1u] == 0u) { /* truncate: trailing_zeros */",
            "        o--;",
            "    }",
            f"    if (o > room) {{ return {ctx.P}_E_BUFFER; }}",
            "    *n = o;",
            "    while (o > 0u) {",
            "        o--;",
            "        out[o] = z[o];",
            "    }",
        ]
    return "\n".join(
        [
            f"/* The content of {message.key} ({message.direction.value}): every value checked against the spec's",
            " * range before a byte is written, then the fields in wire order. */",
            f"static int {ctx.p}__enc_{mid}(const void *mv, {parameters}, size_t *n)",
            "{",
            f"    const {ctx.p}_{mid}_t *m = (const {ctx.p}_{mid}_t *)mv;",
            *locals_,
            "    (void)m;",
            "    (void)c;",
            "    (void)cap;",
            *checks,
            *derived,
            *body,
            *ending,
            f"    return {ctx.P}_OK;",
            "}",
            "",
        ]
    )


# --- JSON ----------------------------------------------------------------------------------------------------------


def json_fields(ctx: Ctx, fields: tuple[Field, ...], target: str, out: list[str], depth: int, first: bool) -> bool:
    """C statements writing `"name": value` pairs of the visible fields (as `serialspec decode --json` does)."""
    pad = "    " * depth
    for f in fields:
        if isinstance(f, Scalar) and f.hidden:
            continue
        name = ident(f.name)
        tgt = f"{target}{name}"
        sep = "" if first else ", "
        first = False
        out.append(f'{pad}{ctx.p}__ws(w, "{sep}\\"{f.name}\\": ");')
        match f:
            case Scalar():
                if f.bits:
                    json_bits(ctx, f.bits, tgt, out, pad)
                else:
                    out.append(pad + json_number(ctx, value_type(f), tgt))
            case Array():
                out.append(f'{pad}{ctx.p}__ws(w, "[");')
                out.append(ctx.loop(pad, depth, f"{f.count}u"))
                out.append(f'{pad}    if (i{depth}) {{ {ctx.p}__ws(w, ", "); }}')
                out.append(f"{pad}    " + json_number(ctx, f.item, f"{tgt}[i{depth}]"))
                out.append(f"{pad}}}")
                out.append(f'{pad}{ctx.p}__ws(w, "]");')
            case Bytes():
                length = f"{f.size}u" if isinstance(f.size, int) else f"{tgt}_len"
                out.append(f"{pad}{ctx.writer('wbytes')}(w, {tgt}, {length});")
            case Text():
                out.append(f"{pad}{ctx.writer('wtext')}(w, {tgt}, {tgt}_len);")
            case Group():
                i = f"i{depth}"
                count = f"{f.count}u" if isinstance(f.count, int) else f"{tgt}_count"
                out.append(f'{pad}{ctx.p}__ws(w, "[");')
                out.append(ctx.loop(pad, depth, count))
                out.append(f'{pad}    {ctx.p}__ws(w, {i} ? ", {{" : "{{");')
                json_fields(ctx, f.fields, f"{tgt}[{i}].", out, depth + 1, True)
                out.append(f'{pad}    {ctx.p}__ws(w, "}}");')
                out.append(f"{pad}}}")
                out.append(f'{pad}{ctx.p}__ws(w, "]");')
            case TableValue():
                out.append(
                    f"{pad}if ({tgt} < 0) {{ {ctx.writer('wi')}(w, (int32_t){tgt}); }} "
                    f"else {{ {ctx.writer('wu')}(w, (uint32_t){tgt}); }}"
                )
            case TableBlock():
                out.append(f'{pad}{ctx.p}__ws(w, "{{");')
                for k, e in enumerate(f.entries):
                    sep2 = "" if k == 0 else ", "
                    out.append(f'{pad}{ctx.p}__ws(w, "{sep2}\\"{e.name}\\": ");')
                    out.append(pad + json_number(ctx, e.type, f"{tgt}.{ident(e.name)}"))
                out.append(f'{pad}{ctx.p}__ws(w, "}}");')
            case List():
                out.append(f'{pad}{ctx.p}__ws(w, "[");')
                out.append(ctx.loop(pad, depth, f"{tgt}_count"))
                out.append(f'{pad}    if (i{depth}) {{ {ctx.p}__ws(w, ", "); }}')
                if f.item is None:
                    bit = f"((unsigned){tgt}[i{depth} / 8u] >> (i{depth} % 8u)) & 1u"  # unsigned: AVR has a 16-bit int
                    out.append(f'{pad}    {ctx.p}__ws(w, ({bit}) ? "true" : "false");')
                else:
                    out.append(f"{pad}    " + json_number(ctx, f.item, f"{tgt}[i{depth}]"))
                out.append(f"{pad}}}")
                out.append(f'{pad}{ctx.p}__ws(w, "]");')
            case Packed():
                out.append(f'{pad}{ctx.p}__ws(w, "[");')
                out.append(ctx.loop(pad, depth, f"{f.count}u"))
                out.append(f'{pad}    if (i{depth}) {{ {ctx.p}__ws(w, ", "); }}')
                out.append(f"{pad}    " + json_number(ctx, packed.item_type(f), f"{tgt}[i{depth}]"))
                out.append(f"{pad}}}")
                out.append(f'{pad}{ctx.p}__ws(w, "]");')
            case Varint():
                out.append(pad + json_number(ctx, f.type, tgt))
            case _:
                assert_never(f)
    return first


def json_bits(ctx: Ctx, bits: tuple[BitField, ...], value: str, out: list[str], pad: str) -> None:
    """A value made of bit fields as an object of them (the bits class's to_fields)."""
    out.append(f'{pad}{ctx.p}__ws(w, "{{");')
    for k, b in enumerate(bits):
        s = "" if k == 0 else ", "
        out.append(
            f'{pad}{ctx.p}__ws(w, "{s}\\"{b.name}\\": "); '
            f"{ctx.writer('wu')}(w, ((uint32_t){value} >> {b.low}) & 0x{b.mask:x}u);"
        )
    out.append(f'{pad}{ctx.p}__ws(w, "}}");')


def json_number(ctx: Ctx, t: ScalarType, expr: str) -> str:
    if t.is_float:
        return f"{ctx.writer('wf')}(w, (double){expr});"
    if wide(t):
        return f"{ctx.writer('wi64' if t.signed else 'wu64')}(w, {expr});"
    if t.signed:
        return f"{ctx.writer('wi')}(w, (int32_t){expr});"
    return f"{ctx.writer('wu')}(w, (uint32_t){expr});"


# --- the whole files -------------------------------------------------------------------------------------------------


def spec_hash(protocol: Protocol) -> str:
    """SHA-256 of the resolved spec (the model's values, whatever the spec's layout or comments): the same wherever
    and however it is generated."""
    from dataclasses import replace

    return hashlib.sha256(repr(replace(protocol, spec_path="")).encode("utf-8")).hexdigest()
