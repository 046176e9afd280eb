"""Immutable value classes for the model, made in microseconds each: what `@dataclass(frozen=True)` gave, without it.

`dataclasses` writes and compiles six methods for every class it decorates (about half a millisecond a class): for
the model's forty-odd classes that was a tenth of what `serialspec generate` does for an edited spec. `frozen`
installs shared methods instead, which read the class's field names: the same constructor (positional or keyword
arguments, defaults and `field(default_factory=...)`, the fields of a frozen base first), equality and hash by
field values within one class, the repr, `__match_args__`, assignment refused with FrozenInstanceError, and
`__dataclass_fields__` (dataclasses.fields, replace and asdict work on them). Methods a class defines itself are
kept, as dataclasses keeps them. `dataclass_transform` tells type checkers what they are. `mutable` does the same
for a plain `@dataclass` (fields may be assigned; not hashable). Not supported, as nothing here uses them:
`field(init=False)`, `__post_init__`, and `@dataclass` subclasses of these classes (use `frozen` or `mutable`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import MISSING, FrozenInstanceError
from typing import Any, TypeVar, dataclass_transform

T = TypeVar("T")


class _Layout:
    """A value class's fields: names in order, defaults, default factories."""

    __slots__ = ("names", "known", "defaults", "factories")

    def __init__(self, names: tuple[str, ...], defaults: dict[str, Any], factories: dict[str, Callable[[], Any]]):
        self.names = names
        self.known = frozenset(names)
        self.defaults = defaults
        self.factories = factories


_LAYOUTS: dict[type, _Layout] = {}
_FIELD = getattr(dataclasses, "_FIELD", None)  # what marks a dataclass field (not a class or init-only variable)


@dataclass_transform(eq_default=True, frozen_default=True, field_specifiers=(dataclasses.field,))
def frozen(cls: type[T]) -> type[T]:
    """Make `cls` an immutable value class of the fields it annotates (after those of its value-class bases)."""
    return _make(cls, _METHODS)


@dataclass_transform(eq_default=True, field_specifiers=(dataclasses.field,))
def mutable(cls: type[T]) -> type[T]:
    """Make `cls` a value class whose fields may be assigned (`@dataclass`): not hashable, as dataclasses makes it."""
    return _make(cls, _MUTABLE_METHODS)


def _make(cls: type[T], methods: dict[str, Any]) -> type[T]:
    names: list[str] = []
    defaults: dict[str, Any] = {}
    factories: dict[str, Callable[[], Any]] = {}
    for base in reversed(cls.__mro__[1:]):
        layout = _LAYOUTS.get(base)
        if layout is not None:
            names += [name for name in layout.names if name not in names]
            defaults.update(layout.defaults)
            factories.update(layout.factories)
    for name, annotation in cls.__dict__.get("__annotations__", {}).items():
        if str(annotation).startswith(("ClassVar", "typing.ClassVar")):
            continue
        if name not in names:
            names.append(name)
        defaults.pop(name, None)
        factories.pop(name, None)
        value = cls.__dict__.get(name, MISSING)
        if isinstance(value, dataclasses.Field):
            if not value.init:
                raise TypeError(f"{cls.__qualname__}.{name}: field(init=False) is not supported here")
            if value.default is not MISSING:
                defaults[name] = value.default
                setattr(cls, name, value.default)
            elif value.default_factory is not MISSING:
                factories[name] = value.default_factory
                delattr(cls, name)
            else:
                delattr(cls, name)
        elif value is not MISSING:
            defaults[name] = value
    if hasattr(cls, "__post_init__"):
        raise TypeError(f"{cls.__qualname__}: __post_init__ is not supported here")
    seen_default = ""
    for name in names:
        if name in defaults or name in factories:
            seen_default = seen_default or name
        elif seen_default:
            raise TypeError(f"non-default argument {name!r} follows default argument {seen_default!r}")
    _LAYOUTS[cls] = _Layout(tuple(names), defaults, factories)
    setattr(cls, "__dataclass_fields__", _fields(cls, names, defaults, factories))  # noqa: B010 (not in the type)
    own = cls.__dict__
    for method, function in methods.items():
        if method not in own or (method == "__hash__" and own[method] is None):  # eq defined here: hash set to None
            setattr(cls, method, function)
    setattr(cls, "__match_args__", tuple(names))  # noqa: B010 (not in the type)
    return cls


