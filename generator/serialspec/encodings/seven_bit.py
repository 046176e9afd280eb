"""`encoding: seven_bit` on a string (`{type: string, size: rest, encoding: seven_bit}`): text of 14-bit
characters, each character's code point as two 7-bit bytes, low first (Firmata's STRING_DATA and REPORT_FIRMWARE's
name): "Hi" is 48 00 69 00. The string's `size` counts bytes on the wire (two a character); its value is text, as any
string's. Here: the grammar's text, the spec check, the runtime (`text_of`, `text_bytes`, the construct adapter) and
the C and Lua helpers.

On an integer, seven_bit (7 bits a byte, bit 7 clear) is encodings/low_bits.py, with nibbles (4 bits a byte).
"""

from __future__ import annotations

from serialspec.encodings.low_bits import SEVEN_BIT, SevenBit  # noqa: F401 (structs generated before nibbles import it here)

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any

NAME = SEVEN_BIT.name
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
