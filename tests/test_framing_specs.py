"""The framing keys end to end: small specs with header-less, trailer and alternative-layout frames are generated,
imported and run (the shipped Modbus RTU and VESC specs are issue 12's; these pin the language they need)."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path
from types import ModuleType

import pytest
from serialspec.backends.python import files
from serialspec.lang import SpecErrors, load_protocol

MODBUS_LIKE = """
protocol: {name}
title: Modbus-like
byte_order: big
serial: {{baudrate: 19200, parity: even}}
framing:
  gap: 3.5
  elements:
    address: {{role: address, type: u8, range: [1, 247], broadcast: 0}}
    function: {{role: command, type: u8}}
    data: {{role: content}}
    crc:
      role: checksum
      type: u16
      algorithm: crc
      crc: {{name: CRC-16/MODBUS, width: 16, poly: 0x8005, init: 0xFFFF, refin: true, refout: true, xorout: 0,
             check: 0x4B37}}
      covers: [address, data]
commands:
  read_holding_registers:
    code: 3
    request:
      fields:
        start: u16
        quantity: {{type: u16, range: [1, 125]}}
    response:
      fields:
        byte_count: u8
        values: {{type: bytes, size: byte_count}}
  write_register:
    code: 6
    request:
      fields: {{register: u16, value: u16}}
    response:
      fields: {{register: u16, value: u16}}
"""

VESC_LIKE = """
protocol: {name}
title: VESC-like
byte_order: big
serial: {{baudrate: 115200}}
framing:
  layouts:
    short:
      elements:
        start: {{role: header, value: "02"}}
        length: {{role: length, type: u8, counts: [command, payload]}}
        command: &command {{role: command, type: u8}}
        payload: &payload {{role: content}}
        crc: &crc
          role: checksum
          type: u16
          endian: big
          algorithm: crc
          crc: {{name: CRC-16/XMODEM, width: 16, poly: 0x1021, init: 0, refin: false, refout: false, xorout: 0,
                 check: 0x31C3}}
          covers: [command, payload]
        end: &end {{role: trailer, value: "03"}}
    long:
      elements:
        start: {{role: header, value: "03"}}
        length: {{role: length, type: u16, endian: big, counts: [command, payload]}}
        command: *command
        payload: *payload
        crc: *crc
        end: *end
commands:
  alive:
    code: 30
    request: {{fields: {{}}}}
  print:
    code: 21
    response:
      fields: {{text: {{type: bytes, size: rest}}}}
