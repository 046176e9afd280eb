"""The jinja2 environments the targets render with: templates hold layout only."""

from __future__ import annotations

import contextlib
import importlib.util
import pickle
from functools import cache
from typing import Any

import jinja2

from serialspec import cache as caches

_SETTINGS: dict[str, Any] = {
    "trim_blocks": True,
    "lstrip_blocks": True,
    "keep_trailing_newline": True,
    "undefined": jinja2.StrictUndefined,
    "autoescape": False,  # targets escape spec text themselves, for where it lands
}


_SYNTAX = (
    "block_start_string",
    "block_end_string",
    "variable_start_string",
    "variable_end_string",
    "comment_start_string",
    "comment_end_string",
    "line_statement_prefix",
    "line_comment_prefix",
    "trim_blocks",
    "lstrip_blocks",
    "newline_sequence",
    "keep_trailing_newline",
    "autoescape",
    "optimized",
)


class _Cache(jinja2.BytecodeCache):
    """Compiled templates, kept in serialspec's cache folder (serialspec.cache) the way Python keeps `.pyc` files.

    Compiling the templates costs more than everything else `serialspec generate` does for a small spec. An entry is
    used only when it was compiled from the same template text, by the same jinja2 with the same settings, for the
    same Python; any other entry, or a damaged one, is a template compiled afresh (and the entry rewritten).
    """

    def __init__(self, environment: jinja2.Environment) -> None:
        # What the compiled code depends on besides the template's text: jinja2 itself and the environment's syntax
        # and settings (the Python version is in jinja2's own header of each entry, and in the key too).
        settings = {name: getattr(environment, name) for name in _SYNTAX}
        settings["undefined"] = environment.undefined.__qualname__
        settings["extensions"] = sorted(environment.extensions)
        settings["filters"] = sorted(environment.filters)
        settings["tests"] = sorted(environment.tests)
        self.fingerprint = repr((jinja2.__version__, sorted(settings.items()))).encode()

    def _key(self, bucket: jinja2.bccache.Bucket) -> bytes:
        return caches.key(importlib.util.MAGIC_NUMBER, self.fingerprint, bucket.key, bucket.checksum)

    def load_bytecode(self, bucket: jinja2.bccache.Bucket) -> None:
        payload = caches.load(f"jinja2/{bucket.key}", self._key(bucket))
        if payload is not None:
            try:
                bucket.bytecode_from_string(payload)
            except (ValueError, EOFError, TypeError, pickle.UnpicklingError):
                bucket.reset()

    def dump_bytecode(self, bucket: jinja2.bccache.Bucket) -> None:
        with contextlib.suppress(TypeError):
            caches.store(f"jinja2/{bucket.key}", self._key(bucket), bucket.bytecode_to_string())


@cache
def environment(package: str) -> jinja2.Environment:
    """The environment of one target package (its templates live in its `templates/` folder)."""
    env = jinja2.Environment(loader=jinja2.PackageLoader(package, "templates"), **_SETTINGS)
    env.filters["pyrepr"] = repr  # a Python literal, safe whatever the text holds
    env.bytecode_cache = _Cache(env)
    return env


def render(target: str, template: str, /, **context: Any) -> str:
    """Render one template of a target package (`serialspec.backends.<target>`)."""
    return environment(target).get_template(template).render(**context)
