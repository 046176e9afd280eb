"""Sizes and counts given by a field (`size: n`, `count: m`) whose `range:` is narrower than its type's:
tests/strategies.py draws only lengths the field allows, so every message it draws encodes and decodes back; and a
length outside the range is refused on encode, in one line naming the sizing field, before a byte is made.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterator
from types import ModuleType
from typing import Any

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.backends import emitters
from serialspec.backends.python import files as python_files
from serialspec.backends.python.memory import imported
from serialspec.lang.loader import load_text
from serialspec.lang.model import Message, Protocol
from serialspec.lang.resolve import resolve
from serialspec.runtime.errors import DecodeError, EncodeError
from strategies import message_fields

SPEC: dict[str, Any] = {
    "protocol": "sized",
    "title": "Sized",
    "description": "Bytes, text, a list and a group, each sized or counted by a field with a narrow range.",
    "byte_order": "little",
    "serial": {"baudrate": 9600},
    "framing": {
        "elements": {
            "header": {"role": "header", "value": "AA"},
            "code": {"role": "command", "type": "u8"},
            "length": {"role": "length", "type": "u8"},
            "content": {"role": "content"},
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["code", "content"]},
        }
    },
    "commands": {
        "put": {
            "code": 1,
            "title": "Put",
            "request": {
                "fields": {
                    "n": {"type": "u8", "range": [2, 4]},
                    "data": {"type": "bytes", "size": "n"},
                    "k": {"type": "u8", "range": [1, 3]},
                    "name": {"type": "string", "size": "k"},
                    "m": {"type": "u8", "range": [1, 2]},
                    "items": {"type": "group", "count": "m", "fields": {"a": "u8"}},
                    "bc": {"type": "u8", "range": [2, 6]},
                    "regs": {"type": "array", "of": "u16", "size": "bc"},
                    "c": {"type": "u8", "range": [3, 5]},
                    "values": {"type": "array", "of": "u8", "count": "c"},
                }
            },
        }
    },
}
# field -> (its sizing field, a value of the field's kind holding `size` items or bytes)
SIZED = {
    "data": ("n", lambda size: "ab " * size),
    "name": ("k", lambda size: "x" * size),
    "items": ("m", lambda size: [{"a": 1}] * size),
    "regs": ("bc", lambda size: [7] * (size // 2)),
    "values": ("c", lambda size: [1] * size),
}
ALLOWED = {"n": (2, 4), "k": (1, 3), "m": (1, 2), "bc": (2, 6), "c": (3, 5)}


@pytest.fixture(scope="module")
def sized() -> Iterator[tuple[Protocol, Message, ModuleType]]:
    protocol = resolve(load_text(yaml.safe_dump(SPEC, sort_keys=False), "sized.yaml"))
    files: dict[str, str] = {}
    for emitter in emitters():
        if emitter.folder != "c":  # (the C target refuses an array sized in bytes)
            files |= {p.split("/", 1)[1]: t for p, t in emitter.files(protocol).items() if p.startswith("sized/")}
    with imported("sized", files, "the sized lengths test") as package:
        importlib.import_module("sized.messages")
        (message,) = protocol.messages()
        yield protocol, message, package


def test_every_drawn_message_encodes(sized: tuple[Protocol, Message, ModuleType]) -> None:
    protocol, message, package = sized
    cls = getattr(package.messages, message.class_name)

    @settings(max_examples=100, deadline=None)
    @given(message_fields(protocol, message))
    def check(fields: dict[str, Any]) -> None:
        built = cls.from_fields(fields)
        assert package.decode(package.encode(built), "request") == built

    check()


@st.composite
def wrong_size(draw: st.DrawFn) -> tuple[str, int]:
    """A sized field and a length its sizing field's range does not allow (of whole items for the u16 array)."""
    field = draw(st.sampled_from(sorted(SIZED)))
    low, high = ALLOWED[SIZED[field][0]]
    size = draw(st.integers(0, low - 1) | st.integers(high + 1, 12)) if low > 0 else draw(st.integers(high + 1, 12))
    if field == "regs" and size % 2:
        size += 1 if size + 1 > high or size + 1 < low else -1
    return field, size


def test_a_length_outside_the_sizing_fields_range_is_refused(sized: tuple[Protocol, Message, ModuleType]) -> None:
    protocol, message, package = sized
    cls = getattr(package.messages, message.class_name)

    @settings(max_examples=100, deadline=None)
    @given(message_fields(protocol, message), wrong_size())
    def check(fields: dict[str, Any], wrong: tuple[str, int]) -> None:
        field, size = wrong
        counter, value = SIZED[field]
        low, high = ALLOWED[counter]
        assert not low <= size <= high
        with pytest.raises((EncodeError, ValueError)) as refused:
            package.encode(cls.from_fields({**fields, field: value(size)}))
        said = str(refused.value)
        assert "\n" not in said and f"{counter} = {size} is outside its range {low}..{high}" in said, said

    check()


