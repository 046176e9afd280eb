"""Rendering with the Python target's templates."""

from __future__ import annotations

from typing import Any

from serialspec.backends.common import render as common


def render(template: str, **context: Any) -> str:
    return common.render("serialspec.backends.python", template, **context)
