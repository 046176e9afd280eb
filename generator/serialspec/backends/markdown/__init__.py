"""The markdown target: one reference page per protocol, under generated/docs/."""

from __future__ import annotations

from serialspec.backends import Emitter
from serialspec.backends.markdown.docs import emit_docs
from serialspec.backends.markdown.text import text_docs
from serialspec.lang.model import Protocol


def files(protocol: Protocol) -> dict[str, str]:
    if protocol.text is not None:
        return {f"docs/{protocol.name}.md": text_docs(protocol, protocol.text)}
    return {f"docs/{protocol.name}.md": emit_docs(protocol)}


EMITTER = Emitter("markdown", files)
