"""Checksum algorithms as C: one function per algorithm, in one place (the registry can take them over per backend).

Each function returns the C text of an incremental, public function `<name>(acc, data, n)` and the expressions that
start and finish it, so a firmware author can checksum a frame in pieces and the frame engine calls the same code.
"""

from __future__ import annotations

from collections.abc import Callable

from serialspec.backends import Unsupported
from serialspec.lang.frozen import frozen
from serialspec.lang.model import Checksum, Crc


@frozen
class CChecksum:
    """One checksum as C: the public function (`acc = name(acc, data, n)`), its start value and its final step."""

    name: str  # the public function's name, prefixed
    ctype: str  # the accumulator's C type
    definition: str  # the function's C text
    prototype: str
    start: str  # C expression of the accumulator's start value
    finish: str  # C expression of the checksum from the accumulator `a` (a str.format template with {a})


def _ctype(width: int) -> str:
    return "uint8_t" if width <= 8 else "uint16_t" if width <= 16 else "uint32_t"


def _reflect(value: int, width: int) -> int:
    return int(f"{value:0{width}b}"[::-1], 2)


def _crc(prefix: str, checksum: Checksum) -> CChecksum:
    crc = checksum.crc
    assert crc is not None
    c = _crc_parts(crc)
    slug = "".join(ch if ch.isalnum() else "_" for ch in crc.name.split(" ")[0].lower()).strip("_")
    name = f"{prefix}_{slug}"
    mask = (1 << crc.width) - 1
    t = _ctype(crc.width)
    doc = (
        f"/* {crc.name}: width {crc.width}, poly 0x{crc.poly:x}, init 0x{crc.init:x}, refin {str(crc.refin).lower()}, "
        f"refout {str(crc.refout).lower()}, xorout 0x{crc.xorout:x} (check 0x{crc.check:x}). Incremental: start with "
        f"{c['start']}, feed pieces, then {c['finish_doc']}. Bitwise: no table, no static data. */"
    )
    prototype = f"{t} {name}({t} acc, const uint8_t *data, size_t n);"
    body = f"""{doc}
{t} {name}({t} acc, const uint8_t *data, size_t n)
{{
    uint32_t r = acc;
    size_t i;
    int bit;
    for (i = 0; i < n; i++) {{
{c["loop"]}
    }}
    return ({t})(r & 0x{mask:x}u);
}}
"""
    return CChecksum(name, t, body, prototype, c["start"], c["finish"])


def _crc_parts(crc: Crc) -> dict[str, str]:
    """The register kept in the input's bit order (reflected when refin); finish reflects it when refout differs."""
    width, mask = crc.width, (1 << crc.width) - 1
    if crc.refin:
        poly = _reflect(crc.poly, width)
        start = _reflect(crc.init, width)
        loop = (
            "        r ^= data[i];\n"
            "        for (bit = 0; bit < 8; bit++) {\n"
            f"            r = (r & 1u) ? ((r >> 1) ^ 0x{poly:x}u) : (r >> 1);\n"
            "        }"
        )
    else:
        start = crc.init
        top = 1 << (width - 1)
        loop = (
            f"        r ^= (uint32_t)data[i] << {width - 8};\n"
            "        for (bit = 0; bit < 8; bit++) {\n"
            f"            r = (r & 0x{top:x}u) ? (((r << 1) ^ 0x{crc.poly:x}u) & 0x{mask:x}u)"
            f" : ((r << 1) & 0x{mask:x}u);\n"
            "        }"
        )
    reflect = crc.refin != crc.refout
    finish = "(uint32_t)({a})"
    if reflect:
        finish = f"{_PREFIX_HOLE}reflect((uint32_t)({{a}}), {width})"
    if crc.xorout:
        finish = f"(({finish}) ^ 0x{crc.xorout:x}u)"
    doc = ("reflect the result over its width, " if reflect else "") + (
        f"xor it with 0x{crc.xorout:x}" if crc.xorout else "use it as is"
    )
    return {"start": f"0x{start:x}u", "loop": loop, "finish": finish, "finish_doc": doc}


_PREFIX_HOLE = "@P@_"  # replaced by the protocol's internal prefix (the engine's reflect helper)


def _sum(prefix: str, checksum: Checksum) -> CChecksum:
    width = checksum.type.size * 8
    t = _ctype(width)
    name = f"{prefix}_sum{width}"
    mask = (1 << width) - 1
    prototype = f"{t} {name}({t} acc, const uint8_t *data, size_t n);"
    final = "the sum inverted" if checksum.invert else "the sum"
    body = f"""/* Sum of the bytes modulo 2^{width}. Incremental: start with 0; the frame's checksum is {final}. */
{t} {name}({t} acc, const uint8_t *data, size_t n)
{{
    uint32_t s = acc;
    size_t i;
    for (i = 0; i < n; i++) {{
        s += data[i];
    }}
    return ({t})(s & 0x{mask:x}u);
}}
"""
    finish = f"(~(uint32_t)({{a}}) & 0x{mask:x}u)" if checksum.invert else "(uint32_t)({a})"
    if checksum.invert:
        name_inv = name  # the same function: the inversion is the frame's final step
        return CChecksum(name_inv, t, body, prototype, "0u", finish)
    return CChecksum(name, t, body, prototype, "0u", finish)


def _xor(prefix: str, checksum: Checksum) -> CChecksum:
    width = checksum.type.size * 8
    if width != 8:
        raise Unsupported(f"checksum: xor over {width}-bit words")
    name = f"{prefix}_xor8"
    prototype = f"uint8_t {name}(uint8_t acc, const uint8_t *data, size_t n);"
    body = f"""/* XOR of the bytes. Incremental: start with 0. */
uint8_t {name}(uint8_t acc, const uint8_t *data, size_t n)
{{
    uint8_t x = acc;
    size_t i;
    for (i = 0; i < n; i++) {{
        x = (uint8_t)(x ^ data[i]);
    }}
    return x;
}}
"""
    return CChecksum(name, "uint8_t", body, prototype, "0u", "(uint32_t)({a})")


ALGORITHMS: dict[str, Callable[[str, Checksum], CChecksum]] = {"crc": _crc, "sum": _sum, "xor": _xor}


def c_checksum(prefix: str, checksum: Checksum) -> CChecksum:
    """The C of one checksum: the algorithm's own function (ALGORITHMS), with the protocol's prefix."""
    made = ALGORITHMS[checksum.algorithm](prefix, checksum)
    return CChecksum(
        made.name,
        made.ctype,
        made.definition,
        made.prototype,
        made.start,
        made.finish.replace(_PREFIX_HOLE, f"{prefix}__"),
    )
