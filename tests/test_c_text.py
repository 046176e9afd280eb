"""The C target for text protocols (`framing: {kind: text}`: NMEA 0183, the textlamp example, the language matrix's
every-text-alternative case, and it with every line a frame) against runtime/text.py: compiled warning-free under the
strict flags (gcc, clang, gcc -m32, the header as C++11, each feature switch off), every example decoded to the texts
the spec states and encoded back byte for byte, random messages, mutated frames and noisy streams cut in random
pieces giving what the Python codec and stream parser give. tests/c/driver.c (hex in, JSON out) runs the generated
code with the sanitizers, as for the binary protocols (tests/test_c_backend.py)."""

from __future__ import annotations

import copy
import dataclasses
import importlib
import json
import subprocess
import sys
from functools import cache
from pathlib import Path
from typing import Any

import pytest
import yaml
from conftest import ROOT, examples, scratch_folder
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import DecodeError, EncodeError
from serialspec.runtime.text import Sentence, TextField, TextFraming, TextSentence, encode_field
from serialspec.runtime.values import replace
from test_c_backend import (
    BUILDS,
    C_CHECK,
    CLANG,
    DEFAULT_BUILD,
    FLAGS,
    GCC,
    GXX,
    Driver,
    compiler,
    m32_builds,
    warning_flags,
)
from test_language_matrix import LABELLED_COMMANDS, TEXT_CASE
from test_text_frames import sentence_values

pytestmark = pytest.mark.skipif(GCC is None, reason="gcc is not installed")

