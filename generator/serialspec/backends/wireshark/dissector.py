"""A Wireshark dissector in Lua for one protocol: the spec as a Lua table, read by one engine (dissector.lua.j2).

The table holds what the Python codec is written from: each direction's frame layouts (elements, the spans lengths
count and checksums cover, byte stuffing), the messages by command code (and sub-command selector), and every
message's fields with their types, units, scales, enums, flags and bit fields. The engine in the template finds the
frames in a packet (several per packet), checks constants, lengths and checksums, and shows each frame's command
and fields under the names `<protocol>.<command>[.<subcommand>].<direction>.<field>`.
"""

from __future__ import annotations

from typing import Any, assert_never

from serialspec.backends import Unsupported
from serialspec.backends.common.frames import layout_codes, runtime_layout
from serialspec.backends.common.render import render
from serialspec.backends.common.text import collapse
from serialspec.encodings import bit_run, low_bits, seven_bit
from serialspec.lang import counts
from serialspec.lang.frozen import frozen
from serialspec.lang.model import (
    VALUE_ROLES,
    Array,
    BitField,
    Bytes,
    Checksum,
    Count,
    Counted,
    Direction,
    EnumDef,
    Field,
    FlagsDef,
    FrameLayout,
    Group,
    List,
    Message,
    Packed,
    Protocol,
    Scalar,
    TableBlock,
    TableEntry,
    TableValue,
    Text,
    Varint,
    content_bounds,
    discriminator,
    engineering_unit,
    refusals_of,
    replies_by_request,
    reply_to,
    size_terms,
    sized_apart,
)
from serialspec.runtime.framing import Layout


def emit_dissector(protocol: Protocol) -> str:
    for message in protocol.messages():
        if (why := counts.lua_refusal(message.fields)) is not None:
            raise Unsupported(f"{message.key} {message.direction.value}: {why}")
    directions = {d.value: _direction(protocol, d) for d in protocol.framing.alternatives}
    used = {
        f.table.name
        for m in protocol.messages()
        for f in _all_fields(m.fields)
        if isinstance(f, TableValue | TableBlock)
    }
    tables = {t.name: {e.key: _entry(e) for e in t.entries} for t in protocol.tables if t.name in used}
    layouts = [d["layouts"] for d in directions.values()]
    shared = None
    if len(layouts) == 2 and layouts[0] == layouts[1]:  # the same frames both ways: written once
        shared = layouts[0]
        for direction in directions.values():
            direction["layouts"] = Ref("LAYOUTS")
    data = {
        "name": protocol.name,
        "title": protocol.title,
        "big": protocol.byte_order == "big",
        "directions": directions,
    }
    return render(
        "serialspec.backends.wireshark",
        "dissector.lua.j2",
        protocol=protocol,
        title=collapse(protocol.title),  # Lua comment lines: one line each
        spec=collapse(protocol.spec_path),
        enums=lua({e.name: _enum_values(e) for e in protocol.enums}, 0),
        tables=lua(tables, 0),
        layouts=lua(shared, 0),
        data=lua(data, 0),
        checksums=_checksum_functions(protocol),
        # the `encoding: seven_bit` and `nibbles` function, where a field uses one
        low_bits_lua=low_bits.LUA
        if any(isinstance(f, Scalar) and f.low_bits for m in protocol.messages() for f in _all_fields(m.fields))
        else "",
        # and its text of 14-bit characters, where a string uses it
        seven_bit_text_lua=seven_bit.LUA_TEXT
        if any(isinstance(f, Text) and f.seven_bit for m in protocol.messages() for f in _all_fields(m.fields))
        else "",
        bit_run_lua=bit_run.LUA
        if any(isinstance(f, Scalar) and f.bit_place for m in protocol.messages() for f in _all_fields(m.fields))
        else "",
        # counts and sizes by expression (lang/counts.py), where a field has one
        counted_lua=counts.LUA
        if any(counts.counted(f) for m in protocol.messages() for f in _all_fields(m.fields))
        else "",
    )


def _all_fields(fields: tuple[Field, ...]) -> list[Field]:
    found: list[Field] = []
    for item in fields:
        found.append(item)
        if isinstance(item, Group):
            found += _all_fields(item.fields)
    return found


@frozen
class Ref:
    """A Lua expression in place of a literal: a table written once and shared (ENUMS, TABLES, LAYOUTS)."""

    expression: str


