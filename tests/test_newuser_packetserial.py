"""PacketSerial (COBS-framed packets, tests/specs/packetserial.yaml), written from the user docs alone and checked
against the `cobs` package from PyPI: its encoder's frames are ours byte for byte (runs of 254 non-zero bytes and
more included), we decode what it encodes, `serialspec sim` answers packets the peer builds over a pseudo-terminal,
and the generated client talks to the sim."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

import pytest
import serial
from cobs import cobs
from conftest import generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from sim_process import serve

SPEC = Path(__file__).parent / "specs" / "packetserial.yaml"


@pytest.fixture(scope="module")
def ps(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("packetserial"), "packetserial")


def peer_frame(plain: bytes) -> bytes:
    """A PacketSerial packet as the peer sends it: COBS, then the 00 delimiter."""
    return bytes(cobs.encode(plain)) + b"\x00"


PAYLOADS = [
    b"",
    b"\x00",
    b"\x00\x00",
    b"\x11" * 252,
    b"\x11" * 254,
    b"\x11" * 300,
    b"\x00" + b"\x22" * 254 + b"\x00",
    bytes(range(256)) * 2,
]


def last_run_is_254(plain: bytes) -> bool:
    """The one place the `cobs` package and PacketSerial write different (both valid) COBS: a span ending with a
    run of 254 non-zero bytes, which PacketSerial follows with the code byte 01 and the package does not."""
    tail = plain.rsplit(b"\x00", 1)[-1]
    return len(tail) % 254 == 0 and len(tail) > 0


@pytest.mark.parametrize("data", PAYLOADS, ids=[f"{len(p)}B" for p in PAYLOADS])
def test_echo_frames_match_the_peer_byte_for_byte(ps: ModuleType, data: bytes) -> None:
    golden = peer_frame(b"\x01" + data)
    assert ps.encode(ps.EchoRequest(data=data)) == golden
    assert ps.decode(golden, ps.Direction.REQUEST) == ps.EchoRequest(data=data)


@settings(max_examples=200, deadline=None)
@given(data=st.binary(max_size=700) | st.binary(min_size=253, max_size=253).map(lambda b: b.replace(b"\x00", b"\x01")))
def test_any_payload_round_trips_with_the_peer(ps: ModuleType, data: bytes) -> None:
    plain = b"\x01" + data
    golden = peer_frame(plain)
    ours = ps.encode(ps.EchoRequest(data=data))
    assert ps.decode(golden, ps.Direction.REQUEST).data == data  # the peer's form always decodes
    assert bytes(cobs.decode(ours[:-1])) == plain  # and the peer decodes ours
    if not last_run_is_254(plain):
        assert ours == golden


def test_a_last_run_of_254_re_encodes_as_the_peer_wrote_it(ps: ModuleType, tmp_path: Path) -> None:
    """PacketSerial's form (the code byte 01 after a last run of 254) by default; `code_after_full_run: false` writes
    the `cobs` package's form, so a frame that peer made re-encodes byte for byte."""
    golden = peer_frame(b"\x01" + b"\x11" * 253)
    assert ps.encode(ps.decode(golden, ps.Direction.REQUEST)) == golden[:-1] + b"\x01\x00"
    text = SPEC.read_text("utf-8").replace("protocol: packetserial", "protocol: packetserial_cobs")
    text = text.replace("span: [command, content]", "span: [command, content]\n    code_after_full_run: false")
    assert "code_after_full_run" in text and "packetserial_cobs" in text
    (tmp_path / "spec").mkdir()
    spec = tmp_path / "spec" / "packetserial.yaml"
    spec.write_text(text, "utf-8")
    peer_form = generate_and_import(spec, tmp_path / "out", "packetserial_cobs")
    for plain in (b"\x01" + b"\x11" * 253, b"\x01" + b"\x22" * 507, b"\x01\x00" + b"\x33" * 254, b"\x01"):
        golden = peer_frame(plain)
        assert peer_form.encode(peer_form.decode(golden, peer_form.Direction.REQUEST)) == golden


def test_the_docs_say_which_cobs_form_encode_writes() -> None:
    docs = (Path(__file__).parent.parent / "docs" / "language.md").read_text("utf-8")
    assert "A span that ends with a run of 254 non-zero bytes is written with the code byte 01 after it" in docs
    assert "`code_after_full_run: false`: the `cobs` package on PyPI" in docs


@settings(max_examples=100, deadline=None)
@given(
    levels=st.lists(st.tuples(st.integers(0, 7), st.integers(0, 1000)), min_size=1, max_size=6),
    cuts=st.lists(st.integers(1, 8), max_size=40),
)
def test_the_stream_parser_reads_peer_frames_however_split(
    ps: ModuleType, levels: list[tuple[int, int]], cuts: list[int]
) -> None:
    stream = b"".join(peer_frame(bytes([2, output]) + level.to_bytes(2, "little")) for output, level in levels)
    parser = ps.StreamParser(ps.Direction.REQUEST)
    got, at = [], 0
    for cut in cuts:
        got += parser.feed(stream[at : at + cut])
        at += cut
    got += parser.feed(stream[at:])
    assert got == [ps.SetLevelRequest(output=o, level=v) for o, v in levels]


def exchange(port: serial.Serial, plain: bytes) -> bytes:
    """The peer's side: send a packet, read up to the delimiter, COBS-decode it."""
    port.write(peer_frame(plain))
    reply = port.read_until(b"\x00")
    assert reply.endswith(b"\x00"), reply
    return bytes(cobs.decode(reply[:-1]))


def test_the_sim_answers_packets_the_peer_builds() -> None:
    with serve(str(SPEC)) as path, serial.Serial(path, 115200, timeout=5) as port:
        assert exchange(port, b"\x01" + b"\x00" * 3 + b"\x33" * 260) == b"\x01" + b"\x00" * 3 + b"\x33" * 260
        assert exchange(port, bytes([2, 5]) + (700).to_bytes(2, "little")) == bytes([2, 5]) + (700).to_bytes(
            2, "little"
        )
        assert exchange(port, bytes([3, 5])) == bytes([3, 5]) + (700).to_bytes(2, "little")


def test_the_generated_client_against_the_sim(ps: ModuleType) -> None:
    import importlib

    client_module = importlib.import_module("packetserial.client")
    with serve(str(SPEC)) as path, client_module.PacketserialClient(path) as board:
        assert board.set_level(1, 256) == 256  # the level the board reports back
        assert board.read_level(1) == 256
        with pytest.raises(Exception, match="outside its range"):
            board.set_level(1, 1001)


def test_a_reply_that_disagrees_with_the_request_is_not_taken_for_an_ack(ps: ModuleType, tmp_path: Path) -> None:
    """A reply field named like a request field is not dropped: the level the board reports (its `reports`) is
    what set_level returns, and a field the spec says the reply repeats (`echoes`) is checked against the request."""
    import importlib

    from serialspec.runtime.errors import EchoMismatch

    text = SPEC.read_text("utf-8").replace(
        "set_level: {stores: {level: level}, reports: {level: level}, echoes: [output]}",
        "set_level: {stores: {level: level}, reports: {level: level + 1}, echoes: [output]}",
    )
    assert "level + 1" in text
    spec = tmp_path / "packetserial.yaml"
    spec.write_text(text, "utf-8")  # a board that answers SET LEVEL 256 with level 257
    with serve(str(spec)) as path, serial.Serial(path, 115200, timeout=5) as port:
        assert exchange(port, bytes([2, 1]) + (256).to_bytes(2, "little")) == bytes([2, 1]) + (257).to_bytes(
            2, "little"
        )
    client_module = importlib.import_module("packetserial.client")
    with serve(str(spec)) as path, client_module.PacketserialClient(path) as board:
        assert board.set_level(1, 256) == 257
    # a board that answers for another output than the one the request named
    other = SPEC.read_text("utf-8").replace(
        "set_level: {stores: {level: level}, reports: {level: level}, echoes: [output]}",
        'set_level: {stores: {level: level}, reports: {level: level, output: "7"}}',
    )
    assert 'output: "7"' in other
    spec.write_text(other, "utf-8")
    with serve(str(spec)) as path, client_module.PacketserialClient(path) as board:
        with pytest.raises(EchoMismatch, match=r"^set_level: the reply's output is 7, not the 1 sent$"):
            board.set_level(1, 256)
        assert board.read_level(1) == 256  # the bus stays usable
