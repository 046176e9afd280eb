"""The small hand-written runtime that generated packages import: errors, framing, hex input (and the checksum
functions from serialspec/checksums/, which the runtime wheel ships too)."""

from __future__ import annotations

import sys

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from types import ModuleType


def import_module(name: str) -> ModuleType:
    """The module of this absolute name, imported if need be: importlib.import_module without importing the
    importlib package (and warnings with it), about 4% of a bare Python start that `serialspec decode PACKAGE` and
    the registries pay no more."""
    __import__(name)
    return sys.modules[name]
