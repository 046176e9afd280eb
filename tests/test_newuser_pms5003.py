"""Plantower PMS5003 particulate sensor (tests/specs/pms5003.yaml), written from the user docs alone and checked against
the `plantower` package on PyPI: its passive-mode commands decode as our requests and re-encode byte for byte, it reads
the data frames we encode (its own checksum check) and it drives the generated simulator, streaming and polled.
Requests carry a command byte and no length, data frames a length and no command byte: one layout, with `directions`
on those two elements. A read in passive mode is answered by the data frame the sensor also streams
(`answered_by: {command: data}`, an `unsolicited` response): the generated client's read() sent the request and
returned None, never waiting for that reply (a response sent on its own answered no request, whatever the spec said):
a bug, fixed."""

from __future__ import annotations

import importlib
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import, simulated
from hypothesis import given, settings
from hypothesis import strategies as st

plantower = pytest.importorskip("plantower")

SPEC = Path(__file__).parent / "specs" / "pms5003.yaml"
WORDS = [
    "pm1_0_cf1",
    "pm2_5_cf1",
    "pm10_cf1",
    "pm1_0_atm",
    "pm2_5_atm",
    "pm10_atm",
    "particles_0_3",
    "particles_0_5",
    "particles_1_0",
    "particles_2_5",
    "particles_5_0",
    "particles_10",
]


@pytest.fixture(scope="module")
def pms(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("pms5003"), "pms5003")


@pytest.mark.parametrize(
    ("constant", "name", "fields"),
    [
        ("PMS_CMD_READ_IN_PASSIVE", "ReadRequest", {}),
        ("PMS_CMD_CHANGE_MODE_PASSIVE", "ChangeModeRequest", {"mode": 0}),
        ("PMS_CMD_CHANGE_MODE_ACTIVE", "ChangeModeRequest", {"mode": 1}),
        ("PMS_CMD_TO_SLEEP", "SleepRequest", {"state": 0}),
        ("PMS_CMD_TO_WAKEUP", "SleepRequest", {"state": 1}),
    ],
)
def test_the_peers_commands_are_our_requests(pms: ModuleType, constant: str, name: str, fields: dict[str, int]) -> None:
    golden = getattr(plantower.plantower, constant)
    message = pms.decode(golden, pms.Direction.REQUEST)
    assert type(message).__name__ == name
    assert {k: int(v) for k, v in message.to_fields().items()} == fields
    assert pms.encode(message) == golden


class FakeSerial:
    """The bytes the peer reads, as a pyserial port."""

    def __init__(self, data: bytes) -> None:
        self.data = data

    def read(self, size: int = 1) -> bytes:
        out, self.data = self.data[:size], self.data[size:]
        return out


@settings(max_examples=examples(25), deadline=None)
@given(values=st.lists(st.integers(0, 0xFFFF), min_size=13, max_size=13))
def test_the_peer_reads_our_data_frames(pms: ModuleType, values: list[int]) -> None:
    message = pms.DataResponse(*values)
    frame = pms.encode(message)
    assert frame[:4] == bytes.fromhex("42 4d 00 1c") and len(frame) == 32
    assert int.from_bytes(frame[-2:], "big") == sum(frame[:-2])  # the sum of every byte before it
    sensor = plantower.Plantower.__new__(plantower.Plantower)  # no port opened
    sensor.serial, sensor.read_timeout = FakeSerial(frame), 1
    sensor.logger = plantower.plantower.logging.getLogger("test")
    reading = sensor.read(perform_flush=False)  # raises PlantowerException on a checksum it disagrees with
    peer = [reading.pm10_cf1, reading.pm25_cf1, reading.pm100_cf1, reading.pm10_std, reading.pm25_std]
    peer += [reading.pm100_std, reading.gr03um, reading.gr05um, reading.gr10um, reading.gr25um, reading.gr50um]
    assert peer + [reading.gr100um] == values[:12]
    assert pms.decode(frame, pms.Direction.RESPONSE) == message


def test_a_frame_with_a_wrong_sum_is_refused(pms: ModuleType) -> None:
    from serialspec.runtime.errors import ChecksumError

    frame = pms.encode(pms.DataResponse(*range(13)))
    with pytest.raises(ChecksumError):
        pms.decode(frame[:-1] + bytes([frame[-1] ^ 1]), pms.Direction.RESPONSE)
    parser = pms.StreamParser(pms.Direction.RESPONSE)
    assert parser.feed(b"\x42" + frame[:7] + frame + frame[:5]) == [pms.DataResponse(*range(13))]


@pytest.fixture
def sim(pms: ModuleType) -> Iterator[str]:
    with simulated("pms5003") as path:
        yield path


def test_the_peer_drives_the_sim(sim: str) -> None:
    sensor = plantower.Plantower(port=sim, read_timeout=5)
    try:
        reading = sensor.read()  # active mode: the frame streamed every second
        assert (reading.pm25_cf1, reading.pm25_std, reading.gr03um) == (12, 12, 1500)
        sensor.mode_change(plantower.PMS_PASSIVE_MODE)
        reading = sensor.read_in_passive()
        assert (reading.pm25_cf1, reading.pm25_std, reading.pm100_cf1) == (12, 12, 15)
    finally:
        sensor.serial.close()


def test_the_generated_client_polls_the_sim_in_passive_mode(pms: ModuleType, sim: str) -> None:
    client_module = importlib.import_module("pms5003.client")
    with client_module.Pms5003Client(sim, timeout=3) as client:
        streamed = next(iter(client.reports(timeout=3)))
        assert (streamed.pm2_5_cf1, streamed.particles_0_3) == (12, 1500)
        client.change_mode(pms.Mode.PASSIVE)
        reply = client.read()  # was None: the request was sent and the reply it is answered by never awaited
        assert "Args:" not in (client_module.Pms5003Client.read.__doc__ or "")  # an empty section once
        assert isinstance(reply, pms.DataResponse)
        assert [getattr(reply, name) for name in WORDS[:3]] == [8, 12, 15]
