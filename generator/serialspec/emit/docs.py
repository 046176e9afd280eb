"""Emit the markdown reference of one protocol."""

from __future__ import annotations

from serialspec.spec.model import Protocol


def emit_docs(protocol: Protocol) -> str:
    return f"# {protocol.title}\n"
