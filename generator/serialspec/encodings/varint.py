"""`encoding: varint`: an integer sent in as many bytes as its value needs, a group of `bits` value bits a byte and
the bit above them (the continuation bit) set on every byte but the last; the bits above that must be clear.

The common families, as `varint: {...}` beside `encoding: varint`:
- LEB128 / protobuf varints (the default): 7 bits a byte, the lowest group first, bit 7 = more (300 is AC 02).
- protobuf sint (zigzag): `sign: zigzag`, 0, -1, 1, -2 sent as 0, 1, 2, 3 (-1 is 01).
- Dimension Engineering Kangaroo: `bits: 6, sign: low_bit`, the magnitude shifted left once with the sign in bit 0,
  then 6 bits a byte, bit 6 = more (1000 is 50 1F, -1 is 03).
- MIDI variable-length quantities, ASN.1 BER tags: `order: high_first`, the highest group first (200 is 81 48).

The field's `type` gives the value's range and what C stores it in (a signed type needs a `sign`, an unsigned one
takes none); a frame carries at most the bytes the type's widest value needs (`most_bytes`): decoding refuses more,
a byte with bits above the continuation bit set, a frame that ends before the last byte, and a value outside the
range. Longer spellings of a value (a zero group sent with the continuation bit, "negative zero") are read as the
value and re-encoded in the shortest form.

Everything of the encoding is here: the grammar's text, the spec check, the runtime (`read`, `write`, the construct
adapter) and each backend's code (C functions, the markdown type note).
"""

from __future__ import annotations

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any

NAME = "varint"
SIGNS = ("zigzag", "low_bit")
ORDERS = ("low_first", "high_first")
#: The grammar's words for it (a field's `encoding:` choices).
DOC = (
    "varint (as many bytes as the value needs: LEB128/protobuf by default, 7 bits a byte, lowest group first, "
    "bit 7 set on every byte but the last; see `varint` for the other families)"
)
#: The grammar's text of the `varint:` key.
KEY_DOC = (
    "With `encoding: varint`, how the integer is spread over its bytes: `bits`, the value bits a byte (1..7, default "
    "7; the bit above them marks more bytes, the bits above that are clear); `order`, low_first (the lowest group "
    "first: LEB128, protobuf; the default) or high_first (MIDI variable-length quantities); `sign` (a signed type "
    "needs one, an unsigned type takes none): zigzag (protobuf sint: 0, -1, 1, -2 sent as 0, 1, 2, 3) or low_bit "
    "(the magnitude shifted left once, the sign in bit 0: Dimension Engineering Kangaroo, `{type: i32, encoding: "
    "varint, varint: {bits: 6, sign: low_bit}}` sends 1000 as 50 1F and -1 as 03). The field's type gives the range; "
    "decoding refuses more bytes than its widest value needs. Not a count or size; in a group's items too (a "
    "protobuf packed list: a group of `count: rest`)."
)
#: The language reference's example: (label, fields, what it shows).
VARIANT = (
    "Integers in as many bytes as they need (`encoding: varint`): a protobuf-style size, a zigzag offset, Dimension "
    "Engineering Kangaroo's bit-packed position, a MIDI delta time",
    {
        "size": {"type": "u32", "encoding": "varint"},
        "offset": {"type": "i32", "encoding": "varint", "varint": {"sign": "zigzag"}},
        "position": {"type": "i32", "encoding": "varint", "varint": {"bits": 6, "sign": "low_bit"}, "unit": "mm"},
        "delta": {"type": "u32", "encoding": "varint", "varint": {"order": "high_first"}, "range": [0, 0x0FFFFFFF]},
    },
    "`size` 300 is sent as AC 02 (LEB128: the low 7 bits first, bit 7 set on every byte but the last); `offset` -1 "
    "as 01 (zigzag: 0, -1, 1, -2 as 0, 1, 2, 3); `position` 1000 as 50 1F and -1 as 03 (the magnitude shifted left "
    "with the sign in bit 0, 6 bits a byte, bit 6 = more); `delta` 200 as 81 48 (the highest group first). Each "
    "takes one byte up to as many as its type's widest value needs (here 5, 5, 6 and 4): decoding refuses more, a "
    "byte with bits above the continuation bit set, a content ending inside it and a value outside the range; "
    "encoding writes the shortest form and refuses a value outside the range before a byte is written. The "
    "content's size varies, so its frame needs a length element, a trailer or a transform (else the spec is refused "
    "in one line); fields after a varint are read after it, and checksums cover its bytes as any others. Every "
    "output takes it: the codec, stream parser, client and simulator, the construct structs (construct's own "
    "VarInt and ZigZag where the form is theirs), the markdown reference, C (the number in a uint64_t: a form "
    "whose number passes 64 bits, an i64 with `sign: low_bit` over its whole range, is refused in one line) and "
    "the Wireshark dissector. A varint is a plain number: no `scale`, `offset`, `enum`, `flags`, `bits`, `const`, "
    "`value` or `endian`, not a count, size or term of a `value:` (each refused in one line); in a group's items "
    "too, the items then of varying size.",
)
#: Field keys a varint refuses (it is a plain number of varying size).
REFUSED_KEYS = ("const", "bits", "flags", "enum", "value", "endian", "status", "scale", "offset")


