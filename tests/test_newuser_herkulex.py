"""HerkuleX DRS-0101/0201 servos, all nine commands (tests/specs/herkulex_drs.yaml), written by a newcomer from the
user docs alone: the size counts the whole packet from its header (`counts: [header, data]`), checksum1 is a masked
XOR over size..data with the checksums inside left out, checksum2 an inverted masked XOR of checksum1, ACKs travel
under `reply_code: "code | 0x40"`. The manual's frames, and packets built by the rules pyherkulex 0.23 writes (its
send_data, checksum1, checksum2 and set_servo_position, ported here: the package on PyPI is Python 2 code, `print "…"`,
so it installs but cannot be imported as a peer), decode and re-encode byte for byte; the generated client drives the
generated simulator. tests/test_herkulex.py keeps the older subset spec and the reply code's error lines."""

from __future__ import annotations

import contextlib
import importlib
import io
from functools import reduce
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import, simulated
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.cli import main as serialspec_main
from serialspec.runtime.errors import ChecksumError

SPEC = Path(__file__).parent / "specs" / "herkulex_drs.yaml"


def send_data(data: list[int]) -> bytes:
    """pyherkulex's send_data: [size, pid, cmd, data...] with FF FF in front and the two checksums after the command."""
    checksum1 = reduce(lambda a, b: a ^ b, data, 0) & 0xFE
    return bytes([0xFF, 0xFF, *data[:3], checksum1, ~checksum1 & 0xFE, *data[3:]])


@pytest.fixture(scope="module")
def hx(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("herkulex_drs"), "herkulex_drs")


MANUAL = [  # (frame as the manual prints it, direction, class, fields)
    ("FF FF 07 FD 07 FC 02", "REQUEST", "StatRequest", {"pid": 0xFD}),
    ("FF FF 09 FD 47 F2 0C 00 40", "RESPONSE", "StatResponse", {"pid": 0xFD, "status_detail": 0x40}),
    ("FF FF 0A FD 03 A0 5E 34 01 60", "REQUEST", "RamWriteRequest", {"address": 52, "values": b"\x60"}),
    ("FF FF 09 FD 04 C4 3A 35 01", "REQUEST", "RamReadRequest", {"address": 53, "length": 1}),
    ("FF FF 0C FD 44 C2 3C 35 01 01 00 42", "RESPONSE", "RamReadResponse", {"values": b"\x01", "status_detail": 0x42}),
]


@pytest.mark.parametrize(("printed", "direction", "name", "fields"), MANUAL)
def test_the_manuals_frames(hx: ModuleType, printed: str, direction: str, name: str, fields: dict[str, object]) -> None:
    frame = bytes.fromhex(printed)
    message = hx.decode(frame, getattr(hx.Direction, direction))
    assert type(message).__name__ == name
    assert {k: getattr(message, k) for k in fields} == fields
    assert hx.encode(message) == frame
    assert type(hx.decode(frame)).__name__ == name  # the code alone says the direction (ACK = code | 0x40)


def test_pyherkulex_set_servo_position_is_an_i_jog(hx: ModuleType) -> None:
    """set_servo_position(0xFD, 512, 60, 0x04): [0x0C, id, I_JOG, lsb, msb, led, id, goaltime]."""
    frame = send_data([0x0C, 0xFD, 0x05, 0x00, 0x02, 0x04, 0xFD, 60])
    message = hx.decode(frame, hx.Direction.REQUEST)
    assert type(message).__name__ == "IJogRequest" and message.pid == 0xFD
    assert [(j.jog, j.set, j.id, j.playtime) for j in message.jogs] == [(512, 4, 0xFD, 60)]
    assert hx.encode(message) == frame


ITEMS = st.lists(st.tuples(st.integers(0, 0xFFFF), st.integers(0, 255), st.integers(0, 253)), max_size=8)


@settings(max_examples=examples(25), deadline=None)
@given(pid=st.integers(0, 254), playtime=st.integers(0, 255), items=ITEMS, data=st.binary(max_size=8))
def test_every_command_by_the_manuals_rules(
    hx: ModuleType, pid: int, playtime: int, items: list[tuple[int, int, int]], data: bytes
) -> None:
    jogs = [v for jog, s, i in items for v in (jog & 0xFF, jog >> 8, s, i)]
    cases = [
        (hx.EepWriteRequest(pid, 30, data), [0x01, 30, len(data), *data]),
        (hx.EepReadRequest(pid, 30, len(data)), [0x02, 30, len(data)]),
        (
            hx.SJogRequest(pid, playtime, [hx.SJogRequestJogsItem(j, s, i) for j, s, i in items]),
            [0x06, playtime, *jogs],
        ),
        (hx.RollbackRequest(pid, 1, 0), [0x08, 1, 0]),
        (hx.RebootRequest(pid), [0x09]),
        (hx.EepReadResponse(pid, 30, data, 0, 0x42), [0x42, 30, len(data), *data, 0, 0x42]),
        (hx.IJogResponse(pid, 0, 0x40), [0x45, 0, 0x40]),
    ]
    for message, body in cases:
        frame = send_data([7 + len(body) - 1, pid, *body])
        assert hx.encode(message) == frame, type(message).__name__
        assert hx.decode(frame) == message
    with pytest.raises(ChecksumError):
        hx.decode(frame[:5] + bytes([frame[5] ^ 0x02]) + frame[6:], hx.Direction.RESPONSE)
    with pytest.raises(ChecksumError):  # without a direction too (the README: ChecksumError for a bad checksum)
        hx.decode(frame[:5] + bytes([frame[5] ^ 0x02]) + frame[6:])


def test_the_client_drives_the_simulator(hx: ModuleType) -> None:
    client_module = importlib.import_module("herkulex_drs.client")
    with simulated("herkulex_drs") as path, client_module.HerkulexDrsClient(path, timeout=2) as servos:
        assert servos.stat(0xFD).status_error == 0
        servos.ram_write(0xFD, 53, b"\x05")
        assert servos.ram_read(0xFD, 53, 1).values == b"\x05"
        assert servos.ram_read(0xFD, 58, 2).values == (512).to_bytes(2, "little")
        assert servos.reboot(0xFD).status_error == 0


def test_sim_of_a_spec_without_a_device_says_what_to_add(tmp_path: Path) -> None:
    """The first spec a newcomer writes has no `device:`; `sim` said only that no simulator is generated."""
    spec = tmp_path / "herkulex_drs.yaml"
    spec.write_text(SPEC.read_text(encoding="utf-8").split("\ndevice:\n")[0] + "\n", encoding="utf-8")
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        assert serialspec_main(["sim", str(spec)]) == 1
    assert err.getvalue().splitlines() == [
        f"serialspec sim: {spec} has no `device:` section, so no simulator is generated: add one"
        " (`device: {}` answers each request with its response, every value 0 or its `default`;"
        " the tutorial's step 4 describes a device)"
    ]
    spec.write_text(spec.read_text(encoding="utf-8") + "device: {}\n", encoding="utf-8")
    from serialspec.lang import load_protocol

    assert load_protocol(str(spec)).device is not None  # the hint's spec is a valid one
