"""The markdown target: one reference page per protocol, under generated/docs/."""

from __future__ import annotations

from serialspec.backends import Emitter
from serialspec.backends.markdown.docs import emit_docs
from serialspec.lang.model import Protocol


def files(protocol: Protocol) -> dict[str, str]:
    return {f"docs/{protocol.name}.md": emit_docs(protocol)}


EMITTER = Emitter("markdown", files)
