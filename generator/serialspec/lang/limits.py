"""How large a spec may be: limits that keep a hostile file from taking the generator down (the loader's own, on
nesting and aliases, are in loader.py). Imports nothing: the CLI reads a spec with them before it knows whether it
needs PyYAML at all (an unchanged spec's outputs come from the cache)."""

from __future__ import annotations

#: A spec file's size (the largest shipped spec is 67 kB): a larger one is refused before it is read whole.
MAX_SPEC_BYTES = 1_000_000
#: One text value's length in characters (checked by the grammar; the longest shipped is 1,148).
MAX_TEXT = 10_000


def read_spec(path: str) -> bytes:
    """A spec file's bytes, read no further than one byte past MAX_SPEC_BYTES (the loader refuses the file then)."""
    with open(path, "rb") as stream:
        return stream.read(MAX_SPEC_BYTES + 1)
