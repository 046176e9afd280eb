"""Validate a loaded spec and resolve it into the immutable model.

Every problem is collected, with the position of the value at fault, and reported together; resolution goes on
past a bad value wherever it can, so one run shows all the mistakes in a spec.
"""

from __future__ import annotations

import keyword
import os
import re
from dataclasses import replace
from typing import Any, Literal

from serialspec.runtime.hexbytes import parse_hex
from serialspec.spec import grammar
from serialspec.spec.errors import SpecError, SpecErrors
from serialspec.spec.loader import Located, Path, dotted, load_file
from serialspec.spec.model import (
    SCALARS,
    Array,
    Behaviour,
    BitField,
    Bytes,
    Checksum,
    Command,
    Crc,
    Device,
    DeviceKind,
    DeviceModel,
    Direction,
    EnumDef,
    EnumValue,
    Erratum,
    ErratumCheck,
    Example,
    Field,
    FlagBit,
    FlagsDef,
    FrameElement,
    FrameLayout,
    Framing,
    Group,
    Message,
    ModelEntry,
    Motion,
    OptionalWhen,
    Protocol,
    Scalar,
    ScalarType,
    Selector,
    Serial,
    Subcommand,
    Table,
    TableBlock,
    TableEntry,
    TableValue,
    replies_by_request,
    reply_to,
)

NAME = re.compile(r"^[a-z][a-z0-9_]*$")
LABEL = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
# Attribute names the generated message classes use themselves.
RESERVED_NAMES = frozenset({"to_fields", "from_fields"})
FIELD_KINDS = (*grammar.SCALAR_TYPES, "bytes", "array", "group", "table_value", "table_block")


def camel(*parts: str) -> str:
    return "".join(word.capitalize() for part in parts for word in part.split("_") if word)


def load_protocol(path: str, display_name: str | None = None) -> Protocol:
    """Load, validate and resolve one spec file; raises SpecErrors listing every mistake."""
    located = load_file(path, display_name or os.path.relpath(path))
    return Resolver(located).resolve()


class _Bad(Exception):
    """A value could not be resolved; its error is already recorded."""


