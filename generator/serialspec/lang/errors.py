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


# Type names of other languages and tools, as a newcomer writes them: the language's own
_OTHER_TYPE_NAMES = {
    "byte": "u8",
    "char": "i8",
    "short": "i16",
    "word": "u16",
    "int": "i32",
    "long": "i32",
    "dword": "u32",
    "float": "f32",
    "single": "f32",
    "real": "f32",
    "double": "f64",
}


def type_hint(name: object) -> str:
    """ "did you mean 'u8'? " for a type written as C, numpy or a datasheet writes it (uint8_t, int16, UINT32,
    float, double), "a u8 with `range: [0, 1]`, or a bit field: " for bool; else ""."""
    import re  # noqa: PLC0415 (only for a spec with a mistake)

    if not isinstance(name, str):
        return ""
    lowered = name.strip().lower()
    unsigned = lowered.startswith("unsigned")
    word = lowered.removeprefix("unsigned ").replace(" ", "")
    if word in ("bool", "boolean"):
        return "a flag is a u8 with `range: [0, 1]`, or a bit field (`bits:`); "
    found = re.fullmatch(r"(u|s)?int(\d+)(_t)?", word) or re.fullmatch(r"(u|i|s)(\d+)", word)
    if found and 1 <= int(found[2]) <= 64:
        sign = "u" if found[1] == "u" or unsigned else "i"
        return f"did you mean '{sign}{found[2]}'? "
    found = re.fullmatch(r"float(32|64)(_t)?", word)
    if found:
        return f"did you mean 'f{found[1]}'? "
    own = _OTHER_TYPE_NAMES.get(word)
    if own and unsigned and own[0] == "i":
        own = "u" + own[1:]
    return f"did you mean {own!r}? " if own else ""


def shown(errors: Sequence[SpecError]) -> list[str]:
    """The lines that report mistakes to people: the first MAX_SHOWN, then one counting the others."""
    lines = [str(e) for e in errors[:MAX_SHOWN]]
    if len(errors) > MAX_SHOWN:
        rest = len(errors) - MAX_SHOWN
        lines.append(f"... and {rest:,} more error{'s' if rest > 1 else ''} ({len(errors):,} in all)")
    return lines
