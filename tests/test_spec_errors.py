"""Bad specs get one line per mistake with file:line:column and what was expected; never a traceback."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from serialspec.backends.markdown.docs import emit_docs
from serialspec.backends.python.package import emit_package
from serialspec.lang import SpecErrors, load_protocol

MINIMAL = """\
protocol: tiny
title: Tiny
byte_order: little
serial: {baudrate: 9600}
framing:
  elements:
    header: {role: header, value: "AA 55"}
    code: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: sum, covers: [code, content]}
commands:
  move:
    code: 1
    title: Move
    request:
      fields:
        servo_id: {type: u8, range: [0, 10]}
        angle: i16
"""
LINE = re.compile(r"^(?P<file>[^:]+):(?P<line>\d+):(?P<column>\d+): (?P<rest>.+)$")


def errors_of(tmp_path: Path, text: str) -> list[str]:
    spec = tmp_path / "tiny.yaml"
    spec.write_text(text, encoding="utf-8")
    with pytest.raises(SpecErrors) as failure:
        load_protocol(str(spec), "tiny.yaml")
    lines = str(failure.value).splitlines()
    for line in lines:
        assert LINE.match(line), line
    return lines


def test_minimal_spec_is_valid(tmp_path: Path) -> None:
    spec = tmp_path / "tiny.yaml"
    spec.write_text(MINIMAL, encoding="utf-8")
    assert load_protocol(str(spec)).commands[0].request is not None


def test_three_mistakes_give_three_lines(tmp_path: Path) -> None:
    text = (
        MINIMAL.replace("angle: i16", "angle: int17")
        .replace("code: 1", "code: one")
        .replace("range: [0, 10]", "range: [0, 300]")
    )
    lines = errors_of(tmp_path, text)
    assert len(lines) == 3, lines
    assert any("tiny.yaml:19:16: commands.move.request.fields.angle: unknown type 'int17'" in x for x in lines), lines
    assert any("commands.move.code: expected an integer" in x for x in lines)
    assert any("range [0, 300] does not fit u8" in x for x in lines)


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (("title: Move", "title: Move\n    colour: red"), "unknown key 'colour'"),
        # a key of the mapping one level lower: says where it goes (a response's `answers` written on its command)
        (
            ("title: Move", "title: Move\n    answers: move"),
            "unknown key 'answers' (a key of `request:` or `response:`, one level lower; expected one of code,",
        ),
        (("angle: i16", "angle: i16\n        angle: u8"), "duplicate key 'angle'"),
        (("angle: i16", "self: i16"), "reserved"),
        (("angle: i16", "from_: i16"), "is the Python name of a field 'from': call it 'from'"),
        (("angle: i16", "Angle: i16"), "lower-case identifier"),
        (("angle: i16", "angle: {type: u8, enum: colours}"), "unknown enum 'colours'"),
        (("covers: [code, content]", "covers: [code, body]"), "unknown frame element 'body'"),
        (('value: "AA 55"', 'value: "AA 5Z"'), "not a hex byte"),
        (("angle: i16", "angle: [i16"), "YAML syntax error"),
        (("angle: i16", "angle: {type: group, count: n, fields: {x: u8}}"), "unknown field 'n'"),
        (("angle: i16", "data: {type: bytes, size: rest}\n        after: u8"), "only the last field"),
        (("angle: i16", "name: {type: string, size: rest}\n        after: u8"), "only the last field"),
        (("angle: i16", "data: {type: bytes, size: 9223372036854775807}"), "more than a field can hold"),
        (("angle: i16", "v: {type: array, of: u64, count: 268435456}"), "2147483648 bytes: more than a field"),
        (
            ("angle: i16", "a: {type: bytes, size: 1500000000}\n        b: {type: bytes, size: 1500000000}"),
            "fields: at least 3000000001 bytes: more than a content can hold",
        ),
        (("angle: i16", "items: {type: array, of: u8, count: rest}\n        after: u8"), "only the last field"),
        (("angle: i16", 'n: {type: u8, value: "2 * m"}'), "unknown field 'm' in '2 * m'"),
        (("angle: i16", 'n: {type: u8, value: "2 ** servo_id"}'), "'2 ** servo_id' is not allowed"),
        (("angle: i16", 'n: {type: u8, value: "len(servo_id)"}'), "servo_id is not a list"),
        (
            ("angle: i16", 'a: {type: u8, value: "b + 1"}\n        b: {type: u8, value: "a - 1"}'),
            "derived values depend on each other: a -> b -> a",
        ),
        (("angle: i16", 'n: {type: f32, value: "servo_id"}'), "a derived value needs an integer type"),
        (("angle: i16", "n: {type: array, of: u16}"), "needs `count` (items) or `size`"),
        (("angle: i16", "n: {type: array, of: bit, count: 8, range: [0, 1]}"), "bits are true or false"),
        (("angle: i16", "name: {type: string}"), "a string needs `size`"),
        (("angle: i16", "name: {type: cstring, size: 4}"), "a cstring ends at its NUL byte"),
        (("type: u8}", "type: u8, error_flag: 0x80}"), "`error_flag` needs a command whose response is marked"),
        (('value: "AA 55"}', 'value: "AA 55", error_value: "AA 56"}'), "`error_value` needs a command whose"),
        (('value: "AA 55"}', 'value: "AA 55", error_value: "AA"}'), "as many bytes as the response header (2)"),
        (('value: "AA 55"}', 'value: "AA 55", error_value: "AA 55"}'), "must differ from the response header"),
        (('value: "AA 55"}', 'value: "AA 55", error_value: "AA 5Z"}'), "not a hex byte"),
        (
            ("role: command, type: u8}", "role: command, type: u8, error_value: 'AA'}"),
            "`error_value` goes on the header",
        ),
        (
            (
                '"AA 55"}\n    code: {role: command, type: u8}',
                '"AA 55", error_value: "AA 56"}\n    code: {role: command, error_flag: 1}',
            ),
            "give either the command element's `error_flag` or the header's `error_value`",
        ),
        (
            ("    request:", "    request:\n      text: {start: <, separator: '|'}"),
            "`text` belongs to messages of text",
        ),
        (("angle: i16", "angle: {type: i16, label: A}"), "`label` belongs to fields of text frames"),
        (("angle: i16", "rc: {type: array, of: u11, count: n}"), "an array of u11 items needs a fixed `count`"),
        (("angle: i16", "rc: {type: array, of: u65, count: 2}"), "u65: packed integers take 1..64 bits"),
        (("angle: i16", "rc: {type: array, of: u11, count: 2, range: [0, 4096]}"), "does not fit u11 (0..2047)"),
        (("angle: i16", "rc: {type: array, of: u24, count: rest}"), "an array of u24 items needs a fixed `count`"),
        (("angle: i16", "rc: {type: array, of: u16, count: 2, bit_order: lsb_first}"), "`bit_order` goes with"),
        (("angle: i16", "name: {type: string, size: 8, pad: 'zz'}"), "pad 'zz' must be one byte in hex"),
        (("angle: i16", "name: {type: cstring, pad: '00'}"), "`pad` goes with a string of a fixed size"),
        (("angle: i16", "m: {type: u8, enum: e, offset: 3}\nenums: {e: {values: {a: 1}}}"), "`offset` goes with"),
        (("angle: i16", "angle: {type: f32, encoding: seven_bit}"), "encoding seven_bit is for integers, not f32"),
        (("angle: i16", "t: {type: i16, encoding: seven_bit, range: [0, 8192]}"), "fit i16 seven_bit (-8192..8191)"),
        (("angle: i16", "t: {type: u16, encoding: seven_bit, range: [0, 16384]}"), "fit u16 seven_bit (0..16383)"),
        (("angle: i16", "t: {type: u16, encoding: seven_bit, const: 3}"), "`const` does not go with encoding seven"),
        # a number where an integer or text is wanted said "unexpected a number", and never why 1.0 is not an integer
        (("angle: i16", "t: {type: bytes, size: 2.0}"), "expected an integer or text, got a number (2.0):"),
        # a default where a message could not use it was accepted and ignored; a bytes one is hex of its size
        (("angle: i16", "t: {type: string, size: 4, default: 5}"), "`default` goes with a number or bytes of a fixed"),
        (("angle: i16", "t: {type: bytes, size: 3, default: 00 00}"), "t.default: 2 bytes, the field's size is 3"),
        (("angle: i16", "t: {type: bytes, size: rest, default: '00'}"), "goes with bytes of a fixed size (a number)"),
        (("angle: i16", "t: {type: bytes, size: 2, default: 0}"), "expected hex text of 2 bytes ('00 00'), got 0"),
        (("angle: i16", "t: {type: u8, default: '00'}"), "t.default: expected a number, got text ('00')"),
        (("angle: i16", "t: {type: u8, bits: {a: 1.0}}"), "expected an integer or a list or a mapping, got a number"),
        (
            ("angle: i16", "n: {type: u16, encoding: seven_bit}\n        v: {type: array, of: u8, count: n}"),
            "'n' holds a count or size: plain, not encoding seven_bit",
        ),
        # found by new users (tests/test_newuser_*.py): a comma in a flow mapping's text made the rest a key, and
        # a scale on an array was dropped without a word
        (
            ("angle: i16", "angle: {type: i16, description: The angle, in steps.}"),
            "a comma inside `{...}` ends a value: quote text that holds one",
        ),
        (("angle: i16", "rc: {type: array, of: u16, count: 2, scale: 0.125}"), "`scale` goes with a number field"),
    ],
)
def test_each_mistake_is_named_with_its_position(tmp_path: Path, change: tuple[str, str], expected: str) -> None:
    lines = errors_of(tmp_path, MINIMAL.replace(*change))
    assert any(expected in line for line in lines), lines


def test_a_key_yaml_reads_as_false_and_a_mistake_elsewhere_give_both_lines(tmp_path: Path) -> None:
    """The loader's mistakes (`off:` read as false) came alone: the passes' (a comma ending a flow value, 20 lines
    further) only showed once they were fixed, one run per kind of mistake. What the passes would say of the mapping
    that lost the key (here nothing, but a required key dropped would) stays unsaid."""
    text = MINIMAL.replace("{role: command, type: u8}", "{role: command, type: u8, description: a code, one byte}")
    text += "enums:\n  on_off:\n    values: {off: 0, 'on': 160}\n"
    lines = errors_of(tmp_path, text)
    assert [line.split(": ", 1)[0] for line in lines] == ["tiny.yaml:8:66", "tiny.yaml:22:14"], lines
    assert "unknown key 'one byte'" in lines[0] and "the key off reads as false in YAML" in lines[1], lines
    dropped = MINIMAL.replace("    code: 1\n", "    code: 1\n    yes: 2\n").replace("title: Move", "off: Move")
    assert [line.split(": ", 2)[2] for line in errors_of(tmp_path, dropped)] == [
        "the key yes reads as true in YAML: quote it ('yes')",
        "the key off reads as false in YAML: quote it ('off')",
    ]


def test_a_misspelt_role_is_one_line_not_one_more_per_key_of_the_role(tmp_path: Path) -> None:
    # `role: lenght` was said, then `counts` and `adds` were each said to belong to a length element
    text = MINIMAL.replace(
        "length: {role: length, type: u8}", "length: {role: lenght, type: u8, counts: [code, content], adds: 1}"
    )
    lines = errors_of(tmp_path, text)
    assert len(lines) == 1 and "framing.elements.length.role: unknown value 'lenght'" in lines[0], lines
    assert errors_of(tmp_path, MINIMAL.replace("role: content}", "role: content, adds: 1}")) == [
        "tiny.yaml:10:36: framing.elements.content.adds: `adds` belongs to a length element"
    ]
    # `algorithm: sum8` was said unknown, then the checksum was said to need an algorithm
    misspelt = errors_of(tmp_path, MINIMAL.replace("algorithm: sum,", "algorithm: sum8,"))
    assert len(misspelt) == 1 and "checksum.algorithm: unknown value 'sum8'" in misspelt[0], misspelt
    missing = errors_of(tmp_path, MINIMAL.replace("algorithm: sum,", ""))
    assert len(missing) == 1 and "framing.elements.checksum: a checksum needs `algorithm: crc`" in missing[0], missing


def test_an_error_flag_with_a_command_code_that_is_not_a_number_is_an_error_line(tmp_path: Path) -> None:
    # the error-reply pass used to apply the flag to the code regardless (TypeError on a list, a traceback)
    text = MINIMAL.replace("type: u8}", "type: u8, error_flag: 0x80}").replace("code: 1", "code: [1]")
    lines = errors_of(tmp_path, text)
    assert any("commands.move.code: expected an integer" in x for x in lines), lines


def test_the_reference_of_an_example_shorter_than_its_frame_says_it_does_not_decode(tmp_path: Path) -> None:
    # the example verification reports such a frame; the docs emitter used to fail first (IndexError, a traceback)
    spec = tmp_path / "tiny.yaml"
    example = 'examples:\n  short: {source: x, direction: request, printed: "AA 55", command: move, fields: {}}\n'
    spec.write_text(MINIMAL + example, encoding="utf-8")
    page = emit_docs(load_protocol(str(spec), "tiny.yaml"))
    assert "does not decode: 2 bytes, fewer than the frame's 5 without content" in page


def test_duplicate_command_codes_and_overlapping_registers(tmp_path: Path) -> None:
    text = (
        MINIMAL
        + """\
  stop:
    code: 1
    request: {fields: {servo_id: u8, speed: i16}}
