"""The Wireshark dissector of a text protocol, run by tshark as a user would: `serialspec generate --target
wireshark`, a capture of random sentences of every message (several in a packet, one cut across two packets, one
with a bad checksum) exported with `serialspec export --pcap`; tshark shows each sentence's command, talker and
fields as the texts `runtime/text.py` decodes (what `serialspec decode --json` prints), the bad checksum flagged."""

from __future__ import annotations

import copy
import importlib
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import HealthCheck, Phase, assume, given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import DecodeError, EncodeError
from serialspec.runtime.text import TextField, TextSentence
from test_c_text import CLI, LINES, NAMES, SPECS, Built, built, python_json
from test_language_matrix import LABELLED_COMMANDS, TEXT_CASE
from test_text_frames import field_values, sentence_values

pytestmark = pytest.mark.slow
TSHARK = shutil.which("tshark")


def run(*args: str) -> str:
    done = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return done.stdout


def sentences(xml: str, name: str) -> list[dict[str, Any]]:
    """Each sentence tshark shows: command, direction, talker, checksum_ok and the fields by name, in order."""
    found = []
    for packet in ET.fromstring(xml).iter("packet"):
        for proto in packet:
            if proto.get("name") != name:
                continue
            shown: dict[str, Any] = {"fields": []}
            for field in proto:
                key = str(field.get("name"))
                value = field.get("show")
                if key in (f"{name}.command", f"{name}.direction", f"{name}.talker", f"{name}.checksum_ok"):
                    shown[key.rsplit(".", 1)[1]] = value
                elif key.count(".") >= 3:
                    shown["fields"].append((key.split(".", 3)[3], value))
            found.append(shown)
    return found


def flat(fields: dict[str, Any]) -> list[tuple[str, str]]:
    """decode --json's fields in order, a repeat's groups as <repeat>.<field> one after another."""
    out: list[tuple[str, str]] = []
    for name, value in fields.items():
        if isinstance(value, list):
            out += [(f"{name}.{k}", v) for row in value for k, v in row.items()]
        else:
            out.append((name, value))
    return out


def encodes(b: Built, s: TextSentence, values: dict[str, Any], talker: str) -> bool:
    """Whether the message's values make a frame (no text holding a character of the framing's or its own)."""
    try:
        b.framing.encode(s.code, values, talker, direction=s.direction)
    except EncodeError:
        return False
    return True


# the C's text specs (the every-kind case's line ending is FF FF FF)
DISSECTED = NAMES


@pytest.mark.skipif(TSHARK is None, reason="tshark is not installed")
@pytest.mark.parametrize("name", DISSECTED)
def test_tshark_shows_random_sentences_as_decode_does(name: str, tmp_path: Path) -> None:
    assert TSHARK is not None
    b = built(name)
    source = str(SPECS.get(name) or b.folder / f"{name}.yaml")
    run(*CLI, "generate", source, "--target", "wireshark", "--out", str(tmp_path))
    script = f"lua_script:{tmp_path / name / f'{name}.lua'}"
    talkers = b.framing.talkers or ("X" * b.framing.talker,)

    @settings(max_examples=3, deadline=None, suppress_health_check=list(HealthCheck), phases=(Phase.generate,))
    @given(st.data())
    def shown_as_decoded(data: st.DataObject) -> None:
        lines, wanted = [f"# serialspec capture: {name}"], []
        frames = []
        for s in b.framing.sentences:
            talker = data.draw(st.sampled_from(talkers))
            # (a text holding one of the framing's or the message's own characters is refused: drawn again)
            values = data.draw(sentence_values(s).filter(lambda v, s=s, t=talker: encodes(b, s, v, t)))
            frame = b.framing.encode(s.code, values, talker, direction=s.direction)
            frames.append((s.direction, frame))
            wanted.append(python_json(b, b.framing.decode(frame, s.direction)) | {"checksum_ok": True})
        direction, last = frames[-1]
        checked = b.framing.checksum is not None and direction in b.framing.checksummed  # (one way: requests only)
        bad = bytearray(last)
        marker = bad.rfind(b.framing.marker.encode())
        bad[marker + 1 : marker + 3] = b"ZZ" if checked else bad[marker + 1 : marker + 3]
        packets = [(d, f) for d, f in frames[:-1]]
        packets.append((direction, last[:5]))  # a sentence cut across two packets
        packets.append((direction, last[5:] + (bytes(bad) if checked else b"")))  # and a second one, a bad checksum
        if checked:
            wanted.append(wanted[-1] | {"checksum_ok": False})
        for d, data_ in packets:
            lines.append(f"2026-11-25T10:00:00.000000+00:00 {d} {data_.hex(' ')}")
        (tmp_path / "t.capture").write_text("\n".join(lines) + "\n", encoding="utf-8")
        run(*CLI, "export", str(tmp_path / "t.capture"), "--pcap", str(tmp_path / "t.pcap"))
        seen = sentences(run(TSHARK, "-X", script, "-r", str(tmp_path / "t.pcap"), "-T", "pdml"), name)
        assert len(seen) == len(wanted)
        for got, expected in zip(seen, wanted, strict=True):
            assert got["command"] == expected["command"] and got["direction"] == expected["direction"]
            assert got.get("talker", "") == expected.get("talker", "")
            assert got["fields"] == flat(expected["fields"]), (got, expected)
            if b.framing.checksum is not None and expected["direction"] in b.framing.checksummed:
                assert (got["checksum_ok"] in ("1", "True")) == expected["checksum_ok"], got

    shown_as_decoded()