MATRIX = copy.deepcopy(TEXT_CASE) | {"protocol": "c_text_matrix"}
# a line ending of bytes above 0x7F (Nextion's FF FF FF) for requests, and one of their own for responses (an
# ELM327's CR CR `>`, here LF LF `>`)
MATRIX["framing"]["end"] = {"request": "\xff\xff\xff", "response": "\n\n>"}
# a start of its own for each direction (Lynxmotion LSS: `#` asks, `*` answers; here `$`)
MATRIX["framing"]["start"] = {"request": "#", "response": "$"}
# an address before the code, every message's first field (LSS's servo id: `#5QD`)
MATRIX["framing"]["address"] = "unit"
MATRIX["fields"]["unit"] = {"type": "integer", "range": [0, 254]}
# a checksum in requests only (G-code's numbered lines carry one, the firmware's replies none: a `!` in them is text)
MATRIX["framing"]["checksum"]["directions"] = ["request"]
# messages in their own text found by their code alone: a reply under a code of its own of two words, a value glued to
# its code beside a longer code it begins (LSS's `D1800`), and a separator and list of their own
MATRIX["commands"]["dial"]["response"]["text"] = {"code": "RE;DL"}
MATRIX["commands"] |= {
    "glued": {
        "code": "GL",
        "response": {"unsolicited": True, "text": {"after_code": ""}, "fields": {"n": {"type": "integer"}}},
    },
    "longer": {"code": "GLX", "response": {"unsolicited": True, "fields": {"v": "integer"}}},
    # a message's own text with a start and end (GRBL's `[MSG:...]`, `[GC:...]`), two messages sharing it
    "bracket": {
        "code": "MSG",
        "response": {
            "unsolicited": True,
            "text": {"start": "[", "end": "]", "separator": ":"},
            "fields": {
                "a": "integer",
                "t": "text",
                "r": {"type": "repeat", "max_count": 2, "fields": {"x": "integer"}},
            },
        },
    },
    "bracket2": {
        "code": "GC",
        "response": {
            "unsolicited": True,
            "text": {"start": "[", "end": "]", "separator": ":"},
            "fields": {"b": "integer"},
        },
    },
    "pairs": {
        "code": "PR",
        "response": {
            "unsolicited": True,
            "text": {"separator": "=", "list": ":"},
            "fields": {
                "vals": {"type": "repeat", "count": 2, "fields": {"v": "integer"}},
                "more": {"type": "repeat", "max_count": 2, "fields": {"w": "integer", "t": "text"}},
            },
        },
    },
}
# messages in their own text with labels (test_language_matrix.LABELLED_COMMANDS): inside a start and an ending (here
# `<` and `>`, a character of the responses' line ending too), found in any order, one labelled with the code right
# after it, labelled repeats, a text; found by their code, labels glued to their values without a separator (the field
# labelled with the code not the first declared) and with one (a request: checksummed, a text too)
MATRIX["commands"] |= copy.deepcopy(LABELLED_COMMANDS)
REPORTED = MATRIX["commands"]["report"]["response"]["fields"]
MATRIX["commands"]["report"]["response"]["fields"] = {"t": {"label": "TX", "type": "text"}, **REPORTED}
MOVED = MATRIX["commands"]["move"]["response"]["fields"]
MOVED["time"]["range"] = [0, 9999]
MATRIX["commands"]["move"]["response"]["fields"] = {"time": MOVED.pop("time"), **MOVED}
MATRIX["commands"]["words"] = {"code": "GW", "request": MATRIX["commands"]["words"]["response"]}
MATRIX["commands"]["words"]["request"].pop("unsolicited")
MATRIX["commands"]["words"]["request"]["fields"]["w"] = {"label": "W", "type": "text"}
# frames without a start character, every line a frame (Marlin's `ok`, ODrive's ASCII protocol), requests ended by
# CR LF, responses by CR CR `>` (an ELM327's); an
# optional XOR checksum written in decimal after a separator in requests (ODrive's `r vbus_voltage *93`); a reply of
# values alone, read as the reply awaited
LINES = copy.deepcopy(TEXT_CASE) | {"protocol": "c_text_lines"}
del LINES["framing"]["start"]
LINES["framing"]["end"] = {"request": "\r\n", "response": "\r\r>"}  # an ELM327's reply ends with CR CR `>`
LINES["framing"]["checksum"] = {
    "algorithm": "xor",
    "format": "decimal",
    "marker": "*",
    "required": False,
    "separated": ["request"],
}
LINES["commands"]["dial"]["response"]["values_only"] = True  # ODrive's `r vbus_voltage` answered `24.1`
# a text to the end of the line (`size: rest`: Marlin's `Error:checksum mismatch, Last Line: 122`), separators and all,
# in a plain message (both cases) and in one found by its code (`ER=...`)
NOTE = {
    "code": "NT",
    "response": {"unsolicited": True, "fields": {"n": "integer", "msg": {"type": "text", "size": "rest"}}},
}
MATRIX["commands"]["note"] = LINES["commands"]["note"] = NOTE
MATRIX["commands"]["error"] = {
    "code": "ER",
    "response": {"unsolicited": True, "text": {"after_code": "="}, "fields": {"msg": {"type": "text", "size": "rest"}}},
}
# replies under codes of their own: an AT modem's `+CSQ: 20,99` and an ELM327's `41 0C 1A F8 ` (here `;` between words)
LINES["commands"] |= {
    "signal": {
        "code": "SQ",
        "request": {"fields": {}},
        "response": {
            "text": {"code": "+SQ:", "after_code": " "},
            "fields": {"rssi": {"type": "integer", "range": [0, 99]}, "ber": {"type": "integer", "range": [0, 99]}},
        },
    },
    "rpm": {
        "code": "RPM",
        "request": {"fields": {}},
        "response": {
            "text": {"code": "41;0C", "end": " "},
            "fields": {
                "a": {"type": "integer", "base": 16, "width": 2, "range": [0, 255]},
                "b": {"type": "integer", "base": 16, "width": 2, "range": [0, 255]},
                "note": "text",
            },
        },
    },
}
# labels after `named` in a message found by its code (`KV|A=1|R=1,2`)
LINES["commands"]["pairs"] = {
    "code": "KV",
    "response": {
        "unsolicited": True,
        "text": {"separator": "|", "named": "=", "list": ","},
        "fields": {
            "a": {"label": "A", "type": "integer"},
            "r": {"label": "R", "type": "repeat", "max_count": 2, "fields": {"x": "integer", "y": "text"}},
        },
    },
}
CASES = {"c_text_matrix": MATRIX, "c_text_lines": LINES}
SPECS = {
    "nmea0183": ROOT / "specs" / "nmea0183.yaml",
    "textlamp": ROOT / "examples" / "textlamp" / "textlamp.yaml",
    "c_text_matrix": None,
}
NAMES = list(SPECS)
# the lines case through the tests that hold the C to Python, and compiled with the strict flags by gcc alone
DIFFERENTIAL = [*NAMES, "c_text_lines"]
CLI = [sys.executable, "-m", "serialspec"]


