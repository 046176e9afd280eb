"""Loading a spec's generated package for the decode/encode verbs."""

from __future__ import annotations

import importlib
import os
from types import ModuleType

from serialspec.runtime.errors import SerialspecError
from serialspec.spec import load_protocol
from serialspec.spec.model import Protocol


def open_spec(path: str) -> tuple[Protocol, ModuleType]:
    """The resolved spec and its generated package; errors are one line for the user."""
    protocol = _load(path)
    try:
        package = importlib.import_module(protocol.name)
    except ImportError:
        raise SerialspecError(
            f"package {protocol.name} is not generated or installed: run `serialspec generate`"
        ) from None
    return protocol, package


def _load(path: str) -> Protocol:
    """Load a spec, once per version of the file (tools that decode many frames in one process call this often)."""
    try:
        stat = os.stat(path)
        key = (os.path.abspath(path), stat.st_mtime_ns, stat.st_size)
    except OSError:
        return load_protocol(path)  # the loader says what is wrong with the path, in one line
    if key not in _LOADED:
        _LOADED[key] = load_protocol(path)
    return _LOADED[key]


_LOADED: dict[tuple[str, int, int], Protocol] = {}


def message_type(package: ModuleType, command: str, subcommand: str | None, direction: str) -> type:
    for cls in package.MESSAGE_TYPES:
        if (cls.COMMAND, cls.SUBCOMMAND, cls.DIRECTION.value) == (command, subcommand, direction):
            return cls  # type: ignore[no-any-return]
    what = f"{command}.{subcommand}" if subcommand else command
    raise SerialspecError(f"{package.__name__} has no {direction} {what!r}")
