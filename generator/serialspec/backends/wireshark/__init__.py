"""The Wireshark target: one Lua dissector per protocol, `<protocol>/<protocol>.lua` (see dissector.py)."""

from __future__ import annotations

from serialspec.backends import Emitter
from serialspec.backends.wireshark.dissector import emit_dissector
from serialspec.backends.wireshark.text import emit_text_dissector
from serialspec.lang.model import Protocol


def files(protocol: Protocol) -> dict[str, str]:
    if protocol.text is not None:
        return {f"{protocol.name}/{protocol.name}.lua": emit_text_dissector(protocol, protocol.text)}
    return {f"{protocol.name}/{protocol.name}.lua": emit_dissector(protocol)}


EMITTER = Emitter("wireshark", files)