def problem(type_name: str, signed: bool, is_float: bool, sign: str) -> str:
    """Why a field of this type and sign cannot take the encoding ("" when it can)."""
    if is_float:
        return f"encoding varint is for integers, not {type_name}"
    if signed and not sign:
        return f"a signed varint ({type_name}) needs `varint: {{sign: zigzag}}` or `sign: low_bit`"
    if sign and not signed:
        return f"`sign: {sign}` goes with a signed type, not {type_name}"
    return ""


def wire(value: int, sign: str) -> int:
    """The unsigned number sent for a value."""
    if sign == "zigzag":
        return value << 1 if value >= 0 else (-value << 1) - 1
    if sign == "low_bit":
        return -value << 1 | 1 if value < 0 else value << 1
    return value


def value_of(number: int, sign: str) -> int:
    """The value of an unsigned number read."""
    if sign == "zigzag":
        return number >> 1 ^ -(number & 1)
    if sign == "low_bit":
        return -(number >> 1) if number & 1 else number >> 1
    return number


def most_bytes(minimum: int, maximum: int, bits: int, sign: str) -> int:
    """The most bytes a value of minimum..maximum takes."""
    widest = max(wire(minimum, sign), wire(maximum, sign))
    return max(1, -(-widest.bit_length() // bits))


# --- runtime ---------------------------------------------------------------------------------------------------------


def read(buf: bytes, at: int, end: int, bits: int, high_first: bool, most: int) -> tuple[int, int]:
    """(the unsigned number, the offset after it) of the bytes at buf[at:end]; ValueError (the reason) for a frame
    ending before the last byte, more than `most` bytes, or a byte with bits above the continuation bit set."""
    more = 1 << bits
    mask = more - 1
    number = shift = 0
    for i in range(most):
        if at + i >= end:
            raise ValueError(f"the frame ends before its last byte (after {i})")
        byte = buf[at + i]
        if byte >> bits > 1:
            raise ValueError(f"byte {i} ({byte:#04x}) has bits above bit {bits} set")
        if high_first:
            number = number << bits | byte & mask
        else:
            number |= (byte & mask) << shift
            shift += bits
        if not byte & more:
            return number, at + i + 1
    raise ValueError(f"more than {most} bytes")


def write(number: int, bits: int, high_first: bool) -> bytes:
    """The bytes of an unsigned number, in as few bytes as it needs."""
    mask = (1 << bits) - 1
    groups = [number & mask]
    number >>= bits
    while number:
        groups.append(number & mask)
        number >>= bits
    if high_first:
        groups.reverse()
    last = len(groups) - 1
    return bytes(group | (1 << bits if i < last else 0) for i, group in enumerate(groups))


def VarintOf(bits: int, sign: str, high_first: bool, minimum: int, maximum: int) -> Any:  # noqa: N802
    """The construct of a varint field other than construct's own VarInt and ZigZag (generated structs.py); construct
    is imported by those structs alone, so here only when one is built."""
    from construct import Construct, StreamError, ValidationError, stream_read, stream_write

    most = most_bytes(minimum, maximum, bits, sign)

    class _Varint(Construct):  # type: ignore[misc, type-arg, unused-ignore]
        def _parse(self, stream: Any, context: Any, path: Any) -> int:
            data = b""
            while True:
                data += stream_read(stream, 1, path)
                if not data[-1] & 1 << bits or len(data) > most:
                    break
            try:
                value = value_of(read(data, 0, len(data), bits, high_first, most)[0], sign)
            except ValueError as exc:
                raise StreamError(str(exc), path=path) from None
            if not minimum <= value <= maximum:
                raise ValidationError(f"{value} is outside {minimum}..{maximum}", path=path)
            return value

        def _build(self, obj: int, stream: Any, context: Any, path: Any) -> int:
            if obj.__class__ is not int or not minimum <= obj <= maximum:
                raise ValidationError(f"{obj!r} is not an integer in {minimum}..{maximum}", path=path)
            data = write(wire(obj, sign), bits, high_first)
            stream_write(stream, data, len(data), path)
            return obj

    return _Varint()


def construct(bits: int, sign: str, high_first: bool, minimum: int, maximum: int) -> str:
    """The construct expression of a field: construct's own VarInt (LEB128) and ZigZag where they match."""
    if bits == 7 and not high_first and sign in ("", "zigzag"):
        base = "ZigZag" if sign else "VarInt"
        return f"ExprValidator({base}, lambda obj, ctx: {minimum} <= obj <= {maximum})"
    return f"VarintOf({bits}, {sign!r}, {high_first}, {minimum}, {maximum})"


def type_note(bits: int, sign: str, high_first: bool, most: int) -> str:
    """What the markdown reference says of the field's type."""
    order = "highest" if high_first else "lowest"
    signs = {"zigzag": ", zigzag sign", "low_bit": ", the sign in bit 0"}
    spread = f"{bits} bits a byte, {order} group first, bit {bits} = more, 1..{most} bytes"
    return f" as a varint ({spread}{signs.get(sign, '')})"


def c_problem(minimum: int, maximum: int, sign: str) -> str:
    """Why the C target cannot take such a field ("" when it can): its numbers are 64-bit."""
    if max(wire(minimum, sign), wire(maximum, sign)) >> 64:
        return f"a varint whose number passes 64 bits ({minimum} with sign {sign}: give a narrower range)"
    return ""


def c_wire(value: str, sign: str) -> str:
    """A C expression of the unsigned number (uint64_t) sent for `value`, a value in range."""
    if sign == "zigzag":
        return f"({value} < 0 ? (((uint64_t)(-((int64_t){value} + 1)) << 1) | 1u) : ((uint64_t){value} << 1))"
    if sign == "low_bit":
        return f"({value} < 0 ? ((((uint64_t)(-((int64_t){value} + 1)) + 1u) << 1) | 1u) : ((uint64_t){value} << 1))"
    return f"((uint64_t){value})"


def c_value(number: str, sign: str) -> str:
    """A C expression of the value (int64_t, or uint64_t unsigned) of `number`, the uint64_t read."""
    if sign == "zigzag":
        return f"(({number} & 1u) ? -(int64_t)({number} >> 1) - 1 : (int64_t)({number} >> 1))"
    if sign == "low_bit":
        return f"(({number} & 1u) ? -(int64_t)({number} >> 1) : (int64_t)({number} >> 1))"
    return number


#: The C helper reading a varint (`P` the protocol's prefix): the unsigned number at src (n bytes left) in *number,
#: its count of bytes; 0 when the bytes end before its last, it runs past `most` bytes, a byte has bits above the
#: continuation bit set, or the number passes 64 bits.
C_GET = """static size_t P__varint_get(const uint8_t *src, size_t n, unsigned bits, unsigned high_first, size_t most,
                             uint64_t *number)
{
    uint64_t v = 0u;
    unsigned shift = 0u;
    size_t i;
    for (i = 0u; i < most && i < n; i++) {
        unsigned byte = src[i];
        uint64_t group = (uint64_t)(byte & ((1u << bits) - 1u));
        if ((byte >> bits) > 1u) {
            return 0u;
        }
        if (high_first) {
            if ((v >> (64u - bits)) != 0u) {
                return 0u;
            }
            v = (v << bits) | group;
        } else if (group != 0u) {
            if (shift >= 64u || (shift > 0u && (group >> (64u - shift)) != 0u)) {
                return 0u;
            }
            v |= group << shift;
        }
        shift += bits;
        if ((byte & (1u << bits)) == 0u) {
            *number = v;
            return i + 1u;
        }
    }
    return 0u;
}"""

#: The C helper writing a varint: the bytes of `number` at dst (NULL: only counted), their count.
C_PUT = """static size_t P__varint_put(uint8_t *dst, uint64_t number, unsigned bits, unsigned high_first)
{
    size_t count = 1u, i;
    uint64_t rest = number >> bits;
    while (rest != 0u) {
        count++;
        rest >>= bits;
    }
    if (dst != NULL) {
        for (i = 0u; i < count; i++) {
            size_t at = high_first ? count - 1u - i : i;
            unsigned more = at + 1u < count ? 1u << bits : 0u;
            dst[at] = (uint8_t)((unsigned)(number & ((1u << bits) - 1u)) | more);
            number >>= bits;
        }
    }
    return count;
}"""
