"""Hypothesis fuzz of `serialspec decode` and `serialspec encode`, in-process, for every protocol: whatever the input,
an exit code of 0 or 1 and at most one line per input on stderr, never a traceback."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import pytest
from conftest import ALL, ROOT, Generated, a_request, encode, examples
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from serialspec.cli import main

SETTINGS = settings(
    max_examples=examples(75), deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


def spec_of(g: Generated) -> str:
    return str(Path(ROOT) / g.protocol.spec_path)


def frames(g: Generated) -> st.SearchStrategy[bytes]:
    """Random bytes, and frames that start like the protocol's (its header) so decoding gets past the first check."""
    headers = [layout.header for layout in g.protocol.framing.layouts.values()]
    return st.one_of(
        st.binary(max_size=40),
        st.tuples(st.sampled_from(headers), st.binary(max_size=40)).map(lambda t: t[0] + t[1]),
        st.sampled_from([e.frame for e in g.protocol.examples] or [b""]).flatmap(
            lambda f: (
                st.integers(0, max(len(f) - 1, 0)).map(lambda i: f[:i] + bytes([(f[i] + 1) & 0xFF]) + f[i + 1 :])
                if f
                else st.just(f)
            )
        ),
    )


@pytest.mark.parametrize("g", ALL, ids=[g.protocol.name for g in ALL])
def test_decode_never_fails_with_a_traceback(g: Generated) -> None:
    spec = spec_of(g)

    @SETTINGS
    @given(frame=frames(g), direction=st.sampled_from([None, "request", "response"]), spaced=st.booleans())
    def check(frame: bytes, direction: str | None, spaced: bool) -> None:
        text = frame.hex(" ") if spaced else frame.hex()
        argv = ["decode", spec, text or "00", *(["--direction", direction] if direction else []), "--json"]
        code, out, err = run(*argv)
        assert code in (0, 1)
        assert len(err.splitlines()) == (1 if code else 0), err
        if code == 0:
            assert json.loads(out)["hex"]

    check()


JSON_LEAVES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**30), 10**30),
    st.integers(-300, 300),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.sampled_from(["", "00 01", "zz", "ff" * 300]),
)
JSON_VALUES = st.recursive(
    JSON_LEAVES,
    lambda children: st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=6), children, max_size=4),
    max_leaves=12,
)


def hostile_fields(g: Generated) -> st.SearchStrategy[dict[str, Any]]:
    """A command's own field names with any JSON values (so the values, not just unknown keys, are exercised)."""

    @st.composite
    def build(draw: st.DrawFn) -> dict[str, Any]:
        message = draw(st.sampled_from(g.protocol.messages()))
        names = [f.name for f in message.fields] + [
            e.name for e in g.protocol.framing.layouts[message.direction].value_elements
        ]
        fields = {name: draw(JSON_VALUES) for name in names if draw(st.booleans())}
        return {
            "command": message.command,
            "subcommand": message.subcommand,
            "direction": message.direction.value,
            "fields": fields,
        }

    return build()


def requests_by_message(g: Generated) -> dict[tuple[str, str | None, str], list[str]]:
    """`--request HEX` for each reply read with its request (conftest.a_request), by (command, subcommand,
    direction); drawn before the fuzzer runs (a_request may search with hypothesis)."""
    found = {}
    for spec in g.protocol.messages():
        if (request := a_request(g, spec)) is not None:
            found[(spec.command, spec.subcommand, spec.direction.value)] = ["--request", encode(g, request).hex(" ")]
    return found


