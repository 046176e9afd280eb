"""The model's frame layouts as the runtime's frame engine objects, for every emitter.

The Python codec prints them as code; the markdown emitter runs them over example frames (to show stuffed frames
byte by byte). One mapping from model to engine, so the two cannot disagree.
"""

from __future__ import annotations

from serialspec.backends import Unsupported
from serialspec.lang.model import (
    Direction,
    FrameElement,
    FrameLayout,
    Message,
    Protocol,
    fixed_bits,
)
from serialspec.runtime.framing import Element, ElementKind, Layout

KINDS: dict[str, ElementKind] = {
    "header": "constant",
    "trailer": "constant",
    "constant": "constant",
    "address": "value",
    "status": "value",
    "value": "value",
    "command": "command",
    "length": "length",
    "content": "content",
    "checksum": "checksum",
    "optional": "optional",
}


def runtime_element(layout: FrameLayout, element: FrameElement) -> Element:
    kind = KINDS[element.role]
    span = (0, 0)
    skip: tuple[int, ...] = ()
    function = None
    if kind == "length":
        span = (layout.index(element.counts[0]), layout.index(element.counts[1]))
    elif kind == "checksum":
        assert element.checksum is not None
        span = (layout.index(element.checksum.first), layout.index(element.checksum.last))
        function = element.checksum.algorithm.function()
        skip = tuple(layout.index(name) for name in element.checksum.skips)
    return Element(
        name=element.name,
        kind=kind,
        size=element.size or 0,
        endian="big" if element.endian == ">" else "little",
        constant=element.constant,
        span=span,
        adds=element.adds,
        checksum=function,
        minimum=int(element.minimum) if kind in ("value", "command") else 0,
        maximum=int(element.maximum) if kind in ("value", "command") else 0,
        also=(  # a broadcast value beside the range (one inside it is no other value)
            element.broadcast
            if kind in ("value", "command")
            and element.broadcast is not None
            and not element.minimum <= element.broadcast <= element.maximum
            else None
        ),
        skip=skip,
        request=element.checksum.from_request if element.checksum is not None else (),
        flag=layout.index(element.present_if[0]) if element.present_if[0] else -1,
        mask=element.present_if[1],
        wire=element.wire,
        limits=length_limits(element) if kind == "length" else None,
        need=fixed_bits(element.bits) if kind == "value" else (0, 0),
        fixed=tuple((b.name, b.low, b.mask, b.const) for b in element.bits if b.const is not None and kind == "value"),
        extended=extended_form(element),
    )


def extended_form(element: FrameElement) -> tuple[int, int, int, int, int, int, int] | None:
    """A length's long form (`extended:`) as the engine's Element holds it (None: the length has none)."""
    x = element.extended
    return None if x is None else (x.marker, x.size, x.adds, *x.short, *x.long)


def length_limits(element: FrameElement) -> tuple[int, int] | None:
    """A length element's `range` where it is narrower than its type's: (low, high); None otherwise."""
    assert element.type is not None
    if (element.minimum, element.maximum) == (element.type.minimum, element.type.maximum):
        return None
    return int(element.minimum), int(element.maximum)


def runtime_layout(layout: FrameLayout, codes: tuple[int, ...] | None = None) -> Layout:
    t = layout.transparency
    transparency = t.transform.runtime((layout.index(t.first), layout.index(t.last))) if t else None
    elements = tuple(runtime_element(layout, e) for e in layout.elements)
    return Layout(layout.name or layout.direction.value, elements, transparency, codes, error=layout.error)


def layout_codes(protocol: Protocol, layout: FrameLayout) -> tuple[int, ...] | None:
    """The command codes sent in a layout, where layouts are chosen by command (`layout:`) and its frames carry
    one, or where its command element is too narrow for some codes (MSP v1's u8 beside v2's u16: those travel in
    a layout that holds them); None otherwise (any code)."""
    if not layout.has_command:
        return None
    if not protocol.framing.by_command:
        return held_codes(protocol, layout)
    codes = set()
    for command in protocol.commands:
        code = command.wire_code(layout.direction)
        for message in command.messages():
            if code is not None and message.direction == layout.direction and protocol.layout(message) == layout:
                codes.add(code)
    return tuple(sorted(codes))


def held_codes(protocol: Protocol, layout: FrameLayout) -> tuple[int, ...] | None:
    """The codes a layout's command element holds, where it does not hold every code of its direction; None
    where it does."""
    element = next(e for e in layout.elements if e.role == "command")
    if element.type is None or element.code or layout.error:  # (an error reply carries the refused request's code)
        return None
    codes = {
        code
        for command in protocol.commands
        if (code := command.wire_code(layout.direction)) is not None
        and any(m.direction == layout.direction for m in command.messages())
    }
    held = {code for code in codes if element.type.minimum <= code <= element.type.maximum}
    return None if held == codes else tuple(sorted(held))


def layout_index(protocol: Protocol, message: Message) -> int:
    """The index of a message's layout among its direction's alternatives."""
    names = [layout.name for layout in protocol.framing.alternatives[message.direction]]
    return names.index(protocol.layout(message).name)


def runtime_layouts(protocol: Protocol, direction: Direction) -> tuple[Layout, ...]:
    return tuple(
        runtime_layout(layout, layout_codes(protocol, layout)) for layout in protocol.framing.alternatives[direction]
    )


def refuse_code_forms(protocol: Protocol, length_byte: bool) -> None:
    """Unsupported for a command element sending an expression of the command's code (`code:`) where the C does not
    translate it: in a transformed layout, in layouts chosen by command, or in frames of the length-byte shape
    (`length_byte`: the C's own parser for them)."""
    for found in protocol.framing.alternatives.values():
        for layout in found:
            if not any(e.code for e in layout.elements if e.role == "command"):
                continue
            if layout.transparency is not None or protocol.framing.by_command or length_byte:
                raise Unsupported(
                    f"a command element sending an expression of the code (`code:`, layout {layout.name}) in a "
                    "layout with a transform, in layouts chosen by command or alone in its direction"
                )


def refuse_partial_values(protocol: Protocol) -> None:
    """Unsupported for a frame value that some alternative layout does not carry (the Pololu form's device number
    beside the compact form): a message holds None for it there, which a C struct's integer cannot."""
    for direction in protocol.framing.alternatives:
        partial = sorted(protocol.framing.partial_values(direction))
        if partial:
            raise Unsupported(
                f"a frame value that some alternative layout does not carry ({', '.join(partial)}, "
                f"{direction.value}s): None in the others"
            )


def optional_elements(protocol: Protocol, direction: Direction) -> tuple[FrameElement, ...]:
    """The optional elements (`present_if`) of a direction's layouts, each once, in element order: every message of
    the direction carries their bytes, or None, after its other fields."""
    found: dict[str, FrameElement] = {}
    for layout in protocol.framing.alternatives.get(direction, ()):
        for element in layout.optional:
            found.setdefault(element.name, element)
    return tuple(found.values())
