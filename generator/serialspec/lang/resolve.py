"""Validate a loaded spec and resolve it into the immutable model, by running the passes of `spec.passes`.

Every problem is collected, with the position of the value at fault, and reported together; resolution goes on
past a bad value wherever it can, so one run shows all the mistakes in a spec.
"""

from __future__ import annotations

import os

from serialspec.collection import without_cycle_collection
from serialspec.lang.errors import SpecError, SpecErrors
from serialspec.lang.loader import Located, load_file
from serialspec.lang.model import Protocol
from serialspec.lang.passes import PASSES, TEXT_PASSES, Context
from serialspec.lang.passes.text import is_text


def load_protocol(path: str, display_name: str | None = None) -> Protocol:
    """Load, validate and resolve one spec file; raises SpecErrors listing every mistake."""
    located = load_file(path, display_name or os.path.relpath(path), keep_going=True)
    return resolve(located)


def _near(path: str, loaded: list[SpecError]) -> bool:
    """Whether a pass's mistake at `path` lies at, inside or around a value the loader refused."""
    return any(
        path == p.path
        or path.startswith((f"{p.path}.", f"{p.path}["))
        or p.path.startswith((f"{path}.", f"{path}["))
        or not path
        or not p.path
        for p in loaded
    )


@without_cycle_collection
def resolve(located: Located) -> Protocol:
    """Run every pass over a loaded spec; raises SpecErrors listing every problem they found, after the loader's
    (`located.problems`: a key YAML reads as true, a duplicate key), whose values the passes never saw: what the passes
    say at or around those paths (a mapping left without that key) is left out."""
    ctx = Context(located)
    problems: list[SpecError] = []
    for step in TEXT_PASSES if is_text(ctx.data) else PASSES:
        problems.extend(step(ctx).run())
        if not isinstance(ctx.data, dict):
            break  # not even a mapping: the structural check has said so, nothing else applies
    if located.problems:
        problems = [*located.problems, *(p for p in problems if not _near(p.path, located.problems))]
    if problems or ctx.framing is None or ctx.serial is None:
        raise SpecErrors(problems)
    data = ctx.data
    return Protocol(
        name=ctx.name,
        title=str(data.get("title", "")),
        description=str(data.get("description", "")),
        spec_path=located.file,
        sources=dict(data.get("sources") or {}),
        byte_order="big" if ctx.endian == ">" else "little",
        serial=ctx.serial,
        framing=ctx.framing,
        matching=ctx.matching,
        matching_description=ctx.matching_description,
        enums=tuple(ctx.enums.values()),
        flags=tuple(ctx.flags.values()),
        tables=tuple(ctx.tables.values()),
        commands=tuple(ctx.commands),
        examples=ctx.examples,
        errata=ctx.errata,
        device=ctx.device,
        client_class=ctx.client_class,
        simulator_class=ctx.simulator_class,
        error_reply=ctx.error_reply,
        text=ctx.text,
    )
