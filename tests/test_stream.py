"""The stream parser on the spec's example frames; tests/test_stress.py feeds it long damaged streams."""

from __future__ import annotations

import pytest
from conftest import ALL, Generated, by_protocol, set_plain_byte
from serialspec.lang.model import Example


def test_fashion_star_parser_takes_both_directions_at_once() -> None:
    fs = next(g for g in ALL if g.protocol.name == "fashionstar_uart")
    parser = fs.package.StreamParser()
    frames = [e.frame for e in fs.protocol.examples]
    assert [m.COMMAND for m in parser.feed(b"".join(frames))] == [e.command for e in fs.protocol.examples]


# --- stray headers and out-of-range frame values never cost an intact frame -------------------------------------------

# Frames found by their header (a header-less frame is found by its gap and CRC: stray bytes are its own problem)
EXAMPLES = by_protocol(
    [(g, e) for g in ALL for e in g.protocol.examples if g.protocol.framing.layouts[e.direction].header]
)


def strays(g: Generated, example: Example) -> list[bytes]:
    """Bytes a line can carry before a frame: its header alone, a truncated start of the frame up to its length,
    a header with the longest length byte, and the frame with every frame-level value out of its declared range."""
    layout = g.protocol.framing.layouts[example.direction]
    frame = example.frame
    # (a frame cut inside its content is left out: with the next frame's first bytes it may pass an 8-bit checksum
    # by chance, and a valid frame is a frame; test_stress.py measures how rarely)
    # (a frame without a length, ended by its trailer, cut anywhere: Modbus ASCII's ':' and hex digits)
    cut = layout.length_offset + 2 if layout.length_offset >= 0 else len(frame)
    found = [layout.header, layout.header * 2, *(frame[:k] for k in range(1, cut))]
    if layout.length_offset >= 0:
        long_candidate = bytearray(frame[: layout.length_offset + 1])
        long_candidate[layout.length_offset] = 0xFF
        found.append(bytes(long_candidate))
    for element in layout.value_elements:
        assert element.type is not None
        if element.type.size == 1 and element.maximum < element.type.maximum:
            value = next(v for v in range(255, -1, -1) if v != element.broadcast and v > element.maximum)
            bad, offset = set_plain_byte(layout, frame, layout.offsets[element.name], lambda _, v=value: v)
            found.extend([bad, bad[: offset + 2]])
    return found


@pytest.mark.parametrize(("g", "example"), EXAMPLES)
def test_no_stray_bytes_before_a_frame_lose_it(g: Generated, example: Example) -> None:
    expected = g.package.decode(example.frame, example.direction.value)
    for stray in strays(g, example):
        whole = g.package.StreamParser(example.direction.value).feed(stray + example.frame)
        assert expected in whole, (stray.hex(" "), whole)
        parser = g.package.StreamParser(example.direction.value)
        trickled = [m for byte in stray + example.frame for m in parser.feed(bytes([byte]))]
        assert expected in trickled, (stray.hex(" "), trickled)


def test_feetech_reply_behind_a_stray_ff_ff() -> None:
    """The case of issue 10: the stray FF FF read as a frame start with length 0xFF hid the reply behind it."""
    sms = next(g for g in ALL if g.protocol.name == "feetech_sms")
    replies = sms.package.StreamParser("response").feed(bytes.fromhex("ff ff ff ff 01 02 00 fc"))
    assert [r.to_fields() for r in replies] == [{"id": 1, "error": 0, "data": ""}]
