"""`method: hex_ascii`: each byte of the span sent as two hex digits, upper case (Modbus ASCII: `:`, the address to
the LRC as hex digits, CR LF). Decoders take either case, as the Modbus over Serial Line guide asks of a receiver.

As with every transform, a length or checksum inside the span sees the plain bytes, before the transform (the
Modbus LRC is the sum of the binary bytes, not of their hex digits); the span's end is where its hex digits end,
so the element after it must be a trailer that does not start with a hex digit (lang/passes/framing.py asks
`check_layout`).

Elements of `type: u4` in the span (before the content) are ONE hex digit each (Victron VE.Direct HEX: `:`, the
command as one digit, then the bytes as pairs): in the plain bytes each is a byte 0..15 (a checksum takes it in so),
at an offset from the span's start that the spec fixes (`digits`).
"""

from __future__ import annotations

import re
from collections.abc import Mapping

from serialspec.runtime.errors import DecodeError
from serialspec.runtime.values import dataclass, replace
from serialspec.transforms.base import CTransform, Report, Sample, Transform

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any

_DIGITS = b"0123456789ABCDEFabcdef"
_HEX = frozenset(_DIGITS)
_NOT_HEX = bytes(byte for byte in range(256) if byte not in _HEX)  # bytes.translate's delete: the hex digits kept
_RUN = re.compile(b"[0-9A-Fa-f]*")


def _hex_digits(data: bytes) -> None:
    """DecodeError naming the first byte of `data` that is not a hex digit."""
    if len(data.translate(None, _NOT_HEX)) != len(data):
        bad = next(i for i, byte in enumerate(data) if byte not in _HEX)
        raise DecodeError(f"hex-ASCII: byte {data[bad]:02X} at {bad} is not a hex digit")


def hex_decode(data: bytes) -> bytes:
    """Pairs of hex digits (either case) -> bytes; DecodeError in one line naming what is wrong and where."""
    _hex_digits(data)
    if len(data) % 2:
        raise DecodeError(f"hex-ASCII: {len(data)} hex digits, not whole bytes (an odd count)")
    return bytes.fromhex(data.decode("ascii"))


def hex_run(buffer: bytes, start: int, end: int) -> int:
    """Where the run of hex digits at buffer[start:end] ends (`end` when it goes on to the end of the buffer)."""
    found = _RUN.match(buffer, start, end)
    assert found is not None  # a run of no digits matches too
    return found.end()


def digits_decode(data: bytes, digits: tuple[int, ...]) -> bytes:
    """Hex digits (either case) -> bytes, the plain bytes at `digits` (offsets) one digit each, the others two;
    DecodeError in one line naming what is wrong and where."""
    if not digits:
        return hex_decode(data)
    _hex_digits(data)
    out, position = bytearray(), 0
    while position < len(data):
        width = 1 if len(out) in digits else 2
        if position + width > len(data):
            raise DecodeError(f"hex-ASCII: {len(data)} hex digits, not whole bytes (a byte cut short)")
        out.append(int(data[position : position + width], 16))
        position += width
    return bytes(out)


@dataclass(frozen=True)
class HexAscii:
    """Each plain byte of the span as two hex digits, those at `digits` (offsets from the span's start) as one: the
    runtime object of `method: hex_ascii`."""

    span: tuple[int, int]
    digits: tuple[int, ...] = ()

    def encode(self, data: bytes) -> bytes:
        if not self.digits:
            return data.hex().upper().encode("ascii")
        for offset in self.digits:  # the element's range (0..15) was checked before a byte was made
            if offset < len(data) and data[offset] > 0x0F:
                raise ValueError(f"hex-ASCII: byte {offset} is {data[offset]:#04x}, not one hex digit")
        return "".join(f"{byte:X}" if i in self.digits else f"{byte:02X}" for i, byte in enumerate(data)).encode(
            "ascii"
        )

    def decode(self, data: bytes) -> bytes:
        """The plain bytes; DecodeError names the first byte that is not a hex digit, or an odd count."""
        return digits_decode(data, self.digits)

    def wire_size(self, count: int) -> int:
        """The hex digits of the first `count` plain bytes."""
        return 2 * count - sum(1 for offset in self.digits if offset < count)

    def plain_prefix(self, buffer: bytes, start: int, end: int, count: int) -> tuple[bytes, int] | None:
        """The first `count` plain bytes of the hex digits at buffer[start:end] (fewer where the digits end before
        them: the span ends there); None while more digits may come; DecodeError for a span ending mid-byte."""
        wire = self.wire_size(count)
        stop = hex_run(buffer, start, min(end, start + wire))
        if stop == end and stop < start + wire:
            return None
        if not self.digits and (stop - start) % 2:
            raise DecodeError(f"hex-ASCII: {stop - start} hex digits, not whole bytes (an odd count)")
        return digits_decode(buffer[start:stop], self.digits), stop - start

    def span_end(self, buffer: bytes, start: int, end: int) -> int | None:
        """Where the span that starts at `start` ends on the wire (its first byte that is no hex digit), None while
        the buffer ends inside it."""
        stop = hex_run(buffer, start, end)
        return None if stop == end else stop


