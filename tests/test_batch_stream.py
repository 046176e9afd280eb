"""The batch scan (split at every header) against the byte-by-byte scan, on streams made to trip it up.

For every stream parser of one frame format whose header cannot overlap itself (the parsers that take the batch
scan), the same reads go to a parser as it is and to one whose batch scan is replaced by the byte-by-byte one. After
every read both must have returned equal messages and agree on errors, skipped bytes and the bytes held back. The
streams mix intact frames of every example with the cases where splitting at headers differs from scanning: a header
inside a frame's bytes, frames cut short by the next header, corrupt checksums, lone headers and partial headers at
read boundaries, garbage made of header bytes.
"""

from __future__ import annotations

import random

import pytest
from conftest import ALL, Generated
from serialspec.runtime.message import Direction, Message
from serialspec.runtime.stream import StreamParser

STREAMS = 300  # per parser; each a few dozen pieces fed in random reads


def batch_scanned(g: Generated, direction: Direction) -> bool:
    parser = g.package.StreamParser(direction)
    single = getattr(parser, "_single", None)  # the frame engine's parsers (non-classic frames) have no batch scan
    return isinstance(parser, StreamParser) and single is not None and bool(single.splittable)


PARSERS = [(g, d) for g in ALL for d in g.protocol.framing.layouts if batch_scanned(g, d)]


def pieces(frames: list[bytes], header: bytes, rng: random.Random) -> list[bytes]:
    frame = rng.choice(frames)
    kind = rng.randrange(8)
    if kind == 0:  # a header in the frame's bytes
        at = rng.randrange(len(header), max(len(header) + 1, len(frame) - len(header)))
        return [frame[:at] + header + frame[at + len(header) :]]
    if kind == 1:  # cut short, the next frame right after
        return [frame[: rng.randrange(1, len(frame))]]
    if kind == 2:  # corrupt checksum
        return [frame[:-1] + bytes([frame[-1] ^ rng.randrange(1, 256)])]
    if kind == 3:  # garbage of header bytes and random ones
        return [bytes(rng.choice([*header, rng.randrange(256)]) for _ in range(rng.randrange(1, 6)))]
    if kind == 4:  # a lone header
        return [header]
    return [frame]


def reads(data: bytes, rng: random.Random) -> list[bytes]:
    cuts = sorted(rng.sample(range(1, len(data)), min(len(data) - 1, rng.randrange(0, 12))))
    return [data[a:b] for a, b in zip([0, *cuts], [*cuts, len(data)], strict=True)]


def byte_by_byte(parser: StreamParser) -> StreamParser:
    parser._split = lambda buffer, current: parser._scan(buffer)  # type: ignore[method-assign]
    return parser


@pytest.mark.parametrize(("g", "direction"), PARSERS, ids=[f"{g.protocol.name}:{d.value}" for g, d in PARSERS])
def test_the_batch_scan_takes_what_the_byte_by_byte_scan_takes(g: Generated, direction: Direction) -> None:
    frames = [e.frame for e in g.protocol.examples if e.direction == direction]
    header = g.protocol.framing.layouts[direction].header
    rng = random.Random(15)
    delivered = 0
    for _ in range(STREAMS):
        data = b"".join(p for _ in range(rng.randrange(1, 40)) for p in pieces(frames, header, rng))
        batch, scan = g.package.StreamParser(direction), byte_by_byte(g.package.StreamParser(direction))
        for chunk in reads(data, rng):
            got: list[Message] = batch.feed(chunk)
            assert got == scan.feed(chunk), data.hex(" ")
            assert (batch.errors, batch.garbage, batch.pending()) == (scan.errors, scan.garbage, scan.pending())
            delivered += len(got)
    assert delivered > STREAMS  # the streams did hold frames