def _layout(cls: type) -> _Layout:
    layout = _LAYOUTS.get(cls)
    if layout is None:  # a subclass that is not made a value class itself: its nearest base's fields
        layout = next(_LAYOUTS[base] for base in cls.__mro__ if base in _LAYOUTS)
    return layout


def _fields(
    cls: type, names: list[str], defaults: dict[str, Any], factories: dict[str, Callable[[], Any]]
) -> dict[str, dataclasses.Field[Any]]:
    """Field descriptions as dataclasses keeps them: `dataclasses.fields`, `replace` and `asdict` work as before."""
    annotations: dict[str, Any] = {}
    for klass in reversed(cls.__mro__):
        annotations.update(klass.__dict__.get("__annotations__", {}))
    described = {}
    for name in names:
        given: dict[str, Any] = (
            {"default": defaults[name]}
            if name in defaults
            else {"default_factory": factories[name]}
            if name in factories
            else {}
        )
        field: dataclasses.Field[Any] = dataclasses.field(**given)
        field.name = name
        field.type = annotations.get(name)
        field.kw_only = False
        field._field_type = _FIELD  # type: ignore[attr-defined]
        described[name] = field
    return described


def _init(self: Any, *args: Any, **kwargs: Any) -> None:
    cls = type(self)
    layout = _layout(cls)
    names = layout.names
    if not kwargs and len(args) == len(names):  # every field given in order: the common case
        self.__dict__.update(zip(names, args, strict=True))
        return
    if len(args) > len(names):
        raise TypeError(f"{cls.__qualname__}() takes {len(names)} arguments but {len(args)} were given")
    values = dict(zip(names, args, strict=False))  # fewer arguments than fields: the rest by keyword or default
    for name, value in kwargs.items():
        if name in values:
            raise TypeError(f"{cls.__qualname__}() got multiple values for argument {name!r}")
        if name not in layout.known:
            raise TypeError(f"{cls.__qualname__}() got an unexpected keyword argument {name!r}")
        values[name] = value
    fields = self.__dict__
    for name in names:  # stored in field order, whatever order they were given in (vars() lists them so)
        if name in values:
            fields[name] = values[name]
        elif name in layout.defaults:
            fields[name] = layout.defaults[name]
        elif name in layout.factories:
            fields[name] = layout.factories[name]()
        else:
            raise TypeError(f"{cls.__qualname__}() missing required argument: {name!r}")


def _values(self: Any) -> tuple[Any, ...]:
    fields = self.__dict__
    return tuple([fields[name] for name in _layout(type(self)).names])


def _eq(self: Any, other: object) -> Any:  # NotImplemented for another class
    if other.__class__ is not self.__class__:
        return NotImplemented
    return _values(self) == _values(other)


def _hash(self: Any) -> int:
    return hash(_values(self))


def _repr(self: Any) -> str:
    fields = self.__dict__
    shown = ", ".join(f"{name}={fields[name]!r}" for name in _layout(type(self)).names)
    return f"{type(self).__qualname__}({shown})"


def _setattr(self: Any, name: str, value: Any) -> None:
    raise FrozenInstanceError(f"cannot assign to field {name!r}")


def _delattr(self: Any, name: str) -> None:
    raise FrozenInstanceError(f"cannot delete field {name!r}")


_METHODS: dict[str, Callable[..., Any]] = {
    "__init__": _init,
    "__repr__": _repr,
    "__eq__": _eq,
    "__hash__": _hash,
    "__setattr__": _setattr,
    "__delattr__": _delattr,
}
_MUTABLE_METHODS: dict[str, Any] = {"__init__": _init, "__repr__": _repr, "__eq__": _eq, "__hash__": None}
