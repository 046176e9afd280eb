"""The Lynxmotion SSC-32 servo controller, tried by a new user from its manual: `#5P1600` (start, channel as the
address before the code, the pulse and a time glued to their letters, `#0P1500T1000`) is in the language; several
servos in one line (`#0P1500#1P900T1000`) and `QP 0` answered by one binary byte (pulse / 10) are strict xfails
naming the gaps. tests/specs/ssc32.yaml; the package is generated once."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

import pytest
from conftest import package_fixture, text_examples_round_trip
from serialspec.runtime.errors import DecodeError, RangeError

SPEC = Path(__file__).parent / "specs" / "ssc32.yaml"

ssc32 = package_fixture(SPEC, "ssc32")


def test_a_single_servo_move(ssc32: ModuleType) -> None:
    assert text_examples_round_trip(ssc32, SPEC, b"\r") == 3
    assert ssc32.decode(b"#0P1500T1000\r") == ssc32.MoveRequest(channel=0, pulse=1500, time=1000)
    assert ssc32.encode(ssc32.MoveRequest(channel=31, pulse=2500)) == b"#31P2500\r"
    with pytest.raises(RangeError, match="pulse = 3000 is outside its range 500..2500"):
        ssc32.encode(ssc32.MoveRequest(channel=0, pulse=3000))


def gap(reason: str) -> pytest.MarkDecorator:
    return pytest.mark.xfail(strict=True, raises=DecodeError, reason=f"language gap: {reason}")


@pytest.mark.parametrize(
    ("line", "direction"),
    [
        pytest.param(
            b"#0P1500#1P900T1000\r",
            None,
            marks=gap(
                "a line of repeated groups each opened by the start character (`#0P1500#1P900T1000`, a group "
                "move): a repeat is separated by the separator, and the start character ends no field"
            ),
            id="group move",
        ),
        pytest.param(
            b"QP 0\r",
            "request",
            marks=gap(
                "a text request answered by one binary byte (`QP 0` answered by the pulse width / 10: 0x96 for 1500 "
                "µs), and a request without the framing's start beside ones with it: a framing is text or binary "
                "for both directions, with one start"
            ),
            id="pulse query",
        ),
    ],
)
def test_what_the_language_cannot_say_yet(ssc32: ModuleType, line: bytes, direction: str | None) -> None:
    ssc32.decode(line, direction)
