"""The jinja2 environment shared by every emitter: templates hold layout only."""

from __future__ import annotations

from functools import cache
from typing import Any

import jinja2


@cache
def environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("serialspec.emit", "templates"),
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        undefined=jinja2.StrictUndefined,
        autoescape=False,  # we emit Python and markdown; emitters escape spec text for each
    )
    env.filters["pyrepr"] = repr  # a Python literal, safe whatever the text holds
    return env


def render(template: str, **context: Any) -> str:
    return environment().get_template(template).render(**context)
