"""Rendering with the Python target's templates, and spec text made safe to place in them."""

from __future__ import annotations

from typing import Any

from serialspec.backends.common import render as common
from serialspec.backends.common.text import collapse


def render(template: str, **context: Any) -> str:
    return common.render("serialspec.backends.python", template, **context)


def one_line(text: str) -> str:
    """Spec text made safe for a comment or docstring: one line, no backslashes or quotes that could close it."""
    return collapse(text).replace("\\", "\\\\").replace('"', "'")
