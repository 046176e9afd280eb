"""`algorithm: fletcher`: Fletcher's checksum, two 8-bit running sums over the covered bytes.

CK_A is the sum of the bytes and CK_B the sum of CK_A after each byte, each modulo 256 (u-blox UBX's "8-bit
Fletcher", the default) or 255 (`modulus: 255`: Fletcher-16 of RFC 1146). The checksum's value is CK_B << 8 | CK_A,
so a little-endian u16 element (the default) sends CK_A first, as UBX does; `endian: big` sends CK_B first.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from itertools import accumulate

from serialspec.checksums.base import (
    Algorithm,
    CCode,
    ChecksumProblem,
    Import,
    Key,
    Report,
    Sample,
    hex_bytes,
    hex_value,
)
from serialspec.runtime.values import dataclass

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any


def fletcher_function(modulus: int) -> Callable[[bytes], int]:
    """CK_B << 8 | CK_A of the bytes: CK_A their sum, CK_B the sum of the running CK_A, each modulo `modulus`.
    The sums are taken whole (in C) and reduced once: reducing each step gives the same remainders."""

    def fletcher(data: bytes) -> int:
        return sum(accumulate(data)) % modulus << 8 | sum(data) % modulus

    return fletcher


@dataclass(frozen=True)
class Fletcher(Algorithm):
    modulus: int = 256
    width: int = 16

    name = "fletcher"
    summary = "Fletcher's two 8-bit running sums, CK_B << 8 | CK_A (u-blox UBX; a little-endian u16 sends CK_A first)"
    keys = (
        Key(
            "modulus",
            "int",
            "fletcher: 256 (u-blox UBX's 8-bit Fletcher) or 255 (Fletcher-16 of RFC 1146).",
            default=256,
            example=255,
            minimum=255,
            maximum=256,
        ),
    )
    samples = (
        Sample("8-bit Fletcher (UBX)", "u16"),
        Sample("Fletcher-16, modulo 255", "u16", {"modulus": 255}),
    )

    @classmethod
    def from_spec(cls, raw: Mapping[str, Any], size: int, type_name: str, report: Report, bits: int = 0) -> Fletcher:
        if size != 2:
            raise ChecksumProblem(("type",), f"a Fletcher checksum is two bytes (CK_A, CK_B): u16, not {type_name}")
        if bits:
            raise ChecksumProblem(("encoding",), "a Fletcher checksum's two sums are whole bytes: not 7 bits a byte")
        return cls(int(raw.get("modulus", 256)))

    def function(self) -> Callable[[bytes], int]:
        return fletcher_function(self.modulus)

    def function_code(self) -> tuple[Import, str]:
        return ("serialspec.checksums.fletcher", "fletcher_function"), f"fletcher_function({self.modulus})"

    def c_code(self, prefix: str) -> CCode:
        m = self.modulus
        name = f"{prefix}_fletcher{m}"
        body = f"""/* Fletcher modulo {m}: CK_A the sum of the bytes, CK_B the sum of CK_A after each byte; the value is
 * CK_B << 8 | CK_A. Incremental: acc holds CK_B << 8 | CK_A, start with 0. */
uint16_t {name}(uint16_t acc, const uint8_t *data, size_t n)
{{
    uint32_t a = acc & 0xFFu, b = (uint32_t)acc >> 8;
    size_t i;
    for (i = 0; i < n; i++) {{
        a = (a + data[i]) % {m}u;
        b = (b + a) % {m}u;
    }}
    return (uint16_t)((b << 8) | a);
}}
"""
        prototype = f"uint16_t {name}(uint16_t acc, const uint8_t *data, size_t n);"
        return CCode(name, "uint16_t", body, prototype, "0u", "(uint32_t)({a})")

    @classmethod
    def lua_function(cls) -> str:
        return _LUA

    def lua_parameters(self) -> dict[str, Any]:
        return {"modulus": self.modulus}

    def describe(self) -> str:
        return (
            f"Fletcher checksum modulo {self.modulus} over the covered bytes: CK_A the sum of the bytes, CK_B the "
            "sum of CK_A after each byte; its value is CK_B << 8 | CK_A"
        )

    def worked(self, covered: bytes) -> str:
        value = self.function()(covered)
        sums = f"CK_A = 0x{value & 0xFF:02X}, CK_B = 0x{value >> 8:02X}"
        return f"over {hex_bytes(covered)}: {sums} → {hex_value(value, 16)}"


# the dissector's code (Algorithm.lua_function): CK_B << 8 | CK_A
_LUA = """function(spec, size, data)
  local a, b = 0, 0
  for i = 1, #data do
    a = (a + data:byte(i)) % spec.modulus
    b = (b + a) % spec.modulus
  end
  return b * 256 + a
end"""
