"""The resolver's passes, in the order they run; each has one job and returns its problems.

structure  the document's shape against the grammar (later passes skip what it reports)
settings   protocol name, byte order, serial line, shared fields, matching
types      enums, flags, tables
framing    frame elements, their offsets per direction, the checksum
commands   commands, sub-commands, messages and their fields (fields.py), codes, answered_by
errors     error replies: the command element's error_flag and the error_reply response
examples   errata and examples
device     the virtual device's behaviour, checked against the commands

text       instead of types..device for a text protocol: its frame, commands and examples
"""

from __future__ import annotations

from serialspec.lang.passes.base import Context, Pass
from serialspec.lang.passes.commands import Commands
from serialspec.lang.passes.device import DevicePass
from serialspec.lang.passes.errors import ErrorReplies
from serialspec.lang.passes.examples import Examples
from serialspec.lang.passes.framing import FramingPass
from serialspec.lang.passes.settings import Settings
from serialspec.lang.passes.structure import Structure
from serialspec.lang.passes.text import TextPass
from serialspec.lang.passes.types import Types

PASSES: tuple[type[Pass], ...] = (
    Structure,
    Settings,
    Types,
    FramingPass,
    Commands,
    ErrorReplies,
    Examples,
    DevicePass,
)

# A text protocol (`framing: {kind: text}`): its own pass after the shared ones.
TEXT_PASSES: tuple[type[Pass], ...] = (Structure, Settings, TextPass)

__all__ = ["PASSES", "TEXT_PASSES", "Context", "Pass"]
