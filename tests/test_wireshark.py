"""The Wireshark dissectors, run by tshark as a user would: `serialspec generate --target wireshark`, a capture
exported with `serialspec export --pcap`, every shipped spec's example frames shown with the command and field values
`serialspec decode --json` gives, several frames a packet, bad checksums flagged."""

from __future__ import annotations

import contextlib
import datetime
import io
import json
import math
import re
import shlex
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest
from conftest import ALL, ROOT, Generated, examples, fitted, requests
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from serialspec import cli
from serialspec.cli.decode import describe
from serialspec.lang.model import (
    Array,
    Bytes,
    Field,
    Group,
    List,
    Message,
    Packed,
    Protocol,
    Scalar,
    TableBlock,
    TableValue,
    Text,
    Varint,
)
from strategies import message_fields

pytestmark = pytest.mark.slow
TSHARK = shutil.which("tshark")
SERIALSPEC = [sys.executable, "-m", "serialspec"]


# the specs the Wireshark target takes: every shipped one (replies read with their request, RoboClaw's, with the last
# request before them in the capture)
DISSECTED = ALL


def run(*args: str) -> str:
    done = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return done.stdout


def decoded(protocol: Protocol, direction: str, frames: list[bytes], request: bytes = b"") -> list[dict[str, Any]]:
    """`serialspec decode SPEC --json --direction D [--request HEX] HEX...`, run in this process (the CLI's own
    code)."""
    spec = str(ROOT / protocol.spec_path)
    out = io.StringIO()
    asked = ["--request", request.hex(" ")] if request else []
    with contextlib.redirect_stdout(out):
        assert (
            cli.main(["decode", spec, "--json", "--direction", direction, *asked, *(f.hex(" ") for f in frames)]) == 0
        )
    return [json.loads(line) for line in out.getvalue().splitlines()]


def example_frames(protocol: Protocol) -> dict[str, list[bytes]]:
    """Every example frame of the spec by direction, those the codec decodes (erratum examples as printed do not);
    not the replies read with their request (see answered_examples)."""
    frames: dict[str, list[bytes]] = {"request": [], "response": []}
    for example in protocol.examples:
        if example.erratum or (example.direction.value == "response" and protocol.framing.requesting):
            continue
        if example.frame not in frames[example.direction.value]:
            frames[example.direction.value].append(example.frame)
    return frames


def answered_examples(protocol: Protocol) -> list[tuple[bytes, bytes]]:
    """(request, reply) of each example reply read with the request it answers (its `request:` example)."""
    frames = {example.name: example.frame for example in protocol.examples}
    found = [
        (frames[example.request], example.frame)
        for example in protocol.examples
        if example.direction.value == "response" and protocol.framing.requesting and not example.erratum
    ]
    assert all(request for request, _ in found), "an example reply read with its request names no request"
    return found


def pdml_frames(xml: str) -> list[ET.Element]:
    """Every frame the dissectors found, in order: the protocol trees after each packet's serialspec header."""
    names = {g.protocol.name for g in ALL}
    return [proto for packet in ET.fromstring(xml).iter("packet") for proto in packet if proto.get("name") in names]


def children(element: ET.Element, name: str) -> list[ET.Element]:
    return [child for child in element if child.get("name") == name]


def child(element: ET.Element, name: str) -> ET.Element:
    found = children(element, name)
    assert len(found) == 1, f"{name}: {len(found)} in {ET.tostring(element, encoding='unicode')[:2000]}"
    return found[0]


def number(text: str) -> int | float:
    """An integer exactly (a 64-bit one passes a float's 53 bits), else a float."""
    try:
        return int(text)
    except ValueError:
        return float(text)


