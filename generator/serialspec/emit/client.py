"""Emit a protocol's typed client: one method per command and sub-command, built on runtime.transport.

Decisions made here, the same for every protocol:
- arguments and results are wire units, like the messages (the spec's `unit`/`scale` are in the docstrings);
- a method returns the reply's one field that is not an echo of the request, the whole reply when there are
  several, and True/False (answered or not) when there are none;
- a reply that can be absent (broadcast address, `optional_when`) makes the method return None then;
- a table that one command reads by key and another writes by key gets read_<entry>/write_<entry> by name:
  `read_parameter(id, "voltage")`.
"""

from __future__ import annotations

from typing import Any

from serialspec.emit.pycode import annotation, number, one_line
from serialspec.emit.render import render
from serialspec.emit.simulator import import_order, request_response_pairs
from serialspec.spec.model import (
    Direction,
    Field,
    Group,
    Message,
    Protocol,
    Scalar,
    Table,
    TableBlock,
    TableValue,
)

RESERVED = {"bus", "close", "subscribe", "optional_replies"}


def address_of(protocol: Protocol) -> tuple[str, int | None]:
    if protocol.device is not None:
        return protocol.device.address, protocol.device.broadcast
    for layout in protocol.framing.layouts.values():
        for element in layout.value_elements:
            if element.role == "address":
                return element.name, element.broadcast
    return "", None


def value_fields(protocol: Protocol, message: Message) -> list[Field]:
    """The members of a message class, frame-level values (SMS id) first, as the codec generator orders them."""
    layout = protocol.framing.layouts[message.direction]
    frame = [
        Scalar(
            e.name,
            e.description,
            "",
            "",
            e.type,
            "<",
            "",
            None,
            e.minimum,
            e.maximum,
            None,
            None,
            None,
            e.flags,
            (),
            "",
            False,
        )
        for e in layout.value_elements
        if e.type is not None
    ]
    return [*frame, *(f for f in message.fields if not (isinstance(f, Scalar) and f.hidden))]


def type_names(f: Field) -> list[str]:
    if isinstance(f, Scalar):
        names = (f.bits_class, f.enum.class_name if f.enum else "", f.flags.class_name if f.flags else "")
        return [n for n in names if n]
    if isinstance(f, Group | TableBlock):
        return [f.class_name]
    return []


def describe(f: Field) -> str:
    parts = [f.description or f.name.replace("_", " ")]
    unit = getattr(f, "unit", "")
    if unit:
        parts.append(f"[{unit}]")
    if isinstance(f, Scalar) and not f.bits and (f.minimum, f.maximum) != (f.type.minimum, f.type.maximum):
        parts.append(f"({number(f.minimum)}..{number(f.maximum)})")
    return one_line(" ".join(parts))


def table_commands(protocol: Protocol) -> list[dict[str, Any]]:
    """Tables some command reads by key and another writes by key: read_/write_<entry> by name."""
    address, _ = address_of(protocol)
    found = []
    for table in protocol.tables:
        reader = writer = None
        for request, response in request_response_pairs(protocol):
            names = [f.name for f in value_fields(protocol, request)]
            if response is not None:
                value = next((f for f in response.fields if isinstance(f, TableValue) and f.table is table), None)
                if value is not None and names == [address, value.key] and reader is None:
                    reader = (request, value)
            value = next((f for f in request.fields if isinstance(f, TableValue) and f.table is table), None)
            if value is not None and names == [address, value.key, value.name] and writer is None:
                writer = (request, value)
        if reader and writer:
            found.append(table_context(protocol, table, reader, writer))
    return found


def method_name(message: Message) -> str:
    name = message.key.replace(".", "_")
    return f"{name}_command" if name in RESERVED else name


def table_context(
    protocol: Protocol, table: Table, reader: tuple[Message, TableValue], writer: tuple[Message, TableValue]
) -> dict[str, Any]:
    entries = [e for e in table.entries if not e.reserved]
    return {
        "name": table.name,
        "singular": table.name[:-1] if table.name.endswith("s") else table.name,
        "upper": table.name.upper(),
        "title": one_line(table.title or table.name),
        "entries": [(e.name, e.key) for e in entries],
        "read_only": [e.name for e in entries if e.access == "r"],
        "reader": method_name(reader[0]),
        "writer": method_name(writer[0]),
        "key": reader[1].key,
    }


