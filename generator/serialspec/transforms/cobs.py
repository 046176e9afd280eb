"""`method: cobs`: Consistent Overhead Byte Stuffing (PacketSerial style). The span is sent without any 00 byte: each
run of up to 254 non-zero bytes is preceded by a code byte (the run's length + 1) that stands for the 00 after it,
and the frame ends with a trailer 00, the delimiter (lang/passes/framing.py checks it comes right after the span)."""

from __future__ import annotations

from collections.abc import Mapping

from serialspec.runtime.errors import DecodeError
from serialspec.runtime.values import dataclass
from serialspec.transforms.base import CTransform, Key, Report, Sample, Transform

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any


def cobs_encode(data: bytes, code_after_full_run: bool = True) -> bytes:
    """COBS: a code byte before each run of non-zero bytes (254 at most), no 00 in the result. Data that ends with
    a run of 254 non-zero bytes gets the code byte 01 after it unless `code_after_full_run` is false."""
    out = bytearray(b"\x00")
    code_at, code, full = 0, 1, False
    for byte in data:
        if byte:
            out.append(byte)
            code += 1
            if code == 0xFF:
                out[code_at], code_at, code, full = code, len(out), 1, True
                out.append(0)
        else:
            out[code_at], code_at, code, full = code, len(out), 1, False
            out.append(0)
    if full and code == 1 and not code_after_full_run:
        del out[code_at]  # the data ended with the full run: no code byte stands for anything after it
        return bytes(out)
    out[code_at] = code
    return bytes(out)


def cobs_decode(data: bytes) -> bytes:
    """The bytes cobs_encode made `data` from; DecodeError for bytes that are no COBS form. A last run of 254 bytes
    may end the data without the code byte 01 after it (the form some encoders make): it decodes the same."""
    plain, used, _ = _decode(data, 0, len(data), None)
    if used != len(data) or not data:
        raise DecodeError(f"bad COBS: {data.hex(' ')} is not the COBS form of any bytes")
    return plain


def _decode(data: bytes, start: int, end: int, count: int | None) -> tuple[bytes, int, bool]:
    """Plain bytes of the COBS bytes data[start:end] (up to `count` when given), the bytes read, and whether the
    span ended (a 00, the delimiter, or the end of `data`) before `count` plain bytes were read."""
    plain = bytearray()
    position = start
    while count is None or len(plain) < count:
        if position >= end:
            return bytes(plain), position - start, count is None
        code = data[position]
        if code == 0:
            return bytes(plain), position - start, True
        run = data[position + 1 : min(position + code, end)]
        if 0 in run:
            raise DecodeError(f"bad COBS: a 00 inside a run of {code - 1} bytes")
        plain += run
        if position + code > end:
            if count is None:
                raise DecodeError(f"bad COBS: a run of {code - 1} bytes goes past the end of the span")
            return bytes(plain), end - start, False
        position += code
        if code < 0xFF and not (position >= len(data) or data[position] == 0):
            plain.append(0)  # the 00 the code byte stands for (none after the last run)
            if len(plain) == count:  # the span's last plain byte: the code byte after it (which makes it a 00,
                return bytes(plain), position + 1 - start, False  # its run the rest) is the span's too
        elif code < 0xFF and count is not None and position >= end:
            return bytes(plain), position - start, False  # the span may go on: is the 00 there or not?
    return bytes(plain[:count]), position - start, False


@dataclass(frozen=True)
class CobsSpan:
    """COBS over a span of elements: the runtime object of `method: cobs`."""

    span: tuple[int, int]
    code_after_full_run: bool = True

    def encode(self, data: bytes) -> bytes:
        return cobs_encode(data, self.code_after_full_run)

    def decode(self, data: bytes) -> bytes:
        return cobs_decode(data)

    def plain_prefix(self, buffer: bytes, start: int, end: int, count: int) -> tuple[bytes, int] | None:
        plain, used, ended = _decode(buffer, start, end, count)
        if len(plain) >= count or ended:
            return plain[:count], used
        return None


