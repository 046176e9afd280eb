"""The fast codec against construct's interpreted structs, and round trips of random valid messages."""

from __future__ import annotations

from contextlib import suppress
from typing import Any

import pytest
from conftest import (
    ALL,
    Generated,
    a_request,
    by_protocol,
    decode,
    encode,
    example_class,
    example_message,
    example_request,
    examples,
    requests,
    struct_context,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.lang.model import Example, Message, Scalar
from serialspec.lang.names import spec_name
from serialspec.runtime.errors import DecodeError, RangeError
from strategies import message_fields

MESSAGES = by_protocol([(g, m) for g in ALL for m in g.protocol.messages()])
EXAMPLES = by_protocol([(g, e) for g in ALL for e in g.protocol.examples])


def plain(value: Any) -> Any:
    """construct's containers as plain data, bytes as the codec's hex text, private keys dropped."""
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items() if not k.startswith("_")}
    if isinstance(value, list):
        return [plain(v) for v in value]
    if isinstance(value, bytes):
        return value.hex(" ")
    return value


def same(parsed: Any, value: Any) -> bool:
    """construct's value equals the message's, leaving out what the message does not hold (derived sizes in items)."""
    if isinstance(value, dict) and isinstance(parsed, dict):
        return all(k in parsed and same(parsed[k], v) for k, v in value.items())
    if isinstance(value, list) and isinstance(parsed, list):
        return len(value) == len(parsed) and all(same(p, v) for p, v in zip(parsed, value, strict=True))
    return bool(parsed == value)


def frame_content(g: Generated, frame: bytes, direction: str, context: dict[str, Any] | None = None) -> bytes:
    """The content of a frame: by the classic layout's offsets, or (stuffed, lengths anywhere) by the frame struct
    (`context`: a reply's layout and request, where replies are read with their request)."""
    if not g.protocol.framing.classic:
        return bytes(getattr(g.structs, f"{direction.upper()}_FRAME").parse(frame, **(context or {})).content)
    layout = next(lay for d, lay in g.protocol.framing.layouts.items() if d.value == direction)
    start = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    return frame[start : len(frame) - (layout.overhead - start)]


def message_type(g: Generated, spec: Message) -> Any:
    return next(c for c in g.package.MESSAGE_TYPES if c.__name__ == spec.class_name)


def spec_names(value: Any) -> Any:
    """Construct's containers keyed by the fields' spec names (the structs name a keyword's field `class_`)."""
    if isinstance(value, dict):
        return {spec_name(k): spec_names(v) for k, v in value.items()}
    if isinstance(value, list):
        return [spec_names(v) for v in value]
    return value


def check_against_construct(
    g: Generated, spec: Message, frame: bytes, fields: dict[str, Any], context: dict[str, Any] | None = None
) -> None:
    content = frame_content(g, frame, spec.direction.value, context)
    content_struct = g.structs.CONTENTS[(spec.key, spec.direction.value)]
    parsed = spec_names(plain(content_struct.parse(content)))
    layout = g.protocol.layout(spec)  # its own layout's values (layouts chosen by command may differ)
    frame_names = {e.name for e in (*layout.value_elements, *layout.optional)}  # the frame's, not the content's
    error = g.protocol.error_reply
    if spec.error_reply and error is not None:
        frame_names.add(error.element)  # the refused request's code, in the command element
    for name, value in fields.items():
        if name in frame_names:
            continue
        assert parsed[name] == pytest.approx(value) if isinstance(value, float) else same(parsed[name], value), name
    frame_struct = getattr(g.structs, f"{spec.direction.name}_FRAME")
    rebuilt = frame_struct.parse(frame, **(context or {}))
    if g.protocol.framing.classic:
        assert rebuilt.body.value.content == content
    else:
        assert frame_struct.build(rebuilt, **(context or {})) == frame


