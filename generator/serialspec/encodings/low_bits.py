"""An integer sent a few bits a byte, the bits above them clear in every byte, the bytes in the field's byte order
(big: the highest group first): `encoding: seven_bit` (7 bits a byte, bit 7 clear: a u16 holds 0..16383; Pololu
Maestro targets, MIDI pitch bend, Firmata) and `encoding: nibbles` (4 bits a byte, the high nibble clear: a u32
holds 0..65535; Sony VISCA's zoom position 0x1234 is 01 02 03 04).

The field's type gives the wire size; the value holds `bits` bits of each byte. On a signed type the value is the
two's complement of the bits it holds: an i32 of nibbles is a 16-bit signed value (-1 is 0F 0F 0F 0F, -32768..32767),
an i16 of seven_bit a 14-bit one (-8192..8191). Decoding refuses a byte with a bit above them set (on such links that
bit marks a command byte); encoding refuses a value past the range before a byte is written, naming the field and
its range.

Everything of these encodings of an integer is here: the grammar's text, the spec check, the runtime's arithmetic
(`gather`, `spread`, the construct adapters) and the code each backend writes (Python, C and Lua expressions, the
markdown type note). The wire word is the field's plain unsigned integer; bit b of the value sits at bit
b + (8 - bits) * (b // bits) of it. (seven_bit on a string, text of 14-bit characters, is encodings/seven_bit.py.)
"""

from __future__ import annotations

from serialspec.runtime.values import dataclass

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any


@dataclass(frozen=True)
class LowBits:
    """One encoding: `bits` value bits in the low bits of each byte."""

    name: str  # the `encoding:` word
    bits: int  # value bits a byte
    flaw: str  # what a refused byte has set ("bit 7"): decode's reason says "<flaw> of a byte of <field> is set"
    construct_name: str  # the construct adapter's name (generated structs import it from here)
    doc: str  # the grammar's words for it (a field's `encoding:` choices)
    type_note: str  # what the markdown reference adds to the field's type

    def problem(self, type_name: str, is_float: bool) -> str:
        """Why a field of this type cannot take the encoding ("" when it can)."""
        return f"encoding {self.name} is for integers, not {type_name}" if is_float else ""

    def low(self, size: int, signed: bool) -> int:
        """The least value a field of `size` bytes holds."""
        return -(1 << (self.bits * size - 1)) if signed else 0

    def high(self, size: int, signed: bool) -> int:
        """The greatest value a field of `size` bytes holds."""
        return (1 << (self.bits * size - signed)) - 1

    def marks(self, size: int) -> int:
        """The bits above the value's in every byte of the wire word: set in none of a valid frame's."""
        above = 0xFF & ~((1 << self.bits) - 1)
        return sum(above << (8 * i) for i in range(size))

    def _parts(self, size: int) -> list[tuple[int, int]]:
        """(shift, mask of the value's bits) of each byte: byte i holds value bits b*i..b*i+b-1 at wire bits 8i.."""
        group = (1 << self.bits) - 1
        return [((8 - self.bits) * i, group << (self.bits * i)) for i in range(size)]

    def _top(self, size: int) -> int:
        """The sign bit of a signed value."""
        return 1 << (self.bits * size - 1)

    # --- runtime -----------------------------------------------------------------------------------------------------

    def gather(self, raw: int, size: int, signed: bool = False) -> int:
        """The value of a wire word (its marks clear)."""
        value = sum((raw >> shift) & mask for shift, mask in self._parts(size))
        return (value ^ self._top(size)) - self._top(size) if signed else value

    def spread(self, value: int, size: int) -> int:
        """The wire word of a value (its low bits × size bits: a negative one's two's complement)."""
        return sum((value << shift) & (mask << shift) for shift, mask in self._parts(size))

    # --- code of each backend ----------------------------------------------------------------------------------------

    def python_decode(self, raw: str, size: int, signed: bool) -> str:
        """A Python expression of the value, from `raw`, the wire word (a local name)."""
        value = " | ".join(
            f"{raw} >> {shift} & {mask:#x}" if shift else f"{raw} & {mask:#x}" for shift, mask in self._parts(size)
        )
        return f"(({value}) ^ {self._top(size):#x}) - {self._top(size):#x}" if signed else value

    def python_encode(self, value: str, size: int) -> str:
        """A Python expression of the wire word, from `value` (an expression, checked to be in range; Python's
        integers make a negative one's two's complement)."""
        parts = [
            f"{value} << {shift} & {mask << shift:#x}" if shift else f"{value} & {mask:#x}"
            for shift, mask in self._parts(size)
        ]
        return "(" + " | ".join(parts) + ")"

    def c_decode(self, raw: str, size: int, signed: bool) -> str:
        """A C expression of the value (unsigned long, long when signed; of an 8-byte word, unsigned long long and
        long long), from `raw`, the wire word (an unsigned expression)."""
        u, s = ("ULL", "LL") if size > 4 else ("UL", "L")
        value = "(" + " | ".join(f"(({raw} >> {shift}) & 0x{mask:x}{u})" for shift, mask in self._parts(size)) + ")"
        top = self._top(size)
        return f"((long{' long' * (size > 4)})({value} ^ 0x{top:x}{u}) - 0x{top:x}{s})" if signed else value

    def c_encode(self, value: str, size: int) -> str:
        """A C expression of the wire word (uint32_t; uint64_t of an 8-byte word), from `value`, a value in range (a
        negative one converted to the unsigned type: its two's complement)."""
        word, u = ("uint64_t", "ULL") if size > 4 else ("uint32_t", "UL")
        parts = [f"((({word}){value} << {shift}) & 0x{mask << shift:x}{u})" for shift, mask in self._parts(size)]
        return "(" + " | ".join(parts) + ")"

    def lua_field(self, signed: bool) -> dict[str, object]:
        """What the dissector's table says of a field (the engine reads it with `low_bits`, LUA)."""
        return {"bits": self.bits, "signed": signed, "flaw": self.flaw}


