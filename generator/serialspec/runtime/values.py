"""`@dataclass(frozen=True)` for the runtime's value classes, without importing dataclasses.

`dataclasses` imports inspect (and with it ast, dis, tokenize): about as much CPU time as a bare Python start, more
than the rest of `serialspec decode PACKAGE HEX` (bench/startup.py, tests/test_cache.py). The frame engine's layouts
(runtime/framing.py), the text runtime (runtime/text.py) and generated text message classes, and the checksum
algorithms and frame transforms (serialspec/checksums/, transforms/), which generated packages import, are declared
with this module's `dataclass` and `field` instead. They behave as frozen dataclasses: keyword or positional
construction with defaults, `field(default=..., default_factory=..., init=False, compare=False, repr=False)`,
`__post_init__`, equality and hashing by the compared fields (an instance equals only one of its own class),
`Name(field=value, ...)` as repr, `__match_args__`, assignment raising dataclasses.FrozenInstanceError, pickling and
copying; methods a class defines itself are kept. `replace`, `fields` and `asdict` (of fields holding plain values)
work on them as dataclasses' do on dataclasses; `is_value` tells them apart. To a type checker they are dataclasses
(the names are dataclasses' own). Not supported (nothing here uses it): anything but `frozen=True`.
"""

from __future__ import annotations

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from dataclasses import asdict, dataclass, field, fields, replace
    from typing import Any