"""


def generate(tmp_path: Path, text: str, name: str) -> ModuleType:
    spec = tmp_path / f"{name}.yaml"
    spec.write_text(text.format(name=name), encoding="utf-8")
    protocol = load_protocol(str(spec))
    for path, body in files(protocol).items():
        target = tmp_path / "out" / path
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(body, encoding="utf-8")
    for module in [m for m in sys.modules if m == name or m.startswith(f"{name}.")]:
        del sys.modules[module]  # another test's package of the same name, imported before in this process
    sys.path.insert(0, str(tmp_path / "out"))
    try:
        return importlib.import_module(name)
    finally:
        sys.path.remove(str(tmp_path / "out"))


def test_header_less_frames_sized_by_their_command(tmp_path: Path) -> None:
    m = generate(tmp_path, MODBUS_LIKE, "modbus_like")
    request = m.ReadHoldingRegistersRequest(address=1, start=0, quantity=10)
    frame = m.encode(request)
    assert frame == bytes.fromhex("01 03 00 00 00 0A C5 CD")  # the Modbus specification's example
    assert m.decode(frame, "request") == request
    reply = m.ReadHoldingRegistersResponse(address=1, values=bytes(range(20)))
    reply_frame = m.encode(reply)
    assert reply_frame[2] == 20  # the byte count, derived
    parser = m.StreamParser("response")
    found = []
    stream = (
        b"\x00\xff" + reply_frame + m.encode(m.WriteRegisterResponse(address=17, register=5, value=3)) + reply_frame
    )
    for byte in stream:  # byte by byte, back to back, no silence between frames
        found += parser.feed(bytes([byte]))
    assert [type(x).__name__ for x in found] == [
        "ReadHoldingRegistersResponse",
        "WriteRegisterResponse",
        "ReadHoldingRegistersResponse",
    ]
    # no header tells the direction: a frame only one direction decodes needs none (a read reply cannot have 00 00
    # 00 0A after its byte count 0)
    assert m.decode(frame, None) == request


def test_alternative_layouts_with_a_trailer(tmp_path: Path) -> None:
    m = generate(tmp_path, VESC_LIKE, "vesc_like")
    short = m.encode(m.AliveRequest())
    assert short[:3] == bytes([0x02, 0x01, 30]) and short[-1] == 0x03
    long = m.encode(m.PrintResponse(text=b"x" * 300))
    assert long[:3] == bytes([0x03, 0x01, 0x2D]) and long[-1] == 0x03  # 301 bytes counted, big-endian
    assert m.decode(long, "response") == m.PrintResponse(text=b"x" * 300)
    assert m.decode(short, "request") == m.AliveRequest()
    parser = m.StreamParser("response")
    assert parser.feed(b"\x03\x03" + long[:100]) == []
    assert parser.feed(long[100:]) == [m.PrintResponse(text=b"x" * 300)]


def test_framing_mistakes_are_named(tmp_path: Path) -> None:
    spec = tmp_path / "bad.yaml"
    spec.write_text(
        MODBUS_LIKE.format(name="bad")
        .replace("covers: [address, data]", "covers: [address, nothing]")
        .replace("function: {role: command, type: u8}", "function: {role: command, type: u8, counts: [a, b]}"),
        encoding="utf-8",
    )
    with pytest.raises(SpecErrors) as failure:
        load_protocol(str(spec))
    text = str(failure.value)
    assert "unknown frame element 'nothing'" in text
    assert "`counts` belongs to a length element" in text
    spec.write_text(MODBUS_LIKE.format(name="bad").replace("start: u16", "address: u16"), encoding="utf-8")
    with pytest.raises(SpecErrors, match="'address' is already a frame element of every request"):
        load_protocol(str(spec))


def test_a_checksum_inside_the_transparency_span_counted_by_a_length(tmp_path: Path) -> None:
    """A length over the stuffed span counts its plain bytes, the checksum's with them (refused before the transform
    registry): encode, decode and the stream parser agree, whatever the checksum's value stuffs to."""
    m = generate(
        tmp_path,
        """\
protocol: {name}
title: SLIP-like
description: Escaped frames.
serial: {{baudrate: 9600}}
byte_order: little
framing:
  elements:
    header: {{role: header, value: C0}}
    length: {{role: length, type: u8, counts: [code, checksum]}}
    code: {{role: command, type: u8}}
    content: {{role: content}}
    checksum: {{role: checksum, type: u8, algorithm: sum, covers: [code, content]}}
  transparency: {{span: [code, checksum], replace: {{C0: DB DC, DB: DB DD}}}}
commands:
  probe: {{code: 1, request: {{fields: {{v: u8}}}}}}
""",
        "slip_like",
    )
    frames = [m.encode(m.ProbeRequest(v=v)) for v in range(256)]
    assert m.encode(m.ProbeRequest(v=0xBF)) == bytes.fromhex("C0 03 01 BF DB DC")  # 01 + BF = C0, stuffed
    for v, frame in enumerate(frames):
        assert frame[1] == 3  # the plain bytes
        assert m.decode(frame, "request") == m.ProbeRequest(v=v)
    parser = m.StreamParser("request")
    found = [message for byte in b"".join(frames) for message in parser.feed(bytes([byte]))]
    assert found == [m.ProbeRequest(v=v) for v in range(256)]
