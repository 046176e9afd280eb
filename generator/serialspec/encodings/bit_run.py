"""Integer fields of any width, packed with no gaps: `type: u12`, `type: i38` (RTCM 3's data fields, CAN-style
records). A field of such a type opens a bit run: it and the fields after it are one run of bits, read as one
big-endian integer, the first field in the highest bits (MSB first, as RTCM, ASN.1 PER and most standards' bit
tables number them), until the run's bits are a whole number of bytes. A byte-sized integer (u8, i16, ...) met while
the run is open joins it (RTCM 1033's 8-bit counters follow 12-bit fields); any other field there, or the content's
end, is a spec error naming the run and its bit count. Every member is an integer field like any other (range,
scale, offset, enum, const, default, value, counts and sizes): only its place on the wire differs.

Everything of the feature is here: the grammar's text, the types it names, the grouping of fields into runs and its
check, the runtime (the construct class the reference structs use), and the code each backend writes (Python
shifts over one int.from_bytes of the run, C shifts over uint64_t words, the Wireshark dissector's Lua data, the
markdown reference's bit positions). The package imports nothing of the generator.
"""

from __future__ import annotations

import re

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any

#: The byte-sized integer types, which a field names as ever (they join a run only while it is open).
BYTE_SIZED = ("u8", "i8", "u16", "i16", "u24", "i24", "u32", "i32", "u64", "i64")
_TYPE = re.compile(r"^([ui])([1-9][0-9]?)$")

#: The grammar's words for it (the `type:` key of a field).
DOC = (
    "uN or iN for any other N of 1..64 (u12, i38): a bit field; such fields and the integer fields after them pack "
    "with no gaps, the first in the highest bits, until the bits fill whole bytes (RTCM 3: `msg: u12`, `x: i38`)"
)


def width(type_name: object) -> int | None:
    """The bits of a bit-field type name (`u12` -> 12), None for any other name (u8, u16, ... included)."""
    found = _TYPE.match(type_name) if isinstance(type_name, str) else None
    if found is None or type_name in BYTE_SIZED:
        return None
    bits = int(found.group(2))
    return bits if 1 <= bits <= 64 else None


def size_of(bits: int) -> int:
    """The bytes of the smallest machine integer holding `bits` bits (a member's C type, its message value)."""
    return next(size for size in (1, 2, 4, 8) if size * 8 >= bits)


def limits(bits: int, signed: bool) -> tuple[int, int]:
    """The values an integer of `bits` bits holds."""
    return (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)


def problem(field: str, run: str, bits: int) -> str:
    """The spec error of a run that does not end on a byte boundary, `field` the field that ends it ("" at the end
    of the content)."""
    where = f"before {field}" if field else "at the end of the content"
    return (
        f"bit run {run}: {bits} bits {where}, not a whole number of bytes (add fields or reserved bits to fill "
        f"{-(-bits // 8) * 8})"
    )


# --- runtime ---------------------------------------------------------------------------------------------------------


def BitRunMember(  # noqa: N802 (a construct, named as construct's are)
    bits: int, shift: int, size: int, signed: bool, earlier: tuple[tuple[str, int, int], ...] = ()
) -> Any:
    """The construct of one member of a bit run of `size` bytes (the generated structs.py), `shift` bits above the
    run's lowest bit: it reads its bits from the run's bytes, and every member but the last (shift 0) leaves them for
    the next. Building, the members before the last write nothing, and the last writes the whole run from its value
    and the earlier members' in the context: `earlier`, (name, bits, shift) of each."""
    from construct import Construct, ValidationError, stream_read, stream_write

    low, high = limits(bits, signed)
    last = shift == 0

    class _Member(Construct):  # type: ignore[misc, type-arg, unused-ignore]
        def _parse(self, stream: Any, context: Any, path: Any) -> int:
            data = stream_read(stream, size, path)
            if not last:
                stream.seek(-size, 1)
            value = (int.from_bytes(data, "big") >> shift) & ((1 << bits) - 1)
            return value - ((value >> (bits - 1)) << bits) if signed else value

        def _build(self, obj: Any, stream: Any, context: Any, path: Any) -> Any:
            if not isinstance(obj, int) or isinstance(obj, bool) or not low <= obj <= high:
                raise ValidationError(f"{obj!r} is outside {low}..{high}", path=path)
            if last:
                word = obj & ((1 << bits) - 1)
                for name, width, at in earlier:
                    word |= (int(context[name]) & ((1 << width) - 1)) << at
                stream_write(stream, word.to_bytes(size, "big"), size, path)
            return obj

        def _sizeof(self, context: Any, path: Any) -> int:
            return size if last else 0

    return _Member()


# --- code of each backend --------------------------------------------------------------------------------------------


