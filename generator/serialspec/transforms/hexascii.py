"""`method: hex_ascii`: each byte of the span sent as two hex digits, upper case (Modbus ASCII: `:`, the address to
the LRC as hex digits, CR LF). Decoders take either case, as the Modbus over Serial Line guide asks of a receiver.

As with every transform, a length or checksum inside the span sees the plain bytes, before the transform (the
Modbus LRC is the sum of the binary bytes, not of their hex digits); the span's end is where its hex digits end,
so the element after it must be a trailer that does not start with a hex digit (lang/passes/framing.py asks
`check_layout`).
"""

from __future__ import annotations

import re
from collections.abc import Mapping

from serialspec.runtime.errors import DecodeError
from serialspec.runtime.values import dataclass
from serialspec.transforms.base import CTransform, Report, Sample, Transform

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any

_DIGITS = b"0123456789ABCDEFabcdef"
_HEX = frozenset(_DIGITS)
_NOT_HEX = bytes(byte for byte in range(256) if byte not in _HEX)  # bytes.translate's delete: the hex digits kept
_RUN = re.compile(b"[0-9A-Fa-f]*")


def hex_decode(data: bytes) -> bytes:
    """Pairs of hex digits (either case) -> bytes; DecodeError in one line naming what is wrong and where."""
    if len(data.translate(None, _NOT_HEX)) != len(data):
        bad = next(i for i, byte in enumerate(data) if byte not in _HEX)
        raise DecodeError(f"hex-ASCII: byte {data[bad]:02X} at {bad} is not a hex digit")
    if len(data) % 2:
        raise DecodeError(f"hex-ASCII: {len(data)} hex digits, not whole bytes (an odd count)")
    return bytes.fromhex(data.decode("ascii"))


def hex_run(buffer: bytes, start: int, end: int) -> int:
    """Where the run of hex digits at buffer[start:end] ends (`end` when it goes on to the end of the buffer)."""
    found = _RUN.match(buffer, start, end)
    assert found is not None  # a run of no digits matches too
    return found.end()


@dataclass(frozen=True)
class HexAscii:
    """Each plain byte of the span as two hex digits: the runtime object of `method: hex_ascii`."""

    span: tuple[int, int]

    def encode(self, data: bytes) -> bytes:
        return data.hex().upper().encode("ascii")

    def decode(self, data: bytes) -> bytes:
        """The plain bytes; DecodeError names the first byte that is not a hex digit, or an odd count."""
        return hex_decode(data)

    def plain_prefix(self, buffer: bytes, start: int, end: int, count: int) -> tuple[bytes, int] | None:
        """The first `count` plain bytes of the hex digits at buffer[start:end] (fewer where the digits end before
        them: the span ends there); None while more digits may come; DecodeError for a span ending mid-byte."""
        stop = hex_run(buffer, start, min(end, start + 2 * count))
        if stop == end and stop < start + 2 * count:
            return None
        if (stop - start) % 2:
            raise DecodeError(f"hex-ASCII: {stop - start} hex digits, not whole bytes (an odd count)")
        return bytes.fromhex(buffer[start:stop].decode("ascii")), stop - start

    def span_end(self, buffer: bytes, start: int, end: int) -> int | None:
        """Where the span that starts at `start` ends on the wire (its first byte that is no hex digit), None while
        the buffer ends inside it."""
        stop = hex_run(buffer, start, end)
        return None if stop == end else stop


@dataclass(frozen=True)
class HexAsciiTransform(Transform):
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
    )

    @classmethod
    def from_spec(cls, raw: Mapping[str, Any], report: Report) -> HexAsciiTransform:
        return cls()

    def check_layout(self, roles: list[str], constants: list[bytes], first: int, last: int) -> str:
        after = constants[last + 1] if last + 1 < len(roles) and roles[last + 1] == "trailer" else b""
        if not after or after[0] in _HEX:
            return "hex-ASCII needs a trailer right after its span that does not start with a hex digit (CR LF)"
        return ""

    def runtime(self, span: tuple[int, int]) -> HexAscii:
        return HexAscii(span)

    def python_arguments(self, span: tuple[int, int]) -> list[str]:
        return [f"({span[0]}, {span[1]})"]

    def describe(self) -> str:
        return (
            "each byte is sent as two hex digits, upper case (a receiver takes lower case too); a length or checksum "
            "inside the span is computed over the plain bytes, before they are written as hex"
        )

    def worked(self, plain: bytes) -> str:
        wire = self.runtime((0, 0)).encode(plain)
        return f"the span's bytes {plain.hex(' ').upper()} are sent as the text {wire.decode('ascii')}"

    def c_code(self, prefix: str) -> CTransform:
        name = f"{prefix}__hex_ascii"
        return CTransform(name, _C_HEX.replace("NAME", name), f"{name}_end", _C_HEX_END.replace("NAME", name))

    def lua(self) -> dict[str, Any] | None:
        return {"method": "hex_ascii"}


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
    if (to_wire) {
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
    }
    if (n % 2u != 0u || n / 2u > cap) {
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
    return 1;
}
"""

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