@dataclasses.dataclass(frozen=True)
class Built:
    name: str
    folder: Path  # the generated C is in folder/c/<name>/
    package: Any
    framing: TextFraming


@cache
def built(name: str) -> Built:
    """The spec's Python package (imported) and C, generated by the CLI into a temporary folder."""
    folder = scratch_folder(f"serialspec-ctext-{name}-")
    spec = SPECS.get(name)
    if spec is None:
        spec = folder / f"{name}.yaml"
        spec.write_text(yaml.safe_dump(CASES[name], sort_keys=False), encoding="utf-8")
    for target, out in (("python", folder), ("c", folder / "c")):
        done = subprocess.run([*CLI, "generate", str(spec), "--target", target, "--out", str(out)], capture_output=True)
        assert done.returncode == 0, done.stderr.decode()
    sys.path.insert(0, str(folder))
    try:
        package = importlib.import_module(name)
    finally:
        sys.path.remove(str(folder))
    return Built(name, folder, package, package.FRAMING)


@cache
def driver(name: str, command: tuple[str, ...] = (), build: str = DEFAULT_BUILD) -> Driver:
    b = built(name)
    return Driver(name, b.folder / "c" / name, scratch_folder("serialspec-ctext-"), command, build)


# --- what Python gives ---------------------------------------------------------------------------------------------


def field_text(spec: TextField, value: Any) -> str:
    """A field's text as encode writes it, without its range check (what p_to_json shows of any decoded value)."""
    if value is None:
        return ""
    if spec.kind == "text":
        return str(value)
    if spec.kind == "char":
        return str(getattr(value, "value", value))
    return encode_field("", replace(spec, minimum=None, maximum=None), value)


def python_json(b: Built, sentence: Sentence) -> dict[str, Any]:
    spec: TextSentence = b.framing.sentence(sentence.code, sentence.direction)
    fields: dict[str, Any] = {}
    for item in spec.fields:
        value = sentence.values.get(item.name)
        if isinstance(item, TextField):
            fields[item.name] = field_text(item, value)
        else:
            fields[item.name] = [{f.name: field_text(f, row.get(f.name)) for f in item.fields} for row in value or ()]
    command = b.package.CODEC.classes[sentence.code, sentence.direction].COMMAND
    return {
        "command": command,
        "subcommand": None,
        "direction": sentence.direction,
        **({"talker": sentence.talker} if b.framing.talker else {}),
        "sent": sentence.sent,
        "fields": fields,
    }


def c_may_refuse(b: Built, frame: bytes) -> bool:
    """Where the C may refuse what Python takes (P_E_CAPACITY): a number of more than 18 digits (no int64_t holds
    it), a frame longer than any the parser gives with a text longer than the text room."""
    digits = max((len(run) for run in bytes(c if 0x30 <= c <= 0x39 else 0x20 for c in frame).split()), default=0)
    return digits > 18 or len(frame) > b.framing.max_length


def kind_name(b: Built, sentence: TextSentence) -> str:
    """The C kind name (p_kind_name) of a message."""
    return f"{b.package.CODEC.classes[sentence.code, sentence.direction].COMMAND}_{sentence.direction}"


def bare(b: Built) -> TextSentence | None:
    """The case's reply of values alone (`values_only`), if it has one."""
    return next((s for s in b.framing.sentences if s.bare), None)


