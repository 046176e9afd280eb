"""The same commands in two frame forms: a layout without a header beside one with a header, and a command element
whose wire value is an expression of the command's code in one layout (`code: "code & 0x7F"`, the Pololu Maestro's
Pololu protocol beside its compact protocol). A frame is told by its first bytes: a header's layout, else the
headerless one; each mistake in such a spec is one line at its place."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
import yaml
from conftest import examples, generate_and_import
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.lang import SpecErrors, load_protocol
from serialspec.runtime.errors import DecodeError

SPEC: dict[str, Any] = {
    "protocol": "two_forms",
    "title": "Two frame forms of the same commands",
    "byte_order": "little",
    "serial": {"baudrate": 9600},
    "framing": {
        "layouts": {
            "compact": {
                "elements": {
                    "command": {"role": "command", "type": "u8", "directions": ["request"]},
                    "content": {"role": "content"},
                }
            },
            "pololu": {
                "elements": {
                    "start": {"role": "header", "value": "AA", "directions": ["request"]},
                    "command": {"role": "command", "type": "u8", "directions": ["request"], "code": "code & 0x7F"},
                    "content": {"role": "content"},
                }
            },
        }
    },
    "commands": {
        "set_target": {"code": 0x84, "request": {"fields": {"channel": "u8", "low": "u8", "high": "u8"}}},
        "get_position": {"code": 0x90, "request": {"fields": {"channel": "u8"}}},
        "go_home": {"code": 0xA2, "request": {"fields": {}}},
    },
}


def write(tmp_path: Path, data: dict[str, Any]) -> Path:
    path = tmp_path / f"{data['protocol']}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), "utf-8")
    return path


@pytest.fixture(scope="module")
def forms(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    folder = tmp_path_factory.mktemp("forms")
    return generate_and_import(write(folder, SPEC), folder / "out", "two_forms")


def test_both_forms_decode_to_one_message(forms: ModuleType) -> None:
    message = forms.SetTargetRequest(channel=2, low=0x70, high=0x2E)
    assert forms.decode(bytes.fromhex("84 02 70 2e"), forms.Direction.REQUEST) == message
    assert forms.decode(bytes.fromhex("aa 04 02 70 2e"), forms.Direction.REQUEST) == message
    assert forms.encode(message) == bytes.fromhex("84 02 70 2e")  # the first layout that holds it
    assert forms.decode(bytes.fromhex("aa 22"), forms.Direction.REQUEST) == forms.GoHomeRequest()


def test_a_code_the_layout_does_not_send_is_refused_in_one_line(forms: ModuleType) -> None:
    with pytest.raises(DecodeError, match=r"^command = 0x84 is no code of the pololu frame$"):
        forms.decode(bytes.fromhex("aa 84 02 70 2e"), forms.Direction.REQUEST)
    with pytest.raises(DecodeError, match="unknown command 0x04"):
        forms.decode(bytes.fromhex("04 02 70 2e"), forms.Direction.REQUEST)


FRAMES = [
    ("84 02 70 2e", ("SetTargetRequest", {"channel": 2, "low": 0x70, "high": 0x2E})),
    ("aa 04 05 01 02", ("SetTargetRequest", {"channel": 5, "low": 1, "high": 2})),
    ("90 03", ("GetPositionRequest", {"channel": 3})),
    ("aa 10 07", ("GetPositionRequest", {"channel": 7})),
    ("a2", ("GoHomeRequest", {})),
    ("aa 22", ("GoHomeRequest", {})),
]


@settings(max_examples=15, deadline=None)
@given(
    order=st.lists(st.sampled_from(range(len(FRAMES))), min_size=1, max_size=6),
    cuts=st.lists(st.integers(1, 4), max_size=12),
)
def test_the_stream_parser_reads_both_forms_however_split(forms: ModuleType, order: list[int], cuts: list[int]) -> None:
    stream = b"".join(bytes.fromhex(FRAMES[i][0]) for i in order)
    parser = forms.StreamParser(forms.Direction.REQUEST)
    found, position = [], 0
    for cut in [*cuts, len(stream)]:
        found += parser.feed(stream[position : position + cut])
        position += cut
    expected = [getattr(forms, FRAMES[i][1][0])(**FRAMES[i][1][1]) for i in order]
    assert found == expected


def errors_of(tmp_path: Path, change: Any) -> list[str]:
    data = copy.deepcopy(SPEC)
    change(data)
    with pytest.raises(SpecErrors) as failure:
        load_protocol(write(tmp_path, data))
    return [line.split(": ", 2)[-1] for line in str(failure.value).splitlines()]


def elements(data: dict[str, Any], layout: str) -> dict[str, Any]:
    found: dict[str, Any] = data["framing"]["layouts"][layout]["elements"]
    return found


def shared_code(data: dict[str, Any]) -> None:
    data["commands"]["low_target"] = {"code": 0x04, "request": {"fields": {}}}


def bare_code_as_a_header(data: dict[str, Any]) -> None:
    data["commands"]["go_home"]["code"] = 0xAA


def two_bare_layouts(data: dict[str, Any]) -> None:
    elements(data, "pololu").pop("start")


def bare_layout_starting_with_content(data: dict[str, Any]) -> None:
    compact = elements(data, "compact")
    compact["content"] = compact.pop("content")
    data["framing"]["layouts"]["compact"]["elements"] = {"content": compact["content"], "command": compact["command"]}


def code_on_a_header(data: dict[str, Any]) -> None:
    elements(data, "pololu")["start"]["code"] = "code"


def no_code_in_it(data: dict[str, Any]) -> None:
    elements(data, "pololu")["command"]["code"] = "0x7F"


def does_not_fit(data: dict[str, Any]) -> None:
    elements(data, "pololu")["command"]["code"] = "code + 0x80"


def two_device_numbers(data: dict[str, Any]) -> None:
    """A frame value one layout carries and the other not is in the language (tests/test_newuser_maestro.py); one
    name of two types is a mistake."""
    elements(data, "pololu")["device"] = {"role": "address", "type": "u8", "directions": ["request"]}
    compact = elements(data, "compact")
    compact["device"] = {"role": "address", "type": "u16", "directions": ["request"]}
    data["framing"]["layouts"]["compact"]["elements"] = {"command": compact.pop("command"), **compact}


@pytest.mark.parametrize(
    ("change", "said"),
    [
        (two_device_numbers, "frame value device must be the same role, type and range in every layout that carries"),
        (shared_code, "its code in layout pololu, 0x04 (code & 0x7F), is set_target's too: a frame could not tell"),
        (bare_code_as_a_header, "in layout compact (no header) starts aa, as layout pololu's header aa does"),
        (two_bare_layouts, "alternative request layouts must start with different headers (one layout without"),
        (bare_layout_starting_with_content, "alternative request layouts must start with different headers"),
        (code_on_a_header, "`code` belongs to a command element"),
        (no_code_in_it, "an expression of `code` (the command's code), e.g. `code & 0x7F`"),
        (does_not_fit, "its code in layout pololu, 260 (code + 0x80), does not fit the u8 command element (0..255)"),
    ],
)
def test_each_mistake_is_one_line(tmp_path: Path, change: Any, said: str) -> None:
    found = errors_of(tmp_path, change)
    assert any(said in line for line in found), found


PLAIN_FRAMES = ["84 02 70 2e", "aa 84 05 01 02", "90 03", "aa 90 07", "a2", "aa a2"]


@pytest.mark.parametrize("expression", [True, False], ids=["code & 0x7F", "codes as they are"])
def test_the_c_reads_both_forms(tmp_path: Path, expression: bool) -> None:
    """The C takes a frame in the layout its header names, the headerless one last, as Python does (it took
    `aa 84 05 01 02` in the headerless layout: unknown command 0xaa), and translates a code sent as an expression of
    it (it refused the spec); its decoder, encoder and parser give Python's messages, frames and counts."""
    from serialspec.cli import main
    from test_c_backend import GCC, Driver

    if GCC is None:
        pytest.skip("no C compiler")
    data = copy.deepcopy(SPEC)
    name = "coded_forms" if expression else "plain_forms"  # (not the module `forms` imported)
    data["protocol"] = name
    frames = [frame for frame, _ in FRAMES]
    if not expression:
        del elements(data, "pololu")["command"]["code"]
        frames = PLAIN_FRAMES
    spec = write(tmp_path, data)
    assert main(["generate", str(spec), "--out", str(tmp_path / "out")]) == 0
    package = generate_and_import(spec, tmp_path / "py", name)
    driver = Driver(name, tmp_path / "out" / "c" / name, tmp_path)
    try:
        for frame in frames:
            said = driver.ask(f"rt request {frame.replace(' ', '')}")[0]
            message = package.decode(bytes.fromhex(frame), package.Direction.REQUEST)
            assert said == f"ok {package.encode(message).hex()}", frame
        if expression:  # 0x84 is no code of the Pololu form (the Python codec: "command = 0x84 is no code of...")
            assert driver.ask("dec request aa8402")[0] == "err E_UNKNOWN"
        stream = bytes.fromhex(" ".join([*frames, "aa aa", *frames]))
        for cut in (1, 3):
            lines = driver.ask(f"stream request {cut} {stream.hex()}")
            parser = package.StreamParser(package.Direction.REQUEST)
            found = [m for i in range(0, len(stream), cut) for m in parser.feed(stream[i : i + cut])]
            got = [json.loads(line[4:])["fields"] for line in lines if line.startswith("msg ")]
            assert got == [m.to_fields() for m in found] and len(found) == 12
            assert lines[-1] == f"end 12 {parser.garbage} {parser.errors} 0"
    finally:
        driver.close()


