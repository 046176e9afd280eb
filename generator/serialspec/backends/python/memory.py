"""Importing a generated package from its text, in memory, without disturbing another copy already imported.

Each module is compiled as Python would compile its file; the code objects are cached by their exact source text
(serialspec.cache), so generating an unchanged spec again does not compile its package again.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from types import ModuleType

from serialspec import cache


class _Sources(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Imports one generated package from its text, held in memory."""

    def __init__(self, package: str, files: dict[str, str], origin: str) -> None:
        self.package = package
        self.files = files
        self.origin = origin

    def find_spec(
        self, fullname: str, path: object = None, target: object = None
    ) -> importlib.machinery.ModuleSpec | None:
        name = self._file(fullname)
        if name is None:
            return None
        origin = f"{self.origin} ({fullname} generated in memory)"
        return importlib.util.spec_from_loader(fullname, self, origin=origin, is_package=fullname == self.package)

    def _file(self, fullname: str) -> str | None:
        if fullname == self.package:
            return "__init__.py"
        prefix, _, module = fullname.partition(".")
        if prefix == self.package and f"{module}.py" in self.files:
            return f"{module}.py"
        return None

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> None:
        return None

    def exec_module(self, module: ModuleType) -> None:
        name = self._file(module.__name__)
        assert name is not None
        if name not in self.files:  # a package without its __init__.py: an empty package around its modules
            return
        filename = f"<{self.package}/{name} from {self.origin}>"
        exec(cache.compiled(self.files[name], filename, f"{self.package}.{name}"), module.__dict__)


@contextmanager
def imported(package: str, files: dict[str, str], origin: str = "memory", module: str = "") -> Iterator[ModuleType]:
    """The package made of `files` (module file name -> text), imported for the block; or with `module`, that module
    of it (files without "__init__.py": the package is an empty one, its own imports are not run). Any package of
    that name already imported (the committed one, in tests) is set aside meanwhile and put back; the modules
    imported in the block stay usable after it."""

    def ours(name: str) -> bool:
        return name == package or name.startswith(package + ".")

    finder = _Sources(package, files, origin)
    saved = {name: module for name, module in sys.modules.items() if ours(name)}
    for name in saved:
        del sys.modules[name]
    sys.meta_path.insert(0, finder)
    try:
        yield importlib.import_module(f"{package}.{module}" if module else package)
    finally:
        sys.meta_path.remove(finder)
        for name in [name for name in sys.modules if ours(name)]:
            del sys.modules[name]
        sys.modules.update(saved)
