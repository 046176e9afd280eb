"""The Wireshark dissector of a text protocol, run by tshark as a user would: `serialspec generate --target
wireshark`, a capture of random sentences of every message (several in a packet, one cut across two packets, one
with a bad checksum) exported with `serialspec export --pcap`; tshark shows each sentence's command, talker and
fields as the texts `runtime/text.py` decodes (what `serialspec decode --json` prints), the bad checksum flagged."""

from __future__ import annotations

import shutil
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from test_c_text import CLI, NAMES, SPECS, built, python_json
from test_text_frames import sentence_values

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


# the C's text specs, the every-kind case with the ending the dissector takes (the C's ends in FF FF FF)
DISSECTED = [name if name != "c_text_matrix" else "wireshark_text_matrix" for name in NAMES]


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
            values = data.draw(sentence_values(s))
            frame = b.framing.encode(s.code, values, data.draw(st.sampled_from(talkers)), direction=s.direction)
            frames.append((s.direction, frame))
            wanted.append(python_json(b, b.framing.decode(frame, s.direction)) | {"checksum_ok": True})
        direction, last = frames[-1]
        bad = bytearray(last)
        marker = bad.rfind(b.framing.marker.encode())
        bad[marker + 1 : marker + 3] = b"ZZ" if b.framing.checksum is not None else bad[marker + 1 : marker + 3]
        packets = [(d, f) for d, f in frames[:-1]]
        packets.append((direction, last[:5]))  # a sentence cut across two packets
        packets.append((direction, last[5:] + bytes(bad)))  # and a second one in the same packet
        if b.framing.checksum is not None:
            wanted.append(wanted[-1] | {"checksum_ok": False})
        for d, data_ in packets:
            lines.append(f"2026-11-25T10:00:00.000000+00:00 {d} {data_.hex(' ')}")
        (tmp_path / "t.capture").write_text("\n".join(lines) + "\n", encoding="utf-8")
        run(*CLI, "export", str(tmp_path / "t.capture"), "--pcap", str(tmp_path / "t.pcap"))
        seen = sentences(run(TSHARK, "-X", script, "-r", str(tmp_path / "t.pcap"), "-T", "pdml"), name)
        assert len(seen) == len(wanted)
        for got, expected in zip(seen, wanted, strict=True):
            assert got["command"] == expected["command"] and got["direction"] == expected["direction"]
            assert got.get("talker", "") == expected["talker"]
            assert got["fields"] == flat(expected["fields"]), (got, expected)
            if b.framing.checksum is not None:
                assert (got["checksum_ok"] in ("1", "True")) == expected["checksum_ok"], got

    shown_as_decoded()
