"""Building messages from plain data (JSON objects), with errors that name the field at fault."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from enum import IntEnum, IntFlag

from serialspec.runtime.errors import EncodeError, shown
from serialspec.runtime.hexbytes import parse_hex
from serialspec.runtime.message import TYPE_CHECKING, Record, is_sequence


class UnknownFieldError(EncodeError):
    """A field the message does not have (check_keys): neither one of its own nor a value encode computes."""


def check_keys(data: Mapping[str, Any], known: Iterable[str], optional: Iterable[str], where: str) -> None:
    """Refuse unknown keys; `optional` keys (derived values such as counts) may be given and are ignored."""
    allowed = set(known) | set(optional)
    for key in data:
        if key not in allowed:
            raise UnknownFieldError(f"{where}: unknown field {key!r} (expected {', '.join(known) or 'no fields'})")


def check_given(data: Mapping[str, Any], name: str, compute: Callable[[], int], where: str) -> None:
    """A value encode computes (a count, a size, a `value:` expression, a constant) that the caller gave anyway:
    refused in one line unless it is the value encode writes (Modbus `count: 7` with 2 values is a mistake, never
    silently written as 2). Values the expression has no value for (a division by 0) are left to encode's refusal."""
    if name not in data:
        return
    given = integer(data[name], name, where)
    try:
        computed = compute()
    except (ZeroDivisionError, ValueError, TypeError, AttributeError, OverflowError):
        return  # the other fields are at fault: encode refuses them, naming the field
    if given != computed:
        raise EncodeError(f"{where}: {name} is given as {given}, but it is computed: {computed} (leave it out)")


def get(data: Mapping[str, Any], name: str, where: str) -> Any:
    try:
        return data[name]
    except KeyError:
        raise EncodeError(f"{where}: missing field {name!r}") from None


def mapping(value: Any, name: str, where: str) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise EncodeError(f"{where}: {name} must be an object, got {shown(value)}")
    return value


def as_bytes(value: Any, name: str, where: str) -> bytes:
    if isinstance(value, bytes | bytearray):
        return bytes(value)
    if isinstance(value, str):
        if not value.strip():
            return b""
        try:
            return parse_hex(value)
        except ValueError as exc:
            raise EncodeError(f"{where}: {name}: {exc}") from None
    if isinstance(value, list) and all(isinstance(v, int) and 0 <= v <= 255 for v in value):
        return bytes(value)
    raise EncodeError(f"{where}: {name} must be hex text or a list of byte values, got {shown(value)}")


def optional_bytes(data: Mapping[str, Any], name: str, where: str) -> bytes | None:
    """An optional frame element's bytes (`present_if`): None when left out or null."""
    value = data.get(name)
    return None if value is None else as_bytes(value, name, where)


if TYPE_CHECKING:
    from typing import Any, TypeVar

    E = TypeVar("E", bound=IntEnum)
    F = TypeVar("F", bound=IntFlag)


def integer(value: Any, name: str, where: str) -> int:
    """An integer given as data: true/false, text, fractions, lists are refused, naming the field."""
    if isinstance(value, int) and not isinstance(value, bool):
        return value
    raise EncodeError(f"{where}: {name} must be an integer, got {shown(value)}")


def number(value: Any, name: str, where: str) -> float:
    """A finite number given as data (NaN and infinities are refused)."""
    if isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value):
        return value
    raise EncodeError(f"{where}: {name} must be a finite number, got {shown(value)}")


def enum(cls: type[E], value: Any, name: str, where: str) -> E | int:
    """A member of the enum, or an integer the spec names no member for (its range is checked on encoding)."""
    if isinstance(value, cls):
        return value
    number = integer(value, name, where)
    return cls._value2member_map_.get(number, number)  # type: ignore[return-value]