tables:
  regs:
    key: address
    entries:
      position: {key: 0x2A, type: u16}
      speed: {key: 0x2B, type: u16}
"""
    )
    lines = errors_of(tmp_path, text)
    assert any("code 0x01 in request frames is already used by 'move'" in x for x in lines), lines
    assert any("register speed at 0x2b overlaps position" in x for x in lines), lines


def test_wrong_crc_parameters_are_caught_by_the_check_value(tmp_path: Path) -> None:
    text = MINIMAL.replace(
        "algorithm: sum,",
        "algorithm: crc, crc: {width: 8, poly: 0x31, init: 0xFF, refin: true, refout: true, xorout: 0, check: 0xA1},",
    )
    lines = errors_of(tmp_path, text)
    assert any("not the check value 0xa1" in x for x in lines), lines


def test_hostile_text_never_reaches_generated_code_unescaped(tmp_path: Path) -> None:
    hostile = '"""\n\nimport os; os.system("echo pwned")  # \u2028 \\ </td><script>alert(1)</script>'
    spec_data = yaml.safe_load(MINIMAL)
    move = spec_data["commands"]["move"]
    move["title"] = move["description"] = hostile
    move["request"]["fields"]["angle"] = {"type": "i16", "description": hostile, "unit": hostile}
    spec_data["enums"] = {"mode": {"description": hostile, "values": {"fast": {"value": 1, "text": hostile}}}}
    spec = tmp_path / "tiny.yaml"
    spec.write_text(yaml.safe_dump(spec_data, allow_unicode=True, sort_keys=False), encoding="utf-8")
    protocol = load_protocol(str(spec))
    for name, source in emit_package(protocol).items():
        if name.endswith(".py"):
            tree = ast.parse(source, name)  # still valid Python, and the text stayed text:
            imported = {alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names}
            assert "os" not in imported, name
            assert not any(isinstance(node, ast.Attribute) and node.attr == "system" for node in ast.walk(tree)), name
    docs = emit_docs(protocol)
    assert "<script>" not in docs and "</td>" not in docs


