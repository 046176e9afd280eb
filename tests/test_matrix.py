"""Every registered checksum algorithm, with each option it documents (its `samples`), through every output.

Parametrized by the registry (serialspec/checksums/), so a new algorithm is covered here without an edit. Each
option is put in two frame shapes: the classic one (header, command, one-byte length, content, checksum: the
straight-line classic codec and construct's frame struct) and a general one (two-byte header, u16 length, the
checksum over command..content: frames/' straight-line code and the engine). For each: the spec resolves and
its keys are in the JSON Schema; `serialspec generate` writes the package and the docs and `check` passes; the codec
round-trips, stores what the algorithm computes over the covered bytes and refuses a wrong checksum in one line; the
stream parser finds every frame among garbage at any read size (hypothesis); construct parses and builds the frame;
the client talks to `serialspec sim` over a pseudo-terminal; the docs describe the checksum with a worked example.
"""

from __future__ import annotations

import ast
import importlib
import json
import sys
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from conftest import examples
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.checksums import algorithms, owned_keys
from serialspec.checksums.base import Algorithm, Sample
from serialspec.cli import main as serialspec_main
from serialspec.lang import SpecErrors, load_protocol
from serialspec.lang.grammar import json_schema
from serialspec.runtime.errors import ChecksumError
from sim_process import serve

ROOT = Path(__file__).resolve().parent.parent

# (name, header, frame elements before the checksum, the span the checksum covers, covered bytes of a frame)
SHAPES = {
    "classic": (
        '{role: header, value: {request: "AA", response: "BB"}}',
        {"command": "{role: command, type: u8}", "length": "{role: length, type: u8}"},
        ["command", "content"],  # the header left out: the classic codec's fast paths for a skipped header
        lambda frame, size: frame[1:-size],
    ),
    "general": (
        '{role: header, value: "B5 62"}',
        {"command": "{role: command, type: u8}", "length": "{role: length, type: u16}"},
        ["command", "content"],
        lambda frame, size: frame[2:-size],
    ),
}

SPEC = """
protocol: {name}
title: Checksum matrix, {label}
byte_order: little
serial: {{baudrate: 115200}}
framing:
  elements:
    header: {header}
{elements}
    content: {{role: content}}
    checksum: {checksum}
fields:
  lamp_id: {{type: u8, range: [0, 254]}}
commands:
  ping:
    code: 1
    request: {{fields: {{lamp_id: lamp_id}}}}
    response: {{fields: {{lamp_id: lamp_id}}}}
  set_level:
    code: 2
    request: {{fields: {{lamp_id: lamp_id, level: {{type: u16, range: [0, 1000]}}, fade: u16}}}}
    response: {{fields: {{lamp_id: lamp_id}}}}
  read_level:
    code: 3
    request: {{fields: {{lamp_id: lamp_id}}}}
    response: {{fields: {{lamp_id: lamp_id, level: u16}}}}
  echo:
    code: 4
    request: {{fields: {{lamp_id: lamp_id, data: {{type: bytes, size: rest}}}}}}
    response: {{fields: {{lamp_id: lamp_id, data: {{type: bytes, size: rest}}}}}}
tables:
  settings:
    title: Settings
    key: setting
    entries:
      lamp_id: {{key: 1, type: u8, range: [0, 254], default: 1, access: rw}}
      level: {{key: 2, type: u16, range: [0, 1000], default: 0, access: rw}}
device:
  memory: settings
  address: lamp_id
  id_entry: lamp_id
  commands:
    set_level: {{moves: {{state: level, target: level, duration: fade}}}}
    read_level: {{reports: {{level: level}}}}
"""

CASES = [
    pytest.param(name, sample, shape, id=f"{name}-{index}-{shape}")
    for name, algorithm in algorithms().items()
    for index, sample in enumerate(algorithm.samples)
    for shape in SHAPES
]


def test_every_algorithm_documents_its_options() -> None:
    for name, algorithm in algorithms().items():
        assert algorithm.samples, f"{name}: no samples, so no option of it is tested here"
        assert algorithm.__doc__ or sys.modules[algorithm.__module__].__doc__, name


