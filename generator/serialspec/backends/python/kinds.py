"""How each field kind looks in the generated Python: one class per model field kind, registered by model class.

An emitter asks `kind(f)` instead of switching on the field's class: the attribute type, the to/from JSON
expressions, the struct format and the construct expression of each kind live here. Still switches elsewhere: the
fast decode/encode statements (content.py), the simulator's and client's field look-ups, the CLI views.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import replace
from typing import Any, Generic

from serialspec.backends.common.kinds import F, Registry
from serialspec.backends.common.numbers import number
from serialspec.backends.python.ir import Calls
from serialspec.backends.python.render import one_line
from serialspec.encodings import varint
from serialspec.lang import counts, expression
from serialspec.lang.model import (
    Array,
    Bytes,
    Counted,
    Group,
    List,
    Packed,
    Scalar,
    ScalarType,
    TableBlock,
    TableValue,
    Text,
    Varint,
)
from serialspec.lang.model import Field as SpecField
from serialspec.lang.names import spec_key


def _get(f: SpecField) -> Calls:
    """The expression reading a field's JSON value from `data` (the generated `from_fields`)."""
    return Calls(f"_get(data, {spec_key(f.name)}, where)", ["_get"])


class Kind(Generic[F]):
    """What a field kind is in generated Python. The defaults fit a kind of varying size with a plain value."""

    def fixed(self, f: F) -> bool:
        """A member of a run of fixed-size fields read and written by one struct call."""
        return False

    def struct_chars(self, f: F) -> str:
        """The field's part of a struct format; nothing for a kind of varying size."""
        return ""

    def annotation(self, f: F) -> str:
        """The type of the message attribute."""
        raise NotImplementedError

    def construct(self, f: F, parent: str) -> str:
        """The field's construct expression (the reference structs); `parent` is "item" inside a group item."""
        raise NotImplementedError

    def to_json(self, f: F, expr: str) -> str:
        """The JSON value of `expr`, a value of the field (the generated `to_fields`)."""
        return expr

    def from_json(self, f: F) -> Calls:
        """The field's value from `data` (the generated `from_fields`), refusing a wrong kind of value; with the
        runtime helpers it calls."""
        return _get(f)

    def blank(self, f: F) -> str:
        """The field's value (JSON form) in a reply a virtual device builds without a value for it: zero, or the
        empty value of its kind, of the size the kind fixes; a function of the request's fields where the request
        says how many items are meant."""
        return "0"


def zero_bits(bits: Sequence[Any]) -> str:
    """Bit fields (of a field or a frame element) as JSON, each its constant or default, else 0: what a device
    sends when nothing sets them."""
    return "{" + ", ".join(f"{b.name!r}: {b.preset or 0}" for b in bits) + "}"


def _numbers_from_json(f: Array | List) -> Calls:
    """A list of numbers (or bits) from JSON, each checked to be one."""
    kind = "_bits" if f.item is None else "_numbers" if f.item.is_float else "_integers"
    get = _get(f)
    return Calls(f"{kind}({get}, {spec_key(f.name)}, where)", [kind], get)


def _numbers(is_float: bool) -> str:
    return "tuple[float, ...]" if is_float else "tuple[int, ...]"


def list_item_type(f: List) -> str:
    """The Python type of a list field's items (the message holds a tuple of them)."""
    return "bool" if f.item is None else "float" if f.item.is_float else "int"


_INT = {1: "Int8", 2: "Int16", 3: "Int24", 4: "Int32", 8: "Int64"}


def primitive(scalar: ScalarType, endian: str, signed: bool | None = None) -> str:
    """construct's integer of the type (`signed`: read signed or not, whatever the type)."""
    suffix = "b" if endian == ">" else "l"
    signed = scalar.signed if signed is None else signed
    if scalar.is_float:
        return f"Float{scalar.size * 8}{suffix}"
    if scalar.size == 1:
        return "Int8sb" if signed else "Int8ub"
    return f"{_INT[scalar.size]}{'s' if signed else 'u'}{suffix}"