WIDE = """
protocol: wide_forms
title: A code only the second layout's command element holds, sent there as an expression of it
byte_order: little
serial: {baudrate: 9600}
framing:
  layouts:
    short:
      elements:
        code: {role: command, type: u8}
        content: {role: content}
    long:
      elements:
        start: {role: header, value: F0}
        code: {role: command, type: u16, code: "code | 0x8000"}
        content: {role: content}
commands:
  small: {code: 0x10, request: {fields: {a: u8}}}
  big: {code: 0x1234, request: {fields: {b: u16}}}
"""


def test_the_c_sends_a_code_in_the_layout_that_holds_it_as_its_expression(tmp_path: Path) -> None:
    from serialspec.cli import main
    from test_c_backend import GCC, Driver

    if GCC is None:
        pytest.skip("no C compiler")
    spec = tmp_path / "wide_forms.yaml"
    spec.write_text(WIDE, "utf-8")
    assert main(["generate", str(spec), "--out", str(tmp_path / "out")]) == 0
    package = generate_and_import(spec, tmp_path / "py", "wide_forms")
    big = package.encode(package.BigRequest(b=7))
    assert big == bytes.fromhex("f0 34 92 07 00")  # 0x1234 | 0x8000, little-endian
    driver = Driver("wide_forms", tmp_path / "out" / "c" / "wide_forms", tmp_path)
    try:
        assert driver.ask(f"rt request {big.hex()}") == [f"ok {big.hex()}"]  # decoded, then encoded in `long`
        assert driver.ask("rt request 1003") == ["ok 1003"]
        assert driver.ask("dec request f0341207") == ["err E_UNKNOWN"]  # 0x1234 itself is no code sent in `long`
    finally:
        driver.close()


