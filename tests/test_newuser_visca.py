"""Sony VISCA PTZ cameras over RS-232 (tests/specs/visca.yaml), written from the user docs alone and checked by hand
against pyvisca (not a test dependency: its PTZ class turned the simulated camera off and on, zoomed it and read
the zoom back from `serialspec sim`). The tests keep what that found: a u16 request code (01 04: command, camera
category) answered under u8 reply codes was accepted and its replies never decoded (now refused in one line unless
the reply element's codes fit: here each reply is a command of its own); inquiry replies that share 50, told apart
by their size in frames ended by FF, were refused as needing a length element."""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType

import pytest
from conftest import generate_and_import

SPEC = Path(__file__).parent / "specs" / "visca.yaml"


@pytest.fixture(scope="module")
def visca(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("visca"), "visca")


def test_inquiry_replies_under_one_code_are_told_apart_by_their_size(visca: ModuleType) -> None:
    power = bytes.fromhex("90 50 02 ff")
    zoom = bytes.fromhex("90 50 01 02 03 04 ff")
    assert visca.decode(power, visca.Direction.RESPONSE).state == visca.Power.ON
    assert visca.decode(zoom, visca.Direction.RESPONSE).position == visca.PositionBits(p=1, q=2, r=3, s=4)
    parser = visca.StreamParser(visca.Direction.RESPONSE)
    stream = zoom + bytes.fromhex("90 51 ff") + power
    found = [m for i in range(len(stream)) for m in parser.feed(stream[i : i + 1])]
    assert [type(m).__name__ for m in found] == ["ZoomPositionResponse", "CompletionResponse", "PowerStateResponse"]


def test_the_sim_answers_a_command_and_an_inquiry(visca: ModuleType) -> None:
    sim = importlib.import_module("visca.simulator").ViscaSimulator(ids=[0x81])
    [(_, done)] = sim.feed(bytes.fromhex("81 01 04 00 03 ff"))  # pyvisca's power(0): standby
    assert done == bytes.fromhex("90 51 ff")
    [(_, state)] = sim.feed(bytes.fromhex("81 09 04 00 ff"))
    assert state == bytes.fromhex("90 50 03 ff")
