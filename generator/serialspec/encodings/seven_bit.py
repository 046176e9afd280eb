"""`encoding: seven_bit`: an unsigned integer sent 7 bits a byte, bit 7 of every byte clear, the bytes in the field's
byte order (little: the low 7 bits first). A u16 holds 0..16383: Pololu Maestro targets, speeds and accelerations,
MIDI pitch bend; a u24 0..2097151. Decoding refuses a byte with bit 7 set (on such links that bit marks a command
byte); encoding refuses a value past the range before a byte is written, naming the field and its range.

Everything of the encoding is here: the grammar's text, the spec check, the runtime's arithmetic (`gather`,
`spread`, the construct adapter), and the code each backend writes (Python, C and Lua expressions, the markdown
type note). The wire word is the field's plain unsigned integer; bit b of the value sits at bit b + b // 7 of it.

On a string (`{type: string, size: rest, encoding: seven_bit}`) it is text of 14-bit characters: each character's
code point as two 7-bit bytes, low first (Firmata's STRING_DATA and REPORT_FIRMWARE's name): "Hi" is 48 00 69 00.
The string's `size` counts bytes on the wire (two a character); its value is text, as any string's.
"""

from __future__ import annotations

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any

NAME = "seven_bit"
#: The grammar's words for it (a field's `encoding:` choices).
DOC = (
    "seven_bit (7 bits a byte, bit 7 clear, in the field's byte order: a u16 holds 0..16383; Pololu Maestro's "
    "`target: {type: u16, encoding: seven_bit}` sends 6000 as 70 2E)"
)
#: What the markdown reference adds to the field's type.
TYPE_NOTE = " (7 bits a byte)"


def problem(type_name: str, signed: bool, is_float: bool) -> str:
    """Why a field of this type cannot take the encoding ("" when it can)."""
    if signed or is_float:
        return f"encoding seven_bit is for unsigned integers, not {type_name}"
    return ""


#: A string's `encoding:` words (the grammar's text).
TEXT_DOC = (
    "on a string, seven_bit is text of 14-bit characters, each two 7-bit bytes, low first, `size` (`rest` or an "
    "even number) counting bytes: Firmata's STRING_DATA `text: {type: string, size: rest, encoding: seven_bit}` "
    'reads 48 00 69 00 as "Hi"'
)
#: What the markdown reference adds to a string's type.
TEXT_NOTE = ", 14-bit characters as two 7-bit bytes each, low first"
#: The largest character (code point) such text holds.
TEXT_MAXIMUM = 0x3FFF


def text_problem(size: object, padded: bool) -> str:
    """Why a string of this size cannot take the encoding ("" when it can)."""
    if size is None:
        return "encoding seven_bit on text needs `size: rest` or a number of bytes, not a NUL-terminated cstring"
    if padded:
        return "encoding seven_bit on text goes without `pad` (the text fills its size)"
    if isinstance(size, int) and size % 2:
        return f"size {size}: text of 14-bit characters is two bytes a character, an even size"
    if size != "rest" and not isinstance(size, int):
        return "encoding seven_bit on text needs `size: rest` or a number of bytes, not a size field"
    return ""


def maximum(size: int) -> int:
    """The largest value a field of `size` bytes holds."""
    return (1 << (7 * size)) - 1


def marks(size: int) -> int:
    """Bit 7 of every byte of the wire word: set in none of a valid frame's."""
    return sum(0x80 << (8 * i) for i in range(size))


def _parts(size: int) -> list[tuple[int, int]]:
    """(shift, mask of the value's bits) of each byte: byte i holds value bits 7i..7i+6 at wire bits 8i..8i+6."""
    return [(i, 0x7F << (7 * i)) for i in range(size)]


# --- runtime ---------------------------------------------------------------------------------------------------------


def gather(raw: int, size: int) -> int:
    """The value of a wire word (its bit 7s clear)."""
    return sum((raw >> shift) & mask for shift, mask in _parts(size))


def spread(value: int, size: int) -> int:
    """The wire word of a value (0..maximum(size))."""
    return sum((value << shift) & (mask << shift) for shift, mask in _parts(size))


