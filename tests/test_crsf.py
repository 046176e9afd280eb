"""CRSF (Crossfire / ExpressLRS): crsf-parser (PyPI) builds frames we decode to its values and re-encode byte for
byte; it parses what we encode (its full parser knows RC channels, link statistics and battery; for the other types
its header parser and its CRC); `serialspec sim specs/crsf.yaml` streams RC channels and telemetry on its own over a
pty, which the peer's stream parser reads; our client gets device info from the sim.

crsf-parser's RC channel list is in reverse order (it byte-swaps the payload and reads the bits from the top, so its
channels[0] is channel 16); the CRSF documentation's example frame pins which end is channel 1.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import serial
from serialspec_protocols import crsf
from serialspec_protocols.crsf.client import CrsfClient
from sim_process import serve

pytest.importorskip("crsf_parser")
from crsf_parser import CRSFParser, PacketValidationStatus  # noqa: E402
from crsf_parser.frames import crsf_frame, crsf_header  # noqa: E402
from crsf_parser.handling import crsf_build_frame, crsf_frame_crc  # noqa: E402
from crsf_parser.payloads import PacketsTypes  # noqa: E402

FC = 0xC8
CODES = {"gps": 0x02, "attitude": 0x1E, "flight_mode": 0x21, "device_ping": 0x28, "device_info": 0x29}
CHANNELS = (172, 992, 1811, 0, 2047, 1, 1024, 1500, 300, 992, 992, 1234, 172, 1811, 5, 2046)
LINK = {
    "uplink_rssi_ant_1": 45,
    "uplink_rssi_ant_2": 50,
    "uplink_link_quality": 100,
    "uplink_snr": -9,
    "diversity_active_antenna": "ANTENNA_2",
    "rf_mode": "RF_150_FPS",
    "uplink_tx_power": "TX_POWER_100_MW",
    "downlink_rssi": 48,
    "downlink_link_quality": 99,
    "downlink_snr": 8,
}
OURS_LINK = {
    "uplink_rssi_ant1": 45,
    "uplink_rssi_ant2": 50,
    "uplink_link_quality": 100,
    "uplink_snr": -9,
    "active_antenna": 1,
    "rf_mode": 2,
    "uplink_tx_power": crsf.TxPower.MW_100,
    "downlink_rssi": 48,
    "downlink_link_quality": 99,
    "downlink_snr": 8,
}


def test_documented_rc_frame_is_channel_1_first() -> None:
    printed = bytes.fromhex("c8 18 16 e0 03 1f f8 c0 07 3e f0 81 0f 7c e0 03 1f f8 c0 07 3e f0 81 0f 7c ad")
    assert crsf.decode(printed, "response") == crsf.RcChannelsResponse(channels=(992,) * 16)
    ramp = crsf.encode(crsf.RcChannelsRequest(channels=tuple(range(1, 17))))
    assert ramp[3] == 1 and ramp[4] == 2 << 3  # channel 1 in the first byte's low bits, channel 2 after its 11 bits


@pytest.mark.parametrize("direction", ["request", "response"])
def test_peer_rc_channels_decode_and_re_encode(direction: str) -> None:
    frame = bytes(crsf_build_frame(PacketsTypes.RC_CHANNELS_PACKED, {"channels": list(reversed(CHANNELS))}))
    message = crsf.decode(frame, direction)
    assert message.channels == CHANNELS
    assert crsf.encode(message) == frame


def test_peer_battery_and_link_statistics_decode_and_re_encode() -> None:
    battery = {"voltage": 168, "current": 1234, "capacity": 0xABCDEF, "remaining": 80}
    frame = bytes(crsf_build_frame(PacketsTypes.BATTERY_SENSOR, battery))
    message = crsf.decode(frame, "response")
    assert message == crsf.BatteryResponse(**battery)
    assert crsf.encode(message) == frame
    assert message.capacity == 0xABCDEF  # u24
    frame = bytes(crsf_build_frame(PacketsTypes.LINK_STATISTICS, LINK))
    message = crsf.decode(frame, "response")
    assert message == crsf.LinkStatisticsResponse(**OURS_LINK)
    assert crsf.encode(message) == frame


def peer_parses(frame: bytes) -> Any:
    """The peer's full frame parser, after checking the CRC with the peer's own function."""
    assert crsf_frame_crc(frame) == frame[-1]
    return crsf_frame.parse(frame)


def test_peer_parses_our_rc_channels_link_statistics_and_battery() -> None:
    parsed = peer_parses(crsf.encode(crsf.RcChannelsResponse(channels=CHANNELS)))
    assert list(parsed.payload.channels) == list(reversed(CHANNELS))
    parsed = peer_parses(crsf.encode(crsf.LinkStatisticsRequest(**OURS_LINK)))
    assert {k: v if isinstance(v, int) else str(v) for k, v in parsed.payload.items() if k != "_io"} == LINK
    parsed = peer_parses(crsf.encode(crsf.BatteryRequest(voltage=1, current=2, capacity=3, remaining=4)))
    assert (parsed.payload.voltage, parsed.payload.current, parsed.payload.capacity, parsed.payload.remaining) == (
        1,
        2,
        3,
        4,
    )


@pytest.mark.parametrize(
    ("message", "payload"),
    [
        (
            crsf.GpsResponse(
                latitude=473977418,
                longitude=-85455939,
                groundspeed=123,
                heading=27000,
                altitude=1488,
                satellites=12,
            ),
            "1c 40 52 4a fa e8 0b bd 00 7b 69 78 05 d0 0c",
        ),
        (crsf.AttitudeRequest(pitch=-1571, roll=15708, yaw=0), "f9 dd 3d 5c 00 00"),
        (crsf.FlightModeResponse(mode="ANGL*"), "41 4e 47 4c 2a 00"),
        (crsf.DevicePingRequest(destination=crsf.Address.CRSF_RECEIVER, origin=0xEA), "ec ea"),
        (
            crsf.DeviceInfoResponse(
                destination=0xEA,
                origin=0xEC,
                name="ELRS RX",
                serial_number=0x454C5253,
                hardware_id=0,
                firmware_id=0x00030400,
                parameter_count=20,
                parameter_version=0,
            ),
            "ea ec 45 4c 52 53 20 52 58 00 45 4c 52 53 00 00 00 00 00 03 04 00 14 00",
        ),
    ],
    ids=lambda x: type(x).__name__ if not isinstance(x, str) else "",
)
def test_peer_header_and_crc_accept_the_types_it_does_not_parse(message: Any, payload: str) -> None:
    frame = crsf.encode(message)
    header = crsf_header.parse(frame)
    body = bytes.fromhex(payload)
    assert (header.frame_length, header.type) == (len(body) + 2, CODES[message.COMMAND])
    assert frame[3:-1] == body and crsf_frame_crc(frame) == frame[-1]
    if header.type > 0x27:  # the peer reads the extended header's addresses
        assert (header.destination_address, header.origin_address) == (body[0], body[1])
    assert crsf.decode(frame, message.DIRECTION.value) == message


PEER_PARSES = {0x08, 0x14, 0x16}  # the types crsf-parser's stream parser decodes (it raises on GPS and attitude)


def peer_reads(port: serial.Serial, wanted: set[int]) -> dict[int, list[Any]]:
    """Frames read off the port until every wanted type has come: the peer's stream parser decodes the types it
    knows; the others must pass its header parser and its CRC."""
    buffer = bytearray()
    seen: dict[int, list[Any]] = {}
    while not wanted <= seen.keys():
        buffer += port.read(64)
        while len(buffer) >= 2 and len(buffer) >= buffer[1] + 2:
            frame = bytes(buffer[: buffer[1] + 2])
            del buffer[: len(frame)]
            assert frame[0] == FC and crsf_frame_crc(frame) == frame[-1], frame.hex(" ")
            if frame[2] in PEER_PARSES:
                got: list[tuple[Any, PacketValidationStatus]] = []
                CRSFParser(lambda content, status, into=got: into.append((content, status))).parse_stream(
                    bytearray(frame)
                )
                assert [status for _, status in got] == [PacketValidationStatus.VALID], frame.hex(" ")
                seen.setdefault(frame[2], []).append(got[0][0].payload)
            else:
                seen.setdefault(frame[2], []).append(crsf_header.parse(frame))
    return seen


def test_sim_streams_frames_the_peer_parses() -> None:
    with serve("crsf.yaml") as path, serial.Serial(path, 420000, timeout=0.1) as port:
        seen = peer_reads(port, {0x02, 0x08, 0x14, 0x16, 0x1E, 0x21})
    battery = seen[0x08][0]
    assert (battery.voltage, battery.current, battery.capacity, battery.remaining) == (168, 12, 350, 80)
    link = seen[0x14][0]
    assert (link.uplink_rssi_ant_1, link.uplink_link_quality, int(link.uplink_tx_power)) == (45, 100, 3)
    assert len(seen[0x16][0].channels) == 16
    assert len(seen[0x16]) > len(seen[0x08])  # RC channels come 25 times as often as the battery


def test_sim_tap_records_the_reports_the_device_sends_on_its_own(tmp_path: Path) -> None:
    tap = tmp_path / "link.capture"
    with serve("crsf.yaml", options=["--tap", str(tap)]) as path, serial.Serial(path, 420000, timeout=0.1) as port:
        peer_reads(port, {0x08, 0x14, 0x16})
    out = subprocess.run(
        [sys.executable, "-m", "serialspec", "decode", "specs/crsf.yaml", "--file", str(tap), "--json"],
        capture_output=True,
        text=True,
    )
    commands = [json.loads(line)["command"] for line in out.stdout.splitlines()]
    assert out.returncode == 0 and out.stderr == "", out.stderr
    assert {"rc_channels", "link_statistics", "battery"} <= set(commands)


def test_our_client_pings_the_sim_among_its_stream() -> None:
    with serve("crsf.yaml") as path, CrsfClient(path, timeout=2.0) as client:
        info = client.device_ping(crsf.Address.CRSF_RECEIVER, crsf.Address.FLIGHT_CONTROLLER)
        assert (info.name, info.serial_number, info.parameter_count) == ("ELRS RX", 0x454C5253, 20)
        assert (info.destination, info.origin) == (crsf.Address.FLIGHT_CONTROLLER, crsf.Address.CRSF_RECEIVER)
        reports = client.reports(timeout=2.0)
        seen = {type(next(reports)) for _ in range(30)}
        assert {crsf.RcChannelsResponse, crsf.LinkStatisticsResponse} <= seen
        client.rc_channels(CHANNELS)  # sent on its own, nothing answers


def test_bad_crc_is_refused_in_one_line() -> None:
    frame = bytearray(crsf.encode(crsf.RcChannelsResponse(channels=CHANNELS)))
    frame[-1] ^= 1
    with pytest.raises(Exception, match="(?i)checksum|crc") as caught:
        crsf.decode(bytes(frame), "response")
    assert "\n" not in str(caught.value)
