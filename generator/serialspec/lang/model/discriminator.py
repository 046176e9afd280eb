"""Messages picked by a constant leading bit field of their content (RTCM 3's 12-bit message number): where the
messages that share a code (or, in frames without a command element, all of a direction's messages) each begin with
a constant integer field of one width at one place, and no two constants are equal, decode and the stream parser
pick a message by that value before its size, also where sizes overlap. Otherwise they are told apart by their
content size alone. No key of its own: the `const` of each message's first field says it (docs/language.md,
"Messages picked by their leading constant")."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

from serialspec.lang.frozen import frozen
from serialspec.lang.model.commands import Message
from serialspec.lang.model.fields import Scalar


@frozen
class Discriminator:
    """How to read the leading value: the content's first `size` bytes as one integer of byte order `endian`,
    shifted right by `shift` and masked with `mask`; the value of each message picked by it."""

    size: int
    endian: Literal["big", "little"]
    shift: int
    mask: int
    bits: int
    name: str  # the leading field's name (in the first message)
    values: tuple[tuple[int, Message], ...]

    def read(self, content: bytes) -> int:
        return (int.from_bytes(content[: self.size], self.endian) >> self.shift) & self.mask


def leading_constant(message: Message) -> tuple[tuple[int, str, int, int], int] | None:
    """((bytes read, byte order, shift, bits), the value masked) of a message whose first content field is a constant
    integer, else None."""
    if not message.fields:
        return None
    first = message.fields[0]
    if not isinstance(first, Scalar) or first.const is None or first.type.is_float or first.type.size == 3:
        return None
    if first.seven_bit or first.sign_magnitude:
        return None  # its wire bytes are not the value's
    place = first.bit_place
    if place is not None:
        if not place.first:
            return None
        size = (place.bits + 7) // 8
        how = (size, "big", size * 8 - place.bits, place.bits)
    else:
        how = (first.type.size, "big" if first.endian == ">" else "little", 0, first.type.size * 8)
    return how, first.const & ((1 << how[3]) - 1)


def discriminator(messages: Sequence[Message]) -> Discriminator | None:
    """The leading constant that picks one of `messages` (sharing a code, or all without one), or None when some
    message has none, they differ in width or place, or two share a value (then content sizes tell them apart)."""
    if len(messages) < 2:
        return None
    found = [leading_constant(m) for m in messages]
    hows = {f[0] for f in found if f is not None}
    if None in found or len(hows) != 1:
        return None
    values = [f[1] for f in found if f is not None]
    if len(set(values)) != len(values):
        return None
    size, endian, shift, bits = hows.pop()
    assert endian in ("big", "little")
    return Discriminator(
        size=size,
        endian="big" if endian == "big" else "little",
        shift=shift,
        mask=(1 << bits) - 1,
        bits=bits,
        name=messages[0].fields[0].name,
        values=tuple(zip(values, messages, strict=True)),
    )