def list_expr(f: List) -> str:
    """An array whose count varies, or packed bits."""
    count: int | str | Counted = f.count
    if isinstance(f.count, Counted):
        count = f"({counts.construct_count(f.count)})"
    elif isinstance(f.count, str) and f.count not in ("", "rest"):
        count = f"this.{f.count}"
    if f.item is None:
        if f.size:
            return f"PackedBits(Bytes(this.{f.size}))"
        if f.count == "rest":
            return "PackedBits(GreedyBytes)"
        if isinstance(f.count, Counted):
            bits = expression.render(f.count.expr, lambda name: f"ctx.{name}")
            return f"PackedBits(Bytes(lambda ctx: ({bits} + 7) // 8), {count})"
        return f"PackedBits(Bytes(({count} + 7) // 8), {count})"
    item = primitive(f.item, f.endian)
    if f.size:
        return f"Array(this.{f.size} // {f.item.size}, {item})"
    if f.count == "rest":
        return f"GreedyRange({item})"
    return f"Array({count}, {item})"


def bits_expr(f: Scalar) -> str:
    """A BitStruct from the most significant bit down; unlisted bits are constant zero."""
    width = f.type.size * 8
    parts = []
    bit = width - 1
    for field in sorted(f.bits, key=lambda b: -b.high):
        if bit > field.high:
            parts.append(f"'_unused_{bit}' / Const(0, BitsInteger({bit - field.high}))")
        bits = f"BitsInteger({field.high - field.low + 1})"
        parts.append(f"{field.name!r} / " + (bits if field.const is None else f"Const({field.const}, {bits})"))
        bit = field.low - 1
    if bit >= 0:
        parts.append(f"'_unused_{bit}' / Const(0, BitsInteger({bit + 1}))")
    inner = "BitStruct(" + ", ".join(parts) + ")"
    return f"ByteSwapped({inner})" if f.type.size > 1 and f.endian == "<" else inner


def bit_member(f: Scalar) -> str:
    """The construct of a member of a bit run (encodings/bit_run.py's `member`)."""
    place = f.bit_place
    assert place is not None
    return f"BitRunMember({place.bits}, {place.shift}, {place.size}, {f.type.signed}, {place.earlier!r})"


def declared_range(f: Scalar) -> str:
    """Rebuilt's range arguments: a computed value's declared range where it is narrower than its type's (decode
    refuses a value outside it, as encode does), else none."""
    if (f.minimum, f.maximum) == (f.type.minimum, f.type.maximum):
        return ""
    return f", {int(f.minimum)}, {int(f.maximum)}"