def check_decode(
    b: Built, frame: bytes, direction: str, run: Driver | None = None, expect: TextSentence | None = None
) -> None:
    """The C decodes the frame as Python does (or both refuse), and encodes it again as Python does; with `expect`,
    as that reply awaited (p_decode_expect: another kind refused; Python's decode given its code as `reply`)."""
    run = run or driver(b.name)
    kind = "" if expect is None else f" {kind_name(b, expect)}"
    try:
        sentence = b.framing.decode(frame, direction, None if expect is None else expect.code)
    except DecodeError:
        sentence = None
    if (
        expect is not None
        and sentence is not None
        and (sentence.code, sentence.direction)
        != (
            expect.code,
            expect.direction,
        )
    ):
        sentence = None  # another kind than the one awaited: the C's decode_expect refuses it
    (answer,) = run.ask(f"dec {direction} {frame.hex() or '-'}{kind}")
    if sentence is None:
        assert answer.startswith("err "), f"C accepts {frame!r}, Python refuses it: {answer}"
        return
    if answer == "err E_CAPACITY" and c_may_refuse(b, frame):
        return
    assert answer.startswith("ok "), (frame, answer)
    assert json.loads(answer[3:]) == python_json(b, sentence), frame
    try:
        again: bytes | None = b.framing.encode_sentence(sentence)
    except EncodeError:
        again = None
    (answer,) = run.ask(f"rt {direction} {frame.hex()}{kind}")
    assert answer == (f"ok {again.hex()}" if again is not None else answer), (frame, answer, again)
    if again is None:
        assert answer.startswith("err "), (frame, answer)


def python_stream(
    b: Built, direction: str, data: bytes, gaps: tuple[int, ...] = (), expect: TextSentence | None = None
) -> tuple[list[dict[str, Any]], tuple[int, ...]]:
    from serialspec.runtime.text import TextStreamParser

    parser = TextStreamParser(b.framing, direction)
    parser.expect(None if expect is None else expect.code)
    found = []
    for at, byte in enumerate(data):
        for _ in range(gaps.count(at)):
            parser.gap()
        found += [python_json(b, s) for s in parser.feed(bytes([byte]))]
    for _ in range(sum(1 for at in gaps if at >= len(data))):
        parser.gap()
    return found, (len(found), 0, parser.corrupt, len(parser.pending()))


def stream_agrees(
    b: Built,
    direction: str,
    stream: bytes,
    sizes: str,
    run: Driver | None = None,
    gaps: tuple[int, ...] = (),
    expect: TextSentence | None = None,
) -> None:
    """The C parser fed `stream` in pieces of `sizes`, told of a gap in the line before each offset of `gaps` and
    awaiting the reply `expect` (parser_expect), gives the Python parser's sentences and counters; each one's raw
    frame (parser_frame) is the stream's next bytes."""
    kind = "-" if expect is None else kind_name(b, expect)
    where = f" {kind} {','.join(map(str, gaps))}" if gaps else f" {kind}" if expect is not None else ""
    answers = (run or driver(b.name)).ask(f"stream {direction} {sizes} {stream.hex() or '-'}{where}")
    messages = [json.loads(a[4:]) for a in answers if a.startswith("msg ")]
    counters = tuple(int(x) for x in answers[-1].split()[1:])
    assert (messages, counters) == python_stream(b, direction, stream, gaps, expect), stream
    at = 0
    for frame in (bytes.fromhex(a[6:]) for a in answers if a.startswith("frame ")):
        found = stream.find(frame, at)
        assert found >= 0 and frame.startswith(b.framing.start_of(direction).encode()), (frame, stream)
        at = found + len(frame)


def messages_of(b: Built) -> list[tuple[str, TextSentence]]:
    return [(s.direction, s) for s in b.framing.sentences]


