"""`seed: per_command` on a checksum (checksums/seed.py): MAVLink v2's CRC_EXTRA, one byte per message id taken in
after the payload, against pymavlink, the reference implementation (frames it packs decode to its values and
re-encode byte for byte; it parses frames we encode)."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from serialspec.cli import main as serialspec_main
from serialspec.lang import SpecErrors, load_protocol
from serialspec.runtime.errors import ChecksumError

mavlink2 = pytest.importorskip("pymavlink.dialects.v20.common")

# MAVLink v2 without signing; the message id (u24) as a u16 command and its zero high byte. Payload fields in wire
# order (MAVLink sorts them by size). CRC-16/MCRF4XX over length .. payload, then the message's CRC_EXTRA.
MAVLINK = """
protocol: mav_min
title: MAVLink v2, HEARTBEAT and ATTITUDE
byte_order: little
serial: {baudrate: 57600}
framing:
  elements:
    stx: {role: header, value: "FD"}
    length: {role: length, type: u8}
    incompat_flags: {role: constant, value: "00"}
    compat_flags: {role: constant, value: "00"}
    seq: {role: address, type: u8}
    sysid: {role: address, type: u8}
    compid: {role: address, type: u8}
    msgid: {role: command, type: u16}
    msgid_high: {role: constant, value: "00"}
    payload: {role: content}
    checksum:
      role: checksum
      type: u16
      algorithm: crc
      crc: {name: CRC-16/MCRF4XX, width: 16, poly: 0x1021, init: 0xFFFF, refin: true, refout: true, xorout: 0,
            check: 0x6F91}
      covers: [length, payload]
      seed: per_command
commands:
  heartbeat:
    code: 0
    checksum_seed: 50
    request:
      fields:
        custom_mode: u32
        type: u8
        autopilot: u8
        base_mode: u8
        system_status: u8
        mavlink_version: u8
  attitude:
    code: 30
    checksum_seed: 39
    request:
      fields:
        time_boot_ms: u32
        roll: f32
        pitch: f32
        yaw: f32
        rollspeed: f32
        pitchspeed: f32
        yawspeed: f32
"""


@pytest.fixture(scope="module")
def mav(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    out = tmp_path_factory.mktemp("mav")
    spec = out / "mav_min.yaml"
    spec.write_text(MAVLINK, encoding="utf-8")
    assert serialspec_main(["generate", str(spec), "--out", str(out / "out")]) == 0
    sys.path.insert(0, str(out / "out"))
    try:
        return importlib.import_module("mav_min")
    finally:
        sys.path.remove(str(out / "out"))


def peer() -> Any:
    link = mavlink2.MAVLink(None, srcSystem=7, srcComponent=1)
    link.seq = 5
    return link


def packed(message: Any) -> bytes:
    return bytes(message.pack(peer()))


HEARTBEAT = mavlink2.MAVLink_heartbeat_message(2, 3, 81, 0x12345, 4, 3)
ATTITUDE = mavlink2.MAVLink_attitude_message(123456, 0.5, -0.25, 1.5, 0.125, -2.0, 3.0)


def test_frames_pymavlink_packs_decode_and_reencode(mav: ModuleType) -> None:
    frame = packed(HEARTBEAT)
    decoded = mav.decode(frame, "request")
    assert (decoded.custom_mode, decoded.type, decoded.autopilot, decoded.base_mode) == (0x12345, 2, 3, 81)
    assert (decoded.system_status, decoded.mavlink_version) == (4, 3)
    assert (decoded.seq, decoded.sysid, decoded.compid) == (5, 7, 1)
    assert mav.encode(decoded) == frame
    frame = packed(ATTITUDE)
    decoded = mav.decode(frame, "request")
    assert decoded.time_boot_ms == 123456 and (decoded.roll, decoded.yawspeed) == (0.5, 3.0)
    assert mav.encode(decoded) == frame
    parser = mav.StreamParser("request")
    both = packed(HEARTBEAT) + packed(ATTITUDE)
    assert [type(m).__name__ for m in parser.feed(b"\x00" + both[:7]) + parser.feed(both[7:])] == [
        "HeartbeatRequest",
        "AttitudeRequest",
    ]


def test_pymavlink_parses_frames_we_encode(mav: ModuleType) -> None:
    receiver = mavlink2.MAVLink(None)
    frame = mav.encode(
        mav.AttitudeRequest(
            time_boot_ms=99, roll=1, pitch=2, yaw=3, rollspeed=4, pitchspeed=5, yawspeed=6, seq=1, sysid=2, compid=3
        )
    )
    (message,) = receiver.parse_buffer(frame)
    assert message.get_type() == "ATTITUDE" and (message.time_boot_ms, message.yawspeed) == (99, 6.0)


def test_the_seed_is_checked(mav: ModuleType) -> None:
    frame = packed(HEARTBEAT)
    unseeded = bytearray(frame)
    from serialspec.checksums.crc import crc_function

    crc = crc_function(16, 0x1021, 0xFFFF, True, True, 0)(frame[1:-2])
    unseeded[-2:] = crc.to_bytes(2, "little")  # the CRC without CRC_EXTRA: every real peer refuses it
    with pytest.raises(ChecksumError):
        mav.decode(bytes(unseeded), "request")


def test_every_command_gives_its_seed(tmp_path: Path) -> None:
    spec = tmp_path / "mav_min.yaml"
    spec.write_text(MAVLINK.replace("    checksum_seed: 39\n", ""), encoding="utf-8")
    with pytest.raises(SpecErrors) as raised:
        load_protocol(str(spec))
    (line,) = str(raised.value).splitlines()
    assert "commands.attitude: `seed: per_command` on checksum: give `checksum_seed`" in line


def test_a_seed_needs_a_seeded_checksum(tmp_path: Path) -> None:
    spec = tmp_path / "mav_min.yaml"
    spec.write_text(MAVLINK.replace("      seed: per_command\n", ""), encoding="utf-8")
    with pytest.raises(SpecErrors) as raised:
        load_protocol(str(spec))
    lines = str(raised.value).splitlines()
    assert [line.split(": ", 1)[1] for line in lines] == [
        "commands.heartbeat.checksum_seed: no checksum of the frame has `seed: per_command`",
        "commands.attitude.checksum_seed: no checksum of the frame has `seed: per_command`",
    ]


def test_the_seed_needs_the_command_in_the_covered_span(tmp_path: Path) -> None:
    spec = tmp_path / "mav_min.yaml"
    spec.write_text(MAVLINK.replace("covers: [length, payload]", "covers: [msgid_high, payload]"), encoding="utf-8")
    with pytest.raises(SpecErrors) as raised:
        load_protocol(str(spec))
    (line,) = str(raised.value).splitlines()
    assert line.endswith("a per-command seed needs the command element inside the covered span")