def text_of(data: bytes) -> str:
    """The text of the wire bytes; ValueError (the reason) for an odd count or a byte with bit 7 set."""
    if len(data) % 2:
        raise ValueError(f"{len(data)} bytes: an odd count (two bytes a character)")
    for i, byte in enumerate(data):
        if byte & 0x80:
            raise ValueError(f"bit 7 of byte {i} is set ({byte:#04x}): not a 7-bit byte")
    text = "".join(chr(data[i] | data[i + 1] << 7) for i in range(0, len(data), 2))
    try:
        text.encode()
    except UnicodeEncodeError as exc:  # a lone surrogate (D800..DFFF) is not a character of text
        raise ValueError(f"character {exc.start} is a surrogate ({ord(text[exc.start]):#x})") from None
    return text


def text_bytes(text: str) -> bytes:
    """The wire bytes of text; ValueError (the reason) for a character past 14 bits."""
    out = bytearray()
    for i, char in enumerate(text):
        point = ord(char)
        if point > TEXT_MAXIMUM or 0xD800 <= point <= 0xDFFF:
            raise ValueError(f"character {i} ({char!r}, {point:#x}) is not a 14-bit character")
        out += bytes((point & 0x7F, point >> 7))
    return bytes(out)


def SevenBit(subcon: Any, size: int) -> Any:  # noqa: N802 (a construct, named as construct's are)
    """The construct adapter of a field: `SevenBit(Int16ul, 2)` (generated structs.py); construct is imported by
    those structs alone, so here only when one is built."""
    from construct import Adapter, ValidationError

    class _SevenBit(Adapter):  # type: ignore[misc, type-arg, unused-ignore]
        def _decode(self, obj: int, context: Any, path: Any) -> int:
            if obj & marks(size):
                raise ValidationError(f"bit 7 of a byte is set ({obj:#x}): not a 7-bit value", path=path)
            return gather(obj, size)

        def _encode(self, obj: int, context: Any, path: Any) -> int:
            if not 0 <= obj <= maximum(size):
                raise ValidationError(f"{obj} is outside 0..{maximum(size)}", path=path)
            return spread(obj, size)

    return _SevenBit(subcon)


def SevenBitText(subcon: Any) -> Any:  # noqa: N802 (a construct, named as construct's are)
    """The construct adapter of a string of 14-bit characters: `SevenBitText(GreedyBytes)`."""
    from construct import Adapter, ValidationError

    class _SevenBitText(Adapter):  # type: ignore[misc, type-arg, unused-ignore]
        def _decode(self, obj: bytes, context: Any, path: Any) -> str:
            try:
                return text_of(obj)
            except ValueError as exc:
                raise ValidationError(str(exc), path=path) from None

        def _encode(self, obj: str, context: Any, path: Any) -> bytes:
            try:
                return text_bytes(obj)
            except ValueError as exc:
                raise ValidationError(str(exc), path=path) from None

    return _SevenBitText(subcon)


# --- code of each backend --------------------------------------------------------------------------------------------


def python_decode(raw: str, size: int) -> str:
    """A Python expression of the value, from `raw`, the wire word (a local name)."""
    return " | ".join(
        f"{raw} >> {shift} & {mask:#x}" if shift else f"{raw} & {mask:#x}" for shift, mask in _parts(size)
    )


def python_encode(value: str, size: int) -> str:
    """A Python expression of the wire word, from `value` (an expression, checked to be in range)."""
    parts = [
        f"{value} << {shift} & {mask << shift:#x}" if shift else f"{value} & {mask:#x}" for shift, mask in _parts(size)
    ]
    return "(" + " | ".join(parts) + ")"


def c_decode(raw: str, size: int) -> str:
    """A C expression of the value (unsigned long), from `raw`, the wire word (an unsigned expression)."""
    return "(" + " | ".join(f"(({raw} >> {shift}) & 0x{mask:x}UL)" for shift, mask in _parts(size)) + ")"


def c_encode(value: str, size: int) -> str:
    """A C expression of the wire word (uint32_t), from `value`, an unsigned value in range."""
    parts = [f"(((uint32_t){value} << {shift}) & 0x{mask << shift:x}UL)" for shift, mask in _parts(size)]
    return "(" + " | ".join(parts) + ")"


#: The Wireshark dissector's function (arithmetic only: Wireshark's Lua may be 5.2, without bitwise operators): the
#: value of a wire word of `size` bytes, nil when a byte has bit 7 set.
LUA = """local function seven_bit(raw, size)
  local value = 0
  for i = 0, size - 1 do
    local byte = math.floor(raw / 256 ^ i) % 256
    if byte > 0x7F then return nil end
    value = value + byte * 128 ^ i
  end
  return value
end"""


