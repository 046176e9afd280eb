"""Packed integer arrays in C (model.Packed: `type: array` of an N-bit integer, CRSF's 16 × 11-bit channels): the
member type, the decode, range-check, encode and JSON statements and the bit helpers they call, all here.

Items are read and written bit by bit through a bit position, so any width (1..64), either bit order and any
alignment take the same two helpers; the host's byte order never matters. The bits of the last byte after the last
item are written 0 and not checked when read (as runtime/packing.py)."""

from __future__ import annotations

from serialspec.lang.model import Packed, ScalarType


def width(f: Packed) -> int:
    """The bits of the C integer that holds one item (and of the helpers that move it)."""
    return next(w for w in (8, 16, 32, 64) if f.bits <= w)


def item_type(f: Packed) -> ScalarType:
    """A scalar type of the member's items, for the shared type, range and JSON code."""
    w = width(f)
    low, high = (-(1 << (w - 1)), (1 << (w - 1)) - 1) if f.signed else (0, (1 << w) - 1)
    return ScalarType(f"{'i' if f.signed else 'u'}{w}", w // 8, "", f.signed, False, low, high)


def helper_width(f: Packed) -> int:
    return 64 if f.bits > 32 else 32


def decode(p: str, P: str, f: Packed, tgt: str, pad: str, i: str, helpers: set[str]) -> list[str]:
    w = helper_width(f)
    helpers.add(f"bits{w}")
    raw = f"{p}__bits{w}(c + o, {i} * {f.bits}u, {f.bits}u, {int(f.lsb_first)}u)"
    if f.signed:
        helpers.add(f"sx{w}")
        raw = f"{p}__sx{w}({raw}, {f.bits}u)"
    ctype = f"{'int' if f.signed else 'uint'}{width(f)}_t"
    return [
        f"{pad}if (n - o < {f.byte_size}u) {{ return {P}_E_LENGTH; }}",
        f"{pad}for ({i} = 0u; {i} < {f.count}u; {i}++) {{",
        f"{pad}    {tgt}[{i}] = ({ctype}){raw};",
        f"{pad}}}",
        f"{pad}o += {f.byte_size}u;",
    ]


def encode(p: str, P: str, f: Packed, tgt: str, pad: str, i: str, helpers: set[str]) -> list[str]:
    w = helper_width(f)
    helpers.add(f"setbits{w}")
    value = f"(uint{w}_t)(int{w}_t){tgt}[{i}]" if f.signed else f"(uint{w}_t){tgt}[{i}]"
    return [
        f"{pad}if (cap - o < {f.byte_size}u) {{ return {P}_E_BUFFER; }}",
        f"{pad}memset(c + o, 0, {f.byte_size}u); /* {f.name}: {f.count} × {f.bits} bits */",
        f"{pad}for ({i} = 0u; {i} < {f.count}u; {i}++) {{",
        f"{pad}    {p}__setbits{w}(c + o, {i} * {f.bits}u, {f.bits}u, {int(f.lsb_first)}u, {value});",
        f"{pad}}}",
        f"{pad}o += {f.byte_size}u;",
    ]


def helpers(p: str, P: str, used: set[str]) -> list[str]:
    """The C of the bit helpers the generated code calls."""
    parts = []
    for w in (32, 64):
        if f"bits{w}" in used:
            parts.append(
                f"""#if {P}_ENABLE_DECODE
/* n bits (at most {w}) at bit position at: lsb, bit k is bit k % 8 of byte k / 8 and the value's lowest bit comes
   first; else bit k is bit 7 - k % 8 and the value's highest bit comes first. */
static uint{w}_t {p}__bits{w}(const uint8_t *b, size_t at, uint8_t n, uint8_t lsb)
{{
    uint{w}_t v = 0u;
    uint8_t j;
    for (j = 0u; j < n; j++) {{
        size_t k = at + j;
        if (lsb) {{
            v |= (uint{w}_t)(((unsigned)b[k >> 3] >> (k & 7u)) & 1u) << j;
        }} else {{
            v = (v << 1) | (uint{w}_t)(((unsigned)b[k >> 3] >> (7u - (k & 7u))) & 1u);
        }}
    }}
    return v;
}}
#endif
"""
            )
        if f"sx{w}" in used:
            parts.append(
                f"""#if {P}_ENABLE_DECODE
/* An n-bit two's complement value (1 <= n <= {w}) from its bits (no implementation-defined conversion). */
static int{w}_t {p}__sx{w}(uint{w}_t v, uint8_t n)
{{
    uint{w}_t mask = n < {w}u ? ((uint{w}_t)1u << n) - 1u : ~(uint{w}_t)0u;
    if ((v >> (n - 1u)) & 1u) {{
        return -(int{w}_t)((~v) & mask) - 1;
    }}
    return (int{w}_t)(v & mask);
}}
#endif
"""
            )
        if f"setbits{w}" in used:
            parts.append(
                f"""#if {P}_ENABLE_ENCODE
/* The n lowest bits of v at bit position at (the bits there are 0), in the order {p}__bits{w} reads them. */
static void {p}__setbits{w}(uint8_t *b, size_t at, uint8_t n, uint8_t lsb, uint{w}_t v)
{{
    uint8_t j;
    for (j = 0u; j < n; j++) {{
        size_t k = at + j;
        if (((v >> (lsb ? j : (uint8_t)(n - 1u - j))) & 1u) != 0u) {{
            b[k >> 3] = (uint8_t)(b[k >> 3] | (lsb ? (1u << (k & 7u)) : (0x80u >> (k & 7u))));
        }}
    }}
}}
#endif
"""
            )
    return parts
