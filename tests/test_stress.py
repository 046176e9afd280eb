"""The stream parser over long streams of random valid frames mixed with every kind of damage a serial line makes.

For each protocol and direction (and Fashion Star's both-directions parser), a stream of intact frames drawn from a
pool of random valid messages is interleaved with random garbage, truncated frame starts (a header and a length
byte, then the next real frame) and frames with a corrupted checksum, then fed in reads of random sizes. Every intact
frame must come out in order, nothing else may, no exception may escape, and every corrupt frame is counted.

An 8- or 16-bit checksum cannot tell every piece of damage from a frame: 1 truncated start in 256 is followed by
bytes that happen to complete it with a valid checksum. Such a piece makes a frame the protocol itself cannot
distinguish from a real one, so the stream builder leaves it out. It finds them with the codec's `decode` (never with
the parser under test) and the test bounds how many it left out, so this can neither hide a resynchronisation bug
nor quietly test less.

`SERIALSPEC_STRESS_FRAMES` sets the intact frames per stream: 2,000 by default (`make test`), 100,000 under
`make stress`, which runs pytest with `-s` so the summary line of each stream is printed.
"""

from __future__ import annotations

import functools
import os
import random
import time
from dataclasses import dataclass
from typing import Any

import pytest
from conftest import ALL, Generated, a_request, encode, expect, message_class, needs_request, set_plain_byte
from hypothesis import HealthCheck, Phase, given, settings
from serialspec.lang.model import Direction, FrameLayout, Message
from serialspec.runtime.errors import DecodeError
from strategies import message_fields

