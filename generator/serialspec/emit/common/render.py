"""The jinja2 environments the targets render with: templates hold layout only."""

from __future__ import annotations

from functools import cache
from typing import Any

import jinja2


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
    )
    env.filters["pyrepr"] = repr  # a Python literal, safe whatever the text holds
    return env


def render(target: str, template: str, /, **context: Any) -> str:
    """Render one template of a target package (`serialspec.emit.<target>`)."""
    return environment(target).get_template(template).render(**context)
