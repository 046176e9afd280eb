"""The base of every generated message class, and what the generated codec needs to build messages fast."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from enum import Enum, IntEnum, StrEnum
from typing import Any, ClassVar, TypeVar


class Direction(StrEnum):
    REQUEST = "request"
    RESPONSE = "response"


class Message:
    """A decoded frame: one command (and sub-command) in one direction, with its field values in wire units."""

    __slots__ = ()
    PROTOCOL: ClassVar[str]
    COMMAND: ClassVar[str]
    SUBCOMMAND: ClassVar[str | None]
    DIRECTION: ClassVar[Direction]

    def to_fields(self) -> dict[str, Any]:
        """Field values as plain JSON-able data: raw wire values, nested objects as dicts, lists as lists."""
        raise NotImplementedError


E = TypeVar("E", bound=IntEnum)
M = TypeVar("M", bound=Enum)


def enum_or_int(enum: type[E], value: int) -> E | int:
    """The enum member for a wire value, or the plain value when the spec names none (no data is dropped)."""
    return enum._value2member_map_.get(value, value)  # type: ignore[return-value]


def members(enum: type[M]) -> dict[Any, M]:
    """The live value -> member map of an enum or flag class (flag classes add combined values as they are made).

    The codec looks wire values up in it directly: `members.get(value, value)` is what enum_or_int does, without
    a call per field.
    """
    return enum._value2member_map_  # type: ignore[return-value]


def slot_setters(cls: type) -> tuple[Callable[[Any, Any], None], ...]:
    """One setter per field of a frozen slotted dataclass, in field order, that stores into the field's slot.

    The dataclass __init__ of a frozen class stores every field through object.__setattr__, which costs more than
    unpacking a whole frame; the codec builds decoded messages with `object.__new__` and these setters instead
    (the values come from a checked frame, so __init__ has nothing else to do). Raises TypeError for a class
    without slots, so a change of the message classes cannot silently fall back to something slower or wrong.
    """
    setters = []
    for field in dataclasses.fields(cls):
        slot = cls.__dict__.get(field.name)
        if slot is None or not hasattr(slot, "__set__") or type(slot).__name__ != "member_descriptor":
            raise TypeError(f"{cls.__name__}.{field.name} is not a slot")
        setters.append(slot.__set__)
    return tuple(setters)


def compare(value: float | None, op: str, operand: float) -> bool:
    """A device parameter's `optional_when` condition: ==, !=, >= or <= (None, an unknown value, never holds)."""
    if value is None:
        return False
    if op == ">=":
        return value >= operand
    if op == "<=":
        return value <= operand
    if op == "!=":
        return value != operand
    return value == operand
