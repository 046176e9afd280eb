"""Every alternative the language reference documents, through every output.

Each case is a small spec that uses one alternative (a field type, an item type, a size or count form, an
encoding, a byte order, a frame element role or shape). Each spec goes through every output: the front end and
every target's files (with their verification), the markdown reference, the CLI's decode --json, the codec (random
valid messages round trip, also through JSON), construct's structs (they agree with the codec), the stream parser
(random frames among garbage, fed in random pieces, give what byte-at-a-time feeding gives) and the client against
the generated simulator on a real pseudo-terminal. The coverage tests read the alternatives from the grammar, so an
alternative the reference gains without a case here fails the suite: a documented key cannot crash an output
unnoticed.
"""

from __future__ import annotations

import contextlib
import copy
import importlib
import io
import json
import os
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
import yaml
from conftest import Generated, examples, fitted
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec import cli
from serialspec.backends import Unsupported, emitters
from serialspec.backends.python.memory import imported
from serialspec.encodings import bit_run, varint
from serialspec.lang import SpecErrors, grammar
from serialspec.lang.loader import load_text
from serialspec.lang.model import (
    Direction,
    Message,
    Protocol,
    leading_constant,
    refusals_of,
    replies_by_request,
    reply_to,
)
from serialspec.lang.passes.fields import FIELD_KINDS
from serialspec.lang.resolve import resolve
from serialspec.runtime.errors import DecodeError, EncodeError
from serialspec.runtime.transport import Bus
from serialspec.transforms import transforms
from strategies import message_fields
from test_codec import check_against_construct

HEADER = "AA 55"
# The frame of most cases: header, address, command, length, content, an 8-bit sum.
FRAMING: dict[str, Any] = {
    "elements": {
        "header": {"role": "header", "value": HEADER},
        "id": {"role": "address", "type": "u8", "range": [0, 253], "broadcast": 254},
        "code": {"role": "command", "type": "u8"},
        "length": {"role": "length", "type": "u8"},
        "content": {"role": "content"},
        "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["id", "content"]},
    }
}
SHARED: dict[str, Any] = {
    "enums": {"mode": {"values": {"slow": 0, "fast": 1, "off": 7}}},
    "flags": {"alarms": {"bits": {"hot": 0, "stall": 1, "low": 7}}},
    "tables": {
        "regs": {
            "key": "address",
            "entries": {
                "position": {"key": 0, "type": "u16", "range": [0, 1000], "default": 0},
                "speed": {"key": 2, "type": "u8", "range": [0, 100], "default": 10},
                "torque": {"key": 3, "type": "i16", "default": 0},
            },
        }
    },
    "fields": {"angle": {"type": "i16", "range": [-900, 900], "unit": "0.1°", "scale": 0.1}},
}


@dataclass(frozen=True)
class Case:
    """One alternative: the request and response fields of the one command `probe` (or a whole framing)."""

    request: dict[str, Any]
    response: dict[str, Any]
    framing: dict[str, Any] | None = None
    commands: dict[str, Any] | None = None  # more commands beside `probe`
    request_keys: dict[str, Any] | None = None  # more keys of probe's request (answered_by)
    device: dict[str, Any] | None = None  # more of the `device:` section


def same(fields: dict[str, Any]) -> Case:
    return Case(fields, copy.deepcopy(fields))


def with_count(kind: dict[str, Any]) -> dict[str, Any]:
    return {"n": {"type": "u8", "range": [0, 6]}, "items": {**kind, "count": "n"}}


# the scalar types four to a case (a field each: every output sees each type as it does alone, at a quarter of the
# generations and compiles), and the short form
_TYPES = grammar.FIELD_SCALAR_TYPES
SCALAR = {
    " ".join(_TYPES[i : i + 4]): same({f"v_{t}": {"type": t} for t in _TYPES[i : i + 4]})
    for i in range(0, len(_TYPES), 4)
} | {"u8 (short form)": same({"v": "u8"})}
BIT_RUNS: dict[str, Any] = {
    "msg": {"type": "u12", "const": 1005},
    "station": {"type": "u12", "range": [0, 4000], "default": 7},
    "year": "u6",
    "flag": {"type": "u1", "enum": "mode", "range": [0, 1]},
    "x": {"type": "i38", "scale": 0.0001, "offset": 1, "unit": "m"},
    "q": {"type": "u3", "value": "year % 8"},
    "n": "u4",
    "b": "i8",
    "c": "i4",
    "items": {"type": "group", "count": "n", "fields": {"h": "u5", "l": "i11"}},
    "tail": "u16",
}
ITEMS = {f"array of {t}": same({"items": {"type": "array", "of": t, "count": 3}}) for t in grammar.FIELD_SCALAR_TYPES}
CASES: dict[str, Case] = {
    **SCALAR,
    **ITEMS,
    "array of bit": same({"bits": {"type": "array", "of": "bit", "count": 16}}),
    "array of u11, bit_order: lsb_first": same(
        {"rc": {"type": "array", "of": "u11", "count": 16, "bit_order": "lsb_first", "range": [172, 1811]}}
    ),
    "array of i5, bit_order: msb_first": same(
        {"v": "u8", "items": {"type": "array", "of": "i5", "count": 3, "bit_order": "msb_first"}, "tail": "u16"}
    ),
    "array of u24, endian: big": same({"items": {"type": "array", "of": "u24", "count": 2, "endian": "big"}}),
    "array of bit, count field": same(with_count({"type": "array", "of": "bit"})),
    "array, count field": same(with_count({"type": "array", "of": "u16"})),
    "array, count rest": same({"items": {"type": "array", "of": "u16", "count": "rest"}}),
    "array of i64, count rest": same({"items": {"type": "array", "of": "i64", "count": "rest"}}),
    "array, size field": same(
        {"size": {"type": "u8", "value": "2 * len(items)"}, "items": {"type": "array", "of": "u16", "size": "size"}}
    ),
    "bytes, fixed size": same({"data": {"type": "bytes", "size": 4}}),
    "bytes, size rest": same({"data": {"type": "bytes", "size": "rest"}}),
    "bytes, size field": same({"n": "u8", "data": {"type": "bytes", "size": "n"}, "tail": "u8"}),
    "bytes, size field of u64": same({"n": "u64", "data": {"type": "bytes", "size": "n"}, "tail": "u8"}),
    # len() of bytes and of a fixed array in a value (JBD's password size: `value: len(password)`): C's `_len`, a count
    "value: len() of bytes and of a fixed array": same(
        {
            "n": {"type": "u8", "value": "len(data)"},
            "data": {"type": "bytes", "size": "n"},
            "k": {"type": "u8", "value": "len(fixed) + 1"},
            "fixed": {"type": "array", "of": "u8", "count": 3},
        }
    ),
    "array, count field of u64": same({"n": "u64", "items": {"type": "array", "of": "u16", "count": "n"}}),
    # counts and sizes by expression (lang/counts.py): n stays in the message; a frame with n = 0 has no count
    "count and size expressions": same(
        {
            "n": {"type": "u8", "range": [1, 4], "default": 2},
            "items": {"type": "array", "of": "u16", "count": "n - 1"},
            "bits": {"type": "array", "of": "bit", "count": "2 * n"},
            "g": {
                "type": "group",
                "count": "n + 1",
                "fields": {"a": "u8", "k": {"type": "u8", "range": [0, 5]}, "d": {"type": "bytes", "size": "k % 3"}},
            },
            "data": {"type": "bytes", "size": "max(n, 2)"},
            "name": {"type": "string", "size": "n * 2"},
            "tail": "u8",
        }
    ),
    "string, fixed size": same({"name": {"type": "string", "size": 6}}),
    "string, fixed size, pad": same({"name": {"type": "string", "size": 8, "pad": "00"}, "v": "u8"}),
    "strings in group items": same(
        {
            "g": {
                "type": "group",
                "count": 2,
                "fields": {"s": {"type": "string", "size": 3}, "t": {"type": "string", "size": 4, "pad": "20"}},
            },
            "n": "u8",
            "h": {
                "type": "group",
                "count": "n",
                "fields": {"k": "u8", "s": {"type": "string", "size": "k"}, "c": "cstring"},
            },
        }
    ),
    "string, size rest": same({"name": {"type": "string", "size": "rest"}}),
    "string, size field": same({"n": "u8", "name": {"type": "string", "size": "n"}, "tail": "u8"}),
    "cstring": same({"name": {"type": "cstring"}, "tail": "u16"}),
    "group, fixed count": same({"g": {"type": "group", "count": 2, "fields": {"a": "u8", "b": "i16"}}}),
    "group, count field": same(with_count({"type": "group", "fields": {"a": "u8", "b": "u16"}})),
    "group, count rest": same({"g": {"type": "group", "count": "rest", "fields": {"a": "u8", "b": "u16"}}}),
    "table_value": same({"address": "u8", "value": {"type": "table_value", "table": "regs", "key": "address"}}),
    "table_block": same({"block": {"type": "table_block", "table": "regs", "expect_size": 5}}),
    "bytes holding registers": Case(
        {"address": "u8", "data": {"type": "bytes", "size": "rest", "table": "regs", "start": "address"}},
        {"ok": "u8"},
    ),
    "bytes sized by the request": Case(
        {"address": "u8", "length": {"type": "u8", "range": [1, 5]}},
        {
            "data": {
                "type": "bytes",
                "size": "rest",
                "table": "regs",
                "start": "request.address",
                "size_from": "request.length",
            }
        },
    ),
    "array counted by the request": Case(
        {"count": {"type": "u8", "range": [1, 16]}},
        {
            "byte_count": {"type": "u8", "value": "ceil(len(coils) / 8)"},
            "coils": {"type": "array", "of": "bit", "size": "byte_count", "count_from": "request.count"},
        },
    ),
    "enum": same({"mode": {"type": "u8", "enum": "mode"}}),
    "flags": same({"alarms": {"type": "u8", "flags": "alarms"}}),
    "bits": same({"word": {"type": "u16", "bits": {"hi": {"bits": [15, 12]}, "mode": {"bits": 2, "enum": "mode"}}}}),
    "bits and groups defined apart in two commands": Case(
        {
            "word": {"type": "u8", "bits": {"hi": {"bits": [7, 4]}}},
            "g": {"type": "group", "count": 1, "fields": {"a": "u8"}},
        },
        {"v": "u8"},
        commands={
            "other": {
                "code": 2,
                "request": {
                    "fields": {
                        "word": {"type": "u8", "bits": {"lo": {"bits": 0}}},
                        "g": {"type": "group", "count": 1, "fields": {"b": "i8"}},
                    }
                },
            }
        },
    ),
    # a few bits a byte (encodings/low_bits.py): 7 (Pololu, MIDI) or a nibble (Sony VISCA), the highest group first
    # in big-endian order; a signed type holds the two's complement of the bits it carries (an i32 of nibbles: 16)
    "encoding: plain, seven_bit, nibbles": same(
        {
            "v": {"type": "i16", "encoding": "plain"},
            "t": {"type": "u16", "encoding": "seven_bit"},
            "w": "u8",
            "q": {"type": "i16", "encoding": "seven_bit", "endian": "big"},
            "z": {"type": "u32", "encoding": "nibbles", "endian": "big"},
            "p": {"type": "i32", "encoding": "nibbles", "range": [-32768, -1], "default": -2},  # (negative, always)
            "d": {"type": "i8", "encoding": "nibbles"},
            "o": {"type": "u24", "encoding": "nibbles", "endian": "big", "range": [0, 4000]},
            # 8-byte words: C's uint64_t, the dissector's UInt64/Int64
            "u": {"type": "u64", "encoding": "nibbles", "endian": "big"},
            "i": {"type": "i64", "encoding": "nibbles", "range": [-(2**31), -1], "default": -3},
            # seven_bit's 56 bits: past a Lua number's 53 exact ones (none of these values is a double)
            "s": {"type": "u64", "encoding": "seven_bit", "range": [2**56 - 7, 2**56 - 1], "default": 2**56 - 1},
            "m": {
                "type": "i64",
                "encoding": "seven_bit",
                "range": [-(2**55) + 1, -(2**55) + 3],
                "default": -(2**55) + 1,
            },
            "g": {"type": "group", "count": 2, "fields": {"n": {"type": "i16", "encoding": "nibbles"}}},
        }
    ),
    # text of 14-bit characters (Firmata's STRING_DATA): fixed-size, in a group's items, and rest
    "encoding: seven_bit on a string": same(
        {
            "name": {"type": "string", "size": 4, "encoding": "seven_bit"},
            "g": {"type": "group", "count": 2, "fields": {"n": {"type": "string", "size": 2, "encoding": "seven_bit"}}},
            "text": {"type": "string", "size": "rest", "encoding": "seven_bit"},
        }
    ),
    # integers in as many bytes as they need: LEB128 (protobuf), zigzag, Kangaroo's 6 bits a byte with the sign in bit
    # 0, MIDI's highest group first; a fixed field after them and bytes to the end; the reply's in a group's items
    "encoding: varint": Case(
        {
            "a": {"type": "u32", "encoding": "varint"},
            "z": {"type": "i64", "encoding": "varint", "varint": {"sign": "zigzag"}},
            "k": {
                "type": "i32",
                "encoding": "varint",
                "varint": {"bits": 6, "sign": "low_bit"},
                "range": [-100000, 100000],
                "default": 5,
                "unit": "mm",
            },
            "m": {"type": "u32", "encoding": "varint", "varint": {"order": "high_first"}, "range": [0, 0x0FFFFFFF]},
            "w": "u16",
            "tail": {"type": "bytes", "size": "rest"},
        },
        {  # a signed varint only in a group's items
            "w": "u8",
            "g": {
                "type": "group",
                "count": "rest",
                "fields": {"x": {"type": "i16", "encoding": "varint", "varint": {"sign": "zigzag"}}, "y": "u8"},
            },
        },
    ),
    "encoding: sign_magnitude": same({"v": {"type": "i16", "encoding": "sign_magnitude"}}),
    # bit fields (uN/iN of any width) packed MSB first into runs of whole bytes, every integer key on them, a
    # byte-sized integer inside an open run, a run in a group's items; in RTCM 3's frame: a 10-bit length after 6
    # reserved zero bits (read as a big-endian u16 length) and a 3-byte CRC-24Q (a u24 checksum)
    "type: u12, i38 (bit runs), a u24 checksum": Case(
        BIT_RUNS,
        copy.deepcopy(BIT_RUNS),
        {
            "elements": {
                "header": {"role": "header", "value": "D3"},
                "code": {"role": "command", "type": "u8"},
                "length": {"role": "length", "type": "u16", "endian": "big"},
                "content": {"role": "content"},
                "checksum": {
                    "role": "checksum",
                    "type": "u24",
                    "endian": "big",
                    "algorithm": "crc",
                    "covers": ["header", "content"],
                    "crc": {
                        "width": 24,
                        "poly": 0x864CFB,
                        "init": 0,
                        "refin": False,
                        "refout": False,
                        "xorout": 0,
                        "check": 0xCDE703,
                    },
                },
            }
        },
    ),
    "endian: big": same({"v": {"type": "u32", "endian": "big"}, "w": {"type": "f32", "endian": "big"}}),
    "endian: little": same({"v": {"type": "u32", "endian": "little"}}),
    "value (derived)": same({"a": "u8", "b": "u8", "total": {"type": "u16", "value": "a + b * 2"}}),
    "const": same({"sel": {"type": "u8", "const": 3}, "v": "u8"}),
    "default": same({"v": {"type": "u8", "default": 20, "range": [0, 50]}}),
    "range, unit, scale": same({"v": {"type": "i16", "range": [-100, 100], "unit": "mV", "scale": 0.5}}),
    "scale and offset": same({"alt": {"type": "u16", "unit": "m", "scale": 1, "offset": -1000}, "v": "u24"}),
    "field named type": same({"type": "u8", "v": {"type": "u24", "endian": "big"}}),
    # Python keywords as field names (the attribute is `class_`, JSON keeps `class`), referenced by a count, a size
    # and an expression, inside a group item too; two messages each with a `flags` field of their own bit fields
    "fields named after Python keywords": Case(
        {
            "class": "u8",
            "from": "u8",
            "in": {"type": "bytes", "size": "from"},
            "flags": {"type": "u8", "bits": {"a": {"bits": 0}, "b": {"bits": [3, 1]}}},
        },
        {
            "is": {"type": "u8", "value": "len(pass)"},
            "pass": {"type": "array", "of": "u16", "count": "is"},
            "flags": {"type": "u8", "bits": {"c": {"bits": 7}}},
            "g": {"type": "group", "count": 2, "fields": {"lambda": "i8", "with": {"type": "u8", "enum": "mode"}}},
        },
    ),
    "use (shared field)": same({"angle": {"use": "angle"}, "also": "angle"}),
    "status": Case({"v": "u8"}, {"success": {"type": "u8", "status": {"ok": 1}}, "v": "u8"}),
    "answered_by another code, refused_by, request_code": Case(
        {"v": {"type": "u8", "range": [0, 100]}},
        {"v": "u8"},
        commands={
            "ack": {"code": 5, "response": {"request_code": "acked", "fields": {"acked": "u8", "n": "u16"}}},
            "nak": {"code": 6, "response": {"request_code": "refused", "fields": {"refused": "u8"}}},
        },
        request_keys={"answered_by": {"command": "ack", "refused_by": ["nak"]}},
    ),
    "answered_by command_in (a request asking for any command's reply by its code)": Case(
        {},  # the device answers a command asked for as that command's request with no content
        {"v": "u8", "w": "i16"},
        commands={
            "ask": {"code": 7, "request": {"fields": {"wanted": "u16"}, "answered_by": {"command_in": "wanted"}}}
        },
    ),
    # frame shapes: every element role, multi-byte elements in both byte orders, stuffing, alternative layouts
    "frame: trailer, constant, u16 big-endian length and checksum": Case(
        {"v": "u16"},
        {"v": "u16"},
        {
            "elements": {
                "header": {"role": "header", "value": HEADER},
                "reserved": {"role": "constant", "value": "00"},
                "length": {
                    "role": "length",
                    "type": "u16",
                    "endian": "big",
                    "counts": ["code", "checksum"],
                    # a candidate whose length is outside it is no frame (3: code and checksum, no content)
                    "range": [3, 1000],
                },
                "code": {"role": "command", "type": "u8"},
                "content": {"role": "content"},
                "checksum": {
                    "role": "checksum",
                    "type": "u16",
                    "endian": "big",
                    "algorithm": "sum",
                    "covers": ["length", "content"],
                },
                "trailer": {"role": "trailer", "value": "0D 0A"},
            }
        },
    ),
    "frame: status flags, length adds": Case(
        {"v": "u8"},
        {"v": "u8"},
        {
            "elements": {
                "header": {"role": "header", "value": HEADER},
                "id": {"role": "address", "type": "u8"},
                "length": {"role": "length", "type": "u8", "adds": 2, "range": [3, 200]},
                "code": {"role": "command", "type": "u8", "value": {"response": "00"}},
                "status": {"role": "status", "type": "u8", "flags": "alarms", "directions": ["response"]},
                "content": {"role": "content"},
                "checksum": {
                    "role": "checksum",
                    "type": "u8",
                    "algorithm": "sum",
                    "invert": True,
                    "covers": ["id", "content"],
                },
            }
        },
    ),
    # a status whose success is not 0 (Trinamic TMCL: 100 done, 101 stored in EEPROM, below 100 an error)
    "frame: a status with its success values (ok)": Case(
        {"v": "u8"},
        {"v": "u16"},
        {
            "elements": {
                "header": {"role": "header", "value": HEADER},
                "id": {"role": "address", "type": "u8"},
                "status": {"role": "status", "type": "u8", "ok": [100, 101], "directions": ["response"]},
                "code": {"role": "command", "type": "u8"},
                "length": {"role": "length", "type": "u8"},
                "content": {"role": "content"},
                "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["id", "content"]},
            }
        },
        device={"reply": {"status": 100}},
    ),
    # sub-commands picked by a selector of two bytes inside the content, at another offset in each direction (HCI's
    # Command Complete: its u16 opcode after num_packets); the Python decoder once read its first byte alone
    "sub-commands by a u16 selector": Case(
        {"v": "u8"},
        {"v": "u8"},
        commands={
            "op": {
                "code": 7,
                "selector": {"type": "u16", "name": "opcode", "offset": {"request": 0, "response": 1}},
                "subcommands": {
                    "reset": {
                        "code": 0x0C03,
                        "request": {"fields": {}},
                        "response": {"fields": {"packets": "u8", "status": "u8"}},
                    },
                    "version": {
                        "code": 0x1001,
                        "request": {"fields": {"what": "u8"}},
                        "response": {"fields": {"packets": "u8", "major": "u8", "minor": "u16"}},
                    },
                },
            }
        },
    ),
    "frame: status bits, error flag": Case(
        {"v": "u8"},
        {"v": "u8"},
        {
            "elements": {
                "header": {"role": "header", "value": HEADER},
                "code": {"role": "command", "type": "u8", "error_flag": 0x80},
                "status": {
                    "role": "status",
                    "type": "u8",
                    "directions": ["response"],
                    "bits": {"alert": {"bits": 7}, "error": {"bits": [6, 0]}},
                },
                "length": {"role": "length", "type": "u8"},
                "content": {"role": "content"},
                "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["code", "content"]},
            }
        },
        {"refused": {"response": {"error_reply": True, "fields": {"reason": {"type": "u8", "enum": "mode"}}}}},
    ),
    "frame: transparency": Case(
        {"v": "u16", "data": {"type": "bytes", "size": "rest"}},
        {"v": "u16"},
        {
            "elements": {
                "header": {"role": "header", "value": "C0"},
                "length": {"role": "length", "type": "u8", "counts": ["code", "checksum"]},
                "code": {"role": "command", "type": "u8"},
                "content": {"role": "content"},
                "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["length", "content"]},
            },
            "transparency": {"span": ["code", "content"], "replace": {"C0": "DB DC", "DB": "DB DD"}},
        },
    ),
    # HerkuleX: both checksums in the header; the first covers the whole frame but them (XOR & 0xFE), the second
    # is computed from the first (~checksum1 & 0xFE)
    "frame: checksums inside their span, a checksum of a checksum": Case(
        {"v": "u16", "data": {"type": "bytes", "size": "rest"}},
        {"v": "u8"},
        {
            "elements": {
                "header": {"role": "header", "value": "FF FF"},
                "size": {"role": "length", "type": "u8", "counts": ["id", "content"], "adds": 3},
                "id": {"role": "address", "type": "u8", "range": [0, 253], "broadcast": 254},
                "code": {"role": "command", "type": "u8"},
                "checksum1": {
                    "role": "checksum",
                    "type": "u8",
                    "algorithm": "xor",
                    "mask": 0xFE,
                    "covers": ["size", "content"],
                },
                "checksum2": {
                    "role": "checksum",
                    "type": "u8",
                    "algorithm": "xor",
                    "invert": True,
                    "mask": 0xFE,
                    "covers": ["checksum1", "checksum1"],
                },
                "content": {"role": "content"},
            }
        },
    ),
    "frame: ended by a terminator, no length": Case(
        {"v": "u16", "data": {"type": "bytes", "size": "rest"}},
        {"v": "u16"},
        {
            "elements": {
                "header": {"role": "header", "value": "3A"},
                "code": {"role": "command", "type": "u8"},
                "content": {"role": "content"},
                "checksum": {"role": "checksum", "type": "u8", "algorithm": "xor", "covers": ["code", "content"]},
                "end": {"role": "trailer", "value": "0D"},
            }
        },
    ),
    "frame: ended by a terminator, no length, contents of one size": Case(
        {"v": "u16"},
        {"v": "u16", "w": "u8"},
        {
            "elements": {
                "header": {"role": "header", "value": "3A"},
                "code": {"role": "command", "type": "u8"},
                "content": {"role": "content"},
                "checksum": {"role": "checksum", "type": "u8", "algorithm": "xor", "covers": ["code", "content"]},
                "end": {"role": "trailer", "value": "0D"},
            }
        },
    ),
    "frame: layouts": Case(
        {"data": {"type": "bytes", "size": "rest"}},
        {"data": {"type": "bytes", "size": "rest"}},
        {
            "layouts": {
                "short": {
                    "elements": {
                        "start": {"role": "header", "value": "02"},
                        "length": {"role": "length", "type": "u8", "counts": ["code", "content"]},
                        "code": {"role": "command", "type": "u8"},
                        "content": {"role": "content"},
                        "checksum": {
                            "role": "checksum",
                            "type": "u8",
                            "algorithm": "sum",
                            "covers": ["code", "content"],
                        },
                        "end": {"role": "trailer", "value": "03"},
                    }
                },
                "long": {
                    "elements": {
                        "start": {"role": "header", "value": "04"},
                        "length": {"role": "length", "type": "u16", "counts": ["code", "content"]},
                        "code": {"role": "command", "type": "u8"},
                        "content": {"role": "content"},
                        "checksum": {
                            "role": "checksum",
                            "type": "u8",
                            "algorithm": "sum",
                            "covers": ["code", "content"],
                        },
                        "end": {"role": "trailer", "value": "03"},
                    }
                },
            }
        },
    ),
}