def _direction(protocol: Protocol, direction: Direction) -> dict[str, Any]:
    layouts = protocol.framing.alternatives[direction]
    coded = any(layout.has_command for layout in layouts)  # else every message of this direction is codeless
    codes: dict[int | str, Any] = {}
    sharing: dict[int | str, list[Message]] = {}  # each key's messages, for a leading constant that picks them
    for command in protocol.commands:
        message = command.request if direction == Direction.REQUEST else command.response
        if message is not None and not (command.selector is not None and direction in command.selector.offsets):
            key = _code(command.wire_code(direction) if coded else None)
            if protocol.error_reply is not None and command.name == protocol.error_reply.command:
                key = "error"
            sharing.setdefault(key, []).append(message)
    # requests that share a code, and replies none of which is the default: told apart by their content size
    apart = {
        key: sized_apart(found, key == "none" and protocol.framing.by_request(direction))
        for key, found in sharing.items()
    }
    sharing = {}
    for command in protocol.commands:
        selector = command.selector
        if selector is not None and direction in selector.offsets:
            subs = {}
            for sub in command.subcommands:
                message = sub.request if direction == Direction.REQUEST else sub.response
                if message is not None:
                    subs[sub.code] = _message(protocol, message)
            if subs:
                entry: dict[str, Any] = {
                    "selector": {"offset": selector.offsets[direction], "size": selector.type.size},
                    "subs": subs,
                }
                sizes = {(m["min"], m["max"]) for m in subs.values()}
                entry["min"] = min(low for low, _ in sizes)
                entry["max"] = None if any(high is None for _, high in sizes) else max(h for _, h in sizes if h)
                codes.setdefault(_code(command.wire_code(direction) if coded else None), entry)
                continue
        message = command.request if direction == Direction.REQUEST else command.response
        if message is None:
            continue
        key = _code(command.wire_code(direction) if coded else None)
        if protocol.error_reply is not None and command.name == protocol.error_reply.command:
            key = "error"
        sharing.setdefault(key, []).append(message)
        if key in codes and apart.get(key):  # requests (replies without a default) sharing a code: by their size
            shared = codes[key]
            layouts_by_size = shared.get("by_size") or [shared.pop("message")]
            shared["by_size"] = [*layouts_by_size, _message(protocol, message)]
            highs = [m["max"] for m in shared["by_size"]]
            shared["min"] = min(m["min"] for m in shared["by_size"])
            shared["max"] = None if None in highs else max(highs)
            continue
        if key in codes and not message.default_reply:
            continue  # replies sharing a code: the one decoded without its request (the default) is shown
        codes[key] = {"message": _message(protocol, message)}
        codes[key]["min"], codes[key]["max"] = codes[key]["message"]["min"], codes[key]["message"]["max"]
    for key, messages in sharing.items():
        lead = discriminator(messages) if "by_size" in codes[key] else None
        if lead is not None:  # picked by their leading constant (lang/model/discriminator.py), before their size
            if lead.size > 6:
                raise Unsupported(f"a leading constant of {lead.bits} bits that picks a message (Lua numbers: 48)")
            codes[key]["lead"] = {
                "size": lead.size,
                "big": lead.endian == "big",
                "divisor": 1 << lead.shift,
                "modulus": 1 << lead.bits,
                "field": lead.name,
                "values": {value: messages.index(m) + 1 for value, m in lead.values},
            }
    # a layout with optional elements (`present_if`) as the engine's variants: one per choice of them sent or not,
    # told apart by their flag bits like alternative layouts by their constants
    # (a layout without a header beside ones with a header is tried last: it takes the frames no header starts)
    ordered = sorted(layouts, key=lambda layout: not layout.header) if len(layouts) > 1 else layouts
    variants = [(layout, variant) for layout in ordered for variant in runtime_layout(layout).variants]
    result: dict[str, Any] = {"layouts": [], "codes": codes}
    for layout, variant in variants:
        item = _layout(layout, variant)
        item["name"] = layout.name
        found = layout_codes(protocol, layout) if protocol.framing.by_command else None
        if found is not None:  # layouts chosen by command: the codes its frames send, as a set
            item["codes"] = {code: True for code in found}
        result["layouts"].append(item)
    if protocol.framing.by_request(direction):
        # replies that carry no code, read in the layout of the request they answer: each reply by its key (the
        # request's message names it, `answer`), with its layout
        result["answers"] = {}
        for message in protocol.messages():
            if message.direction == direction and not message.unsolicited:
                entry = {"message": _message(protocol, message), "layout": protocol.layout(message).name}
                entry["min"], entry["max"] = entry["message"]["min"], entry["message"]["max"]
                result["answers"][message.key] = entry
    if protocol.error_reply is not None:
        result["error_flag"] = protocol.error_reply.flag
        result["error_element"] = protocol.error_reply.element
        if protocol.error_reply.status:  # told by the status's `error_bits`
            result["error_status"] = protocol.error_reply.status
            result["error_bits"] = protocol.error_reply.bits
    return result


