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
from conftest import Generated, examples
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
    @settings(max_examples=examples(80), deadline=None, suppress_health_check=[HealthCheck.too_slow])
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


def one_key_frames(g: Generated, direction: Direction) -> list[bytes]:
    """The example frames of the first key the sieve knows (frames checked in runs), or none."""
    parser = g.package.StreamParser(direction)
    current = parser._single
    width = len(current.header)
    by_key: dict[bytes, list[bytes]] = {}
    for e in g.protocol.examples:
        if e.direction == direction:
            by_key.setdefault(e.frame[width : width + current.leading], []).append(e.frame)
    return next((frames for key, frames in by_key.items() if key in current.sieves), [])


SIEVED = [(g, d) for g, d in LEAN if one_key_frames(g, d)]


def test_fashion_star_replies_take_the_sieve() -> None:
    assert "fashionstar_uart:response" in [f"{g.protocol.name}:{d.value}" for g, d in SIEVED]


@pytest.mark.parametrize(("g", "direction"), SIEVED, ids=[f"{g.protocol.name}:{d.value}" for g, d in SIEVED])
def test_reads_of_one_key_take_what_the_byte_by_byte_scan_takes(
    g: Generated, direction: Direction, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Frames of one key (their bytes changed, so the sieve checks many checksums) with the damage `damaged` draws,
    now and then a frame of another key: the sieve decides those reads (of a few headers or more, here), or leaves
    them to the loop, as the byte-by-byte scan would."""
    from serialspec.runtime import stream as runtime  # noqa: PLC0415

    monkeypatch.setattr(runtime, "_SIEVE_FROM", 4)
    frames = one_key_frames(g, direction)
    others = [e.frame for e in g.protocol.examples if e.direction == direction]
    header = g.protocol.framing.layouts[direction].header

    @given(st.data())
    @settings(max_examples=examples(80), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    def check(data: st.DataObject) -> None:
        parts: list[bytes] = []
        for _ in range(data.draw(st.integers(1, 80))):
            frame = data.draw(st.sampled_from(frames))
            kind = data.draw(st.integers(0, 19))
            if kind < 3:  # a garbage run
                parts.append(
                    bytes(data.draw(st.lists(st.integers(0, 255) | st.sampled_from(list(header)), max_size=8)))
                )
            elif kind < 7:  # a cut frame start, the next frame right after
                parts.append(data.draw(st.sampled_from(frames))[: data.draw(st.integers(1, len(frame) - 1))])
            elif kind == 7:  # a byte changed
                at = data.draw(st.integers(0, len(frame) - 1))
                frame = frame[:at] + bytes([frame[at] ^ data.draw(st.integers(1, 255))]) + frame[at + 1 :]
            elif kind == 8:
                frame = data.draw(st.sampled_from(others))
            parts.append(frame)
        stream = b"".join(parts)
        expected = fed(scanning(g.package.StreamParser(direction)), [stream])
        assert fed(g.package.StreamParser(direction), [stream]) == expected, stream.hex(" ")
        split = reads(data, stream)
        assert fed(g.package.StreamParser(direction), split) == expected, (stream.hex(" "), [len(c) for c in split])

    check()


def test_the_sieve_decides_a_read_of_frames_and_cut_frame_starts(monkeypatch: pytest.MonkeyPatch) -> None:
    """A read of one key's frames, some after the cut start of another, one corrupt, the last one cut: the sieve
    decides it whole (the loop is not run), with the loop's frames, errors, skipped and held bytes."""
    import serialspec_protocols.fashionstar_uart as fs  # noqa: PLC0415
    from serialspec.runtime import stream as runtime  # noqa: PLC0415

    replies = [fs.encode(fs.ReadAngleResponse(servo_id=i, angle=40 * i - 900)) for i in range(40)]
    corrupt = replies[3][:-1] + bytes([replies[3][-1] ^ 1])
    stream = b"".join(
        [b"\x01\x02", *replies[:3], replies[4][:5], corrupt, replies[5][:2], *replies[5:39], replies[39][:6]]
    )
    monkeypatch.setattr(runtime, "_SIEVE_FROM", 8)  # (the sieve for a read this short, as for the long ones)
    assert len(stream) < 512  # (a longer read takes the batch scan)
    decided: list[object] = []
    sieve = runtime._sieve

    def spy(*args: Any) -> Any:
        decided.append(sieve(*args))
        return decided[-1]

    monkeypatch.setattr(runtime, "_sieve", spy)
    found = fed(fs.StreamParser(Direction.RESPONSE), [stream])
    assert len(decided) == 1 and decided[0]
    assert found == fed(scanning(fs.StreamParser(Direction.RESPONSE)), [stream])
    assert found[0] == [fs.decode(r, Direction.RESPONSE) for r in replies[:3] + replies[5:39]]
    assert found[1] == (2, 2 + 5 + 8 + 2, replies[39][:6])  # (a header alone names no frame: no error)


def test_whole_frames_of_a_run_key_are_checked_and_built_without_a_decoder_call(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The usual piece (a whole frame of a key whose frames are checked in runs) has its sum checked and its message
    built by the loop itself, from the format's units: no decoder is called for it, corrupt or not."""
    g, direction = next((g, d) for g, d in SIEVED if f"{g.protocol.name}:{d.value}" == "fashionstar_uart:response")
    parser = g.package.StreamParser(direction)
    current = parser._single

    def refuse(*_: object) -> None:
        raise AssertionError("a decoder was called for a whole frame of a run key")

    lean = {key: (size, rest, refuse, unit) for key, (size, rest, _, unit) in current.lean.items() if unit is not None}
    assert lean  # the run keys have units
    monkeypatch.setattr(current, "lean", lean)
    frames = one_key_frames(g, direction)[:3]
    corrupt = frames[0][:-1] + bytes((frames[0][-1] ^ 0xFF,))
    assert parser.feed(b"\x00" + b"".join(frames) + corrupt + b"\x07") == [
        g.package.decode(f, direction) for f in frames
    ]
    assert (parser.errors, parser.garbage, parser.pending()) == (1, 1 + len(corrupt), b"\x07")