def test_the_registry_imports_nothing_of_the_generator() -> None:
    """Generated code imports the algorithms' runtime functions from their modules, and the runtime wheel ships the
    package without the generator: its modules import the standard library, each other, the integer encodings
    (serialspec.encodings, which import nothing of the generator either) and the runtime's value classes
    (serialspec.runtime.values; the runtime wheel ships both beside them) only."""
    folder = Path(importlib.import_module("serialspec.checksums").__file__ or "").parent
    for path in sorted(folder.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
            names += [node.module or ""] if isinstance(node, ast.ImportFrom) else []
            for name in names:
                allowed = name.startswith(("serialspec.checksums", "serialspec.encodings"))
                allowed = allowed or name == "serialspec.runtime.values"
                assert name.split(".")[0] != "serialspec" or allowed, (path.name, name)


@pytest.mark.parametrize(("key", "owners"), sorted(owned_keys().items()))
def test_an_algorithms_keys_belong_to_it(tmp_path: Path, key: str, owners: tuple[str, ...]) -> None:
    """Each key an algorithm owns is shown by one of its samples (of each algorithm that owns it: `mask` is both
    sum's and xor's), and refused beside another algorithm."""
    for owner in owners:
        value = next((s.keys[key] for s in algorithms()[owner].samples if key in s.keys), None)
        assert value is not None, f"no sample of {owner} gives `{key}`: the matrix does not test it"
    owner = " or ".join(owners)
    other, algorithm = next((n, a) for n, a in algorithms().items() if n not in owners)
    sample = algorithm.samples[0]
    spec = tmp_path / "foreign.yaml"
    foreign = Sample(sample.label, sample.type, {**sample.keys, key: value})
    spec.write_text(spec_text("foreign", other, foreign, "general"), encoding="utf-8")
    with pytest.raises(SpecErrors) as raised:
        load_protocol(str(spec))
    (line,) = str(raised.value).splitlines()
    assert line.endswith(f"framing.elements.checksum.{key}: `{key}` belongs to `algorithm: {owner}`, not {other}")


@dataclass
class Case:
    name: str
    spec: Path
    out: Path
    algorithm: Algorithm
    size: int
    covered: Any  # frame, size -> covered bytes
    package: ModuleType
    structs: ModuleType
    docs: str


def spec_text(name: str, algorithm: str, sample: Sample, shape: str) -> str:
    header, elements, covers, _ = SHAPES[shape]
    checksum = {"role": "checksum", "type": sample.type, "algorithm": algorithm, "covers": covers, **sample.keys}
    lines = "\n".join(f"    {key}: {value}" for key, value in elements.items())
    text = SPEC.format(
        name=name, label=f"{sample.label}, {shape}", header=header, elements=lines, checksum=json.dumps(checksum)
    )
    if sample.keys.get("seed") == "per_command":  # the element's `seed`: each command gives its byte
        for code, seed in ((1, 50), (2, 39), (3, 0), (4, 255)):
            text = text.replace(f"    code: {code}\n", f"    code: {code}\n    checksum_seed: {seed}\n")
    return text


_MADE: dict[str, Case] = {}


def made(tmp_path_factory: pytest.TempPathFactory, algorithm: str, sample: Sample, shape: str) -> Case:
    """The spec generated once per case (for every test of it) by `serialspec generate`, as a user runs it."""
    index = algorithms()[algorithm].samples.index(sample)
    name = f"matrix_{algorithm}_{index}_{shape}"
    if name in _MADE:
        return _MADE[name]
    folder = tmp_path_factory.mktemp(name)
    spec = folder / f"{name}.yaml"
    spec.write_text(spec_text(name, algorithm, sample, shape), encoding="utf-8")
    out = folder / "out"
    assert serialspec_main(["generate", str(spec), "--out", str(out)]) == 0
    assert serialspec_main(["check", str(spec), "--out", str(out)]) == 0
    protocol = load_protocol(str(spec))
    checksum = protocol.framing.checksum
    assert checksum is not None
    sys.path.insert(0, str(out))
    try:
        package = importlib.import_module(name)
        structs = importlib.import_module(f"{name}.structs")
    finally:
        sys.path.remove(str(out))
    docs = (out / "docs" / f"{name}.md").read_text(encoding="utf-8")
    size = checksum.type.size
    case = Case(name, spec, out, checksum.algorithm, size, SHAPES[shape][3], package, structs, docs)
    _MADE[name] = case
    return case


@pytest.mark.parametrize(("algorithm", "sample", "shape"), CASES)
def test_the_spec_resolves_and_the_schema_knows_it(algorithm: str, sample: Sample, shape: str) -> None:
    schema = json.dumps(json_schema())
    assert f'"{algorithm}"' in schema
    for key in sample.keys:
        assert f'"{key}"' in schema
    protocol_layouts = load_protocol_text(spec_text("resolves", algorithm, sample, shape))
    # the classic engine reads a checksum sent low byte first (every element's default); a big-endian one is general
    classic = shape == "classic" and sample.keys.get("endian", "little") == "little"
    assert protocol_layouts == ("classic" if classic else "general")


def load_protocol_text(text: str) -> str:
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        spec = Path(folder, "resolves.yaml")
        spec.write_text(text, encoding="utf-8")
        protocol = load_protocol(str(spec))
    return "classic" if protocol.framing.classic else "general"


@pytest.mark.parametrize(("algorithm", "sample", "shape"), CASES)
def test_codec_round_trip_and_refusal(
    tmp_path_factory: pytest.TempPathFactory, algorithm: str, sample: Sample, shape: str
) -> None:
    case = made(tmp_path_factory, algorithm, sample, shape)
    p = case.package
    function = case.algorithm.function()
    for message in (
        p.PingRequest(lamp_id=1),
        p.SetLevelRequest(lamp_id=254, level=1000, fade=0x1234),
        p.EchoRequest(lamp_id=3, data=bytes(range(0x70, 0x70 + 37))),
        p.EchoRequest(lamp_id=0, data=b""),
        p.ReadLevelResponse(lamp_id=9, level=0xFFFF),
    ):
        direction = message.DIRECTION.value
        frame = p.encode(message)
        assert p.decode(frame, direction) == message
        stored = int.from_bytes(frame[-case.size :], sample.keys.get("endian", "little"))
        assert stored == function(case.covered(frame, case.size)), (algorithm, frame.hex(" "))
        for flip in (0x01, 0x80):
            bad = frame[:-1] + bytes([frame[-1] ^ flip])
            with pytest.raises(ChecksumError) as refused:
                p.decode(bad, direction)
            assert "\n" not in str(refused.value) and "checksum" in str(refused.value)


@pytest.mark.parametrize(("algorithm", "sample", "shape"), CASES)
def test_stream_parser_at_any_read_size(
    tmp_path_factory: pytest.TempPathFactory, algorithm: str, sample: Sample, shape: str
) -> None:
    case = made(tmp_path_factory, algorithm, sample, shape)
    p = case.package

    @settings(max_examples=examples(25), suppress_health_check=[HealthCheck.function_scoped_fixture], deadline=None)
    @given(
        st.lists(st.tuples(st.integers(0, 254), st.binary(max_size=40), st.binary(max_size=6)), min_size=1, max_size=6),
        st.lists(st.integers(1, 9), min_size=1, max_size=20),
    )
    def check(items: list[tuple[int, bytes, bytes]], sizes: list[int]) -> None:
        messages = [p.EchoResponse(lamp_id=lamp, data=data) for lamp, data, _ in items]
        # garbage without header bytes before each frame: what a line picks up between replies
        stream = b"".join(
            bytes(b for b in junk if b not in (0xBB, 0xB5, 0xAA)) + p.encode(m)
            for m, (_, _, junk) in zip(messages, items, strict=True)
        )
        parser = p.StreamParser("response")
        found = []
        position = 0
        index = 0
        while position < len(stream):
            size = sizes[index % len(sizes)]
            found += parser.feed(stream[position : position + size])
            position += size
            index += 1
        assert found == messages

    check()


@pytest.mark.parametrize(("algorithm", "sample", "shape"), CASES)
def test_construct_structs(
    tmp_path_factory: pytest.TempPathFactory, algorithm: str, sample: Sample, shape: str
) -> None:
    case = made(tmp_path_factory, algorithm, sample, shape)
    p = case.package
    frame = p.encode(p.SetLevelRequest(lamp_id=5, level=513, fade=2))
    parsed = case.structs.REQUEST_FRAME.parse(frame)  # checks the checksum as it parses
    assert case.structs.REQUEST_FRAME.build(parsed) == frame
    bad = frame[:-1] + bytes([frame[-1] ^ 0x01])
    with pytest.raises(Exception, match="(?i)checksum|wrong|bad"):
        case.structs.REQUEST_FRAME.parse(bad)


@pytest.mark.parametrize(("algorithm", "sample", "shape"), CASES)
def test_docs_describe_the_checksum(
    tmp_path_factory: pytest.TempPathFactory, algorithm: str, sample: Sample, shape: str
) -> None:
    case = made(tmp_path_factory, algorithm, sample, shape)
    section = case.docs.split("## Checksum", 1)[1].split("\n## ", 1)[0]
    assert case.algorithm.describe() in section
    for name, value in case.algorithm.parameters():
        assert f"| {name} | {value} |" in section


@pytest.mark.slow
@pytest.mark.parametrize(("algorithm", "sample", "shape"), CASES)
def test_client_against_the_simulator(
    tmp_path_factory: pytest.TempPathFactory, algorithm: str, sample: Sample, shape: str
) -> None:
    case = made(tmp_path_factory, algorithm, sample, shape)
    sys.path.insert(0, str(case.out))
    try:
        client_module = importlib.import_module(f"{case.name}.client")
    finally:
        sys.path.remove(str(case.out))
    client_class = next(v for k, v in vars(client_module).items() if k.endswith("Client") and k != "ClientBase")
    with serve(str(case.spec), 1, 7) as path, client_class(path, timeout=1.0) as client:  # an absolute spec path
        assert client.ping(1) and client.ping(7)
        client.set_level(7, 321, 0)
        assert client.read_level(7) == 321
        assert client.read_level(1) == 0


@pytest.mark.parametrize(("algorithm", "sample", "shape"), CASES)
def test_c_target(tmp_path_factory: pytest.TempPathFactory, algorithm: str, sample: Sample, shape: str) -> None:
    """The C `generate` wrote beside the package (docs/c.md), through tests/test_c_backend.py's sanitized driver:
    messages encode to the Python codec's bytes (its checksum) and decode to its values, a corrupt checksum is
    refused, and a stream in pieces gives the messages the Python parser gives."""
    from conftest import Generated
    from test_c_backend import GCC, Driver, agrees_with_python, stream_agrees_with_python

    if GCC is None:
        pytest.skip("gcc is not installed")
    case = made(tmp_path_factory, algorithm, sample, shape)
    p = case.package
    protocol = load_protocol(str(case.spec))
    g = Generated(protocol, p, case.structs)
    run = Driver(case.name, case.out / "c" / case.name, tmp_path_factory.mktemp("c"))
    try:
        frames = []
        for message in (
            p.PingRequest(lamp_id=1),
            p.SetLevelRequest(lamp_id=254, level=1000, fade=0x1234),
            p.EchoRequest(lamp_id=3, data=bytes(range(0x70, 0x70 + 37))),
            p.EchoResponse(lamp_id=0, data=b""),
            p.ReadLevelResponse(lamp_id=9, level=0xFFFF),
        ):
            spec = next(m for m in protocol.messages() if m.class_name == type(message).__name__)
            frame = agrees_with_python(run, g, spec, message.to_fields())
            bad = frame[:-1] + bytes([frame[-1] ^ 0x01])
            assert run.ask(f"dec {spec.direction.value} {bad.hex()}") == ["err E_CHECKSUM"]
            if spec.direction.value == "response":
                frames.append(frame)
        direction = next(m.direction for m in protocol.messages() if m.direction.value == "response")
        stream_agrees_with_python(run, g, direction, b"\x00".join(frames) + b"\x01", "1,2,5")
    finally:
        run.close()
