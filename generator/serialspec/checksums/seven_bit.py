"""A checksum element with `encoding: seven_bit`: any algorithm's value kept to 7 bits a byte of the element and
sent so, bit 7 of every byte clear, in the element's byte order (Dimension Engineering's Kangaroo: a CRC-14 as two
7-bit bytes, low first). The value's low 7 × size bits are kept (a CRC's width must be those bits; a sum or XOR is
taken modulo them); the element holds the wire word (encodings/low_bits.py: value bit b at wire bit b + b // 7).

The wrapped checksum is still a function of the covered bytes, its result the element's wire word: every codec
path, the frame engine and the stream parser read and write the element as plain bytes, and a frame with bit 7 set
in a checksum byte fails its checksum.
"""

from __future__ import annotations

from collections.abc import Callable

from serialspec.checksums.base import Algorithm, CCode, Import, Wrapping, hex_bytes, hex_value
from serialspec.encodings.low_bits import SEVEN_BIT
from serialspec.runtime.values import dataclass

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any, ClassVar


def seven_bit_function(inner: Callable[[bytes], int], size: int) -> Callable[[bytes], int]:
    """`inner`'s value of the covered bytes, its low 7 × size bits spread 7 to a byte (the element's wire word)."""
    return lambda covered: SEVEN_BIT.spread(inner(covered), size)


@dataclass(frozen=True)
class SevenBitWire(Wrapping):
    inner: Algorithm
    size: int  # bytes of the element

    name: ClassVar[str] = "seven_bit"
    registered = False  # made around an algorithm by the framing pass
    summary = "an algorithm's value sent 7 bits a byte"

    @property
    def width(self) -> int:  # type: ignore[override]
        return 8 * self.size  # the wire word's

    def function(self) -> Callable[[bytes], int]:
        return seven_bit_function(self.inner.function(), self.size)

    def function_code(self) -> tuple[Import, str]:
        _, call = self.inner.function_code()
        return ("serialspec.checksums.seven_bit", "seven_bit_function"), f"seven_bit_function({call}, {self.size})"

    def c_code(self, prefix: str) -> CCode:
        """The inner algorithm's incremental C; its finish spreads the value's low bits 7 to a byte."""
        inner = self.inner.c_code(prefix)
        finish = SEVEN_BIT.c_encode(f"({inner.finish})", self.size)
        return CCode(inner.name, inner.ctype, inner.definition, inner.prototype, inner.start, finish, inner.reflects)

    @classmethod
    def lua_function(cls) -> str:
        return _LUA

    def lua_parameters(self) -> dict[str, Any]:
        return {"inner": self.inner_lua()}

    def describe(self) -> str:
        return f"{self.inner.describe()}, sent 7 bits a byte (bit 7 of each clear)"

    def parameters(self) -> list[tuple[str, str]]:
        return [*self.inner.parameters(), ("sent as", f"{self.size} bytes of 7 bits, in the element's byte order")]

    def worked(self, covered: bytes) -> str:
        value = self.inner.function()(covered) & SEVEN_BIT.high(self.size, False)
        return (
            f"{self.title() or self.inner.name} of {hex_bytes(covered)} = {hex_value(value, 7 * self.size)}, "
            f"7 bits a byte: {hex_value(SEVEN_BIT.spread(value, self.size), self.width)}"
        )


# the dissector's code (Algorithm.lua_function): the inner algorithm's function (in CHECKSUMS), its low 7 × size bits
# spread 7 to a byte
_LUA = """function(spec, size, data)
  local value = CHECKSUMS[spec.inner.algorithm](spec.inner, size, data)
  local wire = 0
  for i = 0, size - 1 do
    wire = bor(wire, lshift(band(rshift(value, 7 * i), 0x7F), 8 * i))
  end
  return wire
end"""
