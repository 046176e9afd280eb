"""`method: replace` (the default): byte stuffing or escaping by substitution. Each plain byte sequence is sent as
its wire sequence, leftmost match first (DYNAMIXEL 'FF FF FD' -> 'FF FF FD FD'; SLIP 'C0' -> 'DB DC'; XBee API mode 2
'7E' -> '7D 5E', '7D' -> '7D 5D', '11' -> '7D 31', '13' -> '7D 33')."""

from __future__ import annotations

import functools
import re
from collections.abc import Callable, Mapping

from serialspec.runtime.errors import DecodeError
from serialspec.runtime.hexbytes import parse_hex
from serialspec.runtime.values import dataclass
from serialspec.transforms.base import Key, Report, Sample, Transform, TransformProblem

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any


@dataclass(frozen=True)
class Transparency:
    """Byte stuffing or escaping over a span: each plain sequence becomes its wire sequence, leftmost first."""

    span: tuple[int, int]
    replace: tuple[tuple[bytes, bytes], ...]

    def encode(self, data: bytes) -> bytes:
        return _rewrite(data, self.replace)

    def decode(self, data: bytes) -> bytes:
        """The plain bytes; DecodeError unless `data` is what encode gives for them (no lone escape)."""
        plain = _rewrite(data, tuple((wire, plain) for plain, wire in self.replace))
        if self.encode(plain) != data:
            raise DecodeError(f"bad stuffing: {data.hex(' ')} is not the stuffed form of any bytes")
        return plain

    def plain_prefix(self, buffer: bytes, start: int, end: int, count: int) -> tuple[bytes, int] | None:
        """The first `count` plain bytes at buffer[start:end] (decode's rule: at each position the first wire
        sequence that matches, else the byte itself) and the wire bytes they took; None while a wire sequence may
        still be cut off by the end of the buffer."""
        plain = bytearray()
        position = start
        pairs = self.replace
        while len(plain) < count:
            if position >= end:
                return None
            for old, wire in pairs:
                if buffer.startswith(wire, position, end):
                    plain += old
                    position += len(wire)
                    break
                if len(wire) > end - position and wire.startswith(buffer[position:end]):
                    return None  # the buffer may end inside this wire sequence
            else:
                plain.append(buffer[position])
                position += 1
        return bytes(plain[:count]), position - start


def _rewrite(data: bytes, pairs: tuple[tuple[bytes, bytes], ...]) -> bytes:
    """Each `old` sequence of `data` replaced by its `new`, scanning left to right (the leftmost match first, the
    pairs tried in order at each position): one bytes.replace for one pair, else one regular expression."""
    if len(pairs) == 1:
        old, new = pairs[0]
        return data.replace(old, new)
    return _rewriter(pairs)(data)


@functools.cache
def _rewriter(pairs: tuple[tuple[bytes, bytes], ...]) -> Callable[[bytes], bytes]:
    table = dict(pairs)
    pattern = re.compile(b"|".join(re.escape(old) for old, _ in pairs))
    return lambda data: pattern.sub(lambda match: table[match.group()], data)


def _hex(data: bytes) -> str:
    return data.hex(" ").upper()


@dataclass(frozen=True)
class Replace(Transform):
    pairs: tuple[tuple[bytes, bytes], ...]

    name = "replace"
    summary = (
        "substitution: each plain byte sequence of `replace` is sent as its wire sequence (stuffing, escaping; "
        "the default)"
    )
    runtime_name = "Transparency"
    keys = (
        Key(
            "replace",
            "hex_map",
            "replace: plain hex bytes -> the hex bytes sent instead, leftmost match first (DYNAMIXEL: 'FF FF FD' -> "
            "'FF FF FD FD'; SLIP: 'C0' -> 'DB DC', 'DB' -> 'DB DD').",
            example={"C0": "DB DC", "DB": "DB DD"},
        ),
    )
    samples = (
        Sample(
            "escaping after the start byte, over the length and checksum (XBee API mode 2)",
            {
                "elements": {
                    "start": {"role": "header", "value": "7E"},
                    "length": {"role": "length", "type": "u16", "endian": "big", "counts": ["code", "content"]},
                    "code": {"role": "command", "type": "u8"},
                    "content": {"role": "content"},
                    "checksum": {
                        "role": "checksum",
                        "type": "u8",
                        "algorithm": "sum",
                        "invert": True,
                        "covers": ["code", "content"],
                    },
                },
                "transparency": {
                    "span": ["length", "checksum"],
                    "replace": {"7E": "7D 5E", "7D": "7D 5D", "11": "7D 31", "13": "7D 33"},
                },
            },
            plain=bytes.fromhex("00 05 10 7E 11 13 7D D0"),
        ),
        Sample(
            "a frame ended by a delimiter, no length, the delimiter escaped (SLIP style)",
            {
                "elements": {
                    "code": {"role": "command", "type": "u8"},
                    "content": {"role": "content"},
                    "checksum": {"role": "checksum", "type": "u8", "algorithm": "xor", "covers": ["code", "content"]},
                    "end": {"role": "trailer", "value": "C0"},
                },
                "transparency": {"span": ["code", "checksum"], "replace": {"C0": "DB DC", "DB": "DB DD"}},
            },
            plain=bytes.fromhex("01 C0 DB 02 18"),
        ),
    )

    @classmethod
    def from_spec(cls, raw: Mapping[str, Any], report: Report) -> Replace:
        pairs = []
        for plain, wire in (raw.get("replace") or {}).items():
            try:
                pairs.append((parse_hex(str(plain)), parse_hex(str(wire))))
            except ValueError as exc:
                raise TransformProblem(("replace", str(plain)), str(exc)) from None
        if not pairs or any(not p or not w for p, w in pairs):
            raise TransformProblem(("replace",), "give plain -> wire byte sequences, none empty")
        return cls(tuple(pairs))

    def runtime(self, span: tuple[int, int]) -> Transparency:
        return Transparency(span, self.pairs)

    def python_arguments(self, span: tuple[int, int]) -> list[str]:
        pairs = ", ".join(f"({plain!r}, {wire!r})" for plain, wire in self.pairs)
        return [f"({span[0]}, {span[1]})", f"({pairs},)"]

    def describe(self) -> str:
        return ", ".join(f"{_hex(plain)} is sent as {_hex(wire)}" for plain, wire in self.pairs)

    def c_refusal(self) -> str:
        return ""  # the frame engine's own substitution (backends/c/engine.py pfx__rewrite), over the layout's pairs

    def lua(self) -> dict[str, Any] | None:
        return {"replace": [[plain, wire] for plain, wire in self.pairs]}