# What the C target does not take but the dissector does, each beside the others: every line a frame (no start
# character, CR LF, an optional XOR checksum in decimal after a separator in requests, a reply of values alone
# read after its request: the C's lines case), and a start, line ending and checksum of each direction's own (LSS's
# `#` and `*` with the servo id before the code, a reply ended by bytes above 0x7F as Nextion's under a code of its
# own, a checksum in requests alone; a text to the end of the line).
ONE_WAY = copy.deepcopy(TEXT_CASE) | {"protocol": "ws_text_one_way"}
ONE_WAY["framing"]["start"] = {"request": "#", "response": "*"}
ONE_WAY["framing"]["end"] = {"request": "\n", "response": "\r\xff\xff\xff"}
ONE_WAY["framing"]["checksum"]["directions"] = ["request"]
ONE_WAY["framing"]["address"] = "unit"  # LSS's servo id: `#5QD` asked, `*5QD1800` answered
ONE_WAY["fields"]["unit"] = {"type": "integer", "range": [0, 254]}
ONE_WAY["commands"]["dial"]["response"]["text"] = {"code": "RE;DL"}  # a reply under a code of its own
ONE_WAY["commands"]["note"] = {  # and a text to the end of the line, separators and all
    "code": "NT",
    "response": {"unsolicited": True, "fields": {"n": "integer", "msg": {"type": "text", "size": "rest"}}},
}
# Messages in their own text: inside a start and an ending, with labels, a list and a value after the code (GRBL's
# `<Idle|MPos:…>`), or with a text to the end of the message's own text; found by their code, glued to it (LSS's
# `D1800`) beside a longer code, with their own separator and list (Roboteq's `A=12:13`); labels glued to their
# values, with a separator (G-code's `X10.5`) and without (LSS's `D1800T1500`).
LAYOUTS = copy.deepcopy(TEXT_CASE) | {"protocol": "ws_text_layouts"}
LAYOUTS["commands"] |= copy.deepcopy(LABELLED_COMMANDS) | {
    "boxed": {  # a text to the end of its own text, its ending not included
        "code": "BX",
        "response": {
            "unsolicited": True,
            "text": {"start": "(", "end": ")", "separator": "|"},
            "fields": {"n": "integer", "msg": {"type": "text", "size": "rest"}},
        },
    },
    "glued": {
        "code": "GL",
        "response": {"unsolicited": True, "text": {"after_code": ""}, "fields": {"n": {"type": "integer"}}},
    },
    "longer": {"code": "GLX", "response": {"unsolicited": True, "fields": {"v": "integer"}}},
    "pairs": {
        "code": "PR",
        "response": {
            "unsolicited": True,
            "text": {"separator": "=", "list": ":"},
            "fields": {"vals": {"type": "repeat", "count": 2, "fields": {"v": "integer"}}},
        },
    },
}
BY_DIRECTION = {
    "ws_text_lines": copy.deepcopy(LINES) | {"protocol": "ws_text_lines"},
    "ws_text_one_way": ONE_WAY,
    "ws_text_layouts": LAYOUTS,
}
# Sentences decode refuses (their text between start and checksum, all responses) and the one line the dissector
# says of each (its expert note, on the sentence's own item), with no Lua file and line in it.
MALFORMED = {
    "ws_text_layouts": [
        ("<ARP=1|Q=1>", "report: unknown label 'Q' (expected one of RP, LV, P, S)"),
        ("<ARP=1|LV=1|LV=2>", "report: label 'LV' sent twice"),
        ("<ARP=1|P=1>", "report: pos has 1 values, expected 2"),
        ("<ARP|S=1,N,2,S,3,N,4,S>", "report: sats has 8 values, at most 6"),
        ("<ARP|S=1>", "report: sats has 1 values, expected a multiple of 2"),
        ("<AEV>", "every is not sent as <…>"),
        ("<AZZ>", "unknown text code 'ZZ'"),
        ("AZZ;1", "unknown text code 'ZZ'"),
    ],
}