def python_decode(word: str, bits: int, shift: int, size: int, signed: bool) -> str:
    """A Python expression of a member's value from `word`, the run as one unsigned integer (a local name)."""
    value = f"{word} >> {shift}" if shift else word
    if shift + bits < size * 8:  # bits above it: masked off
        value = f"({value}) & {(1 << bits) - 1:#x}" if shift else f"{value} & {(1 << bits) - 1:#x}"
    if signed:
        top = 1 << (bits - 1)
        return f"(({value}) ^ {top:#x}) - {top:#x}"
    return value


def python_encode(parts: list[tuple[str, int, int, bool]], size: int) -> str:
    """A Python expression of a run's bytes from its members' (value expression, bits, shift, signed), the values
    checked to be in range already: a signed value is masked to its bits (its two's complement)."""
    terms = []
    for value, bits, shift, signed in parts:
        term = f"({value} & {(1 << bits) - 1:#x})" if signed else f"({value})"
        terms.append(f"{term} << {shift}" if shift else term)
    return f"({' | '.join(terms)}).to_bytes({size}, 'big')"


# --- the runs of a content -------------------------------------------------------------------------------------------


def runs(fields: list[tuple[str, int | None, bool]]) -> tuple[list[list[tuple[str, int]]], tuple[str, str] | None]:
    """The bit runs of a content's fields, each (name, bits of an integer field or None, whether its type is a
    bit-field type) in order: each run a list of (name, bits); and the first field and problem of a run that does
    not end on a byte boundary (None when every run does)."""
    found: list[list[tuple[str, int]]] = []
    run: list[tuple[str, int]] = []
    total = 0
    for name, bits, odd in fields:
        if not run and not odd:
            continue
        if bits is None:  # not an integer: the run is open
            return found, (run[0][0], problem(name, run[0][0], total))
        run.append((name, bits))
        total += bits
        if total % 8 == 0:
            found.append(run)
            run, total = [], 0
    if run:
        return found, (run[0][0], problem("", run[0][0], total))
    return found, None


def c_width(bits: int) -> int:
    """The bits of the C helpers that move a member (backends/c/packed.py's bits, sx and setbits helpers)."""
    return 64 if bits > 32 else 32


def c_decode(p: str, at: str, bits: int, shift: int, size: int, signed: bool) -> str:
    """A C expression of a member's bits (its value, when signed) read from the run's bytes at `at`."""
    w = c_width(bits)
    raw = f"{p}__bits{w}({at}, {size * 8 - shift - bits}u, {bits}u, 0u)"
    return f"{p}__sx{w}({raw}, {bits}u)" if signed else raw


def c_encode(p: str, at: str, bits: int, shift: int, size: int, value: str) -> str:
    """The C statement writing the lowest `bits` bits of `value` (an unsigned expression) as a member, into the
    run's bytes at `at`, which are zero."""
    w = c_width(bits)
    return f"{p}__setbits{w}({at}, {size * 8 - shift - bits}u, {bits}u, 0u, (uint{w}_t)({value}));"


#: The Wireshark dissector's function (arithmetic and the `band`/`rshift` the dissector defines): a member's value,
#: `bits` bits from bit `at` of the run's bytes at `pos`, the highest bit first (exact up to 2^53, as the
#: dissector's other 64-bit values).
LUA = """local function bit_member(tvb, pos, at, bits, signed)
  local value = 0
  for k = at, at + bits - 1 do
    value = value * 2 + band(rshift(tvb(pos + math.floor(k / 8), 1):uint(), 7 - k % 8), 1)
  end
  if signed and value >= 2 ^ (bits - 1) then value = value - 2 ^ bits end
  return value
end"""


def lua_field(bits: int, shift: int, size: int, signed: bool) -> dict[str, object]:
    """What the dissector's table says of a member (its `kind: bit_member` reads it with `bit_member`)."""
    return {
        "kind": "bit_member",
        "width": bits,
        "at": size * 8 - shift - bits,
        "size": size,
        "signed": signed,
        "last": shift == 0,
    }


def span(bits: int, shift: int, size: int) -> tuple[int, int, int]:
    """A member's first bit in the run (bit 0 the highest bit of its first byte, as RTCM's tables count) and the
    run's bytes it touches, first and last."""
    at = size * 8 - shift - bits
    return at, at // 8, (at + bits - 1) // 8


def markdown_where(offset: int, bits: int, shift: int, size: int) -> str:
    """The markdown reference's byte column of a member of a run starting at byte `offset`: its bytes and bits."""
    at, first, last = span(bits, shift, size)
    where = str(offset + first) if first == last else f"{offset + first}..{offset + last}"
    if bits == 8 * size:  # the run's every bit (a u40 between byte-sized fields): its bytes say it all
        return where
    which = f"bit {at}" if bits == 1 else f"bits {at}..{at + bits - 1}"
    run = str(offset) if size == 1 else f"{offset}..{offset + size - 1}"
    return f"{where} ({which} of {run})"
