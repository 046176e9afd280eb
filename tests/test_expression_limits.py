"""Spec expressions cannot crash or exhaust the checker, the generator or a generated codec (issue 25, items 2 and 3).

Hypothesis draws expressions within the grammar's limits (any integers, the names of earlier fields, every operator
and function, any nesting) and puts each as a derived `value:` of a field of any integer type into the tiny spec.
The spec is either refused in one error line per mistake, or generated; then its decoder, fed random contents
under a correct checksum, raises DecodeError or nothing, its stream parser nothing, and its encoder EncodeError or
nothing. The cases of the issue are pinned below, and the ones that give a spec error are in tests/adversarial/.
"""

from __future__ import annotations

import contextlib
import re
from typing import Any

import pytest
from conftest import examples
from hostile_cases import drop, put
from hostile_run import outcome
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.backends.python.memory import imported
from serialspec.lang import expression
from serialspec.runtime.errors import DecodeError, EncodeError

LINE = re.compile(r"^tiny\.yaml:[1-9]\d*:[1-9]\d*: \S.*$")
NAMES = ("angle", "mode", "time")  # the move request's fields (i16, u8, u16) before the derived one
TYPES = {"u8": 1, "i8": 1, "u16": 2, "i16": 2, "u32": 4, "i32": 4}
OPERATORS = ("+", "-", "*", "/", "%", "&", "|", "<<", ">>")

leaves = (
    st.sampled_from(NAMES)
    | st.integers(-3, 80).map(str)
    | st.integers(-(2**70), 2**70).map(str)
    | st.sampled_from(["100000000", "65536", "0"])
)


def combine(children: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
    return (
        st.tuples(children, st.sampled_from(OPERATORS), children).map(lambda t: f"({t[0]} {t[1]} {t[2]})")
        | children.map(lambda a: f"~{a}")
        | children.map(lambda a: f"-{a}")
        | st.tuples(children, children).map(lambda t: f"ceil({t[0]} / {t[1]})")
        | st.tuples(st.sampled_from(["min", "max"]), st.lists(children, min_size=2, max_size=3)).map(
            lambda t: f"{t[0]}({', '.join(t[1])})"
        )
    )


EXPRESSIONS = st.recursive(leaves, combine, max_leaves=8).filter(lambda text: len(text) <= expression.MAX_TEXT)


def generate(value: str, type_name: str) -> tuple[list[str], dict[str, str]]:
    def mutate(data: dict[str, Any]) -> None:
        put("commands/move/request/fields/extra", {"type": type_name, "value": value})(data)
        drop("examples")(data)  # the example frame has no `extra`

    return outcome("tiny", mutate)


def exercise(files: dict[str, str], contents: list[bytes], moves: list[tuple[int, int, int]]) -> None:
    """Decode random contents of the move request, feed them to a stream parser, encode random moves."""
    modules = {path.partition("/")[2]: text for path, text in files.items() if path.startswith("tiny/")}
    with imported("tiny", modules) as package:
        for content in contents:
            body = bytes([1, 1, len(content)]) + content
            frame = b"\xaa\x55" + body + bytes([sum(body) & 0xFF])
            with contextlib.suppress(DecodeError):
                package.decode(frame, "request")
            package.StreamParser("request").feed(frame + frame)
        for angle, mode, time in moves:
            with contextlib.suppress(EncodeError):
                package.encode(package.messages.MoveRequest(id=1, angle=angle, mode=mode, time=time))


@settings(max_examples=examples(40), deadline=None, suppress_health_check=list(HealthCheck))
@given(
    EXPRESSIONS,
    st.sampled_from(sorted(TYPES)),
    st.lists(st.binary(min_size=9, max_size=9), min_size=1, max_size=6),
    st.lists(st.tuples(st.integers(-900, 900), st.integers(0, 1), st.integers(0, 65535)), max_size=4),
)
def test_any_expression_within_the_limits_raises_only_the_librarys_errors(
    text: str, type_name: str, contents: list[bytes], moves: list[tuple[int, int, int]]
) -> None:
    lines, files = generate(text, type_name)
    if lines:
        assert all(LINE.match(line) for line in lines), lines
        return
    size = 5 + TYPES[type_name]  # angle, mode, time, then the derived field: contents its decoder checks
    exercise(files, [bytes(size), *(c[:size] for c in contents)], [(0, 0, 0), *moves])


@pytest.mark.parametrize(
    ("value", "type_name", "said"),
    [
        ("300", "u8", "300 does not fit extra (u8, 0..255)"),
        ("1 << 100000000", "u8", "'1 << 100000000' is a number of more than 512 bits"),
        ("1 << (time * 100000000)", "u32", "'1 << (time * 100000000)' can exceed 512 bits"),
        ("time - 70000", "u16", "time - 70000 is always outside extra's 0..65535: it is -70000..-4465"),
        (" * ".join(["time"] * 1000), "u32", "an expression of 6997 characters is too long (at most 500)"),
        ("*".join(["time"] * 99), "u32", "is nested too deeply (at most 50 levels)"),  # a flat chain is deep too
        ("(" * 240 + "time" + ")" * 240, "u32", "is not an expression"),  # Python's parser: too many parentheses
        ("-" * 400 + "time", "u32", "is nested too deeply (at most 50 levels)"),
    ],
)
def test_expressions_refused_in_one_line(value: str, type_name: str, said: str) -> None:
    lines, _ = generate(value, type_name)
    assert len(lines) == 1 and LINE.match(lines[0]) and said in lines[0], lines


def test_a_divisor_of_zero_from_the_wire_is_a_decode_error() -> None:
    lines, files = generate("time / mode", "u32")
    assert lines == []
    modules = {path.partition("/")[2]: text for path, text in files.items() if path.startswith("tiny/")}
    with imported("tiny", modules) as package:
        body = bytes([1, 1, 9]) + bytes([0, 0, 0, 5, 0, 0, 0, 0, 0])  # angle 0, mode 0, time 5, extra 0
        frame = b"\xaa\x55" + body + bytes([sum(body) & 0xFF])
        with pytest.raises(DecodeError, match="extra: time / mode has no value here"):
            package.decode(frame, "request")
        with pytest.raises(EncodeError):
            package.encode(package.messages.MoveRequest(id=1, angle=0, mode=0, time=5))


@settings(max_examples=examples(50), deadline=None)
@given(EXPRESSIONS)
def test_an_expression_is_shown_as_it_reads(text: str) -> None:
    """What docs and error lines show of an expression reads back as the same expression, a minus sign as one."""
    try:
        parsed = expression.parse(text)
    except expression.ExpressionError:
        return
    shown = expression.show(parsed)
    assert expression.parse(shown) == parsed, shown
    assert "(0 - " not in shown, shown


def test_a_minus_sign_is_shown_as_written() -> None:
    assert expression.show(expression.parse("-200 + n")) == "-200 + n"
    assert expression.show(expression.parse("-(a + b) * 2")) == "-(a + b) * 2"
