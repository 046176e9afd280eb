"""`encoding: seven_bit`: an unsigned integer sent 7 bits a byte, bit 7 of every byte clear, the bytes in the field's
byte order (little: the low 7 bits first). A u16 holds 0..16383: Pololu Maestro targets, speeds and accelerations,
MIDI pitch bend; a u24 0..2097151. Decoding refuses a byte with bit 7 set (on such links that bit marks a command
byte); encoding refuses a value past the range before a byte is written, naming the field and its range.

Everything of the encoding is here: the grammar's text, the spec check, the runtime's arithmetic (`gather`,
`spread`, the construct adapter), and the code each backend writes (Python, C and Lua expressions, the markdown
type note). The wire word is the field's plain unsigned integer; bit b of the value sits at bit b + b // 7 of it.
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
