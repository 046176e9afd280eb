"""Enums, flags and tables: the named types fields and frame elements refer to."""

from __future__ import annotations

import keyword
from typing import Any

from serialspec.lang.errors import SpecError
from serialspec.lang.loader import Path
from serialspec.lang.model import (
    EnumDef,
    EnumValue,
    FlagBit,
    FlagsDef,
    ScalarType,
    Table,
    TableEntry,
)
from serialspec.lang.passes.base import LABEL, Pass, camel, enum_span


class Types(Pass):
    """Resolve `enums:`, `flags:` and `tables:` into the context, in that order (tables use both)."""

    def run(self) -> list[SpecError]:
        for key, value in self.section("enums").items():
            self.guard(("enums", key), self.enum, key, value, ("enums", key))
        for key, value in self.section("flags").items():
            self.guard(("flags", key), self.flag_set, key, value, ("flags", key))
        for key, value in self.section("tables").items():
            self.guard(("tables", key), self.table, key, value, ("tables", key))
        return self.problems

    def enum(self, key: str, value: dict[str, Any], path: Path) -> None:
        self.name(key, path, "enum name")
        scalar = self.scalar_type(value.get("type", "u8"), (*path, "type"), allow_float=False)
        values: list[EnumValue] = []
        seen: dict[int, str] = {}
        for label, item in value["values"].items():
            item_path = (*path, "values", label)
            if not LABEL.match(str(label)) or keyword.iskeyword(str(label)):
                self.error(item_path, f"enum label {label!r} must be an identifier")
            number = item if isinstance(item, int) else item["value"]
            text = "" if isinstance(item, int) else str(item.get("text", ""))
            if number in seen:
                self.error(item_path, f"value {number} is already used by {seen[number]!r}")
            if not scalar.minimum <= number <= scalar.maximum:
                self.error(item_path, f"value {number} does not fit {scalar.name}")
            seen[number] = str(label)
            same = next(
                (other for other in value["values"] if other != label and str(other).upper() == str(label).upper()),
                None,
            )
            if same is not None and any(v.name == str(label).upper() for v in values):
                self.error(item_path, f"enum label {label!r} is the same as {same!r} once upper-cased")
            values.append(EnumValue(str(label).upper(), number, text))
        self.enums[key] = EnumDef(
            key, self.class_name(camel(key), path), scalar, str(value.get("description", "")), tuple(values)
        )

    def flag_set(self, key: str, value: dict[str, Any], path: Path) -> None:
        self.name(key, path, "flags name")
        scalar = self.scalar_type(value.get("type", "u8"), (*path, "type"), allow_float=False)
        bits: list[FlagBit] = []
        for label, item in value["bits"].items():
            bit = item if isinstance(item, int) else item["bit"]
            if not LABEL.match(str(label)):
                self.error((*path, "bits", label), f"flag name {label!r} must be an identifier")
            if not 0 <= bit < scalar.size * 8:
                self.error((*path, "bits", label), f"bit {bit} is outside a {scalar.name}")
            text = "" if isinstance(item, int) else str(item.get("text", ""))
            if any(b.name == str(label).upper() for b in bits):
                same = next(other for other in value["bits"] if str(other).upper() == str(label).upper())
                self.error((*path, "bits", label), f"flag name {label!r} is the same as {same!r} once upper-cased")
            bits.append(FlagBit(str(label).upper(), bit, text))
        self.flags[key] = FlagsDef(
            key, self.class_name(camel(key), path), scalar, str(value.get("description", "")), tuple(bits)
        )

    def table(self, key: str, value: dict[str, Any], path: Path) -> None:
        self.name(key, path, "table name")
        entries: list[TableEntry] = []
        keys: dict[int, str] = {}
        for entry_name, item in value["entries"].items():
            entry_path = (*path, "entries", entry_name)
            self.name(entry_name, entry_path, "entry name")
            scalar = self.scalar_type(item["type"], (*entry_path, "type"))
            if item["key"] in keys:
                self.error((*entry_path, "key"), f"key {item['key']} is already used by {keys[item['key']]!r}")
            keys[item["key"]] = entry_name
            sign_magnitude = item.get("encoding") == "sign_magnitude"
            scalar = self.stored(scalar, sign_magnitude, (*entry_path, "encoding"))
            sign_bit = self.sign_bit(scalar, sign_magnitude, item.get("sign_bit"), (*entry_path, "sign_bit"))
            low, high = self.bounds(scalar, sign_magnitude, item.get("range"), (*entry_path, "range"), sign_bit)
            enum = self.reference("enum", self.enums, item.get("enum"), (*entry_path, "enum"))
            if enum is not None and item.get("range") is None:
                low, high = enum_span(enum, low, high)
            if item.get("scale") == 0:
                self.error((*entry_path, "scale"), "scale 0 would make every value 0 (give the size of one wire step)")
            default = item.get("default")
            if isinstance(default, int | float) and not low <= default <= high:
                self.error((*entry_path, "default"), f"default {default} is outside the range {low:g}..{high:g}")
            entries.append(
                TableEntry(
                    name=entry_name,
                    key=item["key"],
                    type=scalar,
                    name_cn=str(item.get("name_cn", "")),
                    description=str(item.get("description", "")),
                    unit=str(item.get("unit", "")),
                    scale=item.get("scale"),
                    minimum=low,
                    maximum=high,
                    default=item.get("default"),
                    access=str(item.get("access", "rw")),
                    memory=str(item.get("memory", "")),
                    enum=enum,
                    flags=self.reference("flags", self.flags, item.get("flags"), (*entry_path, "flags")),
                    sign_magnitude=sign_magnitude,
                    reserved=bool(item.get("reserved", False)),
                    source=str(item.get("source", "")),
                    sign_bit=sign_bit,
                )
            )
        if all(e.reserved for e in entries):
            raise self.fail((*path, "entries"), "a table needs at least one entry that is not reserved")
        if value.get("key_type") is None:
            self.check_table_layout(entries, path)
        self.tables[key] = Table(
            key,
            str(value.get("title", key)),
            str(value["key"]),
            str(value.get("description", "")),
            str(value.get("source", "")),
            tuple(entries),
            # the generated register map, table values and register-name alias are named after the table
            constant=self.class_name(key.upper(), path),
            value_constant=self.class_name(f"{key.upper()}_VALUE", path),
            names_class=self.class_name(camel(key, "name"), path),
        )

    def check_table_layout(self, entries: list[TableEntry], path: Path) -> None:
        """Register tables (keys are byte addresses) must not overlap."""
        if self.doc.data.get("tables", {}).get(path[-1], {}).get("key") != "address":
            return
        ordered = sorted(entries, key=lambda e: e.key)
        for before, after in zip(ordered, ordered[1:], strict=False):
            if before.key < after.key < before.key + before.type.size:
                self.error(
                    (*path, "entries", after.name, "key"),
                    f"register {after.name} at {after.key:#04x} overlaps {before.name} "
                    f"({before.key:#04x}..{before.key + before.type.size - 1:#04x})",
                )

    def sign_bit(self, scalar: ScalarType, sign_magnitude: bool, given: Any, path: Path) -> int | None:
        if not sign_magnitude:
            if given is not None:
                self.error(path, "`sign_bit` needs `encoding: sign_magnitude`")
            return None
        top = scalar.size * 8 - 1
        if given is None:
            return top
        if not 0 < given <= top:
            self.error(path, f"sign bit {given} is outside {scalar.name}'s bits 1..{top}")
            return top
        return int(given)
