"""Emit construct structs: each frame, each command's content in each direction, parameter values, blocks.

construct is the declarative reference the fast codec is tested against; it is not on the hot path.
"""

from __future__ import annotations

from serialspec.emit.python.frames import checksum_definitions, codec_lines, framing_imports
from serialspec.emit.python.pycode import one_line
from serialspec.emit.python.render import render
from serialspec.spec import expression
from serialspec.spec.model import (
    Array,
    Bytes,
    Direction,
    Field,
    FrameLayout,
    Group,
    List,
    Protocol,
    Scalar,
    ScalarType,
    TableBlock,
    TableValue,
    Text,
)

_INT = {1: "Int8", 2: "Int16", 4: "Int32"}


def primitive(scalar: ScalarType, endian: str) -> str:
    suffix = "b" if endian == ">" else "l"
    if scalar.is_float:
        return f"Float32{suffix}"
    if scalar.size == 1:
        return "Int8sb" if scalar.signed else "Int8ub"
    return f"{_INT[scalar.size]}{'s' if scalar.signed else 'u'}{suffix}"


def field_expr(f: Field, parent: str = "this") -> str:
    if isinstance(f, Scalar):
        base = primitive(f.type, f.endian)
        if f.const is not None:
            return f"Const({f.const}, {base})"
        if f.value is not None:
            return f"Rebuild({base}, lambda ctx: {expression.render(f.value, lambda name: f'ctx[{name!r}]')})"
        if f.derived:
            kind, target = f.derived[0], f.derived[1]
            if kind == "count":
                return f"Rebuild({base}, len_(this.{target}))"
            # evaluated while building: a lambda, so the context is the one being built, not `this` itself
            return f"Rebuild({base}, lambda ctx: _item_size(ctx, {target!r}))"
        if f.bits:
            return bits_expr(f)
        if f.sign_magnitude:
            return f"SignMagnitude({base}, {f.type.size * 8})"
        return base
    if isinstance(f, Array):
        return f"Array({f.count}, {primitive(f.item, f.endian)})"
    if isinstance(f, List):
        return list_expr(f)
    if isinstance(f, Text):
        if f.size is None:
            return "CString('utf8')"
        if f.size == "rest":
            return "Utf8(GreedyBytes)"
        return f"Utf8(Bytes({f.size if isinstance(f.size, int) else 'this.' + f.size}))"
    if isinstance(f, Bytes):
        if f.size == "rest":
            return "GreedyBytes"
        if isinstance(f.size, int):
            return f"Bytes({f.size})"
        # inside a group item the size field sits beside the bytes (BULK WRITE) or in the enclosing content (this._)
        return f"Bytes({'this._' if parent == 'item' else 'this'}.{f.size})"
    if isinstance(f, Group):
        names = {i.name for i in f.fields}
        item = (
            "Struct("
            + ", ".join(
                f"{i.name!r} / {field_expr(i, 'this' if isinstance(i, Bytes) and i.size in names else 'item')}"
                for i in f.fields
            )
            + ")"
        )
        if f.count == "rest":
            return f"GreedyRange({item})"
        count = f.count if isinstance(f.count, int) else f"this.{f.count}"
        return f"Array({count}, {item})"
    if isinstance(f, TableValue):
        return f"Switch(this.{f.key}, {f.table.value_constant})"
    assert isinstance(f, TableBlock)
    return f.struct_name


def list_expr(f: List) -> str:
    """An array whose count varies, or packed bits."""
    count = f"this.{f.count}" if isinstance(f.count, str) and f.count not in ("", "rest") else f.count
    if f.item is None:
        if f.size:
            return f"PackedBits(Bytes(this.{f.size}))"
        if f.count == "rest":
            return "PackedBits(GreedyBytes)"
        return f"PackedBits(Bytes(({count} + 7) // 8), {count})"
    item = primitive(f.item, f.endian)
    if f.size:
        return f"Array(this.{f.size} // {f.item.size}, {item})"
    if f.count == "rest":
        return f"GreedyRange({item})"
    return f"Array({count}, {item})"


