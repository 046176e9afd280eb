"""The ODrive ASCII protocol (firmware 0.5), tried by a new user from the docs: setpoints `p 0 -2 0 0` with no
reply, `f 0` and `r vbus_voltage` answered by their values alone (`values_only`), an optional checksum in decimal
(`checksum: {format: decimal, required: false}`) that the documented example `r vbus_voltage *93` writes after a
space (`separated: [request]`), and a line sent without its checksum encoded again without it.
tests/specs/odrive_v05.yaml; the package is generated once."""

from __future__ import annotations

import importlib
from decimal import Decimal
from pathlib import Path
from types import ModuleType

import pytest
from conftest import package_fixture, text_examples_round_trip
from serialspec.runtime.errors import ChecksumError

SPEC = Path(__file__).parent / "specs" / "odrive_v05.yaml"

odrive = package_fixture(SPEC, "odrive_v05")


def test_the_documented_lines_decode_and_encode_byte_for_byte(odrive: ModuleType) -> None:
    """Each documented example decodes to its values and encodes back to the same characters: with the checksum
    after a space where the docs print one, without a checksum where they print none."""
    assert text_examples_round_trip(odrive, SPEC, b"\n", "request") == 5
    assert odrive.decode(b"q 0 -2 1 0.1\n").torque_lim == Decimal("0.1")  # `q` names the request alone


def test_the_checksum(odrive: ModuleType) -> None:
    """A request built here carries the checksum the docs show; the XOR covers the space before `*`; a wrong one
    is refused; the firmware's own form, without the space, is read too."""
    assert odrive.encode(odrive.ReadRequest(property="vbus_voltage")) == b"r vbus_voltage *93\n"
    assert odrive.decode(b"r vbus_voltage*125\n") == odrive.ReadRequest(property="vbus_voltage")
    with pytest.raises(ChecksumError, match="^bad checksum: the frame has 92, its text gives 93$"):
        odrive.decode(b"r vbus_voltage *92\n")
    moved = odrive.decode(b"w axis0.controller.config.vel_limit 20\n")
    assert (moved.property, moved.value) == ("axis0.controller.config.vel_limit", 20)


def test_replies_of_values_alone(odrive: ModuleType) -> None:
    """`f 0` is answered by `pos vel`, `r ...` by the value, with a checksum (no space) when the request had one."""
    asked = odrive.FeedbackRequest(motor=0)
    reply = odrive.decode(b"0.500000 -1.250000\n", "response", request=asked)
    assert (reply.position, reply.velocity) == (Decimal("0.5"), Decimal("-1.25"))
    value = odrive.decode(b"24.1*25\n", "response", request=odrive.ReadRequest(property="vbus_voltage"))
    assert value.value == Decimal("24.1") and odrive.encode(value) == b"24.1*25\n"
    parser = odrive.StreamParser()  # both directions, as a monitor sees them
    assert parser.feed(b"r vbus_voltage *93\n24.1*25\n") == [odrive.ReadRequest(property="vbus_voltage"), value]


def test_a_client_drives_the_simulated_odrive(odrive: ModuleType) -> None:
    """The generated client against the generated simulator, in this process: setpoints get no reply and are kept;
    feedback and reads come back as values alone."""
    simulator = importlib.import_module("odrive_v05.simulator").SIMULATOR()
    path = simulator.start()
    try:
        with odrive.Client(path) as client:
            assert client.position(0, 2.5) is None
            assert client.velocity(0, -1.25) is None
            feedback = client.feedback(0, timeout=5)
            assert (feedback.position, feedback.velocity) == (2.5, -1.25)
            assert client.read_("vbus_voltage", timeout=5).value == Decimal("24.1")  # `read` is the client's own
            client.write("axis0.controller.config.vel_limit", 20)
    finally:
        simulator.close()


def test_the_simulated_odrive_answers_with_a_checksum_only_when_asked_with_one(odrive: ModuleType) -> None:
    """The docs: a line that ends with a checksum is answered with one; a line without one, without one (a driver
    that sends none would read `24.1*25` as the value)."""
    simulator = importlib.import_module("odrive_v05.simulator").SIMULATOR()
    asked = odrive.ReadRequest(property="vbus_voltage")
    try:
        assert [reply for _, reply in simulator.feed(b"r vbus_voltage\n")] == [b"24.100000\n"]
        (checked,) = [reply for _, reply in simulator.feed(b"r vbus_voltage *93\n")]
        assert checked.startswith(b"24.100000*")
        assert odrive.decode(checked, "response", request=asked).value == Decimal("24.1")
    finally:
        simulator.close()
