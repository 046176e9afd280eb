"""Emitters: each target is a sub-package exporting `EMITTER`; `generate` and `check` run every one of them.

A new target is one new folder here with an `__init__.py` that defines `EMITTER = Emitter(name, files)`.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable
from functools import cache

from serialspec.lang.errors import SpecError
from serialspec.lang.frozen import frozen
from serialspec.lang.model import Protocol


@frozen
class Emitter:
    name: str
    files: Callable[[Protocol], dict[str, str]]  # path relative to generated/ -> text
    # Checks of the spec that need this target's output (the Python target runs the examples through its codec).
    verify: Callable[[Protocol, dict[str, str]], list[SpecError]] | None = None


def target_names() -> tuple[str, ...]:
    """The targets' names (their folders), without importing them."""
    return tuple(sorted(i.name for i in pkgutil.iter_modules(__path__) if i.ispkg and i.name != "common"))


@cache
def emitters() -> tuple[Emitter, ...]:
    """Every target under serialspec.backends, in name order (common/ is the shared layer, not a target)."""
    found = []
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda i: i.name):
        if info.ispkg and info.name != "common":
            module = importlib.import_module(f"{__name__}.{info.name}")
            found.append(module.EMITTER)
    return tuple(found)
