"""Garmin's proprietary NMEA 0183 sentences PGRME and PGRMZ (tests/specs/garmin_nmea.yaml), a text protocol written
from the user docs alone and checked against pynmea2 (its Garmin proprietary sentence classes): the sentences it
renders decode to its values and encode back character for character, it parses (checksum checked) what we encode,
and it reads `serialspec sim`'s sentences from a real pseudo-terminal, as our Client does."""

from __future__ import annotations

import importlib
from decimal import Decimal
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from conftest import examples, generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from sim_process import serve

pynmea2 = pytest.importorskip("pynmea2")
from pynmea2.types.proprietary import grm  # noqa: E402

SPEC = Path(__file__).parent / "specs" / "garmin_nmea.yaml"
GARMIN_EXAMPLE = "$PGRME,15.0,M,45.0,M,25.0,M*1C"  # Garmin's technical specifications (GPS 18x), PGRME


@pytest.fixture(scope="module")
def gn(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("garmin_nmea"), "garmin_nmea")


def tenths() -> st.SearchStrategy[str]:
    return st.integers(0, 99999).map(lambda n: f"{n // 10}.{n % 10}")


def test_garmins_example(gn: ModuleType) -> None:
    peer = pynmea2.parse(GARMIN_EXAMPLE, check=True)
    ours = gn.decode(GARMIN_EXAMPLE)
    assert (ours.hpe, ours.vpe, ours.osepe) == (peer.hpe, peer.vpe, peer.osepe)
    assert ours.hpe_unit == gn.Metres.METRES and peer.hpe_unit == "M"
    assert gn.encode(ours).decode().rstrip("\r\n") == GARMIN_EXAMPLE


@settings(max_examples=examples(30), deadline=None)
@given(hpe=tenths(), vpe=tenths(), osepe=tenths())
def test_position_errors_match_pynmea2(gn: ModuleType, hpe: str, vpe: str, osepe: str) -> None:
    golden = grm.GRME("GRM", ["E", hpe, "M", vpe, "M", osepe, "M"]).render()
    ours = gn.decode(golden)
    assert (ours.hpe, ours.vpe, ours.osepe) == (Decimal(hpe), Decimal(vpe), Decimal(osepe))
    assert gn.encode(ours).decode().rstrip("\r\n") == golden
    built = gn.PositionErrorResponse(
        hpe=Decimal(hpe),
        hpe_unit=gn.Metres.METRES,
        vpe=Decimal(vpe),
        vpe_unit=gn.Metres.METRES,
        osepe=Decimal(osepe),
        osepe_unit=gn.Metres.METRES,
    )
    assert pynmea2.parse(gn.encode(built).decode(), check=True).render() == golden


@settings(max_examples=examples(30), deadline=None)
@given(altitude=st.integers(-1500, 60000), dimension=st.sampled_from([2, 3]))
def test_altitudes_match_pynmea2(gn: ModuleType, altitude: int, dimension: int) -> None:
    golden = grm.GRMZ("GRM", ["Z", str(altitude), "f", str(dimension)]).render()
    ours = gn.decode(golden)
    assert (ours.altitude, ours.altitude_unit, ours.fix_dimension) == (altitude, gn.AltitudeUnit.FEET, dimension)
    assert gn.encode(ours).decode().rstrip("\r\n") == golden
    peer = pynmea2.parse(gn.encode(ours).decode(), check=True)
    assert (Decimal(peer.altitude), peer.altitude_unit, peer.pos_fix_dim) == (altitude, "f", str(dimension))


def test_a_wrong_checksum_is_refused_by_both(gn: ModuleType) -> None:
    bad = GARMIN_EXAMPLE[:-2] + "1D"
    with pytest.raises(ValueError):
        gn.decode(bad)
    with pytest.raises(pynmea2.ChecksumError):
        pynmea2.parse(bad, check=True)


def test_pynmea2_reads_the_sim() -> None:
    import serial

    seen: dict[str, Any] = {}
    with serve(str(SPEC)) as path, serial.Serial(path, 4800, timeout=5) as port:
        reader = pynmea2.NMEAStreamReader(errors="raise")
        while len(seen) < 2:
            chunk = port.read(port.in_waiting or 1).decode("ascii")
            assert chunk, "no sentence from the sim"
            for sentence in reader.next(chunk):
                seen[sentence.sentence_type] = sentence
    errors, altitude = seen["GRME"], seen["GRMZ"]
    assert (errors.hpe, errors.vpe, errors.osepe) == (Decimal("3.5"), Decimal("5.0"), Decimal("6.1"))
    assert (altitude.altitude, altitude.altitude_unit) == (Decimal(1234), "f")


def test_the_generated_client_reads_the_sim(gn: ModuleType) -> None:
    module = importlib.import_module("garmin_nmea")
    with serve(str(SPEC)) as path, module.Client(path) as receiver:
        for message in receiver:
            if isinstance(message, module.AltitudeResponse):
                break
    assert (message.altitude, message.altitude_unit, message.fix_dimension) == (1234, gn.AltitudeUnit.FEET, 3)