@dataclass(frozen=True)
class Cobs(Transform):
    code_after_full_run: bool = True

    name = "cobs"
    summary = (
        "COBS, Consistent Overhead Byte Stuffing (PacketSerial): no 00 in the span, a code byte before each run of "
        "up to 254 non-zero bytes; a trailer 00 right after the span ends the frame. A span that ends with a run "
        "of 254 non-zero bytes is written with the code byte 01 after it (PacketSerial, the COBS paper) or without "
        "(`code_after_full_run: false`: the `cobs` package on PyPI); decode takes both forms"
    )
    runtime_name = "CobsSpan"
    keys = (
        Key(
            "code_after_full_run",
            "bool",
            "cobs: whether a span ending with a run of 254 non-zero bytes is sent with the code byte 01 after it "
            "(true: PacketSerial and the COBS paper) or ends with the run (false: the `cobs` package on PyPI). "
            "Decode takes both forms either way.",
            default=True,
            example=False,
        ),
    )
    samples = (
        Sample(
            "the whole packet, a checksum inside it, then the 00 delimiter (PacketSerial)",
            {
                "elements": {
                    "code": {"role": "command", "type": "u8"},
                    "content": {"role": "content"},
                    "check": {
                        "role": "checksum",
                        "type": "u16",
                        "algorithm": "fletcher",
                        "covers": ["code", "content"],
                    },
                    "delimiter": {"role": "trailer", "value": "00"},
                },
                "transparency": {"method": "cobs", "span": ["code", "check"]},
            },
            plain=bytes.fromhex("01 00 12 00 00 34 47 82"),
        ),
        Sample(
            "after a header, with a length inside the span (it counts the plain bytes)",
            {
                "elements": {
                    "start": {"role": "header", "value": "AA"},
                    "length": {"role": "length", "type": "u8", "counts": ["code", "content"]},
                    "code": {"role": "command", "type": "u8"},
                    "content": {"role": "content"},
                    "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["code", "content"]},
                    "delimiter": {"role": "trailer", "value": "00"},
                },
                "transparency": {"method": "cobs", "span": ["length", "checksum"]},
            },
            plain=bytes.fromhex("03 01 00 05 06"),
        ),
        Sample(
            "a last run of 254 bytes ended without the code byte 01 (the `cobs` package)",
            {
                "elements": {
                    "code": {"role": "command", "type": "u8"},
                    "content": {"role": "content"},
                    "delimiter": {"role": "trailer", "value": "00"},
                },
                "transparency": {"method": "cobs", "span": ["code", "content"], "code_after_full_run": False},
            },
            plain=bytes(range(1, 255)),
        ),
    )

    @classmethod
    def from_spec(cls, raw: Mapping[str, Any], report: Report) -> Cobs:
        return cls(bool(raw.get("code_after_full_run", True)))

    def check_layout(self, roles: list[str], constants: list[bytes], first: int, last: int) -> str:
        if last + 1 >= len(roles) or roles[last + 1] != "trailer" or constants[last + 1] != b"\x00":
            return "COBS needs the delimiter right after its span: a trailer with `value: '00'`"
        return ""

    def runtime(self, span: tuple[int, int]) -> CobsSpan:
        return CobsSpan(span, self.code_after_full_run)

    def python_arguments(self, span: tuple[int, int]) -> list[str]:
        return [f"({span[0]}, {span[1]})", *([] if self.code_after_full_run else ["False"])]

    def describe(self) -> str:
        last = (
            "a last run of 254 is followed by the code byte 01, as PacketSerial sends it, and decoded without it too"
            if self.code_after_full_run
            else "a last run of 254 ends the span without a code byte after it, and is decoded with one too"
        )
        return (
            "the bytes are sent in COBS form (no 00 among them: a code byte, the length of the run of non-zero bytes "
            f"after it + 1, stands for the 00 that ends the run; runs of 254 bytes take a code byte FF and no 00; "
            f"{last})"
        )

    def c_code(self, prefix: str) -> CTransform:
        name = f"{prefix}__cobs"
        code = _C_COBS.replace("NAME", name).replace("CODE_AFTER_FULL_RUN", "1" if self.code_after_full_run else "0")
        return CTransform(name, code, plain_prefix=f"{name}_prefix", prefix_code=_C_PREFIX.replace("NAME", name))

    def lua(self) -> dict[str, Any] | None:
        return {"method": "cobs"}  # the dissector decodes, and decoding takes both forms


