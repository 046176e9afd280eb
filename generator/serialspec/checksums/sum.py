"""`algorithm: sum`: the sum of the covered bytes modulo 2**width, optionally bitwise inverted (one's complement)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from serialspec.checksums.base import Algorithm, CCode, Import, Key, Report, Sample, c_uint, hex_value


def sum_function(width: int, invert: bool) -> Callable[[bytes], int]:
    """Sum of the bytes modulo 2**width, optionally bitwise inverted."""
    mask = (1 << width) - 1
    if invert:
        return lambda data: ~sum(data) & mask
    return lambda data: sum(data) & mask


@dataclass(frozen=True)
class Sum(Algorithm):
    width: int
    invert: bool = False

    name = "sum"
    summary = "the sum of the bytes, modulo 2 to the checksum's bits"
    keys = (Key("invert", "bool", "sum: bitwise NOT of the sum.", default=False),)
    samples = (
        Sample("8-bit sum", "u8"),
        Sample("8-bit inverted sum", "u8", {"invert": True}),
        Sample("16-bit sum", "u16"),
    )

    @classmethod
    def from_spec(cls, raw: Mapping[str, Any], size: int, type_name: str, report: Report) -> Sum:
        return cls(size * 8, bool(raw.get("invert", False)))

    @property
    def mask(self) -> int:
        return (1 << self.width) - 1

    def function(self) -> Callable[[bytes], int]:
        return sum_function(self.width, self.invert)

    def function_code(self) -> tuple[Import, str]:
        return ("serialspec.checksums.sum", "sum_function"), f"sum_function({self.width}, {self.invert})"

    def python_setup(self, name: str) -> tuple[list[Import], list[str]]:
        return [], []  # the built-in sum(), in line

    def python_call(self, name: str) -> str:
        return f"({self.python_sum('{}')})"

    def python_expression(self, name: str, covered: str) -> str:
        return self.python_sum(covered)

    def python_sum(self, covered: str) -> str:
        return f"{'~' if self.invert else ''}sum({covered}) & {self.mask:#x}"

    def byte_total(self, total: str) -> str:
        return f"{'~' if self.invert else ''}({total}) & {self.mask:#x}"

    def frame_test(self, total: str, skipped: int, check: str) -> str | None:
        if self.width != 8:
            return None  # a wider check is more than one byte of the frame's sum
        if self.invert:  # the covered bytes and their inverted sum add up to 0xff
            return f"({total} - {skipped + 0xFF:#x}) & 0xff"
        # the covered bytes sum to the check: the frame to twice the check plus the skipped bytes
        less = f" - {skipped:#x}" if skipped else ""
        return f"({total}{less} - 2 * {check}) & 0xff"

    def summed(self) -> bool | None:
        return self.invert if self.width == 8 else None

    def c_code(self, prefix: str) -> CCode:
        t = c_uint(self.width)
        name = f"{prefix}_sum{self.width}"
        mask = (1 << self.width) - 1
        final = "the sum inverted" if self.invert else "the sum"
        doc = (
            f"/* Sum of the bytes modulo 2^{self.width}. Incremental: start with 0; the frame's checksum is {final}. */"
        )
        body = f"""{doc}
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
        finish = f"(~(uint32_t)({{a}}) & 0x{mask:x}u)" if self.invert else "(uint32_t)({a})"
        prototype = f"{t} {name}({t} acc, const uint8_t *data, size_t n);"
        return CCode(name, t, body, prototype, "0u", finish)

    @classmethod
    def lua_function(cls) -> str:
        return _LUA

    def lua_parameters(self) -> dict[str, Any]:
        return {"invert": self.invert}

    def describe(self) -> str:
        what = "bitwise NOT of the sum" if self.invert else "sum"
        return f"{what} of the covered bytes, modulo {1 << self.width}"

    def worked(self, covered: bytes) -> str:
        invert = "~" if self.invert else ""
        terms = " + ".join(f"0x{b:02X}" for b in covered) or "0"
        return f"{invert}({terms}) = {invert}{sum(covered):#x} → {hex_value(self.function()(covered), self.width)}"


# the dissector's code (Algorithm.lua_function)
_LUA = """function(spec, size, data)
  local mask = width_mask(size * 8)
  local total = 0
  for i = 1, #data do
    total = (total + data:byte(i)) % (mask + 1)
  end
  return spec.invert and mask - total or total
end"""