def value(field: Field, shown: ET.Element, abbr: str) -> Any:
    """A field's value as the dissector shows it, in `decode --json`'s form."""
    match field:
        case Scalar():
            if field.bits:
                return {b.name: int(child(shown, f"{abbr}.{b.name}").get("show") or 0) for b in field.bits}
            return number(shown.get("show") or "")
        case Varint():
            return int(shown.get("show") or "")
        case Array() | List() | Packed():
            items = children(shown, f"{abbr}.value")
            if isinstance(field, List) and field.item is None:
                return [item.get("show") == "1" for item in items]
            return [number(item.get("show") or "") for item in items]
        case Text():
            return text_of(field, shown)
        case Bytes():
            data = bytes.fromhex(shown.get("value") or "")
            return data.hex(" ")
        case Group():
            return [fields_of(field.fields, item, abbr) for item in children(shown, f"{abbr}.item")]
        case TableValue():
            return number(shown.get("show") or "")
        case TableBlock():
            return {e.name: number(child(shown, f"{abbr}.{e.name}").get("show") or "") for e in field.entries}
    raise AssertionError(field)


def text_of(field: Text, shown: ET.Element) -> str:
    """A text as shown; where it holds a line break or a tab, as its bytes say (XML reads those in an attribute as
    spaces)."""
    text = shown.get("show") or ""
    raw = bytes.fromhex(shown.get("value") or "")
    raw = raw[:-1] if field.size is None else raw  # (a NUL-terminated text: its NUL)
    raw = raw.rstrip(bytes([field.pad])) if field.pad is not None else raw
    exact = raw.decode("latin-1")
    return exact if not field.seven_bit and exact.translate({9: 32, 10: 32, 13: 32}) == text else text


def fields_of(fields: tuple[Field, ...], tree: ET.Element, prefix: str) -> dict[str, Any]:
    return {
        f.name: value(f, child(tree, f"{prefix}.{f.name}"), f"{prefix}.{f.name}")
        for f in fields
        if not (isinstance(f, Scalar) and f.hidden)
    }


def message_of(protocol: Protocol, direction: str, command: str, subcommand: str | None) -> Message:
    return next(
        m
        for m in protocol.messages()
        if (m.command, m.subcommand, m.direction.value) == (command, subcommand, direction)
    )


def shown(protocol: Protocol, tree: ET.Element) -> dict[str, Any]:
    """What the dissector shows of one frame, as `decode --json` puts it."""
    name = protocol.name
    direction = child(tree, f"{name}.direction").get("show") or ""
    command = child(tree, f"{name}.command").get("show") or ""
    subs = children(tree, f"{name}.subcommand")
    subcommand = subs[0].get("show") if subs else None
    message = message_of(protocol, direction, command, subcommand)
    prefix = ".".join(p for p in (name, command, subcommand, direction) if p)
    fields: dict[str, Any] = {}
    partial = protocol.framing.partial_values(message.direction)
    for element in protocol.layout(message).value_elements:  # its own layout's (layouts chosen by command)
        if element.name in partial and not children(tree, f"{name}.frame.{element.name}"):
            fields[element.name] = None  # a frame value its frame's layout does not carry (the compact form's)
        elif element.bits:
            item = child(tree, f"{name}.frame.{element.name}")
            fields[element.name] = {
                b.name: int(child(item, f"{name}.frame.{element.name}.{b.name}").get("show") or 0) for b in element.bits
            }
        else:
            fields[element.name] = int(child(tree, f"{name}.frame.{element.name}").get("show") or "")
    if message.error_reply and protocol.error_reply:
        refused = protocol.error_reply.element
        fields[refused] = int(child(tree, f"{prefix}.{refused}").get("show") or "")
    fields.update(fields_of(message.fields, tree, prefix))
    for element in protocol.layout(message).optional:  # its bytes where the frame has them
        sent = children(tree, f"{name}.frame.{element.name}")
        fields[element.name] = bytes.fromhex(sent[0].get("value") or "").hex(" ") if sent else None
    verdict = children(tree, f"{name}.checksum_ok")  # none where the frame has no checksum
    checksum_ok = verdict[0].get("show") == "1" if verdict else None
    return {
        "direction": direction,
        "command": command,
        "subcommand": subcommand,
        "fields": fields,
        "checksum_ok": checksum_ok,
    }


