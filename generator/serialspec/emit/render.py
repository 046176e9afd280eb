"""The jinja2 environment shared by every emitter: templates hold layout only."""

from __future__ import annotations

from functools import cache
from typing import Any

import jinja2


@cache
def environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.PackageLoader("serialspec.emit", "templates"),
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        undefined=jinja2.StrictUndefined,
        autoescape=False,  # noqa: S701 - we emit Python and markdown; text is escaped by the emitters
    )


def render(template: str, **context: Any) -> str:
    return environment().get_template(template).render(**context)
