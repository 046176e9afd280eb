"""Numbers as the spec meant them: integers without a decimal point, other values exactly."""

from __future__ import annotations


def number(value: float) -> str:
    return repr(int(value)) if float(value).is_integer() else repr(value)
