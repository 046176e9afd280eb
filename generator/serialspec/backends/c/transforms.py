"""Frame transforms as C: each transform of the registry (serialspec/transforms/) writes its own C (Transform.c_code,
beside its runtime and docs); the frame engine (engine.py) calls them through the dispatch written here, by the
layout table's `has_t`: 0 none, 1 the engine's own substitution (`method: replace`, over the layout's pairs), 2 and
on the protocol's other transforms, in the order its layouts first use them."""

from __future__ import annotations

from serialspec.lang.model import Protocol
from serialspec.transforms import Transform
from serialspec.transforms.base import CTransform
from serialspec.transforms.replace import Replace

SUBSTITUTION = 1  # has_t of `method: replace`: engine.py's table-driven pfx__rewrite


def _used(protocol: Protocol, p: str) -> list[CTransform]:
    """The C of each transform the protocol's layouts use, but substitution (the engine's own), first use first."""
    found: dict[str, CTransform] = {}
    for layouts in protocol.framing.alternatives.values():
        for layout in layouts:
            t = layout.transparency
            if t is None or isinstance(t.transform, Replace):
                continue
            code = t.transform.c_code(p)
            assert code is not None  # emit.refuse_layout refused the spec
            found.setdefault(code.rewrite, code)
    return list(found.values())


def method(protocol: Protocol, p: str, transform: Transform | None) -> int:
    """The layout table's has_t for a layout with this transform (0: none)."""
    if transform is None:
        return 0
    if isinstance(transform, Replace):
        return SUBSTITUTION
    code = transform.c_code(p)
    assert code is not None
    return 2 + [c.rewrite for c in _used(protocol, p)].index(code.rewrite)


def prefixes(protocol: Protocol, p: str) -> bool:
    """Some layout's length inside its span counts plain bytes under a transform of its own C (not substitution):
    the engine reads it through that transform's plain_prefix."""
    from serialspec.backends.c.emit import plain_span

    for layouts in protocol.framing.alternatives.values():
        for layout in layouts:
            t = layout.transparency
            if t is not None and not isinstance(t.transform, Replace) and plain_span(layout):
                return True
    return False


def dispatch(protocol: Protocol, p: str, P: str) -> str:
    """The transforms' C and the engine's two calls into them: p__transform (rewrite the span, either way) and, for
    the parser, p__span_end (where the span ends on the wire: -1 where the transform cannot tell)."""
    used = _used(protocol, p)
    calls = [(i + 2, f"{c.rewrite}(to_wire, src, n, dst, cmp, cap, out)") for i, c in enumerate(used)]
    ends = [(i + 2, f"{c.span_end}(b, start, avail)") for i, c in enumerate(used) if c.span_end]
    rewrite = _switch(calls, ("method", "to_wire", "src", "n", "dst", "cmp", "cap", "out"), "0")
    span_end = _switch(ends, ("method", "b", "start", "avail"), f"{P}__NONE")
    codes = "".join(c.code + "\n" for c in used)
    span_codes = "".join(c.span_code + "\n" for c in used if c.span_end)
    prefix = ""
    if prefixes(protocol, p):
        calls = [
            (i + 2, f"{c.plain_prefix}(b, start, avail, count, from, dst)")
            for i, c in enumerate(used)
            if c.plain_prefix
        ]
        names = ("method", "b", "start", "avail", "count", "from", "dst")
        prefix_codes = "".join(c.prefix_code + "\n" for c in used if c.plain_prefix)
        prefix = f"""
#if {P}_ENABLE_PARSER && {P}__STUFFED
{prefix_codes}/* The wire bytes that give a span's first `count` plain bytes, by its transform (has_t 2..). */
static long {p}__transform_prefix(uint8_t method, const uint8_t *b, size_t start, size_t avail, size_t count,
                                  size_t from, uint8_t *dst)
{{
{_switch(calls, names, f"{P}__NONE")}
}}
#endif
"""
    return f"""{codes}/* The span rewritten by its transform (has_t 2..; each from serialspec/transforms/). */
static int {p}__transform(uint8_t method, int to_wire, const uint8_t *src, size_t n, uint8_t *dst,
                          const uint8_t *cmp, size_t cap, size_t *out)
{{
{rewrite}
}}

#if {P}_ENABLE_PARSER && {P}__STUFFED
{span_codes}/* Where the span that starts at b[start] ends on the wire, for a transform that can tell ({P}__WAIT: not
 * yet); {P}__NONE where it cannot (the frame then ends at its first trailer). */
static long {p}__span_end(uint8_t method, const uint8_t *b, size_t start, size_t avail)
{{
{span_end}
}}
#endif
{prefix}"""


def _switch(cases: list[tuple[int, str]], parameters: tuple[str, ...], otherwise: str) -> str:
    """A switch on `method` returning each case's call, or, with no case, the parameters marked used."""
    if not cases:
        return "".join(f"    (void){name};\n" for name in parameters) + f"    return {otherwise};"
    body = "".join(f"    case {value}u:\n        return {call};\n" for value, call in cases)
    return f"    switch (method) {{\n{body}    default:\n        return {otherwise};\n    }}"
