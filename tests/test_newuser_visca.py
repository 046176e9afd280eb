"""Sony VISCA PTZ cameras over RS-232 (tests/specs/visca.yaml), written from the user docs alone and checked by hand
against pyvisca (not a test dependency: its PTZ class turned the simulated camera off and on, zoomed it and read
the zoom back from `serialspec sim`). The tests keep what that found: a u16 request code (01 04: command, camera
category) answered under u8 reply codes was accepted and its replies never decoded (now refused in one line unless
the reply element's codes fit: here each reply is a command of its own); inquiry replies that share 50, told apart
by their size in frames ended by FF, were refused as needing a length element. Its 16-bit values, sent a nibble a
byte, were bit fields p, q, r, s of a u32 until `encoding: nibbles` made them one number (a signed pan/tilt position
too: -1 is 0F 0F 0F 0F)."""

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
    assert visca.decode(zoom, visca.Direction.RESPONSE).position == 0x1234
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
    [(_, done)] = sim.feed(bytes.fromhex("81 01 04 47 0a 0b 0c 0d ff"))  # the zoom position, a nibble a byte
    [(_, zoom)] = sim.feed(bytes.fromhex("81 09 04 47 ff"))
    assert (done, zoom) == (bytes.fromhex("90 51 ff"), bytes.fromhex("90 50 0a 0b 0c 0d ff"))


def test_positions_are_numbers_sent_a_nibble_a_byte(visca: ModuleType) -> None:
    """`encoding: nibbles`: the zoom position 0x1234 is 01 02 03 04, a signed pan -1 is 0F 0F 0F 0F; a byte with its
    high nibble set is refused naming the field, a value past 16 bits before a byte is written."""
    from serialspec.runtime.errors import DecodeError, EncodeError

    zoom = bytes.fromhex("81 01 04 47 01 02 03 04 ff")
    assert visca.decode(zoom, visca.Direction.REQUEST).position == 4660
    assert visca.encode(visca.ZoomDirectRequest(camera=0x81, position=0xFFFF)) == bytes.fromhex("81010447 0f0f0f0f ff")
    move = visca.PanTiltAbsoluteRequest(camera=0x81, pan_speed=0x18, tilt_speed=0x14, pan=-1, tilt=-32768)
    frame = visca.encode(move)
    assert frame == bytes.fromhex("81 01 06 02 18 14 0f 0f 0f 0f 08 00 00 00 ff")
    assert visca.decode(frame, visca.Direction.REQUEST) == move
    with pytest.raises(DecodeError, match=r"the high nibble of a byte of position is set \(0x01120304\)"):
        visca.decode(bytes.fromhex("81 01 04 47 01 12 03 04 ff"), visca.Direction.REQUEST)
    with pytest.raises(EncodeError, match=r"position = 65536 is outside its range 0\.\.65535"):
        visca.encode(visca.ZoomDirectRequest(camera=0x81, position=0x10000))
    with pytest.raises(EncodeError, match=r"pan = 32768 is outside its range -32768\.\.32767"):
        visca.encode(visca.PanTiltAbsoluteRequest(camera=0x81, pan_speed=1, tilt_speed=1, pan=32768, tilt=0))
