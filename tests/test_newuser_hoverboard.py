"""The hoverboard firmware's USART frames (EFeru's hoverboard-firmware-hack-FOC: start word 0xABCD, steer and speed,
then `start ^ steer ^ speed`, every word a little-endian u16), written by a new user with `algorithm: xor` on a u16
checksum: the XOR of the words was taken big-endian whatever the element's byte order, so a little-endian checksum
was sent with its bytes swapped (a user had to write `endian: big` in a little-endian protocol). A bug, fixed: words
are taken in the checksum's byte order, so each byte sent is the XOR of the bytes at its place."""

from __future__ import annotations

import struct
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import ChecksumError

SPEC = """protocol: {name}
title: Hoverboard firmware USART
byte_order: {order}
serial: {{baudrate: 115200}}
framing:
  elements:
    start: {{role: header, value: "{start}"}}
    content: {{role: content}}
    checksum: {{role: checksum, type: u16, endian: {order}, algorithm: xor, covers: [start, content]}}
commands:
  command:
    request:
      fields: {{steer: i16, speed: i16}}
"""


def spec(tmp_path_factory: pytest.TempPathFactory, name: str, order: str, start: str) -> ModuleType:
    folder = tmp_path_factory.mktemp(name)
    path = folder / f"{name}.yaml"
    path.write_text(SPEC.format(name=name, order=order, start=start), "utf-8")
    return generate_and_import(path, folder / "out", name)


@pytest.fixture(scope="module")
def little(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return spec(tmp_path_factory, "hoverboard_le", "little", "CD AB")


@pytest.fixture(scope="module")
def big(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return spec(tmp_path_factory, "hoverboard_be", "big", "AB CD")


@settings(max_examples=examples(25), deadline=None)
@given(steer=st.integers(-1000, 1000), speed=st.integers(-1000, 1000))
def test_the_firmwares_checksum_in_either_byte_order(
    little: ModuleType, big: ModuleType, steer: int, speed: int
) -> None:
    checksum = 0xABCD ^ (steer & 0xFFFF) ^ (speed & 0xFFFF)
    for package, order in ((little, "<"), (big, ">")):
        golden = struct.pack(f"{order}HhhH", 0xABCD, steer, speed, checksum)
        message = package.CommandRequest(steer=steer, speed=speed)
        assert package.encode(message) == golden, order
        assert package.decode(golden, package.Direction.REQUEST) == message
        if golden[-1] != golden[-2]:  # the bytes swapped: the old reading of a little-endian one
            with pytest.raises(ChecksumError):
                package.decode(golden[:-2] + golden[-1:] + golden[-2:-1], package.Direction.REQUEST)


def test_the_reference_names_the_word_order(little: ModuleType, tmp_path: Path) -> None:
    docs = Path(little.__file__).parent.parent / "docs" / "hoverboard_le.md"
    assert "little-endian 16-bit words" in docs.read_text("utf-8")
