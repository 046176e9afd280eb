"""The Lynxmotion Smart Servo (LSS) ASCII protocol, tried by a new user from the docs: `#5D1800` (start `#`, the
servo id, the command letters and the value glued, CR) and its query `#5QD` answered by `*5QD1800` (the replies'
own start). Written with each direction's start (`start: {request: "#", response: "*"}`), the id as every
message's address before the code (`framing.address: id`) and values glued to their codes (`text: {after_code:
""}`), each a gap closed here. The modifiers after a value (`#5D1800T1500`) are a strict xfail naming the gap.
tests/specs/lynxmotion_lss.yaml; the package is generated once."""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType

import pytest
from conftest import package_fixture, text_examples_round_trip
from serialspec.runtime.errors import DecodeError, RangeError

SPEC = Path(__file__).parent / "specs" / "lynxmotion_lss.yaml"

lss = package_fixture(SPEC, "lynxmotion_lss")


def test_the_documented_lines_decode_and_encode_byte_for_byte(lss: ModuleType) -> None:
    """Each example decodes, without its direction (the start says it), to its values and encodes back."""
    assert text_examples_round_trip(lss, SPEC, b"\r") == 7
    assert lss.decode(b"*5QD-150\r") == lss.QueryPositionResponse(id=5, position=-150)
    assert lss.encode(lss.MoveRequest(id=254, position=-900)) == b"#254D-900\r"
    assert lss.decode(b"*12Q6\r") == lss.QueryStatusResponse(id=12, status=6)  # Q beside QD: the longest code fits


def test_mistakes_are_refused_in_one_line(lss: ModuleType) -> None:
    with pytest.raises(RangeError, match="id = 300 is outside its range 0..254"):
        lss.encode(lss.MoveRequest(id=300, position=0))
    with pytest.raises(DecodeError, match=r"^text frame does not start with '#' \(a request\) or '\*'"):
        lss.decode(b"5QD\r")
    with pytest.raises(DecodeError, match=r"^text frame does not start with '#'"):
        lss.decode(b"*5QD1800\r", "request")
    with pytest.raises(DecodeError, match="QD: position = 'x' is not an integer"):
        lss.decode(b"*5QDx\r")


def test_a_client_moves_and_queries_the_simulated_servo(lss: ModuleType) -> None:
    """The generated client against the generated simulator in this process: a move gets no reply, the query is
    answered by the servo asked (its id echoed) with the position kept; the parser reads both directions."""
    simulator = importlib.import_module("lynxmotion_lss.simulator").SIMULATOR()
    path = simulator.start()
    try:
        with lss.Client(path) as client:
            assert client.move(5, -150) is None
            assert client.query_position(5, timeout=5) == lss.QueryPositionResponse(id=5, position=-150)
            assert client.query_status(7, timeout=5) == lss.QueryStatusResponse(id=7, status=6)
    finally:
        simulator.close()
    both = lss.StreamParser()
    assert both.feed(b"#5QD\r*5QD-150\r") == [
        lss.QueryPositionRequest(id=5),
        lss.QueryPositionResponse(id=5, position=-150),
    ]


def test_modifiers_glued_after_the_value(lss: ModuleType) -> None:
    """`#5D1800T1500` (a move in 1500 ms): labels glued to their values with nothing between (`text: {named: "",
    separator: ""}`), the position labelled with the code itself; a strict xfail until this was in the language."""
    timed = lss.decode(b"#5D1800T1500\r")
    assert timed == lss.MoveRequest(id=5, position=1800, time=1500)
    assert lss.encode(timed) == b"#5D1800T1500\r"
    assert lss.decode(b"#5D-50SD200\r") == lss.MoveRequest(id=5, position=-50, speed=200)
    with pytest.raises(DecodeError, match="unknown label"):
        lss.decode(b"#5D1800X3\r")
