"""Marlin / RepRap G-code over serial, tried by a new user from the docs: numbered lines `N123 G1 X10.5 Y-3*45`
checked by the XOR of every character before `*`, written in decimal (`checksum: {format: decimal}`), the line
number glued to its `N` (a message found by its code alone: `text: {after_code: ""}`), and replies without a
checksum (`checksum: {directions: [request]}`): `ok`, `ok T:201.3 /202.0 B:117.0 /0.0`, `Resend: 124`,
`Error:checksum mismatch, Last Line: 122`. tests/specs/marlin.yaml; the package is generated once."""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType

import pytest
from conftest import package_fixture, text_examples_round_trip
from serialspec.runtime.errors import ChecksumError, DeviceError

SPEC = Path(__file__).parent / "specs" / "marlin.yaml"

marlin = package_fixture(SPEC, "marlin")


def test_the_documented_lines_decode_and_encode_byte_for_byte(marlin: ModuleType) -> None:
    """Each example: its printed line decodes to the documented values and encodes back to the same characters."""
    assert text_examples_round_trip(marlin, SPEC, b"\n") == 6
    move = marlin.decode(b"N123 G1 X10.5 Y-3*45\n")
    assert (move.number, move.command, [w.word for w in move.words]) == (123, "G1", ["X10.5", "Y-3"])
    built = marlin.LineRequest(number=0, command="M106")
    assert marlin.encode(built) == b"N0 M106*36\n"  # the checksum computed, in decimal


def test_a_damaged_line_is_refused_by_its_checksum(marlin: ModuleType) -> None:
    """`N123 G1 X10.5 Y-3*71` (the figure the task brief gave) does not check: its characters XOR to 45."""
    with pytest.raises(ChecksumError, match="^bad checksum: the frame has 71, its text gives 45$"):
        marlin.decode(b"N123 G1 X10.5 Y-3*71\n")
    with pytest.raises(ChecksumError, match="not a decimal number"):
        marlin.decode(b"N123 G1 X10.5 Y-3*2D\n")  # hex, as NMEA writes it


def test_the_firmware_s_replies(marlin: ModuleType) -> None:
    """What Marlin answers a damaged line with, in one stream: the error, the line to send again, then ok; replies
    carry no checksum, so a `*` in one is text."""
    parser = marlin.StreamParser("response")
    error, resend, ok = parser.feed(b"Error:checksum mismatch, Last Line: 122\nResend: 123\nok\n")
    assert error.message == "checksum mismatch, Last Line: 122"  # one text to the end of the line (`size: rest`)
    assert marlin.encode(error) == b"Error:checksum mismatch, Last Line: 122\n"
    assert (resend.number, ok) == (123, marlin.OkResponse())
    report = marlin.decode(b"ok T:201.3 /202.0 B:117.0 /0.0\n")
    assert [r.item for r in report.report] == ["T:201.3", "/202.0", "B:117.0", "/0.0"]
    assert marlin.encode(report) == b"ok T:201.3 /202.0 B:117.0 /0.0\n"  # no checksum written on a reply
    starred = marlin.decode(b"echo:Unknown command: M999*\n")
    assert starred.message == "Unknown command: M999*"


def test_a_client_sends_numbered_lines_to_the_simulated_printer(marlin: ModuleType) -> None:
    """The generated client against the generated simulator (in this process): a numbered line gets `ok`; a
    refusal in its place is a DeviceError."""
    from pty_pair import answering_line

    simulator = importlib.import_module("marlin.simulator").SIMULATOR()
    path = simulator.start()
    try:
        with marlin.Client(path) as client:
            assert client.line(number=1, command="G28", timeout=5) == marlin.OkResponse()
    finally:
        simulator.close()
    with (
        answering_line(b"N2 M107*39\n", b"Error:checksum mismatch, Last Line: 1\nResend: 2\nok\n") as path,
        marlin.Client(path) as client,
        pytest.raises(DeviceError, match="the device refused it"),
    ):
        client.line(number=2, command="M107", timeout=5)
