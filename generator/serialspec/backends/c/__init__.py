"""The C99 target: generated/c/<protocol>/ with a header, a codec and stream parser, and a JSON formatter."""

from __future__ import annotations

from serialspec.backends import Emitter
from serialspec.backends.c.build import files

EMITTER = Emitter("c", files, folder="c")
