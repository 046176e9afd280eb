"""The base of every generated message class, and what the generated codec needs to build messages fast."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import FrozenInstanceError
from enum import Enum, IntEnum, StrEnum
from typing import Any, ClassVar, TypeVar, dataclass_transform


class Direction(StrEnum):
    REQUEST = "request"
    RESPONSE = "response"


@dataclass_transform(eq_default=True, frozen_default=True)
class Record:
    """The base of the generated value classes: slotted, immutable, compared and hashed by field values.

    The generated classes used to be frozen slotted dataclasses; the decorator's work (compiling __init__, __eq__,
    __repr__, __hash__ and rebuilding the class for its slots) cost ~0.35 ms per class at import, most of a client's
    import time. Now each class lists its fields in `__match_args__` and `__slots__` and has a generated __init__;
    equality, hashing, repr, pickling and immutability (FrozenInstanceError, as before) come from here.
    `dataclass_transform` tells type checkers what it is: keyword construction, frozen fields.
    """

    __slots__ = ()
    __match_args__: ClassVar[tuple[str, ...]] = ()

    def __setattr__(self, name: str, value: Any) -> None:
        raise FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self, name: str) -> None:
        raise FrozenInstanceError(f"cannot delete field {name!r}")

    def _values(self) -> tuple[Any, ...]:
        return tuple([getattr(self, name) for name in self.__match_args__])

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return self._values() == other._values()

    def __hash__(self) -> int:
        return hash(self._values())

    def __repr__(self) -> str:
        values = ", ".join(f"{name}={getattr(self, name)!r}" for name in self.__match_args__)
        return f"{type(self).__qualname__}({values})"

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), self._values())  # __init__ takes the fields positionally, in this order


def field_names(record: Record | type[Record]) -> tuple[str, ...]:
    """The field names of a generated class or instance, in order (what dataclasses.fields gave before)."""
    return record.__match_args__


R = TypeVar("R", bound=Record)


def replace(record: R, **changes: Any) -> R:
    """A copy of `record` with some fields changed (what dataclasses.replace gave before), checked by __init__."""
    unknown = sorted(set(changes) - set(record.__match_args__))
    if unknown:
        raise TypeError(f"{type(record).__qualname__} has no field {', '.join(map(repr, unknown))}")
    values = {name: getattr(record, name) for name in record.__match_args__}
    return type(record)(**(values | changes))


class Message(Record):
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
    """One setter per field of a generated (frozen, slotted) class, in field order, that stores into the field's slot.

    __init__ of a frozen class stores every field through object.__setattr__, which costs more than unpacking a
    whole frame; the codec builds decoded messages with `object.__new__` and these setters instead (the values come
    from a checked frame, so __init__ has nothing else to do). Raises TypeError for a class without slots, so a
    change of the message classes cannot silently fall back to something slower or wrong.
    """
    setters = []
    for name in getattr(cls, "__match_args__", ()):
        slot = cls.__dict__.get(name)
        if slot is None or not hasattr(slot, "__set__") or type(slot).__name__ != "member_descriptor":
            raise TypeError(f"{cls.__name__}.{name} is not a slot")
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
