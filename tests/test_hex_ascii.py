"""The hex-ASCII span encoding (`method: hex_ascii`, Modbus ASCII), checked against minimalmodbus's own hex helpers;
Modbus ASCII frames of the shipped package decoded in either case, and found in noisy streams however they are split
(stray ':' and hex digits before a frame, cut frames), exactly as a reader that knows nothing but decode() finds
them."""

from __future__ import annotations

import importlib
from contextlib import suppress
from typing import Any

import minimalmodbus
import pytest
from conftest import ROOT, SHIPPED, examples
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.lang import load_protocol
from serialspec.runtime.errors import DecodeError
from serialspec.transforms.hexascii import HexAscii

SPAN = HexAscii((1, 4))


@given(st.binary(max_size=300))
@settings(max_examples=200, deadline=None)
def test_encode_is_minimalmodbus_hexencode_and_decode_reverses_it(data: bytes) -> None:
    wire = SPAN.encode(data)
    assert wire == minimalmodbus._hexencode(data)
    assert len(wire) == 2 * len(data)
    assert SPAN.decode(wire) == data
    assert SPAN.decode(wire.lower()) == data  # a receiver accepts either case


def test_read_holding_registers_request_of_the_modbus_guide() -> None:
    """MODBUS over Serial Line §2.5.2: unit 1, function 3, address 0, 1 register, LRC FB."""
    assert SPAN.encode(bytes.fromhex("01 03 00 00 00 01 FB")) == b"010300000001FB"


@pytest.mark.parametrize(
    ("wire", "reason"),
    [
        (b"0G", "hex-ASCII: byte 47 at 1 is not a hex digit"),
        (b":01", "hex-ASCII: byte 3A at 0 is not a hex digit"),
        (b"010", "hex-ASCII: 3 hex digits, not whole bytes (an odd count)"),
        (b"01\r\n", "hex-ASCII: byte 0D at 2 is not a hex digit"),
    ],
)
def test_bad_spans_get_one_line_reasons(wire: bytes, reason: str) -> None:
    with pytest.raises(DecodeError) as error:
        SPAN.decode(wire)
    assert str(error.value) == reason


# --- Modbus ASCII frames in a stream: the generated package of specs/modbus_ascii.yaml ------------------------------

FRAME = b":010300000001FB\r\n"  # MODBUS over Serial Line §2.5.2: read 1 holding register from address 0 of unit 1


EXAMPLES = load_protocol(str(ROOT / "specs" / "modbus_ascii.yaml"), "specs/modbus_ascii.yaml").examples


def modbus_ascii() -> Any:
    return importlib.import_module(f"{SHIPPED}.modbus_ascii")


def test_a_frame_decodes_in_either_case_and_encodes_in_upper_case() -> None:
    m = modbus_ascii()
    request = m.decode(FRAME, "request")
    assert request == m.ReadHoldingRegistersRequest(unit=1, address=0, count=1)
    assert m.decode(FRAME.lower(), "request") == request
    assert m.encode(request) == FRAME


@pytest.mark.parametrize(
    ("frame", "reason"),
    [
        (b":010300000001FC\r\n", "bad lrc: the frame has 0xfc, its bytes give 0xfb"),
        (b":010300000001F\r\n", "hex-ASCII: 13 hex digits, not whole bytes (an odd count)"),
        (b":0103000G0001FB\r\n", "hex-ASCII: byte 47 at 7 is not a hex digit"),
    ],
)
def test_bad_frames_get_one_line_reasons(frame: bytes, reason: str) -> None:
    with pytest.raises(DecodeError) as error:
        modbus_ascii().decode(frame, "request")
    assert str(error.value) == reason


# What a line can carry before a frame: a stray ':' or hex digits, a frame cut anywhere, its colon doubled, a CR LF
STRAYS = [b":", b"::", b"0", b"F", b":0", b":01", b"0:", b"\r\n", b":\r", b"\r", *(FRAME[:k] for k in range(1, 17))]


@pytest.mark.parametrize("stray", STRAYS)
def test_no_stray_before_a_frame_loses_it_in_one_read_or_byte_by_byte(stray: bytes) -> None:
    m = modbus_ascii()
    expected = m.decode(FRAME, "request")
    stream = stray + FRAME + b"x" + FRAME
    assert m.StreamParser("request").feed(stream) == [expected, expected]
    parser = m.StreamParser("request")
    assert [message for byte in stream for message in parser.feed(bytes([byte]))] == [expected, expected]


@st.composite
def noisy_streams(draw: st.DrawFn) -> tuple[bytes, list[int]]:
    """Frames of the package's examples between noise made of the frames' own characters, and cuts to read it by."""
    frames = [e.frame for e in EXAMPLES if e.direction.value == "request"]
    alphabet = st.sampled_from([b":", b"0", b"1", b"A", b"f", b"\r", b"\n", b"G", b" "])
    parts = draw(st.lists(st.one_of(st.sampled_from(frames), alphabet), max_size=30))
    stream = b"".join(parts)
    cuts = sorted(draw(st.lists(st.integers(0, len(stream)), max_size=10)))
    return stream, cuts


@given(noisy_streams())
@settings(max_examples=examples(300), deadline=None)
def test_any_split_gives_the_byte_by_byte_frames(case: tuple[bytes, list[int]]) -> None:
    stream, cuts = case
    m = modbus_ascii()
    trickle = m.StreamParser("request")
    byte_by_byte = [message for byte in stream for message in trickle.feed(bytes([byte]))]
    parser = m.StreamParser("request")
    pieces = [stream[a:b] for a, b in zip([0, *cuts], [*cuts, len(stream)], strict=True)]
    assert [message for piece in pieces for message in parser.feed(piece)] == byte_by_byte
    assert (parser.errors, parser.garbage, parser.pending()) == (trickle.errors, trickle.garbage, trickle.pending())
    # and the frames are those a reader that knows nothing but decode() finds: every frame whose ':' is the last
    # one before its CR LF and that decodes
    found = []
    for end in range(len(stream)):
        if stream.startswith(b"\r\n", end):
            start = stream.rfind(b":", 0, end)
            if start >= 0:
                with suppress(DecodeError):
                    found.append(m.decode(stream[start : end + 2], "request"))
    assert byte_by_byte == found
