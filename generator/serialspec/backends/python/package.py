"""Emit one protocol's Python package: messages, codec, construct structs and the package's __init__."""

from __future__ import annotations

from typing import Any

from serialspec.backends.common.numbers import number
from serialspec.backends.python.client import client_module
from serialspec.backends.python.content import ClassCode, PackageCode
from serialspec.backends.python.dispatch import (
    encoder_name,
)
from serialspec.backends.python.frames.codec import frames_codec_context
from serialspec.backends.python.ir import (
    lines_of,
)
from serialspec.backends.python.optimize import fuse_unpack
from serialspec.backends.python.registers import register_tables, registers_module
from serialspec.backends.python.render import one_line, render
from serialspec.backends.python.simulator import simulator_module
from serialspec.backends.python.structs import structs_module
from serialspec.collection import without_cycle_collection
from serialspec.lang.model import (
    Bytes,
    Group,
    Message,
    Protocol,
    Scalar,
    Table,
    TableValue,
)
from serialspec.lang.names import python_name, python_view, spec_name


def class_context(cls: ClassCode, where: str, keys: list[str], optional: list[str]) -> dict[str, Any]:
    return {
        "name": cls.name,
        "doc": cls.doc,
        "base": cls.base or "Record",
        "attributes": cls.attributes,
        "class_vars": cls.class_vars,
        "to_fields": cls.to_fields,
        "from_fields": cls.from_fields,
        "given_checks": cls.given_checks,
        "default_name": cls.default_name,
        "where": where,
        "keys": repr(tuple(keys)),
        "json_keys": repr(tuple(spec_name(key) for key in keys)),  # a keyword's field: its spec name in JSON
        "optional_keys": repr(tuple(spec_name(key) for key in optional)),
    }


def _keys(cls: ClassCode) -> list[str]:
    return [a.name for a in cls.attributes]


@without_cycle_collection
def emit_package(protocol: Protocol) -> dict[str, str]:
    """File name (relative to the package folder) -> text."""
    spec = protocol  # the spec's names, for the simulator: it works on to_fields()'s dicts, keyed by them
    protocol = python_view(protocol)  # fields named after Python keywords: their attributes (`class_`)
    code = PackageCode(protocol)
    base = {"spec_path": one_line(protocol.spec_path), "title": one_line(protocol.title), "package": protocol.name}
    base["spec_file"] = protocol.spec_path  # as it is, in a Python string (SPEC)
    messages = {m.class_name: m for m in protocol.messages()}
    classes = []
    for cls in [*code.helper_classes, *code.message_classes]:
        message = messages.get(cls.name)
        optional = [f.name for f in message.fields if isinstance(f, Scalar) and f.hidden] if message else []
        where = f"{message.key} {message.direction.value}" if message else cls.name
        if message:
            cls.doc = one_line(message_doc(protocol, message))
        classes.append(class_context(cls, where, _keys(cls), optional))
    helpers = frozenset().union(*(cls.helpers for cls in [*code.helper_classes, *code.message_classes]))
    enums = [
        {
            "class_name": e.class_name,
            "doc": one_line(e.description or e.name.replace("_", " ")),
            "values": [{"name": v.name, "value": v.value, "text": one_line(v.text)} for v in e.values],
        }
        for e in protocol.enums
    ]
    flag_sets = [
        {
            "class_name": f.class_name,
            "doc": one_line(f.description or f.name.replace("_", " ")),
            "bits": [{"name": b.name, "bit": b.bit, "text": one_line(b.text)} for b in f.bits],
        }
        for f in protocol.flags
    ]
    exports = sorted(
        [
            *(e["class_name"] for e in enums),
            *(f["class_name"] for f in flag_sets),
            *(c["name"] for c in classes),
            *(c["default_name"] for c in classes if c["default_name"]),
            "MESSAGE_TYPES",
            "Direction",
            "Message",
        ]
    )
    files = {
        "messages.py": render(
            "messages.py.j2",
            field_imports=field_imports(helpers, bool(classes)),
            **base,
            enums=enums,
            flag_sets=flag_sets,
            enum_imports=[name for name, used in (("IntEnum", enums), ("IntFlag", flag_sets)) if used],
            classes=classes,
            required=any(a.default == "REQUIRED" for c in classes for a in c["attributes"]),
            message_classes=[c for c in classes if c["name"] in messages],
            exports=exports,
        ),
        "codec.py": render(
            "codec.py.j2",
            **base,
            **codec_context(protocol, code, exports),
        ),
        "structs.py": structs_module(protocol),
        "__init__.py": render(
            "init.py.j2",
            **base,
            description=one_line(protocol.description),
            baudrate=protocol.serial.baudrate,
            serial=protocol.serial,
            gap=repr(protocol.framing.gap) if protocol.framing.gap else "",
            turnaround=repr(protocol.framing.turnaround) if protocol.framing.turnaround else "",
            match_by=repr(protocol.matching),
            models=[(m.number, m.name) for m in protocol.device.models] if protocol.device else [],
            model_entry=protocol.device.model_entry if protocol.device else "",
            checksummed=repr(checksummed_directions(protocol)),
            register_views=register_views(spec),
        ),
        "client.py": client_module(protocol),
        "py.typed": "",
    }
    if register_tables(protocol):
        files["registers.py"] = registers_module(protocol)
    if protocol.device is not None:
        files["simulator.py"] = simulator_module(spec)
    return files