_C_PREFIX = r"""/* The COBS bytes from b[start] that give the span's first `count` plain bytes (_decode with a count, as
 * CobsSpan.plain_prefix): -2 while more are needed, -1 where none do (a 00 ends the span first, a 00 inside a run).
 * The plain bytes from index `from` on go to dst. */
static long NAME_prefix(const uint8_t *b, size_t start, size_t avail, size_t count, size_t from, uint8_t *dst)
{
    size_t n = 0u, pos = start, i, stop;
    while (n < count) {
        uint8_t code;
        if (pos >= avail) {
            return -2L;
        }
        code = b[pos];
        if (code == 0u) {
            return -1L; /* the span ended before count plain bytes */
        }
        stop = pos + code < avail ? pos + code : avail;
        for (i = pos + 1u; i < stop; i++) {
            if (b[i] == 0u) {
                return -1L;
            }
        }
        for (i = pos + 1u; i < stop; i++, n++) {
            if (n >= from && n < count) {
                dst[n - from] = b[i];
            }
        }
        if (pos + code > avail) {
            return n >= count ? (long)(avail - start) : -2L;
        }
        pos += code;
        if (code < 0xFFu && pos < avail && b[pos] != 0u) {
            if (n >= from && n < count) {
                dst[n - from] = 0u; /* the 00 the code byte stands for */
            }
            n++;
            if (n == count) {
                return (long)(pos + 1u - start); /* that 00 is the last: the code byte making it one is the span's */
            }
        } else if (code < 0xFFu && pos >= avail) {
            return n >= count ? (long)(pos - start) : -2L; /* the span may go on: is the 00 there or not? */
        }
    }
    return (long)(pos - start);
}
"""

_C_COBS = r"""/* COBS (method: cobs): the plain bytes as a code byte before each run of up to 254 non-zero bytes
 * (to_wire), or back (0 for bytes that are no COBS form: a 00, a run past the end). Decoding checks the form itself:
 * with cmp (the re-encoding check of the frame engine) it is not repeated. */
static int NAME(int to_wire, const uint8_t *src, size_t n, uint8_t *dst, const uint8_t *cmp, size_t cap, size_t *out)
{
    size_t i, o = 0u;
    if (to_wire && cmp != NULL) {
        *out = cap;
        return 1;
    }
    if (to_wire) {
        size_t code_at = 0u;
        uint8_t code = 1u;
        int full = 0; /* the last run closed was 254 bytes long (code FF), not ended by a 00 */
        if (cap < 1u) {
            return 0;
        }
        o = 1u;
        for (i = 0u; i < n; i++) {
            full = 0;
            if (src[i] != 0u) {
                if (o >= cap) {
                    return 0;
                }
                dst[o++] = src[i];
                if (++code != 0xFFu) {
                    continue;
                }
                full = 1;
            }
            dst[code_at] = code;
            code_at = o;
            if (o >= cap) {
                return 0;
            }
            dst[o++] = 0u;
            code = 1u;
        }
        if (!CODE_AFTER_FULL_RUN && full) {
            *out = o - 1u; /* the span ends with the full run: no code byte after it */
            return 1;
        }
        dst[code_at] = code;
        *out = o;
        return 1;
    }
    if (n == 0u) {
        return 0;
    }
    i = 0u;
    while (i < n) {
        size_t code = src[i], j;
        if (code == 0u || i + code > n) {
            return 0;
        }
        for (j = 1u; j < code; j++) {
            if (src[i + j] == 0u || o >= cap) {
                return 0;
            }
            dst[o++] = src[i + j];
        }
        i += code;
        if (code < 0xFFu && i < n) {
            if (o >= cap) {
                return 0;
            }
            dst[o++] = 0u;
        }
    }
    *out = o;
    return 1;
}
"""
