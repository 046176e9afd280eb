"""The checksum algorithms: one registry, one module per algorithm, each owning all of its behaviour (base.py).

`algorithms()` finds them: it imports every module of this package and collects the Algorithm subclasses that set
`name`, so a new algorithm is a new module and nothing else. The package imports nothing of the generator: generated
code imports each algorithm's runtime function from its module (serialspec.checksums.crc.crc_function), and the
runtime wheel ships the package. Importing it finds nothing yet: a generated codec pays only for the module it uses.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from functools import cache

from serialspec.checksums.base import _REGISTERED, Algorithm, ChecksumProblem, Report

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any

__all__ = ["Algorithm", "ChecksumProblem", "algorithms", "from_spec", "owned_keys"]


@cache
def algorithms() -> dict[str, type[Algorithm]]:
    """Every algorithm by its `algorithm:` name, in name order."""
    for module in _modules():
        __import__(f"{__name__}.{module}")  # not importlib.import_module: the importlib package costs a start
    return dict(sorted(_REGISTERED.items()))


def owned_keys() -> dict[str, tuple[str, ...]]:
    """Each algorithm-specific key of a checksum element -> the algorithms that own it (`mask`: sum and xor)."""
    owners: dict[str, tuple[str, ...]] = {}
    for name, algorithm in algorithms().items():
        for key in algorithm.keys:
            owners[key.name] = (*owners.get(key.name, ()), name)
    return owners


def from_spec(raw: Mapping[str, Any], size: int, type_name: str, report: Report, bits: int = 0) -> Algorithm:
    """The algorithm of a checksum element (its keys as the grammar checked them) of `size` bytes of `type_name`.
    `bits`: the value's bits where not 8 a byte (Algorithm.from_spec). Raises ChecksumProblem for a missing
    algorithm; `report` takes another algorithm's keys given with it."""
    found = algorithms()
    name = raw.get("algorithm")
    if name not in found:
        names = list(found)
        choices = ", ".join(f"`algorithm: {n}`" for n in names[:-1]) + f" or `algorithm: {names[-1]}`"
        # at the key when one is given (the grammar has said it is none of these: one mistake, one line)
        raise ChecksumProblem(("algorithm",) if "algorithm" in raw else (), f"a checksum needs {choices}")
    for key, owners in owned_keys().items():
        if key in raw and name not in owners:
            report((key,), f"`{key}` belongs to `algorithm: {' or '.join(owners)}`, not {name}")
    return found[name].from_spec(raw, size, type_name, report, bits)


def _modules() -> list[str]:
    """The names of this package's modules (what pkgutil.iter_modules gives here, without importing pkgutil and
    inspect: generated code that asks for one runtime name does not pay for them)."""
    return sorted(
        name[:-3]
        for folder in __path__
        for name in os.listdir(folder)
        if name.endswith(".py") and name != "__init__.py"
    )
