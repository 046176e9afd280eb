"""The general frame engine's sizers (FrameCodec.sizers: probe() with each layout's plan read once into a closure,
what the stream parser calls per candidate) against probe() itself, on candidates hypothesis draws.

Candidates are cut from streams of example frames, frames with bytes changed, random bytes and bytes that matter to
the layouts (headers, trailers, command codes), at every position, with the end of the buffer anywhere: the sizer
must give probe()'s answer (a size, None to wait for bytes, -1 for no frame) every time, for every protocol whose
frames are not of the classic shape.
"""

from __future__ import annotations

import importlib

import pytest
from conftest import ALL, Generated, example_class, examples
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.runtime.framing import FrameCodec

CODECS = [
    (g, name, value)
    for g in ALL
    for name, value in vars(importlib.import_module(f"{g.package.__name__}.codec")).items()
    if isinstance(value, FrameCodec)
]


def test_general_framings_have_sizers() -> None:
    assert {g.protocol.name for g, _, _ in CODECS} >= {"dynamixel_p2", "modbus_rtu", "vesc"}
    for _, _, codec in CODECS:
        assert len(codec.sizers) == len(codec.variants)  # a layout with optional elements: one per variant


@st.composite
def candidate(draw: st.DrawFn, frames: list[bytes], special: list[int]) -> tuple[bytes, int, int]:
    parts = []
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.integers(0, 4))
        if kind == 0 and frames:
            frame = bytearray(draw(st.sampled_from(frames)))
            for _ in range(draw(st.integers(1, 3))):
                frame[draw(st.integers(0, len(frame) - 1))] = draw(st.sampled_from([*special, 0, 0xFF]))
            parts.append(bytes(frame))
        elif kind == 1:
            parts.append(bytes(draw(st.lists(st.sampled_from([*special, 0, 1, 0xFF]), max_size=12))))
        elif kind == 2:
            parts.append(draw(st.binary(max_size=12)))
        elif frames:
            parts.append(draw(st.sampled_from(frames)))
    buffer = b"".join(parts)
    end = draw(st.integers(0, len(buffer)))
    return buffer, draw(st.integers(0, end)), end


@pytest.mark.parametrize(("g", "name", "codec"), CODECS, ids=[f"{g.protocol.name}:{n}" for g, n, _ in CODECS])
def test_a_sizer_answers_as_probe(g: Generated, name: str, codec: FrameCodec) -> None:
    frames = [e.frame for e in g.protocol.examples]
    # (replies read in their request's layout key their content sizes by class name: no byte)
    codes = {code for code in codec.content_sizes if isinstance(code, int)}
    special = sorted({b for layout in codec.layouts for b in layout.header + layout.trailer} | codes)
    special = [b for b in special if 0 <= b < 256]

    @settings(max_examples=examples(100), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(candidate(frames, special))
    def run(drawn: tuple[bytes, int, int]) -> None:
        buffer, start, end = drawn
        for layout, sizer in zip(codec.variants, codec.sizers, strict=True):
            assert sizer(buffer, start, end) == codec.probe(layout, buffer, start, end), (buffer.hex(" "), start, end)

    run()
    for frame in frames:  # every example frame: both say the same, whole or cut
        for end in range(len(frame) + 1):
            for layout, sizer in zip(codec.variants, codec.sizers, strict=True):
                assert sizer(frame, 0, end) == codec.probe(layout, frame, 0, end)
    # replies read in the layout of their request: the stream parser sizes them by probe() with the reply class
    # awaited (no sizer); each example reply is its whole frame in its class's layout, and no other layout's
    for example in g.protocol.examples if codec.replies else ():
        if example.direction.name != name.strip("_").split("_")[0]:
            continue
        cls = example_class(g, example)
        for index, layout in enumerate(codec.layouts):
            size = codec.probe(layout, example.frame, 0, len(example.frame), cls)
            assert size == (len(example.frame) if codec.replies[cls.__name__] == index else -1), example.name
