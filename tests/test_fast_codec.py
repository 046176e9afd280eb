"""The codec's fast paths against the plain ones they replace.

Decoders build messages from the tuple of their values instead of through __new__, the stream parser decodes
frames in place (`decode_at`) instead of through `decode`, checksums are inlined expressions and loops instead of
runtime calls, and fixed-size frames are packed by one struct. Each must agree with the plain way of doing the same.
"""

from __future__ import annotations

import dataclasses
import pickle
from typing import Any

import pytest
from conftest import ALL, Generated, by_protocol, examples, set_plain_byte
from hypothesis import HealthCheck, given, settings
from serialspec.backends.python.content import PackageCode
from serialspec.lang.model import Message
from serialspec.runtime.errors import ChecksumError
from serialspec.runtime.message import field_names, slot_setters
from strategies import message_fields

MESSAGES = by_protocol([(g, m) for g in ALL for m in g.protocol.messages()])


def message_type(g: Generated, spec: Message) -> Any:
    return next(c for c in g.package.MESSAGE_TYPES if c.__name__ == spec.class_name)


def checksum(g: Generated, covered: bytes) -> int:
    """The frame checksum by the runtime's reference functions, which the generated codec no longer calls."""
    c = g.protocol.framing.checksum
    return c.algorithm.function()(covered)


@pytest.mark.parametrize(("g", "spec"), MESSAGES)
def test_fast_paths_agree_with_the_plain_ones(g: Generated, spec: Message) -> None:
    cls = message_type(g, spec)
    layout = g.protocol.framing.layouts[spec.direction]
    direction = spec.direction.value

    @settings(max_examples=examples(30), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(message_fields(g.protocol, spec))
    def agree(fields: dict[str, Any]) -> None:
        built = cls.from_fields(fields)  # through the dataclass __init__
        frame = g.package.encode(built)
        # the checksum the inlined code appended is the reference function's (where it ends the frame)
        if layout.elements[-1].role == "checksum":
            covered = frame[layout.covered_from : len(frame) - layout.covered_to_end]
            size = layout.checksum_offset_from_end
            assert int.from_bytes(frame[-size:], "little") == checksum(g, covered)
        # built through its slots: equal, same hash, every field set, still frozen
        decoded = g.package.decode(frame, direction, cls)
        assert type(decoded) is cls
        assert decoded == built and hash(decoded) == hash(built)
        assert all(hasattr(decoded, name) for name in field_names(decoded))
        assert repr(decoded) == repr(built) and pickle.loads(pickle.dumps(decoded)) == decoded
        if field_names(decoded):  # a message with no fields (Fashion Star BEGIN_ASYNC) has none to set
            with pytest.raises(dataclasses.FrozenInstanceError):
                decoded.__setattr__(field_names(decoded)[0], 0)
        # the stream parser decodes in place, between other bytes, to the same message
        parser = g.package.StreamParser(direction)
        parser.expect(cls)  # the reply layout, where replies share a code
        assert parser.feed(stray_byte(layout) + frame + frame[: len(layout.header)]) == [decoded]
        assert parser.errors == 0 and parser.pending() == frame[: len(layout.header)]
        # a frame with a wrong checksum fails both ways
        # the checksum's last byte (in a transformed span, its plain byte: the span written again)
        damaged, _ = set_plain_byte(layout, frame, -1 - trailer_size(layout), lambda byte: byte ^ 0x01)
        with pytest.raises(ChecksumError):
            g.package.decode(damaged, direction)
        parser = g.package.StreamParser(direction)
        parser.expect(cls)  # the reply layout, where replies share a code
        assert parser.feed(damaged) == []
        # without a header every byte is a candidate, and a one-byte header (VESC 02) turns up inside frames: a
        # candidate inside the damaged frame may fail its checksum too
        assert parser.errors == 1 if len(layout.header) > 1 else parser.errors >= 1

    agree()


def trailer_size(layout: Any) -> int:
    """Bytes after the frame's last checksum (VESC: its end byte)."""
    index = max(i for i, e in enumerate(layout.elements) if e.role == "checksum")
    return sum(e.size or 0 for e in layout.elements[index + 1 :])


def stray_byte(layout: Any) -> bytes:
    """A byte that cannot start a frame: not a header's first byte, nor a value a leading address can hold."""
    first = layout.elements[0]
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