SEVEN_BIT = LowBits(
    name="seven_bit",
    bits=7,
    flaw="bit 7",
    construct_name="SevenBit",
    doc=(
        "seven_bit (7 bits a byte, bit 7 clear, in the field's byte order: a u16 holds 0..16383, an i16 -8192..8191; "
        "Pololu Maestro's `target: {type: u16, encoding: seven_bit}` sends 6000 as 70 2E)"
    ),
    type_note=" (7 bits a byte)",
)
NIBBLES = LowBits(
    name="nibbles",
    bits=4,
    flaw="the high nibble",
    construct_name="Nibbles",
    doc=(
        "nibbles (4 bits a byte, the high nibble clear, in the field's byte order, big: the highest nibble first: a "
        "u32 holds 0..65535, a u16 0..255, an i32 -32768..32767; Sony VISCA's `position: {type: u32, encoding: "
        "nibbles}` sends 0x1234 as 01 02 03 04, and an i32's -1 is 0F 0F 0F 0F)"
    ),
    type_note=" (a nibble a byte)",
)
#: Each encoding by its `encoding:` word.
ENCODINGS = {e.name: e for e in (SEVEN_BIT, NIBBLES)}
#: What the grammar adds of signed types.
SIGNED_DOC = (
    "seven_bit and nibbles on a signed type hold the two's complement of the bits they carry (an i32 of nibbles is "
    "16 bits)"
)
#: The language reference's example: (label, fields, what it shows).
VARIANT = (
    "Integers a few bits a byte (`encoding: nibbles`, `encoding: seven_bit`): Sony VISCA's zoom and pan positions, "
    "a MIDI pitch bend",
    {
        "zoom": {"type": "u32", "encoding": "nibbles", "endian": "big"},
        "pan": {"type": "i32", "encoding": "nibbles", "endian": "big"},
        "bend": {"type": "u16", "encoding": "seven_bit", "endian": "little"},
    },
    "`zoom` 0x1234 is sent as 01 02 03 04 (a nibble a byte, the highest first in big-endian order; a u32 holds "
    "0..65535); `pan` -1 as 0F 0F 0F 0F (an i32 of nibbles is a 16-bit two's complement value, -32768..32767); "
    "`bend` 8192 as 00 40 (7 bits a byte, the low ones first). Decoding refuses a byte with a bit above its value's "
    "set (`the high nibble of a byte of zoom is set`), encoding a value outside the range before a byte is written "
    "(`pan = 40000 is outside its range -32768..32767`). Every output takes them: the codec, stream parser, client "
    "and simulator, the construct structs, the markdown reference, C (a u64's or i64's word a uint64_t) and the "
    "Wireshark dissector. Such a field is a plain number: no `const`, `bits`, `flags` or `value`, not a count or "
    "size (each refused in one line).",
)


def _adapter(encoding: LowBits, subcon: Any, size: int, signed: bool) -> Any:
    """The construct adapter of a field; construct is imported by the generated structs alone, so here only when one
    is built."""
    from construct import Adapter, ValidationError

    low, high = encoding.low(size, signed), encoding.high(size, signed)

    class _LowBits(Adapter):  # type: ignore[misc, type-arg, unused-ignore]
        def _decode(self, obj: int, context: Any, path: Any) -> int:
            if obj & encoding.marks(size):
                raise ValidationError(f"{encoding.flaw} of a byte is set ({obj:#x})", path=path)
            return encoding.gather(obj, size, signed)

        def _encode(self, obj: int, context: Any, path: Any) -> int:
            if not low <= obj <= high:
                raise ValidationError(f"{obj} is outside {low}..{high}", path=path)
            return encoding.spread(obj, size)

    return _LowBits(subcon)


def SevenBit(subcon: Any, size: int, signed: bool = False) -> Any:  # noqa: N802 (a construct, named as construct's are)
    """`encoding: seven_bit` in generated structs: `SevenBit(Int16ul, 2)`."""
    return _adapter(SEVEN_BIT, subcon, size, signed)


def Nibbles(subcon: Any, size: int, signed: bool = False) -> Any:  # noqa: N802 (a construct, named as construct's are)
    """`encoding: nibbles` in generated structs: `Nibbles(Int32ub, 4, signed=True)`."""
    return _adapter(NIBBLES, subcon, size, signed)


#: The Wireshark dissector's function (arithmetic only: Wireshark's Lua may be 5.2, without bitwise operators): the
#: value of the field's bytes (`range`, `big`: the highest group first), `e.bits` bits a byte (`e` the field's
#: `low_bits`, LowBits.lua_field), read byte by byte; an 8-byte word's value is a UInt64 (Int64 when signed), as
#: seven_bit's 56 bits pass a Lua number's 53 exact ones (2^56 - 1 would show as 2^56); nil when a byte has a bit
#: above them set.
LUA = """local function low_bits(range, big, e)
  local size = range:len()
  local value = size == 8 and UInt64(0) or 0
  for i = 0, size - 1 do
    local byte = range(big and i or size - 1 - i, 1):uint()
    if byte >= 2 ^ e.bits then return nil end
    value = value * 2 ^ e.bits + byte
  end
  local top = 2 ^ (e.bits * size - 1) -- (a power of two: exact as a number)
  if size == 8 then
    if not e.signed then return value end
    if value >= UInt64(top) then return Int64(value) - Int64(2 * top) end
    return Int64(value)
  end
  if e.signed and value >= top then value = value - 2 * top end
  return value
end"""
