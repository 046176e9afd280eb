"""WitMotion IMUs (JY901, HWT905, WT901; tests/specs/witmotion_imu.yaml), written from the user docs alone and
checked against the `witmotion` package on PyPI (its protocol module: the packets' sum and parsers, the
configuration writes' serializer): our frames carry its sum, its parsers read our values at our scales, and its
configuration commands decode as our requests and re-encode byte for byte. The output packets are unsolicited
responses under their type byte; the configuration writes (FF AA, register, value, no checksum) are requests."""

from __future__ import annotations

import struct
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import DecodeError

peer = pytest.importorskip("witmotion.protocol")

SPEC = Path(__file__).parent / "specs" / "witmotion_imu.yaml"
I16 = st.integers(-32768, 32767)
G = peer.G  # the peer reports acceleration in m/s², with g = 9.8


@pytest.fixture(scope="module")
def wm(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("witmotion"), "witmotion_imu")


def peer_packet(message_class: type, values: tuple[int, ...]) -> bytes:
    body = struct.pack("<hhhh", *values)
    return bytes([0x55, message_class.code]) + body + bytes([message_class.compute_checksum(body)])


@settings(max_examples=examples(25), deadline=None)
@given(values=st.tuples(I16, I16, I16, I16))
def test_acceleration_packets_match_the_peer(wm: ModuleType, values: tuple[int, int, int, int]) -> None:
    golden = peer_packet(peer.AccelerationMessage, values)
    message = wm.AccelerationResponse(ax=values[0], ay=values[1], az=values[2], temperature=values[3])
    assert wm.encode(message) == golden
    assert wm.decode(golden, wm.Direction.RESPONSE) == message
    parsed = peer.AccelerationMessage.parse(golden[2:10])
    assert parsed.a == pytest.approx(tuple(v * 16 / 32768 * G for v in values[:3]))  # the spec's scale: 16 / 32768
    assert parsed.temp_celsius == pytest.approx(values[3] * 0.01)


@settings(max_examples=examples(15), deadline=None)
@given(values=st.tuples(I16, I16, I16, st.integers(0, 32767)))
def test_angle_and_gyro_packets_match_the_peer(wm: ModuleType, values: tuple[int, int, int, int]) -> None:
    golden = peer_packet(peer.AngleMessage, values)
    message = wm.decode(golden, wm.Direction.RESPONSE)
    assert message == wm.AngleResponse(roll=values[0], pitch=values[1], yaw=values[2], version=values[3])
    assert wm.encode(message) == golden
    parsed = peer.AngleMessage.parse(golden[2:10])
    assert (parsed.roll, parsed.pitch, parsed.yaw) == pytest.approx(tuple(v * 180 / 32768 for v in values[:3]))
    gyro = peer_packet(peer.AngularVelocityMessage, values)
    assert wm.decode(gyro, wm.Direction.RESPONSE) == wm.AngularVelocityResponse(*values)
    assert peer.AngularVelocityMessage.parse(gyro[2:10]).w == pytest.approx(tuple(v * 2000 / 32768 for v in values[:3]))


@pytest.mark.parametrize(
    ("register", "data", "name", "fields"),
    [
        ("unknown_config_cmd", 0xB588, "UnlockRequest", {}),  # the unlock key is a constant
        ("save", 0, "SaveRequest", {"action": 0}),
        ("rate", 6, "SetRateRequest", {"rate": 6}),  # 10 Hz
        ("baud", 6, "SetBaudRequest", {"baud": 6}),  # 115200
        ("calsw", 1, "CalibrateRequest", {"mode": 1}),
    ],
)
def test_configuration_writes_match_the_peer(
    wm: ModuleType, register: str, data: int, name: str, fields: dict[str, int]
) -> None:
    golden = peer.ConfigCommand(peer.Register[register], data).serialize()
    message = getattr(wm, name)(**fields)
    assert wm.encode(message) == golden
    assert wm.decode(golden, wm.Direction.REQUEST) == message


def test_the_stream_parser_skips_types_the_spec_leaves_out(wm: ModuleType) -> None:
    """An IMU sends more packet types than a user declares (0x50 time, 0x59 quaternion): they are passed over,
    as are a stray 0x55 and a packet with a bad sum; a packet split across reads is completed."""
    acc = peer_packet(peer.AccelerationMessage, (16, -16, 2048, 2860))
    quaternion = peer_packet(peer.QuaternionMessage, (1, 2, 3, 4))
    angle = peer_packet(peer.AngleMessage, (1, 2, 3, 4))
    bad = acc[:-1] + bytes([acc[-1] ^ 1])
    parser = wm.StreamParser(wm.Direction.RESPONSE)
    first = parser.feed(b"\x01\x55" + acc + quaternion + bad + angle + acc[:5])
    assert first == [wm.AccelerationResponse(16, -16, 2048, 2860), wm.AngleResponse(1, 2, 3, 4)]
    assert parser.feed(acc[5:]) == [wm.AccelerationResponse(16, -16, 2048, 2860)]
    with pytest.raises(DecodeError, match="unknown command 0x59"):
        wm.decode(quaternion, wm.Direction.RESPONSE)


def test_a_register_read_and_its_answer(wm: ModuleType) -> None:
    """FF AA 27 reg 00 asks for four registers from reg; the IMU answers 55 5F and their values (an `answers:`
    response under a code of its own)."""
    assert wm.encode(wm.ReadRequest(register=3)) == bytes.fromhex("ff aa 27 03 00")
    answer = bytes.fromhex("55 5f 06 00 02 00 00 00 00 00 bc")
    assert wm.decode(answer, wm.Direction.RESPONSE) == wm.RegistersResponse(values=(6, 2, 0, 0))
