"""Counts and sizes given by an expression (`count: n + 1`, lang/counts.py; issue 21).

The matrix case "count and size expressions" runs every output; here: the spec errors (one line each, at the
count's file:line:column), the decoder's refusal of a negative count, encode's refusal of a list of another length
for every kind (naming the field and the count expected), the stream parser sizing a frame that carries no length by
a `n + k` count, and the markdown reference showing the expression.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from serialspec.backends import Unsupported
from serialspec.backends.c.build import files as c_files
from serialspec.backends.markdown.docs import emit_docs
from serialspec.backends.python.memory import imported
from serialspec.backends.python.package import emit_package
from serialspec.backends.wireshark import files as lua_files
from serialspec.lang import SpecErrors
from serialspec.lang.loader import load_text
from serialspec.lang.model import Protocol
from serialspec.lang.resolve import resolve
from serialspec.runtime.errors import DecodeError, EncodeError

HEAD = """protocol: counted
title: Counted
serial: {baudrate: 9600}
byte_order: little
framing:
  elements:
    header: {role: header, value: AA}
    code: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: sum, covers: [code, content]}
commands:
  probe:
    code: 1
    request:
      fields:
"""
FIELDS = """        n: {type: i8, range: [-2, 5]}
        items: {type: array, of: u16, count: "n + 1"}
        g: {type: group, count: "2 * n", fields: {a: u8}}
        data: {type: bytes, size: "n - 1"}
        name: {type: string, size: "max(n, 0)"}
        tail: u8
