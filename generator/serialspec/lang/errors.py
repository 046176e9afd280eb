"""Spec errors: one line per mistake, naming file, line, column and the path of the offending value."""

from __future__ import annotations

from serialspec.lang.frozen import frozen


@frozen
class SpecError:
    file: str
    line: int
    column: int
    path: str
    message: str

    def __str__(self) -> str:
        where = f"{self.path}: " if self.path else ""
        return f"{self.file}:{self.line}:{self.column}: {where}{self.message}"


class SpecErrors(Exception):
    """Every mistake found in one spec; str() gives one line per mistake."""

    def __init__(self, errors: list[SpecError]) -> None:
        self.errors = sorted(errors, key=lambda e: (e.file, e.line, e.column, e.message))
        super().__init__("\n".join(str(e) for e in self.errors))