def _code(code: int | None) -> int | str:
    return "none" if code is None else code


def _layout(layout: FrameLayout, engine: Layout) -> dict[str, Any]:
    """One plain layout (a variant of `layout` where it has optional elements) as the Lua table's."""
    elements = []
    model = {e.name: e for e in layout.elements}
    for runtime in engine.elements:
        element = model[runtime.name]
        # (the size and byte order the variant's: an extended length's long form is 1 + its wider size, big-endian)
        item: dict[str, Any] = {"name": element.name, "role": element.role, "size": runtime.size}
        item["big"] = runtime.endian == "big"
        if element.fixed:
            item["constant"] = runtime.constant  # a flag element's: with the variant's bit
        if runtime.need != (0, 0):
            item["need"] = list(runtime.need)
        if element.role in (*VALUE_ROLES, "command"):
            item["min"], item["max"] = int(element.minimum), int(element.maximum)
            if element.broadcast is not None:
                item["broadcast"] = element.broadcast
            item.update(_scalar_extras(element.flags, element.bits, None))
        if element.wire:  # the codes sent as an expression of them (`code:`): each command's code by the one sent
            item["wire"] = {sent: code for code, sent in element.wire}
        if element.role == "length":
            item["span"] = [runtime.span[0] + 1, runtime.span[1] + 1]
            item["adds"] = runtime.adds  # (an extended length's long form: the marker above its value added)
            if runtime.limits is not None:  # its range: a candidate whose length is outside it is no frame
                item["limits"] = list(runtime.limits)
        if element.checksum is not None:
            item["span"] = [runtime.span[0] + 1, runtime.span[1] + 1]
            item["checksum"] = _checksum(element.checksum)
            if runtime.skip:  # the elements it leaves out, as a set: skip[i] is true
                item["skip"] = {i + 1: True for i in runtime.skip}
            if element.checksum.from_request:  # the request's elements it takes in first (`from_request`)
                item["request"] = list(element.checksum.from_request)
        item["description"] = element.description
        elements.append(item)
    result: dict[str, Any] = {"elements": elements}
    if layout.error:  # its frames are the error reply (an error header)
        result["error"] = True
    t = layout.transparency
    if t is not None and engine.transparency is not None:
        first, last = engine.transparency.span
        lua = t.transform.lua()
        if lua is None:
            raise Unsupported(f"frames with `method: {t.transform.name}`")
        result["transparency"] = {"first": first + 1, "last": last + 1, **lua}
        inner = engine._plan["probe_inner"]  # type: ignore[attr-defined]
        if inner is not None:  # a length of plain bytes within the span (runtime/framing.py _inner_size)
            in_span, at, _, uncounted, counted_fixed = inner
            assert engine.length is not None
            result["inner_length"] = {
                "index": engine.length + 1,
                "in_span": in_span,
                "at": at,
                "uncounted": uncounted,
                "counted_fixed": counted_fixed,
            }
    return result


def _checksum(checksum: Checksum) -> dict[str, Any]:
    """The algorithm and its parameters, for the algorithm's own Lua code (its lua_function, in CHECKSUMS)."""
    algorithm = checksum.algorithm
    if algorithm.lua_function() is None or algorithm.lua_parameters().get("inner", True) is None:
        # an algorithm with no Lua code yet: the dissector shows the value, unverified, and says why
        return {"algorithm": algorithm.name, "unverified": True}
    return {"algorithm": algorithm.name} | algorithm.lua_parameters()


def _wrapped(algorithm: Any) -> list[Any]:
    """The algorithm and those it wraps (a seed around a 7-bit encoding around a CRC): each has its Lua function."""
    found = []
    while algorithm is not None:
        found.append(algorithm)
        algorithm = getattr(algorithm, "inner", None)
    return found


