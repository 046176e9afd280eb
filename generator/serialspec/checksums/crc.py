"""`algorithm: crc`: a CRC by its catalogue parameters (width, poly, init, refin, refout, xorout; reveng's catalogue),
and `data_bits` where each byte feeds only its low bits (Dimension Engineering's Kangaroo: 7, on a 7-bit link).

The runtime function is the fastest form there is for the parameters (crc_function); generated codecs call the
standard library's C function directly where it computes the CRC, and step an 8-bit CRC through its table in line.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Mapping
from functools import cache

from serialspec.checksums.base import (
    Algorithm,
    CCode,
    ChecksumProblem,
    Import,
    Key,
    NoCode,
    Report,
    Sample,
    TableSteps,
    c_uint,
    hex_bytes,
    hex_value,
)
from serialspec.runtime.values import dataclass

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any


def _reflect(value: int, width: int) -> int:
    result = 0
    for _ in range(width):
        result = (result << 1) | (value & 1)
        value >>= 1
    return result


@cache  # a table is computed once per CRC (generating a spec asks for its table many times)
def crc_table(width: int, poly: int, refin: bool) -> tuple[int, ...]:
    """The 256-entry table of a CRC in the Rocksoft/catalogue model (reflected table when refin)."""
    mask = (1 << width) - 1
    table = []
    for byte in range(256):
        if refin:
            crc = byte
            reflected_poly = _reflect(poly, width)
            for _ in range(8):
                crc = (crc >> 1) ^ reflected_poly if crc & 1 else crc >> 1
        else:
            crc = byte << (width - 8)
            top = 1 << (width - 1)
            for _ in range(8):
                crc = ((crc << 1) ^ poly) if crc & top else crc << 1
        table.append(crc & mask)
    return tuple(table)


def crc_function(
    width: int, poly: int, init: int, refin: bool, refout: bool, xorout: int, data_bits: int = 8
) -> Callable[[bytes], int]:
    """A CRC function from catalogue parameters (width, poly, init, refin, refout, xorout), widths 8..32; with
    `data_bits` below 8, each byte feeds its low `data_bits` bits alone (a bit loop: `_crc_low_bits`).

    The fastest form there is for the parameters: the standard library's C code where it computes the same CRC
    (binascii.crc_hqx: poly 0x1021, unreflected, 16 bits; zlib.crc32: poly 0x04C11DB7, reflected, 32 bits), two
    bytes per step for every other 16-bit CRC (`_crc16_words`), else a table-driven loop over the bytes.
    """
    mask = (1 << width) - 1
    if data_bits != 8:
        return _crc_low_bits(width, poly, init, refin, refout, xorout, data_bits)
    if crc_in_one_call(width, poly, init, refin, refout, xorout) is not None:
        from binascii import crc_hqx  # imported here: loading binascii costs a codec that does not use it ~0.5 ms

        if not xorout:
            return lambda data: crc_hqx(data, init)
        return lambda data: crc_hqx(data, init) ^ xorout
    if width == 32 and poly == 0x04C11DB7 and refin and refout:
        from zlib import crc32  # imported here: a codec that does not need it does not pay for it

        start = _reflect(init, width) ^ mask  # crc32 inverts the register before and after

        return lambda data: crc32(data, start) ^ mask ^ xorout
    if width == 16:
        return _crc16_words(poly, init, refin, refout, xorout)
    return _crc_bytes(width, poly, init, refin, refout, xorout)


# A CRC goes bit by bit (no table) until it has been fed this many bytes, then builds its 256-entry table: the table
# takes as many steps as the bit loop over this many bytes, so a command that checks one frame (`serialspec decode`)
# does not pay for it, and a stream pays at most about twice what the table saves.
_TABLE_AFTER = 256


def _crc_bytes(width: int, poly: int, init: int, refin: bool, refout: bool, xorout: int) -> Callable[[bytes], int]:
    """The CRC as a loop over the bytes through the 256-entry table (bit by bit until the table is made)."""
    mask = (1 << width) - 1
    table: tuple[int, ...] = ()
    fed = 0
    if refin:
        start = _reflect(init, width)
        reflected_poly = _reflect(poly, width)

        def bits(data: bytes) -> int:
            value = start
            for byte in data:
                value ^= byte
                for _ in range(8):
                    value = (value >> 1) ^ reflected_poly if value & 1 else value >> 1
            return value

        def crc(data: bytes) -> int:
            nonlocal table, fed
            if table:
                value = start
                for byte in data:
                    value = table[(value ^ byte) & 0xFF] ^ (value >> 8)
            else:
                fed += len(data)
                value = bits(data)
                if fed >= _TABLE_AFTER:
                    table = crc_table(width, poly, refin)
            if not refout:
                value = _reflect(value, width)
            return (value ^ xorout) & mask

    else:
        shift = width - 8
        top = 1 << (width - 1)

        def bits(data: bytes) -> int:
            value = init
            for byte in data:
                value ^= byte << shift
                for _ in range(8):
                    value = ((value << 1) ^ poly) if value & top else value << 1
                value &= mask
            return value

        def crc(data: bytes) -> int:
            nonlocal table, fed
            if table:
                value = init
                for byte in data:
                    value = table[((value >> shift) ^ byte) & 0xFF] ^ ((value << 8) & mask)
            else:
                fed += len(data)
                value = bits(data)
                if fed >= _TABLE_AFTER:
                    table = crc_table(width, poly, refin)
            if refout:
                value = _reflect(value, width)
            return (value ^ xorout) & mask

    return crc


def _crc_low_bits(
    width: int, poly: int, init: int, refin: bool, refout: bool, xorout: int, data_bits: int
) -> Callable[[bytes], int]:
    """The CRC where each byte feeds only its low `data_bits` bits (bit 7 of a 7-bit link's bytes left out), bit by
    bit: reflected, the bits go in lowest first; else highest first."""
    mask = (1 << width) - 1
    low = (1 << data_bits) - 1
    if refin:
        start, reflected_poly = _reflect(init, width), _reflect(poly, width)

        def crc(data: bytes) -> int:
            value = start
            for byte in data:
                value ^= byte & low
                for _ in range(data_bits):
                    value = (value >> 1) ^ reflected_poly if value & 1 else value >> 1
            return ((value if refout else _reflect(value, width)) ^ xorout) & mask

        return crc
    shift, top = width - data_bits, 1 << (width - 1)

    def crc_msb(data: bytes) -> int:
        value = init
        for byte in data:
            value ^= (byte & low) << shift
            for _ in range(data_bits):
                value = ((value << 1) ^ poly) & mask if value & top else (value << 1) & mask
        return ((_reflect(value, width) if refout else value) ^ xorout) & mask

    return crc_msb


def crc_in_one_call(width: int, poly: int, init: int, refin: bool, refout: bool, xorout: int) -> str | None:
    """Generated code's expression of the CRC of `{}` where the standard library computes it in one C call
    (binascii.crc_hqx, which generated code imports from binascii: poly 0x1021, unreflected, 16 bits), so a codec
    calls it with no Python function between; None for the others, which generated code calls through
    crc_function's result."""
    if width == 16 and poly == 0x1021 and not refin and not refout:
        call = f"_crc_hqx({{}}, {init:#x})"
        return f"({call} ^ {xorout:#x})" if xorout else call
    return None


# Runs of k 16-bit words (k < _WORD_RUNS) are read by precompiled structs, made with the word table.
_WORD_RUNS = 128
# A 16-bit CRC goes byte by byte until it has been fed this many bytes, then builds its word table: the table costs
# about as much as the byte loop over this many bytes takes longer, so a command that checks one frame (`serialspec
# decode`) does not pay milliseconds for it, and a stream pays at most about twice what the table saves.
_WORDS_AFTER = 1 << 16


@cache
def _unpack_words(order: str) -> tuple[Callable[[bytes], tuple[int, ...]], ...]:
    """unpack_from of a struct reading k words in this byte order, for each k < _WORD_RUNS."""
    return tuple(struct.Struct(f"{order}{k}H").unpack_from for k in range(_WORD_RUNS))


@cache
def _word_table(poly: int, refin: bool) -> tuple[int, ...]:
    """Entry x: the 16-bit register x after two zero bytes. Feeding bytes is linear (XOR) in the register, so entry
    x is the entry of its high byte's part XOR the entry of its low byte's: 65,536 XORs, about 2 ms."""
    table = crc_table(16, poly, refin)
    if refin:  # the low byte goes in first: entry (low) = table[low] >> 8 ^ table[table[low] & 0xFF]
        low = [(t >> 8) ^ table[t & 0xFF] for t in table]
        return tuple([h ^ entry for h in table for entry in low])  # entry (high << 8) is table[high]
    high = [((t << 8) & 0xFFFF) ^ table[t >> 8] for t in table]  # entry (high << 8); entry (low) is table[low]
    return tuple([h ^ entry for h in high for entry in table])


def _crc16_words(poly: int, init: int, refin: bool, refout: bool, xorout: int) -> Callable[[bytes], int]:
    """A 16-bit CRC two bytes per step: the register after two more bytes is table[register ^ those two bytes]
    (the bytes as one word, low byte first when reflected), from a 65,536-entry table made once it has been fed
    _WORDS_AFTER bytes (a few milliseconds, not paid by an import, shared by every CRC of that polynomial; until
    then it goes byte by byte); an odd last byte goes through the 256-entry table."""
    table: tuple[int, ...] = ()  # the 256-entry table, for an odd last byte once the word table is made
    by_bytes = _crc_bytes(16, poly, init, refin, refout, xorout)
    fed = 0
    order = "<" if refin else ">"
    unpack: tuple[Callable[[bytes], tuple[int, ...]], ...] = ()
    start = _reflect(init, 16) if refin else init
    pairs: tuple[int, ...] = ()
    plain = refin == refout and not xorout  # the register is the CRC
    longest = 2 * _WORD_RUNS  # bytes: longer data is read by a struct made for it

    def finish(value: int) -> int:
        return (_reflect(value, 16) if refin != refout else value) ^ xorout

    def crc(data: bytes) -> int:
        nonlocal pairs, unpack, fed, table
        if not pairs:
            fed += len(data)
            if fed < _WORDS_AFTER:
                return by_bytes(data)
            pairs, unpack, table = _word_table(poly, refin), _unpack_words(order), crc_table(16, poly, refin)
        value = start
        n = len(data)
        for word in unpack[n >> 1](data) if n < longest else struct.unpack_from(f"{order}{n >> 1}H", data):
            value = pairs[value ^ word]
        if n & 1:  # the last byte alone, as in crc_function's byte loop
            last = data[-1]
            value = (
                (value >> 8) ^ table[(value ^ last) & 0xFF]
                if refin
                else (value & 0xFF) << 8 ^ table[(value >> 8) ^ last]
            )
        return value if plain else finish(value)

    return crc


def __getattr__(name: str) -> Callable[[bytes, int], int]:
    # crc_hqx, which packages generated before took from here, from binascii when first asked for (as the
    # old names of runtime/checksums.py): this module does not load binascii for codecs that do not use it
    if name == "crc_hqx":
        from binascii import crc_hqx

        return crc_hqx
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


_PARAMETERS = ("width", "poly", "init", "refin", "refout", "xorout", "check")

#: Dimension Engineering's Kangaroo CRC-14 over the low 7 bits of each byte (a sample here, the language reference's
#: example of `data_bits`)
KANGAROO_CRC14 = {
    "width": 14,
    "poly": 0x03D1,
    "init": 0x3FFF,
    "refin": True,
    "refout": True,
    "xorout": 0x3FFF,
    "check": 0x1D66,
    "data_bits": 7,
}


@dataclass(frozen=True)
class Crc(Algorithm):
    width: int
    poly: int
    init: int
    refin: bool
    refout: bool
    xorout: int
    check: int
    catalogue: str = ""  # the catalogue name, e.g. CRC-16/MODBUS
    data_bits: int = 8  # the low bits of each byte that it takes in (Kangaroo: 7)

    name = "crc"
    summary = "a CRC given by its catalogue parameters in `crc:`"
    keys = (
        Key(
            "crc",
            "object",
            "crc: the CRC by its catalogue parameters (reveng's CRC catalogue); the generator checks `check` against "
            "the CRC of '123456789'.",
            keys=(
                Key("name", "str", "Catalogue name, e.g. CRC-16/MODBUS."),
                Key("width", "int", "Bits of the CRC."),
                Key("poly", "int", "Generator polynomial, normal form without the top bit (0x8005)."),
                Key("init", "int", "Register value before the first byte."),
                Key("refin", "bool", "Each input byte is reflected (least significant bit first)."),
                Key("refout", "bool", "The result is reflected before `xorout`."),
                Key("xorout", "int", "Value XORed into the result."),
                Key("check", "int", "The catalogue check value: the CRC of b'123456789'."),
                Key(
                    "data_bits",
                    "int",
                    "The low bits of each byte that the CRC takes in (default 8): 7 on links whose bytes carry 7 bits "
                    "(Dimension Engineering's Kangaroo: bit 7 of its address byte is left out, 7 shifts a byte); the "
                    "check value is then of those bits of '123456789'.",
                    default=8,
                    example=7,
                    minimum=1,
                    maximum=8,
                ),
            ),
            required=_PARAMETERS,
        ),
    )
    samples = (
        Sample(
            "CRC-8/MAXIM (reflected, a table step per byte)",
            "u8",
            {
                "crc": {
                    "name": "CRC-8/MAXIM",
                    "width": 8,
                    "poly": 0x31,
                    "init": 0,
                    "refin": True,
                    "refout": True,
                    "xorout": 0,
                    "check": 0xA1,
                }
            },
        ),
        Sample(
            "CRC-8/SMBUS (unreflected)",
            "u8",
            {
                "crc": {
                    "name": "CRC-8/SMBUS",
                    "width": 8,
                    "poly": 0x07,
                    "init": 0,
                    "refin": False,
                    "refout": False,
                    "xorout": 0,
                    "check": 0xF4,
                }
            },
        ),
        Sample(
            "CRC-16/MODBUS (two bytes a step)",
            "u16",
            {
                "crc": {
                    "name": "CRC-16/MODBUS",
                    "width": 16,
                    "poly": 0x8005,
                    "init": 0xFFFF,
                    "refin": True,
                    "refout": True,
                    "xorout": 0,
                    "check": 0x4B37,
                }
            },
        ),
        Sample(
            "CRC-16/XMODEM (binascii.crc_hqx)",
            "u16",
            {
                "crc": {
                    "name": "CRC-16/XMODEM",
                    "width": 16,
                    "poly": 0x1021,
                    "init": 0,
                    "refin": False,
                    "refout": False,
                    "xorout": 0,
                    "check": 0x31C3,
                }
            },
        ),
        Sample(
            "CRC-16/MCRF4XX with a per-command seed byte (MAVLink v2's CRC_EXTRA; the element's `seed`)",
            "u16",
            {
                "crc": {
                    "name": "CRC-16/MCRF4XX",
                    "width": 16,
                    "poly": 0x1021,
                    "init": 0xFFFF,
                    "refin": True,
                    "refout": True,
                    "xorout": 0,
                    "check": 0x6F91,
                },
                "seed": "per_command",
            },
        ),
        Sample(
            "a CRC-14 over the low 7 bits of each byte (data_bits 7), sent 7 bits a byte (the element's encoding "
            "seven_bit), as Dimension Engineering's Kangaroo",
            "u16",
            {
                "crc": KANGAROO_CRC14,
                "encoding": "seven_bit",
            },
        ),
        Sample(
            "a CRC-8 over the low 7 bits of each byte, unreflected (data_bits 7)",
            "u8",
            {
                "crc": {
                    "width": 8,
                    "poly": 0x07,
                    "init": 0,
                    "refin": False,
                    "refout": False,
                    "xorout": 0,
                    "check": 0xAB,
                    "data_bits": 7,
                }
            },
        ),
        Sample(
            "CRC-32/ISO-HDLC (zlib.crc32)",
            "u32",
            {
                "crc": {
                    "name": "CRC-32/ISO-HDLC",
                    "width": 32,
                    "poly": 0x04C11DB7,
                    "init": 0xFFFFFFFF,
                    "refin": True,
                    "refout": True,
                    "xorout": 0xFFFFFFFF,
                    "check": 0xCBF43926,
                }
            },
        ),
    )

    @classmethod
    def from_spec(cls, raw: Mapping[str, Any], size: int, type_name: str, report: Report, bits: int = 0) -> Crc:
        params = raw.get("crc")
        if not params:
            raise ChecksumProblem((), "algorithm crc needs `crc:` with width, poly, init, refin, refout, xorout, check")
        data_bits = int(params.get("data_bits", 8))
        if not 1 <= data_bits <= 8:  # the grammar said so already: no check value of such bits to add to it
            raise ChecksumProblem(("crc", "data_bits"), f"{data_bits} is outside 1..8")
        crc = cls(
            **{key: params[key] for key in _PARAMETERS}, catalogue=str(params.get("name", "")), data_bits=data_bits
        )
        if crc.width != (bits or size * 8):
            held = f"the {bits} bits of a {type_name} sent 7 bits a byte" if bits else f"a {type_name}"
            raise ChecksumProblem(("crc", "width"), f"a {crc.width}-bit CRC does not fill {held}")
        if data_bits > crc.width:
            raise ChecksumProblem(("crc", "data_bits"), f"{data_bits} bits a byte do not fit a {crc.width}-bit CRC")
        for key in ("poly", "init", "xorout", "check"):
            if not 0 <= params[key] < 1 << crc.width:
                raise ChecksumProblem(("crc", key), f"{key} {params[key]} does not fit {crc.width} bits")
        computed = crc.function()(b"123456789")
        if computed != crc.check:
            report(
                ("crc", "check"),
                f"these parameters give {computed:#x} for '123456789', not the check value {crc.check:#x}",
            )
        return crc

    @property
    def parameters_tuple(self) -> tuple[int, int, int, bool, bool, int]:
        return self.width, self.poly, self.init, self.refin, self.refout, self.xorout

    @property
    def whole_bytes(self) -> bool:
        """Every bit of each byte goes in (`data_bits` 8): the standard library's and the table's forms apply."""
        return self.data_bits == 8

    def function(self) -> Callable[[bytes], int]:
        return crc_function(*self.parameters_tuple, self.data_bits)

    def function_code(self) -> tuple[Import, str]:
        low = "" if self.whole_bytes else f", data_bits={self.data_bits}"
        return ("serialspec.checksums.crc", "crc_function"), (
            f"crc_function({self.width}, {self.poly:#x}, {self.init:#x}, {self.refin}, {self.refout}, "
            f"{self.xorout:#x}{low})"
        )

    def title(self) -> str:
        return " ".join(self.catalogue.split())

    @property
    def stepped(self) -> bool:
        """An 8-bit CRC as generated code computes it in line: `crc = table[crc ^ byte]` (reflected or not)."""
        return self.width == 8 and self.refin == self.refout and self.whole_bytes

    def python_setup(self, name: str) -> tuple[list[Import], list[str]]:
        if self.stepped:  # python_lines' table (python_call calls the function)
            table = f"{name.upper()}_TABLE = crc_table(8, {self.poly:#x}, {self.refin})"
            return [("serialspec.checksums.crc", "crc_table")], [
                f"{table}  # {self.title()}" if self.title() else table
            ]
        if self.in_one_call is not None:
            return [("binascii", "crc_hqx as _crc_hqx")], []
        return super().python_setup(name)

    @property
    def in_one_call(self) -> str | None:
        """crc_in_one_call's expression, for a CRC of whole bytes."""
        return crc_in_one_call(*self.parameters_tuple) if self.whole_bytes else None

    def python_call(self, name: str) -> str:
        return self.in_one_call or super().python_call(name)

    def python_calls_function(self) -> bool:
        return self.in_one_call is None

    def python_expression(self, name: str, covered: str) -> str | None:
        return None if self.stepped else super().python_expression(name, covered)

    def python_lines(self, name: str, covered: str, target: str) -> list[str]:
        steps = self.byte_table(name, target)
        if steps is None:
            return super().python_lines(name, covered, target)
        return [
            f"{target} = {steps.start:#x}",
            f"for byte in {covered}:",
            f"    {target} = {steps.table}[{target} ^ byte]",
            *steps.finish,
        ]

    def byte_table(self, name: str, target: str) -> TableSteps | None:
        if not self.stepped:
            return None
        # With 8 bits the table-driven step is table[crc ^ byte] whether the CRC is reflected or not.
        start = _reflect(self.init, 8) if self.refin else self.init
        finish = (f"{target} ^= {self.xorout:#x}",) if self.xorout else ()
        return TableSteps(f"{name.upper()}_TABLE", crc_table(8, self.poly, self.refin), start, finish)

    def c_code(self, prefix: str) -> CCode:
        if not 8 <= self.width <= 32:
            raise NoCode(f"a CRC of {self.width} bits")
        title = self.title()
        slug = "".join(ch if ch.isalnum() else "_" for ch in title.split(" ")[0].lower()).strip("_") if title else ""
        if not slug:
            slug = f"crc{self.width}_{self.poly:x}_{self.init:x}_{int(self.refin)}{int(self.refout)}_{self.xorout:x}"
        name = f"{prefix}_{slug}"
        mask = (1 << self.width) - 1
        t = c_uint(self.width)
        d = self.data_bits
        byte = "data[i]" if self.whole_bytes else f"(data[i] & 0x{(1 << d) - 1:x}u)"
        if (
            self.refin
        ):  # the register kept in the input's bit order (reflected); finish reflects it where refout differs
            start = _reflect(self.init, self.width)
            poly = _reflect(self.poly, self.width)
            loop = (
                f"        r ^= {byte};\n"
                f"        for (bit = 0; bit < {d}; bit++) {{\n"
                f"            r = (r & 1u) ? ((r >> 1) ^ 0x{poly:x}u) : (r >> 1);\n"
                "        }"
            )
        else:
            start = self.init
            top = 1 << (self.width - 1)
            loop = (
                f"        r ^= (uint32_t){byte} << {self.width - d};\n"
                f"        for (bit = 0; bit < {d}; bit++) {{\n"
                f"            r = (r & 0x{top:x}u) ? (((r << 1) ^ 0x{self.poly:x}u) & 0x{mask:x}u)"
                f" : ((r << 1) & 0x{mask:x}u);\n"
                "        }"
            )
        reflect = self.refin != self.refout
        finish = f"{prefix}__reflect((uint32_t)({{a}}), {self.width})" if reflect else "(uint32_t)({a})"
        if self.xorout:
            finish = f"(({finish}) ^ 0x{self.xorout:x}u)"
        steps = ("reflect the result over its width, " if reflect else "") + (
            f"xor it with 0x{self.xorout:x}" if self.xorout else "use it as is"
        )
        doc = (
            f"/* {title or 'CRC'}: width {self.width}, poly 0x{self.poly:x}, init 0x{self.init:x}, refin "
            f"{str(self.refin).lower()}, refout {str(self.refout).lower()}, xorout 0x{self.xorout:x} (check "
            f"0x{self.check:x}{'' if self.whole_bytes else f', the low {d} bits of each byte'}). Incremental: start "
            f"with 0x{start:x}, feed pieces, then {steps}. Bitwise: no table, no static data. */"
        )
        body = f"""{doc}
{t} {name}({t} acc, const uint8_t *data, size_t n)
{{
    uint32_t r = acc;
    size_t i;
    int bit;
    for (i = 0; i < n; i++) {{
{loop}
    }}
    return ({t})(r & 0x{mask:x}u);
}}
"""
        prototype = f"{t} {name}({t} acc, const uint8_t *data, size_t n);"
        return CCode(name, t, body, prototype, f"0x{start:x}u", finish, reflects=reflect)

    @classmethod
    def lua_function(cls) -> str:
        return _LUA

    def lua_parameters(self) -> dict[str, Any]:
        return {"name": self.catalogue} | {
            p: getattr(self, p) for p in ("width", "poly", "init", "refin", "refout", "xorout", "data_bits")
        }

    def describe(self) -> str:
        return f"{self.title() or 'CRC'} over the covered bytes"

    def parameters(self) -> list[tuple[str, str]]:
        return [
            ("width", str(self.width)),
            ("poly", f"{self.poly:#04x}"),
            ("init", f"{self.init:#04x}"),
            ("refin", str(self.refin)),
            ("refout", str(self.refout)),
            ("xorout", f"{self.xorout:#04x}"),
            ("check ('123456789')", f"{self.check:#04x}"),
            *([] if self.whole_bytes else [("bits of each byte taken in", f"the low {self.data_bits}")]),
        ]

    def worked(self, covered: bytes) -> str:
        return f"{self.title() or 'CRC'} of {hex_bytes(covered)} = {hex_value(self.function()(covered), self.width)}"


# the dissector's code (Algorithm.lua_function): bit by bit, from the catalogue parameters
_LUA = """function(spec, size, data)
  local function reflect(value, width)
    local result = 0
    for _ = 1, width do
      result = bor(lshift(result, 1), band(value, 1))
      value = rshift(value, 1)
    end
    return result
  end
  local width = spec.width
  local top, crc_mask = lshift(1, width - 1), width_mask(width)
  local crc = spec.init
  local bits = spec.data_bits
  for i = 1, #data do
    local byte = band(data:byte(i), width_mask(bits))
    if spec.refin then
      byte = reflect(byte, bits)
    end
    for bit = bits - 1, 0, -1 do
      local feedback = band(crc, top) ~= 0
      if band(rshift(byte, bit), 1) == 1 then
        feedback = not feedback
      end
      crc = band(lshift(crc, 1), crc_mask)
      if feedback then
        crc = bxor(crc, spec.poly)
      end
    end
  end
  if spec.refout then
    crc = reflect(crc, width)
  end
  return band(bxor(crc, spec.xorout), crc_mask)
end"""