def frames(b: Built, direction: str) -> st.SearchStrategy[bytes]:
    """Valid frames of the direction's messages, encoded by runtime/text.py, with any of the spec's talkers."""
    talkers = b.framing.talkers or ("X" * b.framing.talker,)

    def encoded(s: TextSentence, values: dict[str, Any], talker: str) -> bytes | None:
        try:
            return b.framing.encode(s.code, values, talker, direction=s.direction)
        except EncodeError:  # a text holding a character of the framing's (a line ending's `>`)
            return None

    choices = [
        st.tuples(values_of(s), st.sampled_from(talkers)).map(lambda x, s=s: encoded(s, *x))
        for s in b.framing.sentences
        if s.direction == direction
    ]
    return st.one_of(choices).filter(lambda frame: frame is not None)  # type: ignore[arg-type]


def values_of(sentence: TextSentence) -> st.SearchStrategy[dict[str, Any]]:
    """A message's values (test_text_frames.sentence_values), a text to the end of the line holding the separator
    and a message's own characters too."""
    rest = [f for f in sentence.fields if isinstance(f, TextField) and f.rest]
    if not rest:
        return sentence_values(sentence)
    text = st.one_of(st.none(), st.text(st.sampled_from("ab =;:1"), min_size=1))
    return st.tuples(sentence_values(sentence), text).map(lambda x: {**x[0], rest[0].name: x[1]})


def directions(b: Built) -> list[str]:
    return sorted({s.direction for s in b.framing.sentences})


# --- the tests -----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("level", ["-O0", "-O2"] if C_CHECK else ["-O2"])  # every level in `make c-check`
@pytest.mark.parametrize(("name", "build"), [(n, b) for n in NAMES for b in BUILDS[:3]] + [("c_text_lines", BUILDS[0])])
def test_compiles_without_a_warning(name: str, level: str, build: str, tmp_path: Path) -> None:
    folder = built(name).folder / "c" / name
    for source in (folder / f"{name}.c", folder / f"{name}_json.c"):
        done = subprocess.run(
            [*compiler(build), *FLAGS, level, *warning_flags(build), "-c", str(source), "-o", str(tmp_path / "o.o")]
        )
        assert done.returncode == 0


@pytest.mark.parametrize("name", NAMES)
def test_header_compiles_as_cpp11_and_switches_and_roles_leave_parts_out_without_a_warning(
    name: str, tmp_path: Path
) -> None:
    folder = built(name).folder / "c" / name
    if GXX is not None:
        done = subprocess.run([GXX, "-std=c++11", "-pedantic", "-Wall", "-Wextra", "-Werror", "-x", "c++",
                               "-fsyntax-only", str(folder / f"{name}.h")], capture_output=True, text=True)  # fmt: skip
        assert done.returncode == 0, done.stderr
    P = name.upper()
    off = [f"-D{P}_ENABLE_{part}=0" for part in ("ENCODE", "PARSER", "DECODE")]
    roles = [[f"-D{P}_ROLE={P}_ROLE_{role}"] for role in ("HOST", "DEVICE")]  # the parser's role checks too
    for switches in (off[:1], off[1:2], off[1:], off, off[:2], *roles):
        done = subprocess.run([str(GCC), *FLAGS, *switches, "-c", str(folder / f"{name}.c"), "-o", str(tmp_path / "o")],
                              capture_output=True, text=True)  # fmt: skip
        assert done.returncode == 0, (switches, done.stderr)


@pytest.mark.parametrize("name", NAMES)
def test_every_example_decodes_to_the_spec_texts_and_encodes_back(name: str) -> None:
    from serialspec.lang import load_protocol

    b = built(name)
    spec = SPECS[name] or b.folder / f"{name}.yaml"
    text = load_protocol(str(spec), spec.name).text
    assert text is not None
    assert text.examples or name == "c_text_matrix"
    for example in text.examples:
        frame = example.printed.encode("ascii")
        direction = example.direction.value
        ending = b.framing.end_of(direction).encode("latin-1")
        frame += b"" if frame.endswith(ending) else ending
        (answer,) = driver(name).ask(f"dec {direction} {frame.hex()}")
        assert answer.startswith("ok "), (example.name, answer)
        got = json.loads(answer[3:])
        assert got["command"] == example.command
        assert {k: got["fields"][k] for k in example.fields} == {k: _texts(v) for k, v in example.fields.items()}
        check_decode(b, frame, direction)


