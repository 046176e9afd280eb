"""The codec's fast paths against the plain ones they replace.

Decoders build messages from the tuple of their values instead of through __new__, the stream parser decodes
frames in place (`decode_at`) instead of through `decode`, checksums are inlined expressions and loops instead of
runtime calls, and fixed-size frames are packed by one struct. Each must agree with the plain way of doing the same.
"""

from __future__ import annotations

import dataclasses
import pickle
from contextlib import suppress
from typing import Any

import pytest
from conftest import ALL, Generated, by_protocol, decode, encode, examples, expect, requested, requests, set_plain_byte
from hypothesis import HealthCheck, given, settings
from serialspec.backends.python.content import PackageCode
from serialspec.lang.model import Message
from serialspec.runtime.errors import ChecksumError, DecodeError
from serialspec.runtime.message import field_names, slot_setters
from strategies import message_fields

MESSAGES = by_protocol([(g, m) for g in ALL for m in g.protocol.messages()])


def message_type(g: Generated, spec: Message) -> Any:
    return next(c for c in g.package.MESSAGE_TYPES if c.__name__ == spec.class_name)


def checksum(g: Generated, covered: bytes, element: Any) -> int:
    """The frame checksum by the runtime's reference functions, which the generated codec no longer calls."""
    c = element.checksum or g.protocol.framing.checksum
    return c.algorithm.function()(covered)


