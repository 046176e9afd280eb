"""The base of every generated message class, and what the generated codec needs to build messages fast."""

from __future__ import annotations

import enum
import keyword
from collections import _tuplegetter  # type: ignore[attr-defined]
from collections.abc import Callable
from enum import Enum, StrEnum

# typing.TYPE_CHECKING without importing typing: typing takes about a fifth of a bare Python start, and nothing
# that `serialspec decode PACKAGE` or a generated package imports needs it at run time (tests/test_cache.py)
TYPE_CHECKING = False

if TYPE_CHECKING:  # to a type checker, and in what they make, the standard library's classes
    from enum import IntEnum as IntEnum
    from enum import IntFlag as IntFlag
else:
    try:
        from enum import _simple_enum  # how the standard library builds its own enums (re, http, ssl) quickly
    except ImportError:  # a Python without it: generated enums are built the usual way
        _simple_enum = None

    class _QuickEnum(type):
        """Builds a generated enum or flag class (`class MavType(IntEnum)`, IntEnum from here) with
        enum._simple_enum: the very class `class MavType(enum.IntEnum)` makes (a subclass of enum.IntEnum or
        enum.IntFlag: its members, their repr, str, format and pickling, value lookup, flag boundary and operators;
        tests/test_quick_enums.py compares them), in about half the time. What it leaves out are the class
        statement's checks of each member (about 10 µs each), whose names and values the generator checked."""

        def __new__(metacls, cls: str, bases: tuple[type, ...], classdict: dict[str, Any]) -> Any:
            if not bases:  # IntEnum or IntFlag below: a plain class
                return super().__new__(metacls, cls, bases, classdict)
            return _simple_enum(bases[0].standard)(type(cls, (), classdict))

    if _simple_enum is None:
        IntEnum, IntFlag = enum.IntEnum, enum.IntFlag
    else:

        class IntEnum(metaclass=_QuickEnum):
            """The base a generated enum class names: the class made is a subclass of enum.IntEnum."""

            standard = enum.IntEnum

        class IntFlag(metaclass=_QuickEnum):
            """The base a generated flag class names: the class made is a subclass of enum.IntFlag."""

            standard = enum.IntFlag


class Direction(StrEnum):
    REQUEST = "request"
    RESPONSE = "response"


if TYPE_CHECKING:  # to a type checker a record is a plain object with frozen attributes, not a sequence
    from typing import Any, ClassVar, TypeGuard, TypeVar, dataclass_transform

    R = TypeVar("R", bound="Record")
    E = TypeVar("E", bound=IntEnum)
    M = TypeVar("M", bound=Enum)
    _Base = object

    def build(cls: type[R], values: tuple[Any, ...], /) -> R:
        """A record of class `cls` holding `values`, its fields in order, unchecked (what decoders call)."""
        raise NotImplementedError

else:
    _Base = tuple
    build = tuple.__new__

    def dataclass_transform(**_: object) -> Callable[[type], type]:
        return lambda cls: cls  # what typing's does at run time, but for a marker attribute


class _Required:
    """The default of a parameter that has none but follows one that has (a frame value whose bit fields are all
    constants or defaults, before the fields): the class refuses it, as Python would a missing argument."""

    def __repr__(self) -> str:
        return "REQUIRED"


REQUIRED: Any = _Required()


def missing(cls: type, name: str) -> TypeError:
    """The error for a parameter left at REQUIRED."""
    return TypeError(f"{cls.__name__}() missing required argument: {name!r}")


_ALL = slice(None)
# tuple's own methods, called on records (typed loosely: to a type checker a record is not a tuple)
_items: Callable[[object, slice], tuple[Any, ...]] = tuple.__getitem__  # type: ignore[assignment]
_tuple_eq: Callable[[object, object], bool] = tuple.__eq__  # type: ignore[assignment]
_tuple_ne: Callable[[object, object], bool] = tuple.__ne__
_tuple_hash: Callable[[object], int] = tuple.__hash__  # type: ignore[assignment]


