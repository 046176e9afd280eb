"""Runs: the batch scan checks frames of one size key that follow one another together (key bytes as columns of the
joined frames, 8-bit sums in the lanes of a big integer) and decodes them with one generated run decoder.

Hypothesis draws streams made mostly of runs of one frame (where runs are taken), broken by frames with a byte
changed (key, content, checksum), with another length byte but the same sum, cut frames, stray headers and noise,
and feeds them in random reads to a parser as it is and to one that scans byte by byte: both must return equal
messages and agree on errors, skipped bytes and bytes held back, and runs must have been taken. The same for a
made-up format whose sum skips the header and is inverted, with a header that overlaps itself, since the runtime
reads all of it from the frame format.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from conftest import Generated, examples
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.runtime.message import Direction, Message, build
from serialspec.runtime.stream import FrameFormat, StreamParser
from test_batch_stream import PARSERS, byte_by_byte

RUNS = [(g, d) for g, d in PARSERS if g.package.StreamParser(d)._single.runs]


def test_runs_are_generated_for_plain_summed_frames() -> None:
    """Fashion Star's frames whose message is their content as unpacked, under an 8-bit sum, have run decoders."""
    assert RUNS
    for g, direction in RUNS:
        candidate = g.package.StreamParser(direction)._single
        assert set(candidate.runs) <= set(candidate.pieces)


def counting(parser: StreamParser) -> list[int]:
    """The frames each run took, as the parser takes them."""
    taken: list[int] = []
    run = parser._run

    def spy(*args: object) -> tuple[int, bytes]:
        count, frames = run(*args)  # type: ignore[arg-type]
        taken.append(count)
        return count, frames

    parser._run = spy  # type: ignore[assignment, method-assign]
    return taken


@st.composite
def run_stream(draw: st.DrawFn, frames: list[bytes], header: bytes, length_at: int) -> tuple[bytes, list[bytes]]:
    """Runs of one frame long enough to be taken as runs, a few frames in them damaged, noise after some."""
    parts: list[bytes] = []
    for _ in range(draw(st.integers(1, 4))):
        frame = draw(st.sampled_from(frames))
        copies = [frame] * draw(st.integers(1, 120))
        noise = st.binary(min_size=1, max_size=3) | st.lists(
            st.sampled_from([*header, 0, 1, 0xFF, *frame[len(header) :]]), min_size=1, max_size=3
        ).map(bytes)
        for at, extra in draw(st.lists(st.tuples(st.integers(0, len(copies) - 1), noise), max_size=40)):
            copies[at] += extra  # the frame, then noise
        for _ in range(draw(st.integers(0, 3))):
            at = draw(st.integers(0, len(copies) - 1))
            kind = draw(st.integers(0, 3))
            if kind == 0:  # a byte changed after the header: key, content or checksum
                where = draw(st.integers(len(header), len(frame) - 1))
                copies[at] = frame[:where] + bytes([frame[where] ^ draw(st.integers(1, 255))]) + frame[where + 1 :]
            elif kind == 1:  # cut short
                copies[at] = frame[: draw(st.integers(1, len(frame) - 1))]
            elif kind == 2 and length_at < len(frame) - 2:  # another length byte, its sum kept: another key
                changed = bytearray(frame)
                step = draw(st.integers(1, 255))
                changed[length_at] = (changed[length_at] + step) & 0xFF
                changed[-2] = (changed[-2] - step) & 0xFF
                copies[at] = bytes(changed)
            else:  # a stray header before it
                copies[at] = header[: draw(st.integers(1, len(header)))] + copies[at]
        parts += copies
    return in_reads(draw, b"".join(parts))


def in_reads(draw: st.DrawFn, data: bytes) -> tuple[bytes, list[bytes]]:
    """The stream, and the reads it comes in."""
    edges = [0, *sorted(set(draw(st.lists(st.integers(0, len(data)), max_size=4)))), len(data)]
    return data, [data[a:b] for a, b in zip(edges, edges[1:], strict=False)]


def agree(batch: StreamParser, scan: StreamParser, data: bytes, reads: list[bytes]) -> None:
    """After every read: the same messages, errors, skipped bytes and bytes held back."""
    for chunk in reads:
        got = batch.feed(chunk)
        assert got == scan.feed(chunk), data.hex(" ")
        assert (batch.errors, batch.garbage, batch.pending()) == (scan.errors, scan.garbage, scan.pending())