@pytest.mark.parametrize(("g", "example"), EXAMPLES)
def test_construct_struct_agrees_on_every_example(g: Generated, example: Example) -> None:
    request = example_request(g, example)
    message = decode(g, example.frame, example.direction.value, example_class(g, example), request)
    spec = next(m for m in g.protocol.messages() if m.class_name == type(message).__name__)
    check_against_construct(g, spec, example.frame, message.to_fields(), struct_context(g, spec, request))


@pytest.mark.parametrize(("g", "spec"), MESSAGES)
def test_random_valid_messages_round_trip_and_agree_with_construct(g: Generated, spec: Message) -> None:
    cls = message_type(g, spec)

    @settings(max_examples=examples(20), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(message_fields(g.protocol, spec), requests(g, spec))
    def round_trip(fields: dict[str, Any], request: Any) -> None:
        frame = encode(g, cls.from_fields(fields), request)
        decoded = decode(g, frame, spec.direction.value, cls, request)
        assert type(decoded) is cls
        assert decoded.to_fields() == fields
        context = struct_context(g, spec, request)
        check_against_construct(g, spec, frame, fields, context)
        content = frame_content(g, frame, spec.direction.value, context)
        content_struct = g.structs.CONTENTS[(spec.key, spec.direction.value)]
        assert content_struct.build(content_struct.parse(content)) == content

    round_trip()


def bounded_fields(spec: Message) -> list[Scalar]:
    """The integer fields whose range is narrower than their type's: a value outside it still fits the wire."""
    scalars = [f for f in spec.fields if isinstance(f, Scalar) and not f.hidden and not f.bits and not f.type.is_float]
    return [f for f in scalars if f.maximum < 2 ** (8 * f.type.size) - 1 or f.minimum > f.type.minimum]


@pytest.mark.parametrize(
    ("g", "spec"), by_protocol([(g, m) for g in ALL for m in g.protocol.messages() if bounded_fields(m)])
)
def test_out_of_range_values_are_refused_naming_field_and_range(g: Generated, spec: Message) -> None:
    cls = message_type(g, spec)
    bounded = bounded_fields(spec)
    request = a_request(g, spec)

    @settings(max_examples=examples(12), deadline=None)
    @given(message_fields(g.protocol, spec), st.data())
    def refused(fields: dict[str, Any], data: st.DataObject) -> None:
        target = data.draw(st.sampled_from(bounded))
        too_big = data.draw(st.booleans()) and target.maximum < target.type.maximum
        bad = int(target.maximum) + 1 if too_big or target.minimum <= target.type.minimum else int(target.minimum) - 1
        with pytest.raises(RangeError) as refused:
            encode(g, cls.from_fields({**fields, target.name: bad}), request)
        text = str(refused.value)
        assert target.name in text and f"{int(target.minimum)}..{int(target.maximum)}" in text

    refused()


@pytest.mark.parametrize("g", ALL, ids=[g.protocol.name for g in ALL])
def test_damaged_frames_fail_with_one_line(g: Generated) -> None:
    for example in g.protocol.examples:
        direction = example.direction.value
        frame = example.frame
        request = example_request(g, example)
        first = bytes([frame[0] ^ 0x01])  # a header byte, or an address the checksum covers
        last = frame[:-1] + bytes([(frame[-1] + 1) & 0xFF])
        optional = g.protocol.framing.layouts[example.direction].optional
        if any(example.fields.get(e.name) for e in optional):
            last = frame[:-1]  # the frame ends in an optional element's bytes, which the codec carries unchecked
        changed = (last, first + frame[1:])
        # a frame no checksum covers (a RoboClaw read request: address and command alone) with one byte changed can
        # be another valid frame: it must then decode to another message
        checked = any(e.role == "checksum" for e in g.protocol.layout(example_message(g, example)).elements)
        for damaged in (frame[:-1], *changed, frame + b"\x00"):
            if not checked and damaged in changed:
                with suppress(DecodeError):
                    assert decode(g, damaged, direction, None, request) != decode(g, frame, direction, None, request)
                    continue
            with pytest.raises(DecodeError) as failure:
                decode(g, damaged, direction, None, request)
            assert "\n" not in str(failure.value) and str(failure.value)