def spec_text(name: str, case: Case) -> str:
    framing = case.framing or FRAMING
    elements = next(iter(framing["layouts"].values()))["elements"] if "layouts" in framing else framing["elements"]
    address = next((n for n, e in elements.items() if e["role"] == "address"), None)
    answered = address is not None and "response" in elements[address].get("directions", ["response"])
    layouts = [layout["elements"] for layout in framing["layouts"].values()] if "layouts" in framing else [elements]
    coded = any(e["role"] == "command" for layout in layouts for e in layout.values())
    matching = [address, "command"] if answered else ["command"]
    spec: dict[str, Any] = {
        "protocol": "matrix_case",
        "title": f"Matrix: {name}",
        "description": f"The language matrix case {name!r}.",
        "byte_order": "little",
        "serial": {"baudrate": 115200},
        "framing": framing,
        **({"matching": {"by": matching}} if coded else {}),
        **copy.deepcopy(SHARED),
        "commands": {
            "probe": {
                "code": 1,
                "title": "Probe",
                "request": {"fields": case.request, **copy.deepcopy(case.request_keys or {})},
                "response": {"fields": case.response},
            },
            **copy.deepcopy(case.commands or {}),
        },
        "device": {"memory": "regs", **({"address": address} if address else {}), **copy.deepcopy(case.device or {})},
    }
    if not coded:  # the one command of frames without a command element has no code
        del spec["commands"]["probe"]["code"]
    return yaml.safe_dump(spec, sort_keys=False, allow_unicode=True)


@dataclass(frozen=True)
class Built:
    text: str
    protocol: Protocol
    files: dict[str, str]


# Cases the C target refuses (backends.Unsupported), with the one line it says: the C files are left out.
C_REFUSES: dict[str, str] = {}


# Cases the Wireshark target refuses (backends.Unsupported), with the one line it says.
WIRESHARK_REFUSES: dict[str, str] = {}


def build(name: str) -> Built:
    text = spec_text(name, CASES[name])
    try:
        protocol = resolve(load_text(text, "matrix_case.yaml"))
        files: dict[str, str] = {}
        problems = []
        for emitter in emitters():
            if emitter.name == "c" and name in C_REFUSES:
                with pytest.raises(Unsupported) as refused:
                    emitter.files(protocol)
                said = str(refused.value)
                assert C_REFUSES[name] in said and "\n" not in said, said
                continue
            if emitter.name == "wireshark" and name in WIRESHARK_REFUSES:
                with pytest.raises(Unsupported) as refused:
                    emitter.files(protocol)
                said = str(refused.value)
                assert WIRESHARK_REFUSES[name] in said and "\n" not in said, said
                continue
            emitted = emitter.files(protocol)
            files.update({f"{emitter.folder}/{path}" if emitter.folder else path: t for path, t in emitted.items()})
            if emitter.verify is not None:
                problems.extend(emitter.verify(protocol, emitted))
        if problems:
            raise SpecErrors(problems)
    except SpecErrors as exc:
        pytest.fail(f"case {name!r}: the spec is refused:\n{exc}\n{text}")
    return Built(text, protocol, files)


@contextlib.contextmanager
def package(built: Built) -> Iterator[Generated]:
    modules = {path.split("/", 1)[1]: text for path, text in built.files.items() if path.startswith("matrix_case/")}
    with imported("matrix_case", modules, "the language matrix") as root:
        structs: ModuleType = importlib.import_module("matrix_case.structs")
        yield Generated(built.protocol, root, structs)


def message_class(g: Generated, message: Message) -> Any:
    return next(c for c in g.package.MESSAGE_TYPES if c.__name__ == message.class_name)


# Known to fail; each is a bug to fix, strict so that the fix is noticed (and the mark removed).
KNOWN: dict[str, str] = {}
# a one-byte length that says a larger size in a wider one after it (`extended:`, MQTT-SN's shape: the length counts
# itself, 0x01 then a big-endian u16): 251 + 2 bytes and a few more, so random messages take either form
_EXTENDED = {"pad": {"type": "bytes", "size": 251}, "data": {"type": "bytes", "size": "rest"}}
CASES["frame: extended length (a marker, then a u16), counting itself"] = Case(
    _EXTENDED,
    copy.deepcopy(_EXTENDED),
    {
        "elements": {
            "header": {"role": "header", "value": HEADER},
            "length": {
                "role": "length",
                "type": "u8",
                "extended": {"when": 1, "type": "u16"},
                "counts": ["length", "content"],
                "range": [2, 700],
            },
            "code": {"role": "command", "type": "u8"},
            "content": {"role": "content"},
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "xor", "covers": ["length", "content"]},
        }
    },
)
CASES["frame: transparency, a length of the span's plain bytes, the checksum inside it"] = Case(
    CASES["frame: transparency"].request,
    {"v": "u16"},
    {
        "elements": {
            **CASES["frame: transparency"].framing["elements"],  # type: ignore[index]
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["code", "content"]},
        },
        "transparency": {"span": ["code", "checksum"], "replace": {"C0": "DB DC", "DB": "DB DD"}},
    },
)
CASES["frame: transparency, checksum over exactly the span"] = Case(
    {"v": "u16"},
    {"v": "u16"},
    {
        **CASES["frame: transparency"].framing,  # type: ignore[dict-item]
        "elements": {
            **CASES["frame: transparency"].framing["elements"],  # type: ignore[index]
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["code", "content"]},
        },
    },
)
# Plain frame values: a sequence number the client fills in, a flags byte given in every message
CASES["frame: plain values, a sequence"] = Case(
    {"v": "u16"},
    {"w": "u8"},
    {
        "elements": {
            "header": {"role": "header", "value": HEADER},
            "id": {"role": "address", "type": "u8", "range": [0, 253], "broadcast": 254},
            "seq": {"role": "value", "type": "u16", "endian": "big", "range": [1, 999], "sequence": True},
            "flags": {"role": "value", "type": "u8"},
            "code": {"role": "command", "type": "u8"},
            "length": {"role": "length", "type": "u8"},
            "content": {"role": "content"},
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["id", "content"]},
        }
    },
)
# A header of one byte (the C parser keeps no tail then: its copy loop to 0 did not compile under -Wextra) and a
# negative constant (the C compared the bits read with -3UL)
CASES["frame: a one-byte header, a negative constant"] = Case(
    {"marker": {"type": "i16", "const": -3}, "v": "u8"},
    {"w": "i8", "tag": {"type": "i8", "const": -128}},
    {
        "elements": {
            **{"header": {"role": "header", "value": "A5"}},
            **{k: v for k, v in FRAMING["elements"].items() if k != "header"},
        }
    },
)
# The waits a client keeps: the silence between frames (`gap`) and the turnaround after a broadcast
CASES["frame: gap and turnaround"] = Case({"v": "u16"}, {"w": "u8"}, {**FRAMING, "gap": 3.5, "turnaround": 0.01})
# Constant and default bit fields (`const`, `default`): in a frame value (a sync nibble; no argument needed) and in
# a content field; decode refuses another constant, encode writes it
CASES["frame: constant and default bit fields"] = Case(
    {"word": {"type": "u8", "bits": {"tag": {"bits": [7, 6], "const": 2}, "low": {"bits": [3, 0], "default": 1}}}},
    {"v": "u8"},
    {
        "elements": {
            "sync": {
                "role": "value",
                "type": "u8",
                "bits": {"nibble": {"bits": [3, 0], "const": 5}, "reserved": {"bits": [7, 4], "default": 0}},
            },
            "code": {"role": "command", "type": "u8"},
            "length": {"role": "length", "type": "u8"},
            "content": {"role": "content"},
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["sync", "content"]},
        }
    },
)
# No command element: one command, its frame a header, a length byte, the content and a sum (generate crashed here)
CASES["frame: no command element, a length byte"] = Case(
    {"v": "u16", "w": "u8"},
    {"v": "u16"},
    {
        "elements": {
            "header": {"role": "header", "value": HEADER},
            "length": {"role": "length", "type": "u8"},
            "content": {"role": "content"},
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["length", "content"]},
        }
    },
)
# Alternative layouts holding different algorithms under one element name (MSP v1's XOR beside v2's CRC-8): each
# layout's frames are checked with their own
DVB_S2 = {"width": 8, "poly": 0xD5, "init": 0, "refin": False, "refout": False, "xorout": 0, "check": 0xBC}
CASES["frame: layouts, each its own checksum algorithm"] = copy.deepcopy(CASES["frame: layouts"])
_long = CASES["frame: layouts, each its own checksum algorithm"].framing
assert _long is not None
_long["layouts"]["long"]["elements"]["checksum"] |= {"algorithm": "crc", "crc": DVB_S2}

