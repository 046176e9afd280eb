"""The capture format `monitor --save` and `sim --tap` write and `decode --file` reads.

A capture is UTF-8 text, one line per chunk of bytes as it was seen on the port:

    # serialspec capture: fashionstar_uart
    2026-11-22T09:40:01.123456+00:00 request 12 4c 01 01 03 63
    2026-11-22T09:40:01.124013+00:00 response 05 1c 01 01 00 23

Each line holds a timestamp (ISO 8601, UTC), the direction (`request`, `response`, or `-` where the bytes' direction
is not known) and the raw bytes in hex. A chunk need not hold whole frames: `decode --file` joins each direction's
bytes again and splits them into frames. Lines starting with `#` are comments; a line of hex alone is a chunk of
unknown direction, so a file of frames in hex, one per line, is a capture too.

The log of a client opened on pyserial's `spy://PATH?file=LOG` (its hexdump format) reads as a capture too: `TX`
lines are requests, `RX` lines responses (the client's view), timestamps in seconds from the port's opening; its
lines about control signals and empty reads are left out.

    000000.002 TX   0000  12 4C 01 01 03 63                                  .L...c
"""

from __future__ import annotations

import datetime
import re
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import TextIO

from serialspec.runtime.errors import SerialspecError
from serialspec.runtime.hexbytes import parse_hex

DIRECTIONS = ("request", "response", "-")
# pyserial's spy:// hexdump: a timestamp, a label of 4 (TX, RX, or a control signal's name), then for data the
# offset and 16 bytes in a column 49 wide (a space after the eighth), then the bytes as ASCII
SPY = re.compile(r"(?:\x1b\[[0-9;]*m)?(\d+\.\d{3}) (\S+)\s+(?:([0-9A-F]{4})  (.{1,49}))?")
SPY_DIRECTIONS = {"TX": "request", "RX": "response"}


@dataclass(frozen=True)
class Chunk:
    when: str  # the timestamp as written, "" when the line had none
    direction: str | None  # "request", "response", or None when unknown
    data: bytes


def stamp(moment: float | None = None) -> str:
    at = (
        datetime.datetime.now(datetime.UTC) if moment is None else datetime.datetime.fromtimestamp(moment, datetime.UTC)
    )
    return at.isoformat(timespec="microseconds")


class Writer:
    """Appends chunks to a capture file as they are seen (flushed at once, so a capture survives a kill)."""

    def __init__(self, stream: TextIO, protocol: str) -> None:
        self.stream = stream
        stream.write(f"# serialspec capture: {protocol}\n")
        stream.flush()

    def write(self, direction: str | None, data: bytes, moment: float | None = None) -> None:
        if data:
            self.stream.write(f"{stamp(moment)} {direction or '-'} {data.hex(' ')}\n")
            self.stream.flush()


def open_text(path: str) -> TextIO:
    """A capture file opened for reading; SerialspecError naming it when it cannot be. Bytes that are not UTF-8 (a
    binary file) read as U+FFFD: the line that holds them is then refused, by number, as no hex."""
    try:
        return open(path, encoding="utf-8", errors="replace")
    except OSError as exc:
        raise SerialspecError(f"cannot read {path}: {exc.strerror}") from None


def read(lines: Iterable[str]) -> Iterator[tuple[int, Chunk]]:
    """(line number, chunk) for every line that holds bytes; raises ValueError naming a line that does not parse."""
    for number, line in enumerate(lines, 1):
        text = line.strip()
        if not text or text.startswith("#"):
            continue
        spy = SPY.match(line)
        if spy is not None and (spy[2] not in SPY_DIRECTIONS or spy[3] is None):
            continue  # a control signal, or an empty read
        if spy is not None:
            when, direction, rest = spy[1], SPY_DIRECTIONS[spy[2]], spy[4]
            yield number, Chunk(when, direction, parse_hex(rest))  # the column holds hex and spaces only
            continue
        words = text.split(maxsplit=2)
        if len(words) == 3 and "T" in words[0] and words[1] in DIRECTIONS:
            when, direction, rest = words
        else:
            when, direction, rest = "", "-", text
        try:
            data = parse_hex(rest)
        except ValueError as exc:
            raise ValueError(f"line {number}: {exc}") from None
        yield number, Chunk(when, None if direction == "-" else direction, data)