def framed_spec(length: dict[str, Any]) -> str:
    """A frame whose length element has a `range` (CRSF's [2, 62], RTCM 3's 10 bits after 6 reserved zero bits) and
    one command whose content is any size: only the range, not the content, bounds a candidate's length."""
    elements = {
        "header": SPEC["framing"]["elements"]["header"],
        "length": {"role": "length", **length},
        "content": {"role": "content"},
        "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["length", "content"]},
    }
    note = {"request": {"unsolicited": True, "fields": {"data": {"type": "bytes", "size": "rest"}}}}
    return yaml.safe_dump(
        SPEC | {"protocol": "ranged", "title": "Ranged", "framing": {"elements": elements}, "commands": {"note": note}},
        sort_keys=False,
    )


@pytest.mark.parametrize(
    "length",
    [{"type": "u8", "range": [1, 6]}, {"type": "u16", "endian": "big", "range": [1, 6]}],
    ids=["u8 (the length-byte engine)", "u16 big (the general engine)"],
)
def test_a_frame_whose_length_is_outside_its_range_is_no_frame(length: dict[str, Any]) -> None:
    """Decode refuses it in one line, the stream parser looks past it at once (it would otherwise wait for the bytes
    the length claims, the frame after it unread) whatever the reads, and encode refuses a content it cannot count."""
    protocol = resolve(load_text(framed_spec(length), "ranged.yaml"))
    files = {path.split("/", 1)[1]: code for path, code in python_files(protocol).items()}
    with imported("ranged", files, "the ranged length test") as package:
        good = package.encode(package.NoteRequest(data=b"hi"))
        width = 1 if length["type"] == "u8" else 2
        bad = b"\xaa" + (9).to_bytes(width, "big") + b"\x01" * 10  # 9: outside 1..6
        with pytest.raises(DecodeError) as refused:
            package.decode(bad, "request")
        assert str(refused.value) == "length = 9 is outside its range 1..6"
        stream = bad[: 1 + width] + good
        for split in range(len(stream) + 1):
            parser = package.StreamParser("request")
            got = parser.feed(stream[:split]) + parser.feed(stream[split:])
            assert [m.data for m in got] == [b"hi"], split
        with pytest.raises(EncodeError) as refused_encode:
            package.encode(package.NoteRequest(data=b"seven!!"))  # 7 bytes: a length of 7
        assert str(refused_encode.value) == "request frame: length = 7 is outside its range 1..6"


def test_a_fixed_size_frame_whose_length_is_outside_its_range_is_refused_on_encode() -> None:
    """A command of one content size has an inline encoder with its length as a constant: that constant is held to
    the range too (it once sent a length of 8 that decode and the stream parser then refused)."""
    text = framed_spec({"type": "u16", "endian": "big", "range": [1, 6]}).replace(
        "data:\n          type: bytes\n          size: rest", "a: u32\n        b: u32"
    )
    assert "b: u32" in text
    protocol = resolve(load_text(text, "ranged.yaml"))
    files = {path.split("/", 1)[1]: code for path, code in python_files(protocol).items()}
    with imported("ranged", files, "the ranged length test") as package:
        with pytest.raises(EncodeError) as refused:
            package.encode(package.NoteRequest(a=1, b=2))
        assert str(refused.value) == "request frame: length = 8 is outside its range 1..6"


def test_a_length_may_count_itself() -> None:
    """Found writing an LX-16A spec as a newcomer: its length is "N parameters + 3", counting itself, the command and
    the checksum (`counts: [length, checksum]`), which was refused ("the length must come before what it counts");
    it reads as counting from the next element with its own size added. SERVO_POS_READ to servo 1 is 55 55 01 03 1C DF
    in the LX-16A document."""
    text = yaml.safe_dump(
        SPEC
        | {
            "protocol": "selfcount",
            "title": "Self-counting length",
            "framing": {
                "elements": {
                    "header": {"role": "header", "value": "55 55"},
                    "id": {"role": "address", "type": "u8"},
                    "length": {"role": "length", "type": "u8", "counts": ["length", "checksum"]},
                    "code": {"role": "command", "type": "u8"},
                    "content": {"role": "content"},
                    "checksum": {"role": "checksum", "algorithm": "sum", "invert": True, "covers": ["id", "content"]},
                }
            },
            "commands": {
                "pos_read": {"code": 0x1C, "request": {"fields": {}}},
                "move": {"code": 1, "request": {"fields": {"angle": "u16", "time": "u16"}}},
            },
        },
        sort_keys=False,
    )
    protocol = resolve(load_text(text, "selfcount.yaml"))
    files = {path.split("/", 1)[1]: code for path, code in python_files(protocol).items()}
    with imported("selfcount", files, "the self-counting length test") as package:
        assert package.encode(package.PosReadRequest(id=1)) == bytes.fromhex("55 55 01 03 1c df")
        move = bytes.fromhex("55 55 01 07 01 f4 01 e8 03 16")
        assert package.decode(move, "request") == package.MoveRequest(id=1, angle=500, time=1000)
        assert package.StreamParser("request").feed(b"\x00" + move) == [package.MoveRequest(id=1, angle=500, time=1000)]
