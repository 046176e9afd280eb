"""MultiWii Serial Protocol v2 native ($X<, tests/specs/msp2.yaml), written from the user docs alone and checked
against yamspy (Betaflight's and iNAV's Python MSP client): our codec reads the v2 requests its send_RAW_msg builds
and re-encodes them byte for byte, its receive_msg and process_recv_data read our replies to the values we encoded,
and yamspy's own send and receive code asks `serialspec sim` on a real pseudo-terminal (its MSPy() constructor is
left out: its handshake asks v1 commands, which a v2-only spec does not answer)."""

from __future__ import annotations

import importlib
import os
import struct
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from conftest import examples, generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import DecodeError
from sim_process import serve

yamspy = pytest.importorskip("yamspy")

SPEC = Path(__file__).parent / "specs" / "msp2.yaml"
ANALOG = yamspy.MSPy.MSPCodes["MSPV2_INAV_ANALOG"]
DEBUG = yamspy.MSPy.MSPCodes["MSP2_INAV_DEBUG"]


@pytest.fixture(scope="module")
def m2(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("msp2"), "msp2")


class Port:
    """What yamspy reads from and writes to: bytes given to read, bytes written kept."""

    def __init__(self, incoming: bytes = b"") -> None:
        self.incoming, self.written = incoming, b""

    def write(self, data: bytes) -> int:
        self.written += bytes(data)
        return len(data)

    def read(self, size: int = 1) -> bytes:
        chunk, self.incoming = self.incoming[:size], self.incoming[size:]
        return chunk


def board(port: object) -> Any:
    """An MSPy on `port`, as an iNAV board, without `with` (which opens the port and asks v1 commands)."""
    peer = yamspy.MSPy("unused", logfilename=os.devnull, loglevel="WARNING")  # opens nothing until `with`
    peer.conn, peer.INAV = port, True
    return peer


def test_requests_match_yamspy(m2: ModuleType) -> None:
    for code, message in [(ANALOG, m2.InavAnalogRequest()), (DEBUG, m2.InavDebugRequest())]:
        port = Port()
        board(port).send_RAW_msg(code, data=[])
        assert m2.encode(message) == port.written
        assert m2.decode(port.written, m2.Direction.REQUEST) == message


@settings(max_examples=examples(30), deadline=None)
@given(
    cells=st.integers(0, 15),
    voltage=st.integers(0, 65535),
    amperage=st.integers(0, 65535),
    power=st.integers(0, 2**32 - 1),
    mah=st.integers(0, 2**32 - 1),
    percentage=st.integers(0, 100),
    rssi=st.integers(0, 1023),
)
def test_yamspy_reads_our_analog_replies(
    m2: ModuleType, cells: int, voltage: int, amperage: int, power: int, mah: int, percentage: int, rssi: int
) -> None:
    flags = m2.BatteryFlagsBits(full_when_plugged_in=1, use_capacity_thresholds=0, battery_state=2, cell_count=cells)
    message = m2.InavAnalogResponse(
        battery_flags=flags,
        voltage=voltage,
        amperage=amperage,
        power=power,
        mah_drawn=mah,
        mwh_drawn=7,
        remaining_capacity=8,
        percentage=percentage,
        rssi=rssi,
    )
    frame = m2.encode(message)
    assert m2.decode(frame, m2.Direction.RESPONSE) == message
    peer = board(Port(frame))
    handler = peer.receive_msg()
    assert not handler["crcError"] and not handler["packet_error"]
    assert handler["code"] == ANALOG
    assert peer.process_recv_data(handler) == 0  # (the payload bytes it left over)
    analog = peer.ANALOG
    assert (analog["cell_count"], analog["battery_state"], analog["battery_full_when_plugged_in"]) == (cells, 2, True)
    assert (analog["voltage"], analog["amperage"], analog["power"]) == (voltage / 100, amperage / 100, power / 100)
    assert (analog["mAhdrawn"], analog["battery_percentage"], analog["rssi"]) == (mah, percentage, rssi)


def test_a_reply_with_a_wrong_crc_is_refused_by_both(m2: ModuleType) -> None:
    frame = bytearray(m2.encode(m2.InavDebugResponse(debug=(1, 2, 3, 4, 5, 6, 7, 8))))
    frame[-1] ^= 0x01
    with pytest.raises(DecodeError):
        m2.decode(bytes(frame), m2.Direction.RESPONSE)
    assert board(Port(bytes(frame))).receive_msg()["crcError"]


def test_yamspy_asks_the_sim() -> None:
    import serial

    with serve(str(SPEC)) as path, serial.Serial(path, 115200, timeout=2) as port:
        peer = board(port)
        for code in (ANALOG, DEBUG):
            peer.send_RAW_msg(code, data=[])
            # yamspy reads one byte past a v2 frame (size + 2 for a 1-byte CRC): the port's timeout ends that read
            assert peer.process_recv_data(peer.receive_msg()) == 0
    analog = peer.ANALOG
    assert (analog["voltage"], analog["cell_count"], analog["battery_percentage"], analog["rssi"]) == (
        16.8,
        4,
        93,
        1000,
    )
    assert peer.SENSOR_DATA["debug"] == [1, -2, 3, -4, 5, -6, 7, -8]


def test_the_generated_client_asks_the_sim(m2: ModuleType) -> None:
    client_module = importlib.import_module("msp2.client")
    with serve(str(SPEC)) as path, client_module.Msp2Client(path, timeout=5) as fc:
        analog = fc.inav_analog()
        assert (analog.voltage, analog.battery_flags.cell_count, analog.percentage) == (1680, 4, 93)
        assert fc.inav_debug() == (1, -2, 3, -4, 5, -6, 7, -8)
    assert struct.calcsize("<BHHIIIIBH") == 24  # iNAV's MSPV2_INAV_ANALOG payload: our spec's field sizes add up
