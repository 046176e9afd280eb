"""The model's frame layouts as the runtime's frame engine objects, for every emitter.

The Python codec prints them as code; the markdown emitter runs them over example frames (to show stuffed frames
byte by byte). One mapping from model to engine, so the two cannot disagree.
"""

from __future__ import annotations

from serialspec.lang.model import Direction, FrameElement, FrameLayout, Protocol
from serialspec.runtime.framing import Element, ElementKind, Layout

KINDS: dict[str, ElementKind] = {
    "header": "constant",
    "trailer": "constant",
    "constant": "constant",
    "address": "value",
    "status": "value",
    "command": "command",
    "length": "length",
    "content": "content",
    "checksum": "checksum",
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
        also=element.broadcast if kind in ("value", "command") else None,
        skip=skip,
    )


def runtime_layout(layout: FrameLayout) -> Layout:
    t = layout.transparency
    transparency = t.transform.runtime((layout.index(t.first), layout.index(t.last))) if t else None
    elements = tuple(runtime_element(layout, e) for e in layout.elements)
    return Layout(layout.name or layout.direction.value, elements, transparency)


def runtime_layouts(protocol: Protocol, direction: Direction) -> tuple[Layout, ...]:
    return tuple(runtime_layout(layout) for layout in protocol.framing.alternatives[direction])
