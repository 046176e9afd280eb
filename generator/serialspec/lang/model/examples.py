"""Example frames from the documents, and the errata that record where the documents are wrong."""

from __future__ import annotations

from serialspec.lang.frozen import frozen
from serialspec.runtime.message import Direction


@frozen
class Example:
    name: str
    source: str
    description: str
    direction: Direction
    printed: str
    frame: bytes
    erratum: str
    command: str
    subcommand: str | None
    request: str
    fields: dict[str, object]
    completed: str = ""  # the document prints no complete frame: how `frame` completes it (not an erratum)
    # bytes of the frame before and after the part the document prints (`printed_span`; (0, 0): the whole frame)
    printed_span: tuple[int, int] = (0, 0)
    position: tuple[int, int] = (1, 1)  # line and column in the spec, for errors found after resolution
    printed_text: bytes | None = None  # `printed_as: text`: the bytes of the printed characters and the trailer

    @property
    def printed_part(self) -> bytes:
        """The bytes of the frame that the document prints."""
        before, after = self.printed_span
        return self.frame[before : len(self.frame) - after]


@frozen
class ErratumCheck:
    kind: str
    frame: bytes | None
    frame_text: str
    direction: Direction | None
    error: str
    command: str
    subcommand: str | None
    fields: dict[str, object]
    claimed: object
    actual: int | None
    examples: tuple[str, ...]


@frozen
class Erratum:
    name: str
    source: str
    printed: str
    correct: str
    check: ErratumCheck
    position: tuple[int, int] = (1, 1)  # line and column of its check in the spec