# A content sent without its trailing zero bytes (MAVLink v2)
# an error reply told by its header (MSP's `$M!` for `$M>`): the refused code in the command element, no content
CASES["frame: error header (error_value), an error reply without fields"] = Case(
    {"v": "u8"},
    {"v": "u16"},
    {
        "elements": {
            "header": {
                "role": "header",
                "value": {"request": "24 4d 3c", "response": "24 4d 3e"},
                "error_value": "24 4d 21",
            },
            "length": {"role": "length", "type": "u8"},
            "code": {"role": "command", "type": "u8"},
            "content": {"role": "content"},
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "xor", "covers": ["length", "content"]},
        }
    },
    {"refused": {"response": {"error_reply": True, "fields": {}}}},
)
# an error reply told by its status (SHDLC's state byte, its execution error code 6..0): the refused code in the
# command element as it is, no content; a status with bit 7 alone is a normal reply
CASES["frame: error status (error_bits), an error reply without fields"] = Case(
    {"v": "u8"},
    {"v": "u16"},
    {
        "elements": {
            "header": {"role": "header", "value": "7E"},
            "code": {"role": "command", "type": "u8"},
            "state": {
                "role": "status",
                "type": "u8",
                "directions": ["response"],
                "error_bits": 0x7F,
                "bits": {"alert": {"bits": 7}, "error": {"bits": [6, 0]}},
            },
            "length": {"role": "length", "type": "u8"},
            "content": {"role": "content"},
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["code", "content"]},
        }
    },
    {"refused": {"response": {"error_reply": True, "fields": {}}}},
)
# MSP v1 beside v2: layouts told apart by header with different element orders and checksums, and a code only
# the second layout's u16 command element holds (encode sends it there; a code both hold goes in the first)
CASES["frame: layouts, a code only a later layout's command element holds"] = Case(
    {"v": "u8"},
    {"v": "u16"},
    {
        "layouts": {
            "v1": {
                "elements": {
                    "header": {"role": "header", "value": {"request": "24 4d 3c", "response": "24 4d 3e"}},
                    "size": {"role": "length", "type": "u8"},
                    "code": {"role": "command", "type": "u8"},
                    "content": {"role": "content"},
                    "checksum": {"role": "checksum", "type": "u8", "algorithm": "xor", "covers": ["size", "content"]},
                }
            },
            "v2": {
                "elements": {
                    "header": {"role": "header", "value": {"request": "24 58 3c", "response": "24 58 3e"}},
                    "flag": {"role": "constant", "value": "00"},
                    "code": {"role": "command", "type": "u16"},
                    "size": {"role": "length", "type": "u16"},
                    "content": {"role": "content"},
                    "checksum": {
                        "role": "checksum",
                        "type": "u8",
                        "algorithm": "crc",
                        "crc": DVB_S2,
                        "covers": ["flag", "content"],
                    },
                }
            },
        }
    },
    {"wide": {"code": 0x2002, "request": {"fields": {"w": "u16"}}, "response": {"fields": {"x": "i32"}}}},
)
CASES["frame: truncate: trailing_zeros"] = Case(
    {"v": "u16", "w": "u32", "name": {"type": "string", "size": 4, "pad": "00"}, "z": "u8"},
    {"x": "f32", "y": {"type": "i8", "range": [-3, 3]}},
    {
        "elements": {
            "header": {"role": "header", "value": "FD"},
            "length": {"role": "length", "type": "u8"},
            "id": {"role": "address", "type": "u8", "range": [0, 253], "broadcast": 254},
            "code": {"role": "command", "type": "u16"},
            "content": {"role": "content", "truncate": "trailing_zeros"},
            "checksum": {
                "role": "checksum",
                "type": "u16",
                "algorithm": "crc",
                "crc": {
                    "width": 16,
                    "poly": 0x1021,
                    "init": 0xFFFF,
                    "refin": True,
                    "refout": True,
                    "xorout": 0,
                    "check": 0x6F91,
                },
                "covers": ["length", "content"],
            },
        }
    },
    commands={"empty": {"code": 0x1234, "request": {"fields": {"n": "u8"}}, "response": {}}},
)
# Optional elements (`present_if`): bytes after the checksum sent when a constant's bit is set (MAVLink v2 signing),
# and bytes before the checksum, outside its span, when a value's bit is set (the message gives the flags)
CASES["frame: optional element, present_if a constant's bit"] = Case(
    {"v": "u16"},
    {"w": "u8"},
    {
        "elements": {
            "header": {"role": "header", "value": HEADER},
            "flags": {"role": "constant", "value": "00"},
            **{k: v for k, v in FRAMING["elements"].items() if k != "header"},
            "tag": {"role": "optional", "size": 5, "present_if": "flags & 0x04"},
        }
    },
)
CASES["frame: optional element, present_if a value's bit"] = Case(
    {"v": "u16"},
    {"w": "u8", "z": "u16"},
    {
        "elements": {
            "header": {"role": "header", "value": HEADER},
            "id": {"role": "address", "type": "u8", "range": [0, 253], "broadcast": 254},
            "flags": {"role": "value", "type": "u8", "range": [0, 3]},
            "code": {"role": "command", "type": "u8"},
            "length": {"role": "length", "type": "u8"},
            "content": {"role": "content"},
            "stamp": {"role": "optional", "size": 2, "present_if": "flags & 2"},
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["id", "content"]},
        }
    },
)
# Replies under a code computed from the request's (HerkuleX: code | 0x40), in the usual frame and in one the frame
# engine reads; a reply-only command's frames carry the computed code too
REPLY_CODED = {
    "other": {"code": 2, "request": {"fields": {"a": "u8"}}, "response": {"fields": {"b": "i16"}}},
    "told": {"code": 3, "response": {"unsolicited": True, "fields": {"c": "u8"}}},
}
CASES["frame: reply_code, a reply code computed from the request code"] = Case(
    {"v": "u16"},
    {"w": "u8"},
    {"elements": {**FRAMING["elements"], "code": {"role": "command", "type": "u8", "reply_code": "code | 0x40"}}},
    commands=REPLY_CODED,
)
CASES["frame: reply_code, frame engine"] = Case(
    {"v": "u16"},
    {"w": "u16"},
    {
        "elements": {
            **CASES["frame: trailer, constant, u16 big-endian length and checksum"].framing["elements"],  # type: ignore[index]
            "code": {"role": "command", "type": "u8", "reply_code": "(code + 0x80) & 0xFF"},
        }
    },
    commands=REPLY_CODED,
)
# A request code wider than the replies' command element (VISCA: 01 04 asked, 50 answered): the reply code's
# expression takes the request's u16 code, and a reply-only command's code fits the reply element
CASES["frame: reply_code, u16 request codes and u8 reply codes"] = Case(
    {"v": "u16"},
    {"w": "u8"},
    {
        "elements": {
            "header": {"role": "header", "value": HEADER},
            "id": {"role": "address", "type": "u8", "range": [0, 253], "broadcast": 254},
            "code": {"role": "command", "type": "u16", "endian": "big", "directions": ["request"]},
            "reply": {
                "role": "command",
                "type": "u8",
                "directions": ["response"],
                "reply_code": "(code + (code >> 8)) & 0xFF",
            },
            "length": {"role": "length", "type": "u8"},
            "content": {"role": "content"},
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["id", "content"]},
        }
    },
    commands={**REPLY_CODED, "other": {**REPLY_CODED["other"], "code": 0x0902}},
)
# Requests that share a code, told apart by their content size (0, 2, 3 or more bytes), in the usual frame and in
# one the frame engine reads
SHARED_CODE = {
    "poll": {"code": 1, "request": {"fields": {}}},
    "long": {"code": 1, "request": {"fields": {"a": "u8", "b": "u16", "data": {"type": "bytes", "size": "rest"}}}},
}
# (and in the usual frame, code 2 shared by requests of one size picked by a leading u8 constant: the case of
# leading constants below, whole bytes in a coded frame)
CASES["requests sharing a code, by content size or a leading u8"] = Case(
    {"v": "u16"},
    {"w": "u8"},
    commands={
        **SHARED_CODE,
        "get": {"code": 2, "request": {"fields": {"kind": {"type": "u8", "const": 1}, "a": "u16"}}},
        "put": {"code": 2, "request": {"fields": {"kind": {"type": "u8", "const": 2}, "b": "i16"}}},
    },
)
# Requests that share a code and one fixed size, picked by a leading u8, in a frame with no length (iRobot's Open
# Interface: the opcode alone, 8E 16 asks for the voltage, 8E 17 the current): the size of the one size
CASES["requests sharing a code and one size, picked by a leading u8, no length element"] = Case(
    {"v": "u16"},
    {"w": "u16"},
    {
        "elements": {
            "start": {"role": "header", "value": "A5", "directions": ["response"]},  # (replies of their own)
            "opcode": {"role": "command", "type": "u8", "directions": ["request"]},
            "content": {"role": "content"},
        }
    },
    commands={
        "voltage": {"code": 0x8E, "request": {"fields": {"packet": {"type": "u8", "const": 22}}}},
        "current": {"code": 0x8E, "request": {"fields": {"packet": {"type": "u8", "const": 23}}}},
    },
)
# A frame with no length element sized by a count by expression before what it counts (`2 * n + 1` items of 2 bytes:
# 2 + 4 per n), as by a count field (lang/counts.py, model/sizes.py linear): every stream parser, C's and tshark's too
CASES["frame: no length, sized by a count expression"] = Case(
    {"n": {"type": "u8", "range": [0, 3]}, "items": {"type": "array", "of": "u16", "count": "2 * n + 1"}},
    {"m": "u8", "items": {"type": "array", "of": "u8", "count": "m + 2"}},
    {
        "elements": {
            "header": {"role": "header", "value": HEADER},
            "code": {"role": "command", "type": "u8"},
            "content": {"role": "content"},
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["code", "content"]},
        }
    },
)
CASES["requests sharing a code, by content size, frame engine"] = Case(
    {"v": "u16"},
    {"w": "u16"},
    CASES["frame: trailer, constant, u16 big-endian length and checksum"].framing,
    commands=SHARED_CODE,
)
# Replies that share a code, none of them `default`, told apart by their content size (SPS30's measured values: 40
# bytes of floats, 20 of integers, or none): probe's reply and two more that answer probe, in the usual frame and in
# one the frame engine reads
SHARED_REPLIES = {
    "probe_short": {"code": 1, "response": {"answers": "probe", "fields": {"w": "u8"}}},
    "probe_empty": {"code": 1, "response": {"answers": "probe", "fields": {}}},
}
CASES["replies sharing a code, by content size"] = Case({"v": "u16"}, {"w": "u8", "x": "u32"}, commands=SHARED_REPLIES)
CASES["replies sharing a code, by content size, frame engine"] = Case(
    {"v": "u16"},
    {"w": "u8", "x": "u32"},
    CASES["frame: trailer, constant, u16 big-endian length and checksum"].framing,
    commands=SHARED_REPLIES,
)
# ... and in a frame ended by its terminator, without a length (VISCA's inquiry replies, 90 50 ... FF)
CASES["replies sharing a code, by content size, ended by a terminator"] = Case(
    {"v": "u16"},
    {"w": "u8", "x": "u32"},
    CASES["frame: ended by a terminator, no length"].framing,
    commands=SHARED_REPLIES,
)
# Messages picked by their leading constant (lang/model/discriminator.py), before sizes that overlap: RTCM 3's frame
# without a command element, each request's content beginning with its 12-bit message number (`descriptor`'s
# counted string makes 4 bytes or more, probe's 5); and requests that share a code, picked by a leading u8
_RTCM_CRC = CASES["type: u12, i38 (bit runs), a u24 checksum"].framing["elements"]["checksum"]  # type: ignore[index]
CASES["requests picked by a leading constant bit field, no command element"] = Case(
    {"msg": {"type": "u12", "const": 1005}, "station": "u12", "v": "u16"},
    {"v": "u16"},
    {
        "elements": {
            "header": {"role": "header", "value": "D3"},
            "length": {"role": "length", "type": "u16", "endian": "big", "range": [0, 1023]},
            "content": {"role": "content"},
            "checksum": _RTCM_CRC,
        }
    },
    commands={
        "descriptor": {
            "request": {
                "fields": {
                    "msg": {"type": "u12", "const": 1033},
                    "station": "u12",
                    "n": {"type": "u8", "range": [0, 6]},
                    "name": {"type": "string", "size": "n"},
                }
            }
        },
    },
)
# One layout whose replies carry no code and differ in size, with nothing in the frame to size them (Pololu Maestro's
# compact protocol written with `framing.elements`): each is read as the reply awaited (Framing.codeless_replies), in
# Python and in C (p_parser_expect, p_decode_expect), the others' bytes garbage
CODELESS_REPLIES = {
    "elements": {"code": {"role": "command", "type": "u8", "directions": ["request"]}, "content": {"role": "content"}}
}
CASES["frame: one layout, code-less replies of different sizes, read as the reply awaited"] = Case(
    {"v": "u16"},
    {"w": "u16", "x": "u8"},
    CODELESS_REPLIES,
    commands={
        "other": {"code": 2, "request": {"fields": {"a": "u8"}}, "response": {"default": True, "fields": {"b": "i16"}}}
    },
)
# And a code-less reply whose last bytes are as many as its request asks for (the Pololu Tic's Get Variable, the
# Maestro's raw reads: `size_from`), which nothing in the frame sizes: sized by the request awaited (C: `asked`);
# here one more than the field says (STM32's Read Memory sends the count minus one: `request.length + 1`)
CASES["frame: one layout, a code-less reply sized by its request (size_from)"] = Case(
    {"offset": "u8", "length": {"type": "u8", "range": [0, 5]}},
    {"data": {"type": "bytes", "size": "rest", "size_from": "request.length + 1"}},
    CODELESS_REPLIES,
    commands={
        "other": {"code": 2, "request": {"fields": {"a": "u8"}}, "response": {"default": True, "fields": {"b": "i16"}}}
    },
)
# Messages picked by their leading constant in a frame with no command element and no length, each of its own size
# (Kondo ICS: the command in a byte's top 3 bits, the servo id in its low 5; MIDI: a u4 status before a u4 channel
# beside u8 system messages, a prefix code): requests and replies alike, each sized by its own bytes (fixed, or a
# count before the rest)
CASES["messages picked by leading constants of mixed widths, no command element, no length"] = Case(
    {"kind": {"type": "u3", "const": 4}, "id": "u5", "position": {"type": "u16", "encoding": "seven_bit"}},
    {"kind": {"type": "u3", "const": 0}, "id": "u5", "position": {"type": "u16", "encoding": "seven_bit"}},
    {"elements": {"content": {"role": "content"}}},
    commands={
        "read": {
            "request": {"fields": {"kind": {"type": "u3", "const": 5}, "id": "u5", "what": "u8"}},
            "response": {"fields": {"kind": {"type": "u3", "const": 1}, "id": "u5", "what": "u8", "v": "u8"}},
        },
        "dump": {
            "request": {
                "fields": {
                    "kind": {"type": "u3", "const": 6},
                    "id": "u5",
                    "n": {"type": "u8", "range": [0, 6]},
                    "data": {"type": "bytes", "size": "n"},
                }
            }
        },
        "stop": {"request": {"fields": {"kind": {"type": "u8", "const": 0xFF}}}},
    },
)
# The device rules and unsolicited output: the simulator sends `beat` every 5 ms while the client's requests are
# matched to their replies (client_against_simulator), a derived entry, a lock, a move to an expression.
CASES["device: derived, locks, sends, moves.to"] = Case(
    {"v": "u16"},
    {"v": "u16"},
    commands={
        "beat": {"code": 9, "title": "Beat", "response": {"unsolicited": True, "fields": {"where": "u16"}}},
        "go": {"code": 10, "title": "Go", "request": {"fields": {"target": "u16"}}, "response": {}},
    },
    device={
        "state": {"held": 0, "beats": 0},
        "derived": {"torque": "position + speed"},
        "locks": [{"entries": ["speed"], "while": "held"}],
        "errors": {"locked": {"v": 1}},
        "sends": {"beat": {"every": 5, "step": "beats", "values": {"where": "torque"}}, "probe": {"after": ["go"]}},
        "commands": {"go": {"moves": {"state": "position", "target": "target", "to": "target / 2"}}},
    },
)
# Layouts chosen by command (RoboClaw packet serial): `read` requests get their data and a CRC that starts with the
# request's address and command (`from_request`), `write` requests (their own checksum) one bare 0xFF byte
XMODEM = {"width": 16, "poly": 0x1021, "init": 0, "refin": False, "refout": False, "xorout": 0, "check": 0x31C3}
BY_COMMAND = "frame: layouts chosen by command (layout:), a bare acknowledgement, a reply checksum from_request"
CASES[BY_COMMAND] = Case(
    {"v": "u16"},
    {"w": "i32", "s": {"type": "u8", "range": [0, 9]}},
    {
        "layouts": {
            "read": {
                "elements": {
                    "id": {"role": "address", "type": "u8", "range": [128, 135], "directions": ["request"]},
                    "code": {"role": "command", "type": "u8", "directions": ["request"]},
                    "content": {"role": "content"},
                    "crc": {
                        "role": "checksum",
                        "type": "u16",
                        "endian": "big",
                        "algorithm": "crc",
                        "crc": XMODEM,
                        "covers": ["content", "content"],
                        "from_request": ["id", "code"],
                        "directions": ["response"],
                    },
                    "sum": {
                        "role": "checksum",
                        "type": "u16",
                        "endian": "big",
                        "algorithm": "crc",
                        "crc": XMODEM,
                        "covers": ["id", "content"],
                        "directions": ["request"],
                    },
                }
            },
            "write": {
                "elements": {
                    "id": {"role": "address", "type": "u8", "range": [128, 135], "directions": ["request"]},
                    "code": {"role": "command", "type": "u8", "directions": ["request"]},
                    "content": {"role": "content", "directions": ["request"]},
                    "sum": {
                        "role": "checksum",
                        "type": "u8",
                        "algorithm": "sum",
                        "covers": ["id", "content"],
                        "directions": ["request"],
                    },
                    "ack": {"role": "header", "value": "FF", "directions": ["response"]},
                }
            },
        }
    },
    commands={
        "drive": {"code": 2, "layout": "write", "request": {"fields": {"speed": "i16"}}, "response": {}},
        "peek": {
            "code": 3,
            "layout": {"request": "read", "response": "read"},
            "request": {},
            "response": {"fields": {"x": "u16"}},
        },
    },
)
# Layouts chosen by command whose replies carry no code (Bosch BNO055: AA op register length data; a read answered
# by BB length data, a write by EE status), a read refused by a write's status reply in that reply's own layout
CASES["frame: layouts chosen by command, a refusal in another layout (refused_by)"] = Case(
    {"n": {"type": "u8", "range": [1, 9]}},
    {"data": {"type": "bytes", "size": "rest"}},
    {
        "layouts": {
            "data": {
                "elements": {
                    "start": {"role": "header", "value": {"request": "AA", "response": "BB"}},
                    "op": {"role": "command", "type": "u8", "directions": ["request"]},
                    "register": {"role": "address", "type": "u8", "directions": ["request"]},
                    "length": {"role": "length", "type": "u8", "directions": ["response"]},
                    "content": {"role": "content"},
                }
            },
            "status": {
                "elements": {
                    "start": {"role": "header", "value": "EE", "directions": ["response"]},
                    "content": {"role": "content"},
                }
            },
        }
    },
    commands={
        "write": {
            "code": 0,
            "layout": {"request": "data", "response": "status"},
            "request": {"fields": {"count": "u8", "data": {"type": "bytes", "size": "count"}}},
            "response": {"fields": {"status": {"type": "u8", "range": [1, 10]}}},
        },
    },
    request_keys={"answered_by": {"command": "probe", "refused_by": ["write"]}},
)
# Layouts chosen by command, one with a command element and one without (TFmini: configuration frames 42 57 02 00,
# parameters, the command byte last; data frames 59 59 with no command): a codeless command travels in its own layout
MIXED = "frame: layouts chosen by command, one without a command element, the command byte after the content"
CASES[MIXED] = Case(
    {"v": "u16"},
    {"v": "u16", "on": {"type": "u8", "range": [0, 1]}},
    {
        "layouts": {
            "config": {
                "elements": {
                    "header": {"role": "header", "value": {"request": "42 57 02 00", "response": "42 57 02 01"}},
                    "content": {"role": "content"},
                    "code": {"role": "command", "type": "u8"},
                }
            },
            "data": {
                "elements": {
                    "header": {"role": "header", "value": "59 59"},
                    "content": {"role": "content"},
                    "sum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["header", "content"]},
                }
            },
        }
    },
    commands={
        "mode": {
            "code": 0x11,
            "layout": "config",
            "request": {"fields": {"m": "u8"}},
            "response": {"fields": {"m": "u8"}},
        },
        "measure": {"layout": "data", "request": {}, "response": {"fields": {"distance": "u16", "strength": "u16"}}},
    },
)