def bits_expr(f: Scalar) -> str:
    """A BitStruct from the most significant bit down; unlisted bits are constant zero."""
    width = f.type.size * 8
    parts = []
    bit = width - 1
    for field in sorted(f.bits, key=lambda b: -b.high):
        if bit > field.high:
            parts.append(f"'_unused_{bit}' / Const(0, BitsInteger({bit - field.high}))")
        parts.append(f"{field.name!r} / BitsInteger({field.high - field.low + 1})")
        bit = field.low - 1
    if bit >= 0:
        parts.append(f"'_unused_{bit}' / Const(0, BitsInteger({bit + 1}))")
    inner = "BitStruct(" + ", ".join(parts) + ")"
    return f"ByteSwapped({inner})" if f.type.size > 1 and f.endian == "<" else inner


def frame_expr(layout: FrameLayout) -> str:
    body = []
    adds = layout.length_adds
    for element in layout.elements:
        if element.role == "header":
            body.append(f"'{element.name}' / Const({layout.header!r})")
        elif element.role == "length":
            assert element.type is not None
            size = f"len_(this.content) + {adds}" if adds else "len_(this.content)"
            body.append(f"'{element.name}' / Rebuild({primitive(element.type, '<')}, {size})")
        elif element.role == "content":
            length = next(e.name for e in layout.elements if e.role == "length")
            body.append(f"'content' / Bytes(this.{length}{f' - {adds}' if adds else ''})")
        elif element.role != "checksum":
            assert element.type is not None
            body.append(f"'{element.name}' / {primitive(element.type, '<')}")
    checksum = next(e for e in layout.elements if e.role == "checksum")
    assert checksum.type is not None
    trim = layout.covered_to_end - layout.checksum_offset_from_end
    covered = f"this.body.data[{layout.covered_from}:{-trim if trim else ''}]"
    return (
        f"Struct('body' / RawCopy(Struct({', '.join(body)})), "
        f"'{checksum.name}' / Checksum({primitive(checksum.type, '<')}, _checksum, {covered}))"
    )


def structs_module(protocol: Protocol) -> str:
    contents = []
    for message in protocol.messages():
        fields = [f"{f.name!r} / {field_expr(f)}" for f in message.fields]
        contents.append(
            {
                "name": message.struct_name,
                "fields": fields,
                "key": message.key,
                "direction": message.direction.value,
            }
        )
    tables = [
        {
            "name": t.value_constant,
            "entries": [(e.key, field_expr_entry(e.type, e.sign_bit)) for e in t.entries if not e.reserved],
        }
        for t in protocol.tables
    ]
    blocks = {}
    for message in protocol.messages():
        for f in message.fields:
            if isinstance(f, TableBlock):
                blocks[f.struct_name] = [
                    f"{e.name!r} / {field_expr_entry(e.type, e.sign_bit, f.endian)}" for e in f.entries
                ]
    framing = protocol.framing
    definitions: list[str] = []
    if framing.classic:
        checksum = framing.checksum
        assert checksum is not None
        if checksum.algorithm == "crc":
            assert checksum.crc is not None
            c = checksum.crc
            checksum_expr = f"crc_function({c.width}, {c.poly:#x}, {c.init:#x}, {c.refin}, {c.refout}, {c.xorout:#x})"
        else:
            checksum_expr = f"sum_function({checksum.type.size * 8}, invert={checksum.invert})"
        definitions.append(f"_checksum = {checksum_expr}")
        checksum_imports = ["crc_function" if checksum.algorithm == "crc" else "sum_function"]
        frames = [{"name": f"{d.name}_FRAME", "expr": frame_expr(layout)} for d, layout in framing.layouts.items()]
    else:
        checksum_imports, definitions = checksum_definitions(protocol)
        for direction in Direction:
            definitions += ["", *codec_lines(protocol, direction, [], {})]
        frames = [{"name": f"{d.name}_FRAME", "expr": f"Framed(_{d.name}_FRAMES)"} for d in Direction]
    return render(
        "structs.py.j2",
        spec_path=protocol.spec_path,
        title=one_line(protocol.title),
        contents=contents,
        tables=tables,
        blocks=blocks,
        frames=frames,
        definitions=definitions,
        checksum_imports=checksum_imports,
        framing_imports=framing_imports(definitions),
        classic=framing.classic,
    )


def field_expr_entry(scalar: ScalarType, sign_bit: int | None, endian: str = "<") -> str:
    """A table entry's construct: plain, or sign-magnitude with the sign in `sign_bit`."""
    base = primitive(scalar, endian)
    return f"SignMagnitude({base}, {sign_bit + 1})" if sign_bit is not None else base