def client_module(protocol: Protocol) -> str:
    address, broadcast = address_of(protocol)
    imports: set[str] = set()
    methods = []
    optional_keys: set[int] = set()
    tables = table_commands(protocol)
    writers = {t["writer"]: t for t in tables}
    for request, response in request_response_pairs(protocol):
        command = protocol.command(request.command)
        sub = next((s for s in command.subcommands if s.name == request.subcommand), None)
        fields = value_fields(protocol, request)
        imports.add(request.class_name)
        params = []
        trailing = True
        defaults: dict[str, str] = {}
        for f in reversed(fields):
            if trailing and isinstance(f, Scalar) and f.default is not None and not f.enum and not f.bits:
                defaults[f.name] = number(f.default)
            else:
                trailing = False
        for f in fields:
            imports.update(type_names(f))
            default = f" = {defaults[f.name]}" if f.name in defaults else ""
            params.append(f"{f.name}: {annotation(f)}{default}")
        title = (sub.title if sub else command.title) or request.key.replace("_", " ")
        doc = [one_line(title) + ("" if title.endswith(".") else ".")]
        description = (sub.description if sub else command.description) or request.description
        if description:
            doc.append("")
            doc.append(one_line(description))
        if command.broadcast:
            doc.append("")
            doc.append("Broadcast: " + one_line(command.broadcast))
        doc.append("")
        doc.append("Args:")
        doc.extend(f"    {f.name}: {describe(f)}" for f in fields)
        may_broadcast = any(
            f.name == address and isinstance(f, Scalar) and broadcast is not None and f.maximum >= broadcast
            for f in fields
        )
        optional = response.optional_when if response else None
        if optional:
            optional_keys.add(optional.key)
        silent = response is None or optional is not None or may_broadcast
        kind = "send"
        returns = "None"
        result_expr = ""
        if response is not None:
            imports.add(response.class_name)
            echoes = {f.name for f in fields}
            rest = [f for f in value_fields(protocol, response) if f.name not in echoes]
            if not rest:
                kind, returns = ("bool", "bool")
            elif len(rest) == 1:
                imports.update(type_names(rest[0]))
                kind, returns, result_expr = "value", annotation(rest[0]), f"reply.{rest[0].name}"
            else:
                kind, returns, result_expr = "message", response.class_name, "reply"
            if silent and kind != "bool":
                returns = f"{returns} | None"
            doc.append("")
            if kind == "bool":
                doc.append("Returns: True if the device answered, False if it stayed silent (timeout).")
            elif kind == "value":
                doc.append(f"Returns: {rest[0].name}: {describe(rest[0])}")
            else:
                doc.append(f"Returns: the {response.class_name} reply.")
            if silent:
                why = one_line(response.optional) if response.optional else "broadcast gets no reply"
                doc.append(f"None when no reply is due ({why}).")
        else:
            doc.append("")
            doc.append("The device does not answer.")
        table = writers.get(method_name(request))
        methods.append(
            {
                "name": method_name(request),
                "params": ", ".join(params),
                "returns": returns,
                "doc": doc,
                "request": request.class_name,
                "response": response.class_name if response else "",
                "build": ", ".join(f"{f.name}={f.name}" for f in fields),
                "kind": kind,
                "silent": silent,
                "optional": f"({optional.key}, {optional.equals})" if optional else "None",
                "after": repr(response.after) if response and response.after else "",
                "result": result_expr,
                "remember": (
                    f"self._remember({address}, {table['key']}, "
                    f"{next(f.name for f in request.fields if isinstance(f, TableValue))})"
                )
                if table
                else "",
            }
        )
    class_name = "".join(w.capitalize() for w in protocol.name.split("_")) + "Client"
    return render(
        "client.py.j2",
        spec_path=protocol.spec_path,
        title=one_line(protocol.title),
        package=protocol.name,
        class_name=class_name,
        description=one_line(protocol.description),
        address=repr(address),
        broadcast=repr(broadcast),
        status=repr(
            tuple(
                e.name
                for layout in [protocol.framing.layouts[Direction.RESPONSE]]
                for e in layout.value_elements
                if e.role == "status"
            )
        ),
        methods=methods,
        tables=tables,
        optional_keys=sorted(optional_keys),
        imports=sorted(imports | {"Direction"}, key=import_order),
        error_imports=[
            name
            for name, used in (("EncodeError", bool(tables)), ("Timeout", any(m["kind"] == "bool" for m in methods)))
            if used
        ],
    )