@pytest.mark.skipif(TSHARK is None, reason="tshark is not installed")
@pytest.mark.parametrize("name", list(BY_DIRECTION))
def test_tshark_shows_lines_and_each_directions_own_text_as_decode_does(name: str, tmp_path: Path) -> None:
    """Each message after the request it answers (a reply of values alone is read as that request's reply, as
    decode reads it given the request); the last one cut across two packets; a request with a bad checksum after
    them. tshark shows each as decode does, the checksum checked where the direction carries one."""
    assert TSHARK is not None
    spec = tmp_path / f"{name}.yaml"
    spec.write_text(yaml.safe_dump(BY_DIRECTION[name], sort_keys=False), encoding="utf-8")
    for target in ("python", "wireshark"):
        run(*CLI, "generate", str(spec), "--target", target, "--out", str(tmp_path))
    sys.path.insert(0, str(tmp_path))
    try:
        package = importlib.import_module(name)
    finally:
        sys.path.remove(str(tmp_path))
    b = Built(name, tmp_path, package, package.FRAMING)
    framing = b.framing
    script = f"lua_script:{tmp_path / name / f'{name}.lua'}"
    talkers = framing.talkers or ("X" * framing.talker,)

    @settings(max_examples=2, deadline=None, suppress_health_check=list(HealthCheck), phases=(Phase.generate,))
    @given(st.data())
    def shown_as_decoded(data: st.DataObject) -> None:
        frames, wanted, asked = [], [], None
        for s in framing.sentences:
            values = data.draw(sentence_values(s))
            for item in s.fields:
                if isinstance(item, TextField) and item.rest:  # a text to the end of the line holds separators
                    values[item.name] = f"a{framing.separator}b {framing.separator}{values[item.name] or ''}"
                if isinstance(item, TextField) and item.label == s.code and values[item.name] is None:
                    # the value labelled with the code, right after it (GRBL's `Hold:0`, LSS's `D1800`)
                    values[item.name] = data.draw(field_values(item).filter(lambda v: v is not None))
            talker = data.draw(st.sampled_from(talkers))
            assume(encodes(b, s, values, talker))  # a text holding an enclosing layout's end cannot be sent
            frame = framing.encode(s.code, values, talker, direction=s.direction)
            frames.append((s.direction, frame))
            decoded = framing.decode(frame, s.direction, asked if s.direction == "response" else None)
            wanted.append(python_json(b, decoded) | {"checksum_ok": True})
            asked = s.code if s.direction == "request" else None
        direction, last = frames[-1]
        packets = [*frames[:-1], (direction, last[:3]), (direction, last[3:])]  # the last one cut across two packets
        first_direction, first = frames[0]
        assert first_direction == "request"
        if framing.checksum is not None:  # a request with a bad checksum
            marker = first.rfind(framing.marker.encode())
            packets.append((first_direction, first[: marker + 1] + b"ZZ" + first[marker + 3 :]))
            wanted.append(wanted[0] | {"checksum_ok": False})
        if not framing.start:  # a blank line cut across packets (CR ends one, LF begins the next): no sentence
            after = next(i for i, (d, _) in enumerate(packets) if i and d == first_direction)
            packets[0], packets[after] = (first_direction, first + b"\r"), (first_direction, b"\n" + packets[after][1])
        lines = [f"# serialspec capture: {name}"]
        lines += [f"2026-11-25T10:00:00.000000+00:00 {d} {f.hex(' ')}" for d, f in packets]
        (tmp_path / "t.capture").write_text("\n".join(lines) + "\n", encoding="utf-8")
        run(*CLI, "export", str(tmp_path / "t.capture"), "--pcap", str(tmp_path / "t.pcap"))
        xml = run(TSHARK, "-X", script, "-r", str(tmp_path / "t.pcap"), "-T", "pdml")
        seen = sentences(xml, name)
        assert len(seen) == len(wanted), seen
        # one sentence continues in the next packet: the one cut across two
        assert [f.get("name") for f in ET.fromstring(xml).iter("field")].count(f"{name}.incomplete") == 1
        for got, expected in zip(seen, wanted, strict=True):
            assert got["command"] == expected["command"] and got["direction"] == expected["direction"], got
            assert got.get("talker", "") == expected.get("talker", "")
            assert got["fields"] == flat(expected["fields"]), (got, expected)
            if expected["direction"] in framing.checksummed and framing.checksum is not None:
                assert (got["checksum_ok"] in ("1", "True")) == expected["checksum_ok"], got
            else:
                assert "checksum_ok" not in got, got

    shown_as_decoded()
    if name not in MALFORMED:
        return
    lines = [f"# serialspec capture: {name}"]
    for body, _ in MALFORMED[name]:
        with pytest.raises(DecodeError):
            framing.decode(framing.frame(body, "response"), "response")
        lines.append(f"2026-11-25T10:00:00.000000+00:00 response {framing.frame(body, 'response').hex(' ')}")
    (tmp_path / "m.capture").write_text("\n".join(lines) + "\n", encoding="utf-8")
    run(*CLI, "export", str(tmp_path / "m.capture"), "--pcap", str(tmp_path / "m.pcap"))
    xml = run(TSHARK, "-X", script, "-r", str(tmp_path / "m.pcap"), "-T", "pdml")
    said = [f.get("showname") for f in ET.fromstring(xml).iter("field") if f.get("name") == f"{name}.malformed"]
    assert said == [line for _, line in MALFORMED[name]]
    assert len(sentences(xml, name)) == len(MALFORMED[name])  # each one item, what was read of it and its note
    items = [p.get("showname") for p in ET.fromstring(xml).iter("proto") if p.get("name") == name]
    assert items[0] == f"{LAYOUTS['title']} response report", items  # an untitled command's item names it


