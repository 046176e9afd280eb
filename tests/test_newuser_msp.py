"""MultiWii Serial Protocol v1 (tests/specs/msp.yaml), written from the user docs alone and checked against yamspy
(Betaflight's and iNAV's Python MSP client): our codec reads the requests its send_RAW_msg builds and re-encodes
them byte for byte, and yamspy connects to `serialspec sim` on a real pseudo-terminal (its API_VERSION and
FC_VARIANT handshake) and reads the attitude and altitude it answers. MSP v2 ($X<, u16 command, u16 size, CRC-8
DVB-S2) beside v1 is the strict xfail below."""

from __future__ import annotations

import struct
from pathlib import Path
from types import ModuleType

import pytest
from conftest import generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from sim_process import serve

yamspy = pytest.importorskip("yamspy")

SPEC = Path(__file__).parent / "specs" / "msp.yaml"


@pytest.fixture(scope="module")
def msp(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("msp"), "msp")


class CapturingPort:
    def __init__(self) -> None:
        self.written = b""

    def write(self, data: bytes) -> int:
        self.written += bytes(data)
        return len(data)


def peer_request(code: int) -> bytes:
    """The frame yamspy's send_RAW_msg writes for a request without data."""
    board = yamspy.MSPy.__new__(yamspy.MSPy)
    from threading import Lock

    board.conn, board.serial_port_write_lock = CapturingPort(), Lock()
    board.send_RAW_msg(code, data=[])
    written: bytes = board.conn.written
    return written


def test_requests_match_yamspy(msp: ModuleType) -> None:
    for name, message in [
        ("MSP_API_VERSION", msp.ApiVersionRequest()),
        ("MSP_FC_VARIANT", msp.FcVariantRequest()),
        ("MSP_ATTITUDE", msp.AttitudeRequest()),
        ("MSP_ALTITUDE", msp.AltitudeRequest()),
    ]:
        golden = peer_request(yamspy.MSPy.MSPCodes[name])
        assert msp.encode(message) == golden, name
        assert msp.decode(golden, msp.Direction.REQUEST) == message


@settings(max_examples=200, deadline=None)
@given(roll=st.integers(-1800, 1800), pitch=st.integers(-900, 900), yaw=st.integers(-180, 360))
def test_attitude_replies_match_the_frame_rules(msp: ModuleType, roll: int, pitch: int, yaw: int) -> None:
    """An attitude reply as Betaflight's msp.c builds it: $M>, size, 108, three i16, the XOR of size..payload."""
    payload = struct.pack("<hhh", roll, pitch, yaw)
    body = bytes([len(payload), 108]) + payload
    checksum = 0
    for byte in body:
        checksum ^= byte
    golden = b"$M>" + body + bytes([checksum])
    message = msp.AttitudeResponse(roll=roll, pitch=pitch, yaw=yaw)
    assert msp.encode(message) == golden
    assert msp.decode(golden, msp.Direction.RESPONSE) == message


def test_yamspy_reads_the_sim(tmp_path: Path) -> None:
    with serve(str(SPEC)) as path:
        with yamspy.MSPy(path, logfilename=str(tmp_path / "MSPy.log"), loglevel="WARNING") as board:
            assert board != 1, "yamspy could not connect"
            assert board.CONFIG["apiVersion"] == "1.44.0"
            assert board.CONFIG["flightControllerIdentifier"] == "BTFL"
            board.fast_read_attitude()
            assert board.SENSOR_DATA["kinematics"] == [1.2, -3.4, 270]
            board.fast_read_altitude()
            assert board.SENSOR_DATA["altitude"] == 12.34


def test_the_generated_client_asks_the_sim(msp: ModuleType) -> None:
    import importlib

    client_module = importlib.import_module("msp.client")
    with serve(str(SPEC)) as path, client_module.MspClient(path) as board:
        assert board.attitude() == msp.AttitudeResponse(roll=12, pitch=-34, yaw=270)
        assert board.fc_variant() == "BTFL"  # a one-field reply is its value