@dataclass_transform(eq_default=True, frozen_default=True)
class Record(_Base):
    """The base of the generated value classes: immutable, compared and hashed by field values.

    A record is stored as a tuple of its field values (a tuple subclass, hidden from type checkers): `build(cls,
    values)` makes one in a single C call (~0.1 µs whatever the number of fields), where filling slots costs ~45 ns
    a field, and a decoder passes the tuple `struct.unpack_from` gives straight to it. Each field is read through a
    C descriptor (`collections._tuplegetter`, what namedtuple uses) that __init_subclass__ installs from
    `__match_args__`; a generated class declares its fields as annotations and has a generated `__new__`.

    Nothing of the tuple shows: a record equals only a record of its own class with equal fields (never a plain
    tuple), does not order, is always true (even with no fields), has no length, cannot be indexed, iterated,
    added or multiplied, and assignment raises FrozenInstanceError as a frozen dataclass did. Its hash is the hash
    of its field values, its repr names them, and it pickles and copies by class and values. `dataclass_transform`
    tells type checkers what it is: keyword construction, frozen fields.
    """

    __slots__ = ()
    __match_args__: ClassVar[tuple[str, ...]] = ()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        names = cls.__dict__.get("__match_args__", ())
        for index, name in enumerate(names):
            setattr(cls, name, _tuplegetter(index, f"Field {index} of {cls.__name__}: {name}."))

    def __setattr__(self, name: str, value: Any) -> None:
        from dataclasses import FrozenInstanceError  # imported when raised: dataclasses imports inspect and ast

        raise FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self, name: str) -> None:
        from dataclasses import FrozenInstanceError

        raise FrozenInstanceError(f"cannot delete field {name!r}")

    def _values(self) -> tuple[Any, ...]:
        return _items(self, _ALL)  # a plain tuple of the field values

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            # a plain tuple would otherwise compare by its items, through tuple's own comparison
            return False if isinstance(other, tuple) else NotImplemented
        return _tuple_eq(self, other)

    def __ne__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return True if isinstance(other, tuple) else NotImplemented
        return _tuple_ne(self, other)

    __hash__ = _tuple_hash  # the hash of the field values, as before

    def __repr__(self) -> str:
        values = ", ".join(f"{name}={getattr(self, name)!r}" for name in self.__match_args__)
        return f"{type(self).__qualname__}({values})"

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), self._values())  # __new__ takes the fields positionally, in this order

    def __bool__(self) -> bool:
        return True  # a tuple of no fields would be false


def _not_a_sequence(self: Record, *args: Any) -> Any:
    raise TypeError(f"{type(self).__qualname__} is a record, not a sequence: use its fields by name")


for _name in ("__len__", "__iter__", "__getitem__", "__contains__", "__add__", "__mul__", "__rmul__", "count", "index"):
    setattr(Record, _name, _not_a_sequence)


def _unordered(self: Record, other: object) -> Any:
    if isinstance(other, tuple):  # tuple's own ordering would otherwise answer for `(1,) < record`
        raise TypeError(f"{type(self).__qualname__} records are not ordered")
    return NotImplemented


for _name in ("__lt__", "__le__", "__gt__", "__ge__"):
    setattr(Record, _name, _unordered)


def is_sequence(value: object) -> TypeGuard[tuple[Any, ...] | list[Any]]:
    """A list or tuple of values, not a record (which is a tuple underneath): how the runtime tells lists apart."""
    return isinstance(value, tuple | list) and not isinstance(value, Record)


def field_names(record: Record | type[Record]) -> tuple[str, ...]:
    """The field names of a generated class or instance, in order (what dataclasses.fields gave before)."""
    return record.__match_args__


def spec_name(name: str) -> str:
    """A field's name in the spec and in to_fields()/JSON, from its attribute's: a field named after a Python keyword
    has the attribute `class_` (serialspec.lang.names.python_name), every other field its own name."""
    return name[:-1] if name.endswith("_") and keyword.iskeyword(name[:-1]) else name


def field_keys(record: Record | type[Record]) -> tuple[str, ...]:
    """The keys of a generated class's to_fields() and from_fields(), in order: its fields' spec names."""
    return tuple(spec_name(name) for name in record.__match_args__)


def replace(record: R, **changes: Any) -> R:
    """A copy of `record` with some fields changed (what dataclasses.replace gave before), checked by __new__."""
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
    """One setter per field of a frozen, slotted class, in field order, that stores into the field's slot.

    Generated classes no longer need it: they are tuples underneath and decoders make them with `build`, in one
    call. For a frozen slotted class of your own, `object.__new__` and these setters fill an instance without its
    __init__ (which stores each field through object.__setattr__). Raises TypeError for a class without slots, so
    a change of the class cannot silently fall back to something slower or wrong.
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


def takes_request(function: Callable[..., Any]) -> bool:
    """Whether a codec's encode or decode takes `request` (its replies are made and read with their request)."""
    import inspect  # only here: importing it costs more than a generated package's import

    try:
        return "request" in inspect.signature(function).parameters
    except (TypeError, ValueError):  # no signature to read: an ordinary codec
        return False
