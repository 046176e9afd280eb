"""`algorithm: xor`: the XOR of the covered bytes, or of the covered data as words of the checksum's size in the
checksum's byte order (so each byte sent is the XOR of the bytes at its place in the words: the hoverboard firmware's
`start ^ steer ^ speed` of little-endian u16s), optionally inverted, then optionally masked (HerkuleX: `& 0xFE`)."""

from __future__ import annotations

from collections.abc import Callable, Mapping

from serialspec.checksums.base import (
    INVERT,
    MASK,
    Algorithm,
    CCode,
    Import,
    Report,
    Sample,
    c_finish,
    c_uint,
    finish,
    finish_problem,
    hex_value,
)
from serialspec.runtime.values import dataclass

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any, Literal


def xor_function(
    width: int, invert: bool = False, mask: int | None = None, little: bool = False
) -> Callable[[bytes], int]:
    """XOR of the bytes (width 8), or of the data taken as words of width / 8 bytes, big-endian (little-endian with
    `little`), the last one padded with zero bytes; optionally inverted, then ANDed with `mask`."""
    if invert or mask is not None:
        plain = xor_function(width, little=little)
        return lambda data: finish(plain(data), width, invert, False, mask)
    if width == 8:

        def xor8(data: bytes) -> int:
            value = 0
            for byte in data:
                value ^= byte
            return value

        return xor8
    size = width // 8
    order: Literal["little", "big"] = "little" if little else "big"

    def xor(data: bytes) -> int:
        value = 0
        padded = data + bytes(-len(data) % size)
        for i in range(0, len(padded), size):
            value ^= int.from_bytes(padded[i : i + size], order)
        return value

    return xor


@dataclass(frozen=True)
class Xor(Algorithm):
    width: int
    invert: bool = False
    mask: int | None = None  # ANDed with the result (None: none beyond the width)
    little: bool = False  # words little-endian (the element's byte order), when wider than a byte

    name = "xor"
    summary = (
        "the XOR of the bytes (of words as wide as the checksum in its byte order, when it is wider than a byte: each "
        "byte sent is the XOR of the bytes at its place in the words)"
    )
    keys = (INVERT, MASK)
    samples = (
        Sample("8-bit XOR", "u8"),
        Sample("8-bit XOR, masked (HerkuleX)", "u8", {"mask": 0xFE}),
        Sample("8-bit inverted XOR", "u8", {"invert": True}),
        Sample("16-bit XOR of words (little-endian, the element's default)", "u16"),
        Sample("16-bit XOR of big-endian words", "u16", {"endian": "big"}),
    )

    @classmethod
    def from_spec(cls, raw: Mapping[str, Any], size: int, type_name: str, report: Report, bits: int = 0) -> Xor:
        problem = finish_problem({**raw, "negate": False}, size * 8)
        if problem is not None:
            raise problem
        little = size > 1 and raw.get("endian", "little") == "little"  # an element's default byte order: little
        return cls(size * 8, bool(raw.get("invert", False)), raw.get("mask"), little)

    def function(self) -> Callable[[bytes], int]:
        return xor_function(self.width, self.invert, self.mask, self.little)

    def function_code(self) -> tuple[Import, str]:
        extra = (", invert=True" if self.invert else "") + (f", mask={self.mask:#x}" if self.mask is not None else "")
        extra += ", little=True" if self.little else ""
        return ("serialspec.checksums.xor", "xor_function"), f"xor_function({self.width}{extra})"

    def c_code(self, prefix: str) -> CCode:
        whole = (1 << self.width) - 1 & (self.mask if self.mask is not None else -1)
        plain = not self.invert and self.mask is None
        finish = "(uint32_t)({a})" if plain else c_finish("~" if self.invert else "", whole)
        if self.width == 8:
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
            return CCode(name, "uint8_t", body, prototype, "0u", finish)
        size = self.width // 8
        t = c_uint(self.width)
        name = f"{prefix}_xor{self.width}"
        order = "little" if self.little else "big"
        shift = (
            "word |= (uint32_t)(i + k < n ? data[i + k] : 0u) << (8u * k);"
            if self.little
            else ("word = (word << 8) | (i + k < n ? data[i + k] : 0u);")
        )
        body = f"""/* XOR of the bytes taken as {order}-endian {self.width}-bit words, the last padded with zeros.
 * Incremental in pieces of whole words: start with 0. */
{t} {name}({t} acc, const uint8_t *data, size_t n)
{{
    uint32_t x = acc;
    size_t i, k;
    for (i = 0; i < n; i += {size}u) {{
        uint32_t word = 0u;
        for (k = 0; k < {size}u; k++) {{
            {shift}
        }}
        x ^= word;
    }}
    return ({t})x;
}}
"""
        prototype = f"{t} {name}({t} acc, const uint8_t *data, size_t n);"
        return CCode(name, t, body, prototype, "0u", finish)

    @classmethod
    def lua_function(cls) -> str:
        return _LUA

    def lua_parameters(self) -> dict[str, Any]:
        return {"invert": self.invert, "little": self.little} | ({} if self.mask is None else {"mask": self.mask})

    def describe(self) -> str:
        what = "bitwise NOT of the XOR" if self.invert else "XOR"
        masked = f", ANDed with {hex_value(self.mask, self.width)}" if self.mask is not None else ""
        if self.width == 8:
            return f"{what} of the covered bytes{masked}"
        words = f"{'little' if self.little else 'big'}-endian {self.width}-bit words (the last padded with zeros)"
        return f"{what} of the covered bytes taken as {words}{masked}"

    def parameters(self) -> list[tuple[str, str]]:
        return [("mask", hex_value(self.mask, self.width))] if self.mask is not None else []

    def worked(self, covered: bytes) -> str:
        size = self.width // 8
        padded = covered + bytes(-len(covered) % size)
        order: Literal["little", "big"] = "little" if self.little else "big"
        words = [int.from_bytes(padded[i : i + size], order) for i in range(0, len(padded), size)]
        terms = " ^ ".join(hex_value(w, self.width) for w in words) or "0"
        if self.invert or self.mask is not None:
            sign = "~" if self.invert else ""
            masked = f" & {hex_value(self.mask, self.width)}" if self.mask is not None else ""
            terms = f"{sign}({terms}){masked}"
        return f"{terms} = {hex_value(self.function()(covered), self.width)}"


# the dissector's code (Algorithm.lua_function): words of `size` bytes, high byte first (low byte first with
# `little`), the last one zero-padded
_LUA = """function(spec, size, data)
  local total = 0
  for i = 1, #data, size do
    local word, place = 0, 1
    for j = i, i + size - 1 do
      if spec.little then
        word = word + (data:byte(j) or 0) * place
        place = place * 256
      else
        word = word * 256 + (data:byte(j) or 0)
      end
    end
    total = bxor(total, word)
  end
  if spec.invert then
    total = width_mask(size * 8) - total
  end
  return spec.mask and band(total, spec.mask) or total
end"""
