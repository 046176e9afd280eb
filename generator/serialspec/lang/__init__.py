"""The spec language: loading YAML with positions, validating, resolving into the immutable model."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from serialspec.lang.errors import SpecError, SpecErrors

if TYPE_CHECKING:
    from serialspec.lang.resolve import load_protocol

__all__ = ["SpecError", "SpecErrors", "load_protocol"]


def __getattr__(name: str) -> Any:
    # load_protocol brings in PyYAML, the grammar and the model: imported when first asked for, so that a command
    # that only reports spec errors (or finds every output in the cache) does not pay for them.
    if name == "load_protocol":
        from serialspec.lang.resolve import load_protocol

        return load_protocol
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
