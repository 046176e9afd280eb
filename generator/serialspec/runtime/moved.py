"""Old import names kept working for one release: a generated package that moved (say, from `vesc` to
`serialspec_protocols.vesc`) leaves a small module under its old name that calls `moved`.

`import vesc`, `from vesc import X` and `import vesc.codec` then give the very modules of the new name (not copies:
their classes are the same objects, so `isinstance` holds across both names), with one DeprecationWarning that says
what to import instead.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import warnings
from collections.abc import Sequence
from types import ModuleType

__all__ = ["moved"]


class _Alias(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds `old.sub` as the already importable `new.sub`."""

    def __init__(self, old: str, new: str) -> None:
        self.old, self.new = old, new

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        if not fullname.startswith(f"{self.old}."):
            return None
        return importlib.machinery.ModuleSpec(fullname, self)

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        # The module under its new name, as it is: the import system sets no attribute that is already there.
        return importlib.import_module(self.new + spec.name[len(self.old) :])

    def exec_module(self, module: ModuleType) -> None:
        """Already executed under its new name."""


def moved(old: str, new: str) -> None:
    """Make the module being imported as `old` (and its submodules) the package `new`, with a DeprecationWarning."""
    warnings.warn(
        f"`{old}` is now `{new}`: import that instead (the old name goes in the next release)",
        DeprecationWarning,
        stacklevel=3,
    )
    if not any(isinstance(f, _Alias) and f.old == old for f in sys.meta_path):
        sys.meta_path.insert(0, _Alias(old, new))
    sys.modules[old] = importlib.import_module(new)
