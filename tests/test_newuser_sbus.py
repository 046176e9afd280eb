"""Futaba S.BUS frames (tests/specs/sbus.yaml), written from the user docs alone. PyPI has no S.BUS peer: `sbus`
0.2.5 is an unrelated message bus (aio-pika), and `pysbus`/`futaba-sbus` do not exist, so the peer here is a bit
packer written from the frame rules (0x0F, 16 × 11-bit channels least significant bit first, the flags byte, 0x00)
one bit at a time, independently of our array code: our codec encodes its frames byte for byte and decodes them to
its values, a reader built on it takes frames from `serialspec sim` on a real pseudo-terminal, and our client
reads the same stream."""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import DecodeError
from sim_process import serve

SPEC = Path(__file__).parent / "specs" / "sbus.yaml"
FLAG_BITS = ("ch17", "ch18", "frame_lost", "failsafe")
SIM_CHANNELS = [172, 992, 1811, 992, 172, 1811] + [992] * 10


@pytest.fixture(scope="module")
def sb(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("sbus"), "sbus")


def peer_pack(channels: list[int], flags: int) -> bytes:
    """The frame, one bit at a time: bit b of channel i is bit 11*i + b of the 176-bit little-endian payload."""
    bits = [(channel >> b) & 1 for channel in channels for b in range(11)]
    payload = bytes(sum(bits[8 * n + k] << k for k in range(8)) for n in range(22))
    return b"\x0f" + payload + bytes([flags, 0x00])


def peer_unpack(frame: bytes) -> tuple[list[int], int]:
    assert len(frame) == 25 and frame[0] == 0x0F and frame[24] == 0x00
    bits = [(frame[1 + n] >> k) & 1 for n in range(22) for k in range(8)]
    return [sum(bits[11 * i + b] << b for b in range(11)) for i in range(16)], frame[23]


@settings(max_examples=examples(30), deadline=None)
@given(channels=st.lists(st.integers(0, 2047), min_size=16, max_size=16), flags=st.integers(0, 15))
def test_frames_match_the_bit_packer(sb: ModuleType, channels: list[int], flags: int) -> None:
    golden = peer_pack(channels, flags)
    bits = sb.FlagsBits(**{name: (flags >> i) & 1 for i, name in enumerate(FLAG_BITS)})
    message = sb.ChannelsResponse(channels=tuple(channels), flags=bits)
    assert sb.encode(message) == golden
    assert sb.decode(golden, sb.Direction.RESPONSE) == message
    assert peer_unpack(sb.encode(message)) == (channels, flags)


def test_a_frame_without_its_end_byte_is_refused(sb: ModuleType) -> None:
    frame = bytearray(peer_pack([992] * 16, 0))
    frame[-1] = 0x04  # the end byte of an S.BUS2 telemetry slot, not of this frame
    with pytest.raises(DecodeError):
        sb.decode(bytes(frame), sb.Direction.RESPONSE)
    with pytest.raises(DecodeError):
        sb.decode(bytes(frame[:-1]), sb.Direction.RESPONSE)


def test_a_channel_past_11_bits_is_refused_before_encoding(sb: ModuleType) -> None:
    with pytest.raises(ValueError, match="channels"):
        sb.encode(sb.ChannelsResponse(channels=(2048,) + (992,) * 15, flags=sb.FlagsBits(0, 0, 0, 0)))


def test_the_peer_reads_the_sim() -> None:
    import serial

    with serve(str(SPEC)) as path, serial.Serial(path, 100000, parity="E", stopbits=2, timeout=5) as port:
        stream = port.read(60)
    start = stream.index(b"\x0f")
    assert peer_unpack(stream[start : start + 25]) == (SIM_CHANNELS, 0b0001)


def test_the_generated_client_reads_the_sim_stream(sb: ModuleType) -> None:
    client_module = importlib.import_module("sbus.client")
    with serve(str(SPEC)) as path, client_module.SbusClient(path) as receiver:
        report = next(iter(receiver.reports(timeout=5)))
    assert list(report.channels) == SIM_CHANNELS
    assert report.flags == sb.FlagsBits(ch17=1, ch18=0, frame_lost=0, failsafe=0)


def test_a_message_built_with_a_list_equals_its_decoded_frame(sb: ModuleType) -> None:
    """A list given for an array field (the natural Python spelling) is stored as the tuple decode gives."""
    message = sb.ChannelsResponse(channels=[992] * 16, flags=sb.FlagsBits(0, 0, 0, 0))
    assert sb.decode(sb.encode(message), sb.Direction.RESPONSE) == message


def test_a_bit_field_may_be_given_by_its_bit_alone() -> None:
    """Found writing this spec: `frame_lost: 2` under `bits:` (as flags take it) was refused, "expected a mapping"; a
    bit number or [high, low] alone is the short form of `{bits: ...}`."""
    from serialspec.lang.loader import load_text
    from serialspec.lang.resolve import resolve

    text = SPEC.read_text(encoding="utf-8")
    short = text.replace("{bits: 0, description: Digital channel 17.}", "0").replace(
        "{bits: 3, description: The receiver is in failsafe.}", "[3, 3]"
    )
    assert short != text

    def flag_bits(spec: str) -> list[tuple[str, int, int]]:
        [command] = resolve(load_text(spec, "sbus.yaml")).commands
        flags = next(f for f in command.response.fields if f.name == "flags")  # type: ignore[union-attr]
        return [(b.name, b.high, b.low) for b in flags.bits]  # type: ignore[attr-defined]

    assert flag_bits(short) == flag_bits(text)
