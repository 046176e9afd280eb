"""Views of a decoded message that need the spec: engineering units, and register runs by name."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from serialspec.lang.model import Bytes, Field, Protocol, Scalar, Table, TableValue, engineering_unit
from serialspec.lang.model import Message as MessageSpec
from serialspec.runtime.message import Message

if TYPE_CHECKING:
    from serialspec.runtime.registers import RegisterMap


class FlagNames(list[str]):
    """The names of the flags set in a value: a JSON list in `--json`, read as words (`overload, overheat`, `none`)."""

    def __str__(self) -> str:
        return ", ".join(self) or "none"


def message_spec(protocol: Protocol, message: Message) -> MessageSpec:
    for spec in protocol.messages():
        if (spec.command, spec.subcommand, spec.direction) == (
            message.COMMAND,
            message.SUBCOMMAND,
            message.DIRECTION,
        ):
            return spec
    raise LookupError(f"{message.COMMAND} is not in {protocol.name}")


def engineering(protocol: Protocol, message: Message, fields: dict[str, Any]) -> dict[str, Any]:
    """Scaled values (wire × scale + offset) and enum/flag names in place of raw numbers."""
    spec = message_spec(protocol, message)
    result = dict(fields)
    for f in spec.fields:
        if f.name in result:
            result[f.name] = _field_units(f, result[f.name], fields)
    for element in protocol.framing.layouts[message.DIRECTION].value_elements:
        if element.flags and element.name in result:
            result[element.name] = _flag_names(element.flags, result[element.name])
    return result


def unit_symbols(protocol: Protocol, message: Message) -> dict[str, str]:
    """The unit of every field that has one (of the value `engineering` gives: wire value x scale)."""
    spec = message_spec(protocol, message)
    fields = message.to_fields()
    symbols = {}
    for f in spec.fields:
        unit = engineering_unit(f.unit, f.scale) if isinstance(f, Scalar) and not (f.enum or f.flags or f.bits) else ""
        if isinstance(f, TableValue):
            entry = f.table.entry(fields.get(f.key, -1))
            unit = engineering_unit(entry.unit, entry.scale) if entry is not None and entry.enum is None else ""
        if unit:
            symbols[f.name] = unit
    return symbols


def with_unit(value: Any, unit: str) -> str:
    return f"{value}{unit}" if unit == "°" else f"{value} {unit}"


def _field_units(f: Field, value: Any, siblings: dict[str, Any]) -> Any:
    if isinstance(f, Scalar):
        if f.bits:
            return {b.name: _enum_name(b.enum, value[b.name]) if b.enum else value[b.name] for b in f.bits}
        if f.enum:
            return _enum_name(f.enum, value)
        if f.flags:
            return _flag_names(f.flags, value)
        if f.scale is not None or f.offset is not None:
            return round(value * (1 if f.scale is None else f.scale) + (f.offset or 0), 6)
    if isinstance(f, TableValue):
        entry = f.table.entry(siblings[f.key])
        if entry is not None and entry.enum:
            return _enum_name(entry.enum, value)
        if entry is not None and entry.scale is not None:
            return round(value * entry.scale, 6)
    return value


def _flag_names(flags: Any, value: int) -> FlagNames:
    return FlagNames(b.name.lower() for b in flags.bits if value >> b.bit & 1)


def _enum_name(enum: Any, value: int) -> str | int:
    return next((v.name.lower() for v in enum.values if v.value == value), value)


def register_view(protocol: Protocol, message: Message, request: Message | None) -> dict[str, Any] | None:
    """Bytes that hold a run of registers, by register name, when the first register's key is known."""
    spec = message_spec(protocol, message)
    for f in spec.fields:
        if not isinstance(f, Bytes) or f.table is None or not f.start:
            continue
        source = message
        start_name = f.start
        if f.start_in_request:
            if request is None:
                return None
            source = request
        start = source.to_fields().get(start_name)
        if not isinstance(start, int):
            return None
        return registers(f.table, start, getattr(message, f.name), protocol.byte_order)
    return None


def register_map(table: Table, byte_order: str) -> RegisterMap:
    """The runtime's register map of a model table (what generated `registers.py` holds, built from the spec)."""
    from serialspec.runtime.registers import Register, RegisterMap

    registers = (
        Register(e.name, e.key, e.type.struct_char, e.minimum, e.maximum, e.access, e.sign_bit)
        for e in table.entries
        if not e.reserved
    )
    return RegisterMap(table.name, registers, byte_order)


def registers(table: Table, start: int, data: bytes, byte_order: str) -> dict[str, Any]:
    """Split bytes read or written from register `start` into named values (unknown bytes by address)."""
    return dict(register_map(table, byte_order).unpack(start, data))
