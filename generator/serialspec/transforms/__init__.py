"""The frame transforms: one registry, one module per transform, each owning all of its behaviour (base.py).

A transform rewrites the bytes of a span of frame elements on the wire (`framing: transparency:`): substitution
stuffing or escaping (`method: replace`, DYNAMIXEL, SLIP, XBee API mode 2), COBS (`method: cobs`). `transforms()`
finds them: it imports every module of this package and collects the Transform subclasses that set `name`, so a new
transform is a new module and nothing else. The package imports nothing of the generator: generated code imports
each transform's runtime class (a codec from the transform's module, so it imports no other transform; structs.py
through serialspec.runtime.framing), and the runtime wheel ships the package.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from functools import cache

from serialspec.runtime import import_module
from serialspec.transforms.base import _REGISTERED, DEFAULT, Report, Transform, TransformProblem

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any

__all__ = ["DEFAULT", "Transform", "TransformProblem", "from_spec", "owned_keys", "runtime_classes", "transforms"]


@cache
def transforms() -> dict[str, type[Transform]]:
    """Every transform by its `method:` name, in name order."""
    for module in _modules():
        if module != "base":
            import_module(f"{__name__}.{module}")
    return dict(sorted(_REGISTERED.items()))


def owned_keys() -> dict[str, str]:
    """Each transform-specific key of `transparency:` -> the transform that owns it."""
    return {key.name: name for name, transform in transforms().items() for key in transform.keys}


def runtime_classes() -> dict[str, tuple[str, str]]:
    """The runtime class name of each transform -> (its module, the class name): what generated code imports."""
    return {t.runtime_name: (t.__module__, t.runtime_name) for t in transforms().values()}


def from_spec(raw: Mapping[str, Any], report: Report) -> Transform:
    """The transform of a `transparency:` mapping (its keys as the grammar checked them). Raises TransformProblem
    where it cannot be made; `report` takes another transform's keys given with it."""
    found = transforms()
    name = raw.get("method", DEFAULT)
    if name not in found:
        raise TransformProblem(("method",), f"unknown method {name!r} (choose {', '.join(found)})")
    for key, owner in owned_keys().items():
        if key in raw and owner != name:
            report((key,), f"`{key}` belongs to `method: {owner}`, not {name}")
    return found[name].from_spec(raw, report)


def _modules() -> list[str]:
    """The names of this package's modules (what pkgutil.iter_modules gives here, without importing pkgutil and
    inspect: generated code that asks for one runtime name does not pay for them)."""
    return sorted(
        name[:-3]
        for folder in __path__
        for name in os.listdir(folder)
        if name.endswith(".py") and name != "__init__.py"
    )
