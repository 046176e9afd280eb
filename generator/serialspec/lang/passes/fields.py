"""The content of messages: fields of every kind, shared fields, counts and sizes derived from fields."""

from __future__ import annotations

import re
from dataclasses import replace
from typing import Any, Literal

from serialspec.encodings import bit_run, low_bits, seven_bit, varint
from serialspec.lang import counts, expression, grammar
from serialspec.lang.errors import listed, type_hint
from serialspec.lang.loader import Path
from serialspec.lang.model import (
    MAX_FIXED_SIZE,
    SCALARS,
    Array,
    BitField,
    BitPlace,
    Bytes,
    Count,
    Field,
    Group,
    List,
    Packed,
    Scalar,
    ScalarType,
    TableBlock,
    TableValue,
    Text,
    Varint,
    fixed_size,
    sum_sizes,
    takes_rest,
)
from serialspec.lang.passes.base import RESERVED_FIELD_NAMES, Bad, Pass, camel, enum_span
from serialspec.runtime.hexbytes import parse_hex

FIELD_KINDS = (
    *grammar.FIELD_SCALAR_TYPES,
    "bytes",
    "string",
    "cstring",
    "array",
    "group",
    "table_value",
    "table_block",
)


# Keys of text fields (framing kind text) that a binary field must not have
TEXT_ONLY_FIELD_KEYS = ("precision", "width", "letters", "max_count", "label", "base", "case")


