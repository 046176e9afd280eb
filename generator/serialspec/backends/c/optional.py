"""Optional frame elements (`present_if`) in C: a layout holding one becomes its plain variants, as
runtime/framing.py's Layout.variants: the element sent (an `extra`: fixed bytes the message gives, its flag bit set)
or left out (the bit clear), the same order. The rest of the C backend sees the variants as the direction's layouts
(the parser sizes candidates in each, as the Python stream parser does); this module keeps what the variants add: the
flag bits a frame must have to be read in one (`conditions`), the bit a value flag element must have in it (`needs`),
and which optional elements each sends (`present`), and writes the C that uses them."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from serialspec.backends.c.emit import Ctx, Member, ident
from serialspec.backends.common.frames import optional_elements
from serialspec.lang.model import SCALARS, Direction, FrameElement, FrameLayout, Protocol
from serialspec.lang.model.framing import VALUE_ROLES

EXTRA = "extra"  # the role of an optional element in a variant that sends it: fixed bytes from the message


@dataclass(frozen=True)
class Variant:
    """One plain layout of a direction: `origin` the index of the spec's layout it comes from."""

    layout: FrameLayout
    origin: int
    present: frozenset[str] = frozenset()
    conditions: tuple[tuple[int, int, bool, int, int], ...] = ()  # (offset, size, big-endian, mask, bits)
    needs: dict[str, tuple[int, int]] = field(default_factory=dict)  # value element: (mask, bits) it must have
    unless: tuple[tuple[int, int], ...] = ()  # (offset, byte) a frame must not have (an extended length's marker)

    @property
    def bit_of(self) -> dict[str, tuple[int, int]]:
        """A value element's need as (bit number + 1, 1 set / 0 clear): what the layout tables hold (masks are one
        bit, the language says so)."""
        return {name: (mask.bit_length(), 1 if bits else 0) for name, (mask, bits) in self.needs.items()}


def _offset(layout: FrameLayout, index: int) -> int:
    return sum(_size(e) for e in layout.elements[:index])


def _size(e: FrameElement) -> int:
    return len(e.constant) if e.fixed else e.size or 0


def split(layout: FrameLayout, origin: int, variant: Variant | None = None) -> tuple[Variant, ...]:
    """The plain variants of a layout: with its first optional element sent, then without, each split further."""
    variant = variant or Variant(layout, origin)
    elements = layout.elements
    k = next((i for i, e in enumerate(elements) if e.role == "optional"), -1)
    if k < 0:
        return extended_forms(variant)
    element = elements[k]
    flag_name, mask = element.present_if
    f = layout.index(flag_name)
    flag = elements[f]
    big = flag.endian == ">"
    condition = (_offset(layout, f), _size(flag), big, mask)
    sent = list(elements)
    sent[k] = replace(element, role=EXTRA)
    needs_set, needs_clear = dict(variant.needs), dict(variant.needs)
    if flag.role == "constant":
        value = int.from_bytes(flag.constant, "big" if big else "little") | mask
        sent[f] = replace(flag, constant=value.to_bytes(len(flag.constant), "big" if big else "little"))
    else:
        needs_set[flag_name] = (mask, mask)
        needs_clear[flag_name] = (mask, 0)
    left = elements[:k] + elements[k + 1 :]
    with_it = Variant(
        _plain(layout, tuple(sent)),
        origin,
        variant.present | {element.name},
        (*variant.conditions, (*condition, mask)),
        needs_set,
    )
    without = Variant(
        _plain(layout, left), origin, variant.present, (*variant.conditions, (*condition, 0)), needs_clear
    )
    return (*split(with_it.layout, origin, with_it), *split(without.layout, origin, without))


def extended_forms(variant: Variant) -> tuple[Variant, ...]:
    """A layout whose length has a long form (`extended:`) as its two plain layouts, as runtime/framing.py's
    Layout._extended: the one-byte form (not read where the marker byte is), then the long form as one big-endian
    length of 1 + wider size bytes, the marker shifted above its value in its adds and range."""
    layout = variant.layout
    k = next((i for i, e in enumerate(layout.elements) if e.role == "length" and e.extended is not None), -1)
    if k < 0:
        return (variant,)
    element = layout.elements[k]
    x = element.extended
    assert x is not None and element.type is not None
    offset = _offset(layout, k)
    lead = x.marker << 8 * x.size
    short = replace(element, extended=None, minimum=float(x.short[0]), maximum=float(x.short[1]))
    long = replace(
        element,
        extended=None,
        type=SCALARS[f"u{8 * (1 + x.size)}"],
        size=1 + x.size,
        endian=">",
        adds=x.adds + lead,
        minimum=float(lead + x.long[0]),
        maximum=float(lead + x.long[1]),
    )

    def form(each: FrameElement) -> FrameLayout:
        return _plain(layout, (*layout.elements[:k], each, *layout.elements[k + 1 :]))

    return (
        replace(variant, layout=form(short), unless=(*variant.unless, (offset, x.marker))),
        replace(variant, layout=form(long), conditions=(*variant.conditions, (offset, 1, True, 0xFF, x.marker))),
    )


