"""Pixy2 (CMUcam5) serial packets (tests/specs/pixy2.yaml), written from the user docs alone. No PyPI package
speaks them off the camera's own board: `pixycamev3` builds the same packets but refuses to import anywhere but on a
LEGO EV3 (it reads /sys/class/board-info), `pixy-sdk` is an unrelated video API. So the peer is the packet reference
(its request bytes are golden frames) and a packer written here from its words: requests AE C1, type, length,
payload (or AF C1 with a checksum); responses AF C1, type, length, the u16 sum of the payload, payload. A response's
checksum comes before the bytes it covers. Two layouts (requests with and without a checksum) that are the same in
the response direction but for an element's `directions` were refused as "alternative response layouts must start
with different headers": a bug, fixed (layouts the same in one direction are one layout there)."""

from __future__ import annotations

import struct
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import DecodeError

SPEC = Path(__file__).parent / "specs" / "pixy2.yaml"
BLOCK = struct.Struct("<HHHHHhBB")


@pytest.fixture(scope="module")
def px(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("pixy2"), "pixy2")


def request(kind: int, payload: bytes = b"", checksum: bool = False) -> bytes:
    if checksum:
        return bytes([0xAF, 0xC1, kind, len(payload)]) + struct.pack("<H", sum(payload)) + payload
    return bytes([0xAE, 0xC1, kind, len(payload)]) + payload


def response(kind: int, payload: bytes) -> bytes:
    return bytes([0xAF, 0xC1, kind, len(payload)]) + struct.pack("<H", sum(payload) & 0xFFFF) + payload


@pytest.mark.parametrize(
    ("printed", "name", "fields"),
    [
        ("ae c1 0e 00", "GetVersionRequest", {}),  # the reference's bytes: 174 193 14 0
        ("ae c1 0c 01 00", "GetResolutionRequest", {}),
        ("ae c1 10 01 80", "SetCameraBrightnessRequest", {"brightness": 128}),
        ("ae c1 12 04 ff 01 00 00", "SetServosRequest", {"s0": 511, "s1": 0}),
        ("ae c1 14 03 ff 00 80", "SetLedRequest", {"r": 255, "g": 0, "b": 128}),
        ("ae c1 16 02 01 00", "SetLampRequest", {"upper": 1, "lower": 0}),
        ("ae c1 18 00", "GetFpsRequest", {}),
        ("ae c1 20 02 ff 05", "GetBlocksRequest", {"sigmap": 255, "max_blocks": 5}),
    ],
)
def test_the_references_requests(px: ModuleType, printed: str, name: str, fields: dict[str, int]) -> None:
    frame = bytes.fromhex(printed)
    message = getattr(px, name)(**fields)
    assert px.encode(message) == frame
    assert px.decode(frame, px.Direction.REQUEST) == message


def test_a_request_with_a_checksum(px: ModuleType) -> None:
    """AF C1 requests carry the payload's sum, as responses do: they decode as the same messages."""
    frame = request(0x20, b"\xff\x05", checksum=True)
    assert px.decode(frame, px.Direction.REQUEST) == px.GetBlocksRequest(sigmap=255, max_blocks=5)
    with pytest.raises(DecodeError, match="checksum"):
        px.decode(frame[:4] + b"\x00\x00" + frame[6:], px.Direction.REQUEST)


@settings(max_examples=examples(20), deadline=None)
@given(
    blocks=st.lists(
        st.tuples(
            st.integers(1, 255),
            st.integers(0, 315),
            st.integers(0, 207),
            st.integers(0, 316),
            st.integers(0, 208),
            st.integers(-180, 180),
            st.integers(0, 255),
            st.integers(0, 255),
        ),
        max_size=6,
    )
)
def test_blocks_match_the_references_layout(px: ModuleType, blocks: list[tuple[int, ...]]) -> None:
    golden = response(0x21, b"".join(BLOCK.pack(*block) for block in blocks))
    message = px.decode(golden, px.Direction.RESPONSE)
    assert [tuple(item.to_fields().values()) for item in message.blocks] == blocks
    assert px.encode(message) == golden


def test_version_result_and_error_replies(px: ModuleType) -> None:
    version = response(0x0F, struct.pack("<HBBH10s", 0x2200, 3, 0, 11, b"general\0\0\0"))
    assert px.decode(version, px.Direction.RESPONSE) == px.VersionResponse(0x2200, 3, 0, 11, "general")
    assert px.encode(px.decode(version, px.Direction.RESPONSE)) == version
    result = response(0x01, struct.pack("<i", 60))  # getFPS: 60 frames a second
    assert px.decode(result, px.Direction.RESPONSE) == px.ResultResponse(result=60)
    busy = response(0x03, b"\xfe")  # PIXY_RESULT_BUSY
    assert px.decode(busy, px.Direction.RESPONSE) == px.ErrorResponse(error=-2)
    parser = px.StreamParser(px.Direction.RESPONSE)
    assert parser.feed(b"\xaf\xc1" + version + result[:5]) == [px.VersionResponse(0x2200, 3, 0, 11, "general")]
    assert parser.feed(result[5:] + busy) == [px.ResultResponse(result=60), px.ErrorResponse(error=-2)]