def test_cli_reports_spec_errors_without_traceback(tmp_path: Path) -> None:
    (tmp_path / "specs").mkdir()
    (tmp_path / "specs" / "tiny.yaml").write_text(MINIMAL.replace("angle: i16", "angle: int17"), encoding="utf-8")
    result = subprocess.run(
        [sys.executable, "-m", "serialspec", "check", "--root", str(tmp_path)], capture_output=True, text=True
    )
    assert result.returncode == 1
    assert "Traceback" not in result.stderr
    assert "specs/tiny.yaml:19:16: commands.move.request.fields.angle: unknown type 'int17'" in result.stderr


def test_device_errors_name_fields_the_error_reply_has(tmp_path: Path) -> None:
    text = (
        MINIMAL
        + """\
  refusal:
    code: 0x7F
    response:
      error_reply: true
      fields: {reason: u8}
device:
  errors:
    out_of_range: {reason: 3}
    read_only: {why: 2}
    unsupported: {reason: 1}
  commands:
    move: {restores: {memory: sram, except: [speed]}, broadcast_ignores: {option: 255}, modulo: {angle: 4096}}
"""
    )
    lines = errors_of(tmp_path, text)
    assert any("restores.except[0]: unknown state variable 'speed'" in x for x in lines), lines
    assert any("broadcast_ignores.option: move has no request field 'option'" in x for x in lines), lines
    assert any("modulo.angle: unknown state variable 'angle'" in x for x in lines), lines
    assert any("device.errors.read_only.why: the error reply refusal has no field 'why'" in x for x in lines), lines
    assert any("device.errors.unsupported:" in x and "not classic" in x for x in lines), lines
    assert not any("out_of_range" in x for x in lines), lines