class Resolver:
    def __init__(self, located: Located) -> None:
        self.doc = located
        self.errors: list[SpecError] = []
        self.structural: set[Path] = set()
        self.class_names: dict[str, tuple[Path, object]] = {}
        self.endian: Literal["<", ">"] = "<"
        self.enums: dict[str, EnumDef] = {}
        self.flags: dict[str, FlagsDef] = {}
        self.tables: dict[str, Table] = {}

    # --- reporting ------------------------------------------------------------------------------------------------

    def error(self, path: Path, message: str) -> None:
        if any(path[: len(bad)] == bad for bad in self.structural):
            return  # already reported by the structural check
        self.errors.append(self.doc.error(path, message))

    def fail(self, path: Path, message: str) -> _Bad:
        self.error(path, message)
        return _Bad()

    def name(self, value: str, path: Path, what: str = "name") -> str:
        if not isinstance(value, str) or not NAME.match(value):
            self.error(
                path,
                f"{what} {value!r} must be a lower-case identifier (a-z, 0-9, _; starting with a letter)",
            )
        elif keyword.iskeyword(value) or value in RESERVED_NAMES:
            self.error(path, f"{what} {value!r} is reserved (a Python keyword or a name generated code uses)")
        return str(value)

    def class_name(self, name: str, path: Path, identity: object = None) -> str:
        """Register a generated class name; the same name may be reused only for the same definition."""
        if name in self.class_names:
            other_path, other_identity = self.class_names[name]
            if other_path != path and (identity is None or identity != other_identity):
                self.error(path, f"generated class name {name} is already used by {dotted(other_path)}")
            return name
        self.class_names[name] = (path, identity)
        return name

    # --- top level ------------------------------------------------------------------------------------------------

    def resolve(self) -> Protocol:
        data = self.doc.data
        for path, message in grammar.SPEC.check(data, ()):
            self.errors.append(self.doc.error(path, message))
            self.structural.add(path)
        if not isinstance(data, dict):
            raise SpecErrors(self.errors)
        protocol = self.protocol(data)
        if self.errors or protocol is None:
            raise SpecErrors(self.errors)
        return protocol

    def protocol(self, data: dict[str, Any]) -> Protocol | None:
        name = self.name(data.get("protocol", ""), ("protocol",), "protocol")
        self.endian = ">" if data.get("byte_order") == "big" else "<"
        for key, value in (data.get("enums") or {}).items():
            self.guard(self.enum, key, value, ("enums", key))
        for key, value in (data.get("flags") or {}).items():
            self.guard(self.flag_set, key, value, ("flags", key))
        for key, value in (data.get("tables") or {}).items():
            self.guard(self.table, key, value, ("tables", key))
        self.shared_fields: dict[str, Any] = data.get("fields") or {}
        framing = self.guard(self.framing, data.get("framing") or {}, ("framing",))
        commands = []
        for key, value in (data.get("commands") or {}).items():
            command = self.guard(self.command, key, value, ("commands", key))
            if command:
                commands.append(command)
        if framing:
            self.check_codes(commands, framing)
        self.check_answered_by(commands)
        errata = tuple(
            e
            for key, value in (data.get("errata") or {}).items()
            if (e := self.guard(self.erratum, key, value, ("errata", key), commands))
        )
        examples = tuple(
            e
            for key, value in (data.get("examples") or {}).items()
            if (e := self.guard(self.example, key, value, ("examples", key), commands, errata))
        )
        for erratum in errata:
            for example_name in erratum.check.examples:
                if example_name not in {e.name for e in examples}:
                    self.error(("errata", erratum.name, "check", "examples"), f"unknown example {example_name!r}")
        serial = data.get("serial") or {}
        matching = data.get("matching") or {}
        if framing is None or not isinstance(serial, dict):
            return None
        device = self.guard(self.device, data["device"], ("device",), commands, framing) if "device" in data else None
        return Protocol(
            name=name,
            title=str(data.get("title", "")),
            description=str(data.get("description", "")),
            spec_path=self.doc.file,
            sources=dict(data.get("sources") or {}),
            byte_order="big" if self.endian == ">" else "little",
            serial=Serial(
                baudrate=int(serial.get("baudrate", 0)),
                bytesize=int(serial.get("bytesize", 8)),
                parity=str(serial.get("parity", "none")),
                stopbits=float(serial.get("stopbits", 1)),
                notes=str(serial.get("notes", "")),
            ),
            framing=framing,
            matching=tuple(matching.get("by") or ()),
            matching_description=str(matching.get("description", "")),
            enums=tuple(self.enums.values()),
            flags=tuple(self.flags.values()),
            tables=tuple(self.tables.values()),
            commands=tuple(commands),
            examples=examples,
            errata=errata,
            device=device,
        )

    def guard(self, function: Any, *args: Any) -> Any:
        try:
            return function(*args)
        except _Bad:
            return None
        except (TypeError, AttributeError, ValueError, KeyError):
            # A malformed value the structural check has already reported: skip what depends on it.
            if not self.errors:
                raise
            return None

    # --- enums, flags, tables -------------------------------------------------------------------------------------

    def scalar_type(self, value: Any, path: Path, allow_float: bool = True) -> ScalarType:
        found = SCALARS.get(value) if isinstance(value, str) else None
        if found is None or (found.is_float and not allow_float):
            choices = [n for n, t in SCALARS.items() if allow_float or not t.is_float]
            raise self.fail(path, f"unknown type {value!r} (expected one of {', '.join(choices)})")
        return found

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
            bits.append(FlagBit(str(label).upper(), bit, text))
        self.flags[key] = FlagsDef(
            key, self.class_name(camel(key), path), scalar, str(value.get("description", "")), tuple(bits)
        )

    def reference(self, kind: str, registry: dict[str, Any], value: Any, path: Path) -> Any:
        if value is None:
            return None
        if value not in registry:
            known = ", ".join(registry) or "none defined"
            raise self.fail(path, f"unknown {kind} {value!r} (expected one of: {known})")
        return registry[value]

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
            sign_bit = self.sign_bit(scalar, sign_magnitude, item.get("sign_bit"), (*entry_path, "sign_bit"))
            low, high = self.bounds(scalar, sign_magnitude, item.get("range"), (*entry_path, "range"), sign_bit)
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
                    enum=self.reference("enum", self.enums, item.get("enum"), (*entry_path, "enum")),
                    flags=self.reference("flags", self.flags, item.get("flags"), (*entry_path, "flags")),
                    sign_magnitude=sign_magnitude,
                    reserved=bool(item.get("reserved", False)),
                    source=str(item.get("source", "")),
                    sign_bit=sign_bit,
                )
            )
        if value.get("key_type") is None:
            self.check_table_layout(entries, path)
        self.tables[key] = Table(
            key,
            str(value.get("title", key)),
            str(value["key"]),
            str(value.get("description", "")),
            str(value.get("source", "")),
            tuple(entries),
        )

    def check_table_layout(self, entries: list[TableEntry], path: Path) -> None:
        """Register tables (keys are byte addresses) must not overlap."""
        if self.doc.data.get("tables", {}).get(path[-1], {}).get("key") != "address":
            return
        ordered = sorted(entries, key=lambda e: e.key)
        for before, after in zip(ordered, ordered[1:], strict=False):
            if before.key + before.type.size > after.key:
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

    def bounds(
        self, scalar: ScalarType, sign_magnitude: bool, given: Any, path: Path, sign_bit: int | None = None
    ) -> tuple[float, float]:
        if sign_magnitude:
            limit = (1 << (sign_bit if sign_bit is not None else scalar.size * 8 - 1)) - 1
            low, high = float(-limit), float(limit)
        else:
            low, high = scalar.minimum, scalar.maximum
        if given is None:
            return low, high
        given_low, given_high = given
        if given_low > given_high:
            self.error(path, f"range [{given_low}, {given_high}] is empty")
        if given_low < low or given_high > high:
            self.error(path, f"range [{given_low}, {given_high}] does not fit {scalar.name} ({low:g}..{high:g})")
        return given_low, given_high

    # --- framing --------------------------------------------------------------------------------------------------

    def framing(self, value: dict[str, Any], path: Path) -> Framing:
        raw = value["elements"]
        elements: list[tuple[dict[str, Any], FrameElement]] = []
        checksum: Checksum | None = None
        headers: dict[Direction, bytes] = {}
        length_adds = 0
        for name, item in raw.items():
            item_path = (*path, "elements", name)
            self.name(name, item_path, "frame element")
            role = item["role"]
            directions = tuple(Direction(d) for d in item.get("directions", ("request", "response")))
            scalar = None
            size: int | None = None
            if role == "header":
                header_value = item.get("value")
                if header_value is None:
                    raise self.fail(item_path, "a header needs `value`: hex bytes, or a mapping by direction")
                for direction in directions:
                    text = header_value if isinstance(header_value, str) else header_value.get(direction.value)
                    if text is None:
                        raise self.fail((*item_path, "value"), f"no header given for {direction.value}")
                    try:
                        headers[direction] = parse_hex(text)
                    except ValueError as exc:
                        raise self.fail((*item_path, "value"), str(exc)) from None
                sizes = {len(headers[d]) for d in directions}
                if len(sizes) != 1:
                    raise self.fail((*item_path, "value"), "headers must have the same size in both directions")
                size = sizes.pop()
            elif role != "content":
                scalar = self.scalar_type(item.get("type", "u8"), (*item_path, "type"), allow_float=False)
                size = scalar.size
            if role == "length":
                length_adds = int(item.get("adds", 0))
            low, high = (scalar.minimum, scalar.maximum) if scalar else (0, 0)
            if "range" in item and scalar:
                low, high = self.bounds(scalar, False, item["range"], (*item_path, "range"))
            element = FrameElement(
                name=name,
                role=role,
                type=scalar,
                size=size,
                directions=directions,
                description=str(item.get("description", "")),
                minimum=low,
                maximum=high,
                broadcast=item.get("broadcast"),
                flags=self.reference("flags", self.flags, item.get("flags"), (*item_path, "flags")),
            )
            elements.append((item, element))
            if role == "checksum":
                assert scalar is not None
                checksum = self.checksum(item, name, scalar, item_path, list(raw))
        if checksum is None:
            raise self.fail((*path, "elements"), "framing needs one element with role checksum")
        layouts = {d: self.layout(d, headers, [e for _, e in elements], checksum, length_adds, path) for d in Direction}
        shared = headers.get(Direction.REQUEST) == headers.get(Direction.RESPONSE)
        return Framing(str(value.get("description", "")), layouts, checksum, shared)

    def checksum(self, item: dict[str, Any], name: str, scalar: ScalarType, path: Path, names: list[str]) -> Checksum:
        covers = item.get("covers")
        if not covers:
            raise self.fail(path, "a checksum needs `covers: [first, last]` (frame element names)")
        for covered in covers:
            if covered not in names:
                self.error(
                    (*path, "covers"),
                    f"unknown frame element {covered!r} (expected one of {', '.join(names)})",
                )
        algorithm = item.get("algorithm")
        crc = None
        if algorithm == "crc":
            params = item.get("crc")
            if not params:
                raise self.fail(path, "algorithm crc needs `crc:` with width, poly, init, refin, refout, xorout, check")
            crc = Crc(
                str(params.get("name", "")),
                params["width"],
                params["poly"],
                params["init"],
                params["refin"],
                params["refout"],
                params["xorout"],
                params["check"],
            )
            from serialspec.runtime.checksums import crc_function

            computed = crc_function(crc.width, crc.poly, crc.init, crc.refin, crc.refout, crc.xorout)(b"123456789")
            if computed != crc.check:
                self.error(
                    (*path, "crc", "check"),
                    f"these parameters give {computed:#x} for '123456789', not the check value {crc.check:#x}",
                )
            if crc.width != scalar.size * 8:
                self.error((*path, "crc", "width"), f"a {crc.width}-bit CRC does not fill a {scalar.name}")
        elif algorithm != "sum":
            raise self.fail(path, "a checksum needs `algorithm: sum` or `algorithm: crc`")
        return Checksum(algorithm, bool(item.get("invert", False)), crc, covers[0], covers[1], scalar)

    def layout(
        self,
        direction: Direction,
        headers: dict[Direction, bytes],
        all_elements: list[FrameElement],
        checksum: Checksum,
        length_adds: int,
        path: Path,
    ) -> FrameLayout:
        elements = tuple(e for e in all_elements if direction in e.directions)
        roles = [e.role for e in elements]
        for role in ("header", "length", "content", "checksum"):
            if roles.count(role) != 1:
                raise self.fail((*path, "elements"), f"the {direction.value} frame needs exactly one {role} element")
        if roles.count("command") > 1:
            raise self.fail((*path, "elements"), f"the {direction.value} frame has more than one command element")
        if roles[0] != "header":
            raise self.fail((*path, "elements"), "the frame must start with its header")
        offsets: dict[str, int] = {}
        position = 0
        content_index = roles.index("content")
        for element in elements[:content_index]:
            offsets[element.name] = position
            position += element.size or 0
        offsets[elements[content_index].name] = position
        after = sum(e.size or 0 for e in elements[content_index + 1 :])
        overhead = position + after
        names = [e.name for e in elements]
        if checksum.first not in names or checksum.last not in names:
            raise self.fail(
                (*path, "elements"),
                f"the checksum covers an element missing from the {direction.value} frame",
            )
        last_index = names.index(checksum.last)
        covered_to_end = sum(e.size or 0 for e in elements[last_index + 1 :])
        checksum_element = elements[roles.index("checksum")]
        if roles.index("checksum") != len(roles) - 1:
            raise self.fail((*path, "elements"), "the checksum must be the frame's last element")
        if names.index(checksum.first) > content_index or last_index < content_index:
            raise self.fail((*path, "elements"), "the checksum must cover the content")
        length_index = roles.index("length")
        if length_index > content_index:
            raise self.fail((*path, "elements"), "the length must come before the content")
        return FrameLayout(
            direction=direction,
            header=headers[direction],
            elements=elements,
            offsets=offsets,
            overhead=overhead,
            length_offset=offsets[elements[length_index].name],
            length_adds=length_adds,
            command_offset=offsets[elements[roles.index("command")].name] if "command" in roles else None,
            checksum_offset_from_end=checksum_element.size or 1,
            covered_from=offsets[checksum.first],
            covered_to_end=covered_to_end,
            value_elements=tuple(e for e in elements if e.role in ("address", "status")),
        )

    # --- commands and their content -------------------------------------------------------------------------------

    def command(self, name: str, value: dict[str, Any], path: Path) -> Command:
        self.name(name, path, "command name")
        selector = None
        subcommands: list[Subcommand] = []
        if "subcommands" in value:
            raw_selector = value.get("selector")
            if raw_selector is None:
                raise self.fail(
                    path, "a command with subcommands needs `selector: {type, offset: {request, response}}`"
                )
            selector = Selector(
                name=self.name(raw_selector.get("name", "subcommand_code"), (*path, "selector", "name")),
                type=self.scalar_type(raw_selector.get("type", "u8"), (*path, "selector", "type"), False),
                offsets={Direction(k): v for k, v in raw_selector["offset"].items() if k in ("request", "response")},
            )
            codes: dict[int, str] = {}
            for sub_name, sub in value["subcommands"].items():
                sub_path = (*path, "subcommands", sub_name)
                self.name(sub_name, sub_path, "subcommand name")
                if sub["code"] in codes:
                    self.error(
                        (*sub_path, "code"),
                        f"code {sub['code']:#04x} is already used by {codes[sub['code']]!r}",
                    )
                codes[sub["code"]] = sub_name
                messages = {
                    d: self.guard(
                        self.message,
                        name,
                        sub_name,
                        d,
                        sub[d.value],
                        (*sub_path, d.value),
                        selector,
                        sub["code"],
                    )
                    for d in Direction
                    if d.value in sub
                }
                subcommands.append(
                    Subcommand(
                        sub_name,
                        sub["code"],
                        str(sub.get("title", "")),
                        str(sub.get("title_cn", "")),
                        str(sub.get("description", "")),
                        messages.get(Direction.REQUEST),
                        messages.get(Direction.RESPONSE),
                        str(sub.get("source", "")),
                    )
                )
            for direction in ("request", "response"):
                if direction in value:
                    self.error((*path, direction), "a command with subcommands describes content in each subcommand")
        messages = {
            d: self.guard(self.message, name, None, d, value[d.value], (*path, d.value), None, None)
            for d in Direction
            if d.value in value and "subcommands" not in value
        }
        return Command(
            name=name,
            code=value.get("code"),
            title=str(value.get("title", "")),
            title_cn=str(value.get("title_cn", "")),
            description=str(value.get("description", "")),
            broadcast=str(value.get("broadcast", "")),
            source=str(value.get("source", "")),
            request=messages.get(Direction.REQUEST),
            response=messages.get(Direction.RESPONSE),
            selector=selector,
            subcommands=tuple(subcommands),
        )

    def check_answered_by(self, commands: list[Command]) -> None:
        responses = {m.key: m for c in commands for m in c.messages() if m.direction == Direction.RESPONSE}
        for command in commands:
            for message in command.messages():
                if message.answered_by and message.answered_by not in responses:
                    self.error(
                        ("commands", command.name, "request", "answered_by", "command"),
                        f"{message.answered_by!r} is not a command with a response",
                    )

    def check_codes(self, commands: list[Command], framing: Framing) -> None:
        for direction, layout in framing.layouts.items():
            seen: dict[int | None, str] = {}
            for command in commands:
                has = any(m.direction == direction for m in command.messages())
                if not has:
                    continue
                path: Path = ("commands", command.name)
                if layout.command_offset is None:
                    if command.code is not None:
                        self.error((*path, "code"), f"{direction.value} frames have no command field, so no code")
                elif command.code is None:
                    self.error(path, f"missing key 'code' ({direction.value} frames carry a command field)")
                if command.code in seen:
                    other = seen[command.code]
                    what = f"code {command.code:#04x}" if command.code is not None else "a codeless reply"
                    self.error(path, f"{what} in {direction.value} frames is already used by {other!r}")
                seen[command.code] = command.name

    def message(
        self,
        command: str,
        subcommand: str | None,
        direction: Direction,
        value: dict[str, Any],
        path: Path,
        selector: Selector | None,
        code: int | None,
    ) -> Message:
        fields = self.fields(value.get("fields") or {}, (*path, "fields"), parent=None)
        if selector is not None and code is not None:
            fields = self.insert_selector(fields, selector, direction, code, path)
        self.check_rest(fields, (*path, "fields"))
        low, high = content_bounds(fields)
        class_name = self.class_name(camel(command, subcommand or "", direction.value), path)
        answered_by = value.get("answered_by") or {}
        if direction == Direction.REQUEST:
            for field in fields:
                if isinstance(field, Scalar) and field.status_ok is not None:
                    self.error((*path, "fields", field.name, "status"), "a status is reported in a response")
        if answered_by and direction != Direction.REQUEST:
            self.error((*path, "answered_by"), "`answered_by` names the response that answers a request")
        return Message(
            command=command,
            subcommand=subcommand,
            direction=direction,
            class_name=class_name,
            title=str(value.get("title", "")),
            description=str(value.get("description", "")),
            fields=fields,
            optional=str(value.get("optional", "")),
            unsolicited=bool(value.get("unsolicited", False)),
            answers=str(value.get("answers", "")),
            min_size=low,
            max_size=high,
            source=str(value.get("source", "")),
            optional_when=self.optional_when(value.get("optional_when"), (*path, "optional_when")),
            after=self.after(value.get("after"), fields, direction, path),
            answered_by=str(answered_by.get("command", "")),
            reply_when=self.optional_when(answered_by.get("optional_when"), (*path, "answered_by", "optional_when")),
        )

    def table_entry(self, text: str, path: Path) -> tuple[Table, TableEntry]:
        """A table entry named `entry` (searched in every table) or `table.entry`."""
        table_name, _, entry_name = text.rpartition(".")
        tables = [self.tables[table_name]] if table_name in self.tables else list(self.tables.values())
        for table in tables:
            for entry in table.entries:
                if entry.name == entry_name:
                    return table, entry
        raise self.fail(path, f"unknown table entry {text!r}")

    def optional_when(self, value: Any, path: Path) -> OptionalWhen | None:
        if value is None:
            return None
        table, entry = self.table_entry(value["parameter"], (*path, "parameter"))
        return OptionalWhen(table.name, entry.name, entry.key, int(value["equals"]))

    def after(self, value: Any, fields: tuple[Field, ...], direction: Direction, path: Path) -> str:
        if value is None:
            return ""
        if direction != Direction.RESPONSE:
            self.error((*path, "after"), "`after` describes when a response is sent")
        return str(value)

    def insert_selector(
        self, fields: tuple[Field, ...], selector: Selector, direction: Direction, code: int, path: Path
    ) -> tuple[Field, ...]:
        offset = selector.offsets.get(direction)
        if offset is None:
            raise self.fail(path, f"the selector has no offset for {direction.value}")
        const = Scalar(
            selector.name,
            "sub-command selector",
            "",
            "",
            selector.type,
            self.endian,
            "",
            None,
            selector.type.minimum,
            selector.type.maximum,
            code,
            None,
            None,
            None,
            (),
            "",
            False,
        )
        position = 0
        for index, field in enumerate(fields):
            if position == offset:
                return (*fields[:index], const, *fields[index:])
            size = fixed_size(field)
            if size is None:
                break
            position += size
        if position == offset:
            return (*fields, const)
        raise self.fail(path, f"the selector's offset {offset} does not fall between fixed-size fields")

    def check_rest(self, fields: tuple[Field, ...], path: Path) -> None:
        for field in fields[:-1]:
            takes_rest = (isinstance(field, Bytes) and field.size == "rest") or (
                isinstance(field, Group) and field.count == "rest"
            )
            if takes_rest:
                self.error((*path, field.name), "only the last field can take the rest of the content")

    def fields(self, raw: dict[str, Any], path: Path, parent: list[Field] | None) -> tuple[Field, ...]:
        resolved: list[Field] = []
        for name, item in raw.items():
            field_path = (*path, name)
            self.name(name, field_path, "field name")
            if any(f.name == name for f in resolved):
                self.error(field_path, f"duplicate field {name!r}")
            field = self.guard(self.field, name, item, field_path, resolved, parent)
            if field is not None:
                resolved.append(field)
        return tuple(resolved)

    def expand(self, item: Any, path: Path) -> dict[str, Any]:
        """A field's mapping, with the short forms and `use:` references expanded."""
        if isinstance(item, str):
            if item in FIELD_KINDS:
                return {"type": item}
            if item in self.shared_fields:
                return self.expand(self.shared_fields[item], ("fields", item))
            raise self.fail(
                path,
                f"unknown type {item!r} (expected one of {', '.join(FIELD_KINDS)}, or a field from `fields:`)",
            )
        spec = dict(item)
        if "use" in spec:
            base_name = spec.pop("use")
            if base_name not in self.shared_fields:
                known = ", ".join(self.shared_fields) or "none defined"
                raise self.fail((*path, "use"), f"unknown shared field {base_name!r} (expected one of: {known})")
            spec = {**self.expand(self.shared_fields[base_name], ("fields", base_name)), **spec}
        if "type" not in spec:
            raise self.fail(path, "missing key 'type'")
        return spec

    def field(self, name: str, item: Any, path: Path, siblings: list[Field], parent: list[Field] | None) -> Field:
        spec = self.expand(item, path)
        kind = spec["type"]
        common = dict(
            name=name,
            description=str(spec.get("description", "")),
            description_cn=str(spec.get("description_cn", "")),
            inferred=str(spec.get("inferred", "")),
        )
        endian: Literal["<", ">"] = {"little": "<", "big": ">"}.get(spec.get("endian", ""), self.endian)  # type: ignore[assignment]
        if kind in SCALARS:
            return self.scalar(common, spec, path, endian)
        if kind == "bytes":
            size = spec.get("size")
            if size is None:
                raise self.fail(path, "bytes need `size`: a number, `rest`, or a field name")
            table = self.reference("table", self.tables, spec.get("table"), (*path, "table"))
            if isinstance(size, str) and size != "rest":
                self.size_field(size, name, siblings, parent, path)
            size_from = str(spec.get("size_from", ""))
            if size_from and (size != "rest" or not size_from.startswith("request.")):
                self.error((*path, "size_from"), "`size_from: request.<field>` goes with `size: rest`")
            return Bytes(**common, size=size, table=table, start=str(spec.get("start", "")), size_from=size_from)
        if kind == "array":
            item_type = self.scalar_type(spec.get("of"), (*path, "of"))
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
            inner = self.fields(spec["fields"], (*path, "fields"), parent=siblings)
            if isinstance(count, str) and count != "rest":
                self.derive(count, ("count", name), siblings, path)
            item_size = sum_sizes(inner)
            class_name = self.class_name(camel(name, "item"), path)
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
            return TableBlock(**common, table=table, class_name=class_name, entries=entries, endian=endian)
        raise self.fail((*path, "type"), f"unknown type {kind!r} (expected one of {', '.join(FIELD_KINDS)})")

    def scalar(self, common: dict[str, Any], spec: dict[str, Any], path: Path, endian: Literal["<", ">"]) -> Scalar:
        scalar = SCALARS[spec["type"]]
        sign_magnitude = spec.get("encoding") == "sign_magnitude"
        low, high = self.bounds(scalar, sign_magnitude, spec.get("range"), (*path, "range"))
        const = spec.get("const")
        if const is not None and not low <= const <= high:
            self.error((*path, "const"), f"constant {const} is outside {low:g}..{high:g}")
        default = spec.get("default")
        if default is not None and not low <= default <= high:
            self.error((*path, "default"), f"default {default} is outside the range {low:g}..{high:g}")
        bits: list[BitField] = []
        used = 0
        for bit_name, bit_spec in (spec.get("bits") or {}).items():
            bit_path = (*path, "bits", bit_name)
            self.name(bit_name, bit_path, "bit field name")
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
            bits.append(BitField(bit_name, high_bit, low_bit, enum, str(bit_spec.get("description", ""))))
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
            enum=self.reference("enum", self.enums, spec.get("enum"), (*path, "enum")),
            flags=self.reference("flags", self.flags, spec.get("flags"), (*path, "flags")),
            bits=tuple(bits),
            bits_class=self.class_name(camel(common["name"], "bits"), path) if bits else "",
            sign_magnitude=sign_magnitude,
            status_ok=self.status_ok(spec.get("status"), scalar, low, high, (*path, "status")),
        )

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
                if not isinstance(field, Scalar) or field.type.is_float or field.hidden:
                    raise self.fail(path, f"{name!r} must be an earlier integer field that nothing else derives")
                siblings[index] = replace(field, derived=derivation)
                return
        raise self.fail(path, f"unknown field {name!r}: a count or size must be an earlier field of the same content")

    def size_field(self, size: str, name: str, siblings: list[Field], parent: list[Field] | None, path: Path) -> None:
        """Bytes sized by a field: inside a group, a field before the group sets the size of every item."""
        if parent is not None and any(f.name == size for f in parent):
            self.derive(size, ("size", name), parent, path)
        else:
            self.derive(size, ("size", name), siblings, path)

    # --- device behaviour ---------------------------------------------------------------------------------------

    def device(self, value: dict[str, Any], path: Path, commands: list[Command], framing: Framing) -> Device:
        memory = self.reference("table", self.tables, value.get("memory"), (*path, "memory"))
        entries = {e.name: e for e in memory.entries} if memory else {}
        for name in value.get("initial") or {}:
            if name not in entries:
                self.error((*path, "initial", name), f"unknown memory entry {name!r}")
        address_element = next(
            (e for layout in framing.layouts.values() for e in layout.value_elements if e.role == "address"), None
        )
        address = str(value.get("address") or (address_element.name if address_element else ""))
        if not address:
            self.error(path, "name the field holding the device id with `address:`")
        broadcast = value.get("broadcast", address_element.broadcast if address_element else None)
        id_entry = str(value.get("id_entry", ""))
        if id_entry and id_entry not in entries and id_entry not in (value.get("state") or {}):
            self.error((*path, "id_entry"), f"unknown memory entry or state variable {id_entry!r}")
        state = {str(k): float(v) for k, v in (value.get("state") or {}).items()}
        requests = {m.key: m for c in commands for m in c.messages() if m.direction == Direction.REQUEST}
        replies = replies_by_request(m for c in commands for m in c.messages())
        kinds = {
            str(name): DeviceKind(
                str(name),
                str(kind.get("description", "")),
                str(kind["address"]),
                tuple(int(i) for i in kind["ids"]),
                kind.get("broadcast"),
                {str(k): float(v) for k, v in (kind.get("state") or {}).items()},
            )
            for name, kind in (value.get("kinds") or {}).items()
        }
        behaviours = []
        for key, item in (value.get("commands") or {}).items():
            item_path = (*path, "commands", key)
            request = requests.get(key)
            if request is None:
                self.error(item_path, f"unknown command {key!r} (or it has no request)")
                continue
            kind_name = str(item.get("kind", ""))
            if kind_name and kind_name not in kinds:
                self.error((*item_path, "kind"), f"unknown device kind {kind_name!r} (not in `kinds:`)")
            known_state = kinds[kind_name].state if kind_name in kinds else state
            response = reply_to(request, replies)
            each = str(item.get("each", ""))
            group = next((f for f in request.fields if isinstance(f, Group) and f.name == each), None)
            if each and group is None:
                self.error((*item_path, "each"), f"{key} has no group field {each!r}")
            item_fields = group.fields if group else ()
            request_names = {f.name for f in (*request.fields, *item_fields)}
            response_names = {f.name for f in response.fields} if response else set()
            for name in item.get("reads") or ():
                if name not in response_names:
                    self.error((*item_path, "reads"), f"{key} has no response field {name!r}")
            for name in item.get("writes") or ():
                if name not in request_names:
                    self.error((*item_path, "writes"), f"{key} has no request field {name!r}")
            reports = {str(k): str(v) for k, v in (item.get("reports") or {}).items()}
            for field_name, source in reports.items():
                if field_name not in response_names:
                    self.error((*item_path, "reports", field_name), f"{key} has no response field {field_name!r}")
                if source not in known_state and source not in entries:
                    self.error((*item_path, "reports", field_name), f"unknown state variable {source!r}")
            motion = None
            if "moves" in item:
                moves = item["moves"]
                motion = Motion(
                    str(moves["state"]),
                    str(moves["target"]),
                    str(moves.get("duration", "")),
                    str(moves.get("speed", "")),
                    str(moves.get("accel", "")),
                    str(moves.get("decel", "")),
                )
                if motion.state not in known_state and motion.state not in entries:
                    self.error((*item_path, "moves", "state"), f"unknown state variable {motion.state!r}")
                for role in ("target", "duration", "speed", "accel", "decel"):
                    name = getattr(motion, role)
                    if name and name not in request_names and name not in entries:
                        self.error((*item_path, "moves", role), f"{key} has no request field or memory entry {name!r}")
            stores = {str(k): str(v) for k, v in (item.get("stores") or {}).items()}
            sets = {str(k): float(v) for k, v in (item.get("sets") or {}).items()}
            absent = {str(k): float(v) for k, v in (item.get("absent") or {}).items()}
            for field_name, target in stores.items():
                if field_name not in request_names:
                    self.error((*item_path, "stores", field_name), f"{key} has no request field {field_name!r}")
                if target not in known_state and target not in entries:
                    self.error((*item_path, "stores", field_name), f"unknown state variable {target!r}")
            for target in sets:
                if target not in known_state and target not in entries:
                    self.error((*item_path, "sets", target), f"unknown state variable {target!r}")
            for field_name in absent:
                if field_name not in response_names:
                    self.error((*item_path, "absent", field_name), f"{key} has no response field {field_name!r}")
            behaviours.append(
                Behaviour(
                    key,
                    tuple(item.get("reads") or ()),
                    tuple(item.get("writes") or ()),
                    bool(item.get("resets", False)),
                    reports,
                    motion,
                    bool(item.get("broadcast_reply", False)),
                    each,
                    bool(item.get("buffered", False)),
                    bool(item.get("commits", False)),
                    kind_name,
                    stores,
                    sets,
                    absent,
                    **self.behaviour_extras(
                        item, item_path, key, request_names, response_names, {**entries, **known_state}
                    ),
                )
            )
        status = {str(k): str(v) for k, v in (value.get("status") or {}).items()}
        for field_name, entry_name in status.items():
            if entry_name not in entries:
                self.error((*path, "status", field_name), f"unknown memory entry {entry_name!r}")
        return Device(
            description=str(value.get("description", "")),
            memory=memory,
            initial={str(k): float(v) for k, v in (value.get("initial") or {}).items()},
            address=address,
            id_entry=id_entry,
            broadcast=broadcast,
            state=state,
            reply={str(k): float(v) for k, v in (value.get("reply") or {}).items()},
            refused={str(k): float(v) for k, v in (value.get("refused") or {}).items()},
            behaviours=tuple(behaviours),
            status=status,
            kinds=tuple(kinds.values()),
            echo_address=bool(value.get("echo_address", False)),
            models=self.models(value, path, entries, state),
            model_entry=str(value.get("model_entry", "")),
        )

    def behaviour_extras(
        self,
        item: dict[str, Any],
        path: Path,
        key: str,
        request_names: set[str],
        response_names: set[str],
        variables: dict[str, Any],
    ) -> dict[str, Any]:
        """The behaviours that stop, wrap, count, hold, release and carry, each name checked."""

        def known(name: str, where: Path) -> str:
            if name not in variables:
                self.error(where, f"unknown state variable {name!r}")
            return name

        counts = {}
        for field_name, count in (item.get("counts") or {}).items():
            if field_name not in response_names:
                self.error((*path, "counts", field_name), f"{key} has no response field {field_name!r}")
            counts[str(field_name)] = (known(str(count["state"]), (*path, "counts", field_name)), float(count["per"]))
        for field_name in item.get("cancel_when") or {}:
            if field_name not in request_names:
                self.error((*path, "cancel_when", field_name), f"{key} has no request field {field_name!r}")
        if "cancel_when" in item and "releases" not in item:
            self.error((*path, "cancel_when"), "`cancel_when` needs `releases`")
        carries = item.get("carries")
        if carries:
            for role in ("command", "content"):
                if carries[role] not in request_names:
                    self.error((*path, "carries", role), f"{key} has no request field {carries[role]!r}")
        return {
            "stops": tuple(known(str(n), (*path, "stops")) for n in item.get("stops") or ()),
            "wraps": {known(str(n), (*path, "wraps", n)): float(p) for n, p in (item.get("wraps") or {}).items()},
            "counts": counts,
            "every_device": bool(item.get("every_device", False)),
            "held_while": known(str(item["held_while"]), (*path, "held_while")) if "held_while" in item else "",
            "releases": known(str(item["releases"]), (*path, "releases")) if "releases" in item else "",
            "cancel_when": {str(k): float(v) for k, v in (item.get("cancel_when") or {}).items()},
            "carries": (str(carries["command"]), str(carries["content"])) if carries else None,
        }

    def models(
        self, value: dict[str, Any], path: Path, entries: dict[str, TableEntry], state: dict[str, float]
    ) -> tuple[DeviceModel, ...]:
        """The device's models, the default first; each value checked against the model's (or the table's) range."""
        model_entry = str(value.get("model_entry", ""))
        if model_entry and model_entry not in entries:
            self.error((*path, "model_entry"), f"unknown memory entry {model_entry!r}")
        models: list[DeviceModel] = []
        numbers: dict[int, str] = {}
        for name, item in (value.get("models") or {}).items():
            model_path = (*path, "models", name)
            self.name(name, model_path, "model name")
            number = int(item["number"])
            if number in numbers:
                self.error((*model_path, "number"), f"model number {number} is already used by {numbers[number]!r}")
            numbers[number] = name
            overrides = []
            for entry_name, override in (item.get("entries") or {}).items():
                entry = entries.get(entry_name)
                if entry is None:
                    self.error((*model_path, "entries", entry_name), f"unknown memory entry {entry_name!r}")
                    continue
                range_path = (*model_path, "entries", entry_name, "range")
                low, high = (
                    self.bounds(entry.type, entry.sign_magnitude, override["range"], range_path, entry.sign_bit)
                    if "range" in override
                    else (entry.minimum, entry.maximum)
                )
                overrides.append(
                    ModelEntry(
                        entry_name,
                        low,
                        high,
                        str(override.get("unit", entry.unit)),
                        override.get("scale", entry.scale),
                        str(override.get("description", "")),
                    )
                )
            by_name = {o.name: o for o in overrides}
            initial = {str(k): float(v) for k, v in (item.get("initial") or {}).items()}
            if model_entry:
                initial[model_entry] = float(number)
            for entry_name, number_value in initial.items():
                entry_path = (*model_path, "initial", entry_name)
                if entry_name in state:
                    continue
                entry = entries.get(entry_name)
                if entry is None:
                    self.error(entry_path, f"unknown memory entry or state variable {entry_name!r}")
                    continue
                bounds = by_name.get(entry_name, entry)
                low, high = bounds.minimum, bounds.maximum
                if not low <= number_value <= high:
                    where = (*model_path, "number") if entry_name == model_entry else entry_path
                    self.error(where, f"{entry_name} = {number_value:g} is outside its range {low:g}..{high:g}")
            models.append(
                DeviceModel(
                    name=name,
                    number=number,
                    title=str(item.get("title", "")),
                    description=str(item.get("description", "")),
                    source=str(item.get("source", "")),
                    initial=initial,
                    entries=tuple(overrides),
                )
            )
        default = value.get("default_model")
        if default is not None:
            found = next((m for m in models if m.name == default), None)
            if found is None:
                known = ", ".join(m.name for m in models) or "none defined"
                self.error((*path, "default_model"), f"unknown model {default!r} (expected one of: {known})")
            else:
                models.remove(found)
                models.insert(0, found)
        return tuple(models)

    # --- examples and errata --------------------------------------------------------------------------------------

    def frame_bytes(self, text: str, path: Path) -> bytes:
        try:
            return parse_hex(text)
        except ValueError as exc:
            raise self.fail(path, f"not a frame: {exc}") from None

    def find_message(
        self, commands: list[Command], command: str, subcommand: str | None, direction: Direction, path: Path
    ) -> None:
        found = next((c for c in commands if c.name == command), None)
        if found is None:
            raise self.fail((*path, "command"), f"unknown command {command!r}")
        if subcommand is not None:
            sub = next((s for s in found.subcommands if s.name == subcommand), None)
            if sub is None:
                raise self.fail((*path, "subcommand"), f"unknown subcommand {subcommand!r} of {command}")
            message = sub.request if direction == Direction.REQUEST else sub.response
        else:
            if found.subcommands:
                raise self.fail(path, f"{command} has subcommands: name one with `subcommand:`")
            message = found.request if direction == Direction.REQUEST else found.response
        if message is None:
            raise self.fail(path, f"{command} has no {direction.value}")

    def example(
        self,
        name: str,
        value: dict[str, Any],
        path: Path,
        commands: list[Command],
        errata: tuple[Erratum, ...],
    ) -> Example:
        self.name(name, path, "example name")
        direction = Direction(value["direction"])
        self.find_message(commands, value["command"], value.get("subcommand"), direction, path)
        printed = value["printed"]
        frame_text = value.get("frame", printed)
        frame = self.frame_bytes(frame_text, (*path, "frame" if "frame" in value else "printed"))
        erratum = str(value.get("erratum", ""))
        try:
            printed_ok = parse_hex(printed) == frame
        except ValueError:
            printed_ok = False
        if not printed_ok and not erratum:
            self.error(path, "`frame` differs from `printed`: name the erratum that explains it")
        if erratum and erratum not in {e.name for e in errata}:
            self.error((*path, "erratum"), f"unknown erratum {erratum!r}")
        return Example(
            name,
            str(value["source"]),
            str(value.get("description", "")),
            direction,
            printed,
            frame,
            erratum,
            value["command"],
            value.get("subcommand"),
            str(value.get("request", "")),
            dict(value["fields"]),
        )

    def erratum(self, name: str, value: dict[str, Any], path: Path, commands: list[Command]) -> Erratum:
        self.name(name, path, "erratum name")
        check = value["check"]
        check_path = (*path, "check")
        kind = check["kind"]
        frame = None
        if kind in ("frame_fails", "frame_decodes_as", "checksum_value"):
            if "frame" not in check or "direction" not in check:
                raise self.fail(check_path, f"a {kind} check needs `frame:` and `direction:`")
            frame = self.frame_bytes(check["frame"], (*check_path, "frame")) if kind != "frame_fails" else None
            if kind == "frame_fails":
                try:
                    frame = parse_hex(check["frame"])
                except ValueError:
                    frame = None  # a frame that is not even hex: the failure is in reading it
        if kind == "frame_fails" and not check.get("error"):
            self.error(check_path, "a frame_fails check needs `error:` (words the decode error contains)")
        if kind == "frame_decodes_as":
            if "command" not in check or "fields" not in check:
                raise self.fail(check_path, "a frame_decodes_as check needs `command:` and `fields:`")
            self.find_message(
                commands, check["command"], check.get("subcommand"), Direction(check["direction"]), check_path
            )
        if kind == "checksum_value" and ("claimed" not in check or "actual" not in check):
            self.error(check_path, "a checksum_value check needs `claimed:` and `actual:`")
        if kind == "crc_parameters" and not isinstance(check.get("claimed"), dict):
            self.error(check_path, "a crc_parameters check needs `claimed:` with the claimed parameters")
        return Erratum(
            name,
            str(value["source"]),
            str(value["printed"]),
            str(value["correct"]),
            ErratumCheck(
                kind=kind,
                frame=frame,
                frame_text=str(check.get("frame", "")),
                direction=Direction(check["direction"]) if "direction" in check else None,
                error=str(check.get("error", "")),
                command=str(check.get("command", "")),
                subcommand=check.get("subcommand"),
                fields=dict(check.get("fields") or {}),
                claimed=check.get("claimed"),
                actual=check.get("actual"),
                examples=tuple(check.get("examples") or ()),
            ),
        )


