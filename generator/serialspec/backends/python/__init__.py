"""The Python target: one package per protocol (messages, codec, structs, registers, client, simulator)."""

from __future__ import annotations

from serialspec.backends import Emitter
from serialspec.backends.python.package import emit_package
from serialspec.backends.python.verify import verify
from serialspec.lang.errors import SpecError
from serialspec.lang.model import Protocol


def files(protocol: Protocol) -> dict[str, str]:
    return {f"{protocol.name}/{name}": text for name, text in emit_package(protocol).items()}


def check(protocol: Protocol, emitted: dict[str, str]) -> list[SpecError]:
    """The spec's examples and errata, run through the package just emitted."""
    prefix = f"{protocol.name}/"
    return verify(protocol, {path.removeprefix(prefix): text for path, text in emitted.items()})


EMITTER = Emitter("python", files, check)
