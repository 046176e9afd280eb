"""The codec's frames when they are not of the classic shape: data for the runtime's general frame engine.

Classic frames (a header, a one-byte length, one final checksum, no stuffing) get straight-line code (see
package.py); every other framing is described here as `serialspec.runtime.framing` objects: the layouts of each
direction, the content size bounds by command, and size rules for frames that carry no length. The stream parser
runs on them; single frames are checked and built by straight-line code written from the same layouts
(the other modules of this package).
"""

from __future__ import annotations

from collections.abc import Iterable

from serialspec.backends.common.frames import layout_codes, layout_index, runtime_element
from serialspec.backends.common.pairing import layout_refusals
from serialspec.backends.python.checksum_code import checksum_name
from serialspec.backends.python.dispatch import ERROR_REPLY
from serialspec.checksums.base import Import
from serialspec.lang.model import (
    Bytes,
    Direction,
    Discriminator,
    FrameElement,
    FrameLayout,
    Message,
    Protocol,
    fixed_size,
    nul_ended,
    size_terms,
)
from serialspec.lang.names import python_name
from serialspec.transforms import runtime_classes

# runtime.framing's classes (each transform's runtime class among them), in the order isort wants
FRAMING_NAMES = tuple(sorted(("Element", "FrameCodec", "Layout", "SizeRule", *runtime_classes())))


def checksum_definitions(protocol: Protocol, straight: bool = True) -> tuple[list[str], list[str]]:
    """The import lines and module-level definitions of every checksum the layouts use: its runtime function (the
    engine's elements call it) and, for `straight` code, what its expression needs (checksum_code.checksum_call)."""
    imports: set[Import] = set()
    definitions: dict[str, str] = {}
    for layouts in protocol.framing.alternatives.values():
        for layout in layouts:
            for checksum in layout.checksums:
                name = checksum_name(checksum)
                _, call = checksum.algorithm.function_code()
                title = checksum.algorithm.title()
                imports.update(checksum.algorithm.function_imports())
                definitions[name] = f"{name}: Callable[[bytes], int] = {call}" + (f"  # {title}" if title else "")
                extra_imports, extra = checksum.algorithm.python_setup(name) if straight else ([], [])
                imports.update(extra_imports)
                definitions |= {line: line for line in extra if line != definitions[name]}
    return import_lines(imports), list(definitions.values())


def import_lines(imports: Iterable[Import]) -> list[str]:
    """`from module import name` lines, as ruff's isort orders them: by module, then the plain names of a module
    on one line before or after each aliased one by name."""
    by_module: dict[str, list[str]] = {}
    for module, name in sorted(set(imports)):
        by_module.setdefault(module, []).append(name)
    lines = []
    for module, names in sorted(by_module.items()):
        plain = sorted(n for n in names if " as " not in n)
        statements = [[n] for n in sorted(n for n in names if " as " in n)]
        if plain:
            statements.append(plain)
        for group in sorted(statements, key=lambda g: g[0]):
            lines.append(f"from {module} import {', '.join(group)}")
    return lines


def element_expr(layout: FrameLayout, element: FrameElement) -> str:
    """`Element(...)`: the engine's element (backends/common/frames.py) printed, its checksum by name."""
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
    if e.fixed:
        args += [f"need=({e.need[0]:#x}, {e.need[1]:#x})", f"fixed={e.fixed!r}"]
    if e.limits is not None:
        args.append(f"limits={e.limits}")
    if e.wire:
        pairs = ", ".join(f"({code:#04x}, {sent:#04x})" for code, sent in e.wire)
        args.append(f"wire=({pairs}{',' if len(e.wire) == 1 else ''})")
    if e.kind in ("length", "checksum"):
        args.append(f"span={e.span}")
    if e.kind == "optional":
        args += [f"flag={e.flag}", f"mask={e.mask:#04x}"]
    if e.adds:
        args.append(f"adds={e.adds}")
    if e.extended is not None:
        args.append(f"extended={e.extended}")
    if e.kind == "checksum":
        assert element.checksum is not None
        args.append(f"checksum={checksum_name(element.checksum)}")
        if e.skip:
            args.append(f"skip={e.skip}")
        if e.request:
            args.append(f"request={e.request}")
    return f"Element({', '.join(args)})"


def layout_lines(layout: FrameLayout, codes: tuple[int, ...] | None = None) -> list[str]:
    """`Layout(...)` of one layout, as lines (indented by the caller); `codes`: the codes sent in it."""
    lines = [f"Layout({(layout.name or layout.direction.value)!r}, ("]
    lines += [f"    {element_expr(layout, e)}," for e in layout.elements]
    shown = ", ".join(f"{c:#04x}" for c in codes or ()) + ("," if codes is not None and len(codes) == 1 else "")
    end = f"), codes=({shown}))," if codes is not None else "), error=True)," if layout.error else ")),"
    if layout.transparency is None:
        lines.append(end)
        return lines
    t = layout.transparency
    lines.append(f"), {t.transform.runtime_name}(")
    lines += [
        f"    {argument}," for argument in t.transform.python_arguments((layout.index(t.first), layout.index(t.last)))
    ]
    lines.append(end)
    return lines


