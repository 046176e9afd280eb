"""Graupner HoTT SUMD (tests/specs/sumd.yaml), written from the user docs alone. PyPI has no SUMD peer (`sumd` is
an unrelated markdown tool), so the peers are ArduPilot's RC protocol test frames (libraries/AP_RCProtocol
RCProtocolTest: three receiver frames with the microseconds its decoder gives) and a packer written here from the
frame rules (A8, status, N, N big-endian u16 channels, CRC-16 with polynomial 0x1021 and start value 0 over every
byte before it, high byte first), its CRC computed bit by bit independently of our CRC code. The sim streams frames
a raw pyserial reader built on that packer takes apart. Real frames hold values outside the documented
8800..15200 (ArduPilot's: 8000, 15136, and 0 for unused channels), so the spec gives the channels no range."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import ChecksumError, DecodeError, RangeError
from sim_process import serve

SPEC = Path(__file__).parent / "specs" / "sumd.yaml"

# ArduPilot's frames and the microseconds its decoder reports for them (it swaps the first four channels into
# its own order: the values, not their places, are compared); 1/8 µs steps, so raw = 8 × µs.
ARDUPILOT = [
    (
        "A8 01 08 2F 50 31 E8 21 A0 2F 50 22 60 22 60 2E E0 2E E0 87 C6",
        [1597, 1076, 1514, 1514, 1100, 1100, 1500, 1500],
    ),
    (
        "A8 01 0C 22 60 2F 60 2E E0 2E E0 3B 60 3B 60 3B 60 3B 60 3B 60 3B 60 3B 60 3B 60 17 02",
        [1516, 1500, 1100, 1500, 1900, 1900, 1900, 1900, 1900, 1900, 1900, 1900],
    ),
    (
        "A8 01 10 1F 40 2E E8 2E E0 2E E0 2E E0 2E E0 2E E0 22 60 2E E0 2E E0 2E E0 2E E0"
        " 00 00 00 00 00 00 3B 20 4F 10",
        [1501, 1500, 1000, 1500, 1500, 1500, 1500, 1100, 1500, 1500, 1500, 1500, 0, 0, 0, 1892],
    ),
]


@pytest.fixture(scope="module")
def su(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("sumd"), "sumd")


def crc16(data: bytes) -> int:
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021 if crc & 0x8000 else crc << 1) & 0xFFFF
    return crc


def peer_pack(status: int, channels: list[int]) -> bytes:
    body = bytes([0xA8, status, len(channels)]) + b"".join(c.to_bytes(2, "big") for c in channels)
    return body + crc16(body).to_bytes(2, "big")


def peer_unpack(frame: bytes) -> tuple[int, list[int]]:
    assert frame[0] == 0xA8 and len(frame) == 5 + 2 * frame[2]
    assert crc16(frame[:-2]) == int.from_bytes(frame[-2:], "big")
    return frame[1], [int.from_bytes(frame[3 + 2 * i : 5 + 2 * i], "big") for i in range(frame[2])]


@pytest.mark.parametrize(("printed", "microseconds"), ARDUPILOT)
def test_ardupilots_frames(su: ModuleType, printed: str, microseconds: list[int]) -> None:
    frame = bytes.fromhex(printed)
    message = su.decode(frame, su.Direction.RESPONSE)
    assert message.status == su.Status.LIVE
    assert sorted(c // 8 for c in message.channels) == sorted(microseconds)  # ArduPilot rounds down
    assert su.encode(message) == frame
    assert peer_unpack(frame) == (1, list(message.channels))


@settings(max_examples=examples(25), deadline=None)
@given(status=st.sampled_from([0x01, 0x81]), channels=st.lists(st.integers(0, 0xFFFF), min_size=2, max_size=32))
def test_frames_match_the_packer(su: ModuleType, status: int, channels: list[int]) -> None:
    golden = peer_pack(status, channels)
    message = su.ChannelsResponse(status=su.Status(status), channels=channels)
    assert su.encode(message) == golden
    assert su.decode(golden, su.Direction.RESPONSE) == message


def test_failsafe_and_refusals(su: ModuleType) -> None:
    frame = peer_pack(0x81, [12000] * 4)
    assert su.decode(frame, su.Direction.RESPONSE).status == su.Status.FAILSAFE
    with pytest.raises(ChecksumError):
        su.decode(frame[:-1] + bytes([frame[-1] ^ 1]), su.Direction.RESPONSE)
    with pytest.raises(DecodeError):
        su.decode(frame[:-1], su.Direction.RESPONSE)
    with pytest.raises(RangeError, match="count = 33 is outside its range 2..32"):
        su.encode(su.ChannelsResponse(status=su.Status.LIVE, channels=[12000] * 33))


def test_the_stream_parser_splits_frames_anywhere(su: ModuleType) -> None:
    frames = [bytes.fromhex(printed) for printed, _ in ARDUPILOT]
    stream = b"\xa8\x01\x08" + b"".join(frames) + frames[0][:7]  # a torn frame first, a part of one last
    parser = su.StreamParser(su.Direction.RESPONSE)
    seen = [m for i in range(0, len(stream), 5) for m in parser.feed(stream[i : i + 5])]
    assert [su.encode(m) for m in seen] == frames


def test_a_raw_reader_takes_the_sims_frames() -> None:
    import serial

    with serve(str(SPEC)) as path, serial.Serial(path, 115200, timeout=5) as port:
        stream = port.read(60)
    start = stream.index(b"\xa8\x01\x08")
    assert peer_unpack(stream[start : start + 21]) == (1, [12000, 12000, 8800, 12000, 15200, 12000, 12000, 12000])


def test_encode_takes_a_response_only_command_without_a_direction(capsys: pytest.CaptureFixture[str]) -> None:
    """Found writing this spec: `serialspec encode` took every object without a direction for a request, and said
    `sumd has no request 'channels' (it has )`. A command with one direction is encoded in it; asked for the other,
    the line says which it is."""
    from serialspec.cli import main

    fields = '"fields": {"status": 1, "channels": [12000, 12000]}'
    assert main(["encode", str(SPEC), "--json", '{"command": "channels", ' + fields + "}"]) == 0
    assert capsys.readouterr().out.strip() == "a8 01 02 2e e0 2e e0 ba 63"
    assert main(["encode", str(SPEC), "--direction", "request", "--json", '{"command": "channels", ' + fields + "}"])
    assert "sumd has no request 'channels' (it is a response: give the direction response)" in capsys.readouterr().err


def test_a_scale_on_an_array_is_refused_not_lost(tmp_path: Path) -> None:
    """Found writing this spec: `scale: 0.125` on the channel array (1/8 µs steps) was accepted and dropped:
    `decode --units` showed 12000, not 1500, and nothing said why. Now one line says where it goes."""
    from serialspec.lang import load_protocol
    from serialspec.lang.errors import SpecErrors

    text = SPEC.read_text("utf-8").replace("          unit: 0.125 µs\n", "          unit: µs\n          scale: 0.125\n")
    path = tmp_path / "sumd.yaml"
    path.write_text(text, "utf-8")
    with pytest.raises(SpecErrors, match=r"channels\.scale: `scale` goes with a number field, not an array"):
        load_protocol(path)