# Layouts chosen by command with frame values of their own (RPLIDAR: the response descriptor's size and mode beside
# headerless measurements that carry none; HCI's ACL handle and flags beside commands and events that carry none):
# each message carries its own layout's values (the C: its own layout's, in its struct and the engine's values[])
OWN_VALUES = "frame: layouts chosen by command, a frame value one layout has and another has not"
CASES[OWN_VALUES] = copy.deepcopy(CASES[MIXED])
_data = CASES[OWN_VALUES].framing["layouts"]["data"]["elements"]
_data["seq"] = {"role": "value", "type": "u8", "range": [0, 99]}
_data["content"] = _data.pop("content")
_data["sum"] = _data.pop("sum")
_config = CASES[OWN_VALUES].framing["layouts"]["config"]["elements"]
_config["handle"] = {"role": "value", "type": "u16", "bits": {"link": {"bits": [11, 0]}, "kind": {"bits": [15, 12]}}}
_config["content"] = _config.pop("content")
_config["code"] = _config.pop("code")

# A length counting the whole frame, from the header before it (Benewake TFmini Plus: 5A, the frame's length, ...)
CASES["frame: a length counting from the header before it"] = Case(
    {"v": "u16"},
    {"w": "u8", "z": "i16"},
    {
        "elements": {
            "header": {"role": "header", "value": HEADER},
            "length": {"role": "length", "type": "u8", "counts": ["header", "checksum"]},
            "code": {"role": "command", "type": "u8"},
            "content": {"role": "content"},
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["header", "content"]},
        }
    },
)
# Layouts chosen by command, `reply_code` on one layout's command element only (HLK-LD2410: ACKs under the command
# word | 0x0100 beside reports whose u8 type byte is their own code): the other layout's commands keep their codes
CASES["frame: layouts chosen by command, reply_code on one layout's command element"] = Case(
    {"v": "u16"},
    {"w": "u8"},
    {
        "layouts": {
            "command": {
                "elements": {
                    "header": {"role": "header", "value": "FD FC"},
                    "length": {"role": "length", "type": "u16", "counts": ["word", "content"]},
                    "word": {"role": "command", "type": "u16", "reply_code": "code | 0x0100"},
                    "content": {"role": "content"},
                }
            },
            "report": {
                "elements": {
                    "header": {"role": "header", "value": "F4 F3", "directions": ["response"]},
                    "length": {"role": "length", "type": "u8", "counts": ["type", "content"]},
                    "type": {"role": "command", "type": "u8"},
                    "content": {"role": "content"},
                    "tail": {"role": "trailer", "value": "55"},
                }
            },
        }
    },
    commands={"report": {"code": 2, "layout": "report", "response": {"unsolicited": True, "fields": {"d": "u16"}}}},
)


# The same commands in two frame forms (the Pololu Maestro's compact and Pololu protocols): one layout without a
# header, its code plain, tried last; one after a header, its code an expression of the command's (`code:`)
FORMS = "frame: layouts, one headerless, one sending its code as an expression (`code:`)"
CASES[FORMS] = Case(
    {"v": "u16"},
    {"v": "u16", "on": {"type": "u8", "range": [0, 1]}},
    {
        "layouts": {
            "compact": {
                "elements": {
                    "code": {"role": "command", "type": "u8"},
                    "length": {"role": "length", "type": "u8"},
                    "content": {"role": "content"},
                    "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["code", "content"]},
                }
            },
            "framed": {
                "elements": {
                    "start": {"role": "header", "value": "AA"},
                    "code": {"role": "command", "type": "u8", "code": "code | 0x80"},
                    "length": {"role": "length", "type": "u8"},
                    "content": {"role": "content"},
                    "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["code", "content"]},
                }
            },
        }
    },
    commands={"other": {"code": 2, "request": {"fields": {"a": "u8"}}, "response": {"fields": {"b": "i16"}}}},
)


# A frame value one layout carries and another does not (the Pololu protocol form's device number beside the compact
# form, which has none; here in replies too): None in frames of the layout without it; a message giving it is sent
# in the layout that carries it, one giving None in the other; the simulator answers a request without it without
# it (the C refuses it: a struct's integer holds no None)
PARTIAL = "frame: layouts, a frame value (a device number) one layout carries and the other not"
CASES[PARTIAL] = copy.deepcopy(CASES[FORMS])
_framed = CASES[PARTIAL].framing["layouts"]["framed"]["elements"]
CASES[PARTIAL].framing["layouts"]["framed"]["elements"] = {
    "start": _framed["start"],
    "device": {"role": "address", "type": "u8", "range": [0, 127]},
    **{k: v for k, v in _framed.items() if k != "start"},
}
C_REFUSES[PARTIAL] = "a frame value that some alternative layout does not carry (device, requests)"


# `every` as an expression of the device's values (a rate the request sets): the beats come among the replies
CASES["device: sends every an expression (a rate)"] = Case(
    {"v": "u16"},
    {"v": "u16"},
    commands={"beat": {"code": 9, "title": "Beat", "response": {"unsolicited": True, "fields": {"n": "u16"}}}},
    device={
        "state": {"rate_hz": 200, "beats": 0},
        "sends": {"beat": {"every": "1000 / rate_hz", "step": "beats", "values": {"n": "beats"}}},
        "commands": {"probe": {"stores": {"v": "rate_hz"}}},
    },
)
# `reply` values for a list, an array and a group (one mapping of its fields per item), a bit field by name
CASES["device: reply lists, arrays, groups and bit fields"] = Case(
    {"v": "u16"},
    {
        "temps": {"type": "array", "of": "i8", "count": 2},
        "n": "u8",
        "levels": {"type": "array", "of": "u16", "count": "n"},
        "m": "u8",
        "items": {"type": "group", "count": "m", "fields": {"id": "u8", "tag": {"type": "string", "size": 4}}},
        "flags": {"type": "u8", "bits": {"on": {"bits": 0}, "mode": {"bits": [3, 1]}}},
    },
    device={
        "reply": {
            "temps": [-3, 40],
            "levels": [1, 500, 65535],
            "items": [{"id": 1, "tag": "abcd"}, {"id": 2, "tag": "efgh"}],
            "flags.mode": 5,
        }
    },
)
# sizes and counts from fields whose range is narrower than their type's (tests/strategies.py keeps to it)
CASES["bytes, text and a group sized by fields with a narrow range"] = same(
    {
        "n": {"type": "u8", "range": [2, 4]},
        "data": {"type": "bytes", "size": "n"},
        "k": {"type": "u8", "range": [1, 3]},
        "name": {"type": "string", "size": "k"},
        "m": {"type": "u8", "range": [1, 3]},
        "g": {"type": "group", "count": "m", "fields": {"a": "u8"}},
    }
)
# a value dividing by a field: frames with that field 0 have no value (refused everywhere, C too)
# bytes of a fixed size with a default (a reserved run): messages and JSON may leave them out
CASES["bytes: a default"] = same({"v": "u8", "reserved": {"type": "bytes", "size": 3, "default": "00 A5 00"}})
CASES["value: an expression dividing by a field"] = same(
    {"d": {"type": "u8", "range": [1, 255], "default": 4}, "q": {"type": "u16", "value": "1000 / d"}, "r": "u8"}
)
DEVICE_KEYS = ("derived", "locks", "sends", "reply")  # the device keys a matrix case must use
# Every documented option of every frame transform (serialspec/transforms/), as its sample framing.
for _method, _transform in transforms().items():
    for _sample in _transform.samples:
        CASES[f"transform: {_method}, {_sample.label}"] = Case(
            {"v": "u16", "data": {"type": "bytes", "size": "rest"}}, {"v": "u16"}, dict(_sample.framing)
        )
PARAMS = [
    pytest.param(name, marks=pytest.mark.xfail(reason=KNOWN[name], strict=True)) if name in KNOWN else name
    for name in sorted(CASES)
]