def test_a_table_with_no_entries_is_an_error_line(tmp_path: Path) -> None:
    # a table_value over it used to take the smallest of no sizes (ValueError, a traceback); found by the spec fuzz
    table = "tables:\n  params: {key: data_id, entries: {}}\n"
    fields = "        data_id: u8\n        value: {type: table_value, table: params, key: data_id}\n"
    lines = errors_of(tmp_path, MINIMAL.replace("        angle: i16\n", fields) + table)
    assert any("tables.params.entries: a table needs at least one entry that is not reserved" in x for x in lines)
    assert len(lines) == 1, lines


def test_many_mistakes_show_the_first_50_and_count_the_rest(tmp_path: Path) -> None:
    """A spec with 80 commands sharing one code gave 79 lines (50,000 commands: 50,000 lines, seconds to print): the
    first 50 in file order, then one line counting the rest, from the exception and from `check` and `generate`."""
    commands = "".join(f"  c{i}:\n    code: 1\n    request: {{fields: {{a: u8}}}}\n" for i in range(80))
    text = MINIMAL.partition("commands:\n")[0] + "commands:\n" + commands
    lines = str(load_errors(tmp_path, text)).splitlines()
    assert len(lines) == 51
    assert lines[0] == (
        "tiny.yaml:17:5: commands.c1: code 0x01 in request frames is already used by 'c0', and a content of 1 byte "
        "fits both (requests that share a code are told apart by their content size: 1 byte and 1 byte)"
    )
    assert lines[49].startswith("tiny.yaml:164:5: commands.c50: ")
    assert lines[50] == "... and 29 more errors (79 in all)"
    for verb in ("check", "generate"):
        result = subprocess.run(
            [sys.executable, "-m", "serialspec", verb, "tiny.yaml", "--out", "out"],
            capture_output=True,
            text=True,
            cwd=tmp_path,
        )
        assert result.returncode == 1
        shown = [line for line in result.stderr.splitlines() if line.startswith("tiny.yaml:")]
        assert shown == lines[:50], verb
        assert "... and 29 more errors (79 in all)" in result.stderr.splitlines(), verb


