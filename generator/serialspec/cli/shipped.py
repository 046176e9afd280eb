"""Where a generated protocol package NAME is found, and the spec it ships: the verbs that take a package's name
in place of a spec file (`decode vesc`, `generate fashionstar_uart`) ask here. Nothing of the CLI is imported, so
that cli.project and cli.protocols can both use it."""

from __future__ import annotations

import os
import sys

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from pathlib import Path

SHIPPED_SPEC = "spec.yaml"  # the spec, shipped inside its package (package data) for `serialspec decode NAME`
#: Where serialspec's own protocol packages are installed (the repository's pyproject.toml `namespace`): a protocol
#: name is looked up there too, so `serialspec decode vesc …` needs no namespace.
SHIPPED_NAMESPACE = "serialspec_protocols"


def shipped_spec(name: str) -> Path | None:
    """The spec a generated protocol package NAME ships (found as `installed` finds the package, without importing
    it), for the verbs that read spec files (`generate`, `docs`); None when there is no such package."""
    from pathlib import Path

    if not name.isidentifier():
        return None
    here = str(Path.cwd())
    sys.path.insert(0, here)
    import importlib.util

    try:
        found = importlib.util.find_spec(import_name(name))
    except (ImportError, ValueError):
        found = None
    finally:
        sys.path.remove(here)
    if found is None or not found.submodule_search_locations:
        return None
    shipped = Path(next(iter(found.submodule_search_locations)), SHIPPED_SPEC)
    return shipped if shipped.is_file() else None


def import_name(name: str) -> str:
    """The name to import a protocol's package by (the current folder is on the path): the folder's own package,
    else the shipped one under its namespace (not the old top-level alias, which warns), else NAME as it is."""
    if not name.isidentifier() or os.path.isfile(os.path.join(name, "__init__.py")):
        return name
    import importlib.util

    try:
        shipped = importlib.util.find_spec(f"{SHIPPED_NAMESPACE}.{name}")
    except ImportError:
        shipped = None
    return f"{SHIPPED_NAMESPACE}.{name}" if shipped is not None else name