class ScalarKind(Kind[Scalar]):
    model = Scalar

    def construct(self, f: Scalar, parent: str) -> str:
        base = primitive(f.type, f.endian, f.wire_signed) if f.bit_place is None else bit_member(f)
        if f.const is not None:
            return f"Const({f.const}, {base})"
        if f.value is not None:
            compute = f"lambda ctx: {expression.render(f.value, lambda name: f'ctx[{name!r}]')}"
            if expression.fails(f.value):  # a divisor of 0 or a negative shift: a one-line refusal to build
                compute = f"valued({f.name!r}, {one_line(expression.show(f.value))!r}, {compute})"
            return f"Rebuilt({base}, {compute}{declared_range(f)})"
        if f.derived:
            derived, target = f.derived[0], f.derived[1]
            if derived == "count":
                return f"Rebuilt({base}, len_(this.{target}){declared_range(f)})"
            # evaluated while building: a lambda, so the context is the one being built, not `this` itself
            return f"Rebuilt({base}, lambda ctx: _item_size(ctx, {target!r}){declared_range(f)})"
        if f.bits:
            return bits_expr(f)
        if f.sign_magnitude:
            return f"SignMagnitude({base}, {f.type.size * 8})"
        if f.low_bits is not None:
            signed = ", signed=True" if f.type.signed else ""
            return f"{f.low_bits.construct_name}({base}, {f.type.size}{signed})"
        return base

    def fixed(self, f: Scalar) -> bool:
        return True

    def struct_chars(self, f: Scalar) -> str:
        if f.bit_place is not None:  # the run's bytes, read at its first field (encodings/bit_run.py)
            return f"{f.bit_place.size}s" if f.bit_place.first else ""
        if f.type.signed and not f.wire_signed and not f.odd_width:  # an unsigned word, signed by its own bits
            return f.type.struct_char.upper()
        return f.type.struct_char

    def annotation(self, f: Scalar) -> str:
        if f.bits:
            return f.bits_class
        if f.enum:
            return f"{f.enum.class_name} | int"
        if f.flags:
            return f.flags.class_name
        return "float" if f.type.is_float else "int"

    def to_json(self, f: Scalar, expr: str) -> str:
        if f.bits:
            return f"{expr}.to_fields()"
        return f"int({expr})" if (f.enum or f.flags) else expr

    def from_json(self, f: Scalar) -> Calls:
        get = _get(f)
        if f.bits:
            if all(b.preset is not None for b in f.bits):  # every bit field filled in: the value may be left out
                get = Calls(f"data.get({spec_key(f.name)}, {{}})", [])
            # errors inside name the field too: "spin request method: direction must be an integer"
            text = f"{f.bits_class}.from_fields(_mapping({get}, {spec_key(f.name)}, where), where + {' ' + f.name!r})"
            return Calls(text, ["_mapping"], get)
        if f.enum:
            return Calls(f"_as_enum({f.enum.class_name}, {get}, {spec_key(f.name)}, where)", ["_as_enum"], get)
        if f.flags:
            return Calls(
                f"_as_flags({f.flags.class_name}, {get}, {int(f.maximum)}, {spec_key(f.name)}, where)",
                ["_as_flags"],
                get,
            )
        if f.default is not None:
            get = Calls(f"data.get({spec_key(f.name)}, {number(f.default)})", [])
        kind = "_number" if f.type.is_float else "_integer"
        return Calls(f"{kind}({get}, {spec_key(f.name)}, where)", [kind], get)

    def blank(self, f: Scalar) -> str:
        if f.bits:
            return zero_bits(f.bits)
        return number(f.default) if f.default is not None else "0"


class VarintKind(Kind[Varint]):
    model = Varint

    def construct(self, f: Varint, parent: str) -> str:
        return varint.construct(f.bits, f.sign, f.high_first, f.minimum, f.maximum)

    def annotation(self, f: Varint) -> str:
        return "int"

    def from_json(self, f: Varint) -> Calls:
        get = _get(f) if f.default is None else Calls(f"data.get({spec_key(f.name)}, {f.default})", [])
        return Calls(f"_integer({get}, {spec_key(f.name)}, where)", ["_integer"], get)

    def blank(self, f: Varint) -> str:
        return str(f.default if f.default is not None else max(f.minimum, min(0, f.maximum)))


class ArrayKind(Kind[Array]):
    model = Array

    def construct(self, f: Array, parent: str) -> str:
        return f"Array({f.count}, {primitive(f.item, f.endian)})"

    def fixed(self, f: Array) -> bool:
        return True

    def struct_chars(self, f: Array) -> str:
        return f"{f.count}{f.item.struct_char}"

    def annotation(self, f: Array) -> str:
        return _numbers(f.item.is_float)

    def to_json(self, f: Array, expr: str) -> str:
        return f"list({expr})"

    def from_json(self, f: Array) -> Calls:
        return _numbers_from_json(f)

    def blank(self, f: Array) -> str:
        return f"[0] * {f.count}"


