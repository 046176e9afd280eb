"""Hypothesis: the batch scan (split at every header) against the byte-by-byte scan on random noisy streams.

Streams are drawn from intact example frames, frames with a byte changed (checksum, length byte, command code or
an address out of range), frames cut short, runs of header bytes (a header that can overlap itself, like FEETECH's
FF FF, makes FF FF FF ... candidates that start inside one another), lone headers and random bytes; the same stream
is fed in random reads to a parser as it is and to one whose batch scan is replaced by the byte-by-byte scan. After
every read both must have returned equal messages and agree on errors, skipped bytes and the bytes held back.
The same for made-up frame formats no shipped spec has (headers of one to three bytes that overlap themselves in
other ways, an address range, a command code with frames decoded whole, a two-byte range), since the runtime reads
the frame format from the model and knows no protocol.
"""

from __future__ import annotations

import pytest
from conftest import Generated, examples
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import ChecksumError, EncodeError
from serialspec.runtime.message import Direction, Message, build, field_names, replace
from serialspec.runtime.stream import FrameFormat, StreamParser, ValueRanges
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


# --- frame formats no shipped spec has: other headers that overlap themselves, other value ranges -----------------


class Toy(Message):
    """A frame of a made-up format, kept whole: two are equal when their bytes are."""

    __slots__ = ()  # a message is a tuple of its fields underneath (runtime/message.py)
    __match_args__ = ("frame",)
    PROTOCOL = "toy"
    COMMAND = "toy"
    SUBCOMMAND = None
    DIRECTION = Direction.RESPONSE
    frame: bytes

    def __new__(cls, frame: bytes) -> Toy:
        return build(cls, (frame,))


def toy_decode_at(buf: bytes, start: int, stop: int, width: int) -> Toy:
    if sum(buf[start + width : stop - 1]) & 0xFF != buf[stop - 1]:
        raise ChecksumError("bad sum")
    return Toy(buf[start:stop])


def toy_format(header: bytes, kind: str) -> FrameFormat:
    """`address`: header, address (0..253 or 254), length, content, sum; `command`: header, command, length,
    content, sum, command 1's frames decoded whole; `wide`: header, a 16-bit big-endian address (0..1000), length,
    content, sum. The sum covers what follows the header."""
    width = len(header)

    def decode_at(buf: bytes, start: int, stop: int) -> Toy:
        return toy_decode_at(buf, start, stop, width)

    def whole(buf: bytes, start: int) -> Toy | None:
        try:
            return toy_decode_at(buf, start, start + width + 5, width)
        except ChecksumError:
            return None

    if kind == "address":
        ranges: ValueRanges = ((width, 1, "little", False, 0, 253, 254),)
        return FrameFormat(header, width + 3, width + 1, 0, None, {None: (0, 5)}, decode_at, value_ranges=ranges)
    if kind == "command":
        fixed = {1 << 8 | 2: (width + 5, whole)}
        return FrameFormat(header, width + 3, width + 1, 0, width, {1: (2, 2), 2: (0, 4)}, decode_at, fixed)
    ranges = ((width, 2, "big", False, 0, 1000, None),)
    return FrameFormat(header, width + 4, width + 2, 0, None, {None: (0, 3)}, decode_at, value_ranges=ranges)


@st.composite
def toy_piece(draw: st.DrawFn, header: bytes, kind: str) -> bytes:
    choice = draw(st.integers(0, 5))
    if choice == 0:  # header bytes, repeated
        return header[: draw(st.integers(1, len(header)))] * draw(st.integers(1, 4))
    if choice == 1:  # noise made of header bytes and a few others
        return bytes(draw(st.lists(st.sampled_from([*header, 0, 1, 2, 3, 254, 255]), max_size=8)))
    if kind == "address":
        before = bytes([draw(st.sampled_from([0, 7, 253, 254, 255]))])
    elif kind == "command":
        before = bytes([draw(st.sampled_from([1, 2, 3]))])
    else:
        before = draw(st.sampled_from([0, 999, 1000, 1001, 0xFFFF])).to_bytes(2, "big")
    content = bytes(draw(st.lists(st.sampled_from([*header, 0, 5, 255]), max_size=2)))
    if draw(st.booleans()):  # a last content byte that makes the sum the header's first byte
        fix = (header[0] - sum(before) - len(content) - 1 - sum(content)) & 0xFF
        content += bytes([fix])
    body = before + bytes([len(content)]) + content
    frame = header + body + bytes([sum(body) & 0xFF ^ draw(st.sampled_from([0, 0, 0, 1]))])  # some corrupt
    return frame[: draw(st.integers(1, len(frame)))] if draw(st.integers(0, 5)) == 0 else frame


TOY_HEADERS = [b"\xaa", b"\xaa\xaa", b"\xaa\xaa\xaa", b"\xab\xcd\xab", b"\xab\xab\xcd", b"\xab\xcd"]


@pytest.mark.parametrize("kind", ["address", "command", "wide"])
@pytest.mark.parametrize("header", TOY_HEADERS, ids=[h.hex() for h in TOY_HEADERS])
def test_batch_and_byte_by_byte_scans_agree_on_other_frame_formats(header: bytes, kind: str) -> None:
    frame_format = toy_format(header, kind)
    assert StreamParser(frame_format)._single is not None and StreamParser(frame_format)._single.splittable

    @settings(max_examples=examples(50), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(st.lists(toy_piece(header, kind), min_size=1, max_size=25), st.lists(st.integers(0, 200), max_size=8))
    def run(pieces: list[bytes], cuts: list[int]) -> None:
        data = b"".join(pieces)
        edges = [0, *sorted({min(c, len(data)) for c in cuts}), len(data)]
        batch, scan = StreamParser(frame_format), byte_by_byte(StreamParser(frame_format))
        for a, b in zip(edges, edges[1:], strict=False):
            assert batch.feed(data[a:b]) == scan.feed(data[a:b]), data.hex(" ")
            assert (batch.errors, batch.garbage, batch.pending()) == (scan.errors, scan.garbage, scan.pending())

    run()
