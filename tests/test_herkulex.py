"""HerkuleX servos (tests/specs/herkulex.yaml): a reply code computed from the request code (`reply_code: code |
0x40` on the command element), a masked XOR checksum and a checksum of that checksum. The manual's frames, and frames
built by an independent implementation of the manual's rules, decode and re-encode byte for byte; decode tells a
request from an ACK by its code alone; `serialspec sim` answers the generated client and raw manual requests."""

from __future__ import annotations

import contextlib
import importlib
import io
import json
import os
from functools import reduce
from pathlib import Path
from types import ModuleType

import pytest
from conftest import generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.cli import main as serialspec_main
from serialspec.lang import SpecErrors, load_protocol
from serialspec.runtime.errors import DecodeError
from sim_process import serve

SPEC = Path(__file__).parent / "specs" / "herkulex.yaml"


def packet(pid: int, cmd: int, data: bytes = b"") -> bytes:
    """A HerkuleX packet by the manual's rules: FF FF, size, pID, CMD, checksum1, checksum2, data."""
    size = 7 + len(data)
    checksum1 = reduce(lambda a, b: a ^ b, data, size ^ pid ^ cmd) & 0xFE
    checksum2 = ~checksum1 & 0xFE
    return bytes([0xFF, 0xFF, size, pid, cmd, checksum1, checksum2]) + data


@pytest.fixture(scope="module")
def hx(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("herkulex"), "herkulex")


MANUAL = [  # (frame as the manual prints it, direction, class, fields)
    ("FF FF 07 FD 07 FC 02", "request", "StatRequest", {"pid": 0xFD}),
    ("FF FF 09 FD 47 F2 0C 00 40", "response", "StatResponse", {"pid": 0xFD, "status_error": 0, "status_detail": 0x40}),
    ("FF FF 0A FD 03 A0 5E 34 01 60", "request", "RamWriteRequest", {"pid": 0xFD, "address": 52, "data": b"\x60"}),
    ("FF FF 09 FD 04 C4 3A 35 01", "request", "RamReadRequest", {"pid": 0xFD, "address": 53, "length": 1}),
    (
        "FF FF 0C FD 44 C2 3C 35 01 01 00 42",
        "response",
        "RamReadResponse",
        {"pid": 0xFD, "address": 53, "data": b"\x01", "status_error": 0, "status_detail": 0x42},
    ),
]


@pytest.mark.parametrize(("printed", "direction", "name", "fields"), MANUAL)
def test_the_manuals_frames(hx: ModuleType, printed: str, direction: str, name: str, fields: dict[str, object]) -> None:
    frame = bytes.fromhex(printed)
    cls = getattr(hx, name)
    request_code = {"Stat": 0x07, "RamWrite": 0x03, "RamRead": 0x04}[name.removesuffix(direction.capitalize())]
    code = request_code | 0x40 if direction == "response" else request_code
    assert frame == packet(0xFD, code, frame[7:])  # the independent rules agree with the manual
    decoded = hx.decode(frame, direction)
    assert type(decoded) is cls
    assert {k: getattr(decoded, k) for k in fields} == fields
    assert hx.encode(decoded) == frame
    assert type(hx.decode(frame)) is cls  # without the direction: the code tells a request from an ACK


@settings(max_examples=60, deadline=None)
@given(pid=st.integers(0, 253), address=st.integers(0, 255), data=st.binary(min_size=1, max_size=40))
def test_random_frames_match_the_manuals_rules(hx: ModuleType, pid: int, address: int, data: bytes) -> None:
    write = hx.RamWriteRequest(pid=pid, address=address, data=data)
    assert hx.encode(write) == packet(pid, 0x03, bytes([address, len(data)]) + data)
    ack = hx.RamReadResponse(pid=pid, address=address, data=data, status_error=0, status_detail=3)
    wire = packet(pid, 0x44, bytes([address, len(data)]) + data + b"\x00\x03")
    assert hx.encode(ack) == wire and hx.decode(wire) == ack
    parser = hx.StreamParser("response")
    assert [m for byte in b"\xff" + wire + wire[:5] for m in parser.feed(bytes([byte]))] == [ack]