@pytest.mark.skipif(
    TSHARK is None, reason="tshark is not installed (make generate installs it where it can: root and apt-get)"
)
def test_tshark_shows_every_example_frame_as_decode_json_does(tmp_path: Path) -> None:
    """(A spec the target refuses is shown refused in one line by the random-messages test below.)"""
    assert TSHARK is not None
    specs = [str(ROOT / g.protocol.spec_path) for g in DISSECTED]
    run(*SERIALSPEC, "generate", *specs, "--target", "wireshark", "--out", str(tmp_path / "out"))
    captures = []
    wanted: list[dict[str, Any]] = []
    moment = datetime.datetime(2026, 11, 25, 10, tzinfo=datetime.UTC)
    for g in DISSECTED:
        protocol = g.protocol
        capture = [f"# serialspec capture: {protocol.name}"]
        for direction, frames in example_frames(protocol).items():
            if not frames:
                continue
            results = decoded(protocol, direction, frames)
            assert len(results) == len(frames)
            # one frame a packet, then all of them in one packet
            for data in [*frames, b"".join(frames)]:
                moment += datetime.timedelta(milliseconds=1)
                capture.append(f"{moment.isoformat(timespec='microseconds')} {direction} {data.hex(' ')}")
            wanted += [{"protocol": protocol.name, **r} for r in results] * 2
        for request, reply in answered_examples(protocol):  # each reply after its request, read with it
            for direction, data, results in (
                ("request", request, decoded(protocol, "request", [request])),
                ("response", reply, decoded(protocol, "response", [reply], request)),
            ):
                moment += datetime.timedelta(milliseconds=1)
                capture.append(f"{moment.isoformat(timespec='microseconds')} {direction} {data.hex(' ')}")
                wanted += [{"protocol": protocol.name, **r} for r in results]
        path = tmp_path / f"{protocol.name}.capture"
        path.write_text("\n".join(capture) + "\n", encoding="utf-8")
        captures.append(str(path))
    # every spec's capture in one pcap, read by one tshark with every dissector loaded (they share the link type)
    run(*SERIALSPEC, "export", *captures, "--pcap", str(tmp_path / "examples.pcap"))
    scripts = [f"lua_script:{tmp_path / 'out' / g.protocol.name / f'{g.protocol.name}.lua'}" for g in DISSECTED]
    options = [word for script in scripts for word in ("-X", script)]
    trees = pdml_frames(run(TSHARK, *options, "-r", str(tmp_path / "examples.pcap"), "-T", "pdml"))
    assert len(trees) == len(wanted)
    protocols = {g.protocol.name: g.protocol for g in DISSECTED}
    for tree, expected in zip(trees, wanted, strict=True):
        seen = shown(protocols[expected["protocol"]], tree)
        assert seen == {key: expected[key] for key in seen}, expected["hex"]
    assert sum(len(example_frames(g.protocol)["request"]) for g in DISSECTED) > 50


@pytest.mark.skipif(
    TSHARK is None, reason="tshark is not installed (make generate installs it where it can: root and apt-get)"
)
def test_tshark_flags_a_bad_checksum_bytes_outside_frames_and_a_short_content(tmp_path: Path) -> None:
    assert TSHARK is not None
    spec = str(ROOT / "specs" / "fashionstar_uart.yaml")
    run(*SERIALSPEC, "generate", spec, "--target", "wireshark", "--out", str(tmp_path))
    capture = tmp_path / "bad.capture"
    capture.write_text(
        "# serialspec capture: fashionstar_uart\n"
        "2026-11-25T10:00:00.000000+00:00 request 12 4c 01 01 03 64 99 12 4c 01 01 03 63\n"
        "2026-11-25T10:00:01.000000+00:00 request 12 4c 08 01 02 69\n",  # a ROTATE of one byte: its sum is right
        encoding="utf-8",
    )
    run(*SERIALSPEC, "export", str(capture), "--pcap", str(tmp_path / "bad.pcap"))
    script = f"lua_script:{tmp_path / 'fashionstar_uart' / 'fashionstar_uart.lua'}"
    out = run(TSHARK, "-X", script, "-r", str(tmp_path / "bad.pcap"), "-V")
    assert "checksum: 0x64 [incorrect, should be 0x63]" in out
    assert "Bytes outside any frame: 99" in out
    assert out.count("request ping") == 2
    assert "[angle: 2 byte(s) needed at offset 1, the content has 1]" in out
    fields = run(
        TSHARK, "-X", script, "-r", str(tmp_path / "bad.pcap"), "-T", "fields", "-e", "fashionstar_uart.checksum_ok"
    )
    assert fields.split() == ["0,1", "1"]