class PackedKind(Kind[Packed]):
    model = Packed

    def construct(self, f: Packed, parent: str) -> str:
        return f"PackedInts({f.count}, {f.bits}, {f.lsb_first}, {f.signed})"

    def fixed(self, f: Packed) -> bool:
        return True

    def struct_chars(self, f: Packed) -> str:
        return f"{f.byte_size}s"  # unpacked to integers after the struct call (content.py)

    def annotation(self, f: Packed) -> str:
        return "tuple[int, ...]"

    def to_json(self, f: Packed, expr: str) -> str:
        return f"list({expr})"

    def from_json(self, f: Packed) -> Calls:
        get = _get(f)
        return Calls(f"_integers({get}, {spec_key(f.name)}, where)", ["_integers"], get)

    def blank(self, f: Packed) -> str:
        return f"[{number(max(f.minimum, min(0, f.maximum)))}] * {f.count}"


class ListKind(Kind[List]):
    model = List

    def construct(self, f: List, parent: str) -> str:
        return list_expr(f)

    def annotation(self, f: List) -> str:
        return f"tuple[{list_item_type(f)}, ...]"

    def to_json(self, f: List, expr: str) -> str:
        return f"list({expr})"

    def from_json(self, f: List) -> Calls:
        return _numbers_from_json(f)

    def blank(self, f: List) -> str:
        item = "False" if f.item is None else "0"
        if f.count_from:
            return f"lambda request: [{item}] * request[{f.count_from!r}]"
        if isinstance(f.count, Counted):
            return counts.python_blank(f.count, item)
        return f"[{item}] * {f.count}" if isinstance(f.count, int) else "[]"


