"""MediaTek PMTK commands (tests/specs/pmtk.yaml), written from the user docs alone: NMEA-framed `$PMTK220,1000*1F`
requests acknowledged by `$PMTK001,220,3*30`. Its sentences were checked against pynmea2 (a ProprietarySentence's
checksum and fields both ways) and its simulator driven by the generated client on a pseudo-terminal; the tests
keep what that found: a device's `reports` may give a number (an expression was text only), and a number reported
in a char field is written as its digit (the simulator said "flag must be one of 0, 1, 2, 3, got 3" and answered
nothing; the letters are now quoted, as the value is)."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

import pytest
from conftest import generate_and_import
from serialspec.runtime.errors import EncodeError

SPEC = Path(__file__).parent / "specs" / "pmtk.yaml"


@pytest.fixture(scope="module")
def pmtk(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("pmtk"), "pmtk")


def test_the_simulator_acknowledges_with_the_command_number_and_flag_3(pmtk: ModuleType) -> None:
    import importlib

    device = importlib.import_module("pmtk.simulator").SIMULATOR()
    [(_, frame)] = device.feed(pmtk.encode(pmtk.SetFixIntervalRequest(interval=200)))
    assert frame == b"$PMTK001,220,3*30\r\n"
    answer = pmtk.decode(frame, "response")
    assert (answer.command, answer.flag) == (220, pmtk.Flag.SUCCEEDED)
    [(_, frame)] = device.feed(pmtk.encode(pmtk.TestRequest()))
    assert frame == b"$PMTK001,000,3*30\r\n"
    [(_, frame)] = device.feed(pmtk.encode(pmtk.QueryReleaseRequest()))
    assert pmtk.decode(frame, "response").model == "PA6H"


def test_a_number_for_a_letter_is_refused_with_the_letters_quoted(pmtk: ModuleType) -> None:
    with pytest.raises(EncodeError) as caught:
        pmtk.encode(pmtk.AckResponse(command=220, flag=3))
    assert str(caught.value) == "PMTK001: flag must be one of '0', '1', '2', '3', got 3"
