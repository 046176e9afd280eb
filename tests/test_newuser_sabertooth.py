"""Sabertooth packetized serial (tests/specs/sabertooth.yaml), written from the user docs alone and checked against
pysabertooth: our codec reads the packets its sendCommand builds and re-encodes them byte for byte, and our stream
parser reads what the driver writes to a real pseudo-terminal (its AA baud-rate bytes included) as the commands it
meant. The driver only writes (a Sabertooth answers nothing), so there is no reply to check."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

import pytest
import serial
from conftest import generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from pty_pair import pty_pair

pysabertooth = pytest.importorskip("pysabertooth")

SPEC = Path(__file__).parent / "specs" / "sabertooth.yaml"
SPEED_COMMANDS = {0: "Forward1Request", 1: "Backwards1Request", 4: "Forward2Request", 5: "Backwards2Request"}


@pytest.fixture(scope="module")
def st_(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("sabertooth"), "sabertooth")


class CapturingPort:
    def __init__(self) -> None:
        self.written = b""

    def write(self, data: bytes) -> None:
        self.written += data

    def flush(self) -> None:
        pass

    def close(self) -> None:
        pass


def peer_packet(address: int, command: int, value: int) -> bytes:
    driver = pysabertooth.Sabertooth.__new__(pysabertooth.Sabertooth)
    driver.address, driver.saber = address, CapturingPort()
    driver.sendCommand(command, value)
    return bytes(driver.saber.written)


@settings(max_examples=200, deadline=None)
@given(address=st.integers(128, 135), command=st.sampled_from(sorted(SPEED_COMMANDS)), speed=st.integers(0, 127))
def test_packets_match_the_driver(st_: ModuleType, address: int, command: int, speed: int) -> None:
    golden = peer_packet(address, command, speed)
    message = getattr(st_, SPEED_COMMANDS[command])(address=address, speed=speed)
    assert st_.encode(message) == golden
    assert st_.decode(golden, st_.Direction.REQUEST) == message


def test_the_stream_parser_reads_the_driver_on_a_pty(st_: ModuleType) -> None:
    parser = st_.StreamParser(st_.Direction.REQUEST)
    seen: list[object] = []
    with pty_pair() as (host, motor), serial.Serial(motor, 9600, timeout=1) as port:
        driver = pysabertooth.Sabertooth(host, 9600, address=130)
        try:
            driver.drive(1, 50)
            driver.drive(2, -100)
            while len(seen) < 3:
                chunk = port.read(port.in_waiting or 1)
                assert chunk, f"the driver's bytes stopped; parsed {seen}"
                seen += parser.feed(chunk)
        finally:
            del driver  # its __del__ stops both motors and closes the port
    assert seen == [
        st_.SetBaudrateRequest(address=130, baudrate=st_.Baudrate.B9600),
        st_.Forward1Request(address=130, speed=int(127 * 50 / 100)),
        st_.Backwards2Request(address=130, speed=127),
    ]
