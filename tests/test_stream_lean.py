"""The lean scan (`StreamParser._lean`): reads of a few frames, for formats whose header cannot overlap itself and
whose size key is the bytes right after it (Fashion Star, Hiwonder RRC).

Hypothesis draws noisy streams of the format's example frames with garbage runs, cut frame starts (a frame's first
bytes, then the next frame), corrupt frames and stray headers, as a serial line damages them. Fed in one read, one
byte at a time and in random reads (1 to 300 bytes, most under the batch scan's threshold), the parser must return
the frames a reference parser finds with the byte-by-byte scan alone (`_scan`, fed the stream whole), and end with
the same errors, skipped bytes and bytes held back.
"""

from __future__ import annotations

from typing import Any

import pytest
from conftest import Generated
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.runtime.message import Direction, Message
from serialspec.runtime.stream import StreamParser
from test_batch_stream import PARSERS

LEAN = [(g, d) for g, d in PARSERS if g.package.StreamParser(d)._single.leading]
IDS = [f"{g.protocol.name}:{d.value}" for g, d in LEAN]


def test_fashion_star_replies_take_the_lean_scan() -> None:
    assert "fashionstar_uart:response" in IDS


def scanning(parser: StreamParser) -> StreamParser:
    """The parser with every scan replaced by the byte-by-byte one."""
    scan = parser._scan
    parser._lean = parser._walk = parser._split = lambda buffer, current: scan(buffer)  # type: ignore[method-assign]
    return parser


def counting(parser: StreamParser) -> list[int]:
    calls: list[int] = []
    lean = parser._lean

    def spy(buffer: bytes, current: Any) -> list[Message]:
        calls.append(len(buffer))
        return lean(buffer, current)

    parser._lean = spy  # type: ignore[method-assign]
    return calls


@st.composite
def damaged(draw: st.DrawFn, g: Generated, direction: Direction) -> bytes:
    frames = [e.frame for e in g.protocol.examples if e.direction == direction]
    header = g.protocol.framing.layouts[direction].header
    parts: list[bytes] = []
    for _ in range(draw(st.integers(1, 60))):
        frame = draw(st.sampled_from(frames))
        kind = draw(st.integers(0, 9))
        if kind == 0:  # a garbage run: random bytes and header bytes
            parts.append(bytes(draw(st.lists(st.integers(0, 255) | st.sampled_from(list(header)), max_size=8))))
        elif kind == 1:  # a cut frame start, the next frame right after
            parts.append(frame[: draw(st.integers(1, len(frame) - 1))])
        elif kind == 2:  # a byte changed: mostly a checksum that fails
            at = draw(st.integers(0, len(frame) - 1))
            parts.append(frame[:at] + bytes([frame[at] ^ draw(st.integers(1, 255))]) + frame[at + 1 :])
        elif kind == 3:  # a stray header
            parts.append(header)
        parts.append(frame)
    return b"".join(parts)


def reads(data: st.DataObject, stream: bytes) -> list[bytes]:
    chunks = []
    position = 0
    while position < len(stream):
        size = data.draw(st.integers(1, 300))
        chunks.append(stream[position : position + size])
        position += size
    return chunks


def fed(parser: StreamParser, chunks: list[bytes]) -> tuple[list[Message], tuple[int, int, bytes]]:
    found = [m for chunk in chunks for m in parser.feed(chunk)]
    return found, (parser.errors, parser.garbage, parser.pending())


@pytest.mark.parametrize(("g", "direction"), LEAN, ids=IDS)
def test_every_split_takes_what_the_byte_by_byte_scan_takes(g: Generated, direction: Direction) -> None:
    @given(st.data())
    @settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
    def check(data: st.DataObject) -> None:
        stream = data.draw(damaged(g, direction))
        expected = fed(scanning(g.package.StreamParser(direction)), [stream])
        assert fed(g.package.StreamParser(direction), [stream]) == expected, stream.hex(" ")
        assert fed(g.package.StreamParser(direction), [bytes([b]) for b in stream]) == expected, stream.hex(" ")
        split = reads(data, stream)
        assert fed(g.package.StreamParser(direction), split) == expected, (stream.hex(" "), [len(c) for c in split])

    check()


@pytest.mark.parametrize(("g", "direction"), LEAN, ids=IDS)
def test_reads_of_a_few_frames_take_the_lean_scan(g: Generated, direction: Direction) -> None:
    frames = [e.frame for e in g.protocol.examples if e.direction == direction][:4]
    stream = b"\x00".join(frames * 3)
    assert len(stream) < 512  # (a longer read takes the batch scan)
    parser = g.package.StreamParser(direction)
    calls = counting(parser)
    assert len(parser.feed(stream)) == 3 * len(frames)
    assert calls == [len(stream)]