else:
    _MISSING = object()

    class _Field:
        __slots__ = ("name", "default", "default_factory", "init", "compare", "repr")

        def __init__(
            self,
            default: Any = _MISSING,
            default_factory: Any = _MISSING,
            init: bool = True,
            compare: bool = True,
            repr: bool = True,
        ) -> None:
            self.name = ""
            self.default, self.default_factory, self.init = default, default_factory, init
            self.compare, self.repr = compare, repr

        def __repr__(self) -> str:
            return f"Field(name={self.name!r})"

    def field(
        *,
        default: Any = _MISSING,
        default_factory: Any = _MISSING,
        init: bool = True,
        compare: bool = True,
        repr: bool = True,
    ) -> Any:
        if default is not _MISSING and default_factory is not _MISSING:
            raise ValueError("cannot specify both default and default_factory")
        return _Field(default, default_factory, init, compare, repr)

    def dataclass(cls: type | None = None, /, *, frozen: bool = False) -> Any:
        if not frozen:
            raise TypeError("serialspec.runtime.values makes frozen value classes only: @dataclass(frozen=True)")
        return _make if cls is None else _make(cls)

    def fields(value: Any) -> tuple[_Field, ...]:
        found = getattr(value, "__value_fields__", None)
        if found is None:
            raise TypeError("fields() should be called on a value class or instance")
        return tuple(found.values())

    def replace(value: Any, /, **changes: Any) -> Any:
        found = getattr(type(value), "__value_fields__", None)
        if found is None:
            raise TypeError("replace() should be called on value class instances")
        for name in changes:
            if name in found and not found[name].init:
                raise ValueError(f"field {name} is declared with init=False, it cannot be specified with replace()")
        given = {name: getattr(value, name) for name, f in found.items() if f.init and name not in changes}
        return type(value)(**given, **changes)

    def _frozen_setattr(self: object, name: str, value: object) -> None:
        from dataclasses import FrozenInstanceError  # imported when raised

        raise FrozenInstanceError(f"cannot assign to field {name!r}")

    def _frozen_delattr(self: object, name: str) -> None:
        from dataclasses import FrozenInstanceError

        raise FrozenInstanceError(f"cannot delete field {name!r}")

    def _eq(self: Any, other: Any) -> Any:
        if other.__class__ is not self.__class__:
            return NotImplemented
        names = self.__value_compared__
        return tuple(getattr(self, n) for n in names) == tuple(getattr(other, n) for n in names)

    def _hash(self: Any) -> int:
        return hash(tuple(getattr(self, name) for name in self.__value_compared__))

    def _repr(self: Any) -> str:
        shown = ", ".join(f"{name}={getattr(self, name)!r}" for name in self.__value_shown__)
        return f"{type(self).__qualname__}({shown})"

    def asdict(value: Any) -> dict[str, Any]:
        """The fields of a value class instance by name (as dataclasses.asdict gives for fields of plain values)."""
        return {name: getattr(value, name) for name in value.__value_fields__}

    def _make(cls: type) -> type:
        found: dict[str, _Field] = {}
        for base in reversed(cls.__mro__[1:]):
            found.update(getattr(base, "__value_fields__", {}))
        own = cls.__dict__.get("__annotations__", {})
        for name, annotation in own.items():
            if isinstance(annotation, str) and annotation.replace("typing.", "").startswith("ClassVar"):
                continue
            value = cls.__dict__.get(name, _MISSING)
            f = value if isinstance(value, _Field) else _Field(value)
            f.name = name
            found[name] = f
            if f.default is _MISSING:
                if name in cls.__dict__:
                    delattr(cls, name)
            else:
                setattr(cls, name, f.default)
        cls.__value_fields__ = found
        cls.__value_compared__ = tuple(name for name, f in found.items() if f.compare)
        cls.__value_shown__ = tuple(name for name, f in found.items() if f.repr)
        _add(cls, "__init__", _init(cls, found))
        _add(cls, "__repr__", _repr)
        cls.__setattr__ = _frozen_setattr
        cls.__delattr__ = _frozen_delattr
        _add(cls, "__eq__", _eq)
        if cls.__dict__.get("__hash__", None) is None:  # none of its own (defining __eq__ sets it to None)
            cls.__hash__ = _hash
        _add(cls, "__match_args__", tuple(name for name, f in found.items() if f.init))
        return cls

    def _add(cls: type, name: str, value: Any) -> None:
        if name not in cls.__dict__:
            setattr(cls, name, value)

    def _init(cls: type, found: dict[str, _Field]) -> Any:
        """An __init__ taking the fields as arguments (positional in order, or by name), with their defaults. Not
        compiled from source as dataclasses does: compiling costs about a millisecond a class, which a command's
        start pays for every class it imports. Every field given in order (the hot paths) costs what dataclasses'
        __init__ does; other calls bind their arguments here, about a microsecond more."""
        names = tuple(name for name, f in found.items() if f.init)
        known = frozenset(names)
        defaults = {name: f.default for name, f in found.items() if f.init and f.default is not _MISSING}
        factories = tuple(
            (name, f.default_factory) for name, f in found.items() if f.init and f.default_factory is not _MISSING
        )
        required = tuple(name for name, f in found.items() if f.init and f.default is f.default_factory is _MISSING)
        seen_default = False
        for name in names:
            if name in required and seen_default:
                raise TypeError(f"non-default argument {name!r} follows default argument")
            seen_default = seen_default or name not in required
        derived = tuple(
            (name, f.default, f.default_factory)
            for name, f in found.items()
            if not f.init and (f.default is not _MISSING or f.default_factory is not _MISSING)
        )
        post_init = hasattr(cls, "__post_init__")
        where = f"{cls.__qualname__}.__init__()"

        def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
            d = self.__dict__
            if len(args) == len(names) and not kwargs:  # every field in order (what the runtime's hot paths do)
                d.update(zip(names, args, strict=True))
            else:
                _bind(d, args, kwargs)
            if derived:
                for name, default, factory in derived:
                    d[name] = default if factory is _MISSING else factory()
            if post_init:
                self.__post_init__()

        def _bind(d: dict[str, Any], args: tuple[Any, ...], kwargs: dict[str, Any]) -> None:
            if defaults:
                d.update(defaults)
            if args:
                if len(args) > len(names):
                    raise TypeError(
                        f"{where} takes {len(names) + 1} positional arguments but {len(args) + 1} were given"
                    )
                d.update(zip(names, args, strict=False))  # the first len(args) fields
            if kwargs:
                for name in kwargs:
                    if name not in known:
                        raise TypeError(f"{where} got an unexpected keyword argument {name!r}")
                    if names.index(name) < len(args):
                        raise TypeError(f"{where} got multiple values for argument {name!r}")
                d.update(kwargs)
            for name, factory in factories:
                if name not in kwargs and names.index(name) >= len(args):
                    d[name] = factory()
            if len(args) < len(required):
                missing = [name for name in required if name not in d]
                if missing:
                    raise TypeError(f"{where} missing required argument {missing[0]!r}")

        __init__.__qualname__ = f"{cls.__qualname__}.__init__"
        return __init__


def is_value(value: object) -> bool:
    """Whether `value` is an instance of a class made by this module's `dataclass`."""
    return hasattr(type(value), "__value_fields__")


__all__ = ["asdict", "dataclass", "field", "fields", "is_value", "replace"]
