"""Spec errors: one line per mistake, naming file, line, column and the path of the offending value."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

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
        line = f"{self.file}:{self.line}:{self.column}: {where}{self.message}"
        # one line whatever the file's name or the text quoted: anything unprintable (a newline) escaped
        return line if line.isprintable() else "".join(c if c.isprintable() else f"\\x{ord(c):02x}" for c in line)


#: How many names an error line lists (the names a spec defines, when it names another): the rest are counted.
MAX_NAMES = 12


def listed(names: Iterable[str], empty: str = "none defined") -> str:
    """Names for an error line: the names, or the first MAX_NAMES and a count of the others (a spec of thousands
    of commands gives a line, not a page); `empty` where there are none."""
    every = list(names)
    if not every:
        return empty
    if len(every) <= MAX_NAMES:
        return ", ".join(every)
    return f"{', '.join(every[:MAX_NAMES])} and {len(every) - MAX_NAMES} more"


#: How many mistakes str(SpecErrors) shows, in file order; a last line counts the rest.
MAX_SHOWN = 50


class SpecErrors(Exception):
    """Every mistake found in one spec (`errors`); str() gives one line per mistake, the first MAX_SHOWN of them and
    then a line counting the others."""

    def __init__(self, errors: list[SpecError]) -> None:
        self.errors = sorted(errors, key=lambda e: (e.file, e.line, e.column, e.message))
        super().__init__("\n".join(shown(self.errors)))


def shown(errors: Sequence[SpecError]) -> list[str]:
    """The lines that report mistakes to people: the first MAX_SHOWN, then one counting the others."""
    lines = [str(e) for e in errors[:MAX_SHOWN]]
    if len(errors) > MAX_SHOWN:
        rest = len(errors) - MAX_SHOWN
        lines.append(f"... and {rest:,} more error{'s' if rest > 1 else ''} ({len(errors):,} in all)")
    return lines