def test_an_unknown_name_among_thousands_lists_a_dozen_and_counts_the_rest(tmp_path: Path) -> None:
    """An unknown enum in a spec of 3,000 enums listed all 3,000 names in its one line."""
    enums = "".join(f"  e{i}: {{values: {{a: 1}}}}\n" for i in range(3000))
    lines = errors_of(tmp_path, MINIMAL.replace("angle: i16", "angle: {type: u8, enum: colours}") + "enums:\n" + enums)
    assert lines == [
        "tiny.yaml:19:33: commands.move.request.fields.angle.enum: unknown enum 'colours' (expected one of: e0, e1, "
        "e2, e3, e4, e5, e6, e7, e8, e9, e10, e11 and 2988 more)"
    ], lines


def load_errors(tmp_path: Path, text: str) -> SpecErrors:
    spec = tmp_path / "tiny.yaml"
    spec.write_text(text, encoding="utf-8")
    with pytest.raises(SpecErrors) as failure:
        load_protocol(str(spec), "tiny.yaml")
    return failure.value


def test_a_spec_file_over_the_limit_is_refused_without_reading_it_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A 50 MB description was accepted using about 600 MB: a file over MAX_SPEC_BYTES is one line, read no
    further than the limit (the memory the load takes stays within a few times the limit, whatever the file's size),
    whether it is named by path to the loader, to `decode` or to `check`."""
    import tracemalloc

    from serialspec.cli import protocols
    from serialspec.lang.limits import MAX_SPEC_BYTES

    spec = tmp_path / "big.yaml"
    with spec.open("w", encoding="utf-8") as stream:
        stream.write(MINIMAL.replace("title: Tiny", "title: Tiny\ndescription: "))
        for _ in range(30):
            stream.write("word " * 200_000)  # 30 MB in all
    expected = "big.yaml:1:1: the file is larger than 1,000,000 bytes, the most a spec may have"
    monkeypatch.chdir(tmp_path)
    for load in (lambda: load_protocol("big.yaml"), lambda: protocols.open_spec("big.yaml")):
        tracemalloc.start()
        try:
            with pytest.raises(SpecErrors) as failure:
                load()
            _, peak = tracemalloc.get_traced_memory()
        finally:
            tracemalloc.stop()
        assert str(failure.value) == expected
        assert peak < 4 * MAX_SPEC_BYTES
    result = subprocess.run(
        [sys.executable, "-m", "serialspec", "check", "big.yaml", "--out", "out"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert result.stderr.splitlines()[0] == expected


def test_a_request_code_too_wide_for_the_reply_command_element(tmp_path: Path) -> None:
    """VISCA asks under a u16 (01 04) and answers under a u8 (50): a reply's code is checked against the reply's
    command element (it was checked against either, so replies under 0x0904 were silently never decoded)."""
    text = (
        MINIMAL.replace(
            "    code: {role: command, type: u8}",
            "    code: {role: command, type: u16, directions: [request]}\n"
            "    reply: {role: command, type: u8, directions: [response]}",
        )
        .replace("code: 1", "code: 0x0904")
        .replace("covers: [code, content]", "covers: [length, content]")
    )
    text += "    response:\n      fields: {state: u8}\n"
    lines = errors_of(tmp_path, text)
    assert len(lines) == 1, lines
    assert lines[0].endswith(
        "commands.move.code: code 2308 does not fit the u8 command element of response frames (0..255); give that "
        "element a `reply_code` (the code replies carry, as an expression of `code`)"
    ), lines
    coded = text.replace("directions: [response]}", 'directions: [response], reply_code: "code & 0xFF"}')
    spec = tmp_path / "coded.yaml"
    spec.write_text(coded, encoding="utf-8")
    assert load_protocol(str(spec)).commands[0].response_code == 0x04