@pytest.mark.skipif(
    TSHARK is None, reason="tshark is not installed (make generate installs it where it can: root and apt-get)"
)
def test_the_readme_wireshark_commands_show_what_the_readme_shows(tmp_path: Path) -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme[readme.index("**Captures in Wireshark.**") :]
    section = section[: section.index("\n## ")]
    console = re.findall(r"```console\n(.*?)```", section, flags=re.S)[0].splitlines()
    script = re.findall(r"```sh\n(.*?)```", section, flags=re.S)[0].splitlines()
    shown = re.findall(r"```text\n(.*?)```", section, flags=re.S)[0].splitlines()
    shutil.copytree(ROOT / "specs", tmp_path / "specs")
    shutil.copytree(ROOT / "examples" / "captures", tmp_path / "examples" / "captures")
    commands = [line.removeprefix("$ ") for line in console if line.startswith("$ ")] + script
    out = ""
    for command in commands:
        words = shlex.split(command)
        words = [*SERIALSPEC, *words[1:]] if words[0] == ".venv/bin/serialspec" else words
        done = subprocess.run(words, cwd=tmp_path, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, (command, done.stderr)
        out = done.stdout
    assert console[1] == "9 packet(s) written to build/fashionstar_session.pcap"
    lines = out.splitlines()
    start = lines.index(shown[0])
    assert lines[start : start + len(shown)] == shown, out


@pytest.mark.skipif(
    TSHARK is None, reason="tshark is not installed (make generate installs it where it can: root and apt-get)"
)
def test_a_frame_cut_between_packets_is_shown_whole_where_it_ends(tmp_path: Path) -> None:
    assert TSHARK is not None
    spec = str(ROOT / "specs" / "fashionstar_uart.yaml")
    run(*SERIALSPEC, "generate", spec, "--target", "wireshark", "--out", str(tmp_path))
    capture = tmp_path / "cut.capture"
    capture.write_text(  # a ROTATE in two chunks, a reply between them (the other direction), then a PING
        "# serialspec capture: fashionstar_uart\n"
        "2026-11-25T10:00:00.000000+00:00 request 12 4c 08 07 02\n"
        "2026-11-25T10:00:00.000100+00:00 response 05 1c 0a 03 00 86 03 b7\n"
        "2026-11-25T10:00:00.000200+00:00 request 84 03 f4 01 00 00 eb 12 4c 01\n"
        "2026-11-25T10:00:00.000300+00:00 request 01 03 63\n",
        encoding="utf-8",
    )
    run(*SERIALSPEC, "export", str(capture), "--pcap", str(tmp_path / "cut.pcap"))
    script = f"lua_script:{tmp_path / 'fashionstar_uart' / 'fashionstar_uart.lua'}"
    fields = ["-e", "fashionstar_uart.command", "-e", "fashionstar_uart.rotate.request.angle"]
    out = run(TSHARK, "-X", script, "-r", str(tmp_path / "cut.pcap"), "-T", "fields", *fields)
    assert out.splitlines() == ["\t", "read_angle\t", "rotate\t900", "ping\t"]


def same(seen: Any, wanted: Any) -> bool:
    """Equal, floats to the 6 significant digits Wireshark shows of a float32."""
    if isinstance(wanted, float):
        return isinstance(seen, int | float) and math.isclose(seen, wanted, rel_tol=5e-6, abs_tol=1e-37)
    if isinstance(wanted, dict):
        return isinstance(seen, dict) and seen.keys() == wanted.keys() and all(same(seen[k], wanted[k]) for k in wanted)
    if isinstance(wanted, list):
        return isinstance(seen, list) and len(seen) == len(wanted) and all(map(same, seen, wanted))
    return bool(seen == wanted)


@pytest.mark.skipif(
    TSHARK is None, reason="tshark is not installed (make generate installs it where it can: root and apt-get)"
)
@pytest.mark.parametrize("g", ALL, ids=[g.protocol.name for g in ALL])
def test_tshark_shows_random_messages_of_every_command_as_decode_does(g: Generated, tmp_path: Path) -> None:
    """Every message of the spec with random valid fields (stuffed bytes, groups, lists, texts, table values), all
    in one capture: tshark shows what the codec decodes."""
    assert TSHARK is not None
    protocol = g.protocol
    run(*SERIALSPEC, "generate", str(ROOT / protocol.spec_path), "--target", "wireshark", "--out", str(tmp_path))
    script = f"lua_script:{tmp_path / protocol.name / f'{protocol.name}.lua'}"
    specs = [m for m in protocol.messages() if not m.unsolicited or m.direction.value == "response"]

    # no shrinking: each example runs tshark (a failure shows its frame and both views); two messages of each
    # command in one capture, as one tshark run costs more than all the decoding
    @settings(
        max_examples=examples(1),
        deadline=None,
        suppress_health_check=list(HealthCheck),
        phases=(Phase.explicit, Phase.reuse, Phase.generate),
    )
    @given(st.data())
    def shown_as_decoded(data: st.DataObject) -> None:
        lines = [f"# serialspec capture: {protocol.name}"]
        wanted = []
        for spec in specs * 2:
            cls = next(c for c in g.package.MESSAGE_TYPES if c.__name__ == spec.class_name)
            request = data.draw(requests(g, spec), label=f"{spec.key} answers")
            if request is not None:  # a reply read with its request: the request before it in the capture
                asked = g.package.encode(request)
                wanted.append(describe(protocol, g.package.decode(asked, "request"), asked, False, None))
                lines.append(f"2026-11-25T10:00:00.000000+00:00 request {asked.hex(' ')}")
            message = cls.from_fields(fitted(spec, data.draw(message_fields(protocol, spec), label=spec.key), request))
            frame = g.package.encode(message) if request is None else g.package.encode(message, request)
            if request is None:
                message = g.package.decode(frame, spec.direction.value)  # as a frame without its request decodes
            else:
                message = g.package.decode(frame, spec.direction.value, request=request)
            wanted.append(describe(protocol, message, frame, False, None))
            lines.append(f"2026-11-25T10:00:00.000000+00:00 {spec.direction.value} {frame.hex(' ')}")
        (tmp_path / "random.capture").write_text("\n".join(lines) + "\n", encoding="utf-8")
        run(*SERIALSPEC, "export", str(tmp_path / "random.capture"), "--pcap", str(tmp_path / "random.pcap"))
        trees = pdml_frames(run(TSHARK, "-X", script, "-r", str(tmp_path / "random.pcap"), "-T", "pdml"))
        assert len(trees) == len(wanted)
        for tree, expected in zip(trees, wanted, strict=True):
            seen = shown(protocol, tree)
            assert same(seen, {key: expected[key] for key in seen}), (expected["hex"], seen, expected)

    shown_as_decoded()


def through_tshark(tmp_path: Path, specs: list[str], corrupt: bool = False, twice: bool = False) -> None:
    """Specs (YAML texts, each its own protocol and dissector, all loaded in one tshark): a random message of every
    command and direction, shown as decoded; with `corrupt`, each also with its last byte changed, flagged bad; with
    `twice`, each frame twice in one packet (two frames found in it)."""
    assert TSHARK is not None
    from serialspec.backends.python import files as python_files
    from serialspec.backends.python.memory import imported
    from serialspec.backends.wireshark.dissector import emit_dissector
    from serialspec.lang.loader import load_text
    from serialspec.lang.resolve import resolve

    with contextlib.ExitStack() as stack:
        built: list[tuple[Protocol, Any]] = []
        for text in specs:
            protocol = resolve(load_text(text, "case.yaml"))
            modules = {path.split("/", 1)[1]: code for path, code in python_files(protocol).items()}
            built.append((protocol, stack.enter_context(imported(protocol.name, modules, "a tshark case"))))
            (tmp_path / f"{protocol.name}.lua").write_text(emit_dissector(protocol), encoding="utf-8")
        options = [word for protocol, _ in built for word in ("-X", f"lua_script:{tmp_path / protocol.name}.lua")]

        @settings(
            max_examples=examples(1),
            deadline=None,
            suppress_health_check=list(HealthCheck),
            phases=(Phase.explicit, Phase.reuse, Phase.generate),
        )
        @given(st.data())
        def shown_as_decoded(data: st.DataObject) -> None:
            captures, wanted = [], []
            for protocol, package in built:
                lines = [f"# serialspec capture: {protocol.name}"]
                g = Generated(protocol, package, package)
                for spec in protocol.messages():
                    cls = next(c for c in package.MESSAGE_TYPES if c.__name__ == spec.class_name)
                    fields = data.draw(message_fields(protocol, spec), label=f"{protocol.title} {spec.key}")
                    request = data.draw(requests(g, spec), label=f"{protocol.title} {spec.key} answers")
                    fields = fitted(spec, fields, request)
                    if request is not None:  # a reply read with its request: the request before it in the capture
                        asked = package.encode(request)
                        wanted.append(
                            (protocol, describe(protocol, package.decode(asked, "request"), asked, False, None))
                        )
                        lines.append(f"2026-11-25T10:00:00.000000+00:00 request {asked.hex(' ')}")
                    if request is None:
                        frame = package.encode(cls.from_fields(fields))
                        message = package.decode(frame, spec.direction.value)
                    else:
                        frame = package.encode(cls.from_fields(fields), request)
                        message = package.decode(frame, spec.direction.value, request=request)
                    wanted.append((protocol, describe(protocol, message, frame, False, None)))
                    if twice:
                        wanted.append(wanted[-1])
                    packet = frame + frame if twice else frame
                    lines.append(f"2026-11-25T10:00:00.000000+00:00 {spec.direction.value} {packet.hex(' ')}")
                    if corrupt:
                        bad = frame[:-1] + bytes([frame[-1] ^ 0x5A])
                        wanted.append((protocol, {**wanted[-1][1], "checksum_ok": False, "hex": bad.hex(" ")}))
                        lines.append(f"2026-11-25T10:00:00.000000+00:00 {spec.direction.value} {bad.hex(' ')}")
                (tmp_path / f"{protocol.name}.capture").write_text("\n".join(lines) + "\n", encoding="utf-8")
                captures.append(str(tmp_path / f"{protocol.name}.capture"))
            run(*SERIALSPEC, "export", *captures, "--pcap", str(tmp_path / "cases.pcap"))
            xml = run(TSHARK, *options, "-r", str(tmp_path / "cases.pcap"), "-T", "pdml")
            names = {protocol.name for protocol, _ in built}
            trees = [
                proto for packet in ET.fromstring(xml).iter("packet") for proto in packet if proto.get("name") in names
            ]
            assert [t.get("name") for t in trees] == [protocol.name for protocol, _ in wanted]
            for tree, (protocol, expected) in zip(trees, wanted, strict=True):
                seen = shown(protocol, tree)
                assert same(seen, {key: expected[key] for key in seen}), (protocol.title, expected["hex"], seen)

        shown_as_decoded()


@pytest.mark.skipif(
    TSHARK is None, reason="tshark is not installed (make generate installs it where it can: root and apt-get)"
)
def test_tshark_shows_every_language_matrix_case_as_decode_does(tmp_path: Path) -> None:
    """Every alternative the language documents (tests/test_language_matrix.py's cases)."""
    from test_language_matrix import CASES, KNOWN, WIRESHARK_REFUSES, spec_text

    # a case the Wireshark target refuses in one line (the matrix checks that line) has no dissector to run
    names = [name for name in sorted(CASES) if name not in KNOWN and name not in WIRESHARK_REFUSES]
    specs = [
        spec_text(name, CASES[name]).replace("protocol: matrix_case", f"protocol: matrix_{number}")
        for number, name in enumerate(names)
    ]
    through_tshark(tmp_path, specs)


@pytest.mark.skipif(
    TSHARK is None, reason="tshark is not installed (make generate installs it where it can: root and apt-get)"
)
def test_tshark_finds_two_frames_in_a_packet_of_every_transform_and_terminator(tmp_path: Path) -> None:
    """Frames sized through a transform (serialspec/transforms/) or ended by a delimiter: two in one packet are two
    frames, not one (the dissector sizes each as the stream parser does)."""
    from test_language_matrix import CASES, spec_text

    names = [name for name in sorted(CASES) if name.startswith(("transform: ", "frame: ended by", "frame: transp"))]
    specs = [
        spec_text(name, CASES[name]).replace("protocol: matrix_case", f"protocol: twice_{number}")
        for number, name in enumerate(names)
    ]
    through_tshark(tmp_path, specs, twice=True)


@pytest.mark.skipif(
    TSHARK is None, reason="tshark is not installed (make generate installs it where it can: root and apt-get)"
)
def test_tshark_verifies_every_checksum_algorithm(tmp_path: Path) -> None:
    """Every registered checksum algorithm with each documented option (tests/test_matrix.py's cases): right frames
    pass, a frame with its last byte changed is flagged."""
    from serialspec.checksums import algorithms
    from test_matrix import SHAPES, spec_text

    specs = [
        spec_text(f"checksum_{name}_{index}_{shape}", name, sample, shape)
        for name, algorithm in algorithms().items()
        for index, sample in enumerate(algorithm.samples)
        for shape in SHAPES
    ]
    through_tshark(tmp_path, specs, corrupt=True)


@pytest.mark.skipif(
    TSHARK is None, reason="tshark is not installed (make generate installs it where it can: root and apt-get)"
)
def test_tshark_reads_both_forms_of_the_same_commands(tmp_path: Path) -> None:
    """A headerless layout beside one whose command element sends `code & 0x7F` after a header (the Maestro's
    compact and Pololu forms, tests/test_code_forms.py): each frame, alone or all in one packet, shown as decoded."""
    assert TSHARK is not None
    from serialspec.lang import load_protocol
    from test_code_forms import FRAMES, SPEC, write

    path = write(tmp_path, SPEC)
    protocol = load_protocol(path)
    run(*SERIALSPEC, "generate", str(path), "--target", "wireshark", "--out", str(tmp_path / "out"))
    frames = [bytes.fromhex(printed) for printed, _ in FRAMES]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert cli.main(["decode", str(path), "--json", "--direction", "request", *(f.hex(" ") for f in frames)]) == 0
    results = [json.loads(line) for line in out.getvalue().splitlines()]
    lines = [f"# serialspec capture: {protocol.name}"]
    lines += [f"2026-11-25T10:00:00.000000+00:00 request {data.hex(' ')}" for data in [*frames, b"".join(frames)]]
    (tmp_path / "forms.capture").write_text("\n".join(lines) + "\n", encoding="utf-8")
    run(*SERIALSPEC, "export", str(tmp_path / "forms.capture"), "--pcap", str(tmp_path / "forms.pcap"))
    script = f"lua_script:{tmp_path / 'out' / protocol.name / f'{protocol.name}.lua'}"
    xml = run(TSHARK, "-X", script, "-r", str(tmp_path / "forms.pcap"), "-T", "pdml")
    trees = [
        proto for packet in ET.fromstring(xml).iter("packet") for proto in packet if proto.get("name") == "two_forms"
    ]
    assert len(trees) == 2 * len(results)
    for tree, expected in zip(trees, results * 2, strict=True):
        seen = shown(protocol, tree)
        assert seen == {key: expected[key] for key in seen}, expected["hex"]
    bad = tmp_path / "bad.capture"  # AA before a code the Pololu form does not send (bit 7 set): no Pololu frame
    bad.write_text(f"# serialspec capture: {protocol.name}\n2026-11-25T10:00:00.000000+00:00 request aa 84 02 70 2e\n")
    run(*SERIALSPEC, "export", str(bad), "--pcap", str(tmp_path / "bad.pcap"))
    said = run(TSHARK, "-X", script, "-r", str(tmp_path / "bad.pcap"), "-V")
    assert "Bytes outside any frame: aa" in said and "request set_target" in said, said


@pytest.mark.skipif(
    TSHARK is None, reason="tshark is not installed (make generate installs it where it can: root and apt-get)"
)
def test_tshark_reads_a_refusal_in_a_layout_of_its_own_after_its_request(tmp_path: Path) -> None:
    """The STM32 bootloader refuses a request with a NACK (`1F`), a layout of its own that the request's `refused_by`
    names: after the request it is shown as the NACK, not as bytes outside any frame; the reply itself still is the
    reply."""
    assert TSHARK is not None
    spec = str(ROOT / "tests" / "specs" / "stm32_bootloader.yaml")
    run(*SERIALSPEC, "generate", spec, "--target", "wireshark", "--out", str(tmp_path))
    capture = tmp_path / "refused.capture"
    capture.write_text(
        "# serialspec capture: stm32_bootloader\n"
        "2026-11-25T10:00:00.000000+00:00 request 02 fd\n"
        "2026-11-25T10:00:00.000100+00:00 response 1f\n"
        "2026-11-25T10:00:00.000200+00:00 request 02 fd\n"
        "2026-11-25T10:00:00.000300+00:00 response 79 01 04 10 79\n",
        encoding="utf-8",
    )
    run(*SERIALSPEC, "export", str(capture), "--pcap", str(tmp_path / "refused.pcap"))
    script = f"lua_script:{tmp_path / 'stm32_bootloader' / 'stm32_bootloader.lua'}"
    shown = run(TSHARK, "-X", script, "-r", str(tmp_path / "refused.pcap"), "-T", "fields", "-e", "_ws.col.Info")
    assert shown.split() == ["get_id", "nack", "get_id", "get_id"], shown


@pytest.mark.skipif(
    TSHARK is None, reason="tshark is not installed (make generate installs it where it can: root and apt-get)"
)
def test_tshark_reads_a_reply_with_the_request_before_it(tmp_path: Path) -> None:
    """RoboClaw's replies carry no code and their CRC starts with the request's address and command: a reply before
    any request is one clear note (not garbage, not a guess); after its request it is read in the request's layout,
    its CRC verified over the request's bytes (a wrong one flagged), a write's bare 0xFF read as its acknowledgement."""
    assert TSHARK is not None
    spec = str(ROOT / "specs" / "roboclaw.yaml")
    run(*SERIALSPEC, "generate", spec, "--target", "wireshark", "--out", str(tmp_path))
    capture = tmp_path / "asked.capture"
    capture.write_text(
        "# serialspec capture: roboclaw\n"
        "2026-11-25T10:00:00.000000+00:00 response 00 78 c8 65\n"
        "2026-11-25T10:00:00.000100+00:00 request 80 18\n"
        "2026-11-25T10:00:00.000200+00:00 response 00 78 c8 66\n"
        "2026-11-25T10:00:00.000300+00:00 request 81 18\n"  # another address: another CRC
        "2026-11-25T10:00:00.000400+00:00 response 00 78 c8 65\n"
        "2026-11-25T10:00:00.000500+00:00 request 80 20 c0 00 4d aa\n"
        "2026-11-25T10:00:00.000600+00:00 response ff\n",
        encoding="utf-8",
    )
    run(*SERIALSPEC, "export", str(capture), "--pcap", str(tmp_path / "asked.pcap"))
    script = f"lua_script:{tmp_path / 'roboclaw' / 'roboclaw.lua'}"
    out = run(TSHARK, "-X", script, "-r", str(tmp_path / "asked.pcap"), "-V")
    assert "4 byte(s) read in the layout of the request they answer; the request is not in the capture" in out
    assert "[Request not in capture]" in out
    assert out.count("crc: 0xc866 [incorrect, should be 0xc865]") == 1
    assert out.count("crc: 0xc865 [incorrect, should be ") == 1  # (81 18 gives another CRC)
    fields = [
        "-e",
        "roboclaw.command",
        "-e",
        "roboclaw.read_main_battery.response.voltage",
        "-e",
        "roboclaw.checksum_ok",
    ]
    shown = run(TSHARK, "-X", script, "-r", str(tmp_path / "asked.pcap"), "-T", "fields", *fields)
    assert shown.splitlines() == [
        "\t\t",
        "read_main_battery\t\t",
        "read_main_battery\t120\t0",
        "read_main_battery\t\t",
        "read_main_battery\t120\t0",
        "duty_m1\t\t1",
        "duty_m1\t\t",
    ], shown
