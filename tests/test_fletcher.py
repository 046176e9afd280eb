"""`algorithm: fletcher` (checksums/fletcher.py) on real u-blox UBX frames, and Fletcher-16 modulo 255 on the
published values; test_matrix.py runs both options through every output."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import pytest
from serialspec.checksums.fletcher import fletcher_function
from serialspec.cli import main as serialspec_main
from serialspec.lang import SpecErrors, load_protocol
from serialspec.runtime.errors import ChecksumError

UBX = """
protocol: ubx_min
title: u-blox UBX, a few messages
byte_order: little
serial: {{baudrate: 9600}}
framing:
  elements:
    sync: {{role: header, value: "B5 62"}}
    message: {{role: command, type: u16, endian: big, description: class and id}}
    length: {{role: length, type: u16}}
    payload: {{role: content}}
    ck: {{role: checksum, type: {type}, algorithm: fletcher, covers: [message, payload]}}
commands:
  mon_ver:
    code: 0x0A04
    request: {{fields: {{}}}}
    response: {{fields: {{versions: {{type: bytes, size: rest}}}}}}
  ack:
    code: 0x0501
    response: {{fields: {{cls_id: {{type: u8}}, msg_id: {{type: u8}}}}}}
"""

MON_VER_POLL = bytes.fromhex("B5 62 0A 04 00 00 0E 34")  # UBX-MON-VER poll, as u-blox documents it
ACK_CFG_MSG = bytes.fromhex("B5 62 05 01 02 00 06 01 0F 38")  # UBX-ACK-ACK of a UBX-CFG-MSG


def test_the_runtime_function() -> None:
    ubx = fletcher_function(256)
    assert ubx(bytes.fromhex("0A 04 00 00")) == 0x340E
    assert ubx(bytes.fromhex("05 01 02 00 06 01")) == 0x380F
    assert ubx(b"\xff" * 1000) == ((sum(range(1, 1001)) * 0xFF) % 256) << 8 | (1000 * 0xFF) % 256
    rfc1146 = fletcher_function(255)  # Fletcher-16's published values (the sums' pair as CK_B << 8 | CK_A)
    assert [rfc1146(s) for s in (b"abcde", b"abcdef", b"abcdefgh")] == [0xC8F0, 0x2057, 0x0627]


def test_real_ubx_frames(tmp_path: Path) -> None:
    spec = tmp_path / "ubx_min.yaml"
    spec.write_text(UBX.format(type="u16"), encoding="utf-8")
    assert serialspec_main(["generate", str(spec), "--out", str(tmp_path / "out")]) == 0
    sys.path.insert(0, str(tmp_path / "out"))
    try:
        ubx = importlib.import_module("ubx_min")
        structs = importlib.import_module("ubx_min.structs")
    finally:
        sys.path.remove(str(tmp_path / "out"))
    assert ubx.encode(ubx.MonVerRequest()) == MON_VER_POLL
    assert ubx.decode(MON_VER_POLL, "request") == ubx.MonVerRequest()
    ack = ubx.decode(ACK_CFG_MSG, "response")
    assert (ack.cls_id, ack.msg_id) == (0x06, 0x01) and ubx.encode(ack) == ACK_CFG_MSG
    with pytest.raises(ChecksumError, match="bad ck: the frame has 0x340f, its bytes give 0x340e"):
        ubx.decode(MON_VER_POLL[:-2] + b"\x0f\x34", "request")
    parser = ubx.StreamParser("response")
    assert parser.feed(b"\x00\xb5" + ACK_CFG_MSG[:5]) == [] and parser.feed(ACK_CFG_MSG[5:] + ACK_CFG_MSG) == [ack, ack]
    assert structs.REQUEST_FRAME.parse(MON_VER_POLL).content == b""
    docs = (tmp_path / "out" / "docs" / "ubx_min.md").read_text(encoding="utf-8")
    assert "Fletcher checksum modulo 256" in docs


def test_a_fletcher_checksum_is_two_bytes(tmp_path: Path) -> None:
    spec = tmp_path / "ubx_min.yaml"
    spec.write_text(UBX.format(type="u8"), encoding="utf-8")
    with pytest.raises(SpecErrors) as raised:
        load_protocol(str(spec))
    (line,) = str(raised.value).splitlines()
    assert line.endswith(
        "ubx_min.yaml:12:32: framing.elements.ck.type: a Fletcher checksum is two bytes (CK_A, CK_B): u16, not u8"
    )