def checksummed_directions(protocol: Protocol) -> tuple[str, ...]:
    """The directions whose frames carry a checksum (in any of their layouts); where layouts are chosen by command,
    the message classes whose own layout carries one instead (RoboClaw's read requests carry none)."""
    if protocol.framing.by_command:
        return tuple(m.class_name for m in protocol.messages() if protocol.layout(m).checksums)
    return tuple(
        d.value for d, layouts in protocol.framing.alternatives.items() if any(layout.checksums for layout in layouts)
    )


def register_views(spec: Protocol) -> list[tuple[str, str, str, str]]:
    """(class, bytes field's attribute, start field's spec name, register map constant) of each message whose bytes
    are a run of registers starting at a field of its own (the first such field: what `serialspec decode` shows)."""
    views = []
    for message in spec.messages():
        f = next((f for f in message.fields if isinstance(f, Bytes) and f.table is not None and f.start), None)
        if isinstance(f, Bytes) and f.table is not None and not f.start_in_request:
            views.append((message.class_name, python_name(f.name), f.start, f.table.constant))
    return views


# The runtime's helpers that build fields from data, by the name generated code calls them (serialspec.runtime.fields).
FIELD_HELPERS = (
    ("as_bytes", "_bytes"),
    ("bits", "_bits"),
    ("check_given", "_check_given"),
    ("check_keys", "_check_keys"),
    ("enum", "_as_enum"),
    ("flags", "_as_flags"),
    ("get", "_get"),
    ("integer", "_integer"),
    ("integers", "_integers"),
    ("items", "_items"),
    ("mapping", "_mapping"),
    ("number", "_number"),
    ("numbers", "_numbers"),
    ("optional_bytes", "_optional_bytes"),
    ("text", "_text"),
)


def field_imports(helpers: frozenset[str], classes: bool) -> list[tuple[str, str]]:
    """The helpers the classes' from_fields call (ClassCode.helpers), as (name, alias), in the order isort wants;
    `classes`: there are classes, whose from_fields check their keys (the template calls _check_keys)."""
    used = helpers | {"_check_keys"} if classes else helpers
    assert used <= {alias for _, alias in FIELD_HELPERS}, used - {alias for _, alias in FIELD_HELPERS}
    return [(name, alias) for name, alias in FIELD_HELPERS if alias in used]


def message_doc(protocol: Protocol, message: Message) -> str:
    command = protocol.command(message.command)
    sub = next((s for s in command.subcommands if s.name == message.subcommand), None)
    title = (sub.title if sub else command.title) or message.key
    parts = [f"{title} ({message.direction.value})."]
    if message.description:
        parts.append(message.description)
    if message.optional:
        parts.append(f"Optional: {message.optional}")
    if message.unsolicited:
        parts.append("Sent by the device on its own.")
    return " ".join(parts)


def codec_context(protocol: Protocol, code: PackageCode, exports: list[str]) -> dict[str, Any]:
    frames = frames_codec_context(protocol, code)  # first: its whole-frame decoders add structs the common part lists
    return common_codec_context(protocol, code, exports) | frames


def common_codec_context(protocol: Protocol, code: PackageCode, exports: list[str]) -> dict[str, Any]:
    encoder_table = [(m.class_name, encoder_name(m)) for m in protocol.messages()]
    codec_names = names_used_in_codec(code)
    return {
        "packing_imports": sorted([*code.packing, *(["unpack_runs"] if code.unpack_runs else [])]),
        "unpack_runs": sorted(code.unpack_runs.items()),
        "structs": sorted(code.structs.items()),
        "tables": [
            table_context(t) for t in protocol.tables if any(uses_table(m, t.name) for m in protocol.messages())
        ],
        "member_maps": sorted(code.member_maps),
        "decoders": [
            {"name": n, "returns": r, "extra": e, "lines": lines_of(fuse_unpack(body))}
            for n, r, e, body in code.decoders
        ],
        "encoders": [{"name": n, "type": t, "lines": lines} for n, t, lines in code.encoders],
        "encoder_table": encoder_table,
        "imports": sorted(
            (n for n in exports if n not in ("Direction", "Message", "MESSAGE_TYPES") and n in codec_names),
            key=str.lower,  # the order isort (ruff) expects
        ),
        "shared_header": protocol.framing.shared_header,
    }


def names_used_in_codec(code: PackageCode) -> set[str]:
    """The generated classes the codec's bodies name: the types they return or take, the classes the decoders build
    (PackageCode.build) and the enum and flag classes whose members they look up (PackageCode.member_maps)."""
    types = {r for _, r, _, _ in code.decoders} | {t for _, t, _ in code.encoders}
    return types | set(code.built) | code.member_maps


def uses_table(message: Message, table: str) -> bool:
    """Whether a field of the message (or of a group's items) holds a value of the table by its key."""
    stack = list(message.fields)
    while stack:
        f = stack.pop()
        if isinstance(f, TableValue) and f.table.name == table:
            return True
        if isinstance(f, Group):
            stack.extend(f.fields)
    return False


def table_context(table: Table) -> dict[str, Any]:
    entries = [e for e in table.entries if not e.reserved]
    return {
        "upper": table.name.upper(),
        "structs": [(e.key, "<" + e.type.struct_char) for e in entries],
        "ranges": [(e.key, number(e.minimum), number(e.maximum)) for e in entries],
    }