@pytest.mark.parametrize(("g", "direction"), RUNS, ids=[f"{g.protocol.name}:{d.value}" for g, d in RUNS])
def test_runs_take_what_the_byte_by_byte_scan_takes(g: Generated, direction: Direction) -> None:
    header = g.protocol.framing.layouts[direction].header
    frames = [e.frame for e in g.protocol.examples if e.direction == direction]
    taken: list[list[int]] = []

    @settings(max_examples=examples(100), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(run_stream(frames, header, g.protocol.framing.layouts[direction].length_offset))
    def run(drawn: tuple[bytes, list[bytes]]) -> None:
        batch = g.package.StreamParser(direction)
        taken.append(counting(batch))
        agree(batch, byte_by_byte(g.package.StreamParser(direction)), *drawn)

    run()
    counts = [count for each in taken for count in each]
    assert max(counts) > 1  # runs were taken
    assert 0 in counts  # and runs were refused


# --- a made-up format: header AA AA (it overlaps itself), length, content of two bytes, ~sum after the header ----


class Pair(Message):
    """A made-up frame's two content bytes."""

    __slots__ = ()
    __match_args__ = ("first", "second")
    PROTOCOL = "toy"
    COMMAND = "pair"
    SUBCOMMAND = None
    DIRECTION = Direction.RESPONSE
    first: int
    second: int

    def __new__(cls, first: int, second: int) -> Pair:
        return build(cls, (first, second))


HEADER = b"\xaa\xaa"


def pair_frame(first: int, second: int) -> bytes:
    body = bytes([2, first, second])
    return HEADER + body + bytes([~sum(body) & 0xFF])


def pair_at(buf: bytes, start: int) -> Pair | None:
    if ~sum(buf[start + 2 : start + 5]) & 0xFF != buf[start + 5]:
        return None
    return Pair(buf[start + 3], buf[start + 4])


def pair_decode_at(buf: bytes, start: int, stop: int) -> Pair:
    from serialspec.runtime.errors import ChecksumError

    pair = pair_at(buf, start)
    if pair is None:
        raise ChecksumError("bad sum")
    return pair


def pairs(frames: bytes) -> Iterator[Pair]:
    return (Pair(frames[i + 1], frames[i + 2]) for i in range(0, len(frames), 4))


PAIR_FORMAT = FrameFormat(
    header=HEADER,
    overhead=4,
    length_offset=2,
    length_adds=0,
    command_offset=None,
    content_sizes={None: (2, 2)},
    decode_at=pair_decode_at,
    fixed={2: (6, pair_at)},
    summed=(2, True),
    runs={2: pairs},
)


@st.composite
def pair_stream(draw: st.DrawFn) -> tuple[bytes, list[bytes]]:
    values = st.sampled_from([0, 1, 0xAA, 0x55, 0xFE, 0xFF])
    parts = []
    for _ in range(draw(st.integers(1, 150))):
        frame = pair_frame(draw(values), draw(values))
        kind = draw(st.integers(0, 39))
        if kind == 0:
            at = draw(st.integers(2, 5))
            frame = frame[:at] + bytes([frame[at] ^ draw(st.integers(1, 255))]) + frame[at + 1 :]
        elif kind == 1:
            frame = frame[: draw(st.integers(1, 5))]
        elif kind == 2:
            frame += bytes(draw(st.lists(st.sampled_from([0xAA, 0, 2, 0xFF]), max_size=3)))
        parts.append(frame)
    return in_reads(draw, b"".join(parts))


def test_runs_of_a_made_up_format_with_an_inverted_sum_after_the_header() -> None:
    taken: list[list[int]] = []

    @settings(max_examples=examples(300), deadline=None)
    @given(pair_stream())
    def run(drawn: tuple[bytes, list[bytes]]) -> None:
        batch = StreamParser(PAIR_FORMAT)
        taken.append(counting(batch))
        agree(batch, byte_by_byte(StreamParser(PAIR_FORMAT)), *drawn)

    run()
    assert max(count for each in taken for count in each) > 1


def test_a_long_run_is_every_frame() -> None:
    frames = [pair_frame(i & 0xFF, i * 7 & 0xFF) for i in range(3000)]
    parser = StreamParser(PAIR_FORMAT)
    got = [m for at in range(0, len(frames), 500) for m in parser.feed(b"".join(frames[at : at + 500]))]
    assert got == [Pair(i & 0xFF, i * 7 & 0xFF) for i in range(3000)]
    assert (parser.errors, parser.garbage, parser.pending()) == (0, 0, b"")
