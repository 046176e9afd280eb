"""Spec text on one line: the starting point of every target's escaping."""

from __future__ import annotations


def collapse(text: str) -> str:
    """Whitespace runs (newlines included) as one space, no leading or trailing space."""
    return " ".join(text.split())
