"""The jinja2 environments the targets render with: templates hold layout only."""

from __future__ import annotations

import contextlib
import os
import sys
from functools import cache
from pathlib import Path
from typing import Any

import jinja2

# Compiling the templates costs more than everything else `serialspec generate` does for the shipped specs, so the
# compiled templates are cached the way Python caches modules: in the package's own __pycache__, keyed by each
# template's source (jinja2 checks its checksum and the Python version), written unless Python itself is told not
# to write bytecode (PYTHONDONTWRITEBYTECODE, -B) and read whenever it is there. Where that directory cannot be
# written (a read-only install), the templates are compiled on every run, as before.
_CACHE = Path(__file__).resolve().parent / "__pycache__" / "jinja2"


def _bytecode_cache() -> jinja2.BytecodeCache | None:
    write = not sys.dont_write_bytecode
    if write:
        with contextlib.suppress(OSError):
            _CACHE.mkdir(parents=True, exist_ok=True)
    if not _CACHE.is_dir():
        return None
    return _QuietCache(str(_CACHE), write=write and os.access(_CACHE, os.W_OK))


class _QuietCache(jinja2.FileSystemBytecodeCache):
    """A cache that never fails generation: a file it cannot read or write is a template compiled afresh."""

    def __init__(self, directory: str, *, write: bool) -> None:
        super().__init__(directory)
        self.write = write

    def load_bytecode(self, bucket: jinja2.bccache.Bucket) -> None:
        try:
            super().load_bytecode(bucket)
        except (OSError, EOFError, ValueError):
            bucket.reset()

    def dump_bytecode(self, bucket: jinja2.bccache.Bucket) -> None:
        if self.write:
            with contextlib.suppress(OSError):
                super().dump_bytecode(bucket)


@cache
def environment(package: str) -> jinja2.Environment:
    """The environment of one target package (its templates live in its `templates/` folder)."""
    env = jinja2.Environment(
        loader=jinja2.PackageLoader(package, "templates"),
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        undefined=jinja2.StrictUndefined,
        autoescape=False,  # targets escape spec text themselves, for where it lands
        bytecode_cache=_bytecode_cache(),
    )
    env.filters["pyrepr"] = repr  # a Python literal, safe whatever the text holds
    return env


def render(target: str, template: str, /, **context: Any) -> str:
    """Render one template of a target package (`serialspec.emit.<target>`)."""
    return environment(target).get_template(template).render(**context)
