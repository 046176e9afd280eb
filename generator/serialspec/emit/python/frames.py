"""The codec's frames when they are not of the classic shape: data for the runtime's general frame engine.

Classic frames (a header, a one-byte length, one final checksum, no stuffing) get straight-line code (see
package.py); every other framing is described here as `serialspec.runtime.framing` objects: the layouts of each
direction, the content size bounds by command, and size rules for frames that carry no length.
"""

from __future__ import annotations

from serialspec.emit.common.frames import runtime_element
from serialspec.emit.python.pycode import one_line
from serialspec.spec.model import (
    Bytes,
    Checksum,
    Command,
    Direction,
    FrameElement,
    FrameLayout,
    Group,
    Message,
    Protocol,
    Scalar,
    fixed_size,
)


def checksum_name(checksum: Checksum) -> str:
    return f"_CHECK_{checksum.name.upper()}"


def checksum_definitions(protocol: Protocol) -> tuple[list[str], list[str]]:
    """The runtime imports and module-level definitions of every checksum function the layouts use."""
    imports: set[str] = set()
    definitions: dict[str, str] = {}
    for layouts in protocol.framing.alternatives.values():
        for layout in layouts:
            for checksum in layout.checksums:
                width = checksum.type.size * 8
                if checksum.algorithm == "crc":
                    crc = checksum.crc
                    assert crc is not None
                    imports.add("crc_function")
                    value = (
                        f"crc_function({crc.width}, {crc.poly:#x}, {crc.init:#x}, {crc.refin}, {crc.refout}, "
                        f"{crc.xorout:#x})  # {one_line(crc.name)}"
                    )
                elif checksum.algorithm == "xor":
                    imports.add("xor_function")
                    value = f"xor_function({width})"
                else:
                    imports.add("sum_function")
                    value = f"sum_function({width}, {checksum.invert})"
                definitions[checksum_name(checksum)] = f"{checksum_name(checksum)}: Callable[[bytes], int] = {value}"
    return sorted(imports), [definitions[name] for name in sorted(definitions)]


def element_expr(layout: FrameLayout, element: FrameElement) -> str:
    """`Element(...)`: the engine's element (emit/common/frames.py) printed, its checksum by name."""
    e = runtime_element(layout, element)
    args = [repr(e.name), repr(e.kind)]
    if e.kind != "content":
        args.append(str(e.size))
    if e.endian == "big" and e.size > 1:
        args.append("endian='big'")
    if e.kind == "constant":
        args.append(f"constant={e.constant!r}")
    if e.kind in ("value", "command"):
        args += [f"minimum={e.minimum}", f"maximum={e.maximum}"]
        if e.also is not None:
            args.append(f"also={e.also}")
    if e.kind in ("length", "checksum"):
        args.append(f"span={e.span}")
    if e.adds:
        args.append(f"adds={e.adds}")
    if e.kind == "checksum":
        assert element.checksum is not None
        args.append(f"checksum={checksum_name(element.checksum)}")
    return f"Element({', '.join(args)})"


def layout_lines(layout: FrameLayout) -> list[str]:
    """`Layout(...)` of one layout, as lines (indented by the caller)."""
    lines = [f"Layout({(layout.name or layout.direction.value)!r}, ("]
    lines += [f"    {element_expr(layout, e)}," for e in layout.elements]
    if layout.transparency is None:
        lines.append(")),")
        return lines
    t = layout.transparency
    pairs = ", ".join(f"({plain!r}, {wire!r})" for plain, wire in t.replace)
    lines.append("), Transparency(")
    lines.append(f"    ({layout.index(t.first)}, {layout.index(t.last)}),")
    lines.append(f"    ({pairs},),")
    lines.append(")),")
    return lines


def size_rule(message: Message) -> str | None:
    """`SizeRule(...)` for a message whose content size follows from its fields, or None (`rest`, tables)."""
    fixed = 0
    offset: int | None = 0
    offsets: dict[str, int] = {}
    terms: list[str] = []
    for field in message.fields:
        size = fixed_size(field)
        if offset is not None:
            offsets[field.name] = offset
        if size is not None:
            fixed += size
            offset = None if offset is None else offset + size
            continue
        counter = ""
        factor: int | None = None
        if isinstance(field, Bytes) and isinstance(field.size, str) and field.size != "rest":
            counter, factor = field.size, 1
        elif isinstance(field, Group) and isinstance(field.count, str) and field.count != "rest":
            counter, factor = field.count, field.item_size
        counted = next((f for f in message.fields if f.name == counter), None)
        if factor is None or counter not in offsets or not isinstance(counted, Scalar):
            return None
        endian = "'big'" if counted.endian == ">" else "'little'"
        terms.append(f"({offsets[counter]}, {counted.type.size}, {endian}, {factor})")
        offset = None
    if not terms:
        return f"SizeRule({fixed})"
    return f"SizeRule({fixed}, ({', '.join(terms)},))"


def codec_lines(
    protocol: Protocol,
    direction: Direction,
    sizes: list[tuple[str, int, int | None]],
    messages: dict[str, Message],
) -> list[str]:
    """`_<DIRECTION>_FRAMES = FrameCodec(...)`: the layouts, content sizes by code and, without a length, size
    rules by code (`messages`: the one message of each code, where there is one)."""
    layouts = protocol.framing.alternatives[direction]
    lines = [f"_{direction.name}_FRAMES = FrameCodec(", "    ("]
    for layout in layouts:
        lines += [f"        {line}" for line in layout_lines(layout)]
    lines.append("    ),")
    # content size bounds by command code (None: unbounded)
    lines.append("    {")
    lines += [f"        {code}: ({low}, {high})," for code, low, high in sizes]
    lines.append("    },")
    if any(layout.length is None for layout in layouts):
        rules = [(code, rule) for code, message in messages.items() if (rule := size_rule(message))]
        lines.append("    {" + ", ".join(f"{code}: {rule}" for code, rule in rules) + "},")
    lines.append(")")
    return lines


def code_key(command: Command, layout: FrameLayout) -> str:
    return "None" if command.code is None or not layout.has_command else f"{command.code:#04x}"


def framing_imports(lines: list[str]) -> list[str]:
    """The runtime.framing names that definitions use."""
    text = "\n".join(lines)
    return [name for name in ("Element", "FrameCodec", "Layout", "SizeRule", "Transparency") if f"{name}(" in text]
