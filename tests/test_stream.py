"""The stream parser on the spec's example frames; tests/test_stress.py feeds it long damaged streams."""

from __future__ import annotations

from conftest import ALL


def test_fashion_star_parser_takes_both_directions_at_once() -> None:
    fs = next(g for g in ALL if g.protocol.name == "fashionstar_uart")
    parser = fs.package.StreamParser()
    frames = [e.frame for e in fs.protocol.examples]
    assert [m.COMMAND for m in parser.feed(b"".join(frames))] == [e.command for e in fs.protocol.examples]
