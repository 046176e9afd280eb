"""Fields named after Python keywords (`class`, `from`, `in`, ...): generated Python calls the attribute `class_`,
everything facing the spec's reader (JSON, decode --json, the reference, error lines) keeps `class`; and bit-field
and group classes are named per message, so two commands may each have a `flags` field of their own."""

from __future__ import annotations

import contextlib
import importlib
import inspect
import io
import json
from pathlib import Path
from types import ModuleType

import pytest
from conftest import generate_and_import
from serialspec.cli import main as serialspec_main
from serialspec.lang import SpecErrors, load_protocol
from serialspec.runtime.errors import RangeError

SPEC = """
protocol: keyworded
title: Keyword fields
byte_order: little
serial: {baudrate: 115200}
framing:
  elements:
    header: {role: header, value: "AA 55"}
    id: {role: address, type: u8, range: [0, 253], broadcast: 254}
    code: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: sum, covers: [id, content]}
matching: {by: [id, command]}
commands:
  probe:
    code: 1
    request:
      fields:
        class: {type: u8, range: [0, 9]}
        from: u8
        in: {type: bytes, size: from}
        flags: {type: u8, bits: {a: {bits: 0}}}
    response:
      fields:
        is: {type: u8, value: len(pass)}
        pass: {type: array, of: u16, count: is}
        flags: {type: u8, bits: {b: {bits: 1}}}
  other:
    code: 2
    request:
      fields:
        flags: {type: u8, bits: {c: {bits: 2}, d: {bits: 3}}}
        g: {type: group, count: 1, fields: {lambda: i8}}
    response:
      fields:
        g: {type: group, count: 1, fields: {with: u8}}
examples:
  probe:
    source: made up
    direction: request
    printed: AA 55 01 01 06 02 03 01 02 03 00 13
    command: probe
    fields: {id: 1, class: 2, in: "01 02 03", flags: {a: 0}}
device: {address: id}
"""
FRAME = "AA 55 01 01 06 02 03 01 02 03 00 13"


@pytest.fixture(scope="module")
def package(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    out = tmp_path_factory.mktemp("keyworded")
    spec = out / "keyworded.yaml"
    spec.write_text(SPEC, encoding="utf-8")
    return generate_and_import(spec, out / "out", "keyworded")


def test_python_attributes_and_json_keys(package: ModuleType) -> None:
    message = package.decode(bytes.fromhex(FRAME), "request")
    assert (message.class_, message.in_, message.id) == (2, b"\x01\x02\x03", 1)
    assert message.to_fields() == {"id": 1, "class": 2, "in": "01 02 03", "flags": {"a": 0}}
    assert package.ProbeRequest.from_fields(message.to_fields()) == message
    reply = package.ProbeResponse(id=1, pass_=(1, 2), flags=package.ProbeResponseFlagsBits(b=1))
    assert reply.to_fields() == {"id": 1, "pass": [1, 2], "flags": {"b": 1}}
    assert package.decode(package.encode(reply), "response") == reply
    with pytest.raises(RangeError, match="class = 10 is outside its range 0..9"):
        package.encode(package.ProbeRequest(id=1, class_=10, in_=b"", flags=package.FlagsBits(a=0)))


def test_bit_field_classes_per_message(package: ModuleType) -> None:
    names = {cls.__name__ for cls in vars(package.messages).values() if isinstance(cls, type)}
    assert {"FlagsBits", "ProbeResponseFlagsBits", "OtherRequestFlagsBits"} <= names
    assert {"GItem", "OtherResponseGItem"} <= names
    assert package.OtherResponseGItem(with_=3).to_fields() == {"with": 3}


def test_the_client_takes_the_python_names(package: ModuleType) -> None:
    client = importlib.import_module("keyworded.client")
    parameters = inspect.signature(client.KeywordedClient.probe).parameters
    assert "class_" in parameters and "in_" in parameters


def test_decode_and_encode_json_keep_the_spec_names(tmp_path: Path) -> None:
    spec = tmp_path / "keyworded.yaml"
    spec.write_text(SPEC, encoding="utf-8")
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert serialspec_main(["decode", str(spec), FRAME, "--json", "--direction", "request"]) == 0
    assert json.loads(out.getvalue())["fields"] == {"id": 1, "class": 2, "in": "01 02 03", "flags": {"a": 0}}
    wanted = {"command": "probe", "fields": {"id": 1, "class": 2, "in": "01 02 03", "flags": {"a": 0}}}
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert serialspec_main(["encode", str(spec), "--json", json.dumps(wanted)]) == 0
    assert out.getvalue().strip() == FRAME.lower()


def test_the_python_name_is_not_a_field_name(tmp_path: Path) -> None:
    spec = tmp_path / "keyworded.yaml"
    spec.write_text(SPEC.replace("        from: u8\n", "        from_: u8\n").replace("size: from}", "size: from_}"))
    with pytest.raises(SpecErrors) as raised:
        load_protocol(str(spec))
    (line,) = str(raised.value).splitlines()
    assert line.endswith("field name 'from_' is the Python name of a field 'from': call it 'from'")


def test_the_reference_names_the_python_attribute(tmp_path: Path) -> None:
    spec = tmp_path / "keyworded.yaml"
    spec.write_text(SPEC, encoding="utf-8")
    assert serialspec_main(["generate", str(spec), "--out", str(tmp_path / "out"), "--target", "markdown"]) == 0
    docs = (tmp_path / "out" / "docs" / "keyworded.md").read_text("utf-8")
    assert "| class |" in docs.replace("`", "") and "(In Python: `class_`.)" in docs
