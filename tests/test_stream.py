"""The stream parser under garbage, truncated frame starts, corrupt checksums and random read sizes."""

from __future__ import annotations

import random

import pytest
from conftest import ALL, Generated


def examples_by_direction(g: Generated) -> dict[str, list[bytes]]:
    frames: dict[str, list[bytes]] = {}
    for example in g.protocol.examples:
        frames.setdefault(example.direction.value, []).append(example.frame)
    return frames


@pytest.mark.parametrize("g", ALL, ids=[g.protocol.name for g in ALL])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_every_intact_frame_is_delivered_in_order(g: Generated, seed: int) -> None:
    rng = random.Random(seed)
    for direction, frames in examples_by_direction(g).items():
        header = g.protocol.framing.layouts[next(d for d in g.protocol.framing.layouts if d.value == direction)].header
        stream = bytearray()
        sent: list[bytes] = []
        corrupt = 0
        for _ in range(2000):
            frame = rng.choice(frames)
            roll = rng.random()
            if roll < 0.2:  # a truncated frame start: the header and a length byte, then the next real frame
                stream += frame[: len(header) + 2]
            elif roll < 0.3:
                stream += bytes(rng.randrange(256) for _ in range(rng.randrange(1, 12)))
            elif roll < 0.4:  # corrupt checksum
                stream += frame[:-1] + bytes([frame[-1] ^ 0x5A])
                corrupt += 1
                continue
            stream += frame
            sent.append(frame)
        parser = g.package.StreamParser(direction)
        received = []
        position = 0
        while position < len(stream):
            size = rng.randrange(1, 64)
            received += parser.feed(bytes(stream[position : position + size]))
            position += size
        assert [g.package.encode(m) for m in received] == sent
        assert parser.errors >= corrupt


def test_fashion_star_parser_takes_both_directions_at_once() -> None:
    fs = next(g for g in ALL if g.protocol.name == "fashionstar_uart")
    parser = fs.package.StreamParser()
    frames = [e.frame for e in fs.protocol.examples]
    assert [m.COMMAND for m in parser.feed(b"".join(frames))] == [e.command for e in fs.protocol.examples]