# --- sizes ----------------------------------------------------------------------------------------------------------


def fixed_size(field: Field) -> int | None:
    if isinstance(field, Scalar):
        return field.type.size
    if isinstance(field, Array):
        return field.item.size * field.count
    if isinstance(field, Bytes):
        return field.size if isinstance(field.size, int) else None
    if isinstance(field, Group):
        if isinstance(field.count, int) and field.item_size is not None:
            return field.count * field.item_size
        return None
    if isinstance(field, TableBlock):
        return sum(e.type.size for e in field.entries)
    return None


def sum_sizes(fields: tuple[Field, ...]) -> int | None:
    total = 0
    for field in fields:
        size = fixed_size(field)
        if size is None:
            return None
        total += size
    return total


def content_bounds(fields: tuple[Field, ...]) -> tuple[int, int | None]:
    """Smallest and largest content size (None: unbounded) the fields allow."""
    low = 0
    high: int | None = 0
    by_name = {f.name: f for f in fields}
    for field in fields:
        size = fixed_size(field)
        if size is not None:
            low += size
            high = None if high is None else high + size
            continue
        if isinstance(field, TableValue):
            sizes = [e.type.size for e in field.table.entries if not e.reserved]
            low += min(sizes)
            high = None if high is None else high + max(sizes)
        elif isinstance(field, Group) and isinstance(field.count, str) and field.count != "rest" and field.item_size:
            counter = by_name.get(field.count)
            most = int(counter.maximum) if isinstance(counter, Scalar) else None
            high = None if high is None or most is None else high + most * field.item_size
        elif isinstance(field, Bytes) and isinstance(field.size, str) and field.size != "rest":
            counter = by_name.get(field.size)
            most = int(counter.maximum) if isinstance(counter, Scalar) else None
            high = None if high is None or most is None else high + most
        else:
            high = None
    return low, high
