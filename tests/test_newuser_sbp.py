"""Swift Navigation Binary Protocol (tests/specs/swift_sbp.yaml), written from the user docs alone and checked
against Swift's `sbp` package: the frames its message classes write (heartbeat, GPS time, position, velocity, log)
decode to its values and re-encode byte for byte, its parser reads ours, and its Framer reads the simulated
receiver's stream off a pseudo-terminal, as our client does. The language carries it as it is: a u16 message type,
a u16 sender as the address, f64 fields, bit fields of a u32, a CRC-16/XMODEM over type to payload.

A usability note, not a gap: the device's `reply` names fields across messages, so the heartbeat's `flags` (bit
fields) and the navigation messages' `flags` (a byte) cannot both be given there; the spec names the heartbeat's
`status_flags`."""

from __future__ import annotations

import importlib
import time
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from conftest import generate_afresh, simulated

sbp = pytest.importorskip("sbp")
from sbp.logging import MsgLog  # noqa: E402
from sbp.msg import SBP  # noqa: E402
from sbp.navigation import MsgGPSTime, MsgPosLLH, MsgVelNED  # noqa: E402
from sbp.system import MsgHeartbeat  # noqa: E402
from sbp.table import dispatch  # noqa: E402

SPEC = Path(__file__).parent / "specs" / "swift_sbp.yaml"


@pytest.fixture(scope="module")
def swift(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_afresh(SPEC, tmp_path_factory, "swift_sbp")


POS = {"tow": 345600123, "lat": 37.7749295, "lon": -122.4194155, "height": -12.25, "h_accuracy": 1500}
PEER_MESSAGES = [
    (MsgPosLLH(sender=0x42, **POS, v_accuracy=2500, n_sats=14, flags=4), "PosLlhResponse"),
    (MsgGPSTime(sender=0x42, wn=2345, tow=345600123, ns_residual=-250000, flags=1), "GpsTimeResponse"),
    (
        MsgVelNED(sender=7, tow=1, n=-1234, e=5678, d=-9, h_accuracy=30, v_accuracy=40, n_sats=12, flags=1),
        "VelNedResponse",
    ),
    (MsgLog(sender=0xFFFF, level=6, text=b"Piksi Multi v2.4.20"), "LogResponse"),
]


def our_fields(peer: Any) -> dict[str, Any]:
    fields = {name: getattr(peer, name) for name in peer.__slots__ if name not in ("msg_type", "payload", "crc")}
    fields["sender"] = peer.sender
    if isinstance(fields.get("text"), bytes):
        fields["text"] = fields["text"].decode()
    return fields


@pytest.mark.parametrize(("peer", "name"), PEER_MESSAGES, ids=[name for _, name in PEER_MESSAGES])
def test_the_peers_frames_decode_and_re_encode(swift: ModuleType, peer: Any, name: str) -> None:
    frame = peer.to_binary()
    message = swift.decode(frame, swift.Direction.RESPONSE)
    assert type(message).__name__ == name
    assert message.to_fields() == our_fields(peer)
    assert swift.encode(message) == frame


def test_the_heartbeats_bit_fields(swift: ModuleType) -> None:
    flags = 1 << 31 | 2 << 16 | 4 << 8 | 0b101
    frame = MsgHeartbeat(sender=0x1234, flags=flags).to_binary()
    message = swift.decode(frame, swift.Direction.RESPONSE)
    bits = message.status_flags
    assert (bits.system_error, bits.io_error, bits.swift_nap_error) == (1, 0, 1)
    assert (bits.protocol_major, bits.protocol_minor, bits.external_antenna) == (2, 4, 1)
    assert message.sender == 0x1234 and swift.encode(message) == frame


def test_the_peer_reads_our_frames(swift: ModuleType) -> None:
    ours = swift.PosLlhResponse(sender=0x42, **POS, v_accuracy=2500, n_sats=14, flags=4)
    peer = dispatch(SBP.unpack(swift.encode(ours)))
    assert isinstance(peer, MsgPosLLH) and our_fields(peer) == ours.to_fields()
    assert peer.crc == int.from_bytes(swift.encode(ours)[-2:], "little")


def test_the_stream_parser_reads_a_two_byte_message_type(swift: ModuleType) -> None:
    """A frame of the classic shape (a header, a one-byte length, a final checksum) with a u16 command: the stream
    parser's fast format read the code as one byte and dropped every frame as garbage (decode read them)."""
    frames = [peer.to_binary() for peer, _ in PEER_MESSAGES] + [MsgHeartbeat(sender=1, flags=0).to_binary()]
    stream = b"\x00\x55" + b"".join(frames)
    for size in (1, 5, len(stream)):
        parser = swift.StreamParser(swift.Direction.RESPONSE)
        got = [m for i in range(0, len(stream), size) for m in parser.feed(stream[i : i + size])]
        assert [swift.encode(m) for m in got] == frames, size


def test_the_peers_framer_reads_the_simulated_receiver(swift: ModuleType) -> None:
    """sbp's Framer (its own preamble search and CRC check) over the simulator's pseudo-terminal: heartbeats and
    positions, every 20 ms, with the device's values; our client reads the same stream."""
    import serial
    from sbp.client import Framer

    with simulated("swift_sbp") as path:
        with serial.Serial(path, 115200, timeout=0.2) as port:
            framer = Framer(port.read, port.write)
            seen: dict[type, Any] = {}
            deadline = time.monotonic() + 5
            while len(seen) < 2 and time.monotonic() < deadline:
                for message, _metadata in framer:
                    if message is None:
                        break
                    seen[type(message)] = message
                    if len(seen) == 2:
                        break
        assert seen[MsgHeartbeat].flags == 2 << 16
        position = seen[MsgPosLLH]
        assert (position.lat, position.lon, position.height) == (37.7749, -122.4194, 16.5)
        assert (position.tow, position.n_sats, position.h_accuracy) == (345600000, 14, 1500)
        client_module = importlib.import_module("swift_sbp.client")
        client_class = next(v for k, v in vars(client_module).items() if k.endswith("Client") and k != "ClientBase")
        with client_class(path, timeout=2.0) as client:
            report = next(r for r in client.reports(timeout=5) if type(r).__name__ == "PosLlhResponse")
        assert (report.lat, report.n_sats) == (37.7749, 14)