def _plain(layout: FrameLayout, elements: tuple[FrameElement, ...]) -> FrameLayout:
    return replace(
        layout,
        elements=elements,
        overhead=sum(_size(e) for e in elements),
        value_elements=tuple(e for e in elements if e.role in VALUE_ROLES),
    )


def variants(protocol: Protocol) -> dict[Direction, tuple[Variant, ...]]:
    """Every direction's plain layouts, in the order the Python stream parser tries them."""
    return {
        d: tuple(v for k, layout in enumerate(layouts) for v in split(layout, k))
        for d, layouts in protocol.framing.alternatives.items()
    }


def expanded(protocol: Protocol) -> tuple[Protocol, dict[Direction, tuple[Variant, ...]]]:
    """The protocol with each layout of optional elements replaced by its variants (itself when it has none)."""
    found = variants(protocol)
    if all(len(v) == len(protocol.framing.alternatives[d]) for d, v in found.items()):
        return protocol, found
    framing = replace(
        protocol.framing,
        alternatives={d: tuple(v.layout for v in vs) for d, vs in found.items()},
        layouts={d: vs[0].layout for d, vs in found.items()},
    )
    return replace(protocol, framing=framing), found


def has_optional(ctx: Ctx) -> bool:
    return any(optional_elements(ctx.protocol if ctx.original is None else ctx.original, d) for d in Direction)


def elements_of(ctx: Ctx, direction: Direction) -> tuple[FrameElement, ...]:
    """The direction's optional elements, each once (every message of it carries them)."""
    return optional_elements(ctx.original or ctx.protocol, direction)


def members(ctx: Ctx, direction: Direction) -> list[Member]:
    """The message struct's members of the optional elements: a presence flag and the bytes."""
    found = []
    for e in elements_of(ctx, direction):
        name = ident(e.name)
        found.append(Member(f"has_{name}", f"bool has_{name};", f"{e.name} sent (encode: send it)", "bool"))
        doc = f"frame {e.name}: its bytes, when has_{name}"
        found.append(Member(name, f"uint8_t {name}[{e.size}];", doc, "uint8_t", e.size or 0))
    return found


def splits(ctx: Ctx) -> bool:
    """Some layout is read as several plain ones (optional elements, an extended length): p__admits tells them."""
    return ctx.original is not None  # (expanded() gives the spec itself where no layout splits)


def admits_function(ctx: Ctx) -> str:
    """`p__admits(dir, k, frame, n)`: 1 when the frame has variant k's flag bits (Layout.admits)."""
    p, P = ctx.p, ctx.P
    cases = []
    for d, vs in ctx.variants.items():
        rows = []
        for k, v in enumerate(vs):
            tests = []
            for offset, size, big, mask, bits in v.conditions:
                order = range(size) if big else range(size - 1, -1, -1)
                value = " | ".join(
                    f"((uint32_t)f[{offset + i}u] << {8 * (size - 1 - j)}u)" for j, i in enumerate(order)
                )
                tests.append(f"n >= {offset + size}u && (({value}) & {mask}UL) == {bits}UL")
            tests += [f"n > {offset}u && f[{offset}u] != 0x{byte:02x}u" for offset, byte in v.unless]
            if tests:
                rows.append(f"        case {k}u:\n            return {' && '.join(tests)};")
        if rows:
            cases.append(
                f"    case {P}_{d.name}:\n        switch (k) {{\n"
                + "\n".join(rows)
                + "\n        default:\n            break;\n        }\n        break;"
            )
    return f"""
/* 1 when frame f[0..n) has the flag bits of the direction's layout k (the optional elements it sends; an extended
 * length's marker byte, or not). */
static int {p}__admits({p}_direction_t dir, uint8_t k, const uint8_t *f, size_t n)
{{
    (void)f;
    (void)n;
    switch (dir) {{
{chr(10).join(cases)}
    default:
        break;
    }}
    return 1;
}}
"""


def admits(ctx: Ctx) -> str:
    """`p__admits(dir, k, frame, n)` and the optional elements' helpers (see admits_function)."""
    p = ctx.p
    return (
        admits_function(ctx)
        + f"""

/* Where the optional elements of layout k lie in frame f[0..n) (NULL: not sent), by their order in the direction. */
static void {p}__extras({p}_direction_t dir, uint8_t k, const uint8_t *f, size_t n, const uint8_t **at)
{{
{extras_cases(ctx)}
}}

/* An optional element's bytes into a message (at NULL: not sent). */
static void {p}__extra(bool *has, uint8_t *bytes, const uint8_t *at, size_t size)
{{
    *has = at != NULL;
    if (at != NULL) {{
        memcpy(bytes, at, size);
    }} else {{
        memset(bytes, 0, size);
    }}
}}
"""
    )