class FieldResolver(Pass):
    """Resolves a message's fields; the commands pass uses it for every message."""

    later_names: frozenset[str] = frozenset()  # the names of the content being resolved (a count naming one not
    # resolved yet names a later field)

    def check_rest(self, fields: tuple[Field, ...], path: Path) -> None:
        for field in fields[:-1]:
            if takes_rest(field):
                self.error((*path, field.name), "only the last field can take the rest of the content")

    def fields(self, raw: dict[str, Any], path: Path, parent: list[Field] | None) -> tuple[Field, ...]:
        resolved: list[Field] = []
        names: set[str] = set()
        every = frozenset(raw)
        for name, item in raw.items():
            self.later_names = every  # to tell a later field from an unknown one (counts.resolve; set each time: a
            # group's fields, resolved inside this loop, set their own)
            field_path = (*path, name)
            self.name(name, field_path, "field name", RESERVED_FIELD_NAMES, keywords=True)
            if name in names:
                self.error(field_path, f"duplicate field {name!r}")
            field = self.guard(field_path, self.field, name, item, field_path, resolved, parent)
            if field is not None and (fixed_size(field) or 0) > MAX_FIXED_SIZE:
                self.error(field_path, f"{fixed_size(field)} bytes: more than a field can hold ({MAX_FIXED_SIZE})")
            if field is not None:
                resolved.append(field)
                names.add(field.name)
        self.check_values(resolved, path)
        return tuple(self.bit_runs(resolved, path, complete=len(resolved) == len(raw)))

    def bit_runs(self, fields: list[Field], path: Path, complete: bool = True) -> list[Field]:
        """Each field of a bit run (encodings/bit_run.py) with its place; a run that does not end on a byte boundary
        is an error at its first field (unless a field is missing, its mistake said: the runs are not known)."""

        def bits(f: Field) -> int | None:
            plain = isinstance(f, Scalar) and not (f.type.is_float or f.bits or f.sign_magnitude or f.low_bits)
            if not isinstance(f, Scalar) or not plain:
                return None
            return bit_run.width(f.type.name) or f.type.size * 8

        listed = [(f.name, bits(f), isinstance(f, Scalar) and bit_run.width(f.type.name) is not None) for f in fields]
        runs, problem = bit_run.runs(listed)
        if problem is not None and complete:
            self.error((*path, problem[0]), problem[1])
        by_name = {f.name: f for f in fields}
        for run in runs:
            size, shift = sum(b for _, b in run) // 8, sum(b for _, b in run)
            earlier: list[tuple[str, int, int]] = []
            for name, width in run:
                shift -= width
                field = by_name[name]
                assert isinstance(field, Scalar)
                place = BitPlace(run[0][0], width, shift, size, tuple(earlier) if shift == 0 else ())
                by_name[name] = replace(field, bit_place=place)
                earlier.append((name, width, shift))
        return [by_name[f.name] for f in fields]

    def check_values(self, fields: list[Field], path: Path) -> None:
        """Every `value:` expression names fields of the same content, and no value depends on itself."""
        by_name = {f.name: f for f in fields}
        for field in fields:
            if not isinstance(field, Scalar) or field.value is None:
                continue
            where = (*path, field.name, "value")
            for name in sorted(set(expression.names(field.value))):
                other = by_name.get(name)
                if other is None:
                    self.error(where, f"unknown field {name!r} in {expression.show(field.value)!r}")
                elif name == field.name:
                    self.error(where, f"{field.name} cannot be derived from itself")
            for node in expression.nodes(field.value):
                other = by_name.get(getattr(node, "name", ""))
                if isinstance(node, expression.Length) and other is not None and not isinstance(other, LISTS):
                    self.error(where, f"len({node.name}): {node.name} is not a list, bytes or text")
                elif isinstance(node, expression.Length) and isinstance(other, Text):
                    # its characters are not its bytes (UTF-8, 7-bit pairs): a value of them made frames that do
                    # not decode
                    self.error(
                        where,
                        f"len({node.name}): {node.name} is text, whose characters are not its bytes; size it by a "
                        f"field (`size: {field.name}`), which encode then writes",
                    )
                integer = isinstance(other, Scalar) and not other.type.is_float
                if isinstance(node, expression.Name) and isinstance(other, Varint):
                    self.error(where, f"{node.name} is a varint: a `value:` names fixed-size integer fields")
                elif isinstance(node, expression.Name) and other is not None and not integer:
                    self.error(where, f"{node.name} is not an integer field (use len({node.name}) for its size)")
                elif isinstance(node, expression.Name) and isinstance(other, Scalar) and other.bits:
                    # its message value is the bit fields, not a number: encode could not compute the expression
                    self.error(where, f"{node.name} has bit fields (bits:): an expression cannot name it")
        seen: set[str] = set()
        for field in fields:
            if isinstance(field, Scalar) and field.value is not None and field.name not in seen:
                cycle = _cycle(field.name, by_name, [])
                if cycle:
                    seen.update(cycle)
                    chain = " -> ".join(cycle)
                    self.error((*path, field.name, "value"), f"derived values depend on each other: {chain}")
        if not seen:
            self.check_value_bounds(fields, by_name, path)

    def check_value_bounds(self, fields: list[Field], by_name: dict[str, Field], path: Path) -> None:
        """Every derived value can fit its field, and no value it can take for any wire values of its fields is
        huge (expression.bounds); a constant one is checked against the field's range."""
        found: dict[str, expression.Bounds | None] = {}

        def of(field: Field) -> expression.Bounds | None:
            """The values a field can hold: its type's (from the wire), and its expression's (on encode)."""
            if field.name in found:
                return found[field.name]
            found[field.name] = None
            if not isinstance(field, Scalar) or field.type.is_float:
                return None
            wire = (int(field.type.minimum), int(field.type.maximum))
            if field.value is None:
                found[field.name] = wire
                return wire
            names: dict[str, expression.Bounds] = {}
            for name in expression.names(field.value):
                other = by_name.get(name)
                known = None if other is None else of(other)
                if known is None and not isinstance(other, LISTS):
                    return None  # an error said so already
                names[name] = known or (0, 0)
            where = (*path, field.name, "value")
            try:
                low, high = expression.bounds(field.value, names)
            except expression.ExpressionError as exc:
                self.error(where, str(exc))
                return None
            shown = expression.show(field.value)
            shown = shown if len(shown) <= 60 else shown[:57] + "..."
            first, last = int(field.minimum), int(field.maximum)
            if low == high and not first <= low <= last:
                said = shown if isinstance(field.value, expression.Const) else f"{shown} = {low}"
                self.error(where, f"{said} does not fit {field.name} ({field.type.name}, {first}..{last})")
            elif high < first or low > last:
                self.error(where, f"{shown} is always outside {field.name}'s {first}..{last}: it is {low}..{high}")
            found[field.name] = (min(low, wire[0]), max(high, wire[1]))
            return found[field.name]

        for field in fields:
            if isinstance(field, Scalar) and field.value is not None:
                of(field)

    def expand(self, item: Any, path: Path) -> dict[str, Any]:
        """A field's mapping, with the short forms and `use:` references expanded."""
        if isinstance(item, str):
            if item in FIELD_KINDS or bit_run.width(item):
                return {"type": item}
            if item in self.shared_fields:
                return self.expand(self.shared_fields[item], ("fields", item))
            raise self.fail(
                path,
                f"unknown type {item!r} ({type_hint(item)}expected one of {', '.join(FIELD_KINDS)}, uN/iN of 1..64 "
                "bits, or a field from `fields:`)",
            )
        if not isinstance(item, dict):
            raise Bad  # neither a type name nor a mapping: the structural check has said so
        spec = dict(item)
        if "use" in spec:
            base_name = spec.pop("use")
            if base_name not in self.shared_fields:
                known = listed(self.shared_fields)
                raise self.fail((*path, "use"), f"unknown shared field {base_name!r} (expected one of: {known})")
            spec = {**self.expand(self.shared_fields[base_name], ("fields", base_name)), **spec}
        if "type" not in spec:
            raise self.fail(path, "missing key 'type'")
        return spec

    def field(self, name: str, item: Any, path: Path, siblings: list[Field], parent: list[Field] | None) -> Field:
        later = self.later_names
        spec = self.expand(item, path)
        kind = spec["type"]
        for text_key in TEXT_ONLY_FIELD_KEYS:
            if text_key in spec:
                self.error(
                    (*path, text_key), f"`{text_key}` belongs to fields of text frames (`framing: {{kind: text}}`)"
                )
        common = dict(
            name=name,
            description=str(spec.get("description", "")),
            description_cn=str(spec.get("description_cn", "")),
            inferred=str(spec.get("inferred", "")),
        )
        endian: Literal["<", ">"] = {"little": "<", "big": ">"}.get(spec.get("endian", ""), self.endian)  # type: ignore[assignment]
        if "varint" in spec and spec.get("encoding") != varint.NAME:
            self.error((*path, "varint"), "`varint` goes with `encoding: varint`")
        if spec.get("encoding") == varint.NAME and kind in SCALARS:
            return self.varint(common, spec, path)
        if kind in SCALARS or bit_run.width(kind):
            return self.scalar(common, spec, path, endian)
        encoding = spec.get("encoding", "plain")
        text_encoding = kind in ("string", "cstring") and encoding == seven_bit.NAME
        if encoding != "plain" and not text_encoding:
            what = "a string takes only seven_bit (14-bit characters)" if kind == "string" else f"a {kind} has none"
            self.error((*path, "encoding"), f"`encoding` is how an integer is stored: {what}")
        if "default" in spec and kind != "bytes":
            self.error((*path, "default"), f"`default` goes with a number or bytes of a fixed size, not a {kind}")
        if kind == "bytes":
            size = spec.get("size")
            if size is None:
                raise self.fail(path, "bytes need `size`: a number, `rest`, or a field name")
            if isinstance(size, int) and size < 1:
                raise self.fail((*path, "size"), f"size {size}: bytes of a fixed size hold at least one byte")
            table = self.reference("table", self.tables, spec.get("table"), (*path, "table"))
            size = self.count_of(size, "size", name, siblings, parent, path, later)
            size_from, size_from_adds = self.size_from(spec.get("size_from"), (*path, "size_from"))
            if size_from and size != "rest":
                self.error((*path, "size_from"), "`size_from: request.<field>` goes with `size: rest`")
            if size_from_adds and table is not None:
                self.error((*path, "size_from"), "a run of registers is as long as the request's field: no `+ N`")
            start = str(spec.get("start", ""))
            if start and table is None:
                self.error((*path, "start"), "`start` goes with `table:` (the bytes are a run of its registers)")
            if start and not start.startswith("request."):
                earlier = [f for f in (*siblings, *(parent or ())) if f.name == start]
                if not earlier or not isinstance(earlier[0], Scalar) or earlier[0].type.is_float:
                    raise self.fail(
                        (*path, "start"), f"unknown field {start!r}: `start` names an earlier integer field"
                    )
            default = self.bytes_default(spec.get("default"), size, (*path, "default"))
            return Bytes(
                **common,
                default=default,
                size=size,
                table=table,
                start=start.removeprefix("request."),
                start_in_request=start.startswith("request."),
                size_from=size_from,
                size_from_adds=size_from_adds,
            )
        if kind in ("string", "cstring"):
            size = spec.get("size")
            if "pad" in spec and (kind == "cstring" or not isinstance(size, int)):
                self.error((*path, "pad"), "`pad` goes with a string of a fixed size (a number)")
            if kind == "cstring":
                if size is not None:
                    self.error((*path, "size"), "a cstring ends at its NUL byte: it takes no `size`")
                if text_encoding:
                    self.error((*path, "encoding"), seven_bit.text_problem(None, False))
                return Text(**common, size=None, pad=None, seven_bit=False)
            if size is None:
                raise self.fail(path, "a string needs `size`: a number, `rest`, or a field name (or use cstring)")
            size = self.count_of(size, "size", name, siblings, parent, path, later)
            if text_encoding and (why := seven_bit.text_problem(size, "pad" in spec)):
                self.error((*path, "encoding"), why)
            pad = self.pad(spec.get("pad"), size, (*path, "pad"))
            return Text(**common, size=size, pad=pad, seven_bit=text_encoding)
        if kind == "array" and (odd := [key for key in ("scale", "offset") if key in spec]):
            self.error(  # an array's items are kept, shown and plotted as sent: a scale would be silently lost
                (*path, odd[0]), f"`{odd[0]}` goes with a number field, not an array (give the unit of one wire step)"
            )
        if kind == "array" and _PACKED.match(str(spec.get("of", ""))) and str(spec["of"]) not in _BYTE_ALIGNED:
            return self.packed(common, spec, path, endian)
        if "bit_order" in spec:
            self.error((*path, "bit_order"), "`bit_order` goes with an array of uN or iN items (e.g. of: u11)")
        if kind == "array" and (spec.get("of") == "bit" or not isinstance(spec.get("count"), int) or "size" in spec):
            return self.list_field(common, spec, path, endian, siblings, later)
        if kind == "array":
            item_type = self.scalar_type(spec.get("of"), (*path, "of"), for_field=True)
            count = spec.get("count")
            if not isinstance(count, int) or count < 1:
                raise self.fail((*path, "count"), "an array needs a fixed `count` (use a group for counted items)")
            low, high = self.bounds(item_type, False, spec.get("range"), (*path, "range"))
            return Array(
                **common,
                item=item_type,
                endian=endian,
                count=count,
                unit=str(spec.get("unit", "")),
                minimum=low,
                maximum=high,
            )
        if kind == "group":
            count = spec.get("count")
            if count is None:
                raise self.fail(path, "a group needs `count`: a number, `rest`, or the name of an earlier count field")
            if not isinstance(spec.get("fields"), dict):
                raise self.fail(path, "a group needs `fields:` (a mapping of its item's fields)")
            if not spec["fields"]:
                raise self.fail((*path, "fields"), "a group needs at least one field in each item")
            inner = self.fields(spec["fields"], (*path, "fields"), parent=siblings)
            count = self.count_of(count, "count", name, siblings, None, path, later)
            item_size = sum_sizes(inner)
            class_name = self.class_name(camel(name, "item"), path, identity=("group", inner), scoped=True)
            return Group(**common, class_name=class_name, count=count, fields=inner, item_size=item_size)
        if kind == "table_value":
            table = self.reference("table", self.tables, spec.get("table"), (*path, "table"))
            key = spec.get("key")
            if table is None or not any(f.name == key for f in siblings):
                raise self.fail(path, "a table_value needs `table:` and `key:` naming an earlier field")
            return TableValue(**common, table=table, key=str(key))
        if kind == "table_block":
            table = self.reference("table", self.tables, spec.get("table"), (*path, "table"))
            if table is None:
                raise self.fail(path, "a table_block needs `table:`")
            select = spec.get("select") or {}
            entries = tuple(
                e for e in table.entries if all(str(getattr(e, k, None)) == str(v) for k, v in select.items())
            )
            size = sum(e.type.size for e in entries)
            expected = spec.get("expect_size")
            if expected is not None and size != expected:
                self.error((*path, "expect_size"), f"the selected entries take {size} bytes, not {expected}")
            class_name = self.class_name(camel(name), path, identity=("table_block", table.name, entries))
            struct_name = self.class_name(f"{class_name}Block", path, identity=("table_block", table.name, entries))
            return TableBlock(
                **common, table=table, class_name=class_name, entries=entries, endian=endian, struct_name=struct_name
            )
        kinds = ", ".join(FIELD_KINDS)
        raise self.fail(
            (*path, "type"), f"unknown type {kind!r} ({type_hint(kind)}expected one of {kinds}, or uN/iN of 1..64 bits)"
        )

    def pad(self, pad: Any, size: Any, path: Path) -> int | None:
        """The pad byte of a fixed-size string, from its hex ('00')."""
        if pad is None or not isinstance(size, int):
            return None
        try:
            value = bytes.fromhex(str(pad))
        except ValueError:
            value = b""
        if len(value) != 1:
            raise self.fail(path, f"pad {pad!r} must be one byte in hex, e.g. '00'")
        return value[0]

    def packed(self, common: dict[str, Any], spec: dict[str, Any], path: Path, endian: Literal["<", ">"]) -> Packed:
        """An array of integers of any number of bits (1..64), packed with no gaps."""
        of = str(spec["of"])
        bits = int(of[1:])
        if not 1 <= bits <= 64:
            raise self.fail((*path, "of"), f"{of}: packed integers take 1..64 bits")
        count = spec.get("count")
        if not isinstance(count, int) or count < 1 or "size" in spec:
            raise self.fail((*path, "count"), f"an array of {of} items needs a fixed `count` (a number)")
        signed = of.startswith("i")
        low_type, high_type = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
        low, high = float(low_type), float(high_type)
        given = spec.get("range")
        if given is not None:
            low, high = float(given[0]), float(given[1])
            if not low_type <= low <= high <= high_type:
                self.error((*path, "range"), f"range {low:g}..{high:g} does not fit {of} ({low_type}..{high_type})")
        order = spec.get("bit_order", "lsb_first" if endian == "<" else "msb_first")
        return Packed(
            **common,
            bits=bits,
            signed=signed,
            count=count,
            lsb_first=order == "lsb_first",
            unit=str(spec.get("unit", "")),
            minimum=low,
            maximum=high,
        )

    def list_field(
        self,
        common: dict[str, Any],
        spec: dict[str, Any],
        path: Path,
        endian: Literal["<", ">"],
        siblings: list[Field],
        later: frozenset[str],
    ) -> List:
        """An array whose count varies (a count field, a byte-size field, the rest), or an array of bits."""
        name = common["name"]
        bits = spec.get("of") == "bit"
        item_type = None if bits else self.scalar_type(spec.get("of"), (*path, "of"), for_field=True)
        if item_type is not None and item_type.size == 3:
            raise self.fail((*path, "count"), f"an array of {item_type.name} items needs a fixed `count` (a number)")
        count = spec.get("count", "")
        size = spec.get("size", "")
        if bool(count) == bool(size):
            raise self.fail(path, "an array of varying size needs `count` (items) or `size` (a byte-size field)")
        if isinstance(count, int) and count < 1:
            raise self.fail((*path, "count"), "an array's count must be at least 1")
        if size and not isinstance(size, str) or size == "rest":
            raise self.fail((*path, "size"), "an array's `size` names the earlier field holding its size in bytes")
        if count:
            count = self.count_of(count, "count", name, siblings, None, path, later)
        if size:
            self.derive(size, ("size", name), siblings, path)
        if bits:
            if "range" in spec:
                self.error((*path, "range"), "bits are true or false: no range")
            low, high = 0.0, 1.0
        else:
            assert item_type is not None
            low, high = self.bounds(item_type, False, spec.get("range"), (*path, "range"))
        return List(
            **common,
            item=item_type,
            endian=endian,
            count=count,
            size=str(size),
            unit=str(spec.get("unit", "")),
            minimum=low,
            maximum=high,
            count_from=self.count_from(spec.get("count_from"), (*path, "count_from")),
        )

    def count_from(self, value: Any, path: Path) -> str:
        if value is None:
            return ""
        if not str(value).startswith("request."):
            self.error(path, "`count_from` names a field of the request: request.<field>")
        return str(value).removeprefix("request.")

    def value_expression(self, text: Any, path: Path) -> expression.Expr | None:
        if text is None:
            return None
        try:
            return expression.parse(text)
        except expression.ExpressionError as exc:
            raise self.fail(path, str(exc)) from None

    def bytes_default(self, given: Any, size: Count, path: Path) -> bytes | None:
        """A bytes field's `default`: hex text of exactly its fixed size."""
        if given is None:
            return None
        if not isinstance(size, int):
            self.error(path, f"`default` goes with bytes of a fixed size (a number), not size {size}")
            return None
        if not isinstance(given, str):
            self.error(path, f"expected hex text of {size} bytes ('{' '.join(['00'] * min(size, 4))}'), got {given!r}")
            return None
        try:
            value = parse_hex(given)
        except ValueError as exc:
            self.error(path, str(exc))
            return None
        if len(value) != size:
            self.error(path, f"{len(value)} bytes, the field's size is {size}")
            return None
        return value

    def scalar(self, common: dict[str, Any], spec: dict[str, Any], path: Path, endian: Literal["<", ">"]) -> Scalar:
        sign_magnitude = spec.get("encoding") == "sign_magnitude"
        scalar = self.stored(field_type(spec["type"]), sign_magnitude, (*path, "encoding"))
        if bit_run.width(scalar.name) and (odd := [k for k in ("bits", "flags", "encoding", "endian") if k in spec]):
            raise self.fail(
                (*path, odd[0]), f"`{odd[0]}` does not go with a bit field ({scalar.name}: packed MSB first)"
            )
        encoding = low_bits.ENCODINGS.get(str(spec.get("encoding")))  # a few bits a byte (encodings/low_bits.py)
        if encoding is not None and (why := encoding.problem(scalar.name, scalar.is_float)):
            self.error((*path, "encoding"), why)
            encoding = None
        if encoding is not None and (mixed := [key for key in ("const", "bits", "flags", "value") if key in spec]):
            self.error(
                (*path, mixed[0]),
                f"`{mixed[0]}` does not go with encoding {encoding.name} (a number {encoding.bits} bits a byte)",
            )
        low, high = self.bounds(scalar, sign_magnitude, spec.get("range"), (*path, "range"), low_bits=encoding)
        value_enum = self.reference("enum", self.enums, spec.get("enum"), (*path, "enum"))
        if value_enum is not None and spec.get("range") is None:
            low, high = enum_span(value_enum, low, high)
        const = spec.get("const")
        if isinstance(const, bool) or not isinstance(const, int):  # none, or not an integer (the grammar said so)
            const = None
        if const is not None and not low <= const <= high:
            self.error((*path, "const"), f"constant {const} is outside {low:g}..{high:g}")
        if spec.get("scale") == 0:
            self.error((*path, "scale"), "scale 0 would make every value 0 (give the size of one wire step)")
        if "offset" in spec and any(k in spec for k in ("enum", "flags", "bits")):
            self.error((*path, "offset"), "`offset` goes with a number, not an enum, flags or bit fields")
        default = spec.get("default")
        if isinstance(default, str):
            raise self.fail((*path, "default"), f"expected a number, got text ({default!r})")
        if default is not None and not low <= default <= high:
            self.error((*path, "default"), f"default {default} is outside the range {low:g}..{high:g}")
        bits: list[BitField] = []
        used = 0
        for bit_name, bit_spec in (spec.get("bits") or {}).items():
            bit_path = (*path, "bits", bit_name)
            self.name(bit_name, bit_path, "bit field name")
            if not isinstance(bit_spec, dict):  # the short form: the bit number or [high, low] alone
                bit_spec = {"bits": bit_spec}
            where = bit_spec["bits"]
            high_bit, low_bit = (where, where) if isinstance(where, int) else (where[0], where[1])
            if not 0 <= low_bit <= high_bit < scalar.size * 8:
                self.error(bit_path, f"bits {high_bit}..{low_bit} do not fit a {scalar.name}")
                continue
            mask = ((1 << (high_bit - low_bit + 1)) - 1) << low_bit
            if used & mask:
                self.error(bit_path, "overlaps another bit field")
            used |= mask
            enum = self.reference("enum", self.enums, bit_spec.get("enum"), (*bit_path, "enum"))
            preset: dict[str, int | None] = {}
            for key in ("const", "default"):
                value = bit_spec.get(key)
                if value is not None and not 0 <= value <= mask >> low_bit:
                    self.error(
                        (*bit_path, key),
                        f"{key} {value} does not fit bits {high_bit}..{low_bit} (0..{mask >> low_bit})",
                    )
                    value = None
                preset[key] = value
            if preset["const"] is not None and preset["default"] is not None:
                self.error((*bit_path, "default"), "a constant bit field has no default: it is always its `const`")
            description = str(bit_spec.get("description", ""))
            bits.append(BitField(bit_name, high_bit, low_bit, enum, description, preset["const"], preset["default"]))
        if bits and (scalar.is_float or scalar.signed):
            self.error((*path, "bits"), "bit fields need an unsigned integer type")
        return Scalar(
            **common,
            type=scalar,
            endian=endian,
            unit=str(spec.get("unit", "")),
            scale=spec.get("scale"),
            minimum=low,
            maximum=high,
            const=const,
            default=default,
            enum=value_enum,
            flags=self.reference("flags", self.flags, spec.get("flags"), (*path, "flags")),
            bits=tuple(bits),
            bits_class=self.class_name(camel(common["name"], "bits"), path, ("bits", *bits), True) if bits else "",
            sign_magnitude=sign_magnitude,
            status_ok=self.status_ok(spec.get("status"), scalar, low, high, (*path, "status")),
            value=self.derived_value(spec, scalar, path),
            offset=spec.get("offset"),
            value_at=self.doc.where((*path, "value")),
            low_bits=encoding,
        )

    def varint(self, common: dict[str, Any], spec: dict[str, Any], path: Path) -> Field:
        """An integer in as many bytes as its value needs (encodings/varint.py)."""
        scalar = SCALARS[spec["type"]]
        options = spec.get("varint") or {}
        sign = str(options.get("sign", ""))
        if why := varint.problem(scalar.name, scalar.signed, scalar.is_float, sign):
            raise self.fail((*path, "varint") if sign else (*path, "encoding"), why)
        if odd := [key for key in varint.REFUSED_KEYS if key in spec]:
            raise self.fail((*path, odd[0]), f"`{odd[0]}` does not go with encoding varint (a plain number)")
        low, high = self.bounds(scalar, False, spec.get("range"), (*path, "range"))
        default = spec.get("default")
        if isinstance(default, str) or (default is not None and not float(default).is_integer()):
            raise self.fail((*path, "default"), f"expected a whole number, got {default!r}")
        if default is not None and not low <= default <= high:
            self.error((*path, "default"), f"default {default} is outside the range {low:g}..{high:g}")
        bits = int(options.get("bits", 7))
        sign_: Literal["", "zigzag", "low_bit"] = "zigzag" if sign == "zigzag" else "low_bit" if sign else ""
        return Varint(
            **common,
            type=scalar,
            bits=bits,
            sign=sign_,
            high_first=options.get("order") == "high_first",
            unit=str(spec.get("unit", "")),
            minimum=int(low),
            maximum=int(high),
            default=None if default is None else int(default),
            most_bytes=varint.most_bytes(int(low), int(high), bits, sign),
        )

    def derived_value(self, spec: dict[str, Any], scalar: ScalarType, path: Path) -> expression.Expr | None:
        value = self.value_expression(spec.get("value"), (*path, "value"))
        if value is not None:
            if scalar.is_float:
                self.error((*path, "value"), "a derived value needs an integer type")
            for other in ("const", "default", "bits", "enum", "flags"):
                if other in spec:
                    self.error((*path, other), f"a derived value (`value:`) takes no `{other}`")
        return value

    def status_ok(self, status: Any, scalar: ScalarType, low: float, high: float, path: Path) -> int | None:
        if status is None:
            return None
        ok = int(status["ok"])
        if scalar.is_float:
            self.error(path, "a status needs an integer type")
        elif not low <= ok <= high:
            self.error((*path, "ok"), f"{ok} is outside the field's range {low:g}..{high:g}")
        return ok

    def derive(self, name: str, derivation: tuple[str, ...], siblings: list[Field], path: Path) -> None:
        for index, field in enumerate(siblings):
            if field.name == name:
                if isinstance(field, Scalar) and field.value is not None and not field.derived:
                    return  # derived by its own expression, which decoding checks
                if not isinstance(field, Scalar) or field.type.is_float or field.hidden:
                    raise self.fail(path, f"{name!r} must be an earlier integer field that nothing else derives")
                if field.low_bits is not None:
                    raise self.fail(path, f"{name!r} holds a count or size: plain, not encoding {field.low_bits.name}")
                siblings[index] = replace(field, derived=derivation)
                return
        raise self.fail(path, f"unknown field {name!r}: a count or size must be an earlier field of the same content")

    def count_of(
        self,
        value: Any,
        key: str,
        name: str,
        siblings: list[Field],
        parent: list[Field] | None,
        path: Path,
        later: frozenset[str],
    ) -> Count:
        """A count or size as given: a number or `rest` as it is; a field's name, that field made derived (encode
        writes the length); an expression over earlier fields, which stay in the message (serialspec/lang/counts.py)."""
        if not isinstance(value, str) or value == "rest":
            return value  # type: ignore[no-any-return]
        try:
            parsed = counts.parse(value)
            if isinstance(parsed, str):
                if key == "size":
                    self.size_field(parsed, name, siblings, parent, path)
                else:
                    self.derive(parsed, ("count", name), siblings, path)
                return parsed
            return counts.resolve(parsed, siblings, later)
        except counts.CountError as exc:
            raise self.fail((*path, key), str(exc)) from None

    def size_from(self, value: Any, path: Path) -> tuple[str, int]:
        """`size_from: request.<field>`, or `request.<field> + N` (`- N`): the request field and the bytes added."""
        if value is None:
            return "", 0
        match = re.fullmatch(r"\s*request\.([a-z_][a-z0-9_]*)\s*(?:([+-])\s*(\d+)\s*)?", str(value))
        if match is None:
            if not str(value).startswith("request."):
                self.error(path, "`size_from: request.<field>` goes with `size: rest`")
            else:
                self.error(path, "`size_from` is `request.<field>`, or `request.<field> + N` (a count minus one)")
            return "", 0
        name, sign, number = match.groups()
        return name, (int(number) if sign == "+" else -int(number)) if number else 0

    def size_field(self, size: str, name: str, siblings: list[Field], parent: list[Field] | None, path: Path) -> None:
        """Bytes sized by a field: an earlier field of the item (or the message); inside a group, where the item has
        no field of that name, a field before the group sets the size of every item (the innermost field of a name
        is the one meant, as the generated decoders read it)."""
        if parent is not None and any(f.name == size for f in parent) and not any(f.name == size for f in siblings):
            self.derive(size, ("size", name), parent, path)
        else:
            self.derive(size, ("size", name), siblings, path)


def field_type(name: str) -> ScalarType:
    """A field's integer or float type by name: one of SCALARS, or a bit-field type (u12, i38)."""
    bits = bit_run.width(name)
    if bits is None:
        return SCALARS[name]
    low, high = bit_run.limits(bits, name.startswith("i"))
    return ScalarType(name, bit_run.size_of(bits), "", name.startswith("i"), False, low, high)


LISTS = (Array, Packed, List, Bytes, Text, Group)
_PACKED = re.compile(r"^[ui][0-9]{1,3}$")  # `of: u11`: packed integers (u8, u16, ... are byte-aligned arrays)
_BYTE_ALIGNED = ("u8", "i8", "u16", "i16", "u32", "i32", "u64", "i64")


def _cycle(name: str, fields: dict[str, Field], trail: list[str]) -> list[str]:
    """A chain of `value:` expressions from `name` back to a field already on the trail, or []."""
    if name in trail:
        return [*trail[trail.index(name) :], name]
    field = fields.get(name)
    if not isinstance(field, Scalar) or field.value is None:
        return []
    for other in expression.names(field.value):
        found = _cycle(other, fields, [*trail, name])
        if found:
            return found
    return []
