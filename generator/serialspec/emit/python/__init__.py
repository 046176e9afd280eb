"""The Python target: one package per protocol (messages, codec, structs, registers, client, simulator)."""

from __future__ import annotations

from serialspec.emit import Emitter
from serialspec.emit.python.package import emit_package
from serialspec.spec.model import Protocol


def files(protocol: Protocol) -> dict[str, str]:
    return {f"{protocol.name}/{name}": text for name, text in emit_package(protocol).items()}


EMITTER = Emitter("python", files)