@pytest.mark.parametrize("name", DIFFERENTIAL)
def test_random_messages_and_mutated_frames_decode_and_encode_as_python_does(name: str) -> None:
    b = built(name)

    @settings(max_examples=examples(60), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(st.sampled_from(directions(b)).flatmap(lambda d: st.tuples(st.just(d), frames(b, d))), st.data())
    def agree(case: tuple[str, bytes], data: st.DataObject) -> None:
        direction, frame = case
        check_decode(b, frame, direction)
        check_decode(b, frame, "response" if direction == "request" else "request")  # read as the other direction
        awaited = bare(b)
        if awaited is not None and direction == awaited.direction:  # read as the reply of values alone awaited
            check_decode(b, frame, direction, expect=awaited)
        at = data.draw(st.integers(0, len(frame) - 1))
        flipped = (
            frame[:at] + bytes([data.draw(st.sampled_from(b"0123456789.-+,;*!#$ANSZaz\x00\x80"))]) + frame[at + 1 :]
        )
        check_decode(b, flipped, direction)
        check_decode(b, frame[: data.draw(st.integers(0, len(frame)))], direction)

    agree()


@pytest.mark.parametrize("name", DIFFERENTIAL)
def test_noisy_streams_byte_by_byte_and_in_random_pieces_give_what_python_gives(name: str) -> None:
    b = built(name)
    start, end = b.framing.start.encode(), b.framing.end.encode("latin-1")
    other = b.framing.response_end.encode("latin-1")  # the responses' own line ending, where they have one
    answer = b.framing.response_start.encode()  # the responses' own start, where they have one

    @settings(max_examples=examples(25), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(st.sampled_from(directions(b)), st.data())
    def agree(direction: str, data: st.DataObject) -> None:
        valid = frames(b, direction)
        piece = st.one_of(
            valid,
            valid.flatmap(lambda f: st.integers(0, len(f) - 1).map(lambda k: f[:k])),  # cut short
            valid.flatmap(
                lambda f: st.tuples(st.integers(0, len(f) - 1), st.integers(1, 127)).map(
                    lambda x: f[: x[0]] + bytes([f[x[0]] ^ x[1]]) + f[x[0] + 1 :]
                )
            ),  # fmt: skip
            st.binary(max_size=6),
            st.sampled_from([start, end, other, answer, start + b"X" * (b.framing.max_length + 3), b"\r", b"\n"]),
        )
        stream = b"".join(data.draw(st.lists(piece, max_size=8)))
        sizes = data.draw(st.lists(st.integers(0, 9), min_size=1, max_size=6))
        if not any(sizes):
            sizes.append(1)
        stream_agrees(b, direction, stream, "1")
        stream_agrees(b, direction, stream, ",".join(map(str, sizes)))
        gaps = tuple(sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=4))))
        stream_agrees(b, direction, stream, ",".join(map(str, sizes)), gaps=gaps)  # the line idle at `gaps`
        awaited = bare(b)
        if awaited is not None and direction == awaited.direction:  # a reply of values alone awaited
            stream_agrees(b, direction, stream, ",".join(map(str, sizes)), expect=awaited)

    agree()
    reply = bare(b)
    if reply is not None and name == "c_text_lines":  # answered once: the next line of values is no reply any more
        line = b.framing.encode(reply.code, {"level": 7}, b.framing.talkers[0], direction=reply.direction)
        stream_agrees(b, reply.direction, line + line, "1", expect=reply)


