"""Kondo ICS 3.5 serial servos (tests/specs/kondo_ics.yaml), written from the user docs alone: a strict xfail. PyPI
has no ICS peer (the `kondo*` packages are unrelated), so the golden frames are the manual's rule: the command byte
is the command in its top three bits and the servo id in its low five (position 0x80 | id, read 0xA0 | id, write
0xC0 | id), the reply's the same byte with bit 7 cleared; a 14-bit position is two 7-bit bytes, high first.

The spec writes the command byte as the content's leading bit fields (`command: {type: u3, const: 4}`, `id: u5`, as
RTCM 3 picks a message by its leading 12-bit number), in a frame with no command element and no length: each
message, request or reply, is picked by its command bits and sized by its own fields."""

from __future__ import annotations

import importlib
import os
import threading
import tty
from pathlib import Path
from types import ModuleType

import pytest
from conftest import generate_and_import
from serialspec.runtime.errors import DecodeError

SPEC = Path(__file__).parent / "specs" / "kondo_ics.yaml"


def manual_position(servo: int, position: int) -> bytes:
    return bytes([0x80 | servo, position >> 7 & 0x7F, position & 0x7F])


def test_the_manuals_example_frame() -> None:
    assert manual_position(0, 7500) == bytes.fromhex("80 3a 4c")


@pytest.fixture(scope="module")
def ics(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("kondo"), "kondo_ics")


def test_the_manuals_frames_decode_and_encode_back(ics: ModuleType) -> None:
    """Once refused (`such requests are told apart by their content size, which needs a length element`, and `a
    codeless reply is shared ...: mark one of them default: true`): each message is picked by its command bits and
    sized by its own fields, requests and replies alike, with no request given."""
    message = ics.decode(manual_position(5, 7500), ics.Direction.REQUEST)
    assert message == ics.SetPositionRequest(id=5, position=7500)
    assert ics.encode(message) == manual_position(5, 7500)
    reply = ics.decode(bytes([0x05, 0x3A, 0x4C]), ics.Direction.RESPONSE)
    assert reply == ics.SetPositionResponse(id=5, position=7500)
    read = ics.decode(bytes.fromhex("a5 02"), ics.Direction.REQUEST)
    assert read == ics.ReadParameterRequest(id=5, parameter=ics.Parameter.SPEED)
    assert ics.decode(bytes.fromhex("25 02 50"), ics.Direction.RESPONSE) == ics.ReadParameterResponse(
        id=5, parameter=ics.Parameter.SPEED, value=80
    )
    with pytest.raises(DecodeError, match=r"unknown command 7 \(known: set_position: 4, read_parameter: 5, "):
        ics.decode(bytes.fromhex("e5 02"), ics.Direction.REQUEST)


@pytest.mark.parametrize("cut", [1, 2, 4, 64])
def test_the_stream_parser_sizes_each_message_by_its_command_bits(ics: ModuleType, cut: int) -> None:
    """Three messages of two sizes, with no length and no header: each sized by the message its first bits pick;
    a byte whose bits pick none is garbage (the 7F before the last one)."""
    stream = bytes.fromhex("25 02 50 05 3a 4c 45 03 10 7f 05 00 01")
    parser = ics.StreamParser(ics.Direction.RESPONSE)
    found = [m for i in range(0, len(stream), cut) for m in parser.feed(stream[i : i + cut])]
    assert found == [
        ics.ReadParameterResponse(id=5, parameter=ics.Parameter.SPEED, value=80),
        ics.SetPositionResponse(id=5, position=7500),
        ics.WriteParameterResponse(id=5, parameter=ics.Parameter.CURRENT, value=16),
        ics.SetPositionResponse(id=5, position=1),
    ]
    assert parser.garbage == 1


def test_the_client_asks_a_servo(ics: ModuleType) -> None:
    client_module = importlib.import_module("kondo_ics.client")
    controller, device = os.openpty()
    tty.setraw(device)
    try:
        with client_module.KondoIcsClient(os.ttyname(device), timeout=1.0) as client:
            thread = answer(controller, 2, bytes.fromhex("25 02 50"))
            assert client.read_parameter(5, ics.Parameter.SPEED) == 80
            thread.join()
            assert thread.got == bytes.fromhex("a5 02")  # type: ignore[attr-defined]
    finally:
        os.close(controller)
        os.close(device)


def answer(controller: int, size: int, reply: bytes) -> threading.Thread:
    """A servo on the other end of the pty: reads the request's `size` bytes, then writes `reply`."""

    def run() -> None:
        got = b""
        while len(got) < size:
            got += os.read(controller, size - len(got))
        thread.got = got  # type: ignore[attr-defined]
        os.write(controller, reply)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread
