"""Victron VE.Direct HEX (tests/specs/vedirect_hex.yaml), written from the user docs alone. The frames are
Victron's own (the VE.Direct protocol FAQ: `:70010003E` asks for register 0x1000, `:7001000C80076` answers 200;
`:7FF0F0040` asks for the SOC, 0x0FFF) and the ping `:154`. (The brief's `:70001004E` for register 0x0100 is not a
valid frame: 0x55 - 7 - 0x00 - 0x01 - 0x00 is 0x4D.) PyPI's `vedirect`, `vedirect-m8` and `vedirect-jmfife` read
the TEXT protocol (label-TAB-value lines), not HEX; no peer there. Two gaps once, closed: the checksum (0x55 minus
the sum), a sum with a start value (`init`), and the command as ONE hex digit inside the hex-ASCII span (`type: u4`
on the command element)."""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType

import pytest

SPEC = Path(__file__).parent / "specs" / "vedirect_hex.yaml"
FAQ = [":70010003E", ":7FF0F0040", ":154"]


def victron_checksum(command: int, payload: bytes) -> int:
    """The FAQ's rule: start at 0x55, subtract the command and every byte, modulo 256."""
    return (0x55 - command - sum(payload)) & 0xFF


def test_the_faqs_frames_follow_the_faqs_rule() -> None:
    """The golden frames themselves: the checksum the FAQ's rule gives is the one printed (so the xfail below fails
    for the language, not for the frames)."""
    for text in [*FAQ, ":7001000C80076"]:
        command, rest = int(text[1], 16), bytes.fromhex(text[2:])
        assert victron_checksum(command, rest[:-1]) == rest[-1], text
    assert victron_checksum(7, bytes.fromhex("000100")) == 0x4D  # not the brief's 0x4E


@pytest.fixture(scope="module")
def vedirect(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    from conftest import generate_afresh

    return generate_afresh(SPEC, tmp_path_factory, "vedirect_hex")


def test_the_faqs_frames_decode_and_re_encode(vedirect: ModuleType) -> None:
    request = vedirect.decode(b":70010003E\n", vedirect.Direction.REQUEST)
    assert request == vedirect.GetRequest(register=0x1000, flags=0)
    assert vedirect.encode(request) == b":70010003E\n"
    reply = vedirect.decode(b":7001000C80076\n", vedirect.Direction.RESPONSE)
    assert reply.value == bytes.fromhex("c800")
    assert vedirect.encode(reply) == b":7001000C80076\n"
    assert vedirect.encode(vedirect.GetRequest(register=0x0FFF, flags=0)) == b":7FF0F0040\n"
    assert vedirect.encode(vedirect.PingRequest()) == b":154\n"
    assert vedirect.decode(b":7ff0f0040\n", vedirect.Direction.REQUEST).register == 0x0FFF  # lower case taken


@pytest.mark.parametrize(
    "frame",
    [b":70010003F\n", b":07001000" + b"3E\n", b":70010003\n", b":7G010003E\n"],
    ids=["checksum", "two-digit-command", "cut-short", "not-hex"],
)
def test_a_bad_frame_is_refused_in_one_line(vedirect: ModuleType, frame: bytes) -> None:
    from serialspec.runtime.errors import DecodeError

    with pytest.raises(DecodeError) as caught:
        vedirect.decode(frame, vedirect.Direction.REQUEST)
    assert "\n" not in str(caught.value)


def test_the_stream_parser_reads_the_faqs_frames_however_split(vedirect: ModuleType) -> None:
    stream = b"\x00:70010003E\n:7FF0F0040\nxx:154\n"
    for size in (1, 3, 7, len(stream)):
        parser = vedirect.StreamParser(vedirect.Direction.REQUEST)
        got = [m for i in range(0, len(stream), size) for m in parser.feed(stream[i : i + size])]
        assert [vedirect.encode(m) for m in got] == [b":70010003E\n", b":7FF0F0040\n", b":154\n"], size


def test_the_client_talks_to_the_simulator(vedirect: ModuleType) -> None:
    from conftest import simulated

    client_module = importlib.import_module("vedirect_hex.client")
    client_class = next(v for k, v in vars(client_module).items() if k.endswith("Client") and k != "ClientBase")
    with simulated("vedirect_hex") as path, client_class(path, timeout=2.0) as client:
        assert client.ping() == 0x4141  # the reply's one field, the version


@pytest.mark.parametrize(
    ("old", "new", "said"),
    [
        ("  transparency: {method: hex_ascii, span: [command, checksum]}\n", "", "must lie in a hex_ascii span"),
        (
            "{method: hex_ascii, span: [command, checksum]}",
            "{method: hex_ascii, span: [content, checksum]}",
            "lies in the transparency span, before the content",
        ),
        ("checksum: {role: checksum, type: u8,", "checksum: {role: checksum, type: u4,", "u4 is an address's"),
        ("{role: command, type: u4}", "{role: command, type: u4, range: [0, 16]}", "does not fit u4 (0..15)"),
        ("method: hex_ascii, span: [command, checksum]}\n", "method: cobs, span: [command, checksum]}\n", "not cobs"),
    ],
)
def test_a_u4_mistake_is_one_line(tmp_path: Path, old: str, new: str, said: str) -> None:
    from conftest import spec_error

    text = SPEC.read_text("utf-8").replace("end: {role: trailer, value: 0A}", 'end: {role: trailer, value: "00"}')
    assert old in text  # (a NUL trailer: COBS needs it, hex-ASCII takes it)
    assert said in spec_error(text.replace(old, new), tmp_path)


CHECKSUM_ONLY = """
protocol: vedirect_byte
title: VE.Direct HEX with the command as a whole byte (not the real frame), for its checksum
byte_order: little
serial: {baudrate: 19200}
framing:
  elements:
    start: {role: header, value: 3A}
    command: {role: command, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: sum, init: 0xAB, negate: true, covers: [command, content]}
    end: {role: trailer, value: 0A}
  transparency: {method: hex_ascii, span: [command, checksum]}
commands:
  get:
    code: 7
    request: {fields: {register: u16, flags: u8}}
    response: {fields: {register: u16, flags: u8, value: u16}}
"""


def test_a_sum_from_a_start_value_gives_victrons_checksums(tmp_path: Path) -> None:
    """The gap fixed: `init` on a sum (refused as an unknown key before). With the command as a whole byte (two
    digits: not Victron's frame, whose command is one digit) the checksums are the FAQ's: 3E for the request, 76
    for the reply, and 40 for the SOC request, whose bytes wrap past 0x55."""
    from conftest import generate_and_import

    path = tmp_path / "vedirect_byte.yaml"
    path.write_text(CHECKSUM_ONLY, "utf-8")
    module = generate_and_import(path, tmp_path / "out", "vedirect_byte")
    assert module.encode(module.GetRequest(register=0x1000, flags=0)) == b":07001000" + b"3E\n"
    assert module.encode(module.GetResponse(register=0x1000, flags=0, value=200)) == b":07001000C800" + b"76\n"
    assert module.encode(module.GetRequest(register=0x0FFF, flags=0)) == b":07FF0F00" + b"40\n"
    reply = module.decode(b":07001000C80076\n", module.Direction.RESPONSE)
    assert reply.value == 200
