"""`algorithm: xor`: the XOR of the covered bytes, or of the covered data as big-endian words of the checksum's size."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from serialspec.checksums.base import Algorithm, CCode, Import, Report, Sample, c_uint, hex_value


def xor_function(width: int) -> Callable[[bytes], int]:
    """XOR of the bytes (width 8), or of the data taken as big-endian words of width / 8 bytes (the last one padded
    with zero bytes)."""
    if width == 8:

        def xor8(data: bytes) -> int:
            value = 0
            for byte in data:
                value ^= byte
            return value

        return xor8
    size = width // 8

    def xor(data: bytes) -> int:
        value = 0
        padded = data + bytes(-len(data) % size)
        for i in range(0, len(padded), size):
            value ^= int.from_bytes(padded[i : i + size], "big")
        return value

    return xor


@dataclass(frozen=True)
class Xor(Algorithm):
    width: int

    name = "xor"
    summary = "the XOR of the bytes (of big-endian words as wide as the checksum, when it is wider than a byte)"
    samples = (Sample("8-bit XOR", "u8"), Sample("16-bit XOR of words", "u16"))

    @classmethod
    def from_spec(cls, raw: Mapping[str, Any], size: int, type_name: str, report: Report) -> Xor:
        return cls(size * 8)

    def function(self) -> Callable[[bytes], int]:
        return xor_function(self.width)

    def function_code(self) -> tuple[Import, str]:
        return ("serialspec.checksums.xor", "xor_function"), f"xor_function({self.width})"

    def c_code(self, prefix: str) -> CCode:
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
            return CCode(name, "uint8_t", body, prototype, "0u", "(uint32_t)({a})")
        size = self.width // 8
        t = c_uint(self.width)
        name = f"{prefix}_xor{self.width}"
        body = f"""/* XOR of the bytes taken as big-endian {self.width}-bit words, the last padded with zeros.
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
        return CCode(name, t, body, prototype, "0u", "(uint32_t)({a})")

    @classmethod
    def lua_function(cls) -> str:
        return _LUA

    def describe(self) -> str:
        if self.width == 8:
            return "XOR of the covered bytes"
        return f"XOR of the covered bytes taken as big-endian {self.width}-bit words (the last padded with zeros)"

    def worked(self, covered: bytes) -> str:
        size = self.width // 8
        padded = covered + bytes(-len(covered) % size)
        words = [int.from_bytes(padded[i : i + size], "big") for i in range(0, len(padded), size)]
        terms = " ^ ".join(hex_value(w, self.width) for w in words) or "0"
        return f"{terms} = {hex_value(self.function()(covered), self.width)}"


# the dissector's code (Algorithm.lua_function): words of `size` bytes, high byte first, the last one zero-padded
_LUA = """function(spec, size, data)
  local total = 0
  for i = 1, #data, size do
    local word = 0
    for j = i, i + size - 1 do
      word = word * 256 + (data:byte(j) or 0)
    end
    total = bxor(total, word)
  end
  return total
end"""
