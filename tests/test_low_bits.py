"""An integer a few bits a byte (serialspec/encodings/low_bits.py): `encoding: nibbles` (Sony VISCA) and
`encoding: seven_bit` (Pololu, MIDI), unsigned and signed. The published values, a round trip of any value of every
size through the arithmetic, the generated Python's expressions and the construct adapter, and each spec mistake in
one line. Every output runs both in tests/test_language_matrix.py ("encoding: plain, seven_bit, nibbles"); VISCA's
positions in test_newuser_visca.py."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import examples, spec_error
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.encodings.low_bits import ENCODINGS, NIBBLES, SEVEN_BIT, LowBits
from test_varint import SPEC as VARINT_SPEC


def wire(encoding: LowBits, value: int, size: int, order: str) -> str:
    return encoding.spread(value, size).to_bytes(size, order).hex(" ")  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("encoding", "type_name", "order", "value", "sent"),
    [
        (NIBBLES, "u32", "big", 0x1234, "01 02 03 04"),  # VISCA CAM_Zoom Direct: 81 01 04 47 0p 0q 0r 0s FF
        (NIBBLES, "u32", "big", 0xFFFF, "0f 0f 0f 0f"),
        (NIBBLES, "i32", "big", -1, "0f 0f 0f 0f"),  # VISCA pan/tilt: a signed 16-bit position
        (NIBBLES, "i32", "big", -32768, "08 00 00 00"),
        (NIBBLES, "i32", "big", 32767, "07 0f 0f 0f"),
        (NIBBLES, "u16", "big", 0xAB, "0a 0b"),
        (NIBBLES, "u16", "little", 0xAB, "0b 0a"),
        (NIBBLES, "u8", "big", 15, "0f"),
        (NIBBLES, "i8", "big", -8, "08"),
        (SEVEN_BIT, "u16", "little", 6000, "70 2e"),  # Pololu Maestro's Set Target
        (SEVEN_BIT, "u16", "little", 8192, "00 40"),  # MIDI pitch bend's centre
        (SEVEN_BIT, "i16", "little", -1, "7f 7f"),
        (SEVEN_BIT, "i16", "big", -8192, "40 00"),
    ],
)
def test_published_values(encoding: LowBits, type_name: str, order: str, value: int, sent: str) -> None:
    size, signed = int(type_name[1:]) // 8, type_name[0] == "i"
    assert encoding.low(size, signed) <= value <= encoding.high(size, signed)
    assert wire(encoding, value, size, order) == sent
    raw = int.from_bytes(bytes.fromhex(sent), order)  # type: ignore[arg-type]
    assert raw & encoding.marks(size) == 0
    assert encoding.gather(raw, size, signed) == value
    assert eval(encoding.python_decode("raw", size, signed), {"raw": raw}) == value


def test_the_ranges() -> None:
    assert (NIBBLES.low(4, False), NIBBLES.high(4, False)) == (0, 0xFFFF)
    assert (NIBBLES.low(4, True), NIBBLES.high(4, True)) == (-32768, 32767)
    assert (NIBBLES.low(2, False), NIBBLES.high(2, False), NIBBLES.high(1, False)) == (0, 255, 15)
    assert (SEVEN_BIT.low(2, True), SEVEN_BIT.high(2, True), SEVEN_BIT.high(3, False)) == (-8192, 8191, 2097151)
    assert (NIBBLES.marks(2), SEVEN_BIT.marks(2)) == (0xF0F0, 0x8080)


@settings(max_examples=examples(60))
@given(st.sampled_from(sorted(ENCODINGS)), st.sampled_from([1, 2, 3, 4, 8]), st.booleans(), st.data())
def test_any_value_round_trips(name: str, size: int, signed: bool, data: st.DataObject) -> None:
    """spread/gather, the generated Python's expressions and the construct adapter agree, every byte below 2^bits."""
    from construct import BytesInteger

    encoding = ENCODINGS[name]
    value = data.draw(st.integers(encoding.low(size, signed), encoding.high(size, signed)))
    raw = encoding.spread(value, size)
    assert raw & encoding.marks(size) == 0 and raw.bit_length() <= 8 * size
    assert all(byte >> encoding.bits == 0 for byte in raw.to_bytes(size, "little"))
    assert encoding.gather(raw, size, signed) == value
    assert eval(encoding.python_encode("value", size), {"value": value}) == raw
    assert eval(encoding.python_decode("raw", size, signed), {"raw": raw}) == value
    adapter = getattr(__import__("serialspec.encodings.low_bits", fromlist=["x"]), encoding.construct_name)
    word = adapter(BytesInteger(size, signed=False, swapped=False), size, signed)
    assert word.build(value) == raw.to_bytes(size, "big")
    assert word.parse(raw.to_bytes(size, "big")) == value