"""


def spec(fields: str = FIELDS, head: str = HEAD) -> str:
    return head + fields


def protocol_of(text: str) -> Protocol:
    return resolve(load_text(text, "counted.yaml"))


@pytest.fixture(scope="module")
def package() -> Iterator[ModuleType]:
    protocol = protocol_of(spec())
    with imported("counted", emit_package(protocol), "count expressions") as root:
        yield root


@pytest.mark.parametrize(
    ("fields", "said"),
    [
        (
            '        items: {type: array, of: u8, count: "m + 1"}\n',
            "items.count: unknown field 'm' in 'm + 1': a count or size names earlier integer fields",
        ),
        (
            '        items: {type: array, of: u8, count: "n + 1"}\n        n: u8\n',
            "items.count: a later field 'n' in 'n + 1': a count or size names earlier integer fields",
        ),
        (
            '        n: f32\n        data: {type: bytes, size: "n * 2"}\n',
            "data.size: 'n' in 'n * 2' is not an integer field",
        ),
        (
            '        n: {type: string, size: 2}\n        g: {type: group, count: "n - 1", fields: {a: u8}}\n',
            "g.count: 'n' in 'n - 1' is text: a count or size names earlier integer fields",
        ),
        (
            '        n: {type: u8, const: 3}\n        items: {type: array, of: u8, count: "n + 1"}\n',
            "items.count: 'n' in 'n + 1' is constant or derived: a count names plain integer fields of the message",
        ),
        (
            '        n: u8\n        items: {type: array, of: u8, count: "len(n)"}\n',
            "items.count: 'len(n)': a count names integer fields, not len() (a list's length is its count)",
        ),
        (
            '        n: u8\n        items: {type: array, of: u8, count: "8 / n"}\n',
            "items.count: '8 / n' may divide by 0 or shift by a negative count: a count divides and shifts by numbers",
        ),
        (
            '        n: i8\n        items: {type: array, of: u8, count: "n - 200"}\n',
            "items.count: 'n - 200' is always negative (-328..-73): no count",
        ),
        (
            '        n: u8\n        name: {type: string, size: "n + ", encoding: seven_bit}\n',
            "name.size: 'n + ' is not an expression (a count or size is a number, `rest`, a field name or an "
            "expression)",
        ),
    ],
)
def test_a_bad_count_expression_is_one_line_at_its_place(fields: str, said: str) -> None:
    text = spec(fields)
    with pytest.raises(SpecErrors) as refused:
        protocol_of(text)
    lines = str(refused.value).splitlines()
    assert len(lines) == 1, lines
    key = said.split(":")[0].split(".")[-1]
    row = next(
        i for i, line in enumerate(text.splitlines(), 1) if f"{key}: " in line and "{" in line and "type" in line
    )
    line = text.splitlines()[row - 1]
    column = line.index(f"{key}: ") + len(key) + 3
    expected = f"counted.yaml:{row}:{column}: commands.probe.request.fields.{said}"
    assert lines[0] == expected


def frame(content: bytes) -> bytes:
    body = bytes([1, len(content)]) + content
    return b"\xaa" + body + bytes([sum(body) & 0xFF])


def test_a_negative_count_on_the_wire_is_one_decode_error(package: ModuleType) -> None:
    """n = -2 (in its range): n + 1 items is -1, refused in one line before anything else is read."""
    with pytest.raises(DecodeError) as refused:
        package.decode(frame(b"\xfe\x00"), "request")
    assert str(refused.value) == "probe request: items has n + 1 = -1 items: a count cannot be negative"
    assert len(str(refused.value).splitlines()) == 1
    with pytest.raises(DecodeError, match="items needs 12 bytes, 1 left$"):  # n = 5: more than the frame holds
        package.decode(frame(b"\x05\x00"), "request")


def message(package: ModuleType, **fields: Any) -> Any:
    values = {"n": 2, "items": [1, 2, 3], "g": [{"a": 1}] * 4, "data": "07", "name": "ab", "tail": 9} | fields
    return package.ProbeRequest.from_fields(values)


def test_each_kind_is_read_as_many_as_the_expression_says(package: ModuleType) -> None:
    sent = package.encode(message(package))
    assert sent == frame(bytes.fromhex("02 0100 0200 0300 01010101 07") + b"ab" + b"\x09")
    assert package.decode(sent, "request") == message(package)
    assert package.StreamParser("request").feed(b"\x00" + sent + sent[:4]) == [message(package)]


@pytest.mark.parametrize(
    ("fields", "said"),
    [
        ({"items": [1, 2]}, "items needs n + 1 = 3 items, got 2"),
        ({"g": [{"a": 1}]}, "g needs 2 * n = 4 items, got 1"),
        ({"data": "07 08"}, "data needs n - 1 = 1 bytes, got 2"),
        ({"name": "abc"}, "name needs max(n, 0) = 2 bytes, got 3"),
    ],
)
def test_encode_refuses_another_length_naming_the_count(package: ModuleType, fields: dict[str, Any], said: str) -> None:
    with pytest.raises(EncodeError) as refused:
        package.encode(message(package, **fields))
    assert str(refused.value) == f"probe request: {said}"


NO_LENGTH = HEAD.replace("    length: {role: length, type: u8}\n", "")


def test_a_frame_without_a_length_is_sized_by_a_count_of_n_plus_k() -> None:
    """No length element: `2 * n + 1` items of 2 bytes size the frame (fixed + 4 per n); a count the stream parser
    cannot size by is refused in one line, as any content its own bytes do not size."""
    fields = '        n: u8\n        items: {type: array, of: u16, count: "2 * n + 1"}\n'
    protocol = protocol_of(spec(fields, NO_LENGTH))
    with imported("counted", emit_package(protocol), "count expressions") as package:
        sent = [
            package.encode(package.ProbeRequest.from_fields({"n": n, "items": list(range(2 * n + 1))})) for n in (0, 3)
        ]
        wire = b"\x00" + sent[0] + sent[1] + sent[0][:3]
        found = package.StreamParser("request").feed(wire)
        assert [len(m.items) for m in found] == [1, 7]
        parser = package.StreamParser("request")
        assert [m for byte in wire for m in parser.feed(bytes([byte]))] == found
    for item, count in (("u16", "n - 1"), ("bit", "n + 1")):  # not k * n + m; bits (not whole bytes an item)
        text = spec(f'        n: u8\n        items: {{type: array, of: {item}, count: "{count}"}}\n', NO_LENGTH)
        with pytest.raises(SpecErrors) as refused:
            protocol_of(text)
        row, column = len(text.splitlines()), text.splitlines()[-1].index("count") + 8
        assert str(refused.value) == (
            f"counted.yaml:{row}:{column}: commands.probe.request.fields.items.count: '{count}' cannot size a frame "
            "that has no length element (a stream parser sizes such frames by a count `k * field + m` of items of "
            "one size before them)"
        )


@pytest.mark.parametrize(
    ("field", "key"),
    [
        ("{type: bytes, size: rest}", "size"),
        ("{type: string, size: rest}", "size"),
        ("{type: array, of: u8, count: rest}", "count"),
        ("{type: group, count: rest, fields: {a: u8}}", "count"),
    ],
)
def test_the_rest_of_a_frame_without_a_length_is_one_line(field: str, key: str) -> None:
    """No length element, trailer or transform: nothing says where a frame whose last field takes the rest ends, so
    the stream parser dropped every such frame as garbage (and a client waited for a reply it never saw). One line
    instead; with a trailer the frame ends there and the spec stands."""
    text = spec(f"        n: u8\n        tail: {field}\n", NO_LENGTH)
    with pytest.raises(SpecErrors) as refused:
        protocol_of(text)
    row, column = len(text.splitlines()), text.splitlines()[-1].index(key) + 1 + len(key) + 2
    assert str(refused.value) == (
        f"counted.yaml:{row}:{column}: commands.probe.request.fields.tail.{key}: `{key}: rest` cannot size a frame "
        "that has no length element, trailer or transform: a stream parser could not tell where it ends (give the "
        f"frame a length element, or the field a {key} a field or a number says)"
    )
    ended = NO_LENGTH.replace("content]}\n", "content]}\n    end: {role: trailer, value: 0D}\n", 1)
    protocol_of(spec(f"        n: u8\n        tail: {field}\n", ended))


def test_the_c_refuses_a_negative_count_and_reads_the_others(package: ModuleType, tmp_path: Path) -> None:
    from test_c_backend import GCC, spec_driver

    if GCC is None:
        pytest.skip("no C compiler")
    spec_file = tmp_path / "counted.yaml"
    spec_file.write_text(spec(), "utf-8")
    driver = spec_driver(spec_file, "counted", tmp_path)
    try:
        sent = package.encode(message(package))
        said = driver.ask(f"dec request {sent.hex()}")[0]
        assert said.startswith("ok ") and json.loads(said[3:])["fields"] == message(package).to_fields()
        assert driver.ask(f"rt request {sent.hex()}") == [f"ok {sent.hex()}"]
        negative = frame(bytes([0xFE, 0]))  # n = -2: n + 1 items is -1
        said = driver.ask(f"dec request {negative.hex()}")[0]
        assert said == "err E_CONTENT", said
    finally:
        driver.close()


def test_wireshark_refuses_bit_operators_in_one_line_and_the_reference_shows_counts() -> None:
    """Lua 5.2 has no bit operators: a count of `n & 7` is refused by the dissector alone; C generates it."""
    protocol = protocol_of(spec('        n: u8\n        items: {type: array, of: u8, count: "n & 7"}\n'))
    with pytest.raises(Unsupported) as refused:
        lua_files(protocol)
    assert str(refused.value) == (
        "probe request: a count by an expression with bit operators (`items`: `count: n & 7`): Lua 5.2 has none"
    )
    assert c_files(protocol)
    page = emit_docs(protocol_of(spec()))
    assert "u16 list × (n + 1)" in page and "group × (2 * n)" in page and "bytes (n - 1)" in page