@dataclass(frozen=True)
class HexAsciiTransform(Transform):
    digits: tuple[int, ...] = ()  # plain offsets from the span's start sent as one digit (`type: u4` elements)

    name = "hex_ascii"
    summary = (
        "hex-ASCII (Modbus ASCII): each byte as two hex digits, upper case (decoders take either case); the span "
        "ends where its digits end, at a trailer that is no hex digit"
    )
    runtime_name = "HexAscii"
    samples = (
        Sample(
            "Modbus ASCII: ':', the address to the LRC as hex digits, CR LF (the LRC over the plain bytes)",
            {
                "elements": {
                    "start": {"role": "header", "value": "3A"},
                    "unit": {"role": "address", "type": "u8"},
                    "code": {"role": "command", "type": "u8"},
                    "content": {"role": "content"},
                    "lrc": {
                        "role": "checksum",
                        "type": "u8",
                        "algorithm": "sum",
                        "negate": True,
                        "covers": ["unit", "content"],
                    },
                    "end": {"role": "trailer", "value": "0D 0A"},
                },
                "transparency": {"method": "hex_ascii", "span": ["unit", "lrc"]},
            },
            plain=bytes.fromhex("01 03 00 00 00 01 FB"),
        ),
        Sample(
            "VE.Direct HEX: ':', the command as ONE hex digit (a u4 element), the bytes as pairs, a checksum, LF",
            {
                "elements": {
                    "start": {"role": "header", "value": "3A"},
                    "code": {"role": "command", "type": "u4"},
                    "content": {"role": "content"},
                    "check": {
                        "role": "checksum",
                        "type": "u8",
                        "algorithm": "sum",
                        "init": 0xAB,
                        "negate": True,
                        "covers": ["code", "content"],
                    },
                    "end": {"role": "trailer", "value": "0A"},
                },
                "transparency": {"method": "hex_ascii", "span": ["code", "check"]},
            },
            plain=bytes.fromhex("07 00 10 00 3E"),
        ),
    )

    @classmethod
    def from_spec(cls, raw: Mapping[str, Any], report: Report) -> HexAsciiTransform:
        return cls()

    def check_layout(self, roles: list[str], constants: list[bytes], first: int, last: int) -> str:
        after = constants[last + 1] if last + 1 < len(roles) and roles[last + 1] == "trailer" else b""
        if not after or after[0] in _HEX:
            return "hex-ASCII needs a trailer right after its span that does not start with a hex digit (CR LF)"
        return ""

    def with_digits(self, offsets: tuple[int, ...]) -> HexAsciiTransform | str:
        return replace(self, digits=offsets)

    def runtime(self, span: tuple[int, int]) -> HexAscii:
        return HexAscii(span, self.digits)

    def python_arguments(self, span: tuple[int, int]) -> list[str]:
        return [f"({span[0]}, {span[1]})", *([repr(self.digits)] if self.digits else [])]

    def describe(self) -> str:
        ones = ", ".join(str(offset) for offset in self.digits)
        single = f" (the span's byte {ones}, a u4 element, as one digit)" if self.digits else ""
        return (
            f"each byte is sent as two hex digits{single}, upper case (a receiver takes lower case too); a length or "
            "checksum inside the span is computed over the plain bytes, before they are written as hex"
        )

    def worked(self, plain: bytes) -> str:
        wire = self.runtime((0, 0)).encode(plain)
        return f"the span's bytes {plain.hex(' ').upper()} are sent as the text {wire.decode('ascii')}"

    def c_code(self, prefix: str) -> CTransform:
        name = f"{prefix}__hex_ascii"
        code = _C_HEX
        if self.digits:  # the bytes at `digits` one digit each: to the wire and back, byte by byte
            test = " || ".join(f"k == {offset}u" for offset in self.digits)
            code = code.replace("TO_WIRE", _C_DIGITS_TO_WIRE).replace("FROM_WIRE", _C_DIGITS_FROM_WIRE)
            code = code.replace("ONE_DIGIT", test)  # parenthesised in the templates (clang: no `((a == b))`)
        if not self.digits:
            code = code.replace("TO_WIRE", _C_PAIRS_TO_WIRE).replace("FROM_WIRE", _C_PAIRS_FROM_WIRE)
        return CTransform(name, code.replace("NAME", name), f"{name}_end", _C_HEX_END.replace("NAME", name))

    def lua(self) -> dict[str, Any] | None:
        return {"method": "hex_ascii", **({"digits": {offset: True for offset in self.digits}} if self.digits else {})}