def _checksum_functions(protocol: Protocol) -> list[tuple[str, str]]:
    """(algorithm name as a Lua string, its Lua function) of each algorithm the frames use that has one."""
    found = {
        algorithm.name: code
        for layouts in protocol.framing.alternatives.values()
        for layout in layouts
        for checksum in layout.checksums
        for algorithm in _wrapped(checksum.algorithm)
        if (code := algorithm.lua_function()) is not None
    }
    return [(_lua_name(name), code) for name, code in sorted(found.items())]


def _message(protocol: Protocol, message: Message) -> dict[str, Any]:
    parts = [message.command, message.subcommand, message.direction.value]
    low, high = content_bounds(message.fields)
    result: dict[str, Any] = {
        "command": message.command,
        "subcommand": message.subcommand,
        "title": message.title,
        "prefix": ".".join([protocol.name, *(p for p in parts if p)]),
        "fields": _fields(message.fields),
        "min": low,
        "max": high,
    }
    terms = size_terms(message.fields)
    if terms is not None:
        fixed, sized = terms
        result["size"] = {"fixed": fixed, "terms": [[o + 1, s, e == "big", f] for o, s, e, f in sized]}
    if message.error_reply and protocol.error_reply is not None:
        result["refused"] = protocol.error_reply.element
    if message.padded is not None:  # truncate: trailing_zeros
        result["padded"] = message.padded
    if message.direction == Direction.REQUEST and protocol.framing.by_request(Direction.RESPONSE):
        replies = replies_by_request(protocol.messages())
        reply = reply_to(message, replies)
        if reply is not None:  # the reply it gets (in `answers`), where replies are read with their request
            result["answer"] = reply.key
        refusals = [r.key for r in refusals_of(message, replies)]
        if refusals:  # the replies that refuse it instead (`refused_by`), each maybe in a layout of its own
            result["refusals"] = refusals
    return result


def _count(count: Count | None) -> int | str | Ref | None:
    """A count or size as the engine reads it: a number, `rest`, a field's name, or a function of the fields read
    (an expression: lang/counts.py)."""
    if not isinstance(count, Counted):
        return count
    function = counts.lua_function(count)
    assert function is not None  # refused: counts.lua_refusal
    return Ref(function)


def _fields(fields: tuple[Field, ...]) -> list[dict[str, Any]]:
    tails, tail = [], 0  # the fewest bytes after each field: the later fields' smallest sizes, summed from the end
    for item in reversed(fields):
        tails.append(tail)
        tail += content_bounds((item,))[0]
    return [_field(item, tail) for item, tail in zip(fields, reversed(tails), strict=True)]


def _field(item: Field, tail: int) -> dict[str, Any]:
    """One field as the engine reads it; `tail`: the fewest bytes the fields after it take (for `rest`)."""
    common: dict[str, Any] = {"name": item.name, "description": item.description, "tail": tail}
    match item:
        case Scalar():
            unit = engineering_unit(item.unit, item.scale)
            common.update(kind="scalar", type=item.type.name, big=item.endian == ">", unit=unit, scale=item.scale)
            common["offset"] = item.offset
            common.update(_scalar_extras(item.flags, item.bits, item.enum), hidden=item.hidden)
            common["sign_magnitude"] = item.sign_magnitude
            if item.low_bits is not None:  # a few bits a byte (absent: nil, false to the engine)
                common["low_bits"] = item.low_bits.lua_field(item.type.signed)
            if (place := item.bit_place) is not None:  # a member of a bit run (encodings/bit_run.py)
                common.update(bit_run.lua_field(place.bits, place.shift, place.size, item.type.signed))
        case Varint():  # as many bytes as the value needs (encodings/varint.py)
            common.update(kind="varint", bits=item.bits, sign=item.sign or None, high_first=item.high_first or None)
            common.update(most=item.most_bytes, signed=item.type.signed, minimum=item.minimum, maximum=item.maximum)
            common["unit"] = item.unit
        case Array():
            common.update(kind="list", type=item.item.name, big=item.endian == ">", count=item.count, unit=item.unit)
        case List():
            common.update(kind="list", type=item.item.name if item.item else "bit", big=item.endian == ">")
            common.update(count=_count(item.count) or None, size=item.size or None, unit=item.unit)
        case Packed():
            common.update(kind="packed", bits=item.bits, count=item.count, lsb_first=item.lsb_first, unit=item.unit)
            common["signed"] = item.signed
        case Text():
            common.update(kind="text", size=_count(item.size), pad=item.pad)
            if item.seven_bit:  # 14-bit characters (absent: nil to the engine)
                common["seven_bit"] = True
        case Bytes():
            common.update(kind="bytes", size=_count(item.size))
        case Group():
            common.update(kind="group", count=_count(item.count), fields=_fields(item.fields))
        case TableValue():
            common.update(kind="table_value", key=item.key, entries=Ref(f"TABLES[{_lua_name(item.table.name)}]"))
        case TableBlock():
            table = Ref(f"TABLES[{_lua_name(item.table.name)}]")
            common.update(kind="table_block", table=table, keys=[e.key for e in item.entries], big=item.endian == ">")
        case _:
            assert_never(item)
    return common