def test_the_construct_adapter_refuses_what_decode_and_encode_refuse() -> None:
    from construct import Int32ub, ValidationError
    from serialspec.encodings.low_bits import Nibbles

    word = Nibbles(Int32ub, 4, signed=True)
    with pytest.raises(ValidationError, match="the high nibble of a byte is set"):
        word.parse(bytes.fromhex("01 12 03 04"))
    with pytest.raises(ValidationError, match=r"32768 is outside -32768\.\.32767"):
        word.build(32768)


# test_varint.py's frame (a length element, a sum), its field an integer of nibbles
SPEC = VARINT_SPEC.replace(
    "v: {type: i32, encoding: varint, varint: {sign: zigzag}}", "position: {type: u32, encoding: nibbles}"
)


@pytest.mark.parametrize(
    ("old", "new", "said"),
    [
        (
            "{type: u32, encoding: nibbles}",
            "{type: f32, encoding: nibbles}",
            "encoding nibbles is for integers, not f32",
        ),
        ("encoding: nibbles}", "encoding: nibbles, range: [0, 65536]}", "does not fit u32 nibbles (0..65535)"),
        ("u32, encoding: nibbles}", "i16, encoding: nibbles, range: [-129, 0]}", "fit i16 nibbles (-128..127)"),
        ("encoding: nibbles}", "encoding: nibbles, const: 3}", "`const` does not go with encoding nibbles (a numb"),
        ("encoding: nibbles}", "encoding: nibbles, bits: {a: 0}}", "`bits` does not go with encoding nibbles"),
        ("type: u32, encoding: nibbles", "type: u12, encoding: nibbles", "`encoding` does not go with a bit field"),
        (
            "        n: u8\n        position: {type: u32, encoding: nibbles}\n",
            "        n: {type: u16, encoding: nibbles}\n        v: {type: array, of: u8, count: n}\n",
            "'n' holds a count or size: plain, not encoding nibbles",
        ),
        ("{type: u32, encoding: nibbles}", "{type: string, size: 4, encoding: nibbles}", "a string takes only seven"),
    ],
)
def test_a_mistake_is_one_line(tmp_path: Path, old: str, new: str, said: str) -> None:
    assert old in SPEC
    assert said in spec_error(SPEC.replace(old, new), tmp_path)


def test_a_signed_field_holds_the_twos_complement_of_its_bits(tmp_path: Path) -> None:
    """An i16 of nibbles is an 8-bit signed value, an i16 of seven_bit a 14-bit one: the model's range says so."""
    from serialspec.lang import load_protocol
    from serialspec.lang.model import Scalar

    text = SPEC.replace("n: u8", "n: {type: i16, encoding: seven_bit}").replace(
        "type: u32, encoding: nib", "type: i16, encoding: nib"
    )
    (tmp_path / "spec.yaml").write_text(text, "utf-8")
    [message] = [m for m in load_protocol(str(tmp_path / "spec.yaml")).messages() if m.command == "go"]
    ranges = [(f.minimum, f.maximum) for f in message.fields if isinstance(f, Scalar)]
    assert ranges == [(-8192, 8191), (-128, 127)]
