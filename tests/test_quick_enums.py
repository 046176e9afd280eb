"""Generated enum and flag classes are built quickly (serialspec.runtime.message's IntEnum and IntFlag, through
enum._simple_enum) and are the very classes a plain `class X(enum.IntEnum)` makes: compared here, for every enum
and flag class of every shipped package, with the class the standard library builds from the same members."""

from __future__ import annotations

import enum
import importlib
import pickle
from typing import Any

import pytest
from conftest import PACKAGES, SHIPPED

NAMES = sorted(p.name for p in PACKAGES.iterdir() if (p / "messages.py").is_file())


def enum_classes(name: str) -> list[type[enum.Enum]]:
    messages = importlib.import_module(f"{SHIPPED}.{name}.messages")
    found = [v for v in vars(messages).values() if isinstance(v, type) and issubclass(v, enum.Enum)]
    return [cls for cls in found if cls.__module__ == messages.__name__]


def standard(cls: type[enum.Enum]) -> Any:
    """The class `class X(enum.IntEnum)` (or IntFlag) makes with the same members, docstring and names: through
    EnumType's class statement steps (its __prepare__ namespace, then the metaclass call)."""
    base = enum.IntFlag if issubclass(cls, enum.Flag) else enum.IntEnum
    namespace = enum.EnumType.__prepare__(cls.__name__, (base,))
    namespace.update({"__doc__": cls.__doc__, "__module__": cls.__module__, "__qualname__": cls.__qualname__})
    for member, value in cls.__members__.items():
        namespace[member] = value.value
    return enum.EnumType(cls.__name__, (base,), namespace)


def facts(cls: Any) -> list[Any]:
    members = list(cls)
    out: list[Any] = [
        cls.__name__,
        cls.__qualname__,
        cls.__doc__,
        type(cls),
        [b.__name__ for b in cls.__mro__[1:]],
        [(n, int(m), m.name) for n, m in cls.__members__.items()],
        [(repr(m), str(m), format(m), f"{m:d}", hash(m)) for m in members],
        # the members' values (a flag class adds each combination met since, which differs by what ran before)
        {v: m.name for v, m in cls._value2member_map_.items() if v in {int(m) for m in cls.__members__.values()}},
    ]
    if issubclass(cls, enum.Flag):
        every = 0
        for m in members:
            every |= m.value
        out += [
            repr(cls(every)),
            repr(cls(every | 1 << 40)),  # KEEP: an unnamed bit is kept
            repr(cls(0)),
            repr(~members[-1]),
            repr(members[0] | members[-1]),
            [repr(m) for m in cls(every)],
            cls._boundary_,
        ]
    else:
        with pytest.raises(ValueError) as refused:
            cls(10**9)
        out.append(str(refused.value))
    return out


@pytest.mark.parametrize("name", NAMES)
def test_generated_enums_are_the_classes_the_standard_library_makes(name: str) -> None:
    classes = enum_classes(name)
    for cls in classes:
        assert issubclass(cls, enum.IntFlag if issubclass(cls, enum.Flag) else enum.IntEnum)
        assert facts(cls) == facts(standard(cls)), cls.__name__
        for member in cls:
            assert pickle.loads(pickle.dumps(member)) is member
            assert cls(member.value) is member and cls[member.name] is member


def test_every_shipped_package_with_enums_is_compared() -> None:
    assert sum(bool(enum_classes(name)) for name in NAMES) >= 9