def test_every_documented_alternative_has_a_case() -> None:
    """The alternatives the grammar documents (and so docs/language.md), each used by some case."""
    used: dict[str, set[Any]] = {
        "type": set(),
        "of": set(),
        "encoding": set(),
        "endian": set(),
        "bit_order": set(),
        "pad": set(),
        "size": set(),
        "count": set(),
        "role": set(),
        "element type": set(),
        "element endian": set(),
    }

    def walk_fields(fields: dict[str, Any]) -> None:
        for spec in fields.values():
            spec = {"type": spec} if isinstance(spec, str) else spec
            used["type"].add(spec.get("type", "use"))
            for key in ("of", "encoding", "endian", "bit_order", "pad"):
                if key in spec:
                    used[key].add(spec[key])
            for key in ("size", "count"):
                if key in spec:
                    plain = not isinstance(spec[key], str) or spec[key].isidentifier()
                    used[key].add(
                        "rest" if spec[key] == "rest" else type(spec[key]).__name__ if plain else "expression"
                    )
            walk_fields(spec.get("fields", {}))

    for case in CASES.values():
        walk_fields(case.request)
        walk_fields(case.response)
        framing = case.framing or FRAMING
        layouts = framing["layouts"].values() if "layouts" in framing else [framing]
        for layout in layouts:
            for element in layout["elements"].values():
                used["role"].add(element["role"])
                used["element type"].add(element.get("type", "u8"))
                used["element endian"].add(element.get("endian", "little"))
    commands = [c for case in CASES.values() for c in (case.commands or {}).values()]
    assert any("layout" in c for c in commands)  # layouts chosen by command
    assert {"from_request", "covers", "extended"} <= {k for case in CASES.values() for k in element_keys(case)}
    used_device = {key for case in CASES.values() for key in case.device or {}}
    assert set(DEVICE_KEYS) <= set(grammar.DEVICE.keys) and set(DEVICE_KEYS) - used_device == set()
    field = grammar._FIELD_LONG
    element = grammar.FRAME_ELEMENT.keys
    methods = {
        case.framing["transparency"].get("method", "replace")
        for case in CASES.values()
        if case.framing and "transparency" in case.framing
    }
    assert set(transforms()) - methods == set()  # every frame transform (the grammar's `method` choices)
    assert set(FIELD_KINDS) - used["type"] == set()
    assert (set(grammar.FIELD_SCALAR_TYPES) | {"bit"}) - used["of"] == set()
    assert set(field["bit_order"].choices) - used["bit_order"] == set()  # type: ignore[attr-defined]
    assert used["pad"] and any(f"u{n}" in used["of"] for n in (3, 5, 11)) | any(
        "i" + str(n) in used["of"] for n in (5,)
    )
    assert set(field["encoding"].choices) - used["encoding"] == set()  # type: ignore[attr-defined]
    assert set(field["endian"].choices) - used["endian"] == set()  # type: ignore[attr-defined]
    assert {"rest", "int", "str", "expression"} - used["size"] == set()
    assert {"rest", "int", "str", "expression"} - used["count"] == set()
    assert set(element["role"].choices) - used["role"] == set()  # type: ignore[attr-defined]
    assert {"u8", "u16", "u24", "u4"} - used["element type"] == set()
    assert any(bit_run.width(t) for t in used["type"])  # a bit field (uN/iN of another width)
    forms = [  # every varint form: each sign, each order, another width than 7 bits
        spec["varint"]
        for case in CASES.values()
        for fields in (case.request, case.response)
        for spec in fields.values()
        if isinstance(spec, dict) and "varint" in spec
    ]
    assert set(varint.SIGNS) <= {form.get("sign") for form in forms}
    assert set(varint.ORDERS) <= {form.get("order", "low_first") for form in forms}
    assert any(form.get("bits", 7) != 7 for form in forms)
    assert set(element["endian"].choices) - used["element endian"] == set()  # type: ignore[attr-defined]


def element_keys(case: Case) -> set[str]:
    framing = case.framing or FRAMING
    layouts = framing["layouts"].values() if "layouts" in framing else [framing]
    return {key for layout in layouts for element in layout["elements"].values() for key in element}


@pytest.mark.parametrize("name", PARAMS)
def test_every_output(name: str, tmp_path: Path) -> None:
    built = build(name)
    docs = next(text for path, text in built.files.items() if path.endswith(".md"))
    assert "probe" in docs.lower() and "Traceback" not in docs
    with package(built) as g:
        for message in built.protocol.messages():
            codec_and_structs(g, message)
        stream(g)
        client_against_simulator(g)
        spec = tmp_path / "matrix_case.yaml"
        spec.write_text(built.text, encoding="utf-8")
        cli_decode(g, spec)
        if name not in C_REFUSES:
            c_target(name, g, built, tmp_path)


def c_target(name: str, g: Generated, built: Built, tmp_path: Path) -> None:
    """The case's C (tests/test_c_backend.py's driver, with the sanitizers) against the Python codec: random messages
    give the same values and bytes, and a stream of them among garbage in pieces gives the same messages; the C
    compiles without a warning under the shipped specs' flags."""
    from test_c_backend import (
        AVR_GCC,
        AVR_LEAVES_OUT,
        C_CHECK,
        CLANG,
        DEFAULT_BUILD,
        FLAGS,
        GCC,
        PPC_GCC,
        QEMU_PPC,
        Driver,
        agrees_with_python,
        stream_agrees_with_python,
    )

    if GCC is None:
        return
    source = c_source(built, tmp_path)
    # the golden-vector program shipped beside the C, built with the shipped specs' warning flags (the JSON
    # formatter compiled and linked in, so that it is held to them too): the examples decode, encode back and parse
    check = tmp_path / "check_vectors"
    sources = [str(source / name) for name in ("test/check_vectors.c", "matrix_case.c", "matrix_case_json.c")]
    strict = subprocess.run([GCC, *FLAGS, *sources, "-o", str(check)], capture_output=True, text=True)
    assert strict.returncode == 0 and not strict.stderr, strict.stderr
    checked = subprocess.run([str(check)], capture_output=True, text=True, timeout=60)
    assert checked.returncode == 0 and checked.stdout.endswith(" 0 failed\n"), checked.stdout + checked.stderr
    if CLANG:  # clang's own warnings (-Wparentheses-equality, ...): its front end alone, a fifth of a build's time
        clang = subprocess.run([CLANG, *FLAGS, "-fsyntax-only", *sources[1:]], capture_output=True, text=True)
        assert clang.returncode == 0 and not clang.stderr, clang.stderr
    if C_CHECK and AVR_GCC and "f64" not in name:  # 16-bit int (f64 needs an 8-byte double: AVR's has 4)
        flags = [flag for flag in FLAGS if flag not in AVR_LEAVES_OUT]
        for file in ("matrix_case.c", "matrix_case_json.c"):
            avr = [AVR_GCC, "-mmcu=atmega2560", *flags, "-Os", "-c", str(source / file), "-o", str(tmp_path / "avr.o")]
            built_for_avr = subprocess.run(avr, capture_output=True, text=True)
            assert built_for_avr.returncode == 0 and not built_for_avr.stderr, built_for_avr.stderr
    builds: list[tuple[tuple[str, ...], str]] = [((), DEFAULT_BUILD)]
    if PPC_GCC and QEMU_PPC and any(word in name for word in BYTE_ORDER_WORDS):  # values built from bytes and bits
        builds.append(((PPC_GCC, "-static"), "powerpc-be"))
    for command, build_name in builds:
        folder = tmp_path / build_name
        folder.mkdir()
        run = Driver("matrix_case", source, folder, command, build_name)
        try:
            for direction in g.protocol.framing.layouts:
                frames = []
                for message in g.protocol.messages():
                    if message.direction == direction:
                        request = asked(g, message)
                        for fields in st_examples(message_fields(g.protocol, message), 3):
                            fields = fitted(message, fields, request)
                            frames.append(agrees_with_python(run, g, message, fields, request))
                stream_agrees_with_python(run, g, direction, b"\x00\x01".join(frames) + b"\x02", "1,3,0,7")
                awaited_streams(run, g, direction)
                for element in g.protocol.framing.layouts[direction].optional:
                    # each message with the optional element sent and not, the frames back to back, in any split
                    both = [
                        agrees_with_python(run, g, message, fields)
                        for message in g.protocol.messages()
                        if message.direction == direction
                        for fields in both_ways(g, message, element)
                    ]
                    stream_agrees_with_python(run, g, direction, b"".join(both), "2,1,5")
            crafted(run, g, name)
        finally:
            run.close()


def awaited_streams(run: Any, g: Generated, direction: Direction) -> None:
    """Replies read with their request: for each reply, frames of it answering one request among garbage, the C
    parser awaiting it (parser_expect_reply) as the Python parser does (expect(cls, request))."""
    from conftest import a_request, needs_request
    from test_c_backend import agrees_with_python, stream_agrees_with_python

    for message in g.protocol.messages():
        if message.direction != direction or not needs_request(g, message):
            continue
        request = a_request(g, message)
        frames = [
            agrees_with_python(run, g, message, fitted(message, fields, request), request)
            for fields in st_examples(message_fields(g.protocol, message), 2)
        ]
        stream = b"\x00".join(frames) + b"\x80" + frames[0][:-1]
        stream_agrees_with_python(run, g, direction, stream, "1,4,2", message, request=request)


def c_source(built: Built, tmp_path: Path) -> Path:
    """The case's C files written to tmp_path/c."""
    c_files = [path for path in built.files if path.startswith("c/matrix_case/")]
    assert c_files, "C files"
    source = tmp_path / "c"
    source.mkdir()
    for path, text in built.files.items():
        if path.startswith("c/matrix_case/"):
            target = source / path.removeprefix("c/matrix_case/")
            target.parent.mkdir(exist_ok=True)
            target.write_text(text, encoding="utf-8")
    return source


# Frames that reach a feature of the C that random messages rarely do, for the probe request of a case, and the
# garbage between them: c_target checks each as it checks the random ones, and their stream byte by byte and in
# pieces. Frames ended by their trailer alone: the trailer byte (0D) inside contents, a checksum that is 0D itself
# (code 1 ^ 0D ^ 0D ^ 0C), garbage full of it. XBee API mode 2: lengths that are escaped themselves (0x11, 0x13,
# 0x7D: 3 + len(data)), contents of escaped bytes. COBS with a length inside the span: contents of zeros, runs at the
# COBS limit of 254 bytes, an empty one.
C_FRAMES: dict[str, tuple[dict[str, Any], list[bytes], bytes]] = {
    "frame: ended by a terminator, no length": (
        {"v": 0x0D0D},
        [b"\x0d", b"\x0d\x0d\x0c", b"", b"\x0d\x3a\x0d\x00", b"\x0c"],
        b"\x0d\x3a\x0d",
    ),
    "transform: replace, escaping after the start byte, over the length and checksum (XBee API mode 2)": (
        {"v": 0x7D7E},
        [bytes(0x11 - 3), b"\x7e" * (0x13 - 3), b"\x7d\x11" * 61, b"\x13\x7e", b""],
        b"\x7e\x00\x7d",
    ),
    "transform: cobs, after a header, with a length inside the span (it counts the plain bytes)": (
        {"v": 0x0100},
        # FE: the sum is 00, so the span ends in 00 (its COBS form ends 01 01: the parsers sized it one byte short)
        [bytes(5), b"", bytes(range(1, 253)), b"\x00\x01\x00", bytes(range(1, 250)) + b"\x00", b"\xfe"],
        b"\xaa\x00\xaa\x03",
    ),
    # the length's forms at their edges: 255 in one byte (data 2), 258 in the long form (data 3: 256 and 257 cannot
    # be: 3 more bytes of length), 511 (data 256: the C's data room, P_..._MAX), the marker 01 and FF in the data and
    # the garbage
    "frame: extended length (a marker, then a u16), counting itself": (
        {"pad": " ".join(["01"] * 251)},
        [b"", b"\x01", b"\xff\x01", b"\x01\xff\x01", bytes(range(256)), b"\x01" * 4],
        b"\x01\x01\x00\xff",
    ),
}


def crafted(run: Any, g: Generated, name: str) -> None:
    """The case's C_FRAMES through the C: each as Python gives it, and their stream (garbage between them, a frame
    begun at the end) byte by byte and in pieces as the Python parser gives it."""
    from test_c_backend import agrees_with_python, stream_agrees_with_python

    if name not in C_FRAMES:
        return
    values, contents, garbage = C_FRAMES[name]
    probe = next(m for m in g.protocol.messages() if m.direction == Direction.REQUEST and m.command == "probe")
    frames = [agrees_with_python(run, g, probe, {**values, "data": data.hex(" ")}) for data in contents]
    stream = garbage.join(frames) + garbage + frames[0][:3]
    for sizes in ("1", "3,1,7"):
        stream_agrees_with_python(run, g, Direction.REQUEST, stream, sizes)


def both_ways(g: Generated, message: Message, element: Any) -> list[dict[str, Any]]:
    """A message's fields with an optional frame element sent and not (a value flag element's bit set to say so)."""
    fields = st_examples(message_fields(g.protocol, message), 1)[0]
    flag, mask = element.present_if
    sent = {element.name: " ".join(f"{b:02x}" for b in range(0xA0, 0xA0 + element.size))}
    if flag in fields:
        return [
            {**fields, **sent, flag: fields[flag] | mask},
            {**fields, element.name: None, flag: fields[flag] & ~mask},
        ]
    return [{**fields, **sent}, {**fields, element.name: None}]


# Cases whose C builds values from bytes or bits the host's byte order could get wrong: also run on big-endian
# PowerPC (under qemu-ppc) where its cross gcc is installed
BYTE_ORDER_WORDS = ("u24", "i24", "u64", "i64", "f64", "u11", "i5", "scale and offset")


def test_the_clients_of_every_case_pass_ruff(tmp_path: Path) -> None:
    """Every case's clients (client.py, and aio.py made from the same context) with no unused import, no undefined
    name, imports in ruff's order: the project's own gate, for specs the six protocols do not cover."""
    for number, name in enumerate(sorted(CASES)):
        for path, text in build(name).files.items():
            if path.endswith(("/client.py", "/aio.py", "/__init__.py")):
                (tmp_path / str(number) / path).parent.mkdir(parents=True, exist_ok=True)
                (tmp_path / str(number) / path).write_text(text, encoding="utf-8")
    config = str(Path(__file__).parents[1] / "pyproject.toml")
    ruff = subprocess.run(
        # long lines are allowed in generated code (pyproject's rule for generated/, which tmp_path is not under)
        [sys.executable, "-m", "ruff", "check", "--no-cache", "--config", config, "--ignore", "E501", str(tmp_path)],
        capture_output=True,
        text=True,
    )
    assert ruff.returncode == 0, ruff.stdout + ruff.stderr


SETTINGS = settings(max_examples=examples(6), deadline=None, suppress_health_check=list(HealthCheck))


def requesting(g: Generated) -> bool:
    """Replies are read with the request they answer (codeless replies in layouts chosen by command, a checksum over
    request bytes)."""
    framing = g.protocol.framing
    return any(framing.by_request(d) for d in framing.alternatives) or framing.from_request


def asked(g: Generated, message: Message) -> Any:
    """A request the response `message` answers (or refuses: `refused_by`), where replies are read with their
    request; else None."""
    if not requesting(g) or message.direction.value != "response":
        return None
    replies = replies_by_request(g.protocol.messages())
    request = next(
        m
        for m in g.protocol.messages()
        if m.direction.value == "request" and (reply_to(m, replies) == message or message in refusals_of(m, replies))
    )
    return message_class(g, request).from_fields(st_examples(message_fields(g.protocol, request), 1)[0])


