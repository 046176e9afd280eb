"""How each field kind looks in the generated Python: one class per model field kind, registered by model class.

An emitter asks `kind(f)` instead of switching on the field's class, so a new field kind adds one class here (and
the rest of its behaviour where it has not moved yet: decoding and encoding in pycode.py, the docs, the CLI views).
"""

from __future__ import annotations

from typing import Any, Generic

from serialspec.emit.common.kinds import F, Registry
from serialspec.emit.common.numbers import number
from serialspec.spec.model import Array, Bytes, Group, List, Scalar, TableBlock, TableValue, Text
from serialspec.spec.model import Field as SpecField


def _get(f: SpecField) -> str:
    """The expression reading a field's JSON value from `data` (the generated `from_fields`)."""
    return f"_get(data, {f.name!r}, where)"


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

    def to_json(self, f: F, expr: str) -> str:
        """The JSON value of `expr`, a value of the field (the generated `to_fields`)."""
        return expr

    def from_json(self, f: F) -> str:
        """The field's value from `data` (the generated `from_fields`), refusing a wrong kind of value."""
        return _get(f)


def _numbers(is_float: bool) -> str:
    return "tuple[float, ...]" if is_float else "tuple[int, ...]"


class ScalarKind(Kind[Scalar]):
    model = Scalar

    def fixed(self, f: Scalar) -> bool:
        return True

    def struct_chars(self, f: Scalar) -> str:
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

    def from_json(self, f: Scalar) -> str:
        get = _get(f)
        if f.bits:
            # errors inside name the field too: "spin request method: direction must be an integer"
            return f"{f.bits_class}.from_fields(_mapping({get}, {f.name!r}, where), where + {' ' + f.name!r})"
        if f.enum:
            return f"_as_enum({f.enum.class_name}, {get}, {f.name!r}, where)"
        if f.flags:
            return f"_as_flags({f.flags.class_name}, {get}, {int(f.maximum)}, {f.name!r}, where)"
        if f.default is not None:
            get = f"data.get({f.name!r}, {number(f.default)})"
        kind = "_number" if f.type.is_float else "_integer"
        return f"{kind}({get}, {f.name!r}, where)"


class ArrayKind(Kind[Array]):
    model = Array

    def fixed(self, f: Array) -> bool:
        return True

    def struct_chars(self, f: Array) -> str:
        return f"{f.count}{f.item.struct_char}"

    def annotation(self, f: Array) -> str:
        return _numbers(f.item.is_float)

    def to_json(self, f: Array, expr: str) -> str:
        return f"list({expr})"

    def from_json(self, f: Array) -> str:
        kind = "_numbers" if f.item.is_float else "_integers"
        return f"{kind}({_get(f)}, {f.name!r}, where)"


class ListKind(Kind[List]):
    model = List

    def annotation(self, f: List) -> str:
        return "tuple[bool, ...]" if f.item is None else _numbers(f.item.is_float)

    def to_json(self, f: List, expr: str) -> str:
        return f"list({expr})"

    def from_json(self, f: List) -> str:
        return f"tuple(bool(x) for x in {_get(f)})" if f.bits else f"tuple({_get(f)})"


class TextKind(Kind[Text]):
    model = Text

    def annotation(self, f: Text) -> str:
        return "str"

    def from_json(self, f: Text) -> str:
        return f"str({_get(f)})"


class BytesKind(Kind[Bytes]):
    model = Bytes

    def fixed(self, f: Bytes) -> bool:
        return isinstance(f.size, int)

    def struct_chars(self, f: Bytes) -> str:
        return f"{f.size}s"

    def annotation(self, f: Bytes) -> str:
        return "bytes"

    def to_json(self, f: Bytes, expr: str) -> str:
        return f"{expr}.hex(' ')"

    def from_json(self, f: Bytes) -> str:
        return f"_bytes({_get(f)}, {f.name!r}, where)"


class GroupKind(Kind[Group]):
    model = Group

    def struct_chars(self, f: Group) -> str:
        assert isinstance(f.count, int)
        return "".join(kind(i).struct_chars(i) for i in f.fields) * f.count

    def annotation(self, f: Group) -> str:
        return f"tuple[{f.class_name}, ...]"

    def to_json(self, f: Group, expr: str) -> str:
        return f"[item.to_fields() for item in {expr}]"

    def from_json(self, f: Group) -> str:
        return (
            f"tuple({f.class_name}.from_fields(_mapping(item, {f.name!r}, where), where) "
            f"for item in _items({_get(f)}, {f.name!r}, where))"
        )


class TableValueKind(Kind[TableValue]):
    model = TableValue

    def annotation(self, f: TableValue) -> str:
        return "int | float"


class TableBlockKind(Kind[TableBlock]):
    model = TableBlock

    def fixed(self, f: TableBlock) -> bool:
        return True

    def struct_chars(self, f: TableBlock) -> str:
        return "".join(e.type.struct_char for e in f.entries)

    def annotation(self, f: TableBlock) -> str:
        return f.class_name

    def to_json(self, f: TableBlock, expr: str) -> str:
        return f"{expr}.to_fields()"

    def from_json(self, f: TableBlock) -> str:
        return f"{f.class_name}.from_fields(_mapping({_get(f)}, {f.name!r}, where), where + {' ' + f.name!r})"


kind: Registry[Kind[Any]] = Registry(Kind)