@pytest.mark.parametrize(("g", "spec"), MESSAGES)
def test_fast_paths_agree_with_the_plain_ones(g: Generated, spec: Message) -> None:
    cls = message_type(g, spec)
    layout = g.protocol.layout(spec)
    direction = spec.direction.value
    last = layout.elements[-1]
    checked = any(e.role == "checksum" for e in layout.elements)  # a RoboClaw read request has no checksum
    # frames no checksum protects among this direction's (RoboClaw's read requests) can turn up inside others
    unchecked = any(
        all(e.role != "checksum" for e in other.elements) for other in g.protocol.framing.alternatives[spec.direction]
    )

    @settings(max_examples=examples(12), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(message_fields(g.protocol, spec), requests(g, spec))
    def agree(fields: dict[str, Any], request: Any) -> None:
        built = cls.from_fields(fields)  # through the dataclass __init__
        frame = encode(g, built, request)
        # the checksum the inlined code appended is the reference function's (where it ends the frame), over the
        # request's bytes first where it takes them in (RoboClaw's replies)
        if last.role == "checksum":
            covered = frame[layout.covered_from : len(frame) - layout.covered_to_end]
            size = layout.checksum_offset_from_end
            big = last.checksum is not None and last.checksum.endian == ">"
            assert int.from_bytes(frame[-size:], "big" if big else "little") == checksum(
                g, requested(g, last, request) + covered, last
            )
        # built through its slots: equal, same hash, every field set, still frozen
        decoded = decode(g, frame, direction, cls, request)
        assert type(decoded) is cls
        assert decoded == built and hash(decoded) == hash(built)
        assert all(hasattr(decoded, name) for name in field_names(decoded))
        assert repr(decoded) == repr(built) and pickle.loads(pickle.dumps(decoded)) == decoded
        if field_names(decoded):  # a message with no fields (Fashion Star BEGIN_ASYNC) has none to set
            with pytest.raises(dataclasses.FrozenInstanceError):
                decoded.__setattr__(field_names(decoded)[0], 0)
        # the stream parser decodes in place, between other bytes, to the same message
        parser = g.package.StreamParser(direction)
        expect(parser, cls, request)  # the reply layout, where replies share a code (and the request it answers)
        # a frame start after it (not where the frame is its header alone, as RoboClaw's 0xFF acknowledgement)
        start = frame[: len(layout.header)] if len(frame) > len(layout.header) else b""
        # where some frames have no checksum, a shorter one inside (80 18 in a RoboClaw write) is rightly taken first
        if not (unchecked and hides_a_frame(g, frame, direction)):
            assert parser.feed(stray_byte(layout) + frame + start) == [decoded]
            assert parser.errors == 0 and parser.pending() == start
        if not checked:
            return
        # a frame with a wrong checksum fails both ways
        # the checksum's last byte (in a transformed span, its plain byte: the span written again)
        damaged, _ = set_plain_byte(layout, frame, -1 - trailer_size(layout, built), lambda byte: byte ^ 0x01)
        with pytest.raises(ChecksumError):
            decode(g, damaged, direction, None, request)
        if unchecked and hides_a_frame(g, damaged, direction):
            return
        parser = g.package.StreamParser(direction)
        expect(parser, cls, request)  # the reply layout, where replies share a code (and the request it answers)
        assert parser.feed(damaged) == []
        # without a header every byte is a candidate, and a one-byte header (VESC 02) turns up inside frames: a
        # candidate inside the damaged frame may fail its checksum too
        assert parser.errors == 1 if len(layout.header) > 1 else parser.errors >= 1

    agree()


def hides_a_frame(g: Generated, frame: bytes, direction: str) -> bool:
    """A valid frame of the direction lies inside the frame and ends before it (the codec alone decides)."""
    for start in range(len(frame)):
        for stop in range(start + 1, len(frame) + (start > 0)):
            with suppress(DecodeError):
                g.package.decode(frame[start:stop], direction)
                return True
    return False


def trailer_size(layout: Any, message: Any) -> int:
    """Bytes after the frame's last checksum (VESC: its end byte; MAVLink: its signature, where the message has one)."""
    index = max(i for i, e in enumerate(layout.elements) if e.role == "checksum")
    return sum(
        e.size or 0
        for e in layout.elements[index + 1 :]
        if e.role != "optional" or getattr(message, e.name) is not None
    )


def stray_byte(layout: Any) -> bytes:
    """A byte that cannot start a frame: not a header's first byte, nor a value a leading address can hold (none
    where a frame starts with its content: RoboClaw's replies)."""
    first = layout.elements[0]
    if first.role == "content":
        return b""
    if first.role == "header":
        return b"\x00" if first.constant[:1] != b"\x00" else b"\xff"
    return bytes([next(b for b in range(256) if not (first.minimum <= b <= first.maximum or b == first.broadcast))])


def test_slot_setters_refuse_a_class_without_slots() -> None:
    @dataclasses.dataclass(frozen=True)
    class NoSlots:
        value: int

    with pytest.raises(TypeError, match="NoSlots.value is not a slot"):
        slot_setters(NoSlots)


def test_slot_setters_store_into_a_frozen_slotted_dataclass() -> None:
    @dataclasses.dataclass(frozen=True, slots=True)
    class Pair:
        first: int
        second: str

    set_first, set_second = slot_setters(Pair)
    pair = object.__new__(Pair)
    set_first(pair, 1)
    set_second(pair, "two")
    assert pair == Pair(1, "two") and hash(pair) == hash(Pair(1, "two"))


def test_two_formats_never_share_a_struct_constant() -> None:
    """Formats of more than six items are named after their message; two such formats for one name get two names
    (the second used to replace the first silently, so a decoder would unpack with another message's layout)."""
    code = PackageCode(ALL[0].protocol)
    long_a, long_b = "<BBBBBBBB", "<HHHHHHHH"
    first, second = code.struct("same", long_a), code.struct("same", long_b)
    assert first != second
    assert code.structs[first] == long_a and code.structs[second] == long_b
    assert code.struct("other", long_b) == second  # one format, one constant


def test_replace_copies_a_message_with_changed_fields_and_refuses_unknown_names() -> None:
    from serialspec.runtime.message import field_names, replace
    from serialspec_protocols import fashionstar_uart as fs

    message = fs.RotateRequest(servo_id=2, angle=900, interval=500)
    moved = replace(message, angle=0)
    assert (moved.angle, moved.servo_id, message.angle) == (0, 2, 900)
    assert field_names(moved) == field_names(message)
    with pytest.raises(TypeError, match="no field 'angel'"):
        replace(message, angel=0)
