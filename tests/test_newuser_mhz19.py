"""Winsen MH-Z19B CO2 sensor (tests/specs/winsen_mhz19.yaml), written from the user docs alone and checked against the
`mh-z19` package on PyPI (module mh_z19): the commands it writes decode as our requests and re-encode byte for byte,
its checksum() agrees with ours on random replies, and its read_all() reads the generated simulator. Requests carry
the sensor number 01 where replies do not (a constant with `directions: [request]`), so the check byte covers
different elements by direction (`covers: {request: [sensor, content], response: [command, content]}`)."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import, simulated
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import ChecksumError

try:  # the peer pulls in gpiozero and lgpio, which has no wheel for every Python: not in the test extra
    import mh_z19  # type: ignore[import-not-found]
except ImportError:
    mh_z19 = None
PEER = pytest.mark.skipif(mh_z19 is None, reason="mh-z19 is not installed (pip install mh-z19 to run the peer tests)")

SPEC = Path(__file__).parent / "specs" / "winsen_mhz19.yaml"  # not mh_z19: the peer's module name


@pytest.fixture(scope="module")
def mhz(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("mhz19"), "winsen_mhz19")


class Recorder:
    """What the peer writes to the port it opens."""

    def __init__(self) -> None:
        self.written = b""

    def write(self, data: bytes) -> int:
        self.written += data
        return len(data)

    def close(self) -> None:
        pass


@PEER
@pytest.mark.parametrize(
    ("call", "name", "fields"),
    [
        (lambda: mh_z19.abc_on(serial_console_untouched=True), "AbcLogicRequest", {"abc": 0xA0}),
        (lambda: mh_z19.abc_off(serial_console_untouched=True), "AbcLogicRequest", {"abc": 0}),
        (lambda: mh_z19.zero_point_calibration(serial_console_untouched=True), "ZeroCalibrationRequest", {}),
        (lambda: mh_z19.span_point_calibration(2000, True), "SpanCalibrationRequest", {"span": 2000}),
        (lambda: mh_z19.span_point_calibration(1234, True), "SpanCalibrationRequest", {"span": 1234}),
        (lambda: mh_z19.detection_range_2000(True), "DetectionRangeRequest", {"range": 2000}),
        (lambda: mh_z19.detection_range_5000(True), "DetectionRangeRequest", {"range": 5000}),
        (lambda: mh_z19.detection_range_10000(True), "DetectionRangeRequest", {"range": 10000}),
    ],
)
def test_the_peers_commands_are_our_requests(
    mhz: ModuleType, monkeypatch: pytest.MonkeyPatch, call: Callable[[], None], name: str, fields: dict[str, int]
) -> None:
    port = Recorder()
    monkeypatch.setattr(mh_z19, "connect_serial", lambda: port)
    call()
    message = mhz.decode(port.written, mhz.Direction.REQUEST)
    assert type(message).__name__ == name
    assert {k: int(v) for k, v in message.to_fields().items() if k in fields} == fields
    assert mhz.encode(message) == port.written


@settings(max_examples=examples(25), deadline=None)
@given(
    co2=st.integers(0, 0xFFFF), temperature=st.integers(0, 255), status=st.integers(0, 255), rest=st.integers(0, 0xFFFF)
)
def test_the_checksum_is_the_datasheets(mhz: ModuleType, co2: int, temperature: int, status: int, rest: int) -> None:
    """The datasheet's rule, (~sum of bytes 1..7) + 1, and the peer's checksum() where it is installed."""
    reply = mhz.ReadCo2Response(co2=co2, temperature=temperature, status=status, reserved=rest)
    frame = mhz.encode(reply)
    assert frame[:2] == b"\xff\x86" and len(frame) == 9
    assert frame[-1] == (0xFF - sum(frame[1:-1]) + 1) & 0xFF
    if mh_z19 is not None:
        assert mh_z19.checksum(frame[1:-1]) == frame[-1:]
    assert mhz.decode(frame, mhz.Direction.RESPONSE) == reply
    with pytest.raises(ChecksumError):
        mhz.decode(frame[:-1] + bytes([frame[-1] ^ 0x10]), mhz.Direction.RESPONSE)


def test_the_peer_and_our_client_read_the_sim(mhz: ModuleType, monkeypatch: pytest.MonkeyPatch) -> None:
    with simulated("winsen_mhz19") as path:
        if mh_z19 is not None:
            monkeypatch.setattr(mh_z19, "serial_dev", path)
            assert mh_z19.read_all(serial_console_untouched=True) == {
                "co2": 608,
                "temperature": 31,
                "TT": 71,
                "SS": 0,
                "UhUl": 0,
            }
        client_module = importlib.import_module("winsen_mhz19.client")
        with client_module.WinsenMhz19Client(path, timeout=2) as client:
            reply = client.read_co2()
            assert (reply.co2, reply.temperature) == (608, 71)