def size_rule(sizing: Message | Discriminator) -> str | None:
    """`SizeRule(...)` for a message whose content size follows from its fields (model.size_terms), or for
    messages picked by a leading constant, each sized so (model.sizing_lead); None otherwise."""
    if isinstance(sizing, Discriminator):
        picks = [(low, high, size_rule(m)) for low, high, m in sizing.ranges()]
        shown = ", ".join(f"({low:#x}, {high:#x}, {rule})" for low, high, rule in picks)
        lead = f"({sizing.size}, {sizing.endian!r}, {sizing.shift}, {sizing.mask:#x})"
        return f"SizeRule(0, lead={lead}, picks=({shown},))"
    message = sizing
    found = size_terms(message.fields)
    text = nul_ended(message.fields)
    *before, last = message.fields or (None,)
    if isinstance(last, Bytes) and last.size_from and all(fixed_size(f) is not None for f in before):
        # a reply's last bytes, as many as the request's field says (`size_from`): sized with that request
        fixed = sum(fixed_size(f) or 0 for f in before) + last.size_from_adds
        return f"SizeRule({fixed}, request={python_name(last.size_from)!r})"
    if found is None and text is not None:
        return f"SizeRule({text}, nul={text})"
    if found is None:
        return None
    fixed, terms = found
    if not terms:
        return f"SizeRule({fixed})"
    shown = ", ".join(f"({offset}, {size}, {endian!r}, {factor})" for offset, size, endian, factor in terms)
    return f"SizeRule({fixed}, ({shown},))"


def codec_lines(
    protocol: Protocol,
    direction: Direction,
    sizes: list[tuple[str, int, int | None]],
    messages: dict[str, Message | Discriminator],
) -> tuple[list[str], set[str]]:
    """`_<DIRECTION>_FRAMES = FrameCodec(...)`: the layouts, content sizes by code and, without a length, size
    rules by code (`messages`: the one message of each code, where there is one); and the runtime.framing names
    the lines use."""
    layouts = protocol.framing.alternatives[direction]
    names = {"FrameCodec", "Layout", "Element"}
    lines = [f"_{direction.name}_FRAMES = FrameCodec(", "    ("]
    for layout in layouts:
        lines += [f"        {line}" for line in layout_lines(layout, layout_codes(protocol, layout))]
        names |= {layout.transparency.transform.runtime_name} if layout.transparency is not None else set()
    lines.append("    ),")
    # content size bounds by command code (None: unbounded)
    lines.append("    {")
    lines += [f"        {code}: ({low}, {high})," for code, low, high in sizes]
    lines.append("    },")
    codes = [code for code, _, _ in sizes]
    if any(layout.length is None for layout in layouts):
        rules = [(code, rule) for code, message in messages.items() if (rule := size_rule(message))]
        lines.append("    {" + ", ".join(f"{code}: {rule}" for code, rule in rules) + "},")
        names |= {"SizeRule"} if rules else set()
        codes += [code for code, _ in rules]
    names |= {ERROR_REPLY} if ERROR_REPLY in codes else set()
    error = protocol.error_reply
    if error is not None and direction == Direction.RESPONSE and error.flag:
        lines.append(f"    error_flag={error.flag:#04x},")
    if error is not None and direction == Direction.RESPONSE and error.status:
        lines.append(f"    error_status=({error.status!r}, {error.bits:#04x}),")
    if protocol.framing.partial_values(direction):  # a frame value some layout does not carry: None there
        lines.append("    partial=True,")
    if protocol.framing.by_request(direction):  # each reply class's layout: read with the request's reply class
        lines.append("    replies={")
        lines += [
            f"        {m.class_name!r}: {layout_index(protocol, m)},"
            for m in protocol.messages()
            if m.direction == direction
        ]
        lines.append("    },")
        refusing = reply_refusals(protocol)
        if refusing:
            lines.append("    refusals={")
            lines += [f"        {name!r}: {tuple(others)!r}," for name, others in refusing.items()]
            lines.append("    },")
    return [*lines, ")"], names


def reply_refusals(protocol: Protocol) -> dict[str, tuple[str, ...]]:
    """The FrameCodec's `refusals`: reply class name -> the class names of the replies refusing its request in a
    layout of their own (see layout_refusals)."""
    return {reply.class_name: tuple(m.class_name for m in others) for reply, others in layout_refusals(protocol)}


def framing_imports(names: Iterable[str]) -> list[str]:
    """The runtime.framing names of an import line, in the order isort wants."""
    used = set(names)
    assert used <= {ERROR_REPLY, *FRAMING_NAMES}, used
    return [name for name in (ERROR_REPLY, *FRAMING_NAMES) if name in used]
