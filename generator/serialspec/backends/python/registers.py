"""Emit a protocol's register maps: the tables whose registers READ/WRITE carry as runs of bytes from an address."""

from __future__ import annotations

from typing import assert_never

from serialspec.backends.common.numbers import number
from serialspec.backends.python.render import one_line, render
from serialspec.lang.model import (
    Array,
    Bytes,
    Group,
    List,
    Packed,
    Protocol,
    Scalar,
    Table,
    TableBlock,
    TableValue,
    Text,
    Varint,
)


def register_tables(protocol: Protocol) -> list[Table]:
    """Tables that some message carries as a run of registers (`bytes` with `table:`), in spec order."""
    used: set[str] = set()
    for message in protocol.messages():
        stack = list(message.fields)
        while stack:
            f = stack.pop()
            match f:
                case Bytes() if f.table is not None:
                    used.add(f.table.name)
                case Group():
                    stack.extend(f.fields)
                case Scalar() | Varint() | Array() | Packed() | List() | Text() | Bytes() | TableValue() | TableBlock():
                    pass  # no run of registers
                case _:
                    assert_never(f)
    return [t for t in protocol.tables if t.name in used]


def map_name(table: Table) -> str:
    return table.constant


def names_alias(table: Table) -> str:
    return table.names_class


def model_maps(protocol: Protocol, table: Table) -> list[tuple[str, list[tuple[str, str, str]]]]:
    """The device models of the table the device keeps (name, [(entry, low, high)] where the model's range differs)."""
    device = protocol.device
    if device is None or device.memory is None or device.memory.name != table.name:
        return []
    table_ranges = {e.name: (e.minimum, e.maximum) for e in table.entries}
    return [
        (
            m.name,
            [
                (repr(e.name), number(e.minimum), number(e.maximum))
                for e in m.entries
                if (e.minimum, e.maximum) != table_ranges.get(e.name)
            ],
        )
        for m in device.models
    ]


def registers_module(protocol: Protocol) -> str:
    tables = []
    for table in register_tables(protocol):
        registers = []
        for entry in table.entries:
            if entry.reserved:
                continue
            args = [
                repr(entry.name),
                f"{entry.key:#04x}",
                repr(entry.type.struct_char),
                number(entry.minimum),
                number(entry.maximum),
                repr(entry.access),
            ]
            if entry.sign_magnitude:
                args.append(f"sign_bit={entry.sign_bit}")
            registers.append(f"Register({', '.join(args)}),  # {one_line(entry.unit) or '-'}")
        tables.append(
            {
                "name": table.name,
                "constant": map_name(table),
                "alias": names_alias(table),
                "title": one_line(table.title),
                "names": [e.name for e in table.entries if not e.reserved],
                "registers": registers,
                "models": model_maps(protocol, table),
            }
        )
    return render(
        "registers.py.j2",
        spec_path=one_line(protocol.spec_path),
        title=one_line(protocol.title),
        byte_order=protocol.byte_order,
        tables=tables,
    )
