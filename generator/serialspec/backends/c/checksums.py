"""Checksum algorithms as C: one function per algorithm of the registry (serialspec/checksums/), in one place, so
each can move into its algorithm's class (its C, beside its Python and docs) as the registry grows backends.

Each returns the C text of an incremental, public function `<name>(acc, data, n)` and the expressions that start
and finish it, so a firmware author can checksum a frame in pieces and the frame engine calls the same code.
"""

from __future__ import annotations

from collections.abc import Callable

from serialspec.backends import Unsupported
from serialspec.checksums.crc import Crc
from serialspec.checksums.fletcher import Fletcher
from serialspec.checksums.sum import Sum
from serialspec.checksums.xor import Xor
from serialspec.lang.frozen import frozen
from serialspec.lang.model import Checksum


@frozen
class CChecksum:
    """One checksum as C: the public function (`acc = name(acc, data, n)`), its start value and its final step."""

    name: str  # the public function's name, prefixed
    ctype: str  # the accumulator's C type
    definition: str  # the function's C text
    prototype: str
    start: str  # C expression of the accumulator's start value
    finish: str  # C expression of the checksum from the accumulator (a str.format template with {a})


def _ctype(width: int) -> str:
    return "uint8_t" if width <= 8 else "uint16_t" if width <= 16 else "uint32_t"


def _reflect(value: int, width: int) -> int:
    return int(f"{value:0{width}b}"[::-1], 2)


_PREFIX_HOLE = "@P@_"  # replaced by the protocol's internal prefix (its reflect helper)


def _crc(prefix: str, checksum: Checksum) -> CChecksum:
    crc = checksum.algorithm
    assert isinstance(crc, Crc)
    if not 8 <= crc.width <= 32:
        raise Unsupported(f"checksum {checksum.name}: a CRC of {crc.width} bits")
    title = crc.title()
    slug = "".join(ch if ch.isalnum() else "_" for ch in title.split(" ")[0].lower()).strip("_") if title else ""
    if not slug:
        slug = f"crc{crc.width}_{crc.poly:x}_{crc.init:x}_{int(crc.refin)}{int(crc.refout)}_{crc.xorout:x}"
    name = f"{prefix}_{slug}"
    mask = (1 << crc.width) - 1
    t = _ctype(crc.width)
    if crc.refin:  # the register kept in the input's bit order (reflected); finish reflects it where refout differs
        start = _reflect(crc.init, crc.width)
        poly = _reflect(crc.poly, crc.width)
        loop = (
            "        r ^= data[i];\n"
            "        for (bit = 0; bit < 8; bit++) {\n"
            f"            r = (r & 1u) ? ((r >> 1) ^ 0x{poly:x}u) : (r >> 1);\n"
            "        }"
        )
    else:
        start = crc.init
        top = 1 << (crc.width - 1)
        loop = (
            f"        r ^= (uint32_t)data[i] << {crc.width - 8};\n"
            "        for (bit = 0; bit < 8; bit++) {\n"
            f"            r = (r & 0x{top:x}u) ? (((r << 1) ^ 0x{crc.poly:x}u) & 0x{mask:x}u)"
            f" : ((r << 1) & 0x{mask:x}u);\n"
            "        }"
        )
    reflect = crc.refin != crc.refout
    finish = f"{_PREFIX_HOLE}reflect((uint32_t)({{a}}), {crc.width})" if reflect else "(uint32_t)({a})"
    if crc.xorout:
        finish = f"(({finish}) ^ 0x{crc.xorout:x}u)"
    steps = ("reflect the result over its width, " if reflect else "") + (
        f"xor it with 0x{crc.xorout:x}" if crc.xorout else "use it as is"
    )
    doc = (
        f"/* {title or 'CRC'}: width {crc.width}, poly 0x{crc.poly:x}, init 0x{crc.init:x}, refin "
        f"{str(crc.refin).lower()}, refout {str(crc.refout).lower()}, xorout 0x{crc.xorout:x} (check 0x{crc.check:x}). "
        f"Incremental: start with 0x{start:x}, feed pieces, then {steps}. Bitwise: no table, no static data. */"
    )
    body = f"""{doc}
{t} {name}({t} acc, const uint8_t *data, size_t n)
{{
    uint32_t r = acc;
    size_t i;
    int bit;
    for (i = 0; i < n; i++) {{
{loop}
    }}
    return ({t})(r & 0x{mask:x}u);
}}
"""
    prototype = f"{t} {name}({t} acc, const uint8_t *data, size_t n);"
    return CChecksum(name, t, body, prototype, f"0x{start:x}u", finish)


