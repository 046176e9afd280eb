"""The resolver's passes, in the order they run; each has one job and returns its problems.

structure  the document's shape against the grammar (later passes skip what it reports)
settings   protocol name, byte order, serial line, shared fields, matching
types      enums, flags, tables
framing    frame elements, their offsets per direction, the checksum
commands   commands, sub-commands, messages and their fields (fields.py), codes, answered_by
errors     error replies: the command element's error_flag and the error_reply response
examples   errata and examples
device     the virtual device's behaviour, checked against the commands
"""

from __future__ import annotations

from serialspec.spec.passes.base import Context, Pass
from serialspec.spec.passes.commands import Commands
from serialspec.spec.passes.device import DevicePass
from serialspec.spec.passes.errors import ErrorReplies
from serialspec.spec.passes.examples import Examples
from serialspec.spec.passes.framing import FramingPass
from serialspec.spec.passes.settings import Settings
from serialspec.spec.passes.structure import Structure
from serialspec.spec.passes.types import Types

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

__all__ = ["PASSES", "Context", "Pass"]
