"""Emit one protocol's Python package: messages, codec, construct structs and the package's __init__."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from serialspec.backends.common.numbers import number
from serialspec.backends.python.client import client_module
from serialspec.backends.python.content import (
    ClassCode,
    PackageCode,
    decoder_name,
    encoder_name,
)
from serialspec.backends.python.dispatch import direction_entry, size_dispatch, value_arguments
from serialspec.backends.python.frames import (
    ERROR_REPLY,
    checksum_definitions,
    code_key,
    codec_lines,
)
from serialspec.backends.python.ir import (
    ContentSize,
    lines_of,
)
from serialspec.backends.python.length_byte_frames import length_byte_codec_context
from serialspec.backends.python.optimize import content_unpacked, fuse_unpack
from serialspec.backends.python.registers import register_tables, registers_module
from serialspec.backends.python.render import one_line, render
from serialspec.backends.python.simulator import import_order, simulator_module
from serialspec.backends.python.straight_frames import Target, direction_functions
from serialspec.backends.python.structs import structs_module
from serialspec.collection import without_cycle_collection
from serialspec.lang.model import (
    Direction,
    Group,
    Message,
    Protocol,
    Scalar,
    Table,
    TableValue,
    replies_by_request,
    reply_to,
)
from serialspec.lang.names import python_view, spec_name


def class_context(cls: ClassCode, where: str, keys: list[str], optional: list[str]) -> dict[str, Any]:
    return {
        "name": cls.name,
        "doc": cls.doc,
        "base": cls.base or "Record",
        "attributes": cls.attributes,
        "class_vars": cls.class_vars,
        "to_fields": cls.to_fields,
        "from_fields": cls.from_fields,
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
    base = {"spec_path": protocol.spec_path, "title": one_line(protocol.title), "package": protocol.name}
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
            match_by=repr(protocol.matching),
            models=[(m.number, m.name) for m in protocol.device.models] if protocol.device else [],
            model_entry=protocol.device.model_entry if protocol.device else "",
        ),
        "client.py": client_module(protocol),
        "py.typed": "",
    }
    if register_tables(protocol):
        files["registers.py"] = registers_module(protocol)
    if protocol.device is not None:
        files["simulator.py"] = simulator_module(spec)
    return files


# The runtime's helpers that build fields from data, by the name generated code calls them (serialspec.runtime.fields).
FIELD_HELPERS = (
    ("as_bytes", "_bytes"),
    ("bits", "_bits"),
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
    # the frames' part first: the length-byte codec's whole-frame decoders add structs the common part lists
    length_byte = protocol.framing.classic  # every layout has the length-byte shape (length_byte_frames.py)
    specific = length_byte_codec_context(protocol, code) if length_byte else straight_codec_context(protocol, code)
    return common_codec_context(protocol, code, exports) | specific


def straight_codec_context(protocol: Protocol, code: PackageCode) -> dict[str, Any]:
    """Frames of any other shape: straight-line frame functions per direction where the layouts allow them (see
    straight_frames.py), else the runtime's frame engine; one FrameCodec per direction either way (the stream parser's),
    decoders by code (and by class)."""
    # layouts chosen by command, checksums over request bytes: the engine's code only (no straight-line checks)
    engine_only = protocol.framing.by_command or protocol.framing.from_request
    imports, definitions = checksum_definitions(protocol, straight=not engine_only)
    directions: list[dict[str, Any]] = []
    dispatchers = []
    size_dispatchers: list[dict[str, Any]] = []
    frame_structs: dict[str, str] = {}
    # the runtime.framing names the codec uses: the FrameCodecs' (the straight-line functions' Transparency objects are
    # those of the same layouts) and ERROR_REPLY where error replies are told by their flag
    names = {"EngineFormat"}
    for direction, layout in protocol.framing.layouts.items():
        by_code: dict[str, list[tuple[Message | None, str, int, int | None]]] = {}
        for command in protocol.commands:
            entry = direction_entry(command, direction)
            if entry is None:
                continue
            target, low, high, sub_dispatch = entry
            if sub_dispatch:
                dispatchers.append(sub_dispatch | value_arguments(layout))
            message = None if sub_dispatch else command.request if direction == Direction.REQUEST else command.response
            by_code.setdefault(code_key(command, layout), []).append((message, target, low, high))
        dispatch: list[tuple[str, str]] = []
        expected: list[tuple[str, str, str]] = []  # class, code, decoder: replies chosen by the request they answer
        sizes: list[tuple[str, int, int | None]] = []
        single: dict[str, Message] = {}
        for key, users in by_code.items():
            # the resolver allows several only for plain replies, one of them marked default, and for requests told
            # apart by their content size
            chosen = next((u for u in users if u[0] is not None and u[0].default_reply), users[0])
            if direction == Direction.REQUEST and len(users) > 1:
                by_size = size_dispatch(key, direction, [m for m, _, _, _ in users if m is not None])
                size_dispatchers.append(by_size | value_arguments(layout))
                chosen = (None, by_size["name"], 0, None)
            dispatch.append((key, chosen[1]))
            highs = [u[3] for u in users]
            sizes.append((key, min(u[2] for u in users), None if None in highs else max(h or 0 for h in highs)))
            if len(users) == 1 and users[0][0] is not None:
                single[key] = users[0][0]
            if direction == Direction.RESPONSE:
                expected += [(m.class_name, key, t) for m, t, _, _ in users if m is not None and len(users) > 1]
        only = dispatch[0][1] if not layout.has_command and len(dispatch) == 1 and not expected else ""
        values = tuple(e.name for e in layout.value_elements)
        requesting = protocol.framing.by_command or protocol.framing.from_request
        frames = Target(direction.name, values, expected=bool(expected), only=only, requesting=requesting)
        if protocol.error_reply is not None and direction == Direction.RESPONSE:
            element = next(e for e in layout.elements if e.name == protocol.error_reply.element)
            assert element.type is not None
            mask = (1 << (8 * element.type.size)) - 1
            flag = protocol.error_reply.flag
            frames = replace(frames, error_flag=flag, error_keep=mask & ~flag)
        plain = unpacked_messages(single, code) if not expected and not frames.error_flag else []
        functions, call = direction_functions(protocol, direction, frames, frame_structs, plain)
        names |= {ERROR_REPLY} if frames.error_flag else set()
        if protocol.framing.by_request(direction):  # content sizes and size rules by reply class
            answering = [m for m in protocol.messages() if m.direction == direction]
            sizes = [(repr(m.class_name), m.min_size, m.max_size) for m in answering]
            single = {repr(m.class_name): m for m in answering}
        frame_codec, used = codec_lines(protocol, direction, sizes, single)
        names |= used
        directions.append(
            {
                "name": direction.value,
                "upper": direction.name,
                "dispatch": dispatch,
                "expected": expected,
                "frames": frame_codec,
                "functions": functions,
                "call": call,
                "headers": sorted({layout.header for layout in protocol.framing.alternatives[direction]}),
            }
        )
    headers = [h for d in directions for h in d["headers"]]
    shared = {cls for d in directions for cls, _, _ in d["expected"]}
    replies = replies_by_request(protocol.messages())
    reply_layouts = [
        (m.class_name, reply.class_name)
        for m in protocol.messages()
        if m.direction == Direction.REQUEST
        and (reply := reply_to(m, replies)) is not None
        and reply.class_name in shared
        and not reply.default_reply
    ]
    code.structs.update(frame_structs)  # listed with the content's structs (common_codec_context)
    requesting = protocol.framing.by_command or protocol.framing.from_request
    return {
        "length_byte_frames": False,
        "requesting": requesting,
        "reply_to": [
            (m.class_name, reply.class_name)
            for m in protocol.messages()
            if m.direction == Direction.REQUEST and (reply := reply_to(m, replies)) is not None
        ]
        if requesting
        else [],
        "reply_layouts": reply_layouts,
        "framing_imports": sorted(names, key=import_order),
        # the straight-line frame checks raise it (the engine raises its own)
        "checksum_error": any(
            element.kind == "checksum"
            for direction in protocol.framing.layouts
            if (straight := code.straight(direction)) is not None
            for layout in straight.layouts
            for element in layout.elements
        ),
        "checksum_imports": imports,
        "checksum_definitions": definitions,
        "directions": directions,
        "dispatchers": dispatchers,
        "size_dispatchers": size_dispatchers,
        "by_header": all(headers) and len(set(headers)) == len(headers),
    }


def unpacked_messages(single: dict[str, Message], code: PackageCode) -> list[tuple[int, int, str, str, str]]:
    """(code, content size, class, struct's name stem, its format) of the messages of one size whose decoder, past its
    size check, is one struct's unpack of the content as their message (straight_frames.whole_frames decodes them
    whole)."""
    bodies = {name: body for name, _, _, body in code.decoders}
    found = []
    for key, message in single.items():
        body = bodies[decoder_name(message)]
        if key in ("None", ERROR_REPLY) or message.min_size != message.max_size or len(body) < 2:
            continue
        if not (isinstance(body[0], ContentSize) and body[0].exact):
            continue
        unpacked = content_unpacked(body[1:])
        if unpacked is not None:
            cls, struct = unpacked
            found.append((int(key, 16), message.min_size or 0, cls, code.stems[struct], code.structs[struct]))
    return found


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
