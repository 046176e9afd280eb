"""A checksum element with `seed: per_command`: any algorithm, computed over the covered bytes followed by one byte
that each command gives (`checksum_seed:`), MAVLink's CRC_EXTRA (crc_accumulate(crc_extra) after the payload).

The command's code lies at a fixed offset in the covered bytes (the spec language checks it), so the checksum stays
a function of the covered bytes alone: every codec path, the frame engine and the stream parser call it unchanged.
A code no command has gets no seed byte (the frame then fails as an unknown command, or on its checksum).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from serialspec.checksums.base import Algorithm, CCode, Import, Wrapping, hex_bytes, hex_value
from serialspec.runtime.values import dataclass

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any, ClassVar, Literal


def seeded_function(
    inner: Callable[[bytes], int], offset: int, size: int, little: bool, seeds: Mapping[int, int]
) -> Callable[[bytes], int]:
    """`inner` over the covered bytes and then the seed byte of the code at covered[offset : offset + size]."""
    table = {code: bytes((seed,)) for code, seed in seeds.items()}
    end = offset + size
    order: Literal["little", "big"] = "little" if little else "big"

    def checksum(covered: bytes) -> int:
        return inner(bytes(covered) + table.get(int.from_bytes(covered[offset:end], order), b""))

    return checksum


@dataclass(frozen=True)
class Seeded(Wrapping):
    inner: Algorithm
    offset: int  # of the command's code in the covered bytes
    code_size: int
    little: bool
    seeds: tuple[tuple[int, int], ...]  # (code, seed byte), by code

    name: ClassVar[str] = "seeded"
    registered = False  # made around an algorithm by the framing pass
    summary = "an algorithm with a per-command seed byte after the covered bytes"

    @property
    def width(self) -> int:  # type: ignore[override]
        return self.inner.width

    def function(self) -> Callable[[bytes], int]:
        return seeded_function(self.inner.function(), self.offset, self.code_size, self.little, dict(self.seeds))

    def function_code(self) -> tuple[Import, str]:
        _, call = self.inner.function_code()
        seeds = "{" + ", ".join(f"{code}: {seed}" for code, seed in self.seeds) + "}"
        return ("serialspec.checksums.seed", "seeded_function"), (
            f"seeded_function({call}, {self.offset}, {self.code_size}, {self.little}, {seeds})"
        )

    def c_code(self, prefix: str) -> CCode:
        """The inner algorithm's C (its own copy, named with `<prefix>_seeded`), and a function over the whole
        covered bytes that takes in the seed of the code it finds in them: one call, not incremental."""
        inner = self.inner.c_code(prefix)
        core = self.inner.c_code(f"{prefix}_seeded")
        name = f"{inner.name}_seeded"
        t = inner.ctype
        code = " | ".join(
            f"((uint32_t)data[{self.offset + i}] << {8 * (i if self.little else self.code_size - 1 - i)})"
            for i in range(self.code_size)
        )
        cases = "".join(f"    case {c}u:\n        seed = {s}u;\n        break;\n" for c, s in self.seeds)
        seeds = ", ".join(f"{c}: {s}" for c, s in self.seeds) or "none"
        body = f"""{core.definition}
/* {self.title() or self.inner.name} over the covered bytes, then the seed byte of the command whose code sits at
   offset {self.offset} of them ({self.code_size} byte(s), {"little" if self.little else "big"}-endian); seeds by
   code: {seeds}. Not incremental: call it once, with {inner.start} and all the covered bytes. */
{t} {name}({t} acc, const uint8_t *data, size_t n)
{{
    uint32_t code;
    uint8_t seed;
    acc = {core.name}(acc, data, n);
    if (n < {self.offset + self.code_size}u) {{
        return acc;
    }}
    code = {code};
    switch (code) {{
{cases}    default:
        return acc;
    }}
    return {core.name}(acc, &seed, 1);
}}
"""
        prototype = f"{core.prototype}\n{t} {name}({t} acc, const uint8_t *data, size_t n);"
        return CCode(name, t, body, prototype, inner.start, inner.finish, inner.reflects)

    @classmethod
    def lua_function(cls) -> str:
        return _LUA

    def lua_parameters(self) -> dict[str, Any]:
        return {
            "inner": self.inner_lua(),
            "offset": self.offset,
            "code_size": self.code_size,
            "little": self.little,
            "seeds": dict(self.seeds),
        }

    def describe(self) -> str:
        return f"{self.inner.describe()}, then the command's seed byte (`checksum_seed`)"

    def parameters(self) -> list[tuple[str, str]]:
        seeds = ", ".join(f"{code}: {seed}" for code, seed in self.seeds)
        return [*self.inner.parameters(), ("seed by command code", seeds or "(none)")]

    def worked(self, covered: bytes) -> str:
        code = int.from_bytes(covered[self.offset : self.offset + self.code_size], "little" if self.little else "big")
        seed = dict(self.seeds).get(code)
        if seed is None:
            return self.inner.worked(covered)
        value = self.function()(covered)
        return (
            f"{self.title() or self.inner.name} of {hex_bytes(covered)} then the seed {seed:#04x} of command {code}"
            f" = {hex_value(value, self.width)}"
        )


# the dissector's code (Algorithm.lua_function): the inner algorithm's function (in CHECKSUMS) over the covered bytes
# and the seed byte of the code found in them
_LUA = """function(spec, size, data)
  local code = 0
  for i = 1, spec.code_size do
    local byte = data:byte(spec.offset + i) or 0
    if spec.little then
      code = bor(code, lshift(byte, 8 * (i - 1)))
    else
      code = bor(lshift(code, 8), byte)
    end
  end
  local seed = spec.seeds[code]
  if seed ~= nil and #data >= spec.offset + spec.code_size then
    data = data .. string.char(seed)
  end
  return CHECKSUMS[spec.inner.algorithm](spec.inner, size, data)
end"""