#: The Wireshark dissector's function for text of 14-bit characters: the text (UTF-8) of `raw` (a Lua string of the
#: wire bytes), nil when a byte has bit 7 set or the count is odd.
LUA_TEXT = """local function seven_bit_text(raw)
  if #raw % 2 == 1 then return nil end
  local out = {}
  for i = 1, #raw, 2 do
    local low, high = raw:byte(i), raw:byte(i + 1)
    if low > 0x7F or high > 0x7F then return nil end
    local point = low + high * 128
    if point < 0x80 then
      out[#out + 1] = string.char(point)
    elseif point < 0x800 then
      out[#out + 1] = string.char(0xC0 + math.floor(point / 64), 0x80 + point % 64)
    else
      local middle = 0x80 + math.floor(point / 64) % 64
      out[#out + 1] = string.char(0xE0 + math.floor(point / 4096), middle, 0x80 + point % 64)
    end
  end
  return table.concat(out)
end"""

#: The C helper decoding such text (`P` the protocol's prefix): the characters of `n` wire bytes as UTF-8 in `dst`
#: (`cap` bytes, NUL-terminated), its length in `*len`; 0 when a byte has bit 7 set, the count is odd, a character
#: is a surrogate, or the text does not fit.
C_TEXT_GET = """static int P__text14_get(char *dst, size_t cap, size_t *len, const uint8_t *src, size_t n)
{
    size_t i, k = 0u;
    if (n % 2u) {
        return 0;
    }
    for (i = 0u; i < n; i += 2u) {
        uint32_t point;
        if ((src[i] | src[i + 1u]) & 0x80u) {
            return 0;
        }
        point = (uint32_t)src[i] | ((uint32_t)src[i + 1u] << 7);
        if (point >= 0xD800UL && point <= 0xDFFFUL) {
            return 0;
        }
        if (point < 0x80UL) {
            if (cap - k < 2u) {
                return 0;
            }
            dst[k++] = (char)point;
        } else if (point < 0x800UL) {
            if (cap - k < 3u) {
                return 0;
            }
            dst[k++] = (char)(0xC0UL | (point >> 6));
            dst[k++] = (char)(0x80UL | (point & 0x3FUL));
        } else {
            if (cap - k < 4u) {
                return 0;
            }
            dst[k++] = (char)(0xE0UL | (point >> 12));
            dst[k++] = (char)(0x80UL | ((point >> 6) & 0x3FUL));
            dst[k++] = (char)(0x80UL | (point & 0x3FUL));
        }
    }
    dst[k] = '\\0';
    *len = k;
    return 1;
}"""

#: The C helper encoding such text: the wire bytes of `n` bytes of UTF-8 text written to `dst` (NULL: only counted);
#: their count, or (size_t)-1 when the text is not UTF-8 of 14-bit characters (the encoder's range check).
C_TEXT_PUT = """static size_t P__text14_put(uint8_t *dst, const char *src, size_t n)
{
    const uint8_t *s = (const uint8_t *)src;
    size_t i = 0u, k = 0u, more;
    while (i < n) {
        uint32_t point;
        if (s[i] < 0x80u) {
            point = s[i];
            more = 0u;
        } else if ((s[i] & 0xE0u) == 0xC0u) {
            point = s[i] & 0x1Fu;
            more = 1u;
        } else if ((s[i] & 0xF0u) == 0xE0u) {
            point = s[i] & 0x0Fu;
            more = 2u;
        } else {
            return (size_t)-1;
        }
        if (n - i <= more) {
            return (size_t)-1;
        }
        for (i++; more > 0u; more--, i++) {
            if ((s[i] & 0xC0u) != 0x80u) {
                return (size_t)-1;
            }
            point = (point << 6) | (s[i] & 0x3Fu);
        }
        if (point > 0x3FFFUL || (point >= 0xD800UL && point <= 0xDFFFUL)) {
            return (size_t)-1;
        }
        if (dst != NULL) {
            dst[k] = (uint8_t)(point & 0x7Fu);
            dst[k + 1u] = (uint8_t)(point >> 7);
        }
        k += 2u;
    }
    return k;
}"""