def codec_and_structs(g: Generated, message: Message) -> None:
    cls = message_class(g, message)
    request = asked(g, message)
    given_request = () if request is None else (request,)
    context = (
        {} if request is None else {"layout": g.protocol.layout(message).name, "request": g.package.encode(request)}
    )

    @SETTINGS
    @given(message_fields(g.protocol, message))
    def round_trip(fields: dict[str, Any]) -> None:
        fields = fitted(message, fields, request)
        frame = g.package.encode(cls.from_fields(fields), *given_request)
        decoded = g.package.decode(frame, message.direction.value, cls, *given_request)
        assert decoded.to_fields() == fields
        assert g.package.encode(cls.from_fields(json.loads(json.dumps(decoded.to_fields()))), *given_request) == frame
        check_against_construct(g, message, frame, fields, context)
        if request is not None and g.protocol.framing.codeless_replies:
            # one layout's code-less replies: decoded alone as the default reply, or refused by its size
            default = next(m for m in g.protocol.messages() if m.direction == message.direction and m.default_reply)
            try:
                alone = g.package.decode(frame, message.direction.value)
            except DecodeError:
                assert default.min_size != message.min_size
            else:
                assert type(alone).__name__ == default.class_name
        elif request is not None:  # without its request, such a reply is refused in one line
            with pytest.raises(DecodeError, match="give the request"):
                g.package.decode(frame, message.direction.value)

    round_trip()


def stream(g: Generated) -> None:
    """Random frames among garbage that holds no header byte, in random pieces: all of them, in order."""
    for direction in ("request", "response"):
        stream_direction(g, direction)


def stream_direction(g: Generated, direction: str) -> None:
    headers = {
        e.constant[0]
        for layouts in g.protocol.framing.alternatives.values()
        for layout in layouts
        for e in layout.elements
        if e.role == "header" and e.constant
    }
    if g.protocol.framing.by_command:  # no header: no byte an address at a frame's start can have either
        headers |= {
            v
            for layouts in g.protocol.framing.alternatives.values()
            for layout in layouts
            for e in layout.elements[:1]
            if e.role == "address"
            for v in range(int(e.minimum), int(e.maximum) + 1)
        }
    layouts = g.protocol.framing.alternatives[Direction(direction)]
    if any(layout.elements[0].role == "command" for layout in layouts):  # no header: no byte a code can be
        headers |= {c.wire_code(Direction(direction)) or 0 for c in g.protocol.commands if c.code is not None}
    bare = any(layout.elements[0].role == "content" for layout in layouts)
    if bare:  # no header, no command element: no byte a message's leading constant can begin with (Kondo ICS)
        for message in g.protocol.messages():
            found = leading_constant(message)
            if found is not None and found[0][0] == 1:
                (_, _, shift, bits), value = found
                headers |= {b for b in range(256) if b >> shift & ((1 << bits) - 1) == value}
            elif message.direction.value == direction:
                headers |= set(range(256))  # any byte can begin one (Maestro's code-less replies): no garbage
    garbage = st.binary(max_size=6).map(lambda b: bytes(x for x in b if x not in headers))
    messages = [m for m in g.protocol.messages() if m.direction.value == direction]
    if g.protocol.framing.by_request(Direction(direction)):
        for message in messages:  # replies read with the pending request: those of one request at a time
            replies_direction(g, message, garbage)
        return
    drawn_messages = st.sampled_from(messages).flatmap(lambda m: st.tuples(st.just(m), message_fields(g.protocol, m)))

    @SETTINGS
    @given(st.lists(drawn_messages, min_size=1, max_size=4), st.lists(garbage, min_size=5, max_size=5), st.data())
    def parse(drawn: list[tuple[Message, dict[str, Any]]], noise: list[bytes], data: st.DataObject) -> None:
        frames = [g.package.encode(message_class(g, m).from_fields(f)) for m, f in drawn]
        wire = b"".join(noise[i % 5] + frame for i, frame in enumerate(frames)) + noise[-1]
        cuts = sorted(data.draw(st.lists(st.integers(0, len(wire)), max_size=6)))
        parser = g.package.StreamParser(direction)
        pieces = [wire[a:b] for a, b in zip([0, *cuts], [*cuts, len(wire)], strict=True)]
        got = [m.to_fields() for piece in pieces for m in parser.feed(piece)]
        trickle = g.package.StreamParser(direction)
        one_by_one = [m.to_fields() for byte in wire for m in trickle.feed(bytes([byte]))]
        assert got == one_by_one == [f for _, f in drawn]

    parse()


def replies_direction(g: Generated, message: Message, garbage: st.SearchStrategy[bytes]) -> None:
    """Replies to one pending request among garbage in random pieces: all of them, in order."""
    cls, request = message_class(g, message), asked(g, message)

    @SETTINGS
    @given(
        st.lists(message_fields(g.protocol, message), min_size=1, max_size=4),
        st.lists(garbage, min_size=5, max_size=5),
        st.data(),
    )
    def parse(drawn: list[dict[str, Any]], noise: list[bytes], data: st.DataObject) -> None:
        drawn = [fitted(message, f, request) for f in drawn]
        frames = [g.package.encode(cls.from_fields(f), request) for f in drawn]
        wire = b"".join(noise[i % 5] + frame for i, frame in enumerate(frames)) + noise[-1]
        cuts = sorted(data.draw(st.lists(st.integers(0, len(wire)), max_size=6)))
        parser, trickle, idle = (g.package.StreamParser("response") for _ in range(3))
        parser.expect(cls, request)
        trickle.expect(cls, request)
        pieces = [wire[a:b] for a, b in zip([0, *cuts], [*cuts, len(wire)], strict=True)]
        got = [m.to_fields() for piece in pieces for m in parser.feed(piece)]
        one_by_one = [m.to_fields() for byte in wire for m in trickle.feed(bytes([byte]))]
        assert got == one_by_one == drawn
        assert idle.feed(wire) == []  # no request pending: no reply is taken

    parse()


def client_against_simulator(g: Generated) -> None:
    simulator_module = importlib.import_module("matrix_case.simulator")
    client_module = importlib.import_module("matrix_case.client")
    simulator_class = next(
        v
        for k, v in vars(simulator_module).items()
        if k.endswith("Simulator") and k != "Simulator" and isinstance(v, type)
    )
    request = next(m for m in g.protocol.messages() if m.direction.value == "request" and m.command == "probe")
    response = reply_to(request, replies_by_request(g.protocol.messages()))
    assert response is not None
    addresses = [e for e in g.protocol.framing.layouts[request.direction].value_elements if e.role == "address"]
    device = 1 if not addresses or addresses[0].minimum <= 1 <= addresses[0].maximum else int(addresses[0].minimum)
    simulator = simulator_class(ids=[device])
    path = simulator.start()
    try:
        with Bus(path, client_module.BINDING, timeout=1.0) as bus:
            # an address some layout does not carry: None too (a request in the form without it, answered so)
            partial = g.protocol.framing.partial_values(request.direction)
            ids = [device, None] if any(e.name in partial for e in addresses) else [device]
            for fields in st_examples(message_fields(g.protocol, request), 3):
                for given in ids:
                    fields = {**fields, **{e.name: given for e in addresses}}
                    reply = bus.request(message_class(g, request).from_fields(fields), message_class(g, response))
                    assert type(reply) is message_class(g, response)
                    assert given is not None or all(getattr(reply, e.name, None) is None for e in addresses), reply
        asking = [m for m in g.protocol.messages() if m.asks_in]
        if asking:  # the generated method of a request that asks for probe's reply by probe's code
            client_class = next(v for k, v in vars(client_module).items() if k.endswith("Client") and k != "Client")
            with client_class(path, timeout=1.0) as client:
                for m in asking:
                    method = getattr(client, m.key)
                    assert type(method(**{e.name: device for e in addresses}, **{m.asks_in: 1})) is message_class(
                        g, response
                    )
    finally:
        simulator.close()


def st_examples(strategy: st.SearchStrategy[Any], count: int) -> list[Any]:
    found: list[Any] = []

    @settings(max_examples=count, deadline=None, suppress_health_check=list(HealthCheck), database=None)
    @given(strategy)
    def take(value: Any) -> None:
        found.append(value)

    take()
    return found[:count]


def cli_decode(g: Generated, spec: Path) -> None:
    for message in g.protocol.messages():
        request = asked(g, message)
        fields = fitted(message, st_examples(message_fields(g.protocol, message), 1)[0], request)
        frame = g.package.encode(
            message_class(g, message).from_fields(fields), *(() if request is None else (request,))
        )
        out = io.StringIO()
        given = [] if request is None else ["--request", g.package.encode(request).hex(" ")]
        with contextlib.redirect_stdout(out):
            code = cli.main(
                ["decode", str(spec), frame.hex(" "), "--json", "--direction", message.direction.value, *given]
            )
        assert code == 0, out.getvalue()
        decoded = json.loads(out.getvalue())
        assert decoded["command"] == message.command and decoded["direction"] == message.direction.value


# --- text frames (`framing: {kind: text}`) ------------------------------------------------------------------------

TEXT_CASE: dict[str, Any] = {
    "protocol": "matrix_text",
    "title": "Every text alternative",
    "serial": {"baudrate": 9600},
    "framing": {
        "kind": "text",
        "start": "#",
        "separator": ";",
        "checksum": {"algorithm": "sum", "invert": True, "marker": "!", "format": "hex2", "required": True},
        "end": "\n",
        "talker": {"size": 1, "values": ["A", "B"], "description": "The unit."},
        "max_length": 160,
    },
    "fields": {"side": {"type": "char", "letters": {"north": "N", "south": "S"}}},
    "commands": {
        "every": {
            "code": "EV",
            "title": "Every kind",
            "request": {
                "fields": {
                    "d": {"type": "decimal", "precision": 2, "width": 3, "range": [0, 500], "unit": "V"},
                    "i": {"type": "integer", "width": 2, "range": [0, 99]},
                    "x": {"type": "integer", "base": 16, "width": 4, "range": [0, 65535]},  # hex digits: `0A3F`
                    "lx": {"type": "integer", "base": 16, "case": "lower", "range": [-4096, 4096]},  # `-fa`
                    "a": {"type": "angle", "width": 3, "precision": 3, "range": [0, 180]},
                    "h": {"use": "side"},
                    "g": "side",
                    "c": "char",
                    "t": {"type": "text", "description": "Free text."},
                    "clock": {"type": "time", "precision": 1},
                    "day": "date",
                    "fixed": {"type": "repeat", "count": 2, "fields": {"x": {"type": "integer", "range": [0, 9]}}},
                    "tail": {
                        "type": "repeat",
                        "max_count": 3,
                        "fields": {"y": {"type": "decimal", "precision": 1, "range": [0, 99]}, "z": "char"},
                    },
                }
            },
        },
        "answer": {"code": "OK", "response": {"unsolicited": True, "fields": {"ok": {"use": "side"}}}},
        "dial": {
            "code": "DL",
            "title": "A request answered under the same code",
            "request": {"fields": {"level": {"type": "integer", "range": [0, 99]}, "note": "text"}},
            "response": {
                "fields": {
                    "level": {"type": "integer", "range": [0, 99]},
                    "volts": {"type": "decimal", "precision": 1, "range": [0, 50]},
                    "count": {"type": "integer", "range": [0, 999]},
                    "note": "text",
                }
            },
        },
    },
    "device": {
        "state": {"level": 0, "supply": 12.5, "dials": 0},
        "commands": {
            "dial": {
                "description": "Every key a text device's answer has.",
                "stores": {"level": "level"},
                "sets": {"dials": 1},
                "reports": {"volts": "supply * 2", "count": "dials + level"},
                "echoes": ["note"],
            }
        },
    },
}


# Messages in their own text with labels (each output's tests add them to the text case): inside a start and an ending,
# found in any order, a value after the code labelled with it (GRBL's `<Hold:0|MPos:…>`), labelled repeats; found by
# their code, labels glued to their values without a separator, the first labelled with the code (LSS's
# `D1800T1500`), and with one (G-code's `G1 X10.5 Y-3`).
LABELLED_COMMANDS: dict[str, Any] = {
    "report": {
        "code": "RP",
        "response": {
            "unsolicited": True,
            "text": {"start": "<", "end": ">", "separator": "|", "named": "=", "list": ","},
            "fields": {
                "sub": {"label": "RP", "type": "integer", "range": [0, 9]},  # after the code: `<RP=3|…>`
                "lvl": {"label": "LV", "type": "integer", "range": [0, 99]},
                "pos": {
                    "label": "P",
                    "type": "repeat",
                    "count": 2,
                    "fields": {"x": {"type": "decimal", "precision": 1}},
                },
                "sats": {"label": "S", "type": "repeat", "max_count": 3, "fields": {"n": "integer", "s": "side"}},
            },
        },
    },
    "move": {
        "code": "MV",
        "response": {
            "unsolicited": True,
            "text": {"named": "", "separator": ""},
            "fields": {
                "at": {"label": "MV", "type": "integer"},
                "time": {"label": "T", "type": "integer"},
                "speed": {"label": "SD", "type": "decimal"},
            },
        },
    },
    "words": {
        "code": "GW",
        "response": {
            "unsolicited": True,
            "text": {"named": ""},
            "fields": {"x": {"label": "X", "type": "decimal"}, "y": {"label": "Y", "type": "integer"}},
        },
    },
}


