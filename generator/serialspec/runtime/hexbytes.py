"""Hex text in the forms people paste: '12 4c 08', '0x12 0x4C', '124c08', '12:4c:08', '12-4c-08'."""

from __future__ import annotations

#: The separators people put between hex bytes besides whitespace, each made a space (then str.split() splits on
#: runs of whitespace as a regular expression of [\s:,-]+ would, without compiling one on every start).
_SEPARATORS = str.maketrans(":,-", "   ")


def parse_hex(text: str) -> bytes:
    """Bytes from hex text; raises ValueError naming the first thing that is not a hex byte."""
    try:  # pairs of hex digits, ASCII whitespace between them (what specs and captures mostly hold): read in C
        data = bytes.fromhex(text)
    except ValueError:
        data = b""
    if data:
        return data
    tokens = text.translate(_SEPARATORS).split()
    if not tokens:
        raise ValueError("no hex bytes given")
    out = bytearray()
    for token in tokens:
        prefixed = token[:2].lower() == "0x"
        digits = token[2:] if prefixed else token
        if not digits or any(c not in "0123456789abcdefABCDEF" for c in digits):
            raise ValueError(f"{token!r} is not a hex byte")
        if prefixed or len(tokens) > 1 and len(digits) == 1:
            if len(digits) > 2:
                raise ValueError(f"{token!r} is not one hex byte")
            out.append(int(digits, 16))
        elif len(digits) % 2:
            raise ValueError(f"{token!r} has an odd number of hex digits")
        else:
            out.extend(bytes.fromhex(digits))
    return bytes(out)


def to_hex(data: bytes) -> str:
    return data.hex(" ")
