"""Straight-line frame code (backends/python/frames/) against the interpreted frame engine
(runtime/framing.py).

Codecs of frames that are not of the classic shape check and build their frames in generated straight-line code;
the engine's FrameCodec (which the stream parser still uses to size frames) stays the reference. On random frames,
intact and damaged, both must give the same message or the same error, word for word; on random contents, codes
and frame values both must build the same bytes or refuse with the same error. The shipped DYNAMIXEL 2.0, Modbus
RTU and VESC codecs, and small specs with what those do not have (escaping with two rules, a constant and a length
with `adds` inside a stuffed span, a big-endian u16 length, a trailer) and one the straight-line form cannot take
(a checksum inside the stuffed span, which keeps the engine). Length-byte codecs too: their decode() runs the same
generated checks past its whole-frame tables.
"""

from __future__ import annotations

import sys
from pathlib import Path
from types import ModuleType, SimpleNamespace
from typing import Any

import pytest
from conftest import ALL, Generated, by_protocol, encode, examples, requests
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.backends.common.frames import runtime_layouts
from serialspec.lang.model import Direction, Message
from serialspec.runtime.errors import DecodeError
from serialspec.runtime.framing import ERROR_REPLY, FrameCodec
from strategies import message_fields
from test_framing_specs import generate

SHIPPED = ["dynamixel_p2", "modbus_rtu", "vesc"]

# Bytes that make the shipped and test framings stuff, escape or look like a header or trailer.
SPECIAL = [b"\xff\xff\xfd", b"\xff\xff\xfd\xfd", b"\xc0", b"\xdb", b"\xdb\xdc", b"\xdb\xdd", b"\x02", b"\x03", b"\x7e"]

SLIP_LIKE = """
protocol: {name}
title: SLIP-like
byte_order: little
serial: {{baudrate: 115200}}
framing:
  elements:
    start: {{role: header, value: "C0"}}
    address: {{role: address, type: u8, range: [1, 200], broadcast: 255}}
    length: {{role: length, type: u16, endian: big, counts: [command, check], adds: 1}}
    command: {{role: command, type: u8}}
    reserved: {{role: constant, value: "5A"}}
    body: {{role: content}}
    status: {{role: status, type: u8, directions: [response]}}
    check:
      role: checksum
      type: u16
      endian: big
      algorithm: crc
      crc: {{name: CRC-16/KERMIT, width: 16, poly: 0x1021, init: 0, refin: true, refout: true, xorout: 0,
             check: 0x2189}}
      covers: {{request: [address, body], response: [address, status]}}
    end: {{role: trailer, value: "C0"}}
  transparency:
    span: {{request: [command, body], response: [command, status]}}
    replace: {{"C0": "DB DC", "DB": "DB DD"}}
commands:
  ping:
    code: 1
    request: {{fields: {{}}}}
    response: {{fields: {{model: u16}}}}
  write:
    code: 2
    request:
      fields:
        register: u8
        data: {{type: bytes, size: rest}}
    response: {{fields: {{}}}}
"""

# The checksum lies inside the stuffed span and covers bytes before the stuffing (as HDLC's FCS): the engine's.
INNER_CHECKSUM = """
protocol: {name}
title: Inner checksum
byte_order: little
serial: {{baudrate: 115200}}
framing:
  elements:
    start: {{role: header, value: "7E"}}
    command: {{role: command, type: u8}}
    body: {{role: content}}
    fcs: {{role: checksum, type: u8, algorithm: xor, covers: [command, body]}}
    end: {{role: trailer, value: "7E"}}
  transparency:
    span: [command, fcs]
    replace: {{"7E": "7D 5E", "7D": "7D 5D"}}
commands:
  echo:
    code: 5
    request:
      fields: {{data: {{type: bytes, size: rest}}}}
    response:
      fields: {{data: {{type: bytes, size: rest}}}}
"""


@pytest.fixture(scope="module")
def custom(tmp_path_factory: pytest.TempPathFactory) -> dict[str, ModuleType]:
    path: Path = tmp_path_factory.mktemp("straight")
    return {
        "slip_like": generate(path, SLIP_LIKE, "slip_like"),
        "inner_checksum": generate(path, INNER_CHECKSUM, "inner_checksum"),
    }


