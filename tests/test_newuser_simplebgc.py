"""BaseCam SimpleBGC 32-bit serial API v1 (tests/specs/simplebgc.yaml), written from the user docs alone; no PyPI peer,
so the frames are checked against a packer written in this test from the API's words (`>`, id, size, (id + size) mod
256, payload, payload sum mod 256). Two checksums, the first over the header before the payload, the second over the
payload alone; CMD_CONFIRM shares CMD_CONTROL's id 'C' in the other direction and answers other commands, naming
the one it confirms (`answered_by` with `request_code`)."""

from __future__ import annotations

import importlib
import json
import struct
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import, simulated
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import ChecksumError

SPEC = Path(__file__).parent / "specs" / "simplebgc.yaml"


@pytest.fixture(scope="module")
def bgc(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("simplebgc"), "simplebgc")


def packed(command: int, payload: bytes) -> bytes:
    """A frame by the API's words."""
    return bytes([0x3E, command, len(payload), (command + len(payload)) % 256]) + payload + bytes([sum(payload) % 256])


i16 = st.integers(-32768, 32767)


@settings(max_examples=examples(25), deadline=None)
@given(mode=st.integers(0, 5), values=st.lists(i16, min_size=6, max_size=6))
def test_control_frames_follow_the_api(bgc: ModuleType, mode: int, values: list[int]) -> None:
    message = bgc.ControlRequest(mode, *values)
    golden = packed(67, struct.pack("<B6h", mode, *values))
    assert bgc.encode(message) == golden
    assert bgc.decode(golden, bgc.Direction.REQUEST) == message


@settings(max_examples=examples(25), deadline=None)
@given(values=st.lists(i16, min_size=9, max_size=9))
def test_angle_replies_follow_the_api(bgc: ModuleType, values: list[int]) -> None:
    axes = [bgc.AxesItem(*values[i : i + 3]) for i in (0, 3, 6)]
    golden = packed(73, struct.pack("<9h", *values))
    assert bgc.encode(bgc.GetAnglesResponse(axes=axes)) == golden
    assert list(bgc.decode(golden, bgc.Direction.RESPONSE).axes) == axes


def test_either_checksum_wrong_is_refused(bgc: ModuleType) -> None:
    frame = bytes.fromhex("3E 43 0D 50 02 00 00 00 00 00 00 55 05 00 00 00 00 5C")
    for at in (3, len(frame) - 1):
        with pytest.raises(ChecksumError):
            bgc.decode(frame[:at] + bytes([frame[at] ^ 1]) + frame[at + 1 :], bgc.Direction.REQUEST)


def test_the_stream_parser_reads_replies_among_noise(bgc: ModuleType) -> None:
    info = packed(86, struct.pack("<BHBHBI", 30, 2605, 0, 1, 0, 7) + bytes(7))
    confirm = bytes.fromhex("3E 43 01 44 4D 4D")
    stream = b"\x3e\x01" + info + b"\x3e\x43\x01\x45" + confirm + info[:6]
    parser = bgc.StreamParser(bgc.Direction.RESPONSE)
    found = [m for i in range(0, len(stream), 3) for m in parser.feed(stream[i : i + 3])]
    assert [type(m).__name__ for m in found] == ["BoardInfoResponse", "ConfirmResponse"]
    assert (found[0].firmware_version, found[0].firmware_extra_id, found[1].command_id) == (2605, 7, 77)


@pytest.fixture
def sim_path(bgc: ModuleType) -> Iterator[str]:
    with simulated("simplebgc") as path:
        yield path


def test_the_generated_client_against_the_sim(bgc: ModuleType, sim_path: str) -> None:
    client_module = importlib.import_module("simplebgc.client")
    with client_module.SimplebgcClient(sim_path, timeout=2) as client:
        info = client.board_info()
        assert (info.board_version, info.firmware_version) == (30, 2605)
        assert client.motors_on() == b""  # the CMD_CONFIRM naming CMD_MOTORS_ON
        assert len(client.get_angles()) == 3
        client.control(bgc.ControlMode.ANGLE, 0, 0, 0, 1365, 0, 0)  # no reply


def test_the_c_reads_both_checksums(tmp_path: Path) -> None:
    from test_c_backend import GCC, spec_driver

    if GCC is None:
        pytest.skip("no C compiler")
    driver = spec_driver(SPEC, "simplebgc", tmp_path)
    try:
        said = driver.ask("dec request 3e430d5002000000000000550500000000" + "5c")[0]
        assert said.startswith("ok ") and json.loads(said[3:])["fields"]["angle_pitch"] == 1365
        assert driver.ask("dec request 3e430d5102000000000000550500000000" + "5c")[0].startswith("err")
        said = driver.ask("dec response 3e4301444d4d")[0]
        assert said.startswith("ok ") and json.loads(said[3:])["command"] == "confirm"
    finally:
        driver.close()