# bodies of frames of messages whose fields have labels (runtime/text.py frames them): in any order, the value
# labelled with the code right after it or left out, empty values, and what decode refuses (a label unknown or sent
# twice, a repeat's values of the wrong number, a part without `named`, a value not of its kind)
REPORT = ("=3|P=1.5,2|LV=7", "", "=", "=x", "|", "|LV=7|LV=8", "|Q=1", "|LV", "|P=1", "|P=,", "|P=1,2,3", "|=3")
REPORT += ("|S=1,N,2,S", "|S=1,N,2", "|S=1,N,2,S,3,N,4,S", "|TX=a=b,c|S=,", "=1|RP=2")
# (and what a careless reader gets wrong: signs, spaces, leading zeros, numbers past 32 bits, texts past the text
# room, bytes past ASCII, empty parts)
REPORT += ("=-0", "=+3", "= 3", "=3 ", "=03", "|LV=7|P=1.5,2|S=1,N", "|P=1e5,2", "|P=1.55,2")
REPORT += ("|P=.5,2", "|P=-.5,2", "|P=5.,2", "|TX=" + "a" * 300, "|S=", "|S=1,N,2,X", "|LV=007", "|LV=4294967303")
REPORT += ("|LV=-4294967296", "|TX=\x80\xff", "|TX=a|TX=b", "|P=1,2|", "||LV=1", "|LV=1|", "|S=1,N,,S", "|P=nan,2")
REPORT += ("|P=inf,1", "|LV=0x10", "|LV=1_0")
MOVE = ("1T2SD3.5", "T2", "SD-1T5", "", "1T2T3", "1X2", "1..2", "+1T-0", "T")
WORDS = (";Y2;X1.5", "", ";", ";X", ";Q1", ";X1;X2", ";Wa=b", ";Y2;;X1", ";W")
MOVE += ("1SD2T3", "1S2", "1TSD3", "1T-", "1T2SD", "1T2SD3.5SD4", "-0T0", "99999999999T1", "1T2 ", "T1SD2MV3")
MOVE += ("1T2SD-", "1T2SD.", "1T2SD+.5", "1T4294967297", "1T-2147483649", "1T2147483648", "1SD1e3")
WORDS += (";X1e3", ";X-", ";Y+2", ";X1;Y", ";W" + "z" * 400)
WORDS += (";Y2147483648", ";Y-2147483649", ";X1.5;Y2;", ";;", ";Y 2")
LABELLED = {
    "c_text_matrix": [("response", f"5<ARP{rest}>") for rest in REPORT]
    + [("response", "5<AXY=3>"), ("response", "<BRP=1|LV=2>")]
    + [("response", f"5AMV{rest}") for rest in MOVE]
    + [("request", f"5AGW{rest}") for rest in WORDS],
    "c_text_lines": [
        ("response", f"AKV{rest}") for rest in ("|R=1,a,2,b|A=3", "", "|", "|A", "|R=1", "|A=1|A=2", "|R=1,a,2,b,3,c")
    ],
}


@pytest.mark.parametrize("name", ["c_text_matrix", "c_text_lines"])
def test_labels_in_any_order_and_refused_as_python_refuses(name: str) -> None:
    """Frames of the messages with labels the random messages do not make (those write every label in order):
    decoded, refused and encoded again as Python does, and read so by the stream parser."""
    b = built(name)
    found = [(d, b.framing.frame(body, d)) for d, body in LABELLED[name]]
    for direction, frame in found:
        check_decode(b, frame, direction)
    for direction in directions(b):
        stream_agrees(b, direction, b"".join(f for d, f in found if d == direction), "1,3,7")