def engine_decode(codec: ModuleType, direction: str, frame: bytes, expect: type[Any] | None) -> Any:
    """What the codecs did before they had straight-line frame code: the engine unwraps, the decoder decodes."""
    upper = direction.upper()
    frames: FrameCodec = getattr(codec, f"_{upper}_FRAMES")
    decoders = getattr(codec, f"_{upper}_DECODERS")
    unwrapped = frames.unwrap(frame)
    code, content = unwrapped.code, unwrapped.content
    if code is not None and code & frames.error_flag:
        layout = frames.layouts[0]
        assert layout.command is not None
        mask = (1 << (8 * layout.elements[layout.command].size)) - 1
        keep = mask & ~frames.error_flag
        return decoders[ERROR_REPLY](content, 0, len(content), *unwrapped.values, code & keep)
    decoder = decoders.get(code)
    if expect is not None:
        expected, alternative = getattr(codec, f"_{upper}_EXPECTED", {}).get(expect, (None, None))
        if alternative is not None and expected == code:
            decoder = alternative
    if decoder is None:
        raise DecodeError("unknown command None" if code is None else f"unknown command {code:#04x}")
    return decoder(content, 0, len(content), *unwrapped.values)


def outcome(action: Any, *arguments: Any) -> tuple[str, str]:
    try:
        return "ok", repr(action(*arguments))
    except Exception as exc:  # the same error, word for word, is part of the agreement
        return type(exc).__name__, str(exc)


@st.composite
def frame_cases(draw: st.DrawFn, codec: ModuleType, direction: str) -> tuple[bytes, int | None, tuple[int, ...]]:
    """A content (often holding bytes that get stuffed), a code (usually one the direction knows) and values."""
    frames: FrameCodec = getattr(codec, f"_{direction.upper()}_FRAMES")
    layout = frames.layouts[0]
    pieces = draw(st.lists(st.one_of(st.sampled_from(SPECIAL), st.binary(max_size=6)), max_size=12))
    content = b"".join(pieces)
    codes = sorted(code for code in frames.content_sizes if code is not None and code >= 0)
    code: int | None = None
    if layout.command is not None:
        code = draw(st.sampled_from(codes) if codes else st.integers(0, 255))
        if frames.error_flag and draw(st.booleans()):
            code = draw(st.integers(0, frames.error_flag - 1)) | frames.error_flag
    values = []
    for index in layout.values:
        element = layout.elements[index]
        choices = [st.integers(element.minimum, element.maximum)]
        if element.also is not None:
            choices.append(st.just(element.also))
        values.append(draw(st.one_of(choices)))
    return content, code, tuple(values)


@st.composite
def damaged(draw: st.DrawFn, frame: bytes) -> bytes:
    """The frame intact, or with a byte changed, cut short, lengthened, or a stuffed sequence put in."""
    kind = draw(st.sampled_from(["intact", "byte", "cut", "extra", "special"]))
    if kind == "intact" or not frame:
        return frame
    at = draw(st.integers(0, len(frame) - 1))
    if kind == "byte":
        return frame[:at] + bytes([draw(st.integers(0, 255))]) + frame[at + 1 :]
    if kind == "cut":
        return frame[:at]
    if kind == "extra":
        return frame + draw(st.binary(min_size=1, max_size=4))
    return frame[:at] + draw(st.sampled_from(SPECIAL)) + frame[at:]


def check_agreement(codec: ModuleType, direction: str, data: st.DataObject) -> None:
    content, code, values = data.draw(frame_cases(codec, direction))
    frames: FrameCodec = getattr(codec, f"_{direction.upper()}_FRAMES")
    wrap = getattr(codec, f"_wrap_{direction}")
    built = outcome(wrap, content, code, *values)
    assert built == outcome(frames.wrap, content, code, values)
    frame = frames.wrap(content, code, values) if built[0] == "ok" else data.draw(st.binary(max_size=30))
    frame = data.draw(damaged(frame))
    expected = getattr(codec, f"_{direction.upper()}_EXPECTED", {})
    expect = data.draw(st.sampled_from([None, *expected])) if expected else None
    straight = outcome(codec.decode, frame, direction, expect)
    assert straight == outcome(engine_decode, codec, direction, frame, expect), frame.hex(" ")


