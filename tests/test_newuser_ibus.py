"""FlySky i-BUS servo frames (tests/specs/ibus.yaml), written from the user docs alone and checked against the
flyskyibus package (a pyserial reader and writer): our codec reads the frames its `write` builds and re-encodes them
byte for byte, its `validate`/`unpack` accept ours, and its `read` takes a frame from `serialspec sim` on a real
pseudo-terminal."""

from __future__ import annotations

import struct
from pathlib import Path
from types import ModuleType

import pytest
from conftest import generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import DecodeError
from sim_process import serve

ibus_module = pytest.importorskip("flySkyiBus.IBus")

SPEC = Path(__file__).parent / "specs" / "ibus.yaml"
NAMES = [f"ch{i}" for i in range(1, 15)]


@pytest.fixture(scope="module")
def ib(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("ibus"), "ibus")


class CapturingPort:
    """What IBus.write writes to."""

    def __init__(self) -> None:
        self.written = b""

    def write(self, data: bytes) -> None:
        self.written += data


def peer_frame(channels: list[int]) -> bytes:
    """The frame flyskyibus writes (IBus.write packs the checksum as a signed i16: -sum - 1)."""
    peer = ibus_module.IBus.__new__(ibus_module.IBus)
    peer.serial = CapturingPort()
    peer.write(list(channels))
    return peer.serial.written


@settings(max_examples=200, deadline=None)
@given(channels=st.lists(st.integers(0, 2100), min_size=14, max_size=14))
def test_frames_match_the_peer(ib: ModuleType, channels: list[int]) -> None:
    golden = peer_frame(channels)
    message = ib.ChannelsResponse(**dict(zip(NAMES, channels, strict=True)))
    assert ib.encode(message) == golden
    assert ib.decode(golden, ib.Direction.RESPONSE) == message
    peer = ibus_module.IBus.__new__(ibus_module.IBus)
    assert peer.validate(ib.encode(message))
    assert list(peer.unpack(ib.encode(message))[2:16]) == channels


def test_a_corrupted_checksum_is_refused(ib: ModuleType) -> None:
    frame = bytearray(peer_frame([1500] * 14))
    frame[-1] ^= 1
    with pytest.raises(DecodeError):
        ib.decode(bytes(frame), ib.Direction.RESPONSE)


def test_the_peer_reads_the_sim() -> None:
    with serve(str(SPEC)) as path:
        peer = ibus_module.IBus(path, 115200)
        try:
            peer.serial.timeout = 5
            values = peer.read()
        finally:
            peer.serial.close()
    assert values[:2] == (0x20, 0x40)
    assert list(values[2:16]) == [1000 + 50 * i for i in range(1, 15)]
    assert values[16] == -(sum(struct.pack("<BB14H", *values[:16]))) - 1


def test_the_generated_client_reads_the_sim_stream(ib: ModuleType) -> None:
    import importlib

    client_module = importlib.import_module("ibus.client")
    with serve(str(SPEC)) as path, client_module.IbusClient(path) as receiver:
        report = next(iter(receiver.reports(timeout=5)))
        assert [getattr(report, name) for name in NAMES] == [1000 + 50 * i for i in range(1, 15)]