@pytest.mark.parametrize("build", [b for b in BUILDS[:3] if b != DEFAULT_BUILD])
@pytest.mark.parametrize("name", NAMES)
def test_other_builds_read_random_frames_and_streams_as_python_does(name: str, build: str) -> None:
    """gcc (or clang, where the other tests' driver is gcc's) and gcc -m32 (32-bit size_t and long), with the
    sanitizers."""
    if build == "gcc-m32" and not m32_builds():
        pytest.skip("gcc -m32 cannot link")
    if build == "clang" and CLANG is None:
        pytest.skip("clang is not installed")
    b = built(name)
    run = driver(name, tuple(compiler(build)), build)

    @settings(max_examples=examples(15), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(st.sampled_from(directions(b)).flatmap(lambda d: st.tuples(st.just(d), st.lists(frames(b, d), max_size=4))))
    def agree(case: tuple[str, list[bytes]]) -> None:
        direction, found = case
        for frame in found:
            check_decode(b, frame, direction, run)
        stream_agrees(b, direction, b"\x00".join(found) + b"$#", "1,2,3,5,8,13", run)

    agree()


def test_encode_refuses_out_of_range_values_and_never_writes_past_cap() -> None:
    """A value outside its range is refused (P_E_RANGE) and a buffer one byte short is refused (P_E_BUFFER) with
    nothing written past it (the driver's canary bytes): textlamp's level is 0..100."""
    b = built("textlamp")
    frame = b.framing.encode("LVL", {"level": 100}, direction="request")
    for cap in range(len(frame) + 2):
        (answer,) = driver("textlamp").ask(f"enc1 request {frame.hex()} {cap}")
        assert answer.startswith(f"ok {frame.hex()}" if cap >= len(frame) else "err E_BUFFER "), (cap, answer)
    too_big = b"#LVL,101*" + f"{_xor(b'LVL,101'):02X}".encode() + b"\r"  # decodes, but 101 is out of range
    (answer,) = driver("textlamp").ask(f"rt request {too_big.hex()}")
    assert answer.startswith("err E_RANGE "), answer
    with pytest.raises(EncodeError, match="outside its range"):
        b.framing.encode_sentence(b.framing.decode(too_big, "request"))


@pytest.mark.skipif(GCC is None, reason="no C compiler")
def test_to_json_of_no_message_writes_null(tmp_path: Path) -> None:
    """`p_to_json(NULL, ...)` read the kind of no message (a crash); the binary targets write `null`."""
    name = NAMES[0]
    folder = built(name).folder / "c" / name
    program = tmp_path / "null.c"
    program.write_text(
        f'#include <stdio.h>\n#include "{name}_json.h"\n'
        f"int main(void) {{ char out[16]; size_t n = {name}_to_json(NULL, out, sizeof(out)); "
        'printf("%u %s\\n", (unsigned)n, out); return 0; }\n',
        encoding="utf-8",
    )
    binary = tmp_path / "null"
    sources = [str(program), str(folder / f"{name}.c"), str(folder / f"{name}_json.c")]
    done = subprocess.run(
        [str(GCC), *FLAGS, f"-I{folder}", *sources, "-o", str(binary)], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    assert subprocess.run([str(binary)], capture_output=True, text=True, timeout=30).stdout == "4 null\n"


def _texts(value: Any) -> Any:
    """An example's field as its text (a repeat's groups as lists of dicts of texts)."""
    if isinstance(value, list):
        return [{k: _texts(v) for k, v in row.items()} for row in value]
    return "" if value is None else str(value)


def _xor(data: bytes) -> int:
    value = 0
    for byte in data:
        value ^= byte
    return value


def test_parser_push_reports_a_sentence_of_an_unknown_code_with_a_good_checksum() -> None:
    """p_parser_push: a sentence whose checksum is good but whose code the spec does not have is dropped as the
    Python parser drops it (an error), reported as P_EVENT_FRAME_UNKNOWN with its bytes and counted in `unknown`; a
    bad checksum is no such event; the messages are the Python parser's."""
    b = built("nmea0183")

    def sentence(body: str, good: bool = True) -> bytes:
        check = 0
        for c in body.encode():
            check ^= c
        return f"${body}*{check ^ (0 if good else 1):02X}\r\n".encode()

    unknown = sentence("GPZZZ,1,2")
    gga = b"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n"
    stream = unknown + gga + sentence("GPZZZ,3", good=False) + gga
    answers = driver("nmea0183").ask(f"push response {stream.hex()}")
    messages = [json.loads(a[4:]) for a in answers if a.startswith("msg ")]
    events = [bytes.fromhex(a[8:]) for a in answers if a.startswith("unknown ")]
    *counters, count = (int(x) for x in answers[-1].split()[1:])
    assert (messages, tuple(counters)) == python_stream(b, "response", stream)
    assert (len(messages), events, count) == (2, [unknown], 1)