def text_c_compiles(files: dict[str, str], tmp_path: Path) -> None:
    """The text case's C compiles without a warning under the shipped specs' flags."""
    from test_c_backend import FLAGS, GCC

    assert {path.rsplit("/", 1)[1] for path in files} >= {"matrix_text.c", "matrix_text_json.c", "matrix_text.h"}
    if GCC is None:
        return
    for path, text in files.items():
        (tmp_path / path.rsplit("/", 1)[1]).write_text(text, encoding="utf-8")
    for c in ("matrix_text.c", "matrix_text_json.c"):
        done = subprocess.run([GCC, *FLAGS, "-c", str(tmp_path / c), "-o", os.devnull], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr


def test_every_text_alternative_through_every_output(tmp_path: Path) -> None:
    """The text kinds, both repeat forms, letters (shared and own), the sum checksum, a talker: the front end, every
    target (the C compiled under the strict flags, the Wireshark dissector), the markdown page,
    the generated package (random messages round trip; a stream of them among garbage, byte by byte, gives them
    back)."""
    from serialspec.backends import emit
    from serialspec.lang.passes.text import KINDS

    protocol = resolve(load_text(yaml.safe_dump(TEXT_CASE, sort_keys=False), "matrix_text.yaml"))
    assert protocol.text is not None
    used = {f.kind for m in protocol.text.messages for i in m.fields for f in getattr(i, "fields", (i,))}
    assert set(KINDS) - used == set()
    assert set(grammar.FRAMING.keys["kind"].choices) == {"binary", "text"}  # type: ignore[attr-defined]
    files: dict[str, str] = {}
    for emitter in emitters():
        emitted = emit(emitter, protocol)
        if emitter.name == "wireshark":  # tests/test_wireshark_text.py runs the case's dissector under tshark
            assert list(emitted) == ["matrix_text/matrix_text.lua"]
            assert "local SPEC = " in emitted["matrix_text/matrix_text.lua"]
            continue
        if emitter.name == "c":  # every kind as C (tests/test_c_text.py holds the case's C to the Python codec)
            text_c_compiles(emitted, tmp_path)
            continue
        assert emitter.verify is None or emitter.verify(protocol, emitter.files(protocol)) == []
        files.update(emitted)
    docs = files["docs/matrix_text.md"]
    assert "### `EV`: Every kind" in docs and "`tail[].z`" in docs and "Traceback" not in docs
    modules = {p.split("/", 1)[1]: t for p, t in files.items() if p.startswith("matrix_text/")}
    with imported("matrix_text", modules, "the language matrix") as package:
        for cls in package.MESSAGE_TYPES:
            direction = cls.DIRECTION.value
            frames, messages = random_frames(package, cls, 20)
            parser = package.StreamParser(direction)
            assert [m for byte in frames for m in parser.feed(bytes([byte]))] == messages
        # the device answers the request under its code, as `device.commands.dial` says
        device = importlib.import_module("matrix_text.simulator").SIMULATOR()
        asked = package.DialRequest(talker="A", level=7, note="hi")
        [(_, frame)] = device.feed(package.encode(asked))
        answer = package.decode(frame, "response")
        assert (answer.level, answer.volts, answer.count, answer.note) == (7, 25, 8, "hi"), answer
        # both directions in one stream (a monitor's): the answer right after its request is the response
        both = package.StreamParser()
        assert both.feed(package.encode(asked) + frame) == [asked, answer]
        # integers in hex digits (`base: 16`): upper case, zero-padded to the width; `case: lower`; either case read
        hexed = package.FRAMING.encode("EV", {"x": 0x0A3F, "lx": -250}, "A", direction="request")
        assert hexed.startswith(b"#AEV;;;0A3F;-fa;"), hexed
        assert package.FRAMING.decode(b"#AEV;;;0a3f;-FA" + hexed[15:]).values["lx"] == -250


def test_line_ends_by_direction_and_a_reply_code_of_its_own_through_every_output(tmp_path: Path) -> None:
    """`end: {request: ..., response: ...}` and a response's `text: {code: ...}` of several words (an ELM327's `010C`
    answered `41 0C 1A F8 ` and CR CR `>`): every output takes both (the C compiles; tests/test_c_text.py and
    tests/test_wireshark_text.py hold the C and the dissector to Python); the reference says both; each direction ends
    with its own; the reply is found by its own code, the simulator answers with it and the codec pairs it with its
    request; random messages round trip, all in one stream of both directions read byte by byte; misuse (and of `base`,
    `case`) refused one line each."""

    case = copy.deepcopy(TEXT_CASE)
    case["framing"]["end"] = {"request": "\n", "response": "\n\n>"}
    case["commands"]["dial"]["response"]["text"] = {"code": "RE;DL"}
    files = python_and_markdown(case, {})
    text_c_compiles({p: t for p, t in files.items() if p.startswith("matrix_text/matrix_text")}, tmp_path)
    source = files["matrix_text/matrix_text.c"]
    assert "matrix_text__response_end[] = {0x0Au, 0x0Au, 0x3Eu, 0x00u}" in source and '"RE\\073DL"' in source
    docs = files["docs/matrix_text.md"]
    assert "| end | LF (requests), LF LF > (responses) |" in docs
    assert "`DialResponse`, a response, under a code of its own (its request's is `DL`)" in docs
    own_code = copy.deepcopy(case)
    own_code["framing"]["end"] = "\n"
    python_and_markdown(own_code, {})
    modules = {p.split("/", 1)[1]: t for p, t in files.items() if p.startswith("matrix_text/")}
    with imported("matrix_text", modules, "the language matrix") as package:
        asked = package.DialRequest(talker="A", level=7, note="hi")
        assert package.encode(asked).endswith(b"\n") and not package.encode(asked).endswith(b">")
        device = importlib.import_module("matrix_text.simulator").SIMULATOR()
        [(_, frame)] = device.feed(package.encode(asked))
        assert frame.startswith(b"#ARE;DL;7;") and frame.endswith(b"\n\n>"), frame
        answer = package.decode(frame)
        assert (answer.level, answer.volts, answer.note) == (7, 25, "hi") and package.encode(answer) == frame
        assert package.CODEC.replies("DL")[0] == (package.DialResponse,)  # what a client awaits after `DL`
        frames, messages = b"", []
        for cls in package.MESSAGE_TYPES:
            more, decoded = random_frames(package, cls, 10)
            frames, messages = frames + more, messages + decoded
        parser = package.StreamParser()  # both directions: a request's LF is not the start of a reply's ending
        assert [m for byte in frames + b"\x00" for m in parser.feed(bytes([byte]))] == messages
    for where, change, expected in (
        (("framing", "end"), {"request": "\n", "response": "\n"}, "framing.end: give each direction its own"),
        (("commands", "dial", "response", "text"), {"code": "RE;;DL"}, "text.code: a text code is letters, digits"),
        (("commands", "dial", "response", "text"), {"code": "RE;DL", "start": "<"}, "a text code is letters"),
        (("commands", "dial", "request", "fields", "level"), {"type": "integer", "case": "lower"}, "needs `base: 16`"),
        (("commands", "dial", "request", "fields", "level"), {"type": "decimal", "base": 16}, "`base` does not apply"),
        (("commands", "dial", "request", "fields", "level"), {"type": "integer", "base": 8}, "expected one of 10, 16"),
    ):
        broken = copy.deepcopy(case)
        target = broken
        for key in where[:-1]:
            target = target[key]
        target[where[-1]] = change
        with pytest.raises(SpecErrors) as refused:
            resolve(load_text(yaml.safe_dump(broken, sort_keys=False), "matrix_text.yaml"))
        lines = str(refused.value).splitlines()
        assert len(lines) == 1 and expected in lines[0] and lines[0].startswith("matrix_text.yaml:"), lines


def test_a_reply_of_values_alone_through_every_output() -> None:
    """`values_only` on a text response (the dial's): every output takes it (the C reads it as the reply awaited, the
    dissector as the reply to the request right before it: tests/test_c_text.py and tests/test_wireshark_text.py hold
    them to Python, in the case without a start); the reference shows the reply without its code; the package reads it
    with its request, the simulator answers with it, and a stream of both directions takes it after its request."""

    case = copy.deepcopy(TEXT_CASE)
    case["commands"]["dial"]["response"]["values_only"] = True
    protocol = resolve(load_text(yaml.safe_dump(case, sort_keys=False), "matrix_text.yaml"))
    files: dict[str, str] = {}
    for emitter in emitters():
        emitted = emitter.files(protocol)
        assert emitter.verify is None or emitter.verify(protocol, emitted) == []
        files.update(emitted)
    assert "its values alone: no code" in files["docs/matrix_text.md"] and "matrix_text/matrix_text.c" in files
    assert "matrix_text/matrix_text.lua" in files
    modules = {p.split("/", 1)[1]: t for p, t in files.items() if p.startswith("matrix_text/")}
    with imported("matrix_text", modules, "the language matrix") as package:
        device = importlib.import_module("matrix_text.simulator").SIMULATOR()
        asked = package.DialRequest(talker="A", level=7, note="hi")
        [(_, frame)] = device.feed(package.encode(asked))
        assert frame.startswith(b"#7;"), frame  # the values alone, the first one right after the start
        answer = package.decode(frame, "response", None, asked)
        assert (answer.level, answer.volts, answer.count, answer.note) == (7, 25, 8, "hi"), answer
        assert package.encode(answer) == frame
        both = package.StreamParser()
        assert both.feed(package.encode(asked) + frame) == [asked, answer]


@pytest.mark.parametrize("many", [False, True])
def test_an_answer_ended_by_another_line_through_every_output(many: bool, tmp_path: Path) -> None:
    """`answered_by: {command, then}` on a text request (an AT command's reply line, then its `OK`), with `many`
    (the reply any number of times) and without: every output takes the spec (the C and the dissector read each line
    alone, as before; the C compiles clean), the reference says which line ends the answer, the client's method
    returns the reply (`many`: a tuple of them), and the simulator sends the reply and then that line."""
    from serialspec.backends import emit

    case = copy.deepcopy(TEXT_CASE)
    case["commands"]["ask"] = {
        "code": "AS",
        "title": "Asked for the dial's reply, the answer ended by OK",
        "request": {
            "fields": {"level": {"type": "integer", "range": [0, 99]}, "note": "text"},
            "answered_by": {"command": "dial", "then": "answer", "many": many},
        },
    }
    case["device"]["commands"]["ask"] = case["device"]["commands"]["dial"]
    case["device"]["reply"] = {"ok": "S"}
    protocol = resolve(load_text(yaml.safe_dump(case, sort_keys=False), "matrix_text.yaml"))
    files: dict[str, str] = {}
    for emitter in emitters():
        emitted = emit(emitter, protocol)
        if emitter.name == "c":
            text_c_compiles(emitted, tmp_path)
        assert emitter.verify is None or emitter.verify(protocol, emitted) == []
        files.update(emitted)
    assert "then the `answer` response, which ends the answer" in files["docs/matrix_text.md"]
    returned = "tuple[DialResponse, ...]" if many else "DialResponse"
    assert f"timeout: float = 1.0) -> {returned}:" in files["matrix_text/__init__.py"]
    modules = {p.split("/", 1)[1]: t for p, t in files.items() if p.startswith("matrix_text/")}
    with imported("matrix_text", modules, "the language matrix") as package:
        assert package.CODEC.final("AS") is package.AnswerResponse and package.CODEC.final("DL") is None
        device = importlib.import_module("matrix_text.simulator").SIMULATOR()
        [(_, frames)] = device.feed(package.encode(package.AskRequest(talker="A", level=7, note="hi")))
        reply, ending = package.StreamParser("response").feed(frames)
        assert (reply.level, reply.volts, reply.count, reply.note) == (7, 25, 8, "hi"), reply
        assert ending == package.AnswerResponse(talker=ending.talker, ok=package.Side.SOUTH), ending


def test_a_message_s_own_text_layout_through_every_output(tmp_path: Path) -> None:
    """`text:` (a message's own start, end, separator, labels and lists; a field labelled with the code, its value right
    after the code) beside the case's plain sentences: the C compiles (tests/test_c_text.py holds it to Python,
    tests/test_wireshark_text.py the dissector to decode); the markdown page shows the labels; the generated package
    round-trips random messages (labels left out where a value is None) and finds them byte by byte among garbage and
    other sentences; the simulator sends it."""
    from serialspec.backends import emit
    from serialspec.runtime.text import TextField, TextRepeat
    from test_text_frames import sentence_values

    case = copy.deepcopy(TEXT_CASE)
    case["commands"]["report"] = copy.deepcopy(LABELLED_COMMANDS["report"]) | {"title": "A report in its own text"}
    case["device"]["sends"] = {"report": {"every": 100, "values": {"lvl": "level"}}}
    protocol = resolve(load_text(yaml.safe_dump(case, sort_keys=False), "matrix_text.yaml"))
    assert protocol.text is not None
    files: dict[str, str] = {}
    for emitter in emitters():
        emitted = emit(emitter, protocol)
        if emitter.name == "c":
            text_c_compiles(emitted, tmp_path)
            continue
        assert emitter.verify is None or emitter.verify(protocol, emitted) == []
        files.update(emitted)
    docs = files["docs/matrix_text.md"]
    assert "| `RP=`, right after the code | `sub` |" in docs
    assert "| `LV=` | `lvl` |" in docs and "`sats[].n`" in docs and "Its own text inside the frame: `<`" in docs
    modules = {p.split("/", 1)[1]: t for p, t in files.items() if p.startswith("matrix_text/")}
    with imported("matrix_text", modules, "the language matrix") as package:
        sentence = package.FRAMING.sentence("RP", "response")
        assert all(isinstance(f, TextField | TextRepeat) and f.label for f in sentence.fields)
        frames, messages = b"", []
        other = package.encode(package.AnswerResponse(talker="A", ok=package.Side.NORTH))
        for values in st_examples(sentence_values(sentence), 20):
            message = package.ReportResponse.from_fields(values, talker="B")
            frame = package.encode(message)
            assert frame.startswith(b"#<BRP") and package.decode(frame, "response") == message
            frames += b"\x00garbage#\n" + frame + other
            messages += [message, package.AnswerResponse(talker="A", ok=package.Side.NORTH)]
            sub = package.encode(package.ReportResponse.from_fields({**values, "sub": 3}, talker="B"))
            assert sub.startswith(b"#<BRP=3") and b"RP=" not in sub[7:]  # right after the code, once
        parser = package.StreamParser("response")
        assert [m for byte in frames for m in parser.feed(bytes([byte]))] == messages
        device = importlib.import_module("matrix_text.simulator").SIMULATOR()
        sent = [package.decode(frame, "response") for _, frame in device.due()]
        assert any(isinstance(m, package.ReportResponse) and m.lvl == 0 for m in sent), sent


def random_frames(package: ModuleType, cls: Any, count: int) -> tuple[bytes, list[Any]]:
    """`count` random messages of a text message class, each checked to round trip (decode, and encode again byte
    for byte): their frames, each after some garbage, and the messages."""
    from serialspec.runtime.text import TextField, TextRepeat
    from test_text_frames import sentence_values

    direction = cls.DIRECTION.value
    sentence = package.FRAMING.sentence(cls.CODE, direction)
    assert all(isinstance(f, TextField | TextRepeat) for f in sentence.fields)

    def sendable(values: dict[str, Any]) -> bool:  # a text holding a character of the framing's is refused
        try:
            package.encode(cls.from_fields(values, talker="B"))
        except EncodeError:
            return False
        return True

    frames, messages = b"", []
    for values in st_examples(sentence_values(sentence).filter(sendable), count):
        message = cls.from_fields(values, talker="B")
        frame = package.encode(message)
        assert package.decode(frame, direction) == message, frame
        assert package.encode(package.decode(frame, direction)) == frame
        frames += b"\x00garbage#\n" + frame
        messages.append(message)
    return frames, messages


def streams_back(package: ModuleType, classes: tuple[Any, ...], direction: str | None) -> None:
    """Random messages of these classes round trip (random_frames), and a stream of all of them among garbage, fed
    byte by byte, gives them back in order."""
    frames, messages = b"", []
    for cls in classes:
        more, decoded = random_frames(package, cls, 10)
        frames, messages = frames + more, messages + decoded
    parser = package.StreamParser(direction)
    assert [m for byte in frames for m in parser.feed(bytes([byte]))] == messages


def python_and_markdown(
    case: dict[str, Any], refused: str | dict[str, str], refusing: tuple[str, ...] = ("c", "wireshark")
) -> dict[str, str]:
    """A text case's files from every output but those `refusing` it in one line (each verified); `refused`: the
    line they say, or each one's (the outputs refusing are then its keys)."""
    from serialspec.backends import Unsupported

    protocol = resolve(load_text(yaml.safe_dump(case, sort_keys=False), "matrix_text.yaml"))
    said = refused if isinstance(refused, dict) else dict.fromkeys(refusing, refused)
    files: dict[str, str] = {}
    for emitter in emitters():
        if emitter.name in said:
            with pytest.raises(Unsupported, match=said[emitter.name]):
                emitter.files(protocol)
            continue
        emitted = emitter.files(protocol)
        assert emitter.verify is None or emitter.verify(protocol, emitted) == []
        files.update(emitted)
    return files


def test_a_decimal_text_checksum_through_every_output() -> None:
    """`checksum: {format: decimal}` (G-code's `N1 G28*18`): every output takes it (tests/test_c_text.py holds its C
    to Python, tests/test_wireshark_text.py its dissector to decode, in the case without a start);
    the reference says how it is written; the package writes the checksum in decimal (no leading zeros), reads it
    back, refuses a wrong one and random messages round trip, byte by byte through the stream parser too."""
    from serialspec.runtime.errors import ChecksumError

    case = copy.deepcopy(TEXT_CASE)
    case["framing"]["checksum"] = {"algorithm": "xor", "format": "decimal", "marker": "!"}
    files = python_and_markdown(case, {})
    assert "matrix_text/matrix_text.c" in files  # (the C target, beside the package: matrix_text/*.py)
    assert "`!` + its value in decimal digits (0 to 255)" in files["docs/matrix_text.md"]
    modules = {p.split("/", 1)[1]: t for p, t in files.items() if p.startswith("matrix_text/")}
    with imported("matrix_text", modules, "the language matrix") as package:
        frame = package.encode(package.AnswerResponse(talker="A", ok=package.Side.NORTH))
        assert frame == b"#AOK;N!%d\n" % (ord("A") ^ ord("O") ^ ord("K") ^ ord(";") ^ ord("N")), frame
        assert package.decode(frame) == package.AnswerResponse(talker="A", ok=package.Side.NORTH)
        with pytest.raises(ChecksumError, match="bad checksum: the frame has 7, its text gives"):
            package.decode(b"#AOK;N!7\n")
        with pytest.raises(ChecksumError, match="is not a decimal number of 1 to 3 digits"):
            package.decode(b"#AOK;N!1F\n")
        for cls in package.MESSAGE_TYPES:
            direction = cls.DIRECTION.value
            frames, messages = random_frames(package, cls, 10)
            for frame in frames.split(b"\x00garbage#\n")[1:]:
                written = frame[frame.rindex(b"!") + 1 : -1]
                assert written.isdigit() and (written == b"0" or not written.startswith(b"0")), frame
            parser = package.StreamParser(direction)
            assert [m for byte in frames for m in parser.feed(bytes([byte]))] == messages


def test_messages_found_by_their_code_alone_through_every_output(tmp_path: Path) -> None:
    """A message's own `text:` without a `start` (found by its code: Roboteq's `A=12:13`) and with `after_code` (`""`:
    the value glued to the code, LSS's `D1800`) beside plain sentences and a longer code the glued one begins: every
    output takes it (the C compiles; tests/test_c_text.py and tests/test_wireshark_text.py hold the C and the dissector
    to Python); the reference says how it is written; random messages round trip and are found byte by byte among the
    others; codes that a frame could not tell apart are refused, one line each."""

    case = copy.deepcopy(TEXT_CASE)
    case["commands"]["glued"] = {
        "code": "GL",
        "response": {"unsolicited": True, "text": {"after_code": ""}, "fields": {"n": {"type": "integer"}}},
    }
    case["commands"]["longer"] = {"code": "GLX", "response": {"unsolicited": True, "fields": {"v": "integer"}}}
    case["commands"]["pairs"] = {
        "code": "PR",
        "response": {
            "unsolicited": True,
            "text": {"separator": "=", "list": ":"},
            "fields": {"vals": {"type": "repeat", "count": 2, "fields": {"v": "integer"}}},
        },
    }
    files = python_and_markdown(case, {})
    text_c_compiles({p: t for p, t in files.items() if p.startswith("matrix_text/matrix_text")}, tmp_path)
    docs = files["docs/matrix_text.md"]
    assert "found by its code: the code, the first field right after the code" in docs, docs
    modules = {p.split("/", 1)[1]: t for p, t in files.items() if p.startswith("matrix_text/")}
    with imported("matrix_text", modules, "the language matrix") as package:
        glued = package.GluedResponse(talker="A", n=-12)
        assert package.encode(glued).startswith(b"#AGL-12!")
        assert package.decode(package.encode(glued)) == glued
        assert package.decode(package.encode(package.GluedResponse(talker="A"))) == package.GluedResponse(talker="A")
        assert package.encode(package.PairsResponse.from_fields({"vals": [{"v": 1}]}, "B")).startswith(b"#BPR=1:!")
        streams_back(package, (package.GluedResponse, package.LongerResponse, package.PairsResponse), "response")
    for change, expected in (
        ({"longer": {"code": "GL5"}}, "the code 'GL' then '' begins the code 'GL5': a frame could be either"),
        ({"glued": {"response": {"fields": {"n": "text"}}}}, "the code 'GL' then '' begins the code 'GLX'"),
        ({"pairs": {"response": {"text": {"after_code": "=="}}}}, "`after_code` is one character, or empty"),
        ({"pairs": {"response": {"text": {"after_code": "!"}}}}, "`after_code` differs from the framing's"),
    ):
        broken = copy.deepcopy(case)
        for command, keys in change.items():
            target = broken["commands"][command]
            for key, value in keys.items():
                if isinstance(value, dict):
                    for inner, item in value.items():
                        target[key][inner] = {**target[key][inner], **item} if isinstance(item, dict) else item
                else:
                    target[key] = value
        with pytest.raises(SpecErrors) as refused:
            resolve(load_text(yaml.safe_dump(broken, sort_keys=False), "matrix_text.yaml"))
        lines = str(refused.value).splitlines()
        assert len(lines) == 1 and expected in lines[0] and lines[0].startswith("matrix_text.yaml:"), lines


def test_a_text_checksum_in_one_direction_through_every_output(tmp_path: Path) -> None:
    """`checksum: {directions: [request]}` (G-code: numbered lines carry one, the firmware's replies none): every output
    takes it (the C compiles; tests/test_c_text.py and tests/test_wireshark_text.py hold the C and the dissector to
    Python); requests carry the checksum, responses none (a marker in one is text), with or without the direction given;
    random messages round trip, through the stream parser too."""
    case = copy.deepcopy(TEXT_CASE)
    case["framing"]["checksum"]["directions"] = ["request"]
    files = python_and_markdown(case, {})
    text_c_compiles({p: t for p, t in files.items() if p.startswith("matrix_text/matrix_text")}, tmp_path)
    assert "; requests only |" in files["docs/matrix_text.md"]
    modules = {p.split("/", 1)[1]: t for p, t in files.items() if p.startswith("matrix_text/")}
    with imported("matrix_text", modules, "the language matrix") as package:
        answer = package.AnswerResponse(talker="A", ok=package.Side.NORTH)
        assert package.encode(answer) == b"#AOK;N\n"
        assert package.decode(b"#AOK;N\n") == answer
        dial = package.DialRequest(talker="A", level=7, note="ab")
        assert package.encode(dial).startswith(b"#ADL;7;ab!")
        assert package.decode(package.encode(dial), "request") == dial
        with pytest.raises(EncodeError, match="holds '!', which a text frame cannot carry"):
            package.encode(package.DialRequest(talker="A", level=7, note="a!b"))
        reply = package.DialResponse(talker="A", level=7, note="x!y")
        assert package.encode(reply) == b"#ADL;7;;;x!y\n"
        assert package.decode(b"#ADL;7;;;x!y\n", "response") == reply
        for cls in package.MESSAGE_TYPES:
            direction = cls.DIRECTION.value
            frames, messages = random_frames(package, cls, 10)
            parser = package.StreamParser(direction)
            assert [m for byte in frames for m in parser.feed(bytes([byte]))] == messages


def test_an_optional_text_checksum_after_a_separator_through_every_output() -> None:
    """`checksum: {required: false, separated: [request]}` (ODrive's `r vbus_voltage *93`): every output takes it
    (tests/test_c_text.py and tests/test_wireshark_text.py hold C and the dissector to Python, in the case without a
    start); requests
    write the separator before the marker, covered by the checksum, responses do not; a frame sent without the
    checksum decodes and encodes again without it; random messages round trip."""
    case = copy.deepcopy(TEXT_CASE)
    case["framing"]["checksum"].update({"required": False, "separated": ["request"]})
    files = python_and_markdown(case, {})
    assert "matrix_text/matrix_text.c" in files  # (the C target, beside the package: matrix_text/*.py)
    assert "requests write `;` before the marker, covered by it" in files["docs/matrix_text.md"]
    modules = {p.split("/", 1)[1]: t for p, t in files.items() if p.startswith("matrix_text/")}
    with imported("matrix_text", modules, "the language matrix") as package:
        dial = package.DialRequest(talker="A", level=7, note="ab")
        frame = package.encode(dial)
        assert frame.startswith(b"#ADL;7;ab;!") and package.decode(frame, "request") == dial
        assert package.decode(b"#ADL;7;ab\n", "request") == dial  # without the checksum
        assert package.encode(package.decode(b"#ADL;7;ab\n", "request")) == b"#ADL;7;ab\n"
        assert package.encode(package.AnswerResponse(talker="A", ok=package.Side.NORTH)).startswith(b"#AOK;N!")
        sum_without = (~sum(b"ADL;7;ab")) & 0xFF  # the separator is covered: one over the fields alone fails
        with pytest.raises(DecodeError, match="bad checksum: the frame has"):
            package.decode(b"#ADL;7;ab;!%02X\n" % sum_without, "request")
        for cls in package.MESSAGE_TYPES:
            frames, messages = random_frames(package, cls, 10)
            parser = package.StreamParser(cls.DIRECTION.value)
            assert [m for byte in frames for m in parser.feed(bytes([byte]))] == messages


def test_starts_by_direction_and_an_address_before_the_code_through_every_output(tmp_path: Path) -> None:
    """`start: {request: "#", response: "$"}` and `address: unit` (Lynxmotion LSS's `#5QD` / `*5QD1800`): every output
    takes both (the C compiles; tests/test_c_text.py and tests/test_wireshark_text.py hold the C and the dissector to
    Python); the reference shows both starts; the start says the direction; every message carries the address first, its
    digits before the talker and code; random messages round trip, among each other in a stream of both directions; the
    simulator answers with the request's address."""
    case = copy.deepcopy(TEXT_CASE)
    case["framing"]["start"] = {"request": "#", "response": "$"}
    case["framing"]["address"] = "unit"
    case["fields"]["unit"] = {"type": "integer", "range": [0, 254]}
    files = python_and_markdown(case, {})
    text_c_compiles({p: t for p, t in files.items() if p.startswith("matrix_text/matrix_text")}, tmp_path)
    source = files["matrix_text/matrix_text.c"]
    assert "#define MATRIX_TEXT__RESPONSE_START 0x24u" in source and "the address: the digits right" in source
    assert "| start | `#` or `$` | starts a request or a response |" in files["docs/matrix_text.md"]
    modules = {p.split("/", 1)[1]: t for p, t in files.items() if p.startswith("matrix_text/")}
    with imported("matrix_text", modules, "the language matrix") as package:
        asked = package.DialRequest(unit=12, talker="A", level=7, note="hi")
        frame = package.encode(asked)
        assert frame.startswith(b"#12ADL;7;hi!") and package.decode(frame) == asked  # no direction needed
        device = importlib.import_module("matrix_text.simulator").SIMULATOR()
        [(_, answer)] = device.feed(frame)
        assert answer.startswith(b"$12ADL;7;") and package.decode(answer).unit == 12, answer
        frames, messages = b"", []
        for cls in package.MESSAGE_TYPES:
            more, decoded = random_frames(package, cls, 10)
            frames, messages = frames + more, messages + decoded
        parser = package.StreamParser()
        assert [m for byte in frames for m in parser.feed(bytes([byte]))] == messages
    refused = copy.deepcopy(case)
    refused["framing"]["address"] = "side"
    with pytest.raises(SpecErrors, match=r"framing\.address: the address 'side' is an integer field"):
        resolve(load_text(yaml.safe_dump(refused, sort_keys=False), "matrix_text.yaml"))
    refused = copy.deepcopy(case)
    refused["fields"]["unit"]["base"] = 16  # hex digits could not be told from a code's letters
    with pytest.raises(SpecErrors, match=r"framing\.address: the address 'unit' is read as the decimal digits"):
        resolve(load_text(yaml.safe_dump(refused, sort_keys=False), "matrix_text.yaml"))


def test_labels_glued_to_their_values_through_every_output(tmp_path: Path) -> None:
    """`text: {named: ""}` (G-code's `G1 X10.5 Y-3`) and with `separator: ""` too (Lynxmotion LSS's `D1800T1500`, the
    first value labelled with the code): the C and the dissector read them (tests/test_c_text.py and
    tests/test_wireshark_text.py hold them to Python); the reference says how they are
    written; random messages round trip and stream; what a frame could not tell apart is refused."""
    case = copy.deepcopy(TEXT_CASE)
    case["commands"] |= {key: copy.deepcopy(LABELLED_COMMANDS[key]) for key in ("move", "words")}
    files = python_and_markdown(case, {})
    text_c_compiles({p: t for p, t in files.items() if p.startswith("matrix_text/matrix_text")}, tmp_path)
    assert "written as its label glued to its value" in files["docs/matrix_text.md"]
    modules = {p.split("/", 1)[1]: t for p, t in files.items() if p.startswith("matrix_text/")}
    with imported("matrix_text", modules, "the language matrix") as package:
        move = package.MoveResponse(talker="A", at=-15, time=1500)
        assert package.encode(move).startswith(b"#AMV-15T1500!") and package.decode(package.encode(move)) == move
        words = package.WordsResponse(talker="A", x=10.5, y=-3)
        assert package.encode(words).startswith(b"#AGW;X10.5;Y-3!")
        reordered = package.FRAMING.frame("AGW;Y-3;X10.5", "response")
        assert package.decode(reordered) == package.decode(package.encode(words))  # in any order
        streams_back(package, (package.MoveResponse, package.WordsResponse, package.AnswerResponse), "response")
    for command, field, change, expected in (
        ("move", "time", {"label": "SDX"}, "label 'SD' begins another label"),
        ("move", "time", {"type": "text"}, "without a separator, a value glued between labels is a decimal number"),
        ("move", "time", {"base": 16}, "without a separator, a value glued between labels is a decimal number"),
        ("words", "y", {"label": "X1"}, "label 'X' begins another label"),
    ):
        broken = copy.deepcopy(case)
        broken["commands"][command]["response"]["fields"][field].update(change)
        with pytest.raises(SpecErrors, match=expected):
            resolve(load_text(yaml.safe_dump(broken, sort_keys=False), "matrix_text.yaml"))
    broken = copy.deepcopy(case)
    broken["commands"]["words"]["response"]["text"]["start"] = "<"
    with pytest.raises(SpecErrors, match="need a message found by its code"):
        resolve(load_text(yaml.safe_dump(broken, sort_keys=False), "matrix_text.yaml"))


def test_a_text_to_the_end_of_the_line_through_every_output(tmp_path: Path) -> None:
    """A `text` field's `size: rest` (Marlin's `Error:checksum mismatch, Last Line: 122`): the rest of the line,
    separators included, in a plain message and in one found by its code: every output takes it (the C compiles;
    tests/test_c_text.py and tests/test_wireshark_text.py hold the C and the dissector to Python); the reference says
    so; round trips, with separators and the layout's own characters in the text; misplaced, refused."""
    case = copy.deepcopy(TEXT_CASE)
    case["commands"]["note"] = {
        "code": "NT",
        "response": {"unsolicited": True, "fields": {"n": "integer", "msg": {"type": "text", "size": "rest"}}},
    }
    case["commands"]["error"] = {
        "code": "ER",
        "response": {
            "unsolicited": True,
            "text": {"after_code": "="},
            "fields": {"msg": {"type": "text", "size": "rest"}},
        },
    }
    files = python_and_markdown(case, {})
    text_c_compiles({p: t for p, t in files.items() if p.startswith("matrix_text/matrix_text")}, tmp_path)
    assert "text (the rest of the line, separators included)" in files["docs/matrix_text.md"]
    modules = {p.split("/", 1)[1]: t for p, t in files.items() if p.startswith("matrix_text/")}
    with imported("matrix_text", modules, "the language matrix") as package:
        note = package.NoteResponse(talker="A", n=3, msg="a;b = c;")
        assert package.encode(note).startswith(b"#ANT;3;a;b = c;!") and package.decode(package.encode(note)) == note
        error = package.ErrorResponse(talker="A", msg="bad=1; x")
        assert package.encode(error).startswith(b"#AER=bad=1; x!") and package.decode(package.encode(error)) == error
        with pytest.raises(EncodeError, match="holds '!'"):
            package.encode(package.NoteResponse(talker="A", msg="a!b"))  # the checksum's marker: still the framing's
        streams_back(package, (package.NoteResponse, package.ErrorResponse, package.AnswerResponse), "response")
    broken = copy.deepcopy(case)
    broken["commands"]["note"]["response"]["fields"] = {"msg": {"type": "text", "size": "rest"}, "n": "integer"}
    with pytest.raises(SpecErrors, match=r"msg\.size: the rest of the line \(`size: rest`\) is the last field"):
        resolve(load_text(yaml.safe_dump(broken, sort_keys=False), "matrix_text.yaml"))
    broken["commands"]["note"]["response"]["fields"] = {"msg": {"type": "text", "size": 4}}
    with pytest.raises(SpecErrors, match="a text field's size is `rest`"):
        resolve(load_text(yaml.safe_dump(broken, sort_keys=False), "matrix_text.yaml"))
