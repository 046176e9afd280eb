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


# a group's items named as the message's fields, before and after the group: items of one size read in a loop that
# converts them (sign_magnitude, nibbles), items of varying size read one by one, a group in a group's items
SHARED = """
protocol: shared_names
title: Items named as their message's fields
byte_order: little
serial: {baudrate: 115200}
framing:
  elements:
    header: {role: header, value: "AA 55"}
    code: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
commands:
  probe:
    code: 1
    request:
      fields:
        n: u8
        k: {type: i16, encoding: nibbles}
        s: u8
        g: {type: group, count: 2, fields: {n: {type: i8, encoding: sign_magnitude}, k: {type: i16, encoding: nibbles}}}
        v: {type: group, count: 2, fields: {n: {type: i8, encoding: sign_magnitude}, d: {type: bytes, size: s}}}
        w: {type: group, count: 1, fields: {s: u8, d: {type: bytes, size: s}}}
        h:
          type: group
          count: 1
          fields:
            n: {type: i8, encoding: sign_magnitude}
            g: {type: group, count: 1, fields: {n: {type: i8, encoding: sign_magnitude}}}
        tail: {type: bytes, size: rest}
"""


def test_items_named_as_their_message_s_fields_keep_each_value() -> None:
    """A group item's value was decoded into the local of the message's field of its name, which then took the last
    item's value (n = -1 for 3 here); a group in an item packed into the list of the message's group of its name
    (g's bytes were h.g's). An item's size is its own earlier field where it has one of that name (w's s), else the
    field before its group (v's items' d: the message's s)."""
    from serialspec.backends.python import files as python_files
    from serialspec.backends.python.memory import imported
    from serialspec.lang.loader import load_text
    from serialspec.lang.resolve import resolve

    protocol = resolve(load_text(SHARED, "shared.yaml"))
    modules = {path.split("/", 1)[1]: code for path, code in python_files(protocol).items()}
    with imported(protocol.name, modules, "the shared names test") as package:
        fields = {
            "n": 3,
            "k": 100,
            "g": [{"n": 1, "k": -1}, {"n": -2, "k": -3}],
            "v": [{"n": -1, "d": "0a"}, {"n": 0, "d": "0b"}],
            "w": [{"d": "0c 0d"}],
            "h": [{"n": -5, "g": [{"n": -6}]}],
            "tail": "01 02 03",
        }
        message = package.ProbeRequest.from_fields(fields)
        decoded = package.decode(package.encode(message), "request")
        assert decoded == message and decoded.to_fields() == fields
