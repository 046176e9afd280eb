"""serialspec.runtime.values: the runtime's frozen value classes behave as the frozen dataclasses they replaced
(construction, defaults, equality, hashing, repr, immutability, pickling, copying, replace, fields, match)."""

from __future__ import annotations

import copy
import dataclasses
import pickle
from typing import Any, ClassVar

import pytest
from serialspec.runtime import values
from serialspec.runtime.framing import Element, Layout
from serialspec.runtime.text import TextField, TextFraming


def declare(make: Any, field: Any) -> type:
    @make(frozen=True)
    class Point:
        KIND: ClassVar[str] = "point"
        x: int
        y: int = 0
        tags: tuple[str, ...] = ()
        seen: list[int] = field(default_factory=list)
        sent: int = field(default=-1, compare=False, repr=False)
        total: int = field(init=False, default=0)

        def __post_init__(self) -> None:
            object.__setattr__(self, "total", self.x + self.y)

    return Point


OURS = declare(values.dataclass, values.field)
THEIRS = declare(dataclasses.dataclass, dataclasses.field)
OURS.__qualname__, THEIRS.__qualname__ = "OURS", "THEIRS"  # found by pickle under these names


def shown(value: object) -> str:
    """The repr after the class name."""
    return repr(value).partition("(")[2]


CALLS: list[tuple[tuple[Any, ...], dict[str, Any]]] = [
    ((1,), {}),
    ((1, 2), {}),
    ((1, 2, ("a",), [3], 7), {}),
    ((), {"x": 1, "sent": 4}),
    ((1,), {"tags": ("b",), "y": 5}),
]


@pytest.mark.parametrize(("args", "kwargs"), CALLS)
def test_a_value_class_behaves_as_the_frozen_dataclass(args: tuple[Any, ...], kwargs: dict[str, Any]) -> None:
    ours, theirs = OURS(*args, **kwargs), THEIRS(*args, **kwargs)
    assert shown(ours) == shown(theirs) and repr(ours).startswith("OURS(x=")
    assert [f.name for f in values.fields(ours)] == [f.name for f in dataclasses.fields(theirs)]
    assert values.asdict(ours) == dataclasses.asdict(theirs)
    assert OURS.__match_args__ == THEIRS.__match_args__  # type: ignore[attr-defined]
    assert ours.total == theirs.total and ours.KIND == "point"
    for other_args, other_kwargs in CALLS:
        other_ours, other_theirs = OURS(*other_args, **other_kwargs), THEIRS(*other_args, **other_kwargs)
        assert (ours == other_ours) == (theirs == other_theirs)
    assert ours == values.replace(ours, sent=99)  # not compared
    assert hash(OURS(1, 2, ("a",), (), 3)) == hash(OURS(1, 2, ("a",), (), 4))
    assert ours != theirs and ours != (1,)
    with pytest.raises(dataclasses.FrozenInstanceError):
        ours.x = 3
    with pytest.raises(dataclasses.FrozenInstanceError):
        del ours.x
    for copied in (pickle.loads(pickle.dumps(ours)), copy.copy(ours), copy.deepcopy(ours)):
        assert copied == ours and repr(copied) == repr(ours)
    changed = values.replace(ours, y=10)
    assert shown(changed) == shown(dataclasses.replace(theirs, y=10)) and changed.total == ours.x + 10
    with pytest.raises(ValueError, match="init=False"):
        values.replace(ours, total=1)
    match ours:
        case OURS(x, y):  # type: ignore[misc]
            assert (x, y) == (ours.x, ours.y)
        case _:
            pytest.fail("no match")


@pytest.mark.parametrize(
    ("args", "kwargs"),
    [((), {}), ((1, 2, (), [], 5, 6), {}), ((1,), {"x": 2}), ((1,), {"z": 2})],
)
def test_wrong_arguments_are_refused_as_dataclasses_refuse_them(args: tuple[Any, ...], kwargs: dict[str, Any]) -> None:
    with pytest.raises(TypeError):
        THEIRS(*args, **kwargs)
    with pytest.raises(TypeError):
        OURS(*args, **kwargs)


def test_a_field_without_default_after_one_with_is_refused() -> None:
    with pytest.raises(TypeError, match="non-default argument 'b' follows default argument"):

        @values.dataclass(frozen=True)
        class Bad:
            a: int = 0
            b: int  # type: ignore[misc]


def test_the_runtime_classes_are_value_classes() -> None:
    element = Element("id", "value", 1)
    assert values.is_value(element) and not dataclasses.is_dataclass(element)
    assert element == Element(name="id", kind="value", size=1) and repr(element).startswith("Element(name='id'")
    layout = Layout("plain", (element,))
    assert layout.values == (0,) and pickle.loads(pickle.dumps(layout)) == layout  # derived in __post_init__
    assert values.replace(TextField("a", "text"), precision=2) == TextField("a", "text", 2)
    assert [f.name for f in values.fields(TextFraming)][:3] == ["start", "separator", "end"]