@pytest.mark.parametrize("direction", ["request", "response"])
@pytest.mark.parametrize("name", SHIPPED)
@settings(max_examples=examples(100), suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_shipped_codecs_agree_with_the_engine(name: str, direction: str, data: st.DataObject) -> None:
    codec = pytest.importorskip(f"{name}.codec")
    check_agreement(codec, direction, data)


@pytest.mark.parametrize("direction", ["request", "response"])
@pytest.mark.parametrize("name", ["slip_like", "inner_checksum"])
@settings(max_examples=examples(100), suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_specs_with_other_framings_agree_with_the_engine(
    custom: dict[str, ModuleType], name: str, direction: str, data: st.DataObject
) -> None:
    check_agreement(custom[name].codec, direction, data)


def test_which_codecs_are_straight_line(custom: dict[str, ModuleType]) -> None:
    """The shipped general framings and the SLIP-like one get straight-line code; the checksum inside a stuffed
    span keeps the engine (its frame functions call FrameCodec)."""
    import inspect

    for name in SHIPPED:
        codec = pytest.importorskip(f"{name}.codec")
        for direction in ("request", "response"):
            assert "_FRAMES.unwrap" not in inspect.getsource(getattr(codec, f"_decode_{direction}")), name
            assert "_FRAMES.wrap" not in inspect.getsource(getattr(codec, f"_wrap_{direction}")), name
    assert "_FRAMES.unwrap" not in inspect.getsource(custom["slip_like"].codec._decode_request)
    assert "_REQUEST_FRAMES.unwrap" in inspect.getsource(custom["inner_checksum"].codec._decode_request)


def test_slip_like_round_trip_with_escapes(custom: dict[str, ModuleType]) -> None:
    m = custom["slip_like"]
    request = m.WriteRequest(address=7, register=0xC0, data=b"\xdb\xc0\x00")
    frame = m.encode(request)
    assert frame[0] == 0xC0 and frame[-1] == 0xC0 and b"\xc0" not in frame[1:-1]  # every C0 inside escaped
    assert m.decode(frame, "request") == request
    assert m.StreamParser("request").feed(b"\x00" + frame + frame) == [request, request]
    with pytest.raises(DecodeError, match="bad stuffing"):
        m.decode(frame[:4] + b"\xdb\x00" + frame[4:], "request")


def test_an_item_cut_short_is_a_decode_error() -> None:
    """Found by the agreement fuzzer: a BULK_WRITE item with 3 of its 5 leading bytes. Content is decoded in place,
    so the item's fields are checked against the bytes left rather than read from the CRC after them (the engine,
    which decoded a copy, let struct.error out)."""
    dynamixel_p2 = pytest.importorskip("dynamixel_p2")
    frame = bytes.fromhex("ff ff fd 00 fe 07 00 93 ff ff fd fd dc 18")
    with pytest.raises(DecodeError, match="bulk_write request: id needs 5 bytes, 3 left"):
        dynamixel_p2.decode(frame, "request")


LENGTH_BYTE = [g for g in ALL if g.protocol.text is None and g.protocol.framing.classic]


@pytest.mark.parametrize("direction", ["request", "response"])
@pytest.mark.parametrize("g", LENGTH_BYTE, ids=[g.protocol.name for g in LENGTH_BYTE])
@settings(max_examples=examples(100), suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_length_byte_codecs_agree_with_the_engine(g: Generated, direction: str, data: st.DataObject) -> None:
    """A length-byte codec's decode() (its whole-frame tables first, then the checks frames/ writes for every
    framing) gives the engine's message or error, word for word, on intact and damaged frames; the engine made from
    the same layouts (backends/common/frames.py) and the codec's content sizes."""
    codec, upper = g.package.codec, direction.upper()
    layouts = runtime_layouts(g.protocol, Direction(direction))
    engine = SimpleNamespace(
        **{
            f"_{upper}_FRAMES": FrameCodec(layouts, getattr(codec, f"_{upper}_SIZES")),
            f"_{upper}_DECODERS": getattr(codec, f"_{upper}_DECODERS"),
        }
    )
    content, code, values = data.draw(frame_cases(engine, direction))
    frames: FrameCodec = getattr(engine, f"_{upper}_FRAMES")
    built = outcome(frames.wrap, content, code, values)
    frame = frames.wrap(content, code, values) if built[0] == "ok" else data.draw(st.binary(max_size=30))
    frame = data.draw(damaged(frame))
    assert outcome(codec.decode, frame, direction, None) == outcome(engine_decode, engine, direction, frame, None), (
        frame.hex(" ")
    )


GENERAL = by_protocol([(g, m) for g in ALL if not g.protocol.framing.classic for m in g.protocol.messages()])


@pytest.mark.parametrize(("g", "spec"), GENERAL)
def test_encoders_make_the_frames_the_engine_makes(g: Generated, spec: Message) -> None:
    """Encoders whose frame is made inline (the head packed with the content) give the engine's bytes: the
    engine takes the frame apart and wraps its content again into the same frame."""
    cls = next(c for c in g.package.MESSAGE_TYPES if c.__name__ == spec.class_name)
    frames: FrameCodec = getattr(g.package.codec, f"_{spec.direction.name}_FRAMES")

    by_command = g.protocol.framing.by_command  # layouts chosen by command: wrap in the one the frame was read in

    @settings(max_examples=examples(20), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(message_fields(g.protocol, spec), requests(g, spec))
    def same_bytes(fields: dict[str, Any], request: Any) -> None:
        frame = encode(g, cls.from_fields(fields), request)
        # a reply read with its request: in its class's layout, with the request's elements by name
        asked = None if request is None else g.package.codec._REQUEST_FRAMES.unwrap(encode(g, request)).named()
        unwrapped = frames.unwrap(frame, cls, asked) if asked is not None else frames.unwrap(frame)
        layout = frames.layouts.index(unwrapped.layout) if by_command else None
        rewrapped = frames.wrap(
            unwrapped.content, unwrapped.code, unwrapped.values, layout, asked, extras=unwrapped.extras
        )
        assert rewrapped == frame

    same_bytes()


# Requests and responses told apart by their header, in a framing that is not of the classic shape (a two-byte
# length, a CRC-16): decode() without a direction picks the direction by the header.
TOLD_BY_HEADER = """
protocol: {name}
title: Told by header
byte_order: little
serial: {{baudrate: 115200}}
framing:
  elements:
    start: {{role: header, value: {{request: "A5 01", response: "5A 02"}}}}
    length: {{role: length, type: u16, counts: [command, body]}}
    command: {{role: command, type: u8}}
    body: {{role: content}}
    check:
      role: checksum
      type: u16
      algorithm: crc
      crc: {{name: CRC-16/MODBUS, width: 16, poly: 0x8005, init: 0xffff, refin: true, refout: true, xorout: 0,
             check: 0x4b37}}
      covers: [length, body]
commands:
  get:
    code: 3
    request: {{fields: {{channel: u8}}}}
    response: {{fields: {{channel: u8, value: i16}}}}
"""


def test_a_general_framing_tells_directions_by_header(tmp_path: Path) -> None:
    codec = generate(tmp_path, TOLD_BY_HEADER, "told_by_header")
    messages = sys.modules["told_by_header.messages"]
    request, response = messages.GetRequest(channel=2), messages.GetResponse(channel=2, value=-300)
    for message in (request, response):
        frame = codec.encode(message)
        assert codec.decode(frame) == message == codec.decode(frame, message.DIRECTION)
    with pytest.raises(DecodeError, match="neither a request nor a response header"):
        codec.decode(b"\x00" + codec.encode(request)[1:])
    with pytest.raises(ValueError, match="direction must be request or response"):
        codec.decode(codec.encode(request), "sideways")
