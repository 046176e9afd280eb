"""Emit construct structs: each frame, each command's content in each direction, parameter values, blocks.

construct is the declarative reference the fast codec is tested against; it is not on the hot path.
"""

from __future__ import annotations

from serialspec.backends.python.frames.engine import checksum_definitions, codec_lines, framing_imports, import_lines
from serialspec.backends.python.kinds import derived_checks, kind, primitive
from serialspec.backends.python.render import one_line, render
from serialspec.lang.model import (
    Direction,
    Field,
    FrameLayout,
    Protocol,
    ScalarType,
    TableBlock,
)


def field_expr(f: Field, parent: str = "this") -> str:
    """The construct expression of a field; `parent` is "item" inside a group item."""
    return kind(f).construct(f, parent)


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
    # a function of the context, not `this.body.data[a:b]`: construct's typed stubs (construct-typing) index a path
    # by name only
    covered = f"lambda ctx: ctx.body.data[{layout.covered_from}:{-trim if trim else ''}]"
    return (
        f"Struct('body' / RawCopy(Struct({', '.join(body)})), "
        f"'{checksum.name}' / Checksum({primitive(checksum.type, '<')}, _checksum, {covered}))"
    )


def structs_module(protocol: Protocol) -> str:
    contents = []
    for message in protocol.messages():
        fields = [f"{f.name!r} / {field_expr(f)}" for f in message.fields] + derived_checks(message.fields)
        contents.append(
            {
                "name": message.struct_name,
                "fields": fields,
                "key": message.key,
                "direction": message.direction.value,
                "padded": message.padded,
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
    names: set[str] = set()  # the runtime.framing names the definitions use
    if framing.classic:
        checksum = framing.checksum
        assert checksum is not None
        _, call = checksum.algorithm.function_code()
        definitions.append(f"_checksum = {call}")
        checksum_imports = import_lines(checksum.algorithm.function_imports())
        frames = [{"name": f"{d.name}_FRAME", "expr": frame_expr(layout)} for d, layout in framing.layouts.items()]
    else:
        checksum_imports, definitions = checksum_definitions(protocol, straight=False)
        for direction in Direction:
            lines, used = codec_lines(protocol, direction, [], {})
            definitions += ["", *lines]
            names |= used
        # replies read with their request (layouts chosen by command, a checksum over request bytes): its frames'
        requests = protocol.framing.requesting
        asked = {d: ", _REQUEST_FRAMES" if requests and d == Direction.RESPONSE else "" for d in Direction}
        frames = [{"name": f"{d.name}_FRAME", "expr": f"Framed(_{d.name}_FRAMES{asked[d]})"} for d in Direction]
    return render(
        "structs.py.j2",
        spec_path=one_line(protocol.spec_path),
        title=one_line(protocol.title),
        contents=contents,
        tables=tables,
        blocks=blocks,
        frames=frames,
        definitions=definitions,
        checksum_imports=checksum_imports,
        framing_imports=framing_imports(names),
        classic=framing.classic,
    )


def field_expr_entry(scalar: ScalarType, sign_bit: int | None, endian: str = "<") -> str:
    """A table entry's construct: plain, or sign-magnitude with the sign in `sign_bit`."""
    base = primitive(scalar, endian)
    return f"SignMagnitude({base}, {sign_bit + 1})" if sign_bit is not None else base