_C_HEX = r"""/* The value of a hex digit of either case; 16 for a byte that is none. */
static uint8_t NAME_value(uint8_t c)
{
    if (c >= 0x30u && c <= 0x39u) {
        return (uint8_t)(c - 0x30u);
    }
    if (c >= 0x41u && c <= 0x46u) {
        return (uint8_t)(c - 0x37u);
    }
    if (c >= 0x61u && c <= 0x66u) {
        return (uint8_t)(c - 0x57u);
    }
    return 16u;
}

/* hex-ASCII (method: hex_ascii): each plain byte as two hex digits, upper case (to_wire), or back from pairs of hex
 * digits of either case (0 for a byte that is no hex digit, or an odd count). Decoding checks the form itself: with
 * cmp (the re-encoding check of the frame engine) it is not repeated, so lower case digits are taken. */
static int NAME(int to_wire, const uint8_t *src, size_t n, uint8_t *dst, const uint8_t *cmp, size_t cap, size_t *out)
{
    size_t i;
    if (to_wire && cmp != NULL) {
        *out = cap;
        return 1;
    }
TO_WIRE
FROM_WIRE
}
"""

_C_PAIRS_TO_WIRE = r"""    if (to_wire) {
        if (n > cap / 2u) {
            return 0;
        }
        for (i = 0u; i < n; i++) {
            uint8_t high = (uint8_t)(src[i] >> 4), low = (uint8_t)(src[i] & 0x0Fu);
            dst[2u * i] = (uint8_t)(high < 10u ? 0x30u + high : 0x37u + high);
            dst[2u * i + 1u] = (uint8_t)(low < 10u ? 0x30u + low : 0x37u + low);
        }
        *out = 2u * n;
        return 1;
    }"""
_C_PAIRS_FROM_WIRE = r"""    if (n % 2u != 0u || n / 2u > cap) {
        return 0;
    }
    for (i = 0u; i < n; i += 2u) {
        uint8_t high = NAME_value(src[i]), low = NAME_value(src[i + 1u]);
        if (high > 15u || low > 15u) {
            return 0;
        }
        dst[i / 2u] = (uint8_t)((high << 4) | low);
    }
    *out = n / 2u;
    return 1;"""
# with `digits`: the plain bytes at those offsets (ONE_DIGIT of k) one hex digit each
_C_DIGITS_TO_WIRE = r"""    if (to_wire) {
        size_t k, w = 0u;
        for (k = 0u; k < n; k++) {
            uint8_t high = (uint8_t)(src[k] >> 4), low = (uint8_t)(src[k] & 0x0Fu);
            if (ONE_DIGIT) {
                if (high != 0u || w + 1u > cap) {
                    return 0;
                }
            } else {
                if (w + 2u > cap) {
                    return 0;
                }
                dst[w++] = (uint8_t)(high < 10u ? 0x30u + high : 0x37u + high);
            }
            dst[w++] = (uint8_t)(low < 10u ? 0x30u + low : 0x37u + low);
        }
        *out = w;
        return 1;
    }"""
_C_DIGITS_FROM_WIRE = r"""    {
        size_t k = 0u;
        for (i = 0u; i < n; k++) {
            uint8_t high = 0u, low;
            if (k >= cap) {
                return 0;
            }
            if (!(ONE_DIGIT)) {
                high = NAME_value(src[i++]);
                if (i >= n) {
                    return 0;
                }
            }
            low = NAME_value(src[i++]);
            if (high > 15u || low > 15u) {
                return 0;
            }
            dst[k] = (uint8_t)((high << 4) | low);
        }
        *out = k;
        return 1;
    }"""

_C_HEX_END = r"""/* Where the hex digits that start at b[start] end (the first byte that is no hex digit), -2 while
 * b[0..avail) ends inside them (runtime HexAscii.span_end). */
static long NAME_end(const uint8_t *b, size_t start, size_t avail)
{
    size_t i;
    for (i = start; i < avail; i++) {
        if (NAME_value(b[i]) > 15u) {
            return (long)i;
        }
    }
    return -2L;
}
"""