RPLIDAR = Path(__file__).parent / "specs" / "slamtec_rplidar.yaml"
# RPLIDAR responses where the headed frame is the one to take: a scan descriptor and an info reply with no measurement
# inside them (at every place inside, the angle's check bit, bit 0 of the second byte, is clear), measurements
# after the descriptor, a health reply (a measurement inside it ends first), garbage and a stray header between them
RPLIDAR_STREAMS = [
    "a5 5a 06 00 00 40 81 3e 01 02 10 27 3d 81 02 20 4e",
    "a5 5a 14 00 00 00 04" + " 02" * 20 + " a5 5a 06 00 00 40 81",
    "a5 5a 03 00 00 00 a5 5a 14 00 00 00 04" + " 00" * 20,
    "00 a5 5a a5 5a 06 00 00 40 81 a5 5a 03 00 00 00 06 00 00 00 ff a5",
]


def test_the_c_reads_a_headerless_layout_beside_headed_ones_as_python_does(tmp_path: Path) -> None:
    """RPLIDAR's responses: replies and scan descriptors after their header beside headerless 5-byte measurements
    (layouts chosen by command). Where several layouts fit at one place, the frame is the first of them to complete
    that decodes: the C took the first complete one alone, so the measurement failing at every `A5 5A` (its check
    bit is bit 0 of 0x5A) lost the reply or descriptor there. Fixed and noisy streams of every response, in pieces,
    give the Python parser's frames and counts; the vector check shipped beside the C (a frame inside a vector that
    ends first is taken first, as Python's parser takes it) passes under the strict flags."""
    import subprocess

    from conftest import Generated, message_class
    from serialspec.backends.c.build import files as c_files
    from serialspec.backends.python.memory import imported
    from serialspec.backends.python.package import emit_package
    from serialspec.lang.loader import load_file
    from serialspec.lang.model import Direction
    from serialspec.lang.resolve import resolve
    from strategies import message_fields
    from test_c_backend import FLAGS, GCC, Driver, stream_agrees_with_python

    if GCC is None:
        pytest.skip("no C compiler")
    protocol = resolve(load_file(str(RPLIDAR), RPLIDAR.name))
    name = protocol.name
    for path, text in c_files(protocol).items():
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text(text, encoding="utf-8")
    source = tmp_path / name
    sources = [str(source / "test" / "check_vectors.c"), str(source / f"{name}.c")]
    built = subprocess.run([GCC, *FLAGS, *sources, "-o", str(tmp_path / "check")], capture_output=True, text=True)
    assert built.returncode == 0 and not built.stderr, built.stderr
    checked = subprocess.run([str(tmp_path / "check")], capture_output=True, text=True, timeout=60)
    assert checked.stdout == f"{name}: 5 vectors, 0 refused frames, 0 failed\n", checked.stdout
    driver = Driver(name, source, tmp_path)
    try:
        with imported(name, emit_package(protocol)) as package:
            g = Generated(protocol, package, package)
            for stream in RPLIDAR_STREAMS:
                for sizes in ("1", "3,0,7", "64"):
                    stream_agrees_with_python(driver, g, Direction.RESPONSE, bytes.fromhex(stream), sizes)
            responses = [m for m in protocol.messages() if m.direction == Direction.RESPONSE]
            frames = st.one_of(
                [
                    message_fields(protocol, m).map(lambda f, m=m: package.encode(message_class(g, m).from_fields(f)))
                    for m in responses
                ]
            )
            piece = st.one_of(
                frames,
                frames.flatmap(lambda f: st.integers(0, len(f) - 1).map(lambda k: f[:k])),  # cut short
                st.binary(max_size=4),
                st.just(b"\xa5\x5a"),
            )

            @settings(max_examples=examples(10), deadline=None, suppress_health_check=list(HealthCheck))
            @given(st.lists(piece, max_size=8).map(b"".join), st.lists(st.integers(0, 9), min_size=1, max_size=5))
            def agree(stream: bytes, sizes: list[int]) -> None:
                stream_agrees_with_python(driver, g, Direction.RESPONSE, stream, ",".join(map(str, [*sizes, 1])))

            agree()
    finally:
        driver.close()
