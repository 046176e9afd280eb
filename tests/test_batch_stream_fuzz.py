"""Hypothesis: the batch scan (split at every header) against the byte-by-byte scan on random noisy streams.

Streams are drawn from intact example frames, frames with a byte changed (checksum, length byte, command code or
an address out of range), frames cut short, runs of header bytes (a header that can overlap itself, like FEETECH's
FF FF, makes FF FF FF ... candidates that start inside one another), lone headers and random bytes; the same stream
is fed in random reads to a parser as it is and to one whose batch scan is replaced by the byte-by-byte scan. After
every read both must have returned equal messages and agree on errors, skipped bytes and the bytes held back.
"""

from __future__ import annotations

import pytest
from conftest import Generated, examples
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import EncodeError
from serialspec.runtime.message import Direction, field_names, replace
from serialspec.runtime.stream import StreamParser
from test_batch_stream import PARSERS, byte_by_byte


def frames_of(g: Generated, direction: Direction) -> list[bytes]:
    return [e.frame for e in g.protocol.examples if e.direction == direction]


@st.composite
def piece(draw: st.DrawFn, frames: list[bytes], header: bytes) -> bytes:
    frame = draw(st.sampled_from(frames))
    kind = draw(st.integers(0, 7))
    if kind == 0:  # a byte changed anywhere after the header
        at = draw(st.integers(len(header), len(frame) - 1))
        return frame[:at] + bytes([frame[at] ^ draw(st.integers(1, 255))]) + frame[at + 1 :]
    if kind == 1:  # cut short
        return frame[: draw(st.integers(1, len(frame) - 1))]
    if kind == 2:  # header bytes, repeated: overlapping candidates
        return header[: draw(st.integers(1, len(header)))] * draw(st.integers(1, 4))
    if kind == 3:  # noise, some of it header bytes
        return bytes(draw(st.lists(st.sampled_from([*header, 0, 0xFF, *range(1, 255, 37)]), max_size=6)))
    if kind == 4:  # a header inside the frame's bytes
        at = draw(st.integers(len(header), max(len(header), len(frame) - len(header))))
        return frame[:at] + header + frame[at + len(header) :]
    return frame


@st.composite
def stream_and_reads(draw: st.DrawFn, frames: list[bytes], header: bytes) -> tuple[bytes, list[bytes]]:
    data = b"".join(draw(st.lists(piece(frames, header), min_size=1, max_size=30)))
    cuts = sorted(set(draw(st.lists(st.integers(0, len(data)), max_size=10))))
    edges = [0, *cuts, len(data)]
    return data, [data[a:b] for a, b in zip(edges, edges[1:], strict=False)]


def check(g: Generated, direction: Direction, data: bytes, reads: list[bytes]) -> None:
    batch: StreamParser = g.package.StreamParser(direction)
    scan = byte_by_byte(g.package.StreamParser(direction))
    for chunk in reads:
        assert batch.feed(chunk) == scan.feed(chunk), data.hex(" ")
        assert (batch.errors, batch.garbage, batch.pending()) == (scan.errors, scan.garbage, scan.pending())


@pytest.mark.parametrize(("g", "direction"), PARSERS, ids=[f"{g.protocol.name}:{d.value}" for g, d in PARSERS])
def test_batch_and_byte_by_byte_scans_agree_on_random_streams(g: Generated, direction: Direction) -> None:
    header = g.protocol.framing.layouts[direction].header

    @settings(max_examples=examples(150), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(stream_and_reads(frames_of(g, direction), header))
    def run(drawn: tuple[bytes, list[bytes]]) -> None:
        check(g, direction, *drawn)

    run()


OVERLAPPING = [(g, d) for g, d in PARSERS if g.package.StreamParser(d)._single.shifts]


def test_a_header_that_overlaps_itself_takes_the_batch_scan() -> None:
    """FEETECH's FF FF (FF FF FF holds two) no longer forces the byte-by-byte scan, and the fuzzer above covers it."""
    assert OVERLAPPING


def frame_ending_with(g: Generated, direction: Direction, tail: bytes) -> bytes | None:
    """An intact frame whose last bytes are `tail`: an example message with one integer field varied."""
    for example in g.protocol.examples:
        if example.direction != direction:
            continue
        message = g.package.decode(example.frame, direction)
        for name in field_names(message):
            if type(getattr(message, name)) is not int:
                continue
            for value in range(256):
                try:
                    frame = g.package.encode(replace(message, **{name: value}))
                except (EncodeError, TypeError, ValueError):
                    continue
                if frame.endswith(tail):
                    return frame
    return None


@pytest.mark.parametrize(("g", "direction"), OVERLAPPING, ids=[f"{g.protocol.name}:{d.value}" for g, d in OVERLAPPING])
def test_a_frame_right_after_one_that_ends_like_a_header(g: Generated, direction: Direction) -> None:
    """A frame ending in the first bytes of a header that overlaps itself (FEETECH: ... FF, then FF FF ...): the
    split finds a header straddling the two frames and misses the one where the second frame starts."""
    header = g.protocol.framing.layouts[direction].header
    shifts = g.package.StreamParser(direction)._single.shifts
    first = frame_ending_with(g, direction, header[: len(header) - shifts[0]])
    assert first is not None, "no example frame can end like the start of a header"
    second = frames_of(g, direction)[0]
    data = first + second
    for reads in ([data], [bytes([b]) for b in data], [data[: len(first)], data[len(first) :]]):
        batch, scan = g.package.StreamParser(direction), byte_by_byte(g.package.StreamParser(direction))
        got = [m for chunk in reads for m in batch.feed(chunk)]
        assert got == [m for chunk in reads for m in scan.feed(chunk)]
        assert got == [g.package.decode(first, direction), g.package.decode(second, direction)]
        assert (batch.errors, batch.garbage, batch.pending()) == (0, 0, b"")


@pytest.mark.parametrize(("g", "direction"), PARSERS, ids=[f"{g.protocol.name}:{d.value}" for g, d in PARSERS])
def test_parsers_of_one_frame_format_share_its_tables(g: Generated, direction: Direction) -> None:
    """A parser is made on every reset and reopen of a bus: its size tables are built once per frame format."""
    first, second = g.package.StreamParser(direction), g.package.StreamParser(direction)
    assert first._single is second._single
    assert first._single.frame_sizes and first._single.pieces
