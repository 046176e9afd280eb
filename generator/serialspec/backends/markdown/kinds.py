"""How each field kind reads in the generated docs: one class per model field kind, registered by model class.

The docs ask `kind(f)` instead of switching on the field's class, so a new field kind adds one class here.
"""

from __future__ import annotations

from typing import Any, Generic

from serialspec.backends.common.kinds import F, Registry
from serialspec.backends.common.numbers import number
from serialspec.encodings import seven_bit, varint
from serialspec.lang import expression
from serialspec.lang.model import (
    Array,
    BitField,
    Bytes,
    Counted,
    Group,
    List,
    Packed,
    Scalar,
    TableBlock,
    TableValue,
    Text,
    Varint,
)


def anchor(*parts: str) -> str:
    return "-".join(p.replace("_", "-").replace(".", "-") for p in parts if p).lower()


def value_range(minimum: float, maximum: float, is_float: bool, type_min: float, type_max: float) -> str:
    """A range as people read it: `any` for a float's whole range, never a 39-digit number."""
    if is_float and (minimum, maximum) == (type_min, type_max):
        return "any"
    show = (lambda v: f"{v:g}") if is_float else number
    return f"{show(minimum)}..{show(maximum)}"


def scalar_range(type_: Any, minimum: float, maximum: float) -> str:
    return value_range(minimum, maximum, type_.is_float, type_.minimum, type_.maximum)


class Kind(Generic[F]):
    """What a field kind shows in a field table. The defaults fit a kind with no unit, range or extra meaning."""

    def type_name(self, f: F) -> str:
        raise NotImplementedError

    def unit(self, f: F) -> str:
        return ""

    def range_text(self, f: F) -> str:
        return ""

    def meaning(self, f: F) -> list[str]:
        """What the meaning column says beyond the field's description."""
        return []


class VarintKind(Kind[Varint]):
    model = Varint

    def type_name(self, f: Varint) -> str:
        return f.type.name + varint.type_note(f.bits, f.sign, f.high_first, f.most_bytes)

    def unit(self, f: Varint) -> str:
        return f.unit

    def range_text(self, f: Varint) -> str:
        return scalar_range(f.type, f.minimum, f.maximum)

    def meaning(self, f: Varint) -> list[str]:
        return [f"default {f.default}"] if f.default is not None else []


class ScalarKind(Kind[Scalar]):
    model = Scalar

    def type_name(self, f: Scalar) -> str:
        name = f.type.name + (" (sign-magnitude)" if f.sign_magnitude else "")
        name += f.low_bits.type_note if f.low_bits is not None else ""
        if f.enum:
            name += f" enum [{f.enum.class_name}](#enum-{anchor(f.enum.name)})"
        if f.flags:
            name += f" flags [{f.flags.class_name}](#flags-{anchor(f.flags.name)})"
        return name

    def unit(self, f: Scalar) -> str:
        return f.unit

    def range_text(self, f: Scalar) -> str:
        if f.const is not None:
            return f"= {f.const:#04x}"
        if f.value is not None:
            return f"= {expression.show(f.value)}"
        if f.derived:
            return "derived: " + (
                f"number of {f.derived[1]}" if f.derived[0] == "count" else f"size of each {f.derived[1]}"
            )
        if f.bits:
            return ""
        shown = scalar_range(f.type, f.minimum, f.maximum)
        if f.offset is not None and not f.type.is_float:  # the engineering values too: wire × scale + offset
            scale = 1 if f.scale is None else f.scale
            low, high = sorted((f.minimum * scale + f.offset, f.maximum * scale + f.offset))
            shown += f" (engineering {number(round(low, 6))}..{number(round(high, 6))})"
        return shown

    def meaning(self, f: Scalar) -> list[str]:
        parts = []
        if f.bits:
            parts += bit_lines(f.bits)
            parts.append("Other bits must be zero.")
        if f.status_ok is not None:
            parts.append(f"**Status:** {f.status_ok} is success; any other value is a device error (DeviceError).")
        if f.offset is not None:
            step = f"wire value × {number(f.scale)}" if f.scale is not None else "wire value"
            parts.append(f"Engineering value = {step} {'-' if f.offset < 0 else '+'} {number(abs(f.offset))}.")
        return parts