def test_an_ack_under_the_request_code_is_refused(hx: ModuleType) -> None:
    with pytest.raises(DecodeError, match="0x07"):
        hx.decode(packet(0xFD, 0x07, b"\x00\x40"), "response")


def test_decode_without_direction_at_the_cli() -> None:
    for printed, direction, _, _ in MANUAL:
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            assert serialspec_main(["decode", str(SPEC), printed, "--json"]) == 0
        assert json.loads(out.getvalue())["direction"] == direction


def test_the_reference_shows_the_reply_code(hx: ModuleType, tmp_path: Path) -> None:
    assert serialspec_main(["generate", str(SPEC), "--out", str(tmp_path)]) == 0
    docs = (tmp_path / "docs" / "herkulex.md").read_text("utf-8")
    assert "0x07, reply 0x47" in docs and "as `code \\| 0x40`" in docs and "decoding tries both directions" in docs


def test_the_simulator_answers_the_client_and_raw_requests(hx: ModuleType) -> None:
    client_module = importlib.import_module("herkulex.client")
    with serve(str(SPEC), 0xFD, 3) as path:
        with client_module.HerkulexClient(path, timeout=1.0) as servos:
            assert servos.stat(0xFD).status_error == 0
            servos.ram_write(3, 53, b"\x05")
            reply = servos.ram_read(3, 53, 1)
            assert (reply.pid, reply.address, reply.data) == (3, 53, b"\x05")
            assert servos.ram_read(0xFD, 58, 2).data == (512).to_bytes(2, "little")
        fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
        try:
            os.write(fd, bytes.fromhex("FF FF 09 FD 04 C4 3A 35 01"))  # the manual's RAM_READ of the LED register
            answer = b""
            while len(answer) < 12:
                answer += os.read(fd, 64)
            assert answer == packet(0xFD, 0x44, bytes([53, 1, 0, 0, 0]))
        finally:
            os.close(fd)


@pytest.mark.parametrize(
    ("change", "said"),
    [
        (('reply_code: "code | 0x40"', 'reply_code: "code | pid"'), "an expression of `code`"),
        (
            ('reply_code: "code | 0x40"', 'reply_code: "code + 0xF9"'),
            "stat.code: its reply code 256 (code + 0xF9) does not",
        ),
        (
            ("      mask: 0xFE\n      covers: [size", "      reply_code: code\n      mask: 0xFE\n      covers: [size"),
            ("`reply_code` goes on the command element"),
        ),
        # (ram_read under 0x47 would share its reply code with stat's: replies of 4 bytes or more and of 2, told
        # apart by their size, as SPS30's measured values are; tests/test_newuser_shdlc.py refuses a tie)
    ],
)
def test_mistakes_in_a_reply_code(tmp_path: Path, change: tuple[str, str], said: str) -> None:
    text = SPEC.read_text("utf-8")
    assert change[0] in text
    spec = tmp_path / "herkulex.yaml"
    spec.write_text(text.replace(change[0], change[1], 1), encoding="utf-8")
    with pytest.raises(SpecErrors) as raised:
        load_protocol(str(spec))
    lines = str(raised.value).splitlines()
    assert any(said in line for line in lines), lines
    assert len(lines) == 1 and lines[0].split(":")[0].endswith("herkulex.yaml"), lines


def test_tshark_shows_the_frames_as_decode_does(tmp_path: Path) -> None:
    """The Wireshark dissector reads requests and ACKs by their own codes, both checksums verified."""
    from test_wireshark import TSHARK, through_tshark

    if TSHARK is None:
        pytest.skip("tshark is not installed")
    through_tshark(tmp_path, [SPEC.read_text("utf-8")])
