"""Messages picked by a constant leading bit field of their content (RTCM 3's 12-bit message number): where the
messages that share a code (or, in frames without a command element, all of a direction's messages) each begin with
a constant integer field of one width at one place, and no two constants are equal, decode and the stream parser
pick a message by that value before its size, also where sizes overlap. Constants of different widths that each
lead the content's first bits (MIDI's status byte: a u4 `0xE` before a u4 channel beside a u8 `0xF9`) pick as a
prefix code: no constant may begin another, and each is read as all the values of the widest it begins. Otherwise
they are told apart by their content size alone. No key of its own: the `const` of each message's first field says
it (docs/language.md, "Messages picked by their leading constant")."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

from serialspec.lang.frozen import frozen
from serialspec.lang.model.commands import Message
from serialspec.lang.model.fields import Scalar
from serialspec.lang.model.sizes import sized_by_itself


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
    values: tuple[tuple[int, Message], ...]  # every value read, with the message it picks
    # each message's constant as written: (value, its width in bits, the message)
    picks: tuple[tuple[int, int, Message], ...]

    def known(self) -> str:
        """Each message's constant, for messages: `set_position: 4, read: 5` (`0x9/4 bits` where widths differ)."""
        mixed = len({bits for _, bits, _ in self.picks}) > 1
        shown = [
            f"{m.command}: {value:#x}/{bits} bits" if mixed else f"{m.command}: {value}"
            for value, bits, m in self.picks
        ]
        return ", ".join(shown)

    def ranges(self) -> tuple[tuple[int, int, Message], ...]:
        """The values read as runs of the same message: (lowest, highest, message), lowest first (a prefix code's
        narrower constant is one run of every value of the widest it begins)."""
        runs: list[tuple[int, int, Message]] = []
        for value, message in sorted(self.values, key=lambda item: item[0]):
            if runs and runs[-1][2] is message and runs[-1][1] == value - 1:
                runs[-1] = (runs[-1][0], value, message)
            else:
                runs.append((value, value, message))
        return tuple(runs)

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
    if first.low_bits is not None or first.sign_magnitude:
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


# The most values a prefix code of constants of different widths may be read as (each narrower constant stands for
# every value of the widest it begins: a u4 beside a u8 is 16 values), so the tables stay small in every output.
MOST_PREFIX_VALUES = 256


def discriminator(messages: Sequence[Message]) -> Discriminator | None:
    """The leading constant that picks one of `messages` (sharing a code, or all without one), or None when some
    message has none, two share a value, or they differ in width or place and are no prefix code of the content's
    first bits (then content sizes tell them apart)."""
    if len(messages) < 2:
        return None
    found = [leading_constant(m) for m in messages]
    if None in found:
        return None
    leads = [f for f in found if f is not None]
    hows = {how for how, _ in leads}
    if len(hows) == 1:
        values = [value for _, value in leads]
        if len(set(values)) != len(values):
            return None
        size, endian, shift, bits = hows.pop()
        return Discriminator(
            size=size,
            endian="big" if endian == "big" else "little",
            shift=shift,
            mask=(1 << bits) - 1,
            bits=bits,
            name=messages[0].fields[0].name,
            values=tuple(zip(values, messages, strict=True)),
            picks=tuple((value, bits, m) for value, m in zip(values, messages, strict=True)),
        )
    return _prefix_code(messages, leads)


def _prefix_code(
    messages: Sequence[Message], leads: list[tuple[tuple[int, str, int, int], int]]
) -> Discriminator | None:
    """Constants of different widths, each the first bits of the content read big-endian (a bit field, a byte, or a
    big-endian integer), as one prefix code read as wide as the widest; None when one begins another, a message is
    shorter than the widest, or the code would be read as more than MOST_PREFIX_VALUES values."""
    widths = []
    for (size, endian, shift, bits), _ in leads:
        if size > 1 and endian != "big" or shift != size * 8 - bits:
            return None  # a little-endian integer's first bits are not its highest
        widths.append(bits)
    widest = max(widths)
    size = (widest + 7) // 8
    if sum(1 << (widest - bits) for bits in widths) > MOST_PREFIX_VALUES:
        return None
    if any(m.min_size < size for m in messages):
        return None
    values: dict[int, Message] = {}
    for message, bits, (_, value) in zip(messages, widths, leads, strict=True):
        first = value << (widest - bits)
        for each in range(first, first + (1 << (widest - bits))):
            if each in values:
                return None  # one constant begins another (or two are equal)
            values[each] = message
    return Discriminator(
        size=size,
        endian="big",
        shift=size * 8 - widest,
        mask=(1 << widest) - 1,
        bits=widest,
        name=messages[0].fields[0].name,
        values=tuple(sorted(values.items(), key=lambda item: item[0])),
        picks=tuple((value, bits, m) for m, bits, (_, value) in zip(messages, widths, leads, strict=True)),
    )


def sizing_message(messages: Sequence[Message]) -> Message | None:
    """The message whose content size rule sizes the frames of a code without a length element: its one message, or
    one of several that share the code, all of one fixed content size (requests picked by a leading constant, iRobot's
    sensor queries 8E and a packet id); None where no one rule sizes them."""
    if len(messages) == 1:
        return messages[0]
    if len({(m.min_size, m.max_size) for m in messages}) == 1 and messages[0].min_size == messages[0].max_size:
        return messages[0]
    return None


def sizing_lead(messages: Sequence[Message]) -> Discriminator | None:
    """Where no one message sizes the frames of a code without a length element (sizing_message), the leading
    constant that picks the message whose own size rule does (Kondo ICS: the command in a byte's top bits, each
    message of its own size); None where there is none or some message is not sized by its own bytes."""
    if sizing_message(messages) is not None or any(m.subcommand is not None for m in messages):
        return None  # (sub-commands: told apart by their selector)
    lead = discriminator(messages)
    if lead is None or not all(sized_by_itself(m.fields) for m in messages):
        return None
    return lead


def why_not_picked(messages: Sequence[Message]) -> str:
    """Why no leading constant sizes the frames of `messages` (sizing_lead is None), as words for the loader's
    line; "" where none of them begins with a constant (or one of them sizes them all)."""
    leads = [leading_constant(m) for m in messages]
    if all(lead is None for lead in leads) or sizing_message(messages) is not None:
        return ""
    without = next((m for m, lead in zip(messages, leads, strict=True) if lead is None), None)
    if without is not None:
        return f" (or a leading constant, which {without.command!r} does not begin with)"
    if discriminator(messages) is not None:
        unsized = next(m for m in messages if not sized_by_itself(m.fields))
        return (
            f" (picked by their leading constant, each needs a size its own bytes tell, which {unsized.command}'s "
            "do not: fixed fields, a count before what it counts, a NUL-terminated text last)"
        )
    found = [(m, how, value) for m, (how, value) in zip(messages, (lead for lead in leads if lead), strict=True)]
    for message, (_, _, _, bits), value in found:
        for other, (_, _, _, wider), longer in found:
            if other is not message and wider >= bits and longer >> (wider - bits) == value:
                return (
                    f" (a leading constant cannot pick: {other.command}'s {longer:#x} of {wider} bits begins with "
                    f"{message.command}'s {value:#x} of {bits} bits)"
                )
    return (
        " (a leading constant picks only where each message begins with a constant bit field, byte or big-endian "
        f"integer, none beginning another, and reads as at most {MOST_PREFIX_VALUES} values)"
    )