def flags(cls: type[F], value: Any, maximum: int, name: str, where: str) -> F:
    """A set of flags: a member, or an integer 0..maximum (-1 is not "all flags")."""
    if isinstance(value, cls):
        return value
    number = integer(value, name, where)
    if not 0 <= number <= maximum:
        raise EncodeError(f"{where}: {name} = {shown(number)} is outside its range 0..{maximum}")
    return cls(number)


def items(value: Any, name: str, where: str) -> list[Any]:
    """The items of an array or group: a list."""
    if is_sequence(value):
        return list(value)
    raise EncodeError(f"{where}: {name} must be a list, got {shown(value)}")


def integers(value: Any, name: str, where: str) -> tuple[int, ...]:
    return tuple(integer(item, f"{name}[{index}]", where) for index, item in enumerate(items(value, name, where)))


def numbers(value: Any, name: str, where: str) -> tuple[float, ...]:
    return tuple(number(item, f"{name}[{index}]", where) for index, item in enumerate(items(value, name, where)))


def bits(value: Any, name: str, where: str) -> tuple[bool, ...]:
    """A list of bits: true/false (or 0/1); text, 2, 0.5 and the like are refused, naming the item."""
    result = []
    for index, item in enumerate(items(value, name, where)):
        if item is True or item is False or (item.__class__ is int and item in (0, 1)):
            result.append(bool(item))
        else:
            raise EncodeError(f"{where}: {name}[{index}] must be a bit (true/false or 0/1), got {shown(item)}")
    return tuple(result)


def text(value: Any, name: str, where: str) -> str:
    """Text given as data: a string (a number is not text)."""
    if isinstance(value, str):
        return value
    raise EncodeError(f"{where}: {name} must be text, got {shown(value)}")


def wrong_type(message: Any, exc: Exception) -> EncodeError:
    """The field of a message built in Python (not from data) whose value has the wrong type, as one line."""
    where = " ".join(p for p in (message.COMMAND, message.SUBCOMMAND, message.DIRECTION.value) if p)
    problem = _problem(message)
    return EncodeError(f"{where}: {problem}" if problem else f"{where}: {exc}")


def _problem(obj: Any, prefix: str = "") -> str:
    annotations = type(obj).__annotations__  # strings: the generated modules postpone annotations
    for field in obj.__match_args__:
        value = getattr(obj, field)
        name = prefix + field
        annotation = str(annotations[field])
        if annotation.startswith("tuple["):
            if not is_sequence(value):
                return f"{name} must be a tuple, got {shown(value)}"
            for index, item in enumerate(value):
                wrong = _value_problem(item, annotation[6:-1].split(",")[0].strip(), f"{name}[{index}]")
                if wrong:
                    return wrong
        elif wrong := _value_problem(value, annotation, name):
            return wrong
    return ""


def _value_problem(value: Any, annotation: str, name: str) -> str:
    kinds = {part.strip() for part in annotation.split("|")}
    if isinstance(value, Record):
        return _problem(value, name + ".")
    if "bool" in kinds:
        ok = value is True or value is False or (value.__class__ is int and value in (0, 1))
        return "" if ok else f"{name} must be a bit (true/false or 0/1), got {shown(value)}"
    if "str" in kinds:
        return "" if isinstance(value, str) else f"{name} must be text, got {shown(value)}"
    if "bytes" in kinds:
        return "" if isinstance(value, bytes | bytearray) else f"{name} must be bytes, got {shown(value)}"
    if "float" in kinds:
        ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
        return "" if ok else f"{name} must be a finite number, got {shown(value)}"
    if "int" in kinds:
        return (
            ""
            if isinstance(value, int) and not isinstance(value, bool)
            else f"{name} must be an integer, got {shown(value)}"
        )
    if kinds and not any(k[:1].isupper() for k in kinds):
        return ""
    if type(value).__name__ in kinds:  # a member of the field's own enum or flags (every value of its type named)
        return ""
    if not isinstance(value, Record):  # a class of the package: bit fields, a table block, a group item
        return f"{name} must be {annotation.split(' |')[0]}, got {shown(value)}"
    return ""