class ArrayKind(Kind[Array]):
    model = Array

    def type_name(self, f: Array) -> str:
        return f"{f.item.name}[{f.count}]"

    def unit(self, f: Array) -> str:
        return f.unit

    def range_text(self, f: Array) -> str:
        return scalar_range(f.item, f.minimum, f.maximum)


class PackedKind(Kind[Packed]):
    model = Packed

    def type_name(self, f: Packed) -> str:
        order = "lowest bit first" if f.lsb_first else "highest bit first"
        return f"{'i' if f.signed else 'u'}{f.bits}[{f.count}], packed ({f.byte_size} bytes, {order})"

    def unit(self, f: Packed) -> str:
        return f.unit

    def range_text(self, f: Packed) -> str:
        return f"{number(f.minimum)}..{number(f.maximum)}"


class ListKind(Kind[List]):
    model = List

    def type_name(self, f: List) -> str:
        item = "bits (8 per byte, first in bit 0)" if f.item is None else f"{f.item.name} list"
        if f.size:
            return f"{item}, {f.size} bytes"
        count = f"({f.count})" if isinstance(f.count, Counted) else f.count
        return f"{item}, up to the end" if f.count == "rest" else f"{item} × {count}"

    def unit(self, f: List) -> str:
        return f.unit

    def range_text(self, f: List) -> str:
        return "" if f.item is None else scalar_range(f.item, f.minimum, f.maximum)


class TextKind(Kind[Text]):
    model = Text

    def type_name(self, f: Text) -> str:
        return self.plain_name(f) + (seven_bit.TEXT_NOTE if f.seven_bit else "")

    def plain_name(self, f: Text) -> str:
        if f.size is None:
            return "text, NUL-terminated"
        if f.size == "rest":
            return "text (rest of content)"
        return f"text ({f.size} bytes{f', padded with {f.pad:02X}' if f.pad is not None else ''})"


class BytesKind(Kind[Bytes]):
    model = Bytes

    def type_name(self, f: Bytes) -> str:
        size = "rest of content" if f.size == "rest" else f.size
        return f"bytes ({size})"

    def meaning(self, f: Bytes) -> list[str]:
        return [f"Default `{f.default.hex(' ')}`."] if f.default is not None else []


class GroupKind(Kind[Group]):
    model = Group

    def type_name(self, f: Group) -> str:
        count = {"rest": "up to the end"}.get(
            str(f.count), f"× ({f.count})" if isinstance(f.count, Counted) else f"× {f.count}"
        )
        return f"group {count}"


class TableValueKind(Kind[TableValue]):
    model = TableValue

    def type_name(self, f: TableValue) -> str:
        return f"typed by {f.key} ([{f.table.title}](#table-{anchor(f.table.name)}))"


class TableBlockKind(Kind[TableBlock]):
    model = TableBlock

    def type_name(self, f: TableBlock) -> str:
        return f"block of [{f.table.title}](#table-{anchor(f.table.name)})"


kind: Registry[Kind[Any]] = Registry(Kind)


def bit_lines(bits: tuple[BitField, ...]) -> list[str]:
    """A sentence per bit field: its bits, name, enum and constant or default value."""
    parts = []
    for bit in bits:
        where = f"bit {bit.low}" if bit.high == bit.low else f"bits {bit.high}..{bit.low}"
        enum = f" ({', '.join(f'{v.value}={v.name.lower()}' for v in bit.enum.values)})" if bit.enum else ""
        preset = ""
        if bit.const is not None:
            preset = f", always {bit.const} (a frame with another value is refused)"
        elif bit.default is not None:
            preset = f", default {bit.default}"
        parts.append(f"{where}: {bit.name}{enum}{preset}.")
    return parts