def extras_cases(ctx: Ctx) -> str:
    P = ctx.P
    lines = ["    size_t i;", f"    for (i = 0u; i < {P}__OPTIONALS; i++) {{", "        at[i] = NULL;", "    }"]
    lines += ["    (void)f;", "    (void)n;", "    switch (dir) {"]
    for d, vs in ctx.variants.items():
        names = [e.name for e in elements_of(ctx, d)]
        rows = []
        for k, v in enumerate(vs):
            elements = v.layout.elements
            content = next((i for i, e in enumerate(elements) if e.role == "content"), len(elements))
            t = v.layout.transparency
            last = v.layout.index(t.last) if t is not None else content
            sets = []
            for i, e in enumerate(elements):
                if e.role != EXTRA:
                    continue
                if i < content and (t is None or i < v.layout.index(t.first)):
                    where = f"f + {_offset(v.layout, i)}u"
                else:
                    assert i > last
                    where = f"f + n - {sum(_size(x) for x in elements[i:])}u"
                sets.append(f"            at[{names.index(e.name)}] = {where};")
            if sets:
                rows.append(f"        case {k}u:\n" + "\n".join(sets) + "\n            break;")
        if rows:
            lines.append(
                f"    case {P}_{d.name}:\n        switch (k) {{\n"
                + "\n".join(rows)
                + "\n        default:\n            break;\n        }\n        break;"
            )
    lines += ["    default:", "        break;", "    }"]
    return "\n".join(lines)


def encode_lines(ctx: Ctx, direction: Direction) -> tuple[list[str], list[str]]:
    """A public encoder's choice of variant: the optional elements the message gives (`present`, a bit each, and
    `extras`, their bytes); a value flag element whose bit disagrees is refused (Layout._sending)."""
    P = ctx.P
    elements = elements_of(ctx, direction)
    layout = (ctx.original or ctx.protocol).framing.layouts[direction]
    values = {e.name for e in layout.value_elements}
    decls = [f"    const uint8_t *extras[{max(1, len(elements))}];", "    uint8_t present = 0u;"]
    lines: list[str] = []
    for i, e in enumerate(elements):
        has, name = f"m->has_{ident(e.name)}", ident(e.name)
        flag, mask = e.present_if
        if flag in values:
            lines.append(
                f"    if ({has} != ((m->{ident(flag)} & {mask}u) != 0u)) {{ return {P}_E_RANGE; }} "
                f"/* {e.name} given exactly when {flag} has bit {mask:#04x} */"
            )
        lines.append(f"    extras[{i}] = {has} ? m->{name} : NULL;")
        lines.append(f"    present = (uint8_t)(present | ({has} ? {1 << i}u : 0u));")
    return decls, lines


def present(ctx: Ctx) -> str:
    """`p__present(dir, k)`: the optional elements layout k sends, a bit each in the direction's order."""
    p, P = ctx.p, ctx.P
    cases = []
    for d, vs in ctx.variants.items():
        names = [e.name for e in elements_of(ctx, d)]
        bits = [sum(1 << names.index(n) for n in v.present) for v in vs]
        table = ", ".join(f"{b}u" for b in bits)
        cases.append(
            f"    case {P}_{d.name}: {{\n        static const uint8_t sent[] = {{{table}}};\n"
            f"        return k < {len(bits)}u ? sent[k] : 0u;\n    }}"
        )
    return f"""
/* The optional elements the direction's layout k sends: a bit each, in the order the messages hold them. */
static uint8_t {p}__present({p}_direction_t dir, uint8_t k)
{{
    switch (dir) {{
{chr(10).join(cases)}
    default:
        return 0u;
    }}
}}
"""


def dec_sets(ctx: Ctx, mid: str, direction: Direction) -> str:
    """A decoded message's optional elements, from where p__extras found them."""
    return " ".join(
        f"{ctx.p}__extra(&out->u.{mid}.has_{ident(e.name)}, out->u.{mid}.{ident(e.name)}, extras[{i}], {e.size}u);"
        for i, e in enumerate(elements_of(ctx, direction))
    )


def json_lines(ctx: Ctx, direction: Direction, first: bool) -> list[str]:
    """The optional elements in a message's JSON, as `decode --json`: null, or the bytes as spaced hex."""
    p = ctx.p
    out = []
    for e in elements_of(ctx, direction):
        name = ident(e.name)
        out.append(f'    {p}__ws(w, "{"" if first else ", "}\\"{e.name}\\": ");')
        out.append(f"    if (!m->has_{name}) {{")
        out.append(f'        {p}__ws(w, "null");')
        out.append("    } else {")
        out.append(f"        {ctx.writer('wbytes')}(w, m->{name}, {e.size}u);")
        out.append("    }")
        first = False
    return out
