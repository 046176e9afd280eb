"""SiRF binary protocol (tests/specs/sirf_binary.yaml), written from the user docs alone; no PyPI peer, so the frames
are checked against the reference manual's printed examples (spec examples) and a packer written in this test from its
words: A0 A2, a 15-bit length, the payload (message id first), the 15-bit sum of the payload (`mask: 0x7FFF`), B0 B3.
Found writing it: `device.reply` giving a field made of bit fields a whole number (`mode1: 4`) was accepted by
`check` and `generate`, and the simulator then sent nothing, logging `mode1 must be an object, got 4` each second: a
bug, fixed (one line at load time naming the `field.bit_field` form)."""

from __future__ import annotations

import importlib
import json
import struct
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import, simulated, spec_error
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import ChecksumError, EncodeError

SPEC = Path(__file__).parent / "specs" / "sirf_binary.yaml"


@pytest.fixture(scope="module")
def sirf(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("sirf"), "sirf_binary")


def packed(payload: bytes) -> bytes:
    """A message by the manual's words."""
    return (
        b"\xa0\xa2" + struct.pack(">H", len(payload)) + payload + struct.pack(">H", sum(payload) & 0x7FFF) + b"\xb0\xb3"
    )


@settings(max_examples=examples(25), deadline=None)
@given(
    position=st.lists(st.integers(-(2**31), 2**31 - 1), min_size=3, max_size=3),
    velocity=st.lists(st.integers(-32768, 32767), min_size=3, max_size=3),
    mode1=st.integers(0, 255),
    rest=st.tuples(st.integers(0, 255), st.integers(0, 255), st.integers(0, 1023), st.integers(0, 2**32 - 1)),
    channels=st.lists(st.integers(0, 32), min_size=12, max_size=12),
)
def test_navigation_data_follows_the_manual(
    sirf: ModuleType,
    position: list[int],
    velocity: list[int],
    mode1: int,
    rest: tuple[int, int, int, int],
    channels: list[int],
) -> None:
    hdop, mode2, week, tow = rest
    golden = packed(
        struct.pack(">B3i3hBBBHIB12B", 2, *position, *velocity, mode1, hdop, mode2, week, tow, 7, *channels)
    )
    message = sirf.decode(golden, sirf.Direction.RESPONSE)
    assert (message.x, message.y, message.z, message.vx, message.vy, message.vz) == (*position, *velocity)
    assert message.mode1.position == mode1 & 7 and message.mode1.dgps == mode1 >> 7
    assert (message.week, message.time_of_week, list(message.channels)) == (week, tow, channels)
    assert sirf.encode(message) == golden


def test_the_checksum_keeps_15_bits(sirf: ModuleType) -> None:
    """A payload whose sum passes 0x7FFF (and 0xFFFF): the checksum is the sum's low 15 bits."""
    frame = sirf.encode(sirf.SoftwareVersionResponse(version="~" * 299))
    assert frame == packed(b"\x06" + b"~" * 299)
    assert sum(frame[4:-4]) > 0x7FFF and frame[-4:-2] == struct.pack(">H", sum(frame[4:-4]) & 0x7FFF)
    with pytest.raises(ChecksumError):
        sirf.decode(frame[:-4] + struct.pack(">H", sum(frame[4:-4]) & 0xFFFF) + frame[-2:], sirf.Direction.RESPONSE)


def test_a_payload_past_15_bits_is_refused(sirf: ModuleType) -> None:
    with pytest.raises(EncodeError, match="length"):
        sirf.encode(sirf.SoftwareVersionResponse(version="x" * 32767))


def test_the_stream_parser_splits_messages_anywhere(sirf: ModuleType) -> None:
    ack = packed(bytes([0x0B, 0x86]))
    version = packed(b"\x06GSW3")
    stream = b"\xa0\xa2\x00" + ack + b"\xb0\xb3\xa0" + version + ack[:5]
    for size in (1, 2, 5, len(stream)):
        parser = sirf.StreamParser(sirf.Direction.RESPONSE)
        found = [m for i in range(0, len(stream), size) for m in parser.feed(stream[i : i + size])]
        assert found == [sirf.AckResponse(acked_id=0x86), sirf.SoftwareVersionResponse(version="GSW3")], size


def test_a_whole_number_for_bit_fields_in_reply_is_one_line(tmp_path: Path) -> None:
    text = SPEC.read_text("utf-8").replace("mode1.position: 4,", "mode1: 4,")
    assert spec_error(text, tmp_path).endswith(
        "device.reply.mode1: the measured_navigation response's mode1 is made of bit fields: give each as "
        "`mode1.dgps: ...` (its bit fields: dgps, dop_mask, altitude, trickle, position)"
    )


@pytest.fixture
def sim_path(sirf: ModuleType) -> Iterator[str]:
    with simulated("sirf_binary") as path:
        yield path


def test_the_generated_client_against_the_sim(sirf: ModuleType, sim_path: str) -> None:
    client_module = importlib.import_module("sirf_binary.client")
    with client_module.SirfBinaryClient(sim_path, timeout=3) as client:
        fix = next(iter(client.reports(timeout=3)))
        assert (fix.x, fix.mode1.position, fix.satellites) == (-2686727, 4, 7)
        assert client.poll_software_version() == "GSW3.5.0_3.5.00.00-SDK-3EP2.01"
        assert client.set_serial_port(9600, 8, 1, sirf.Parity.NONE) is True  # MID 11 naming MID 134


def test_the_c_reads_the_manuals_messages(tmp_path: Path) -> None:
    from test_c_backend import GCC, spec_driver

    if GCC is None:
        pytest.skip("no C compiler")
    driver = spec_driver(SPEC, "sirf_binary", tmp_path)
    try:
        said = driver.ask("dec request a0a20009860000258008010000" + "0134b0b3")[0]
        assert said.startswith("ok ") and json.loads(said[3:])["fields"]["bit_rate"] == 9600
        assert driver.ask("dec request a0a20009860000258008010000" + "8134b0b3")[0].startswith("err")
        big = packed(b"\x06" + "\u00ff".encode() * 127).hex()  # 254 bytes (C's default capacity: 256), sum > 0x7FFF
        said = driver.ask(f"dec response {big}")[0]
        assert said.startswith("ok ") and json.loads(said[3:])["command"] == "software_version"
    finally:
        driver.close()
