"""`encoding: varint` (serialspec/encodings/varint.py): the families' published values, a round trip of any value in
every form (and construct's own VarInt and ZigZag agreeing where they apply), and each mistake in one line. Every
output runs it in tests/test_language_matrix.py ("encoding: varint"); Kangaroo's form in test_newuser_kangaroo.py."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import examples, spec_error
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.encodings import varint


def sent(value: int, bits: int = 7, sign: str = "", high_first: bool = False) -> bytes:
    return varint.write(varint.wire(value, sign), bits, high_first)


def read(data: bytes, bits: int = 7, sign: str = "", high_first: bool = False, most: int = 10) -> int:
    number, stop = varint.read(data, 0, len(data), bits, high_first, most)
    assert stop == len(data)
    return varint.value_of(number, sign)


@pytest.mark.parametrize(
    ("value", "form", "wire"),
    [
        (300, {}, "ac 02"),  # protobuf's encoding guide
        (624485, {}, "e5 8e 26"),  # LEB128 (DWARF)
        (0, {}, "00"),
        (-1, {"sign": "zigzag"}, "01"),  # protobuf sint32: 0, -1, 1, -2 as 0, 1, 2, 3
        (1, {"sign": "zigzag"}, "02"),
        (-2147483648, {"sign": "zigzag"}, "ff ff ff ff 0f"),
        (0x3FFF, {"high_first": True}, "ff 7f"),  # MIDI variable-length quantities (SMF 1.0)
        (0x200000, {"high_first": True}, "81 80 80 00"),
        (0x0FFFFFFF, {"high_first": True}, "ff ff ff 7f"),
        (1000, {"bits": 6, "sign": "low_bit"}, "50 1f"),  # Dimension Engineering Kangaroo (KangarooCommandWriter)
        (-1, {"bits": 6, "sign": "low_bit"}, "03"),
    ],
)
def test_the_families_published_values(value: int, form: dict[str, object], wire: str) -> None:
    assert sent(value, **form).hex(" ") == wire  # type: ignore[arg-type]
    assert read(bytes.fromhex(wire), **form) == value  # type: ignore[arg-type]


@settings(max_examples=examples(60))
@given(
    st.integers(1, 7),
    st.sampled_from(["", *varint.SIGNS]),
    st.booleans(),
    st.integers(-(2**63), 2**64 - 1),
)
def test_any_value_round_trips_in_every_form(bits: int, sign: str, high_first: bool, value: int) -> None:
    value = abs(value) if not sign else max(value, -(2**63))
    value = min(value, 2**63 - 1) if sign else value
    data = sent(value, bits, sign, high_first)
    most = varint.most_bytes(-(2**63) if sign else 0, 2**63 - 1 if sign else 2**64 - 1, bits, sign)
    assert len(data) <= most
    assert all(byte >> bits == (i < len(data) - 1) for i, byte in enumerate(data))  # continuation bits
    assert read(data, bits, sign, high_first, most) == value
    if bits == 7 and not high_first and sign != "low_bit":  # construct's own VarInt and ZigZag agree
        from construct import VarInt, ZigZag

        assert (ZigZag if sign else VarInt).build(value) == data


@pytest.mark.parametrize(
    ("data", "reason"),
    [
        (b"\x80\x80", "ends before its last byte"),
        (b"\x80" * 5, "more than 5 bytes"),
        (b"\x81", "bits above bit 6"),
    ],
)
def test_a_bad_varint_says_why(data: bytes, reason: str) -> None:
    bits = 6 if reason.startswith("bits") else 7
    with pytest.raises(ValueError, match=reason):
        varint.read(data, 0, len(data), bits, False, 5)


SPEC = """protocol: v
title: V
serial: {baudrate: 9600}
byte_order: little
framing:
  elements:
    header: {role: header, value: "AA"}
    code: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: sum, covers: [code, content]}
commands:
  go:
    code: 1
    request:
      fields:
        n: u8
        v: {type: i32, encoding: varint, varint: {sign: zigzag}}
"""


@pytest.mark.parametrize(
    ("old", "new", "said"),
    [
        ("{type: i32, encoding: varint, varint: {sign: zigzag}}", "{type: i32, encoding: varint}", "needs `varint: "),
        ("type: i32, encoding: varint,", "type: u32, encoding: varint,", "`sign: zigzag` goes with a signed type"),
        ("{type: i32, encoding: varint, varint: {sign: zigzag}}", "{type: f32, encoding: varint}", "not f32"),
        ("{sign: zigzag}", "{sign: zigzag, bits: 8}", "8 is outside 1..7"),
        ("{sign: zigzag}", "{sign: twos}", "expected one of zigzag, low_bit"),
        ("encoding: varint, ", "", "`varint` goes with `encoding: varint`"),
        ("{sign: zigzag}}", "{sign: zigzag}, scale: 0.1}", "`scale` does not go with encoding varint"),
        ("{sign: zigzag}}", "{sign: zigzag}, range: [0, 3000000000]}", "does not fit i32"),
        ("zigzag}}\n", 'zigzag}}\n        i: {type: array, of: u8, count: "v % 4"}\n', "'v' in 'v % 4' is a varint"),
        ("zigzag}}\n", 'zigzag}}\n        d: {type: u8, value: "v + 1"}\n', "v is a varint: a `value:` names"),
        ("    length: {role: length, type: u8}\n", "", "a varint cannot size a frame that has no length element"),
    ],
)
def test_a_mistake_is_one_line(tmp_path: Path, old: str, new: str, said: str) -> None:
    assert old in SPEC
    assert said in spec_error(SPEC.replace(old, new), tmp_path)
