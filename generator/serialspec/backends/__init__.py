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


class Unsupported(Exception):
    """A spec feature a target cannot generate yet; its message names the feature in one line.

    `serialspec generate --target NAME` refuses the spec with it; a run of every target leaves that target's files
    out for the spec (the other targets are still written)."""


@frozen
class Emitter:
    name: str
    files: Callable[[Protocol], dict[str, str]]  # path relative to generated/ -> text
    # Checks of the spec that need this target's output (the Python target runs the examples through its codec).
    verify: Callable[[Protocol, dict[str, str]], list[SpecError]] | None = None
    # The folder under the project's generated/ that holds this target's files (`--target NAME --out DIR` writes
    # them to DIR without it): "" when the paths need none.
    folder: str = ""


def emit(emitter: Emitter, protocol: Protocol) -> dict[str, str]:
    """A target's files for a protocol by path under generated/ (its folder first); none where the target cannot
    generate the spec yet (Unsupported: `generate --target NAME` says why)."""
    return emit_or_refuse(emitter, protocol)[0]


def emit_or_refuse(emitter: Emitter, protocol: Protocol) -> tuple[dict[str, str], str | None]:
    """emit(), and the one-line reason (Unsupported's message) when the target cannot generate the spec."""
    try:
        emitted = emitter.files(protocol)
    except Unsupported as exc:
        return {}, str(exc)
    return {f"{emitter.folder}/{path}" if emitter.folder else path: text for path, text in emitted.items()}, None


def target_folder(name: str) -> str:
    """The folder a target's files go to under the project's generated/ (Emitter.folder), importing that target
    alone."""
    emitter: Emitter = importlib.import_module(f"{__name__}.{name}").EMITTER
    return emitter.folder


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