class TextKind(Kind[Text]):
    model = Text

    def construct(self, f: Text, parent: str) -> str:
        if f.seven_bit:  # 14-bit characters: fixed or rest (the spec check refused the rest)
            return f"SevenBitText({'GreedyBytes' if f.size == 'rest' else f'Bytes({f.size})'})"
        if isinstance(f.size, int) and f.pad is not None:
            return f"PaddedUtf8({f.size}, {f.pad})"
        if f.size is None:
            return "CString('utf8')"
        if f.size == "rest":
            return "Utf8(GreedyBytes)"
        if isinstance(f.size, Counted):
            return f"Utf8(Bytes({counts.construct_count(f.size)}))"
        return f"Utf8(Bytes({f.size if isinstance(f.size, int) else 'this.' + f.size}))"

    def fixed(self, f: Text) -> bool:
        return isinstance(f.size, int)

    def struct_chars(self, f: Text) -> str:
        return f"{f.size}s"  # decoded to text after the struct call (content.py)

    def annotation(self, f: Text) -> str:
        return "str"

    def from_json(self, f: Text) -> Calls:
        get = _get(f)
        return Calls(f"_text({get}, {spec_key(f.name)}, where)", ["_text"], get)

    def blank(self, f: Text) -> str:
        if isinstance(f.size, int) and f.pad is None:
            return repr(" " * (f.size // 2 if f.seven_bit else f.size))
        if isinstance(f.size, Counted):
            return counts.python_blank(f.size, "' '")
        return "''"


class BytesKind(Kind[Bytes]):
    model = Bytes

    def construct(self, f: Bytes, parent: str) -> str:
        if f.size == "rest":
            return "GreedyBytes"
        if isinstance(f.size, int):
            return f"Bytes({f.size})"
        if isinstance(f.size, Counted):
            return f"Bytes({counts.construct_count(f.size)})"
        # inside a group item the size field sits beside the bytes (BULK WRITE) or in the enclosing content (this._)
        return f"Bytes({'this._' if parent == 'item' else 'this'}.{f.size})"

    def fixed(self, f: Bytes) -> bool:
        return isinstance(f.size, int)

    def struct_chars(self, f: Bytes) -> str:
        return f"{f.size}s"

    def annotation(self, f: Bytes) -> str:
        return "bytes"

    def to_json(self, f: Bytes, expr: str) -> str:
        return f"{expr}.hex(' ')"

    def from_json(self, f: Bytes) -> Calls:
        get = _get(f)
        if f.default is not None:  # left out: its default, as the message class has it
            get = Calls(f"data.get({spec_key(f.name)}, {f.default.hex(' ')!r})", [])
        return Calls(f"_bytes({get}, {spec_key(f.name)}, where)", ["_bytes"], get)

    def blank(self, f: Bytes) -> str:
        if f.default is not None:
            return repr(f.default.hex(" "))
        if f.size_from:  # as many as the request asks for (zeros)
            return f"lambda request: ' '.join(['00'] * (request[{f.size_from!r}] + {f.size_from_adds}))"
        if isinstance(f.size, Counted):
            return counts.python_blank(f.size, "'00'")
        return repr(" ".join(["00"] * f.size)) if isinstance(f.size, int) else "''"


def derived_checks(fields: Sequence[SpecField]) -> list[str]:
    """construct elements to put after `fields`: a Check of each value derived by a `value:` expression (Rebuild
    computes it on build, and reads whatever the frame holds on parse)."""
    return [
        f"derived({f.name!r}, lambda ctx: {expression.render(f.value, lambda name: f'ctx[{name!r}]')})"
        for f in fields
        if isinstance(f, Scalar) and f.value is not None
    ]


class GroupKind(Kind[Group]):
    model = Group

    def construct(self, f: Group, parent: str) -> str:
        names = {i.name for i in f.fields}
        parts = [
            f"{i.name!r} / {kind(i).construct(i, 'this' if isinstance(i, Bytes) and i.size in names else 'item')}"
            for i in f.fields
        ]
        item = "Struct(" + ", ".join(parts + derived_checks(f.fields)) + ")"
        if f.count == "rest":
            return f"GreedyRange({item})"
        if isinstance(f.count, Counted):
            return f"Array({counts.construct_count(f.count)}, {item})"
        count = f.count if isinstance(f.count, int) else f"this.{f.count}"
        return f"Array({count}, {item})"

    def struct_chars(self, f: Group) -> str:
        assert isinstance(f.count, int)
        return "".join(kind(i).struct_chars(i) for i in f.fields) * f.count

    def annotation(self, f: Group) -> str:
        return f"tuple[{f.class_name}, ...]"

    def to_json(self, f: Group, expr: str) -> str:
        return f"[item.to_fields() for item in {expr}]"

    def from_json(self, f: Group) -> Calls:
        get = _get(f)
        text = (
            f"tuple({f.class_name}.from_fields(_mapping(item, {spec_key(f.name)}, where), where) "
            f"for item in _items({get}, {spec_key(f.name)}, where))"
        )
        return Calls(text, ["_mapping", "_items"], get)

    def blank(self, f: Group) -> str:
        if not isinstance(f.count, int | Counted):
            return "[]"
        shown = [i for i in f.fields if not getattr(i, "hidden", False)]  # derived values are computed
        item = "{" + ", ".join(f"{i.name!r}: {self.item_blank(i)}" for i in shown) + "}"
        return counts.python_blank(f.count, item) if isinstance(f.count, Counted) else f"[{item}] * {f.count}"

    @staticmethod
    def item_blank(f: SpecField) -> str:
        """A field's blank in a blank group item, whose other fields are 0: a counted one as long as that makes it."""
        count = counts.counted(f)
        if count is None:
            return kind(f).blank(f)
        least = counts.least(count, dict.fromkeys(counts.names(count), 0))
        if isinstance(f, List | Group):
            return kind(f).blank(replace(f, count=least))
        assert isinstance(f, Bytes | Text)
        return kind(f).blank(replace(f, size=least))


class TableValueKind(Kind[TableValue]):
    model = TableValue

    def construct(self, f: TableValue, parent: str) -> str:
        return f"Switch(this.{f.key}, {f.table.value_constant})"

    def annotation(self, f: TableValue) -> str:
        return "int | float"


class TableBlockKind(Kind[TableBlock]):
    model = TableBlock

    def construct(self, f: TableBlock, parent: str) -> str:
        return f.struct_name

    def fixed(self, f: TableBlock) -> bool:
        return True

    def struct_chars(self, f: TableBlock) -> str:
        return "".join(e.type.struct_char for e in f.entries)

    def annotation(self, f: TableBlock) -> str:
        return f.class_name

    def to_json(self, f: TableBlock, expr: str) -> str:
        return f"{expr}.to_fields()"

    def from_json(self, f: TableBlock) -> Calls:
        get = _get(f)
        text = f"{f.class_name}.from_fields(_mapping({get}, {spec_key(f.name)}, where), where + {' ' + f.name!r})"
        return Calls(text, ["_mapping"], get)

    def blank(self, f: TableBlock) -> str:
        return "{" + ", ".join(f"{e.name!r}: 0" for e in f.entries) + "}"


kind: Registry[Kind[Any]] = Registry(Kind)


def takes_the_rest(f: SpecField | None) -> bool:
    """A field that reads exactly up to the end of the content, whatever its size.

    Not a group of varying-size items: its last item may overrun `end`, which the check after it must catch.
    """
    if isinstance(f, Group):
        return f.count == "rest" and f.item_size is not None
    return isinstance(f, Bytes) and f.size == "rest"


# --- runs of fixed-size fields (one struct call each) ---------------------------------------------------------------


def struct_order(f: SpecField) -> str | None:
    """The struct byte order a fixed-size field is read in, None where none matters (single bytes; a 3-byte scalar
    is read as bytes and converted in its own byte order)."""
    if isinstance(f, Array | TableBlock) or (isinstance(f, Scalar) and not f.odd_width):
        return None if byte_order_free(kind(f).struct_chars(f)) else f.endian
    return None


def run_endian(fields: list[SpecField]) -> str:
    """The struct byte order of a run of fixed-size fields: its multi-byte fields' (fixed_runs keeps one a run), else
    its first field's that has one (single bytes: either order reads them)."""
    order = next((o for o in map(struct_order, fields) if o is not None), None)
    if order is not None:
        return order
    for f in fields:
        if isinstance(f, Array | TableBlock) or (isinstance(f, Scalar) and not f.odd_width):
            return f.endian
    return "<"


def one_order(fields: list[SpecField]) -> bool:
    """Whether fixed-size fields can be one struct: their multi-byte ones have one byte order (a big-endian device
    id after little-endian values, SDS011's, cannot)."""
    return len({struct_order(f) for f in fields} - {None}) <= 1


def struct_format(endian: str, fields: list[SpecField]) -> str:
    """The struct format of a run of fixed-size fields."""
    return endian + "".join(kind(f).struct_chars(f) for f in fields)


def is_fixed_run_member(f: SpecField) -> bool:
    return kind(f).fixed(f)


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


def byte_order_free(fmt: str) -> bool:
    """Whether a struct format holds single bytes only, so that its byte order changes nothing."""
    return all(char in "bBxs?c" for _, char in struct_tokens(fmt))


def fixed_runs(fields: list[SpecField]) -> Iterator[list[SpecField] | SpecField]:
    """Fields in order, each run of fixed-size fields as one list (one struct call), other fields alone."""
    run: list[SpecField] = []
    order: str | None = None  # the run's byte order so far (one_order of the run, kept as it grows)
    for f in fields:
        if is_fixed_run_member(f):
            own = struct_order(f)
            if own is not None and order is not None and own != order:  # another byte order: a run of its own
                yield run
                run, order = [], None
            run.append(f)
            order = order or own
            continue
        if run:
            yield run
            run, order = [], None
        yield f
    if run:
        yield run
