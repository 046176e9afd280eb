"""Hex-ASCII encoding of a span of a frame (Modbus ASCII: each byte from the address to the LRC is sent as two hex
digits, between a ':' header and a CR LF trailer).

The span's plain bytes are what lengths and checksums inside it see, as with transparency (runtime/framing.py's
Transparency has the same encode/decode shape, so either can rewrite a span). Kept in one module so that it can
become one entry of a registry of frame transforms.
"""

from __future__ import annotations

from dataclasses import dataclass

from serialspec.runtime.errors import DecodeError

_HEX = frozenset(b"0123456789ABCDEFabcdef")


@dataclass(frozen=True)
class HexAscii:
    """Each plain byte of the span as two hex digits (upper case on encode; either case accepted on decode, as
    Modbus ASCII asks of a receiver)."""

    span: tuple[int, int]
    upper: bool = True

    def encode(self, data: bytes) -> bytes:
        text = data.hex().encode("ascii")
        return text.upper() if self.upper else text

    def decode(self, data: bytes) -> bytes:
        """The plain bytes; DecodeError names the first character that is not a hex digit, or an odd count."""
        return hex_decode(data)

    @staticmethod
    def wire_size(plain: int) -> int:
        return 2 * plain


def hex_decode(data: bytes) -> bytes:
    """Pairs of hex digits -> bytes; DecodeError in one line naming what is wrong and where."""
    bad = next((i for i, byte in enumerate(data) if byte not in _HEX), None)
    if bad is not None:
        raise DecodeError(f"hex-ASCII: byte {data[bad]:02X} at {bad} is not a hex digit")
    if len(data) % 2:
        raise DecodeError(f"hex-ASCII: {len(data)} hex digits, not whole bytes (an odd count)")
    return bytes.fromhex(data.decode("ascii"))
