"""`algorithm: sum`: the sum of the covered bytes modulo 2**width, optionally inverted (one's complement) or negated
(two's complement), then optionally masked (HerkuleX: `& 0xFE`). With `end_around_carry`, each carry out of the top
bit is added back in (one's complement addition, FrSky S.Port: `0xFF - sum`, the sum folded at each byte). With
`init`, the sum starts from that value instead of 0 (Victron VE.Direct HEX: the checksum makes the bytes sum to
0x55, `0x55 - sum`, which is the sum from 0xAB negated)."""

from __future__ import annotations

from collections.abc import Callable, Mapping

from serialspec.checksums.base import (
    INVERT,
    MASK,
    Algorithm,
    CCode,
    ChecksumProblem,
    Import,
    Key,
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
    from typing import Any


def sum_function(
    width: int,
    invert: bool,
    negate: bool = False,
    mask: int | None = None,
    end_around_carry: bool = False,
    init: int = 0,
) -> Callable[[bytes], int]:
    """Sum of the bytes from `init`, modulo 2**width (or with end-around carry), optionally bitwise inverted or
    negated, then ANDed with `mask`."""
    whole = (1 << width) - 1 & (mask if mask is not None else -1)
    if end_around_carry:
        return lambda data: finish(folded(init + sum(data), width), width, invert, negate, mask)
    if invert:
        return lambda data: ~(init + sum(data)) & whole
    if negate:
        return lambda data: -(init + sum(data)) & whole
    return lambda data: (init + sum(data)) & whole


def folded(total: int, width: int) -> int:
    """A sum of bytes with each carry out of the top of `width` bits added back in, as adding them one at a time
    does: 0 for no bytes or zeros, else the value in 1..2**width-1 congruent to it modulo 2**width-1."""
    top = (1 << width) - 1
    return (total - 1) % top + 1 if total else 0


END_AROUND = Key(
    "end_around_carry",
    "bool",
    "sum: each carry out of the top bit is added back in (one's complement addition: FrSky S.Port's checksum, "
    "`invert: true` on a u8, is 0xFF minus the bytes' sum folded so at each byte).",
    default=False,
    example=True,
)


@dataclass(frozen=True)
class Sum(Algorithm):
    width: int
    invert: bool = False
    negate: bool = False
    mask: int | None = None  # ANDed with the result (None: none beyond the width)
    end_around_carry: bool = False  # each carry out of the top bit added back in
    init: int = 0  # the value the sum starts from

    name = "sum"
    summary = "the sum of the bytes, modulo 2 to the checksum's bits"
    keys = (
        INVERT,
        Key("negate", "bool", "sum: the sum negated (two's complement).", default=False, example=True),
        MASK,
        END_AROUND,
        Key(
            "init",
            "int",
            "sum: the value the sum starts from before the covered bytes are added (default 0), then inverted, "
            "negated or masked as asked. Victron VE.Direct HEX makes the bytes and the checksum sum to 0x55: "
            "`negate: true, init: 0xAB` (0x55 - sum = -(0xAB + sum) modulo 256).",
            default=0,
            example=0xAB,
            minimum=0,
        ),
    )
    samples = (
        Sample("8-bit sum", "u8"),
        Sample("8-bit inverted sum", "u8", {"invert": True}),
        Sample("8-bit negated sum (two's complement)", "u8", {"negate": True}),
        Sample("8-bit inverted sum, masked", "u8", {"invert": True, "mask": 0xFE}),
        Sample("16-bit sum", "u16"),
        Sample(
            "8-bit sum with end-around carry, inverted (FrSky S.Port)", "u8", {"invert": True, "end_around_carry": True}
        ),
        Sample("16-bit sum with end-around carry", "u16", {"end_around_carry": True}),
        Sample(
            "8-bit negated sum from 0xAB (Victron VE.Direct HEX, the bytes and the checksum summing to 0x55)",
            "u8",
            {"negate": True, "init": 0xAB},
        ),
    )

    @classmethod
    def from_spec(cls, raw: Mapping[str, Any], size: int, type_name: str, report: Report, bits: int = 0) -> Sum:
        problem = finish_problem(raw, size * 8)
        if problem is not None:
            raise problem
        end_around = bool(raw.get("end_around_carry", False))
        init = raw.get("init", 0)
        if not 0 <= init < 1 << size * 8:
            raise ChecksumProblem(("init",), f"init {init:#x} does not fit the checksum's {size * 8} bits")
        return cls(
            size * 8, bool(raw.get("invert", False)), bool(raw.get("negate", False)), raw.get("mask"), end_around, init
        )

    @property
    def whole(self) -> int:
        """The mask of the result: the width's, and `mask` within it."""
        return (1 << self.width) - 1 & (self.mask if self.mask is not None else -1)

    @property
    def sign(self) -> str:
        return "~" if self.invert else "-" if self.negate else ""

    def function(self) -> Callable[[bytes], int]:
        return sum_function(self.width, self.invert, self.negate, self.mask, self.end_around_carry, self.init)

    def function_code(self) -> tuple[Import, str]:
        extra = (", negate=True" if self.negate else "") + (f", mask={self.mask:#x}" if self.mask is not None else "")
        extra += ", end_around_carry=True" if self.end_around_carry else ""
        extra += f", init={self.init:#x}" if self.init else ""
        return ("serialspec.checksums.sum", "sum_function"), f"sum_function({self.width}, {self.invert}{extra})"

    # With end-around carry the codec calls the runtime function (the base class's), which folds the sum once.

    def python_setup(self, name: str) -> tuple[list[Import], list[str]]:
        if self.end_around_carry:
            return super().python_setup(name)
        return [], []  # the built-in sum(), in line

    def python_call(self, name: str) -> str:
        if self.end_around_carry:
            return super().python_call(name)
        return f"({self.python_sum('{}')})"

    def python_calls_function(self) -> bool:
        return self.end_around_carry

    def python_expression(self, name: str, covered: str) -> str:
        if self.end_around_carry:
            return self.python_call(name).format(covered)
        return self.python_sum(covered)

    def python_sum(self, covered: str) -> str:
        if self.init:
            return f"{self.sign}({self.init:#x} + sum({covered})) & {self.whole:#x}"
        return f"{self.sign}sum({covered}) & {self.whole:#x}"

    def byte_total(self, total: str) -> str | None:
        if self.end_around_carry:
            return None
        if self.init:
            return f"{self.sign}({self.init:#x} + {total}) & {self.whole:#x}"
        return f"{self.sign}({total}) & {self.whole:#x}"

    def frame_test(self, total: str, skipped: int, check: str) -> str | None:
        if self.width != 8 or self.mask is not None or self.end_around_carry or self.init:
            return None  # a wider check is more than one byte of the frame's sum; a mask loses bits
        if self.invert:  # the covered bytes and their inverted sum add up to 0xff
            return f"({total} - {skipped + 0xFF:#x}) & 0xff"
        if self.negate:  # the covered bytes and their negated sum add up to 0
            return f"({total} - {skipped:#x}) & 0xff" if skipped else f"{total} & 0xff"
        # the covered bytes sum to the check: the frame to twice the check plus the skipped bytes
        less = f" - {skipped:#x}" if skipped else ""
        return f"({total}{less} - 2 * {check}) & 0xff"

    def summed(self) -> bool | None:
        plain = not self.negate and self.mask is None and not self.end_around_carry and not self.init
        return self.invert if self.width == 8 and plain else None

    def c_code(self, prefix: str) -> CCode:
        t = c_uint(self.width)
        name = f"{prefix}_sum{self.width}" + ("_folded" if self.end_around_carry else "")
        mask = (1 << self.width) - 1
        final = "the sum inverted" if self.invert else "the sum negated" if self.negate else "the sum"
        final += f", ANDed with 0x{self.mask:x}" if self.mask is not None else ""
        how = "with each carry out of the top bit added back in" if self.end_around_carry else f"modulo 2^{self.width}"
        doc = f"/* Sum of the bytes {how}. Incremental: start with 0 (or `init`); the frame's checksum is {final}. */"
        step = (
            f"s = (s & 0x{mask:x}u) + (s >> {self.width}); /* the carry, added back in */"
            if self.end_around_carry
            else ""
        )
        body = f"""{doc}
{t} {name}({t} acc, const uint8_t *data, size_t n)
{{
    uint32_t s = acc;
    size_t i;
    for (i = 0; i < n; i++) {{
        s += data[i];{chr(10) + "        " + step if step else ""}
    }}
    return ({t})(s & 0x{mask:x}u);
}}
"""
        finish = c_finish(self.sign, self.whole)
        prototype = f"{t} {name}({t} acc, const uint8_t *data, size_t n);"
        return CCode(name, t, body, prototype, f"0x{self.init:x}u" if self.init else "0u", finish)

    @classmethod
    def lua_function(cls) -> str:
        return _LUA

    def lua_parameters(self) -> dict[str, Any]:
        masked = {} if self.mask is None else {"mask": self.mask}
        folded = {"end_around_carry": True} if self.end_around_carry else {}
        started = {"init": self.init} if self.init else {}
        return {"invert": self.invert, "negate": self.negate} | masked | folded | started

    def describe(self) -> str:
        what = "bitwise NOT of the sum" if self.invert else "two's complement of the sum" if self.negate else "sum"
        masked = f", ANDed with {hex_value(self.mask, self.width)}" if self.mask is not None else ""
        start = f" from {hex_value(self.init, self.width)}" if self.init else ""
        if self.end_around_carry:
            return f"{what} of the covered bytes{start}, each carry out of bit {self.width - 1} added back in{masked}"
        return f"{what} of the covered bytes{start}, modulo {1 << self.width}{masked}"

    def parameters(self) -> list[tuple[str, str]]:
        shown = [("mask", hex_value(self.mask, self.width))] if self.mask is not None else []
        return shown + ([("init", hex_value(self.init, self.width))] if self.init else [])

    def worked(self, covered: bytes) -> str:
        sign = self.sign
        terms = " + ".join(
            [*([hex_value(self.init, self.width)] if self.init else []), *(f"0x{b:02X}" for b in covered)]
        )
        terms = terms or "0"
        masked = f" & {hex_value(self.mask, self.width)}" if self.mask is not None else ""
        plain = self.init + sum(covered)
        total = folded(plain, self.width) if self.end_around_carry else plain
        value = hex_value(finish(total, self.width, self.invert, self.negate, self.mask), self.width)
        if self.end_around_carry:
            return f"{sign}fold({terms}){masked} = {sign}fold({plain:#x}) = {sign}{total:#x}{masked} → {value}"
        return f"{sign}({terms}){masked} = {sign}{plain:#x}{masked} → {value}"


# the dissector's code (Algorithm.lua_function)
_LUA = """function(spec, size, data)
  local mask = width_mask(size * 8)
  local total = spec.init or 0
  for i = 1, #data do
    total = total + data:byte(i)
    if spec.end_around_carry then
      total = band(total, mask) + rshift(total, size * 8)
    else
      total = total % (mask + 1)
    end
  end
  if spec.invert then
    total = mask - total
  elseif spec.negate then
    total = (mask + 1 - total) % (mask + 1)
  end
  return spec.mask and band(total, spec.mask) or total
end"""
