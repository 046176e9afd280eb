"""The Python target: one package per protocol (messages, codec, structs, registers, client, its asyncio twin
aio, simulator)."""

from __future__ import annotations

from serialspec.backends import Emitter
from serialspec.backends.python.aio import aio_module
from serialspec.backends.python.package import emit_package
from serialspec.backends.python.text import text_package
from serialspec.backends.python.verify import verify, verify_text
from serialspec.lang.errors import SpecError
from serialspec.lang.model import Protocol


def files(protocol: Protocol) -> dict[str, str]:
    if protocol.text is not None:
        return {f"{protocol.name}/{name}": text for name, text in text_package(protocol, protocol.text).items()}
    package = emit_package(protocol)
    if "client.py" in package:
        package["aio.py"] = aio_module(protocol)
    return {f"{protocol.name}/{name}": text for name, text in package.items()}


def check(protocol: Protocol, emitted: dict[str, str]) -> list[SpecError]:
    """The spec's examples and errata, run through the package just emitted."""
    prefix = f"{protocol.name}/"
    if protocol.text is not None:
        return verify_text(protocol, protocol.text, {path.removeprefix(prefix): text for path, text in emitted.items()})
    return verify(protocol, {path.removeprefix(prefix): text for path, text in emitted.items()})


EMITTER = Emitter("python", files, check)
