"""XBee API mode 2 (tests/specs/xbee_api2.yaml), written from the user docs alone and checked against Digi's
digi-xbee library: the packets it builds and escapes are our golden frames (every escaped byte in the length, the
data and the checksum included) and decode to its values, our encoder writes them byte for byte, the library parses
what we encode, `serialspec sim` answers packets the library builds over a pseudo-terminal, and the generated client
talks to the sim."""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType

import pytest
import serial
from conftest import generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from sim_process import serve

xbee = pytest.importorskip("digi.xbee.packets.common")
from digi.xbee.models.address import XBee16BitAddress, XBee64BitAddress  # noqa: E402
from digi.xbee.models.mode import OperatingMode  # noqa: E402
from digi.xbee.models.status import ATCommandStatus  # noqa: E402
from digi.xbee.packets.base import XBeePacket  # noqa: E402
from digi.xbee.packets.factory import build_frame  # noqa: E402

SPEC = Path(__file__).parent / "specs" / "xbee_api2.yaml"


def parse(frame: bytes) -> object:
    """The library's packet for an escaped frame. Its reader unescapes bytes as they arrive; its build_frame in
    ESCAPED_API_MODE misreads a frame whose length byte is escaped (7E 00 7D 33 ...: "length field 125"), its own
    output too, so frames are unescaped first, as the reader does."""
    return build_frame(XBeePacket.unescape_data(bytearray(frame)), OperatingMode.API_MODE)


@pytest.fixture(scope="module")
def xb(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("xbee_api2"), "xbee_api2")


def x64(value: int) -> XBee64BitAddress:
    return XBee64BitAddress(bytearray(value.to_bytes(8, "big")))


def x16(value: int) -> XBee16BitAddress:
    return XBee16BitAddress(bytearray(value.to_bytes(2, "big")))


def test_the_librarys_packets_decode_and_re_encode(xb: ModuleType) -> None:
    cases = [
        (xbee.ATCommPacket(1, "NI"), xb.AtCommandRequest(frame_id=1, command="NI", parameter=b"")),
        (
            xbee.ATCommPacket(0x7E, "ID", bytearray(b"\x11\x13")),
            xb.AtCommandRequest(frame_id=0x7E, command="ID", parameter=b"\x11\x13"),
        ),
        (
            xbee.TransmitPacket(0x11, x64(0x0013A20040A1B2C3), x16(0xFFFE), 0, 0, bytearray(b"hello\x7e\x7d")),
            xb.TransmitRequestRequest(
                frame_id=0x11,
                destination=0x0013A20040A1B2C3,
                destination_16=0xFFFE,
                broadcast_radius=0,
                options=0,
                rf_data=b"hello\x7e\x7d",
            ),
        ),
        (
            xbee.ATCommResponsePacket(1, "NI", ATCommandStatus.OK, bytearray(b"ROUTER")),
            xb.AtCommandResponseResponse(frame_id=1, command="NI", status=0, data=b"ROUTER"),
        ),
        (
            xbee.TransmitStatusPacket(0x13, x16(0x7D33), 2),
            xb.TransmitStatusResponse(
                frame_id=0x13, destination_16=0x7D33, retry_count=2, delivery_status=0, discovery_status=0
            ),
        ),
        (
            xbee.ReceivePacket(x64(0x0013A2004111117E), x16(0x1234), 1, bytearray(b"\x13\x11")),
            xb.ReceivePacketResponse(source=0x0013A2004111117E, source_16=0x1234, options=1, rf_data=b"\x13\x11"),
        ),
    ]
    for packet, message in cases:
        golden = bytes(packet.output(escaped=True))
        direction = message.DIRECTION
        assert xb.decode(golden, direction) == message, golden.hex(" ")
        assert xb.encode(message) == golden


@settings(max_examples=150, deadline=None)
@given(frame_id=st.integers(0, 255), destination=st.integers(0, 2**64 - 1), rf_data=st.binary(max_size=120))
def test_any_transmit_request_matches_the_library(
    xb: ModuleType, frame_id: int, destination: int, rf_data: bytes
) -> None:
    packet = xbee.TransmitPacket(frame_id, x64(destination), x16(0xFFFE), 0, 0, bytearray(rf_data))
    message = xb.TransmitRequestRequest(
        frame_id=frame_id,
        destination=destination,
        destination_16=0xFFFE,
        broadcast_radius=0,
        options=0,
        rf_data=rf_data,
    )
    ours = xb.encode(message)
    assert ours == bytes(packet.output(escaped=True))
    parsed = parse(ours)  # the library reads what we send
    assert bytes(parsed.rf_data or b"") == rf_data and parsed.frame_id == frame_id  # empty data: None


@settings(max_examples=60, deadline=None)
@given(
    payloads=st.lists(st.binary(max_size=30), min_size=1, max_size=5),
    cuts=st.lists(st.integers(1, 7), max_size=40),
)
def test_the_stream_parser_reads_library_frames_however_split(
    xb: ModuleType, payloads: list[bytes], cuts: list[int]
) -> None:
    source = 0x0013A200407E7D11
    stream = b"".join(
        bytes(xbee.ReceivePacket(x64(source), x16(0x1113), 0, bytearray(p)).output(escaped=True)) for p in payloads
    )
    parser = xb.StreamParser(xb.Direction.RESPONSE)
    got, at = [], 0
    for cut in cuts:
        got += parser.feed(stream[at : at + cut])
        at += cut
    got += parser.feed(stream[at:])
    assert [m.rf_data for m in got] == payloads


def read_packet(port: serial.Serial) -> bytes:
    """One escaped API frame from the port, as the library's reader takes it: 7E, then unescape to the length."""
    assert port.read(1) == b"\x7e"
    raw = bytearray(b"\x7e")
    plain = bytearray()
    while len(plain) < 3 or len(plain) < 3 + int.from_bytes(plain[:2], "big"):
        byte = port.read(1)
        assert byte, "timeout"
        raw += byte
        if byte == b"\x7d":
            nxt = port.read(1)
            raw += nxt
            plain.append(nxt[0] ^ 0x20)
        else:
            plain.append(byte[0])
    return bytes(raw)


def test_the_sim_answers_packets_the_library_builds() -> None:
    with serve(str(SPEC)) as path, serial.Serial(path, 9600, timeout=5) as port:
        port.write(bytes(xbee.ATCommPacket(0x7D, "NI").output(escaped=True)))
        reply = parse(read_packet(port))
        assert isinstance(reply, xbee.ATCommResponsePacket)
        assert (reply.frame_id, reply.command, reply.status) == (0x7D, "NI", ATCommandStatus.OK)
        send = xbee.TransmitPacket(0x13, x64(0x000000000000FFFF), x16(0xFFFE), 0, 0, bytearray(b"\x7e\x11"))
        port.write(bytes(send.output(escaped=True)))
        status = parse(read_packet(port))
        assert isinstance(status, xbee.TransmitStatusPacket)
        assert status.frame_id == 0x13 and status.x16bit_dest_addr == x16(0xFFFE)


def test_the_generated_client_against_the_sim(xb: ModuleType) -> None:
    client_module = importlib.import_module("xbee_api2.client")
    with serve(str(SPEC)) as path, client_module.XbeeApi2Client(path) as module:
        reply = module.at_command(0x11, "NI", b"")
        assert (reply.frame_id, reply.command, reply.status) == (0x11, "NI", 0)
        status = module.transmit_request(0x7E, 0xFFFF, 0xFFFE, 0, 0, b"\x13hi")
        assert status.frame_id == 0x7E and status.delivery_status == 0
