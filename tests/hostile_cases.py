# ruff: noqa: E501  (a table: one case a line where it fits, error messages quoted whole)
"""The hostile-spec corpus: small base specs and a table of mutations, each with the one error line it must give.

A case is (id, base, mutation, expected). The base is a spec loaded once ("tiny" is tests/hostile/tiny.yaml, the
others are the project's specs); the mutation changes its data (`put`, `drop`, `rename`) or, for the loader's
cases, its text (`Text`); expected is the `path: message` of the single error line (after `file:line:column: `),
or None when the spec is valid and its generated package must import and pass its examples.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

Data = dict[str, Any]
Mutation = Callable[[Data], None]


@dataclass(frozen=True)
class Text:
    """A loader case: the spec file's bytes, made from the base's text."""

    make: Callable[[str], bytes]


def _walk(data: Data, path: str) -> tuple[Any, str]:
    *parents, last = path.split("/")
    node: Any = data
    for key in parents:
        node = node.setdefault(key, {}) if isinstance(node, dict) else node[int(key)]
    return node, last


def put(path: str, value: Any) -> Mutation:
    """Set the value at a /-separated path (missing mappings are created)."""

    def mutate(data: Data) -> None:
        node, last = _walk(data, path)
        node[last] = copy.deepcopy(value)

    return mutate


def drop(path: str) -> Mutation:
    def mutate(data: Data) -> None:
        node, last = _walk(data, path)
        del node[last]

    return mutate


def rename(path: str, new: str) -> Mutation:
    """Rename a key, keeping its place."""

    def mutate(data: Data) -> None:
        node, last = _walk(data, path)
        items = [(new if k == last else k, v) for k, v in node.items()]
        node.clear()
        node.update(items)

    return mutate


def _status_reply(count: int) -> Data:
    """tiny's status reply with one value: an example recording its count (which encode computes) as given."""
    fields = {"id": 1, "alarms": 0, "count": count, "values": [{"v": 258}]}
    return {
        "source": "made up",
        "direction": "response",
        "printed": "AA 55 01 04 04 00 01 02 01 0D",
        "command": "status",
        "fields": fields,
    }


def both(*mutations: Mutation) -> Mutation:
    def mutate(data: Data) -> None:
        for mutation in mutations:
            mutation(data)

    return mutate


def replace_text(old: str, new: str) -> Text:
    def make(text: str) -> bytes:
        assert old in text, old
        return text.replace(old, new, 1).encode("utf-8")

    return Text(make)


def raw(data: bytes) -> Text:
    return Text(lambda _text: data)


BOMB = "".join(
    f"{name}: &{name} [{', '.join([f'*{prev}'] * 9) if prev else ', '.join(['lol'] * 9)}]\n"
    for prev, name in zip(["", "a", "b", "c", "d", "e", "f", "g", "h"], "abcdefghi", strict=True)
)
HOSTILE = '"""\n\nimport os; os.system("echo pwned")  # \u2028 \\ </td><script>alert(1)</script> | `x` ${{ }}'

