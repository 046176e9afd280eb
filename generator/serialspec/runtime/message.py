"""The base of every generated message class."""

from __future__ import annotations

from enum import IntEnum, StrEnum
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


def enum_or_int(enum: type[E], value: int) -> E | int:
    """The enum member for a wire value, or the plain value when the spec names none (no data is dropped)."""
    return enum._value2member_map_.get(value, value)  # type: ignore[return-value]
