"""`algorithm: xor` in every output, as a user meets it: `serialspec generate` then `check` on a spec of the classic
shape (straight-line codec, construct frame struct) and one of the general shape (u16 length, 16-bit XOR of words),
the package, its structs, its stream parser and its docs. It crashed `generate` in the markdown docs and the
classic codec, and the classic construct struct summed the bytes instead (issue 20)."""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest
from serialspec.runtime.errors import ChecksumError

CLASSIC = """
protocol: xor_classic
title: XOR lamp (classic frame)
byte_order: little
serial: {baudrate: 9600}
framing:
  elements:
    header: {role: header, value: {request: "AA", response: "BB"}}
    command: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: xor, covers: [header, content]}
commands:
  ping:
    code: 1
    request: {fields: {lamp_id: u8}}
    response: {fields: {lamp_id: u8, level: u16}}
examples:
  ping_request:
    source: made up (AA ^ 01 ^ 01 ^ 01 = AB; the sum would be AD)
    direction: request
    printed: "aa 01 01 01 ab"
    command: ping
    fields: {lamp_id: 1}
"""

GENERAL = """
protocol: xor_words
title: XOR of 16-bit words (u16 length)
byte_order: little
serial: {baudrate: 9600}
framing:
  elements:
    sync: {role: header, value: "B5 62"}
    command: {role: command, type: u8}
    length: {role: length, type: u16}
    content: {role: content}
    check: {role: checksum, type: u16, algorithm: xor, covers: [command, content]}
commands:
  ping:
    code: 1
    request: {fields: {lamp_id: u8}}
    response: {fields: {lamp_id: u8, level: u16}}
examples:
  ping_request:
    source: made up (little-endian words, as the checksum is, 0x0101 ^ 0x0100 = 0x0001, sent 01 00)
    direction: request
    printed: "b5 62 01 01 00 01 01 00"
    command: ping
    fields: {lamp_id: 1}
"""


def serialspec(*arguments: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "serialspec", *arguments], cwd=cwd, capture_output=True, text=True, check=False
    )


def generated(tmp_path: Path, name: str, text: str) -> tuple[ModuleType, ModuleType, str]:
    spec = tmp_path / f"{name}.yaml"
    spec.write_text(text, encoding="utf-8")
    made = serialspec("generate", str(spec), "--out", "out", cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    checked = serialspec("check", str(spec), "--out", "out", cwd=tmp_path)
    assert checked.returncode == 0, checked.stdout + checked.stderr
    sys.path.insert(0, str(tmp_path / "out"))
    try:
        package = importlib.import_module(name)
        structs = importlib.import_module(f"{name}.structs")
    finally:
        sys.path.remove(str(tmp_path / "out"))
    return package, structs, (tmp_path / "out" / "docs" / f"{name}.md").read_text(encoding="utf-8")


@pytest.mark.parametrize(("name", "text", "frame"), [("xor_classic", CLASSIC, "aa 01 01 01 ab")])
def test_xor_in_a_classic_frame(tmp_path: Path, name: str, text: str, frame: str) -> None:
    package, structs, docs = generated(tmp_path, name, text)
    data = bytes.fromhex(frame)
    message = package.decode(data, "request")
    assert message.lamp_id == 1 and package.encode(message) == data
    with pytest.raises(ChecksumError):
        package.decode(data[:-1] + b"\xad", "request")  # the sum of the bytes: not this frame's checksum
    reply = package.PingResponse(lamp_id=7, level=0x1234)
    wire = package.encode(reply)
    covered = wire[:-1]
    expected = 0
    for byte in covered:
        expected ^= byte
    assert wire[-1] == expected
    parser = package.StreamParser("response")
    assert parser.feed(b"\x00" + wire[:3]) == [] and parser.feed(wire[3:] + wire) == [reply, reply]
    parsed = structs.REQUEST_FRAME.parse(data)  # construct checks the checksum while it parses
    assert parsed.checksum == 0xAB and structs.REQUEST_FRAME.build(parsed) == data
    assert "XOR of the covered bytes" in docs and "→" not in docs.split("Worked example:")[1].split("\n")[0]
    assert "0xAA ^ 0x01 ^ 0x01 ^ 0x01 = 0xAB" in docs


def test_xor_of_words_in_a_general_frame(tmp_path: Path) -> None:
    package, structs, docs = generated(tmp_path, "xor_words", GENERAL)
    data = bytes.fromhex("b5 62 01 01 00 01 01 00")
    message = package.decode(data, "request")
    assert message.lamp_id == 1 and package.encode(message) == data
    with pytest.raises(ChecksumError):  # the words read big-endian (what it did before its byte order counted)
        package.decode(data[:-2] + b"\x00\x01", "request")
    reply = package.PingResponse(lamp_id=7, level=0x1234)
    wire = package.encode(reply)
    parser = package.StreamParser("response")
    assert parser.feed(wire[:5]) == [] and parser.feed(wire[5:]) == [reply]
    assert structs.REQUEST_FRAME.parse(data).content == b"\x01"
    assert "XOR of the covered bytes taken as little-endian 16-bit words" in docs
    assert "0x0101 ^ 0x0100 = 0x0001" in docs
