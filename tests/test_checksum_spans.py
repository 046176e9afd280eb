"""Checksums inside the span they cover, and a checksum computed from another (HerkuleX: checksum1 is the XOR of
every byte but the two checksums, & 0xFE; checksum2 is ~checksum1 & 0xFE), with the frames of its manual."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from serialspec.cli import main
from serialspec.lang import SpecErrors, load_protocol

SPEC = """\
protocol: herkulex_like
title: Both checksums in the header
byte_order: little
serial:
  baudrate: 115200
framing:
  elements:
    header: {role: header, value: "FF FF"}
    size: {role: length, type: u8, counts: [pid, data], adds: 3}
    pid: {role: address, type: u8}
    cmd: {role: command, type: u8}
    checksum1: {role: checksum, type: u8, algorithm: xor, mask: 0xFE, covers: [size, data]}
    checksum2: {role: checksum, type: u8, algorithm: xor, invert: true, mask: 0xFE, covers: [checksum1, checksum1]}
    data: {role: content}
commands:
  ram_write:
    code: 3
    request:
      fields: {address: u8, length: u8, value: u8}
"""

LED = "ff ff 0a fd 03 c0 3e 35 01 01"  # RAM_WRITE of LED control (address 0x35) = 1 to id 0xFD, from the manual


@pytest.fixture
def spec(tmp_path: Path) -> str:
    path = tmp_path / "herkulex_like.yaml"
    path.write_text(SPEC, encoding="utf-8")
    return str(path)


def test_the_manuals_frame_decodes_and_encodes_byte_for_byte(spec: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["decode", spec, LED, "--json"]) == 0
    decoded = json.loads(capsys.readouterr().out)
    assert decoded["fields"] == {"pid": 0xFD, "address": 0x35, "length": 1, "value": 1}
    assert main(["encode", spec, "--json", json.dumps({"command": "ram_write", "fields": decoded["fields"]})]) == 0
    assert capsys.readouterr().out.strip() == LED


@pytest.mark.parametrize(
    ("frame", "reason"),
    [
        ("ff ff 0a fd 03 c1 3e 35 01 01", "bad checksum1: the frame has 0xc1, its bytes give 0xc0"),
        ("ff ff 0a fd 03 c0 3f 35 01 01", "bad checksum2: the frame has 0x3f, its bytes give 0x3e"),
        ("ff ff 0a fd 03 c0 3e 35 01 03", "bad checksum1: the frame has 0xc0, its bytes give 0xc2"),
    ],
)
def test_a_wrong_byte_is_refused_by_the_checksum_that_covers_it(
    spec: str, capsys: pytest.CaptureFixture[str], frame: str, reason: str
) -> None:
    assert main(["decode", spec, frame]) == 1
    assert capsys.readouterr().err.strip() == f"serialspec decode: {frame}: {reason}"


@pytest.mark.parametrize(
    ("covers", "message"),
    [
        ("[checksum1, data]", "a checksum cannot begin or end the span it covers"),
        ("[checksum2, checksum2]", "a checksum covering checksum2 must come after it in the frame"),
    ],
)
def test_spans_a_checksum_cannot_have(tmp_path: Path, covers: str, message: str) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(SPEC.replace("covers: [size, data]", f"covers: {covers}"), encoding="utf-8")
    with pytest.raises(SpecErrors) as raised:
        load_protocol(str(path))
    assert str(raised.value).endswith(f"framing.elements.checksum1.covers: {message}")
