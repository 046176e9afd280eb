"""Per-kind behaviour of fields, shared by the targets: each target defines one class per model field kind.

A target's base class (generic in `F`, the model field class) has one subclass per kind, each naming its model class
in `model`; `Registry(Base)` finds them and refuses a model field kind with no class, so a new field kind is one new
class per target and an emitter asks `kind(f)` instead of switching on the field's class.
"""

from __future__ import annotations

from typing import Any, Generic, TypeVar, get_args

from serialspec.lang.model import Array, Bytes, Group, List, Packed, Scalar, TableBlock, TableValue, Text, Varint
from serialspec.lang.model import Field as SpecField

F = TypeVar("F", Scalar, Varint, Array, Packed, List, Text, Bytes, Group, TableValue, TableBlock)
K = TypeVar("K")


class Registry(Generic[K]):
    """The behaviour object of each model field kind, from the subclasses of a target's base class."""

    def __init__(self, base: type[K]) -> None:
        self.by_model: dict[type, K] = {}
        for cls in base.__subclasses__():
            model: Any = vars(cls)["model"]  # each kind class names its own model class
            self.by_model[model] = cls()
        missing = set(get_args(SpecField)) - set(self.by_model)
        if missing:
            raise AssertionError(f"{base.__module__}: no behaviour for {sorted(c.__name__ for c in missing)}")

    def __call__(self, f: SpecField) -> K:
        return self.by_model[type(f)]