def _sum(prefix: str, checksum: Checksum) -> CChecksum:
    algorithm = checksum.algorithm
    assert isinstance(algorithm, Sum)
    width = algorithm.width
    t = _ctype(width)
    name = f"{prefix}_sum{width}"
    mask = (1 << width) - 1
    final = "the sum inverted" if algorithm.invert else "the sum negated" if algorithm.negate else "the sum"
    final += f", ANDed with 0x{algorithm.mask:x}" if algorithm.mask is not None else ""
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
    prototype = f"{t} {name}({t} acc, const uint8_t *data, size_t n);"
    return CChecksum(name, t, body, prototype, "0u", _finish(algorithm.sign, algorithm.whole))


def _finish(sign: str, whole: int) -> str:
    """The C finish of an accumulator inverted (~), negated (-) or kept (""), within the bits of `whole`."""
    if not sign and whole == 0xFFFFFFFF:
        return "(uint32_t)({a})"
    return f"({sign}(uint32_t)({{a}}) & 0x{whole:x}u)"


def _xor(prefix: str, checksum: Checksum) -> CChecksum:
    algorithm = checksum.algorithm
    assert isinstance(algorithm, Xor)
    width = algorithm.width
    whole = (1 << width) - 1 & (algorithm.mask if algorithm.mask is not None else -1)
    plain = not algorithm.invert and algorithm.mask is None
    xor_finish = "(uint32_t)({a})" if plain else _finish("~" if algorithm.invert else "", whole)
    if width == 8:
        name = f"{prefix}_xor8"
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
        prototype = f"uint8_t {name}(uint8_t acc, const uint8_t *data, size_t n);"
        return CChecksum(name, "uint8_t", body, prototype, "0u", xor_finish)
    size = width // 8
    t = _ctype(width)
    name = f"{prefix}_xor{width}"
    body = f"""/* XOR of the bytes taken as big-endian {width}-bit words, the last padded with zeros.
 * Incremental in pieces of whole words: start with 0. */
{t} {name}({t} acc, const uint8_t *data, size_t n)
{{
    uint32_t x = acc;
    size_t i, k;
    for (i = 0; i < n; i += {size}u) {{
        uint32_t word = 0u;
        for (k = 0; k < {size}u; k++) {{
            word = (word << 8) | (i + k < n ? data[i + k] : 0u);
        }}
        x ^= word;
    }}
    return ({t})x;
}}
"""
    prototype = f"{t} {name}({t} acc, const uint8_t *data, size_t n);"
    return CChecksum(name, t, body, prototype, "0u", xor_finish)


def _fletcher(prefix: str, checksum: Checksum) -> CChecksum:
    algorithm = checksum.algorithm
    assert isinstance(algorithm, Fletcher)
    m = algorithm.modulus
    name = f"{prefix}_fletcher{m}"
    body = f"""/* Fletcher modulo {m}: CK_A the sum of the bytes, CK_B the sum of CK_A after each byte; the value is
 * CK_B << 8 | CK_A. Incremental: acc holds CK_B << 8 | CK_A, start with 0. */
uint16_t {name}(uint16_t acc, const uint8_t *data, size_t n)
{{
    uint32_t a = acc & 0xFFu, b = (uint32_t)acc >> 8;
    size_t i;
    for (i = 0; i < n; i++) {{
        a = (a + data[i]) % {m}u;
        b = (b + a) % {m}u;
    }}
    return (uint16_t)((b << 8) | a);
}}
"""
    prototype = f"uint16_t {name}(uint16_t acc, const uint8_t *data, size_t n);"
    return CChecksum(name, "uint16_t", body, prototype, "0u", "(uint32_t)({a})")


ALGORITHMS: dict[str, Callable[[str, Checksum], CChecksum]] = {
    "crc": _crc,
    "sum": _sum,
    "xor": _xor,
    "fletcher": _fletcher,
}


def c_checksum(prefix: str, checksum: Checksum) -> CChecksum:
    """The C of one checksum: its algorithm's function (ALGORITHMS), with the protocol's prefix."""
    make = ALGORITHMS.get(checksum.algorithm.name)
    if make is None:
        raise Unsupported(f"checksum {checksum.name}: algorithm {checksum.algorithm.name}")
    made = make(prefix, checksum)
    return CChecksum(
        made.name,
        made.ctype,
        made.definition,
        made.prototype,
        made.start,
        made.finish.replace(_PREFIX_HOLE, f"{prefix}__"),
    )
