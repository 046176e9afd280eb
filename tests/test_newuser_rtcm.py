"""RTCM 3 (tests/specs/rtcm3.yaml), written as a new user would from RTCM's own tables: a payload of integer data
fields of any width packed highest bit first (bit fields `u12`, `i38`: serialspec/encodings/bit_run.py), in a frame
of preamble D3, a 10-bit length after six reserved zero bits (read as one big-endian u16) and a CRC-24Q (a `u24`
checksum). Checked against pyrtcm: its frames decode to its values and encode back byte for byte, it parses the
frames we make, and hypothesis round trips random bit runs through the codec and construct's structs."""

from __future__ import annotations

import io
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from conftest import generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.backends.python import files as python_files
from serialspec.backends.python.memory import imported
from serialspec.lang import SpecErrors
from serialspec.lang.loader import load_text
from serialspec.lang.resolve import resolve
from serialspec.runtime.errors import DecodeError

pyrtcm = pytest.importorskip("pyrtcm")

SPEC = Path(__file__).parent / "specs" / "rtcm3.yaml"
# our field -> pyrtcm's data field, and the scale pyrtcm applies (its values are in metres)
NAMES = {
    "station_id": ("DF003", 1),
    "itrf_year": ("DF021", 1),
    "gps": ("DF022", 1),
    "glonass": ("DF023", 1),
    "galileo": ("DF024", 1),
    "reference_station": ("DF141", 1),
    "x": ("DF025", 0.0001),
    "oscillator": ("DF142", 1),
    "y": ("DF026", 0.0001),
    "quarter_cycle": ("DF364", 1),
    "z": ("DF027", 0.0001),
    "height": ("DF028", 0.0001),
}
RESERVED_BIT = 12 + 12 + 6 + 4 + 38 + 1  # DF001 of 1005/1006, counted from the payload's highest bit


@pytest.fixture(scope="module")
def rtcm(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("rtcm3"), "rtcm3")


def theirs(message: Any) -> dict[str, int]:
    """pyrtcm's values of a parsed 1005/1006, in our fields' wire units."""
    found = {}
    for ours, (df, scale) in NAMES.items():
        if hasattr(message, df):
            found[ours] = round(getattr(message, df) / scale)
    return found


def payload(number: int, size: int, bits: int) -> bytes:
    """A payload of `size` bytes whose first 12 bits are `number`, its reserved bit 0 and the rest from `bits`."""
    rest = size * 8 - 12
    whole = (number << rest) | (bits & ((1 << rest) - 1))
    whole &= ~(1 << (size * 8 - 1 - RESERVED_BIT))
    return whole.to_bytes(size, "big")


def test_the_standard_s_1005_example(rtcm: ModuleType) -> None:
    """RTCM 10403's message 1005 example: pyrtcm and we read the same station; we write the same bytes."""
    frame = bytes.fromhex("D3 00 13 3E D7 D3 02 02 98 0E DE EF 34 B4 BD 62 AC 09 41 98 6F 33 36 0B 98")
    ours = rtcm.decode(frame, "request")
    parsed = pyrtcm.RTCMReader.parse(frame)
    assert parsed.identity == "1005" and ours.to_fields() == theirs(parsed)
    assert ours.x == 11141045999 and ours.station_id == 2003
    assert rtcm.encode(ours) == frame


def test_a_reserved_bit_set_before_the_length_is_no_frame(rtcm: ModuleType) -> None:
    """The 6 bits before the 10-bit length must be 0 (the length's `range: [0, 1023]`): decode refuses a frame with
    one set in one line, and the stream parser looks past it to the frame after it, whatever the reads."""
    frame = bytes.fromhex("D3 00 13 3E D7 D3 02 02 98 0E DE EF 34 B4 BD 62 AC 09 41 98 6F 33 36 0B 98")
    bad = frame[:1] + bytes([frame[1] | 0x04]) + frame[2:]
    with pytest.raises(DecodeError) as refused:
        rtcm.decode(bad, "request")
    assert str(refused.value) == "length = 1043 is outside its range 0..1023"
    stream = bad[:3] + frame
    for split in range(len(stream) + 1):
        parser = rtcm.StreamParser(rtcm.Direction.REQUEST)
        assert [m.station_id for m in parser.feed(stream[:split]) + parser.feed(stream[split:])] == [2003]