@pytest.mark.parametrize("g", ALL, ids=[g.protocol.name for g in ALL])
def test_encode_never_fails_with_a_traceback(g: Generated) -> None:
    spec = spec_of(g)
    requests = requests_by_message(g)

    @SETTINGS
    @given(obj=st.one_of(hostile_fields(g), JSON_VALUES))
    # a bit list (Modbus coils) that is not a list: was a TypeError from the generated from_fields
    @example(
        obj={"command": "read_coils", "subcommand": None, "direction": "response", "fields": {"coils": None, "unit": 0}}
    )
    @example(
        obj={
            "command": "read_coils",
            "subcommand": None,
            "direction": "response",
            "fields": {"coils": [1, "x"], "unit": 0},
        }
    )
    def check(obj: Any) -> None:
        # a reply made and read with its request: --request HEX both ways
        key = (obj.get("command"), obj.get("subcommand"), obj.get("direction")) if isinstance(obj, dict) else None
        asked = requests.get(key, []) if isinstance(key, tuple) and all(isinstance(k, str | None) for k in key) else []
        code, out, err = run("encode", spec, "--json=" + json.dumps(obj), *asked)
        assert code in (0, 1)
        assert len(err.splitlines()) == (1 if code else 0), err
        if code == 0:  # what encodes decodes back to the same values
            decoded = json.loads(run("decode", spec, out.strip(), "--direction", obj["direction"], "--json", *asked)[1])
            assert decoded["command"] == obj["command"]

    check()


@pytest.mark.parametrize(
    ("value", "words"),
    [
        ("true", "must be"),
        ("1.5", "must be an integer, got 1.5"),
        ("NaN", "must be an integer, got nan"),
        ("-Infinity", "must be an integer, got -inf"),
        ('"12"', "must be an integer, got '12'"),
        ("[1, [2, [3]]]", "must be an integer, got [1, [2, [3]]]"),
        ("9" * 5000, "--json cannot be read"),
        ("[" * 50000 + "]" * 50000, "--json cannot be read"),
        ("1" + "0" * 200, "a number of about 201 digits is outside its range"),
    ],
)
def test_strict_encode_at_the_cli(value: str, words: str) -> None:
    spec = str(ROOT / "specs" / "fashionstar_uart.yaml")
    obj = '{"command": "rotate", "fields": {"servo_id": 1, "interval": 5, "angle": ' + value + "}}"
    code, out, err = run("encode", spec, "--json", obj)
    assert (code, out) == (1, "")
    assert len(err.splitlines()) == 1 and words in err, err
    assert "angle" in err or "--json" in err


def test_a_binary_file_as_a_capture_is_one_line_naming_its_line(tmp_path: Path) -> None:
    """Bytes that are not UTF-8 as a capture: `decode --file`, `replay` and `export` (and `plot`) refuse the line that
    holds them (export raised UnicodeDecodeError; replay said only "'utf-8' codec can't decode")."""
    capture = tmp_path / "junk.capture"
    capture.write_bytes(b"# serialspec capture: feetech_sms\n\x9b\xff\x1b[2J\x00junk\n")
    pcap = str(tmp_path / "out.pcap")
    for argv in (
        ["decode", "feetech_sms", "--file", str(capture)],
        ["replay", str(capture), "--port", "/dev/null", "--spec", "feetech_sms"],
        ["export", str(capture), "--pcap", pcap],
    ):
        code, _, err = run(*argv)
        assert code == 1 and len(err.splitlines()) == 1, (argv, err)
        assert "line 2: " in err and "\x1b" not in err, err


def test_a_line_of_junk_on_stdin_is_told_quoted() -> None:
    """`decode -` names a line it cannot read as hex quoted and cut short, not as it came (terminal escapes)."""
    import sys

    lines = io.StringIO("\x1b]0;pwned\x07" + "zz" * 100 + "\n")
    real, sys.stdin = sys.stdin, lines
    try:
        code, _, err = run("decode", "feetech_sms", "-")
    finally:
        sys.stdin = real
    assert code == 1 and len(err.splitlines()) == 1 and "\x1b" not in err and "\x07" not in err, err


def test_a_folder_or_a_device_named_as_a_spec_is_said_so(tmp_path: Path) -> None:
    """`check` and `generate` of a folder, or of /dev/null, said "no such spec file" of something that is there."""
    folder = tmp_path / "lamp.yaml"
    folder.mkdir()
    for verb in ("check", "generate"):
        for path, said in ((folder, "is a folder, not a spec file"), (Path("/dev/null"), "is a device or a pipe")):
            code, _, err = run(verb, str(path), *(["--out", str(tmp_path / "out")] if verb == "generate" else []))
            assert code == 1 and f":1:1: {said}" in err.splitlines()[0], err
