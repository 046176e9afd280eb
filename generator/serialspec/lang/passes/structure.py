"""The structural check: every value has the shape the grammar gives it (keys, types, choices)."""

from __future__ import annotations

from serialspec.lang import grammar
from serialspec.lang.errors import SpecError
from serialspec.lang.passes.base import Pass


class Structure(Pass):
    """Check the document against the grammar; later passes skip what this one reports."""

    def run(self) -> list[SpecError]:
        for path, message in grammar.SPEC.check(self.ctx.data, ()):
            self.problems.append(self.doc.error(path, message))
            self.ctx.structural.add(path)
        return self.problems