@settings(max_examples=25, deadline=None)
@given(st.sampled_from([(1005, 19), (1006, 21)]), st.integers(0, (1 << 168) - 1))
def test_pyrtcm_frames_decode_to_its_values_and_encode_back(rtcm: ModuleType, kind: tuple[int, int], bits: int) -> None:
    number, size = kind
    frame = pyrtcm.RTCMMessage(payload=payload(number, size, bits)).serialize()  # pyrtcm's header, length and CRC
    parsed = pyrtcm.RTCMReader.parse(frame)
    ours = rtcm.decode(frame, "request")
    assert type(ours).__name__ == ("StationRequest" if number == 1005 else "StationHeightRequest")
    assert ours.to_fields() == theirs(parsed)
    assert rtcm.encode(ours) == frame


def ours_strategy(height: bool) -> st.SearchStrategy[dict[str, Any]]:
    ecef = st.integers(-(1 << 37), (1 << 37) - 1)
    fields: dict[str, st.SearchStrategy[int]] = {
        "station_id": st.integers(0, 4095),
        "itrf_year": st.integers(0, 63),
        "gps": st.integers(0, 1),
        "glonass": st.integers(0, 1),
        "galileo": st.integers(0, 1),
        "reference_station": st.integers(0, 1),
        "x": ecef,
        "oscillator": st.integers(0, 1),
        "y": ecef,
        "quarter_cycle": st.integers(0, 3),
        "z": ecef,
    }
    if height:
        fields["height"] = st.integers(0, 0xFFFF)
    return st.fixed_dictionaries(fields)


@settings(max_examples=25, deadline=None)
@given(st.booleans().flatmap(lambda h: st.tuples(st.just(h), ours_strategy(h))))
def test_pyrtcm_parses_the_frames_we_make(rtcm: ModuleType, drawn: tuple[bool, dict[str, Any]]) -> None:
    height, fields = drawn
    cls = rtcm.StationHeightRequest if height else rtcm.StationRequest
    frame = rtcm.encode(cls.from_fields(fields))
    parsed = pyrtcm.RTCMReader.parse(frame)  # checks the CRC
    assert parsed.identity == ("1006" if height else "1005")
    assert theirs(parsed) == fields


def test_pyrtcm_reads_a_stream_of_our_frames_and_we_read_its(rtcm: ModuleType) -> None:
    """A stream of frames both ways: pyrtcm's reader over our frames, our stream parser over the same bytes fed
    a few at a time, with garbage and a frame whose CRC is broken between them."""
    messages = []
    for n in range(1, 7):
        fields = {**dict.fromkeys(NAMES, n % 2), "station_id": n, "x": -n * 1000}
        if n % 2:
            del fields["height"]
        messages.append((rtcm.StationRequest if n % 2 else rtcm.StationHeightRequest).from_fields(fields))
    frames = [rtcm.encode(m) for m in messages]
    stream = b"".join(frames)
    read = [parsed for _, parsed in pyrtcm.RTCMReader(io.BytesIO(stream))]
    assert [int(p.DF003) for p in read] == list(range(1, 7))
    bad = bytearray(frames[0])
    bad[-1] ^= 0x55
    noisy = b"\xd3\x00" + frames[0] + bytes(bad) + b"\x00\xd3\x03\xff" + stream
    parser = rtcm.StreamParser(rtcm.Direction.REQUEST)
    got = []
    for at in range(0, len(noisy), 5):
        got += parser.feed(noisy[at : at + 5])
    assert [m.station_id for m in got] == [1, *range(1, 7)]


def bit_run_spec(widths: list[tuple[str, int]]) -> str:
    fields = "\n".join(
        f"        f{i}: {{type: {'i' if signed else 'u'}{bits}}}" for i, (signed, bits) in enumerate(widths)
    )
    return f"""protocol: bitrun
title: Bit runs
byte_order: little
serial: {{baudrate: 9600}}
framing:
  elements:
    header: {{role: header, value: "AA"}}
    code: {{role: command, type: u8}}
    length: {{role: length, type: u8}}
    content: {{role: content}}
    checksum: {{role: checksum, type: u8, algorithm: sum, covers: [length, content]}}
commands:
  probe:
    code: 1
    request:
      fields:
{fields}
"""