def _scalar_extras(flags: FlagsDef | None, bits: tuple[BitField, ...], enum: EnumDef | None) -> dict[str, Any]:
    extras: dict[str, Any] = {}
    if enum is not None:
        extras["enum"] = _enum(enum)
    if flags is not None:
        extras["flags"] = [{"name": b.name.lower(), "bit": b.bit, "description": b.text} for b in flags.bits]
    if bits:
        extras["bits"] = [
            {
                "name": b.name,
                "high": b.high,
                "low": b.low,
                "enum": _enum(b.enum),
                "description": b.description,
                "const": b.const,
            }
            for b in bits
        ]
    return extras


def _entry(entry: TableEntry) -> dict[str, Any]:
    return {
        "name": entry.name,
        "type": entry.type.name,
        "unit": engineering_unit(entry.unit, entry.scale),
        "scale": entry.scale,
        "description": entry.description,
        "sign_magnitude": entry.sign_magnitude,
        **_scalar_extras(entry.flags, (), entry.enum),
    }


def _enum(enum: EnumDef | None) -> Ref | dict[int, str] | None:
    return None if enum is None else Ref(f"ENUMS[{_lua_name(enum.name)}]")


def _enum_values(enum: EnumDef) -> dict[int, str]:
    return {v.value: v.name.lower() for v in enum.values}


def _lua_name(name: str) -> str:
    return _lua_string(name.encode("utf-8"))


def lua(value: object, depth: int) -> str:
    """A Lua literal of a value made of dicts, lists, text, bytes, numbers, booleans and None (nil)."""
    pad = "  " * (depth + 1)
    match value:
        case None:
            return "nil"
        case Ref():
            return value.expression
        case bool():
            return "true" if value else "false"
        case int():
            return str(value)
        case float():
            return repr(value)
        case str():
            return _lua_string(value.encode("utf-8"))
        case bytes():
            return _lua_string(value)
        case list() | tuple():
            if not value:
                return "{}"
            items = [lua(v, depth + 1) for v in value]
            if all("\n" not in i for i in items) and sum(len(i) for i in items) < 80:
                return "{" + ", ".join(items) + "}"
            return "{\n" + "".join(f"{pad}{i},\n" for i in items) + "  " * depth + "}"
        case dict():
            entries = []
            for key, item in value.items():
                if item is None:
                    continue
                name = (
                    key if isinstance(key, str) and key.isidentifier() and key not in _KEYWORDS else f"[{lua(key, 0)}]"
                )
                entries.append(f"{name} = {lua(item, depth + 1)}")
            if not entries:
                return "{}"
            if all("\n" not in e for e in entries) and sum(len(e) for e in entries) < 80:
                return "{" + ", ".join(entries) + "}"
            return "{\n" + "".join(f"{pad}{e},\n" for e in entries) + "  " * depth + "}"
    raise TypeError(f"no Lua literal for {value!r}")


_KEYWORDS = frozenset(
    [
        "and",
        "break",
        "do",
        "else",
        "elseif",
        "end",
        "false",
        "for",
        "function",
        "goto",
        "if",
        "in",
        "local",
        "nil",
        "not",
        "or",
        "repeat",
        "return",
        "then",
        "true",
        "until",
        "while",
    ]
)


def _lua_string(data: bytes) -> str:
    out = []
    for byte in data:
        char = chr(byte)
        if char in '"\\':
            out.append("\\" + char)
        elif 0x20 <= byte < 0x7F:
            out.append(char)
        else:
            out.append(f"\\x{byte:02x}")
    return '"' + "".join(out) + '"'
