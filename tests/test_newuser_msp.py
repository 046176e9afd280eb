"""MultiWii Serial Protocol v1 (tests/specs/msp.yaml), written from the user docs alone and checked against yamspy
(Betaflight's and iNAV's Python MSP client): our codec reads the requests its send_RAW_msg builds and re-encodes
them byte for byte, and yamspy connects to `serialspec sim` on a real pseudo-terminal (its API_VERSION and
FC_VARIANT handshake) and reads the attitude and altitude it answers. MSP v2 ($X<, u16 command, u16 size, CRC-8
DVB-S2) beside v1 in one spec: two layouts told apart by header, a v2-only code (above 255) sent in v2 as yamspy
sends it."""

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
    log = str(tmp_path / "MSPy.log")
    with serve(str(SPEC)) as path, yamspy.MSPy(path, logfilename=log, loglevel="WARNING") as board:
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


V2_LAYOUTS = """framing:
  layouts:
    v1:
      elements:
        header: {role: header, value: {request: "24 4d 3c", response: "24 4d 3e"}, error_value: "24 4d 21"}
        size: {role: length, type: u8}
        command: {role: command, type: u8}
        content: {role: content}
        checksum: {role: checksum, type: u8, algorithm: xor, covers: [size, content]}
    v2:
      elements:
        header: {role: header, value: {request: "24 58 3c", response: "24 58 3e"}, error_value: "24 58 21"}
        flag: {role: constant, value: "00"}
        command: {role: command, type: u16}
        size: {role: length, type: u16}
        content: {role: content}
        checksum:
          role: checksum
          type: u8
          algorithm: crc
          crc: {name: CRC-8/DVB-S2, width: 8, poly: 0xD5, init: 0, refin: false, refout: false, xorout: 0, check: 0xBC}
          covers: [flag, content]
"""


def spec_with_v2(tmp_path: Path) -> Path:
    """The MSP spec with MSP v2 beside v1: two layouts told apart by their headers, each with its own checksum."""
    text = SPEC.read_text("utf-8")
    start, end = text.index("framing:"), text.index("matching:")
    spec = tmp_path / "msp.yaml"
    spec.write_text(text[:start] + V2_LAYOUTS + text[end:], "utf-8")
    return spec


def test_v1_and_v2_layouts_each_keep_their_checksum(tmp_path: Path) -> None:
    """Found by a new user: each layout's frames were checked with the last layout's algorithm (both elements are
    named `checksum`), so a v1 frame was refused with 'bad checksum: ... give 0xd5'."""
    from serialspec.cli import main as serialspec_main

    spec = spec_with_v2(tmp_path)
    assert serialspec_main(["decode", str(spec), "24 4d 3c 00 01 01"]) == 0  # v1: XOR of size, command
    assert serialspec_main(["decode", str(spec), "24 58 3c 00 01 00 00 00 45"]) == 0  # v2: CRC-8/DVB-S2
    assert serialspec_main(["decode", str(spec), "24 58 3c 00 01 00 00 00 01"]) != 0  # v1's sum is no v2 checksum
    assert (
        serialspec_main(["decode", str(spec), "24 58 21 00 69 00 00 00 5c"]) == 0
    )  # v2's error header (CRC-8/DVB-S2 5c)


def test_the_client_raises_for_the_error_header(msp: ModuleType) -> None:
    """A `$M!` reply to a command the board refuses is a DeviceError naming the command; the stream parser gives
    it as the error reply however the bytes are split."""
    import os
    import threading

    from serialspec.runtime.errors import DeviceError

    refusal = bytes.fromhex("24 4d 21 00 6c 6c")
    parser = msp.StreamParser()
    assert [m for byte in refusal for m in parser.feed(bytes([byte]))] == [msp.RefusedResponse(command=108)]
    assert msp.encode(msp.RefusedResponse(command=108)) == refusal
    controller, device = os.openpty()

    def refuse() -> None:
        asked = b""
        while len(asked) < 6:
            asked += os.read(controller, 64)
        os.write(controller, refusal)

    answering = threading.Thread(target=refuse)
    answering.start()
    try:
        import importlib

        client_module = importlib.import_module("msp.client")
        with (
            client_module.MspClient(os.ttyname(device)) as board,
            pytest.raises(DeviceError, match="^attitude: the device refuses it$"),
        ):
            board.attitude()
    finally:
        answering.join(5)
        os.close(controller)
        os.close(device)


def test_an_unknown_command_gets_the_error_header(msp: ModuleType) -> None:
    import serial

    with serve(str(SPEC)) as path, serial.Serial(path, 115200, timeout=2) as port:
        port.write(peer_request(yamspy.MSPy.MSPCodes["MSP_RC"]))
        assert port.read(6) == b"$M!\x00\x69\x69"


V2_COMMAND = """  inav_analog:
    code: 0x2002
    title: Battery and RSSI (MSPV2_INAV_ANALOG)
    request: {fields: {}}
    response: {fields: {battery_flags: u8, voltage: u16, amperage: u16}}
"""


def test_v2_codes_travel_in_v2_beside_v1(tmp_path: Path) -> None:
    """v1 and v2 in one spec: a code above 255 does not fit v1's u8 command element, so it is sent in v2 (as
    yamspy's send_RAW_msg sends it), a code both hold in v1, the first layout; a frame is read by its header, and
    the stream parser takes both forms back to back."""
    spec = spec_with_v2(tmp_path)
    text = spec.read_text("utf-8")
    text = text.replace("  refused:\n", V2_COMMAND + "  refused:\n").replace("protocol: msp\n", "protocol: msp_mixed\n")
    spec.write_text(text, "utf-8")
    mixed = generate_and_import(spec, tmp_path / "out", "msp_mixed")
    for message, code in [
        (mixed.InavAnalogRequest(), yamspy.MSPy.MSPCodes["MSPV2_INAV_ANALOG"]),
        (mixed.AttitudeRequest(), yamspy.MSPy.MSPCodes["MSP_ATTITUDE"]),
    ]:
        golden = peer_request(code)
        assert mixed.encode(message) == golden
        assert mixed.decode(golden, mixed.Direction.REQUEST) == message
    reply = mixed.InavAnalogResponse(battery_flags=0x41, voltage=1680, amperage=250)
    frame = mixed.encode(reply)
    assert frame[:3] == b"$X>" and frame[4:6] == (0x2002).to_bytes(2, "little")
    attitude = mixed.AttitudeResponse(roll=1, pitch=-2, yaw=3)
    stream = mixed.encode(attitude) + frame + mixed.encode(attitude)
    parser = mixed.StreamParser()
    assert [m for byte in stream for m in parser.feed(bytes([byte]))] == [attitude, reply, attitude]