@pytest.mark.skipif(TSHARK is None, reason="tshark is not installed")
def test_tshark_reads_a_blank_line_cut_before_its_prompt(tmp_path: Path) -> None:
    """ELM327's replies end with CR CR `>` (every line a frame): a blank line's CR CR ending one packet and its `>`
    beginning the next is no sentence, and the reply after it is read as decode reads it (once the CR CR was dropped
    and the `>` read as the start of the next reply's code)."""
    from serialspec import cli
    from serialspec.backends import emitters
    from serialspec.lang.loader import load_text
    from serialspec.lang.resolve import resolve

    spec = Path(__file__).parent / "specs" / "elm327.yaml"
    protocol = resolve(load_text(spec.read_text("utf-8"), "elm327.yaml"))
    wireshark = next(e for e in emitters() if e.name == "wireshark")
    (tmp_path / "elm327.lua").write_text(wireshark.files(protocol)["elm327/elm327.lua"], encoding="utf-8")
    reply = b"41 0C 1A F8 \r\r>"
    lines = ["# serialspec capture: elm327"]
    lines += [f"2026-11-25T10:00:00.000000+00:00 response {p.hex(' ')}" for p in (reply, b"\r\r", b">", reply)]
    (tmp_path / "t.capture").write_text("\n".join(lines) + "\n", encoding="utf-8")
    assert cli.main(["export", str(tmp_path / "t.capture"), "--pcap", str(tmp_path / "t.pcap")]) == 0
    xml = run(TSHARK or "", "-X", f"lua_script:{tmp_path / 'elm327.lua'}", "-r", str(tmp_path / "t.pcap"), "-T", "pdml")
    fields = [(f.get("command"), f["fields"]) for f in sentences(xml, "elm327")]
    assert fields == [("engine_rpm", [("a", "1A"), ("b", "F8")])] * 2, fields
    assert not [
        f for f in ET.fromstring(xml).iter("field") if f.get("name") in ("elm327.incomplete", "elm327.malformed")
    ]
