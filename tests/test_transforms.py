"""The frame transform registry (serialspec/transforms/): each transform's runtime against known vectors and its own
inverse, the stream parser's reading through a transform (plain_prefix) against decode, golden frames of real
protocols, and the spec mistakes each transform names. Every sample also goes through every output in
tests/test_language_matrix.py (and through tshark in tests/test_wireshark.py)."""

from __future__ import annotations

import ast
import importlib
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pytest
import yaml
from conftest import examples
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.lang import SpecErrors, load_protocol
from serialspec.runtime.errors import DecodeError
from serialspec.transforms import transforms
from serialspec.transforms.cobs import CobsSpan, cobs_decode, cobs_encode
from serialspec.transforms.replace import Transparency
from test_framing_specs import generate

SETTINGS = settings(max_examples=examples(200), deadline=None)
XBEE = Transparency(
    (0, 0), ((b"\x7e", b"\x7d\x5e"), (b"\x7d", b"\x7d\x5d"), (b"\x11", b"\x7d\x31"), (b"\x13", b"\x7d\x33"))
)
SLIP = Transparency((0, 0), ((b"\xc0", b"\xdb\xdc"), (b"\xdb", b"\xdb\xdd")))
DYNAMIXEL = Transparency((0, 0), ((b"\xff\xff\xfd", b"\xff\xff\xfd\xfd"),))


def test_every_transform_documents_its_options() -> None:
    for name, transform in transforms().items():
        assert transform.samples, name
        for sample in transform.samples:
            assert sample.framing["transparency"].get("method", "replace") == name
            assert sample.plain, sample.label
            assert transform.worked_sample(sample).startswith("For example, ")


@pytest.mark.parametrize(
    ("plain", "wire"),
    [
        (b"", b"\x01"),
        (b"\x00", b"\x01\x01"),
        (b"\x00\x00", b"\x01\x01\x01"),
        (b"\x11\x22\x00\x33", b"\x03\x11\x22\x02\x33"),
        (b"\x11\x22\x33\x44", b"\x05\x11\x22\x33\x44"),
        (b"\x11\x00\x00\x00", b"\x02\x11\x01\x01\x01"),
        (bytes(range(1, 255)), b"\xff" + bytes(range(1, 255)) + b"\x01"),  # PacketSerial's COBS.h: the 01 after
        (bytes(range(0, 255)), b"\x01\xff" + bytes(range(1, 255)) + b"\x01"),
    ],
)
def test_cobs_vectors(plain: bytes, wire: bytes) -> None:
    assert cobs_encode(plain) == wire
    assert cobs_decode(wire) == plain


def test_cobs_refuses_what_is_no_cobs_form() -> None:
    assert cobs_decode(b"\xff" + bytes(range(1, 255))) == bytes(range(1, 255))  # a full last run without its 01
    for bad in (b"", b"\x05\x01", b"\x02\x00", b"\x03\x01\x00"):
        with pytest.raises(DecodeError, match="bad COBS"):
            cobs_decode(bad)