@st.composite
def runs(draw: st.DrawFn) -> list[tuple[bool, int]]:
    """Widths of 1..64 bits, with a last one that makes the run whole bytes. A byte-sized integer (u8, i16, ...) only
    inside an open run, which it joins: elsewhere it is a plain field in the protocol's byte order."""
    widths: list[tuple[bool, int]] = []
    for signed, bits in draw(st.lists(st.tuples(st.booleans(), st.integers(1, 64)), min_size=1, max_size=6)):
        if bits in (8, 16, 24, 32, 64) and sum(b for _, b in widths) % 8 == 0:
            bits -= 1
        widths.append((signed, bits))
    short = -sum(b for _, b in widths) % 8
    return widths + [(False, short)] if short else widths


@settings(max_examples=8, deadline=None)
@given(runs(), st.data())
def test_random_bit_runs_round_trip_and_match_a_plain_packer(
    widths: list[tuple[bool, int]], data: st.DataObject
) -> None:
    """Any widths: the codec writes each value's bits highest first with no gaps (as a plain packer does), reads them
    back, and construct's structs read and build the same bytes."""
    protocol = resolve(load_text(bit_run_spec(widths), "bitrun.yaml"))
    modules = {path.split("/", 1)[1]: code for path, code in python_files(protocol).items()}
    values = {
        f"f{i}": data.draw(st.integers(-(1 << (b - 1)), (1 << (b - 1)) - 1) if signed else st.integers(0, (1 << b) - 1))
        for i, (signed, b) in enumerate(widths)
    }
    whole = 0
    for i, (_, b) in enumerate(widths):
        whole = (whole << b) | (values[f"f{i}"] & ((1 << b) - 1))
    content = whole.to_bytes(sum(b for _, b in widths) // 8, "big")
    with imported("bitrun", modules, "a bit-run case") as package:
        import importlib

        frame = package.encode(package.ProbeRequest.from_fields(values))
        assert frame[3 : 3 + len(content)] == content
        assert package.decode(frame, "request").to_fields() == values
        structs = importlib.import_module("bitrun.structs")
        struct = structs.CONTENTS[("probe", "request")]
        assert {k: v for k, v in struct.parse(content).items() if k in values} == values
        assert struct.build(values) == content


def test_a_run_short_of_a_byte_is_one_spec_error() -> None:
    text = bit_run_spec([(False, 12), (True, 38)])  # 50 bits
    with pytest.raises(SpecErrors) as failure:
        resolve(load_text(text, "bitrun.yaml"))
    assert str(failure.value).splitlines() == [
        "bitrun.yaml:17:13: commands.probe.request.fields.f0: bit run f0: 50 bits at the end of the content, not a "
        "whole number of bytes (add fields or reserved bits to fill 56)"
    ]


DESCRIPTOR = bytes.fromhex(
    "D3 00 42 40 97 D3 14 54 52 4D 35 39 38 30 30 2E 30 30 20 20 20 20 20 53 43 49 53 00 0A 35 30 30 30 31 31 38 34"
    "37 30 0D 54 52 49 4D 42 4C 45 20 4E 45 54 52 39 04 34 2E 38 35 0A 35 30 33 35 4B 36 39 37 34 39 12 D8 B8"
)
# ours -> pyrtcm's counted character group of a 1033
STRINGS = {
    "antenna": "DF030",
    "antenna_serial": "DF033",
    "receiver": "DF228",
    "firmware": "DF230",
    "receiver_serial": "DF232",
}


def their_descriptor(message: Any) -> dict[str, Any]:
    """pyrtcm's values of a parsed 1033, as our fields."""
    found: dict[str, Any] = {"station_id": message.DF003, "setup_id": message.DF031}
    for ours, df in STRINGS.items():
        found[ours] = "".join(
            getattr(message, name) for name in sorted(n for n in vars(message) if n.startswith(df + "_"))
        )
    return found


def test_the_descriptor_is_picked_by_its_message_number(rtcm: ModuleType) -> None:
    """1033's counted strings give it sizes that 1005 (19 bytes) and 1006 (21) also have: the message number (the
    leading constant u12 of each) picks it. A 1033 of 19 bytes decodes as a 1033, alone and in a stream."""
    ours = rtcm.decode(DESCRIPTOR, "request")
    assert ours.to_fields() == their_descriptor(pyrtcm.RTCMReader.parse(DESCRIPTOR))
    assert rtcm.encode(ours) == DESCRIPTOR
    short = rtcm.DescriptorRequest.from_fields(
        {
            "station_id": 1,
            "antenna": "ANTEN",
            "setup_id": 2,
            "antenna_serial": "",
            "receiver": "RX",
            "firmware": "1",
            "receiver_serial": "S1",
        }
    )
    frame = rtcm.encode(short)
    assert len(frame) - 6 == 19  # the size of a 1005
    assert pyrtcm.RTCMReader.parse(frame).identity == "1033"
    assert rtcm.decode(frame, "request") == short
    station = rtcm.decode(
        bytes.fromhex("D3 00 13 3E D7 D3 02 02 98 0E DE EF 34 B4 BD 62 AC 09 41 98 6F 33 36 0B 98"), "request"
    )
    stream = frame + rtcm.encode(station) + DESCRIPTOR
    for split in (1, 20, 30, len(stream) - 2):
        parser = rtcm.StreamParser(rtcm.Direction.REQUEST)
        got = parser.feed(stream[:split]) + parser.feed(stream[split:])
        assert [type(m).__name__ for m in got] == ["DescriptorRequest", "StationRequest", "DescriptorRequest"]


def test_an_unknown_message_number_is_one_line(rtcm: ModuleType) -> None:
    frame = pyrtcm.RTCMMessage(payload=payload(1004, 19, 0)).serialize()
    with pytest.raises(DecodeError) as refused:
        rtcm.decode(frame, "request")
    assert str(refused.value) == (
        "request without a code: unknown message_number 1004 (known: station: 1005, station_height: 1006, "
        "descriptor: 1033)"
    )


@pytest.mark.parametrize(
    ("first", "why"),
    [
        ("{type: u12, const: 1005}", "both begin with message_number = 1005, which cannot pick one"),
        (
            "{type: u12}",
            "a leading constant picks a message only where every one of them begins with a constant integer field of "
            "the same width, no two equal",
        ),
    ],
)
def test_a_message_number_that_cannot_pick_is_one_error(first: str, why: str) -> None:
    """Where 1033's first field is no constant, or 1005's, the sizes must tell the messages apart and cannot."""
    text = SPEC.read_text(encoding="utf-8").split("\nexamples:")[0]
    text = text.replace("message_number: {type: u12, const: 1033, description: DF002.}", f"message_number: {first}")
    with pytest.raises(SpecErrors) as failure:
        resolve(load_text(text, "rtcm3.yaml"))
    assert str(failure.value).splitlines() == [
        "rtcm3.yaml:68:5: commands.descriptor: 'station' also sends requests without a code, and a content of 19 "
        "bytes fits both (requests without a code are told apart by their content size: 19 bytes and 9..1284 bytes; "
        f"{why})"
    ]


text = st.text(st.characters(min_codepoint=32, max_codepoint=126), max_size=40)


@settings(max_examples=15, deadline=None)
@given(
    st.fixed_dictionaries(
        {"station_id": st.integers(0, 4095), "setup_id": st.integers(0, 255), **dict.fromkeys(STRINGS, text)}
    )
)
def test_pyrtcm_reads_the_descriptors_we_make(rtcm: ModuleType, fields: dict[str, Any]) -> None:
    frame = rtcm.encode(rtcm.DescriptorRequest.from_fields(fields))
    assert their_descriptor(pyrtcm.RTCMReader.parse(frame)) == fields
    assert rtcm.decode(frame, "request").to_fields() == fields


def test_the_c_and_the_dissector_read_rtcm(tmp_path: Path) -> None:
    """The C (strict flags) decodes the example to its values and encodes it back (its check_vectors program);
    tshark shows a random message of each kind as `decode` does (tests/test_wireshark.py's helper)."""
    from test_c_backend import GCC, check_vectors
    from test_wireshark import TSHARK, through_tshark

    if GCC is not None:
        assert check_vectors(SPEC, "rtcm3", tmp_path) == "rtcm3: 2 vectors, 0 refused frames, 0 failed\n"
    if TSHARK is not None:
        through_tshark(tmp_path, [SPEC.read_text(encoding="utf-8")], corrupt=True)