FRAMES = int(os.environ.get("SERIALSPEC_STRESS_FRAMES", "2000"))
# random valid messages per protocol and direction, the stream samples from them: drawing is the slow part
POOL_SIZE = min(1000, max(200, FRAMES // 100))
MAX_FRAME = 255 + 16  # more than any frame a one-byte length can describe, plus the largest overhead

# (protocol, direction or None for a parser of both directions) for every stream parser the packages offer
STREAMS = [(g, d) for g in ALL for d in g.protocol.framing.layouts] + [
    (g, None) for g in ALL if not g.protocol.framing.shared_header
]


def stream_id(stream: tuple[Generated, Direction | None]) -> str:
    g, direction = stream
    return f"{g.protocol.name}:{direction.value if direction else 'both'}"


# A pool's frames with the layout each travels in (layouts chosen by command: a RoboClaw read or write)
Pool = list[tuple[bytes, FrameLayout]]


def random_frames(g: Generated, spec: Message, count: int) -> list[bytes]:
    """`count` frames of random valid values of one message, the same ones on every run (a reply read with its
    request answers the same request throughout: conftest.a_request)."""
    cls = next(c for c in g.package.MESSAGE_TYPES if c.__name__ == spec.class_name)
    request = a_request(g, spec)
    frames: list[bytes] = []

    # Hypothesis as a generator of valid values, not as a test runner.
    @settings(
        max_examples=count,
        database=None,
        derandomize=True,
        phases=[Phase.generate],
        deadline=None,
        suppress_health_check=list(HealthCheck),
    )
    @given(message_fields(g.protocol, spec))
    def draw(fields: dict[str, Any]) -> None:
        frames.append(encode(g, cls.from_fields(fields), request))

    draw()
    return frames


def frame_pool(g: Generated, direction: Direction, awaited: str = "") -> Pool:
    """The spec's example frames and about POOL_SIZE frames of random valid messages of every type (`awaited`: of
    that reply class alone, where replies are read with their request: its share of POOL_SIZE)."""
    return _frame_pool(g.protocol.name, direction, awaited)


@functools.cache
def _frame_pool(protocol: str, direction: Direction, awaited: str) -> Pool:
    g = next(g for g in ALL if g.protocol.name == protocol)
    every = [m for m in g.protocol.messages() if m.direction == direction]
    specs = [m for m in every if awaited in ("", m.class_name)]
    pool: Pool = []
    for spec in specs:
        layout = g.protocol.layout(spec)
        if not awaited:  # (an example reply answers a request of its own)
            pool += [
                (e.frame, layout)
                for e in g.protocol.examples
                if e.direction == direction and e.command == spec.command and e.subcommand == spec.subcommand
            ]
        pool += [(frame, layout) for frame in random_frames(g, spec, max(4, POOL_SIZE // len(every)))]
    # frames no checksum protects (RoboClaw's read requests, address and command alone) turn up inside others: the
    # parser rightly takes such a frame first, and the frame around it is no intact frame of the stream
    if any(not checksums(layout) for _, layout in pool):
        pool = [(frame, layout) for frame, layout in pool if not hides_a_frame(g, frame, direction)]
    return pool


def checksums(layout: FrameLayout) -> bool:
    return any(e.role == "checksum" for e in layout.elements)


def hides_a_frame(g: Generated, frame: bytes, direction: Direction) -> bool:
    """A valid frame lies inside the frame and ends before it (the codec alone decides)."""
    for start in range(len(frame)):
        for stop in range(start + 1, len(frame) + (start > 0)):
            try:
                g.package.decode(frame[start:stop], direction.value)
                return True
            except DecodeError:
                pass
    return False


@dataclass
class Group:
    """Damage (possibly none) followed by one intact frame."""

    damage: list[bytes]
    corrupt: int  # frames among `damage` with a corrupted checksum
    frame: bytes


def damaged(rng: random.Random, pool: Pool) -> tuple[bytes, bool] | None:
    """Damage to put before an intact frame, and whether it is a corrupt frame; None for none."""
    roll = rng.random()
    frame, layout = rng.choice(pool)
    if roll < 0.2:  # a truncated frame start: the header and a length byte (or whatever comes before the content)
        return frame[: start_size(layout)], False
    if roll < 0.3:
        return bytes(rng.randrange(256) for _ in range(rng.randrange(1, 12))), False
    if roll < 0.4 and checksums(layout):  # the frame with its checksum corrupted (a hex-ASCII span stays hex)
        flip = rng.randrange(1, 256)
        spoiled, _ = set_plain_byte(layout, frame, -checksum_from_end(layout), lambda old: old ^ flip)
        return spoiled, True
    return None


def start_size(layout: FrameLayout) -> int:
    """Bytes of a frame start that say what the frame is: up to its length byte, or up to its content."""
    if layout.classic:
        return layout.length_offset + 1
    content = next((i for i, e in enumerate(layout.elements) if e.role == "content"), 0)  # none: nothing says
    return sum(e.size or 0 for e in layout.elements[:content])


def checksum_from_end(layout: FrameLayout) -> int:
    """How far from the end of a frame its (last) checksum starts: the checksum and what follows it (a trailer)."""
    index = max(i for i, e in enumerate(layout.elements) if e.role == "checksum")
    return sum(e.size or 0 for e in layout.elements[index:])


class Ambiguity:
    """Finds damage that would form a valid frame with the bytes after it, with the codec alone."""

    def __init__(self, g: Generated, layouts: list[FrameLayout], waiting: tuple[Any, Any] = (None, None)) -> None:
        self.g = g
        self.layouts = layouts
        self.cls, self.request = waiting  # the reply class and request, where replies are read with their request

    def __call__(self, window: bytes, end: int, window_is_the_rest: bool) -> bool:
        """True if a header starting in window[:end] (the damage) begins a frame that decodes."""
        if not self.g.protocol.framing.classic:
            return self.general(window, end, window_is_the_rest)
        for layout in self.layouts:
            position = window.find(layout.header, 0, end + len(layout.header) - 1)
            while 0 <= position < end:
                if position + layout.length_offset >= len(window):
                    return window_is_the_rest  # a frame start the stream ends in: the parser waits for it
                size = layout.overhead + window[position + layout.length_offset] - layout.length_adds
                if position + size > len(window):
                    return window_is_the_rest
                try:
                    self.g.package.decode(window[position : position + size], layout.direction.value)
                    return True
                except DecodeError:
                    pass
                position = window.find(layout.header, position + 1, end + len(layout.header) - 1)
        return False

    def general(self, window: bytes, end: int, window_is_the_rest: bool) -> bool:
        """The same for frames of any layout, sized by the codec's frame engine (every byte a candidate start
        where frames have no header)."""
        for layout in self.layouts:
            codec = getattr(self.g.package.codec, f"_{layout.direction.name}_FRAMES")
            for position in range(end):
                for alternative in codec.layouts:
                    size = codec.probe(alternative, window, position, len(window), self.cls)
                    if size is None or (size > 0 and position + size > len(window)):
                        if window_is_the_rest:
                            return True  # a frame start the stream ends in: the parser waits for it
                        continue
                    if size < 0:
                        continue
                    try:
                        frame = window[position : position + size]
                        if self.cls is None:
                            self.g.package.decode(frame, layout.direction.value)
                        else:
                            self.g.package.decode(frame, layout.direction.value, self.cls, request=self.request)
                        return True
                    except DecodeError:
                        pass
        return False


def build_stream(
    g: Generated, direction: Direction | None, frames: int, rng: random.Random, waiting: tuple[Any, Any] = (None, None)
) -> tuple[bytes, list[bytes], int, int]:
    """The stream, the intact frames in it in order, the corrupt frames in it, and the damage left out (`waiting`:
    the reply class and request of a stream of replies read with their request)."""
    directions = [direction] if direction else list(g.protocol.framing.layouts)
    awaited = waiting[0].__name__ if waiting[0] is not None else ""
    pools = [frame_pool(g, d, awaited) for d in directions]
    groups: list[Group] = []
    for _ in range(frames):
        pool = rng.choice(pools)
        group = Group([], 0, rng.choice(pool)[0])
        while (damage := damaged(rng, pool)) is not None and len(group.damage) < 3:
            group.damage.append(damage[0])
            group.corrupt += damage[1]
        groups.append(group)
    # From the end backwards, so that the bytes after each group's damage are final when it is checked.
    ambiguous = Ambiguity(g, [g.protocol.framing.layouts[d] for d in directions], waiting)
    left_out = 0
    following = b""  # the first MAX_FRAME bytes of the stream after the current group's damage
    rest_length = 0
    for group in reversed(groups):
        rest_length += len(group.frame)
        following = (group.frame + following)[:MAX_FRAME]
        if group.damage:
            damage = b"".join(group.damage)
            if ambiguous(damage + following, len(damage), rest_length <= MAX_FRAME):
                left_out += len(group.damage)
                group.damage, group.corrupt = [], 0
            else:
                rest_length += len(damage)
                following = (damage + following)[:MAX_FRAME]
    stream = b"".join(b"".join(group.damage) + group.frame for group in groups)
    return stream, [group.frame for group in groups], sum(group.corrupt for group in groups), left_out


def random_reads(stream: bytes, rng: random.Random) -> list[bytes]:
    """Mostly small reads, as a serial port gives them, and now and then a large one."""
    reads = []
    position = 0
    while position < len(stream):
        size = rng.randrange(1, 64) if rng.random() < 0.99 else rng.randrange(64, 4096)
        reads.append(stream[position : position + size])
        position += size
    return reads


def awaits(g: Generated, direction: Direction | None) -> list[tuple[Any, Any]]:
    """The parsers' awaited (reply class, request): where replies are read with their request a parser takes the
    replies of one class to one request, so the stream is one part per reply class; else one part of everything."""
    specs = [m for m in g.protocol.messages() if m.direction == direction]
    if not specs or not needs_request(g, specs[0]):
        return [(None, None)]
    return [(message_class(g, spec), a_request(g, spec)) for spec in specs]


@pytest.mark.parametrize("stream", STREAMS, ids=stream_id)
def test_every_intact_frame_is_delivered_in_order(stream: tuple[Generated, Direction | None]) -> None:
    g, direction = stream
    parts = awaits(g, direction)
    for waiting in parts:
        cls, request = waiting
        name = stream_id(stream) + (f":{cls.__name__}" if cls is not None else "")
        rng = random.Random(f"{name}:{FRAMES}")
        data, sent, corrupt, left_out = build_stream(g, direction, max(1, FRAMES // len(parts)), rng, waiting)
        reads = random_reads(data, rng)
        parser = g.package.StreamParser(direction.value if direction else None)
        if cls is not None:
            expect(parser, cls, request)
        received = []
        started = time.monotonic()
        for chunk in reads:
            received += parser.feed(chunk)
        elapsed = time.monotonic() - started
        frames_received = [encode(g, message, request) for message in received]
        first_difference = next(
            (i for i, (a, b) in enumerate(zip(frames_received, sent, strict=False)) if a != b), None
        )
        assert first_difference is None and len(frames_received) == len(sent), (
            f"{name} frame {first_difference}: got {frames_received[first_difference or 0].hex(' ')}, "
            f"sent {sent[first_difference or 0].hex(' ')}; {len(frames_received)} received of {len(sent)}"
        )
        assert parser.errors >= corrupt
        assert parser.pending() == b""  # the stream ends with an intact frame: nothing is left waiting
        assert left_out <= len(sent) // 100 + 5  # ambiguous damage is rare (about 1 truncated start in 256)
        print(
            f"\nstress {name}: {len(sent)} intact frames delivered in order, {corrupt} corrupt counted "
            f"(parser.errors {parser.errors}), {len(data)} bytes in {len(reads)} reads of 1..4095 bytes, "
            f"{left_out} ambiguous damages left out, parsed in {elapsed:.2f} s"
        )