@SETTINGS
@given(st.binary(max_size=700).map(lambda b: bytes(x if x > 60 else 0 for x in b)) | st.binary(max_size=600))
def test_cobs_round_trip_and_its_plain_prefix(plain: bytes) -> None:
    wire = cobs_encode(plain)
    assert 0 not in wire and len(wire) <= len(plain) + len(plain) // 254 + 1
    assert cobs_decode(wire) == plain
    span = CobsSpan((0, 0))
    buffer = b"\x55" + wire + b"\x00\x12\x34"
    for count in {0, 1, len(plain) // 3, len(plain)}:
        found = span.plain_prefix(buffer, 1, len(buffer), count)
        assert found is not None and found[0] == plain[:count]
    assert span.plain_prefix(buffer, 1, len(buffer), len(plain) + 3) == (plain, len(wire))  # the delimiter ends it
    # all of the span's plain bytes come from all of its bytes (a span ending in 00 ends with that 00's code byte and
    # the code byte 01 after it: the stream parser sized such a frame one byte short and never found it)
    assert not plain or span.plain_prefix(buffer, 1, len(buffer), len(plain)) == (plain, len(wire))
    for cut in range(1, len(wire), max(1, len(wire) // 7)):  # a buffer that ends early: wait, or what it gives
        found = span.plain_prefix(buffer, 1, 1 + cut, len(plain))
        assert found is None or found[0] == plain[: len(found[0])]


@SETTINGS
@given(st.sampled_from([XBEE, SLIP, DYNAMIXEL]), st.lists(st.sampled_from(b"\x7e\x7d\x11\x13\xc0\xdb\xff\xfd\x00\x42")))
def test_substitution_plain_prefix_agrees_with_decode(stuffing: Transparency, values: list[int]) -> None:
    plain = bytes(values)
    wire = stuffing.encode(plain)
    assert stuffing.decode(wire) == plain
    buffer = wire + b"\x42"  # a byte after the span that starts no wire sequence
    for count in range(len(plain) + 1):
        found = stuffing.plain_prefix(buffer, 0, len(buffer), count)
        assert found is not None and found[0] == plain[:count]
        assert stuffing.decode(wire[: found[1]]) == plain[:count]
    for cut in range(len(wire)):
        assert stuffing.plain_prefix(buffer, 0, cut, len(plain)) is None  # the buffer ends first: wait for more


def spec_text(framing: Mapping[str, Any], byte_order: str = "big", code: int = 0x17) -> str:
    """A small spec with `framing` and one command (Digi's remote AT command), for generate() ({name} left in)."""
    fields = {
        "frame": "u8",
        "address": {"type": "bytes", "size": 8},
        "network": "u16",
        "options": "u8",
        "command": {"type": "bytes", "size": 2},
    }
    spec = {
        "protocol": "NAME",
        "title": "Transform test",
        "description": "A frame transform.",
        "serial": {"baudrate": 9600},
        "byte_order": byte_order,
        "framing": framing,
        "commands": {"remote_at": {"code": code, "request": {"fields": fields}}},
    }
    text = yaml.safe_dump(spec, sort_keys=False)
    return text.replace("{", "{{").replace("}", "}}").replace("NAME", "{name}")


def refused(tmp_path: Path, framing: Mapping[str, Any], message: str) -> None:
    spec = tmp_path / "bad.yaml"
    spec.write_text(spec_text(framing).format(name="bad"), encoding="utf-8")
    with pytest.raises(SpecErrors) as error:
        load_protocol(str(spec))
    assert message in str(error.value)


def test_xbee_api_mode_2_golden_frame(tmp_path: Path) -> None:
    """Digi's remote AT command example (XBee API frame 0x17, NI), escaped as API mode 2 sends it: the length and
    checksum count and sum the plain bytes; 13 in the address is sent as 7D 33."""
    m = generate(tmp_path, spec_text(transforms()["replace"].samples[0].framing), "xbee_like")
    message = m.RemoteAtRequest(
        frame=1, address=bytes.fromhex("0013A20040AD142E"), network=0xFFFE, options=2, command=b"NI"
    )
    frame = m.encode(message)
    assert frame == bytes.fromhex("7E 00 0F 17 01 00 7D 33 A2 00 40 AD 14 2E FF FE 02 4E 49 6D")
    assert m.decode(frame, "request") == message
    parser = m.StreamParser("request")
    stream = b"\x00\x7d\x13" + frame + frame[:7] + frame  # noise, a frame, a frame cut short, a frame
    assert [x for byte in stream for x in parser.feed(bytes([byte]))] == [message, message]
    with pytest.raises(DecodeError):
        m.decode(frame.replace(b"\x7d\x33", b"\x13"), "request")  # an unescaped 13: not the escaped form


def test_cobs_packet_serial_frame(tmp_path: Path) -> None:
    """A PacketSerial packet: the COBS form of the whole packet, then 00."""
    m = generate(tmp_path, spec_text(transforms()["cobs"].samples[0].framing, "little", 0), "packet_like")
    message = m.RemoteAtRequest(
        frame=0, address=bytes.fromhex("0012000000000000"), network=0, options=0, command=b"\x00A"
    )
    frame = m.encode(message)
    assert frame[-1] == 0 and 0 not in frame[:-1]
    plain = cobs_decode(frame[:-1])
    assert plain[:14] == bytes.fromhex("00 00 00 12 00 00 00 00 00 00 00 00 00 00")
    assert m.decode(frame, "request") == message
    parser = m.StreamParser("request")
    stream = b"\x05\x01\x00" + frame + frame  # noise ended by a delimiter, then two packets
    assert [x for byte in stream for x in parser.feed(bytes([byte]))] == [message, message]


MISTAKES = [
    (
        {"method": "cobs", "span": ["code", "content"]},
        "COBS needs the delimiter right after its span: a trailer with `value: '00'`",
    ),
    (
        {"method": "cobs", "span": ["code", "content"], "replace": {"C0": "DB DC"}},
        "`replace` belongs to `method: replace`",
    ),
    ({"span": ["code", "content"]}, "give plain -> wire byte sequences"),
    ({"method": "base64", "span": ["code", "content"]}, "base64"),
]


@pytest.mark.parametrize(("transparency", "message"), MISTAKES)
def test_transform_mistakes_are_named(tmp_path: Path, transparency: dict[str, object], message: str) -> None:
    framing = {
        "elements": {
            "start": {"role": "header", "value": "AA"},
            "code": {"role": "command", "type": "u8"},
            "content": {"role": "content"},
            "end": {"role": "trailer", "value": "0D"},
        },
        "transparency": transparency,
    }
    refused(tmp_path, framing, message)


def test_a_length_inside_the_span_counts_inside_it(tmp_path: Path) -> None:
    framing = json.loads(json.dumps(transforms()["replace"].samples[0].framing))
    framing["elements"]["length"]["counts"] = ["code", "checksum"]
    framing["transparency"]["span"] = ["length", "content"]
    refused(tmp_path, framing, "a length inside the transparency span counts elements inside it")


def test_the_runtime_classes_load_from_runtime_framing() -> None:
    framing = importlib.import_module("serialspec.runtime.framing")
    for transform in transforms().values():
        assert getattr(framing, transform.runtime_name).__module__ == transform.__module__


def test_the_registry_imports_nothing_of_the_generator() -> None:
    """The runtime wheel ships the package (packaging/runtime): its modules import the standard library, the runtime,
    the checksum registry's plain data and each other only."""
    folder = Path(importlib.import_module("serialspec.transforms").__file__ or "").parent
    allowed = ("serialspec.transforms", "serialspec.runtime", "serialspec.checksums")
    for path in sorted(folder.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
            names += [node.module or ""] if isinstance(node, ast.ImportFrom) else []
            for name in names:
                assert name.split(".")[0] != "serialspec" or name.startswith(allowed), (path.name, name)
