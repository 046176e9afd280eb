"""Blue Robotics Ping protocol (tests/specs/ping1d.yaml), written from the user docs alone and checked against
bluerobotics-ping (brping, Blue Robotics' own Python library): our codec reads the frames its PingMessage packs and
packs them byte for byte; its Ping1D drives `serialspec sim` on a real pseudo-terminal, where initialize() asks for
the protocol version with general_request, a request naming the message it wants (`answered_by: {command_in:
requested_id}`); our client asks the sim the same way.

brping 0.2.5 merges the message tables of all its devices into one, so the Ping1D ids an S500 also uses (1002, 1200,
1203, 1204, 1206, 1207, 1211, 1213) pack and parse as the S500's messages there: the peer checks leave those out."""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from conftest import generate_and_import
from serialspec.runtime.errors import RangeError
from sim_process import serve

brping = pytest.importorskip("brping")
from brping import definitions, pingmessage  # noqa: E402

SPEC = Path(__file__).parent / "specs" / "ping1d.yaml"


@pytest.fixture(scope="module")
def ping(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("ping1d"), "ping1d")


def packed(message_id: int, **payload: Any) -> bytes:
    """The frame brping's PingMessage packs (from a host: device ids 0)."""
    message = pingmessage.PingMessage(message_id)
    for name, value in payload.items():
        setattr(message, name, value)
    message.src_device_id = message.dst_device_id = 0
    return bytes(message.pack_msg_data())


def asked(message_id: int) -> bytes:
    """The frame of Ping1D.legacyRequest: the message id with an empty payload."""
    message = pingmessage.PingMessage()
    message.request_id = message_id
    message.src_device_id = message.dst_device_id = 0
    return bytes(message.pack_msg_data())


def test_frames_match_brping(ping: ModuleType) -> None:
    host = {"src_device_id": 0, "dst_device_id": 0}
    profile = {
        "distance": 1234,
        "confidence": 87,
        "transmit_duration": 50,
        "ping_number": 9,
        "scan_start": 100,
        "scan_length": 5000,
        "gain_setting": 3,
    }
    cases = [
        (
            packed(definitions.COMMON_GENERAL_REQUEST, requested_id=5),
            ping.GeneralRequestRequest(requested_id=5, **host),
        ),
        (asked(definitions.PING1D_GENERAL_INFO), ping.GeneralInfoRequest(**host)),
        (packed(definitions.PING1D_SET_MODE_AUTO, mode_auto=1), ping.SetModeAutoRequest(mode_auto=1, **host)),
        (packed(definitions.COMMON_ACK, acked_id=1003), ping.AckResponse(acked_id=1003, **host)),
        (
            packed(definitions.COMMON_PROTOCOL_VERSION, version_major=1, version_minor=2, version_patch=3, reserved=0),
            ping.ProtocolVersionResponse(version_major=1, version_minor=2, version_patch=3, reserved=0, **host),
        ),
        (packed(definitions.PING1D_VOLTAGE_5, voltage_5=5012), ping.Voltage5Response(voltage_5=5012, **host)),
        (
            packed(
                definitions.PING1D_PROFILE, **profile, profile_data_length=3, profile_data=bytearray(b"\x01\x80\xff")
            ),
            ping.ProfileResponse(**profile, profile_data=b"\x01\x80\xff", **host),
        ),
    ]
    for golden, message in cases:
        direction = ping.Direction.REQUEST if type(message).__name__.endswith("Request") else ping.Direction.RESPONSE
        assert ping.decode(golden, direction) == message, golden.hex(" ")
        assert ping.encode(message) == golden, type(message).__name__
        parser = pingmessage.PingParser()
        states = [parser.parse_byte(byte) for byte in ping.encode(message)]
        assert states[-1] == pingmessage.PingParser.NEW_MESSAGE and bytes(parser.rx_msg.msg_data) == golden
    # a NACK (brping cannot pack one: its constructor takes len() of the message text before it is set)
    nack = pingmessage.PingMessage(
        msg_data=bytearray(ping.encode(ping.NackResponse(nacked_id=1003, nack_message="bad", **host)))
    )
    assert (nack.message_id, nack.nacked_id, bytes(nack.nack_message)) == (2, 1003, b"bad")


def test_brping_drives_the_sim() -> None:
    with serve(str(SPEC)) as path:
        device = brping.Ping1D()
        device.connect_serial(path, 115200)  # it sends a break and "U" (auto-baud) first: garbage to the sim
        try:
            assert device.initialize()  # general_request for the protocol version, then general_info
            assert device.get_device_id() == {"device_id": 1}
            assert device.get_voltage_5() == {"voltage_5": 5000}
            assert device.get_mode_auto() == {"mode_auto": 1}
            assert device.set_mode_auto(0)  # checked by reading it back
            assert device.get_mode_auto() == {"mode_auto": 0}
            profile = device.get_profile()
            assert profile is not None and profile["distance"] == 1234 and profile["scan_length"] == 5000
        finally:
            device.iodev.close()


def test_our_client_asks_for_a_message_by_its_id(ping: ModuleType) -> None:
    client_module = importlib.import_module("ping1d.client")
    with serve(str(SPEC)) as path, client_module.Ping1dClient(path, timeout=1) as sonar:
        version = sonar.general_request(0, 0, requested_id=5)
        assert version == ping.ProtocolVersionResponse(
            0, 0, version_major=1, version_minor=0, version_patch=0, reserved=0
        )
        assert sonar.general_request(0, 0, requested_id=1205) == ping.ModeAutoResponse(0, 0, mode_auto=1)
        with pytest.raises(RangeError, match="requested_id = 4 is the code of no command with a reply"):
            sonar.general_request(0, 0, requested_id=4)  # refused before a byte is written
        assert sonar.set_mode_auto(0, 0, mode_auto=0) is True
        assert sonar.mode_auto(0, 0) == 0