CASES: list[tuple[str, str, Mutation | Text, str | None]] = [
    # --- the loader: limits, encodings, recursion -------------------------------------------------------------------
    (
        "alias bomb",
        "tiny",
        Text(lambda t: (t + BOMB.replace("a:", "zz_a:", 1)).encode()),
        "e[0][3][4][7][1]: the YAML aliases expand to too many values (a YAML bomb?)",
    ),
    (
        "self alias list",
        "tiny",
        replace_text("title: Tiny", "title: &t [*t]"),
        "title[0]: a YAML alias refers to a value that contains it",
    ),
    (
        "self alias map",
        "tiny",
        replace_text("title: Tiny", "title: &t {x: *t}"),
        "title.x: a YAML alias refers to a value that contains it",
    ),
    (
        "nesting 5000 deep",
        "tiny",
        replace_text("title: Tiny", "title: " + "[" * 5000 + "]" * 5000),
        "title[0][0]: values nested too deeply (more than 64 levels)",
    ),
    (
        "nesting 70 deep",
        "tiny",
        replace_text("title: Tiny", "title: " + "[" * 70 + "]" * 70),
        "title[0][0]: values nested too deeply (more than 64 levels)",
    ),
    (
        "latin-1 byte",
        "tiny",
        Text(lambda t: t.replace("A small", "A sm\x00all").encode().replace(b"\x00", b"\xe9")),
        "not UTF-8 text: byte 0xe9 cannot be decoded (save the spec as UTF-8)",
    ),
    ("utf-16 file", "tiny", Text(lambda t: t.encode("utf-16")), "a binary file (NUL bytes), not YAML text"),
    ("png file", "tiny", raw(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR"), "a binary file (NUL bytes), not YAML text"),
    ("nul at the end", "tiny", Text(lambda t: t.encode() + b"\x00"), "a binary file (NUL bytes), not YAML text"),
    (
        "escaped nul in text",
        "tiny",
        replace_text("title: Tiny", 'title: "Ti\\0ny"'),
        "title: control character U+0000 in text (not allowed in a spec)",
    ),
    (
        "escape character in text",
        "tiny",
        replace_text("title: Tiny", 'title: "\\e[31mTiny"'),
        "title: control character U+001B in text (not allowed in a spec)",
    ),
    (
        "bell in a unit",
        "tiny",
        replace_text('unit: "0.1°"', 'unit: "\\a0.1°"'),
        "commands.move.request.fields.angle.unit: control character U+0007 in text (not allowed in a spec)",
    ),
    (
        "c1 control in text",
        "tiny",
        replace_text("title: Tiny", 'title: "Ti\\x9bny"'),
        "title: control character U+009B in text (not allowed in a spec)",
    ),
    (
        "control character in a key",
        "tiny",
        replace_text("  mode: {values:", '  "mo\\x01de": {values:'),
        "enums.mo\\x01de: control character U+0001 in a key",
    ),
    (
        "5000-digit code",
        "tiny",
        replace_text("code: 1\n", "code: " + "9" * 5000 + "\n"),
        "commands.move.code: number too long (5000 characters)",
    ),
    ("empty file", "tiny", raw(b""), "empty spec (expected a mapping with protocol, framing, ...)"),
    ("comment only", "tiny", raw(b"# nothing here\n"), "empty spec (expected a mapping with protocol, framing, ...)"),
    (
        "top-level list",
        "tiny",
        raw(b"- protocol: tiny\n"),
        "expected a mapping with keys protocol, title, description, sources, byte_order, serial, framing, matching, fields, enums, flags, tables, commands, examples, errata, device, got a list",
    ),
    (
        "top-level text",
        "tiny",
        raw(b"tiny\n"),
        "expected a mapping with keys protocol, title, description, sources, byte_order, serial, framing, matching, fields, enums, flags, tables, commands, examples, errata, device, got text",
    ),
    (
        "python tag",
        "tiny",
        replace_text("title: Tiny", 'title: !!python/object/apply:os.system ["echo pwned"]'),
        "title: YAML tag 'tag:yaml.org,2002:python/object/apply:os.system' is not supported",
    ),
    (
        "tab indentation",
        "tiny",
        replace_text("  move:\n", "\tmove:\n"),
        "YAML syntax error: found character '\\t' that cannot start any token",
    ),
    (
        "unclosed bracket",
        "tiny",
        replace_text("{baudrate: 9600}", "{baudrate: 9600"),
        "YAML syntax error: expected ',' or '}', but got ':'",
    ),
    (
        "duplicate key",
        "tiny",
        replace_text("title: Tiny\n", "title: Tiny\ntitle: Tiny\n"),
        "title: duplicate key 'title'",
    ),
    (
        "list as key",
        "tiny",
        replace_text("title: Tiny\n", "title: Tiny\n? [a, b]\n: c\n"),
        "keys must be names or numbers",
    ),
    (
        "boolean key",
        "tiny",
        replace_text("title: Tiny\n", "title: Tiny\nyes: 1\n"),
        "the key yes reads as true in YAML: quote it ('yes')",
    ),
    (
        "enum value named off",  # a newcomer's first enum: off/on are false/true in YAML 1.1
        "tiny",
        replace_text("mode: {values: {slow: 0, fast: 1}}", "mode: {values: {off: 0, fast: 1}}"),
        "enums.mode.values: the key off reads as false in YAML: quote it ('off')",
    ),
    (
        "null key",
        "tiny",
        replace_text("title: Tiny\n", "title: Tiny\n~: 1\n"),
        "the key ~ reads as nothing in YAML: quote it ('~')",
    ),
    # --- numbers: codes, sizes, scales, ranges, defaults, serial settings ----------------------------------------------
    (
        "code 256",
        "tiny",
        put("commands/move/code", 256),
        "commands.move.code: code 256 does not fit the u8 command element (0..255)",
    ),
    (
        "code -8",
        "tiny",
        put("commands/move/code", -8),
        "commands.move.code: code -8 does not fit the u8 command element (0..255)",
    ),
    (
        "code as text",
        "tiny",
        put("commands/move/code", "one"),
        "commands.move.code: expected an integer, got text (text codes belong to `framing: {kind: text}`)",
    ),
    (
        "a C type name",  # what a datasheet or a C header says
        "tiny",
        put("commands/move/request/fields/time/type", "uint16_t"),
        "commands.move.request.fields.time.type: unknown type 'uint16_t' (did you mean 'u16'? expected one of u8, i8, "
        "u16, i16, u24, i24, u32, i32, u64, i64, f32, f64, bytes, string, cstring, array, group, table_value, "
        "table_block, or uN/iN of 1..64 bits)",
    ),
    (
        "code as a number in quotes",  # YAML reads "0x01" as text
        "tiny",
        put("commands/move/code", "0x01"),
        "commands.move.code: expected an integer, got text (write it without quotes: 0x01)",
    ),
    ("code true", "tiny", put("commands/move/code", True), "commands.move.code: expected an integer, got true/false"),
    (
        "code float",
        "tiny",
        put("commands/move/code", 1.5),
        "commands.move.code: expected an integer, got a number (1.5)",
    ),
    (
        "subcommand code 300",
        "rrc",
        put("commands/bus_servo/subcommands/set_id/code", 300),
        "commands.bus_servo.subcommands.set_id.code: code 300 does not fit the u8 selector (0..255)",
    ),
    ("baudrate text", "tiny", put("serial/baudrate", "fast"), "serial.baudrate: expected an integer, got text"),
    ("baudrate negative", "tiny", put("serial/baudrate", -9600), "serial.baudrate: -9600 is outside the minimum 1"),
    ("baudrate zero", "tiny", put("serial/baudrate", 0), "serial.baudrate: 0 is outside the minimum 1"),
    ("bytesize 9", "tiny", put("serial/bytesize", 9), "serial.bytesize: 9 is outside 5..8"),
    ("stopbits 3", "tiny", put("serial/stopbits", 3), "serial.stopbits: unknown value 3 (expected one of 1, 1.5, 2)"),
    (
        "parity mark",
        "tiny",
        put("serial/parity", "mark"),
        "serial.parity: unknown value 'mark' (expected one of none, even, odd)",
    ),
    # bit fields (uN/iN of any width, serialspec/encodings/bit_run.py): runs end on a byte boundary
    (
        "bit run short of a byte",
        "tiny",
        put("commands/move/request/fields/angle", "u12"),
        "commands.move.request.fields.angle: bit run angle: 36 bits at the end of the content, not a whole number "
        "of bytes (add fields or reserved bits to fill 40)",
    ),
    (
        "bit run cut by text",
        "tiny",
        both(
            put("commands/move/request/fields/a", "u4"),
            put("commands/move/request/fields/s", {"type": "string", "size": 2}),
            put("commands/move/request/fields/b", "u4"),
        ),
        "commands.move.request.fields.a: bit run a: 4 bits before s, not a whole number of bytes (add fields or "
        "reserved bits to fill 8)",
    ),
    (
        "bit field of 65 bits",
        "tiny",
        put("commands/move/request/fields/angle", {"type": "i65"}),
        "commands.move.request.fields.angle.type: unknown type 'i65' (expected one of u8, i8, u16, i16, u24, i24, "
        "u32, i32, u64, i64, f32, f64, bytes, string, cstring, array, group, table_value, table_block, or uN/iN of "
        "1..64 bits)",
    ),
    (
        "bit field with endian",
        "tiny",
        both(
            put("commands/move/request/fields/angle", {"type": "i12", "endian": "big"}),
            put("commands/move/request/fields/pad", "u4"),
        ),
        "commands.move.request.fields.angle.endian: `endian` does not go with a bit field (i12: packed MSB first)",
    ),
    (
        "u24 length",
        "tiny",
        put("framing/elements/length/type", "u24"),
        "framing.elements.length.type: u24 is a checksum's type, not a length's",
    ),
    (
        "scale 0",
        "tiny",
        put("commands/move/request/fields/angle/scale", 0),
        "commands.move.request.fields.angle.scale: scale 0 would make every value 0 (give the size of one wire step)",
    ),
    (
        "scale nan",
        "tiny",
        put("commands/move/request/fields/angle/scale", float("nan")),
        "commands.move.request.fields.angle.scale: expected a finite number, got nan",
    ),
    (
        "scale inf",
        "tiny",
        put("commands/move/request/fields/angle/scale", float("inf")),
        "commands.move.request.fields.angle.scale: expected a finite number, got inf",
    ),
    (
        "scale text",
        "tiny",
        put("commands/move/request/fields/angle/scale", "0.1"),
        "commands.move.request.fields.angle.scale: expected a number, got text",
    ),
    (
        "table scale 0",
        "tiny",
        put("tables/regs/entries/speed/scale", 0),
        "tables.regs.entries.speed.scale: scale 0 would make every value 0 (give the size of one wire step)",
    ),
    (
        "range reversed",
        "tiny",
        put("commands/move/request/fields/angle/range", [900, -900]),
        "commands.move.request.fields.angle.range: range [900, -900] is empty",
    ),
    (
        "range nan",
        "tiny",
        put("commands/move/request/fields/angle/range", [float("nan"), 1]),
        "commands.move.request.fields.angle.range[0]: expected a finite number, got nan",
    ),
    (
        "range too wide",
        "tiny",
        put("commands/move/request/fields/angle/range", [-900, 40000]),
        "commands.move.request.fields.angle.range: range [-900, 40000] does not fit i16 (-32768..32767)",
    ),
    (
        "range of three",
        "tiny",
        put("commands/move/request/fields/angle/range", [1, 2, 3]),
        "commands.move.request.fields.angle.range: expected a list of 2 items, got 3",
    ),
    (
        "range of text",
        "tiny",
        put("commands/move/request/fields/angle/range", ["a", 1]),
        "commands.move.request.fields.angle.range[0]: expected a number, got text",
    ),
    (
        "table range too wide",
        "tiny",
        put("tables/regs/entries/speed/range", [0, 300]),
        "tables.regs.entries.speed.range: range [0, 300] does not fit u8 (0..255)",
    ),
    (
        "table default outside range",
        "tiny",
        put("tables/regs/entries/speed/default", 101),
        "tables.regs.entries.speed.default: default 101 is outside the range 0..100",
    ),
    (
        "table default nan",
        "tiny",
        put("tables/regs/entries/speed/default", float("nan")),
        "tables.regs.entries.speed.default: expected a finite number, got nan",
    ),
    (
        "field default outside range",
        "tiny",
        put("commands/move/request/fields/angle/default", 901),
        "commands.move.request.fields.angle.default: default 901 is outside the range -900..900",
    ),
    (
        "const outside type",
        "tiny",
        put("commands/move/request/fields/mode/const", 300),
        "commands.move.request.fields.mode.const: constant 300 is outside 0..1",
    ),
    (
        "bytes of 300",
        "tiny",
        put("commands/write/request/fields/data", {"type": "bytes", "size": 300}),
        "commands.write.request: content of at least 301 bytes is more than the u8 length element 'length' can count (255)",
    ),
    (
        "bytes of 0",
        "tiny",
        put("commands/write/request/fields/data", {"type": "bytes", "size": 0}),
        "commands.write.request.fields.data.size: size 0: bytes of a fixed size hold at least one byte",
    ),
    (
        "bytes of -1",
        "tiny",
        put("commands/write/request/fields/data", {"type": "bytes", "size": -1}),
        "commands.write.request.fields.data.size: size -1: bytes of a fixed size hold at least one byte",
    ),
    (
        "array of 10^9",
        "tiny",
        put("commands/move/request/fields/extra", {"type": "array", "of": "u8", "count": 10**9}),
        "commands.move.request: content of at least 1000000005 bytes is more than the u8 length element 'length' can count (255)",
    ),
    (
        "array of 0",
        "tiny",
        put("commands/move/request/fields/extra", {"type": "array", "of": "u8", "count": 0}),
        "commands.move.request.fields.extra.count: an array needs a fixed `count` (use a group for counted items)",
    ),
    (
        "array of f128",
        "tiny",
        put("commands/move/request/fields/extra", {"type": "array", "of": "f128", "count": 2}),
        "commands.move.request.fields.extra.of: unknown type 'f128' (expected one of u8, i8, u16, i16, u24, i24, u32, i32, u64, i64, f32, f64)",
    ),
    ("enum value 256", "tiny", put("enums/mode/values/fast", 256), "enums.mode.values.fast: value 256 does not fit u8"),
    ("enum value -1", "tiny", put("enums/mode/values/fast", -1), "enums.mode.values.fast: value -1 does not fit u8"),
    (
        "enum value twice",
        "tiny",
        put("enums/mode/values/fast", 0),
        "enums.mode.values.fast: value 0 is already used by 'slow'",
    ),
    (
        "enum of f32",
        "tiny",
        put("enums/mode/type", "f32"),
        "enums.mode.type: unknown type 'f32' (expected one of u8, i8, u16, i16, u32, i32)",
    ),
    ("flag bit 8", "tiny", put("flags/alarms/bits/stall", 8), "flags.alarms.bits.stall: bit 8 is outside a u8"),
    ("flag bit -1", "tiny", put("flags/alarms/bits/stall", -1), "flags.alarms.bits.stall: bit -1 is outside a u8"),
    (
        "bits outside the type",
        "tiny",
        put("commands/move/request/fields/mode", {"type": "u8", "bits": {"a": {"bits": [9, 0]}}}),
        "commands.move.request.fields.mode.bits.a: bits 9..0 do not fit a u8",
    ),
    (
        "overlapping bits",
        "tiny",
        put("commands/move/request/fields/mode", {"type": "u8", "bits": {"a": {"bits": [3, 0]}, "b": {"bits": 2}}}),
        "commands.move.request.fields.mode.bits.b: overlaps another bit field",
    ),
    (
        "a constant bit field's value does not fit its bits",
        "tiny",
        put("commands/move/request/fields/mode", {"type": "u8", "bits": {"a": {"bits": [3, 0], "const": 16}}}),
        "commands.move.request.fields.mode.bits.a.const: const 16 does not fit bits 3..0 (0..15)",
    ),
    (
        "a bit field's default does not fit its bits",
        "tiny",
        put("commands/move/request/fields/mode", {"type": "u8", "bits": {"a": {"bits": 7, "default": 2}}}),
        "commands.move.request.fields.mode.bits.a.default: default 2 does not fit bits 7..7 (0..1)",
    ),
    (
        "bits of a signed type",
        "tiny",
        put("commands/move/request/fields/mode", {"type": "i8", "bits": {"a": {"bits": 1}}}),
        "commands.move.request.fields.mode.bits: bit fields need an unsigned integer type",
    ),
    (
        "device initial too big",
        "tiny",
        put("device/initial/volts", 300),
        "device.initial.volts: initial value 300 is outside volts's range 0..255",
    ),
    (
        "device initial negative",
        "tiny",
        put("device/initial/volts", -1),
        "device.initial.volts: initial value -1 is outside volts's range 0..255",
    ),
    (
        "device initial text",
        "tiny",
        put("device/initial/volts", "lots"),
        "device.initial.volts: expected a number, got text",
    ),
    (
        "broadcast 300",
        "tiny",
        put("framing/elements/id/broadcast", 300),
        "framing.elements.id.broadcast: broadcast 300 does not fit u8",
    ),
    (
        "element range too wide",
        "tiny",
        put("framing/elements/id/range", [0, 256]),
        "framing.elements.id.range: range [0, 256] does not fit u8 (0..255)",
    ),
    (
        "empty header",
        "tiny",
        put("framing/elements/header/value", ""),
        "framing.elements.header.value: no hex bytes given",
    ),
    (
        "header not hex",
        "tiny",
        put("framing/elements/header/value", "AA 5Z"),
        "framing.elements.header.value: '5Z' is not a hex byte",
    ),
    (
        "checksum of f32",
        "tiny",
        put("framing/elements/checksum/type", "f32"),
        "framing.elements.checksum.type: unknown type 'f32' (expected one of u8, i8, u16, i16, u32, i32)",
    ),
    (
        "crc check wrong",
        "tiny",
        put(
            "framing/elements/checksum",
            {
                "role": "checksum",
                "type": "u8",
                "algorithm": "crc",
                "covers": ["id", "content"],
                "crc": {"width": 8, "poly": 7, "init": 0, "refin": False, "refout": False, "xorout": 0, "check": 0},
            },
        ),
        "framing.elements.checksum.crc.check: these parameters give 0xf4 for '123456789', not the check value 0x0",
    ),
    (
        "crc too wide",
        "tiny",
        put(
            "framing/elements/checksum",
            {
                "role": "checksum",
                "type": "u8",
                "algorithm": "crc",
                "covers": ["id", "content"],
                "crc": {
                    "width": 16,
                    "poly": 0x1021,
                    "init": 0,
                    "refin": False,
                    "refout": False,
                    "xorout": 0,
                    "check": 0x31C3,
                },
            },
        ),
        "framing.elements.checksum.crc.width: a 16-bit CRC does not fill a u8",
    ),
    (
        "sign bit 0",
        "tiny",
        both(
            put("tables/regs/entries/position/encoding", "sign_magnitude"),
            put("tables/regs/entries/position/range", [-100, 100]),
            put("tables/regs/entries/position/sign_bit", 0),
        ),
        "tables.regs.entries.position.sign_bit: sign bit 0 is outside u16's bits 1..15",
    ),
    (
        "sign bit without sign magnitude",
        "tiny",
        put("tables/regs/entries/position/sign_bit", 3),
        "tables.regs.entries.position.sign_bit: `sign_bit` needs `encoding: sign_magnitude`",
    ),
    (
        "overlapping registers",
        "tiny",
        put("tables/regs/entries/speed/key", 1),
        "tables.regs.entries.speed.key: register speed at 0x01 overlaps position (0x00..0x01)",
    ),
    (
        "register key twice",
        "tiny",
        put("tables/regs/entries/speed/key", 0),
        "tables.regs.entries.speed.key: key 0 is already used by 'position'",
    ),
    (
        "status ok outside range",
        "tiny",
        put("commands/move/response/fields/ok", {"type": "u8", "range": [0, 1], "status": {"ok": 2}}),
        "commands.move.response.fields.ok.status.ok: 2 is outside the field's range 0..1",
    ),
    # --- references: every one resolves, or is an error line -----------------------------------------------------
    (
        "after typo",
        "tiny",
        put("commands/move/response/after", "timeX"),
        "commands.move.response.after: no request this response answers has an integer field 'timeX' (they have: angle, mode, time)",
    ),
    (
        "after in a request",
        "tiny",
        put("commands/move/request/after", "time"),
        "commands.move.request.after: `after` describes when a response is sent",
    ),
    (
        "start typo in request",
        "feetech",
        put("commands/reply/response/fields/data/start", "request.adress"),
        "commands.reply.response.fields.data.start: no request this response answers has an integer field 'adress' (they have: address, length)",
    ),
    (
        "start typo",
        "tiny",
        put("commands/write/request/fields/data/start", "adress"),
        "commands.write.request.fields.data.start: unknown field 'adress': `start` names an earlier integer field",
    ),
    (
        "start without table",
        "tiny",
        drop("commands/write/request/fields/data/table"),
        "commands.write.request.fields.data.start: `start` goes with `table:` (the bytes are a run of its registers)",
    ),
    (
        "size_from typo",
        "feetech",
        put("commands/reply/response/fields/data/size_from", "request.lenght"),
        "commands.reply.response.fields.data.size_from: no request this response answers has an integer field 'lenght' (they have: address, length)",
    ),
    (
        "size_from without request",
        "tiny",
        put("commands/read/response/fields/data/size_from", "length"),
        "commands.read.response.fields.data.size_from: `size_from: request.<field>` goes with `size: rest`",
    ),
    (
        "matching by typo",
        "tiny",
        put("matching/by", ["idd"]),
        "matching.by[0]: unknown field 'idd' (no frame element or field has it)",
    ),
    ("matching by a number", "tiny", put("matching/by", [1]), "matching.by[0]: expected text, got a number"),
    (
        "answered_by typo",
        "feetech",
        put("commands/ping/request/answered_by/command", "replay"),
        "commands.ping.request.answered_by.command: 'replay' is not a command with a response",
    ),
    (
        "answered_by in a response",
        "tiny",
        put("commands/move/response/answered_by", {"command": "read"}),
        "commands.move.response.answered_by: `answered_by` names the response that answers a request",
    ),
    (
        "answers typo",
        "tiny",
        put("commands/status/response/answers", "mvoe"),
        "commands.status.response.answers: unknown request 'mvoe' (expected one of: move, read, write, status)",
    ),
    (
        "optional_when parameter typo",
        "feetech",
        put("commands/write/request/answered_by/optional_when/parameter", "respons_level"),
        "commands.write.request.answered_by.optional_when.parameter: unknown table entry 'respons_level'",
    ),
    (
        "count typo",
        "tiny",
        put("commands/status/response/fields/values/count", "cuont"),
        "commands.status.response.fields.values: unknown field 'cuont': a count or size must be an earlier field of the same content",
    ),
    (
        "count is a float field",
        "tiny",
        put("commands/status/response/fields/count", "f32"),
        "commands.status.response.fields.values: 'count' must be an earlier integer field that nothing else derives",
    ),
    (
        "bytes size typo",
        "tiny",
        put("commands/write/request/fields/data/size", "lenght"),
        "commands.write.request.fields.data: unknown field 'lenght': a count or size must be an earlier field of the same content",
    ),
    (
        "enum typo",
        "tiny",
        put("commands/move/request/fields/mode/enum", "mdoe"),
        "commands.move.request.fields.mode.enum: unknown enum 'mdoe' (expected one of: mode)",
    ),
    (
        "flags typo",
        "tiny",
        put("commands/status/response/fields/alarms/flags", "alarm"),
        "commands.status.response.fields.alarms.flags: unknown flags 'alarm' (expected one of: alarms)",
    ),
    (
        "table typo",
        "tiny",
        put("commands/write/request/fields/data/table", "regz"),
        "commands.write.request.fields.data.table: unknown table 'regz' (expected one of: regs)",
    ),
    (
        "shared field typo",
        "tiny",
        put("commands/move/request/fields/extra", {"use": "tiem"}),
        "commands.move.request.fields.extra.use: unknown shared field 'tiem' (expected one of: none defined)",
    ),
    (
        "type typo",
        "tiny",
        put("commands/move/request/fields/extra", "uint16"),
        "commands.move.request.fields.extra: unknown type 'uint16' (did you mean 'u16'? expected one of u8, i8, u16, i16, u24, i24, u32, i32, u64, i64, f32, f64, bytes, string, cstring, array, group, table_value, table_block, uN/iN of 1..64 bits, or a field from `fields:`)",
    ),
    (
        "frame element flags typo",
        "feetech",
        put("framing/elements/error/flags", "error_stat"),
        "framing.elements.error.flags: unknown flags 'error_stat' (expected one of: error_status)",
    ),
    (
        "covers typo",
        "tiny",
        put("framing/elements/checksum/covers", ["idd", "content"]),
        "framing.elements.checksum.covers: unknown frame element 'idd' in the request frame (it has header, id, code, length, content, checksum)",
    ),
    (
        "device memory typo",
        "tiny",
        put("device/memory", "regz"),
        "device.memory: unknown table 'regz' (expected one of: regs)",
    ),
    (
        "device address typo",
        "tiny",
        put("device/address", "idd"),
        "device.address: unknown field 'idd': no request carries it (nor the frame)",
    ),
    (
        "device address names bytes",
        "tiny",
        put("device/address", "data"),
        "device.address: 'data' is no integer field, so it cannot hold a device id",
    ),
    ("device initial typo", "tiny", put("device/initial/volt", 1), "device.initial.volt: unknown memory entry 'volt'"),
    (
        "device command typo",
        "tiny",
        put("device/commands/mvoe", {"reads": []}),
        "device.commands.mvoe: unknown command 'mvoe' (or it has no request)",
    ),
    (
        "device reads typo",
        "tiny",
        put("device/commands/read/reads", ["dta"]),
        "device.commands.read.reads: read has no response field 'dta'",
    ),
    (
        "device writes typo",
        "tiny",
        put("device/commands/write/writes", ["dta"]),
        "device.commands.write.writes: write has no request field 'dta'",
    ),
    (
        "device moves state typo",
        "tiny",
        put("device/commands/move/moves/state", "angel"),
        "device.commands.move.moves.state: unknown state variable 'angel'",
    ),
    (
        "device moves target typo",
        "tiny",
        put("device/commands/move/moves/target", "angel"),
        "device.commands.move.moves.target: move has no request field, memory entry or state variable 'angel'",
    ),
    (
        "device reply typo",
        "tiny",
        put("device/reply/okk", 1),
        "device.reply.okk: unknown response field 'okk': no response carries it",
    ),
    (
        "device errors typo",
        "tiny",
        put("device/errors/out_of_range/okk", 1),
        "device.errors.out_of_range.okk: unknown response field 'okk': no response carries it",
    ),
    (
        "device status typo",
        "feetech",
        put("device/status/eror", "status"),
        "device.status.eror: unknown response field 'eror': no response carries it",
    ),
    (
        "device status entry typo",
        "feetech",
        put("device/status/error", "statu"),
        "device.status.error: unknown memory entry 'statu'",
    ),
    (
        "device id_entry typo",
        "feetech",
        put("device/id_entry", "idd"),
        "device.id_entry: unknown memory entry or state variable 'idd'",
    ),
    (
        "device kind typo",
        "rrc",
        put("device/commands/pwm_servo.set_position/kind", "pwm_servoz"),
        "device.commands.pwm_servo.set_position.kind: unknown device kind 'pwm_servoz' (not in `kinds:`)",
    ),
    (
        "device kind address typo",
        "rrc",
        put("device/kinds/pwm_servo/address", "servo_idd"),
        "device.kinds.pwm_servo.address: unknown field 'servo_idd': no request carries it (nor the frame)",
    ),
    (
        "device each typo",
        "feetech",
        put("device/commands/sync_write/each", "servoz"),
        "device.commands.sync_write.each: sync_write has no group field 'servoz'",
    ),
    (
        "example command typo",
        "tiny",
        put("examples/move_request/command", "mvoe"),
        "examples.move_request.command: unknown command 'mvoe'",
    ),
    (
        "example subcommand of a plain command",
        "tiny",
        put("examples/move_request/subcommand", "x"),
        "examples.move_request.subcommand: unknown subcommand 'x' of move",
    ),
    (
        "example erratum typo",
        "feetech",
        put("examples/ping_request/erratum", "ping_frame_stray_backtik"),
        "examples.ping_request.erratum: unknown erratum 'ping_frame_stray_backtik'",
    ),
    (
        "example request typo",
        "feetech",
        put("examples/ping_reply/request", "ping_requets"),
        "examples.ping_reply.request: unknown example 'ping_requets'",
    ),
    (
        "erratum example typo",
        "rrc",
        put("errata/doc003_crc_init/check/examples", ["nope"]),
        "errata.doc003_crc_init.check.examples: unknown example 'nope'",
    ),
    (  # found by `make stress` (tests/test_spec_fuzz.py): the reference crashed formatting None as hex
        "erratum checksum claimed null",
        "fashionstar",
        put("errata/ping_response_checksum_prose/check/claimed", None),
        "errata.ping_response_checksum_prose.check.claimed: expected the value the document prints, a number or "
        "text; got None",
    ),
    # --- names: reserved, generated, colliding after case-folding ----------------------------------------------------
    (
        "field named self",
        "tiny",
        rename("commands/move/request/fields/mode", "self"),
        "commands.move.request.fields.self: field name 'self' is reserved (a Python keyword or a name generated code uses)",
    ),
    (
        "field named class_",
        "tiny",
        rename("commands/move/request/fields/mode", "class_"),
        "commands.move.request.fields.class_: field name 'class_' is the Python name of a field 'class': call it 'class'",
    ),
    (
        "field named to_fields",
        "tiny",
        rename("commands/move/request/fields/mode", "to_fields"),
        "commands.move.request.fields.to_fields: field name 'to_fields' is reserved (a Python keyword or a name generated code uses)",
    ),
    (
        "field named isinstance",
        "tiny",
        rename("commands/move/request/fields/mode", "isinstance"),
        "commands.move.request.fields.isinstance: field name 'isinstance' is reserved (a Python keyword or a name generated code uses)",
    ),
    (
        "field named len",
        "tiny",
        rename("commands/move/request/fields/mode", "len"),
        "commands.move.request.fields.len: field name 'len' is reserved (a Python keyword or a name generated code uses)",
    ),
    (
        "field named reply",
        "tiny",
        rename("commands/move/request/fields/mode", "reply"),
        "commands.move.request.fields.reply: field name 'reply' is reserved (a Python keyword or a name generated code uses)",
    ),
    (
        "field named request",
        "tiny",
        rename("commands/move/request/fields/mode", "request"),
        "commands.move.request.fields.request: field name 'request' is reserved (a Python keyword or a name generated code uses)",
    ),
    (
        "enum named like the simulator",
        "tiny",
        put("enums/tiny_simulator", {"values": {"a": 0}}),
        "enums.tiny_simulator: generated class name TinySimulator is already used by protocol",
    ),
    (
        "enum named like a struct",
        "tiny",
        put("enums/move_request_content", {"values": {"a": 0}}),
        "commands.move.request: generated class name MoveRequestContent is already used by enums.move_request_content",
    ),
    (
        "field named with capitals",
        "tiny",
        rename("commands/move/request/fields/mode", "Mode"),
        "commands.move.request.fields.Mode: field name 'Mode' must be a lower-case identifier (a-z, 0-9, _; starting with a letter)",
    ),
    (
        "field named with a dash",
        "tiny",
        rename("commands/move/request/fields/mode", "mo-de"),
        "commands.move.request.fields.mo-de: field name 'mo-de' must be a lower-case identifier (a-z, 0-9, _; starting with a letter)",
    ),
    (
        "enum named direction",
        "tiny",
        put("enums/direction", {"values": {"a": 0}}),
        "enums.direction: generated name Direction would shadow the Direction that generated code uses; rename it",
    ),
    (
        "enum named message",
        "tiny",
        put("enums/message", {"values": {"a": 0}}),
        "enums.message: generated name Message would shadow the Message that generated code uses; rename it",
    ),
    (
        "enum named stream_parser",
        "tiny",
        put("enums/stream_parser", {"values": {"a": 0}}),
        "enums.stream_parser: generated name StreamParser would shadow the StreamParser that generated code uses; rename it",
    ),
    (
        "enum named value_error",
        "tiny",
        put("enums/value_error", {"values": {"a": 0}}),
        "enums.value_error: generated name ValueError would shadow the ValueError that generated code uses; rename it",
    ),
    (
        "enum named like the client",
        "tiny",
        put("enums/tiny_client", {"values": {"a": 0}}),
        "enums.tiny_client: generated class name TinyClient is already used by protocol",
    ),
    (
        "enum named like the asyncio client",
        "tiny",
        put("enums/async_tiny_client", {"values": {"a": 0}}),
        "enums.async_tiny_client: generated class name AsyncTinyClient is already used by protocol",
    ),
    (
        "enum named like an asyncio group class",
        "rrc",
        put("enums/async_bus_servo_commands", {"values": {"a": 0}}),
        "commands.bus_servo: generated class name AsyncBusServoCommands is already used by enums.async_bus_servo_commands",
    ),
    (
        "flags named like a message",
        "tiny",
        put("flags/move_request", {"bits": {"a": 0}}),
        "commands.move.request: generated class name MoveRequest is already used by flags.move_request",
    ),
    (
        "enum named like a group item",
        "tiny",
        put("enums/values_item", {"values": {"a": 0}}),
        None,  # the group's item class is named after its place (StatusResponseValuesItem)
    ),
    (
        "protocol serial",
        "tiny",
        put("protocol", "serial"),
        "protocol: protocol 'serial' would shadow the module 'serial' (pick another package name)",
    ),
    (
        "protocol os",
        "tiny",
        put("protocol", "os"),
        "protocol: protocol 'os' would shadow the module 'os' (pick another package name)",
    ),
    (
        "protocol construct",
        "tiny",
        put("protocol", "construct"),
        "protocol: protocol 'construct' would shadow the module 'construct' (pick another package name)",
    ),
    (
        "protocol docs",
        "tiny",
        put("protocol", "docs"),
        "protocol: protocol 'docs' would shadow the module 'docs' (pick another package name)",
    ),
    (
        "protocol json",
        "tiny",
        put("protocol", "json"),
        "protocol: protocol 'json' would shadow the module 'json' (pick another package name)",
    ),
    (
        "protocol serialspec",
        "tiny",
        put("protocol", "serialspec"),
        "protocol: protocol 'serialspec' would shadow the module 'serialspec' (pick another package name)",
    ),
    (
        "protocol with capitals",
        "tiny",
        put("protocol", "Tiny"),
        "protocol: protocol 'Tiny' must be a lower-case identifier (a-z, 0-9, _; starting with a letter)",
    ),
    (
        "protocol keyword",
        "tiny",
        put("protocol", "import"),
        "protocol: protocol 'import' is reserved (a Python keyword or a name generated code uses)",
    ),
    (
        "table named serial",
        "tiny",
        both(
            rename("tables/regs", "serial"),
            put("device/memory", "serial"),
            put("commands/read/response/fields/data/table", "serial"),
            put("commands/write/request/fields/data/table", "serial"),
        ),
        "tables.serial: generated name SERIAL would shadow the SERIAL that generated code uses; rename it",
    ),
    (
        "enum labels differing in case",
        "tiny",
        put("enums/mode/values/FAST", 2),
        "enums.mode.values.FAST: enum label 'FAST' is the same as 'fast' once upper-cased",
    ),
    (
        "flag names differing in case",
        "tiny",
        put("flags/alarms/bits/HOT", 2),
        "flags.alarms.bits.HOT: flag name 'HOT' is the same as 'hot' once upper-cased",
    ),
    (
        "enum label keyword",
        "tiny",
        put("enums/mode/values/class", 2),
        "enums.mode.values.class: enum label 'class' must be an identifier",
    ),
    (
        "enum label with a dash",
        "tiny",
        put("enums/mode/values/very-fast", 2),
        "enums.mode.values.very-fast: enum label 'very-fast' must be an identifier",
    ),
    ("command named like a runtime method", "tiny", rename("commands/status", "close"), None),
    (
        "group class twice",
        "tiny",
        put("commands/read/request/fields/values", {"type": "group", "count": "rest", "fields": {"w": "u8"}}),
        None,  # the second definition's item class is named after its place (StatusResponseValuesItem)
    ),
    (
        "table named like an enum class",
        "tiny",
        put("enums/regs_name", {"values": {"a": 0}}),
        "tables.regs: generated class name RegsName is already used by enums.regs_name",
    ),
    # --- text: control characters refused, everything else inert -------------------------------------------------
    ("hostile title", "tiny", put("title", HOSTILE), None),
    (
        "hostile descriptions",
        "tiny",
        both(
            put("description", HOSTILE),
            put("commands/move/description", HOSTILE),
            put("commands/move/request/fields/angle/description", HOSTILE),
        ),
        None,
    ),
    ("hostile unit", "tiny", put("commands/move/request/fields/angle/unit", HOSTILE), None),
    ("hostile enum text", "tiny", put("enums/mode/values/fast", {"value": 1, "text": HOSTILE}), None),
    (
        "hostile table text",
        "tiny",
        both(
            put("tables/regs/description", HOSTILE),
            put("tables/regs/entries/speed/description", HOSTILE),
            put("tables/regs/entries/speed/unit", HOSTILE),
        ),
        None,
    ),
    ("hostile example source", "tiny", put("examples/move_request/source", HOSTILE), None),
    ("hostile serial notes", "tiny", put("serial/notes", HOSTILE), None),
    ("trailing backslash", "tiny", put("commands/move/title", "Move \\"), None),
    ("triple quotes", "tiny", put("commands/move/description", "ends with '''\"\"\""), None),
    (
        "matching by the command element's name",  # the tutorial matches by `command`; a spec of one's own names it
        "tiny",
        put("matching", {"by": ["id", "code"]}),
        "matching.by[1]: 'code' is the command element: a reply's command is matched as `command`",
    ),
    (
        "matching by the checksum",
        "tiny",
        put("matching", {"by": ["id", "checksum"]}),
        "matching.by[1]: 'checksum' is the frame's checksum, not a value a reply repeats from its request",
    ),
    (
        "example with a wrong 16-bit checksum",  # shown as wide as it is: 0x0000, not 0x00
        "tiny",
        both(
            put("framing/elements/checksum/type", "u16"),
            put("examples/move_request/printed", "AA 55 01 01 05 64 00 01 0A 00 00 00"),
        ),
        "examples.move_request: the frame does not decode: bad checksum: the frame has 0x0000, its bytes give 0x0076",
    ),
    (
        "probe without a reply",
        "tiny",
        put("commands/write/probe", True),
        "commands.write.probe: a probe needs a reply: a `response`, or `answered_by` on its request",
    ),
    ("long description", "tiny", put("description", "word " * 2000), None),
    (
        "description over the text limit",
        "tiny",
        put("commands/move/description", "word " * 2000 + "w"),
        "commands.move.description: text of 10,001 characters (at most 10,000)",
    ),
    (
        "file over the size limit",
        "tiny",
        Text(lambda t: (t + "# " + "x" * 1_000_000 + "\n").encode()),
        "the file is larger than 1,000,000 bytes, the most a spec may have",
    ),
    (
        "nul in a description",
        "tiny",
        put("commands/move/description", "a\x00b"),
        "commands.move.description: control character U+0000 in text (not allowed in a spec)",
    ),
    (
        "escape in an enum text",
        "tiny",
        put("enums/mode/values/fast", {"value": 1, "text": "\x1b[2J"}),
        "enums.mode.values.fast.text: control character U+001B in text (not allowed in a spec)",
    ),
    # --- examples and errata are run through the generated codec --------------------------------------------------
    (
        "example checksum wrong",
        "tiny",
        put("examples/move_request/printed", "AA 55 01 01 05 64 00 01 0A 00 73"),
        "examples.move_request: the frame does not decode: bad checksum: the frame has 0x73, its bytes give 0x76",
    ),
    (
        "example value wrong",
        "tiny",
        put("examples/move_request/fields/angle", 101),
        "examples.move_request: the frame decodes to other values: angle is 100, not 101",
    ),
    (
        "example value by its enum name",  # a newcomer's first example: the member's name where the wire value goes
        "tiny",
        put("examples/move_request/fields/mode", "fast"),
        "examples.move_request: the frame decodes to other values: mode is 1, not 'fast' (examples record wire values: "
        "write 1, which is fast)",
    ),
    (
        "example given as `frame` without `printed`",  # what a newcomer writes first
        "tiny",
        rename("examples/move_request/printed", "frame"),
        "examples.move_request: missing key 'printed' (the frame as the document prints it, e.g. `printed: AA 01 02 "
        "01 32 DE`; `frame` only where the bytes sent differ from it)",
    ),
    (
        "example without `source`",  # found writing LX-16A: which source, and that `sources:` names them, was unsaid
        "tiny",
        drop("examples/move_request/source"),
        "examples.move_request: missing key 'source' (the document and section the frame is printed in, e.g. "
        "`source: manual 4.2`; a top-level `sources:` may name each document)",
    ),
    (
        "example value missing",
        "tiny",
        drop("examples/move_request/fields/time"),
        "examples.move_request: the frame decodes to other values: time=10 is not recorded",
    ),
    (
        "example value extra",
        "tiny",
        put("examples/move_request/fields/speed", 1),
        "examples.move_request: the frame decodes to other values: speed is not in the frame",
    ),
    (
        "a mapping's entries one level too high",  # one mistake, one line (not also one per entry)
        "tiny",
        replace_text(
            "    entries:\n      position: {key: 0, type: u16, range: [0, 1000], default: 0}\n"
            "      speed: {key: 2, type: u8, range: [0, 100], default: 10}\n      volts: {key: 3, type: u8, access: r}\n",
            "    position: {key: 0, type: u16, range: [0, 1000], default: 0}\n"
            "    speed: {key: 2, type: u8, range: [0, 100], default: 10}\n    volts: {key: 3, type: u8, access: r}\n",
        ),
        "tables.regs: missing key 'entries': position, speed, volts belong one level lower, under `entries:`",
    ),
    (
        "a request's fields without `fields:`",
        "tiny",
        put("commands/status/request", {"angle": "u16", "speed": {"type": "u8"}}),
        "commands.status.request: angle, speed belong one level lower, under `fields:`",
    ),
    (
        "a misspelt key beside an absent mapping is a misspelling, not a stray entry",
        "tiny",
        put("commands/status/request", {"descripton": "Status"}),
        "commands.status.request.descripton: unknown key 'descripton' (did you mean 'description'? expected one of "
        "description, fields, text, "
        "optional, unsolicited, values_only, answers, error_reply, optional_when, after, request_code, answered_by, "
        "default, source)",
    ),
    (
        "a comma in flow-style text",  # the rest of the text after the comma reads as a key
        "tiny",
        replace_text('unit: "0.1°"', "unit: tenths, of a degree"),
        "commands.move.request.fields.angle.of a degree: unknown key 'of a degree' (expected one of type, use, label, description, description_cn, unit, scale, offset, range, const, default, enum, flags, bits, encoding, varint, endian, size, count, of, bit_order, pad, count_from, value, fields, table, key, start, size_from, select, expect_size, inferred, precision, width, base, case, letters, max_count, status; a comma inside `{...}` ends a value: quote text that holds one)",
    ),
    (
        "example records a computed count as the frame holds it",  # documents print counts and constants
        "tiny",
        put("examples/status_reply", _status_reply(count=1)),
        None,
    ),
    (
        "example records a computed count wrong",
        "tiny",
        put("examples/status_reply", _status_reply(count=2)),
        "examples.status_reply: the frame decodes to other values: status response: count is given as 2, but it is computed: 1 (leave it out)",
    ),
    (
        "example of another command",
        "tiny",
        put("examples/move_request/command", "status"),
        "examples.move_request: the frame decodes as move, not status",
    ),
    (
        "example truncated",
        "tiny",
        put("examples/move_request/printed", "AA 55 01 01 05 64 00"),
        "examples.move_request: the frame does not decode: length says 5 but the frame holds 1",
    ),
    (
        "example not hex",
        "tiny",
        put("examples/move_request/printed", "AA 55 zz"),
        "examples.move_request.printed: not a frame: 'zz' is not a hex byte",
    ),
    (
        "example value out of range",
        "feetech",
        put("examples/ping_request/fields/id", 300),
        "examples.ping_request: the frame decodes to other values: id is 1, not 300",
    ),
    (
        "erratum frame does not fail",
        "feetech",
        put("errata/ping_frame_stray_backtick/check/frame", "FF FF 01 02 01 FB"),
        "errata.ping_frame_stray_backtick.check: the frame decodes: it does not fail",
    ),
    (
        "erratum fails otherwise",
        "feetech",
        put("errata/ping_frame_stray_backtick/check/error", "checksum"),
        "errata.ping_frame_stray_backtick.check: the frame fails with \"'FB`' is not a hex byte\", not 'checksum'",
    ),
    (
        "erratum decodes otherwise",
        "feetech",
        put("errata/write_length_formula/check/fields", {"id": 2, "address": 0x2A, "data": "00 08 00 00 e8 03"}),
        "errata.write_length_formula.check: the frame decodes to other values: id is 1, not 2",
    ),
    (
        "erratum checksum actual wrong",
        "fashionstar",
        put("errata/ping_response_checksum_prose/check/actual", 0),
        "errata.ping_response_checksum_prose.check: the frame ends in 0x26: `actual` must be it, and differ from `claimed`",
    ),
    # --- simulators: a reply that cannot be built is found at generate time -------------------------------------------
    (
        "reply with bits",
        "tiny",
        put("commands/move/response/fields/ok", {"type": "u8", "bits": {"done": {"bits": 0}}}),
        None,
    ),
    ("reply with fixed bytes", "tiny", put("commands/move/response/fields/ok", {"type": "bytes", "size": 2}), None),
    (
        "reply with a group",
        "tiny",
        put("commands/move/response/fields/ok", {"type": "group", "count": 2, "fields": {"x": "u8"}}),
        None,
    ),
    # --- valid specs that used to generate broken code -----------------------------------------------------------
    (
        "minimal spec",
        "tiny",
        both(
            *(drop(k) for k in ("enums", "flags", "tables", "device", "examples", "matching")),
            drop("commands/read"),
            drop("commands/write"),
            put("commands/status/response/fields/alarms", "u8"),
            put("commands/move/request/fields/mode", "u8"),
        ),
        None,
    ),
    ("register named id", "tiny", rename("tables/regs/entries/speed", "id"), None),
]
