"""GRBL 1.1 (a CNC controller's text protocol: `ok`, `error:N`, `ALARM:N`, `<Idle|MPos:0.000,0.000,0.000|FS:0,0>`),
tried from the user docs alone. There is no PyPI peer worth the name, so there is no spec under tests/specs: what the
text language takes (`ok`, `error:20`, the status report in its own text layout, a state with its sub-state) works,
and each thing it cannot take is a strict xfail naming the gap. examples/grbl/grbl.yaml is the tutorial's spec of
the status report."""

from __future__ import annotations

import contextlib
import io
import json
import subprocess
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from serialspec.lang import load_protocol
from serialspec.runtime.errors import DecodeError, EncodeError

BASE = """
protocol: grbl
title: GRBL 1.1 responses
serial: {baudrate: 115200}
framing:
  kind: text
  separator: ":"
  end: "\\r\\n"
commands:
  ok:
    code: ok
    response: {unsolicited: true}
  error:
    code: error
    response:
      unsolicited: true
      fields:
        code: {type: integer, range: [1, 255]}
"""


@pytest.fixture(scope="module")
def example(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    """examples/grbl/grbl.yaml's package, generated once for this module."""
    from conftest import ROOT, generate_and_import

    def forget() -> None:  # other tests import their own spec of the same protocol name
        for name in [m for m in sys.modules if m.partition(".")[0] == "grbl"]:
            del sys.modules[name]

    forget()
    package = generate_and_import(ROOT / "examples" / "grbl" / "grbl.yaml", tmp_path_factory.mktemp("grbl"), "grbl")
    forget()
    return package


def spec(tmp_path: Path, extra: str = "") -> Path:
    path = tmp_path / "grbl.yaml"
    path.write_text(BASE + extra, "utf-8")
    return path


def decode_json(path: Path, line: str) -> dict[str, Any]:
    """`serialspec decode PATH LINE --json`, in this process (the CLI's processes are tests/test_cli.py's)."""
    from serialspec import cli

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert cli.main(["decode", str(path), line, "--json"]) == 0
    return json.loads(out.getvalue())  # type: ignore[no-any-return]


def test_ok_and_error_lines_decode(tmp_path: Path) -> None:
    path = spec(tmp_path)
    assert decode_json(path, "ok")["command"] == "ok"
    assert decode_json(path, "error:20")["fields"] == {"code": "20"}


def test_a_text_frame_without_a_checksum_is_not_said_to_check(tmp_path: Path) -> None:
    """Found here: `decode --json` said "checksum_ok": true for text frames whose framing has no checksum (binary
    frames without one already said null)."""
    assert decode_json(spec(tmp_path), "ok")["checksum_ok"] is None
    nmea = Path(__file__).parent.parent / "specs" / "nmea0183.yaml"
    gga = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"
    assert decode_json(nmea, gga + "*47")["checksum_ok"] is True
    assert decode_json(nmea, gga)["checksum_ok"] is None  # NMEA allows leaving it out: not checked


ANSWERED = """  home:
    code: $H
    title: Run the homing cycle
    request:
      answered_by: {command: ok, refused_by: [error]}
device:
  description: A GRBL board that answers every line with ok.
  state: {}
"""


def test_ok_answers_a_g_code_line(tmp_path: Path) -> None:
    """GRBL answers every line with `ok` or `error:N`: a request `answered_by` another command's response. The sim
    answers $H with ok, the client returns it; an `error:9` line in its place is a DeviceError naming it."""
    import importlib

    from conftest import generate_and_import
    from pty_pair import answering_line
    from serialspec.runtime.errors import DeviceError

    path = spec(tmp_path, ANSWERED)
    protocol = load_protocol(str(path), "grbl")
    assert protocol.text is not None and protocol.text.answers() == {"$H": (("ok",), ("error",))}
    grbl = generate_and_import(path, tmp_path / "out", "grbl")
    simulator = importlib.import_module("grbl.simulator").SIMULATOR()  # in this process: no `serialspec sim` to start
    try:
        with grbl.Client(simulator.start()) as client:
            assert isinstance(client.home(timeout=5), grbl.OkResponse)
    finally:
        simulator.close()
    with (
        answering_line(b"$H\r\n", b"error:9\r\n") as name,
        grbl.Client(name) as client,
        pytest.raises(DeviceError, match=r"^home \(\$H\): the device refused it"),
    ):
        client.home(timeout=5)


def test_answered_by_mistakes_are_one_line_each(tmp_path: Path) -> None:
    bad = ANSWERED.replace("{command: ok, refused_by: [error]}", "{command: okay, refused_by: [ok]}")
    run = subprocess.run(
        [sys.executable, "-m", "serialspec", "check", str(spec(tmp_path, bad))], capture_output=True, text=True
    )
    lines = (run.stdout + run.stderr).strip().splitlines()
    assert run.returncode != 0 and len(lines) == 1 and "Traceback" not in run.stderr, lines
    assert lines[0].endswith("commands.home.request.answered_by.command: 'okay' is not a command with a response")


def test_a_dollar_command(tmp_path: Path) -> None:
    """GRBL's system commands (`$H`, `$$`) and real-time ones (`?`, `!`, `~`) are text codes; a code holding one of
    the framing's own characters (NMEA's `$` start) is refused in one line."""
    extra = "".join(
        f"  {name}:\n    code: {code!r}\n    request: {{}}\n"
        for name, code in (("home", "$H"), ("settings", "$$"), ("status", "?"), ("hold", "!"), ("resume", "~"))
    )
    path = spec(tmp_path, extra)
    load_protocol(str(path), "grbl")
    for line in ("$H", "$$", "?", "!", "~"):
        assert decode_json(path, line)["fields"] == {}
    nmea = spec(tmp_path, "  home:\n    code: $H\n    request: {}\n")
    nmea.write_text(nmea.read_text("utf-8").replace("kind: text", "kind: text\n  start: $"), "utf-8")
    run = subprocess.run([sys.executable, "-m", "serialspec", "check", str(nmea)], capture_output=True, text=True)
    assert run.returncode != 0 and "Traceback" not in run.stderr
    lines = (run.stdout + run.stderr).strip().splitlines()
    assert len(lines) == 1 and lines[0].endswith(
        "commands.home.code: a text command needs a text `code` (letters, digits and !#%&+-./;=?@^_~), got '$H'"
    ), lines


def test_a_status_report(tmp_path: Path) -> None:
    """Found here: one `start`, one `separator` per framing, so GRBL's status report `<Idle|MPos:1.000,2.000,3.000|
    FS:0,0>` (a `<` where other lines have no start, fields separated by `|`, named with `:`, a field's numbers
    separated by `,`) could not be said. A message's own `text:` says it; its fields are found by their labels."""
    extra = """  status:
    code: Idle
    response:
      unsolicited: true
      text: {start: "<", end: ">", separator: "|", named: ":", list: ","}
      fields:
        mpos: {label: MPos, type: repeat, count: 3, fields: {axis: {type: decimal, precision: 3}}}
        wpos: {label: WPos, type: repeat, count: 3, fields: {axis: {type: decimal, precision: 3}}}
        feed: {label: FS, type: repeat, count: 2, fields: {value: integer}}
        line: {label: Ln, type: integer}
"""
    path = spec(tmp_path, extra)
    load_protocol(str(path), "grbl")
    report = decode_json(path, "<Idle|MPos:1.000,2.000,3.000|FS:0,0>")
    assert report["command"] == "status"
    assert report["fields"]["mpos"] == [{"axis": "1.000"}, {"axis": "2.000"}, {"axis": "3.000"}]
    assert report["fields"]["wpos"] == [] and report["fields"]["line"] == ""  # labels absent


STATES = """  status_{word}:
    code: {code}
    response:
      unsolicited: true
      text: {{start: "<", end: ">", separator: "|", named: ":", list: ","}}
      fields:
        mpos: {{label: MPos, type: repeat, count: 3, fields: {{axis: {{type: decimal, precision: 3}}}}}}
        line: {{label: Ln, type: integer}}
"""


def test_a_command_per_state_word(tmp_path: Path) -> None:
    """What the text language gives today for the status report's state word: one command per state, each with
    the same own text layout (`<Run|…>` is status_run); the `<` tells the layout, the word the command."""
    extra = "".join(STATES.format(word=word.lower(), code=word) for word in ("Idle", "Run", "Jog", "Alarm"))
    path = spec(tmp_path, extra)
    load_protocol(str(path), "grbl")
    from serialspec import cli

    lines = [f"<{word}|MPos:1.000,2.000,3.000|Ln:4>" for word in ("Idle", "Run", "Jog", "Alarm")]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert cli.main(["decode", str(path), "--json", "--direction", "response", *lines]) == 0
    reports = [json.loads(line) for line in out.getvalue().splitlines()]
    assert [r["command"] for r in reports] == ["status_idle", "status_run", "status_jog", "status_alarm"]
    assert {r["fields"]["line"] for r in reports} == {"4"}


# the same report with the sub-state after the state word: the field labelled with the code
SUB_STATE = STATES.replace(
    "      fields:\n", "      fields:\n        sub_state: {{label: {code}, type: integer, range: [0, 9]}}\n"
)


def test_the_state_word_with_a_sub_state(tmp_path: Path) -> None:
    """`<Hold:0|…>`, `<Door:1|…>`: the field labelled with the code is the value right after it; `<Hold|…>` leaves
    it None, and encode writes it after the code (none where it is None)."""
    from conftest import generate_and_import

    extra = "".join(SUB_STATE.format(word=word.lower(), code=word) for word in ("Hold", "Door"))
    path = spec(tmp_path, extra)
    load_protocol(str(path), "grbl")
    report = decode_json(path, "<Hold:1|MPos:1.000,2.000,3.000|Ln:4>")
    assert report["command"] == "status_hold" and report["fields"]["sub_state"] == "1"  # type: ignore[index]
    for name in [m for m in sys.modules if m.partition(".")[0] == "grbl"]:
        del sys.modules[name]
    grbl = generate_and_import(path, tmp_path / "out", "grbl")
    for name in [m for m in sys.modules if m.partition(".")[0] == "grbl"]:
        del sys.modules[name]
    door = grbl.decode(b"<Door:3|Ln:7>\r\n")
    assert isinstance(door, grbl.StatusDoorResponse) and (door.sub_state, door.line) == (3, 7)
    assert grbl.encode(door) == b"<Door:3|Ln:7>\r\n"
    bare = grbl.decode(b"<Hold|MPos:1.000,2.000,3.000>\r\n")
    assert bare.sub_state is None and grbl.encode(bare) == b"<Hold|MPos:1.000,2.000,3.000>\r\n"
    stream = b"ok\r\n<Hold:0|Ln:1>\r\n<Door:1>\r\n"
    parser = grbl.StreamParser()
    found = [m for byte in stream for m in parser.feed(bytes([byte]))]
    assert [(type(m).__name__, getattr(m, "sub_state", None)) for m in found] == [
        ("OkResponse", None),
        ("StatusHoldResponse", 0),
        ("StatusDoorResponse", 1),
    ]
    for bad, reason in (
        ("<Hold:x|Ln:1>", "Hold: sub_state = 'x' is not an integer"),
        ("<Hold:0|Hold:1>", "Hold: label 'Hold' sent twice"),
    ):
        with pytest.raises(DecodeError, match=f"^{reason}"):
            grbl.decode(bad)


def test_the_status_report_s_package(example: ModuleType) -> None:
    """The generated package (examples/grbl/grbl.yaml, the same status report): labels in any order, absent ones
    left out on encode, the stream parser among `ok` and `error:N` lines, bad reports refused in one line."""
    grbl = example
    line = b"<Idle|MPos:1.000,2.000,3.000|FS:0,0>\r\n"
    assert grbl.encode(grbl.decode(line)) == line
    status = grbl.decode(b"<Idle|Ln:7|FS:500,8000|WPos:0.000,-1.500,2.250>\r\n")  # labels in any order
    assert grbl.encode(status) == b"<Idle|WPos:0.000,-1.500,2.250|FS:500,8000|Ln:7>\r\n"  # written in the spec's
    assert grbl.decode(grbl.encode(status)) == status
    assert status.line == 7 and [f.value for f in status.feed] == [500, 8000]
    stream = b"ok\r\n<Idle|MPos:1.000,2.000,3.000|FS:0,0>\r\nerror:9\r\n"
    parser = grbl.StreamParser()
    found = [m for byte in stream for m in parser.feed(bytes([byte]))]
    assert [type(m).__name__ for m in found] == ["OkResponse", "StatusResponse", "ErrorResponse"]
    for bad, reason in (
        ("<Idle|Bf:15,128>", "Idle: unknown label 'Bf' (expected one of MPos, WPos, FS, Ln)"),
        ("<Idle|Ln:1|Ln:2>", "Idle: label 'Ln' sent twice"),
        ("<Idle|MPos:1.000,2.000>", "Idle: mpos has 2 values, expected 3"),
    ):
        with pytest.raises(DecodeError) as refused:
            grbl.decode(bad)
        assert str(refused.value) == reason


def test_a_protocol_without_a_talker_shows_none(example: ModuleType) -> None:
    """GRBL's frames carry no talker: its messages neither show one nor take one as their first argument, and
    `decode --json` names none (it used to print `ErrorResponse(talker='', code=3)` and `"talker": ""`)."""
    from serialspec.cli.textframes import describe

    grbl = example
    error = grbl.decode(b"error:3\r\n")
    assert repr(error) == "ErrorResponse(code=3)"
    assert grbl.ErrorResponse(3) == error and grbl.encode(grbl.ErrorResponse(3)) == b"error:3\r\n"
    assert "talker" not in describe("grbl", grbl, b"error:3\r\n")
    with pytest.raises(EncodeError, match=r"^error: talker 'GP' given, but these frames carry no talker$"):
        grbl.CODEC.framing.encode("error", {"code": "3"}, "GP", direction="response")


def test_codes_with_question_marks_compile_as_c99_without_trigraphs(tmp_path: Path) -> None:
    """`??=` in a C99 string literal is the trigraph `#`: the C target escapes `?` so that the code is sent as written
    (gcc -std=c99 -Wall reads trigraphs and warns about them)."""
    import shutil

    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("no gcc")
    path = spec(tmp_path, "  status:\n    code: '?'\n    request: {}\n  odd:\n    code: '??='\n    request: {}\n")
    path.write_text(path.read_text("utf-8").replace("kind: text", 'kind: text\n  start: "<"'), "utf-8")
    out = tmp_path / "c"
    subprocess.run(
        [sys.executable, "-m", "serialspec", "generate", str(path), "--target", "c", "--out", str(out)], check=True
    )
    source = out / "grbl" / "grbl.c"
    assert '"\\?\\?="' in source.read_text("utf-8")
    flags = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-c", str(source), "-o", str(tmp_path / "o")]
    run = subprocess.run([gcc, *flags], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr


def test_the_client_asks_the_sim_for_a_status_report(example: ModuleType) -> None:
    """examples/grbl/grbl.yaml: `?` is answered by the status report, which the simulator writes in its own text
    layout and the client reads back by its labels."""
    from conftest import ROOT
    from sim_process import serve

    grbl = example
    with serve(str(ROOT / "examples" / "grbl" / "grbl.yaml")) as port, grbl.Client(port) as client:
        status = client.report(timeout=5)
    assert isinstance(status, grbl.StatusResponse) and status.line == 7


def test_status_reports_round_trip_and_stream_however_split(example: ModuleType) -> None:
    """Any values, any labels left out: decode(encode(m)) == m, and the stream parser gives the same messages
    however the bytes are split into reads."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    grbl = example
    axis = st.decimals(-9999, 9999, places=3).map(lambda d: grbl.StatusResponseMpos(axis=d))
    waxis = st.decimals(-9999, 9999, places=3).map(lambda d: grbl.StatusResponseWpos(axis=d))
    feed = st.integers(0, 99999).map(lambda v: grbl.StatusResponseFeed(value=v))
    status = st.builds(
        grbl.StatusResponse,
        mpos=st.one_of(st.just(()), st.tuples(axis, axis, axis)),
        wpos=st.one_of(st.just(()), st.tuples(waxis, waxis, waxis)),
        feed=st.one_of(st.just(()), st.tuples(feed, feed)),
        line=st.one_of(st.none(), st.integers(0, 9999999)),
    )

    @settings(max_examples=60, deadline=None)
    @given(reports=st.lists(status, min_size=1, max_size=3), cuts=st.lists(st.integers(1, 400), max_size=6))
    def check(reports: list[Any], cuts: list[int]) -> None:
        data = b"ok\r\n".join(grbl.encode(r) for r in reports)
        for report in reports:
            assert grbl.decode(grbl.encode(report)) == report
        parser, found, at = grbl.StreamParser(), [], 0
        for cut in sorted(set(cuts)):
            found += parser.feed(data[at:cut])
            at = max(at, cut)
        found += parser.feed(data[at:])
        assert [m for m in found if isinstance(m, grbl.StatusResponse)] == reports

    check()
