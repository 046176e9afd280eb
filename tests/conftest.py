"""Shared fixtures: every spec under specs/ with its generated package, so each test runs for every protocol."""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from hypothesis import Phase, find, settings
from hypothesis import strategies as st
from serialspec.lang import load_protocol
from serialspec.lang.model import (
    Bytes,
    Direction,
    Example,
    FrameElement,
    FrameLayout,
    Message,
    Protocol,
    refusals_of,
    replies_by_request,
)
from strategies import message_fields

# Hypothesis policy. `make test` (and CI, which runs it once on a clean clone) must give the same answer every time:
# a fuzzer that fails one run in five blocks everyone and teaches people to rerun until green. So by default every
# hypothesis test is derandomized (its examples are a fixed function of the test, no example database is read or
# written): a failure there is a real, reproducible regression. Finding new bugs is `make stress`'s job: it sets
# SERIALSPEC_FUZZ_EXAMPLES, which selects random seeds (pass --hypothesis-seed=N to replay one) and runs every fuzzer
# with that many examples; what it finds is fixed and pinned with an @example, so the short run covers it from then on.
FUZZ_EXAMPLES = int(os.environ.get("SERIALSPEC_FUZZ_EXAMPLES") or 0)
settings.register_profile("ci", derandomize=True, database=None, print_blob=True)
settings.register_profile("stress", derandomize=False, database=None, print_blob=True)
settings.load_profile("stress" if FUZZ_EXAMPLES else "ci")


def examples(default: int) -> int:
    """A fuzzer's max_examples: its short form in `make test`, SERIALSPEC_FUZZ_EXAMPLES in `make stress` (never
    fewer than the short form: a long run does not run a test less than `make test` does)."""
    return max(FUZZ_EXAMPLES, default) if FUZZ_EXAMPLES else default


ROOT = Path(__file__).resolve().parent.parent
#: The namespace the shipped protocol packages are generated into (pyproject.toml's [tool.serialspec] namespace).
SHIPPED = "serialspec_protocols"
PACKAGES = ROOT / "generated" / SHIPPED
SPECS = sorted((ROOT / "specs").glob("*.yaml"))


@dataclass(frozen=True)
class Generated:
    protocol: Protocol
    package: ModuleType
    structs: ModuleType


def load(protocol: Protocol) -> Generated:
    package = importlib.import_module(f"{SHIPPED}.{protocol.name}")
    structs = importlib.import_module(f"{SHIPPED}.{protocol.name}.structs")
    return Generated(protocol, package, structs)


# each shipped spec loaded once: text protocols (`framing: {kind: text}`) are tests/test_text_frames.py's, the rest
# the binary suites'
_LOADED = [(spec, load_protocol(str(spec), str(spec.relative_to(ROOT)))) for spec in SPECS]
TEXT_SPECS = [spec for spec, protocol in _LOADED if protocol.text is not None]
ALL = [load(protocol) for _, protocol in _LOADED if protocol.text is None]


def by_protocol(items: list[tuple[Generated, object]]) -> list[object]:
    """Test cases per protocol, named `protocol:example` or `protocol:MessageClass` (not the message's whole repr)."""
    return [
        pytest.param(
            g, item, id=f"{g.protocol.name}:{getattr(item, 'name', None) or getattr(item, 'class_name', item)}"
        )
        for g, item in items
    ]


@pytest.fixture(params=ALL, ids=[g.protocol.name for g in ALL])
def generated(request: pytest.FixtureRequest) -> Generated:
    return request.param  # type: ignore[no-any-return]


def example_class(g: Generated, example: Example) -> Any:
    """The message class an example records: the reply layout to expect where replies share a code."""
    for cls in g.package.MESSAGE_TYPES:
        if (example.command, example.subcommand, example.direction) == (cls.COMMAND, cls.SUBCOMMAND, cls.DIRECTION):
            return cls
    raise AssertionError(f"no message class for example {example.name}")


# Replies read with the request they answer (RoboClaw: layouts chosen by command, a reply CRC over the request's
# address and command): `decode` refuses such a reply without it and the stream parser takes none while no request is
# pending. The suites that run over every shipped spec give them their request through these helpers, so that such a
# protocol is tested as fully as the others; for every other message the request is None and nothing changes.


def needs_request(g: Generated, spec: Message) -> bool:
    """A reply that is encoded and decoded with the request it answers."""
    framing = g.protocol.framing
    return spec.direction == Direction.RESPONSE and (framing.by_request(Direction.RESPONSE) or framing.from_request)


def message_class(g: Generated, spec: Message) -> Any:
    return next(c for c in g.package.MESSAGE_TYPES if c.__name__ == spec.class_name)


def request_spec(g: Generated, spec: Message) -> Message:
    """The request of a reply's command (of its sub-command, where it has one); for a refusal of a command with no
    request (`refused_by`: STM32's NACK, no code), the first request it refuses."""
    command = g.protocol.command(spec.command)
    request = next((s.request for s in command.subcommands if s.name == spec.subcommand), command.request)
    if request is None:
        replies = replies_by_request(g.protocol.messages())
        request = next(
            (m for m in g.protocol.messages() if m.direction == Direction.REQUEST and spec in refusals_of(m, replies)),
            None,
        )
    assert request is not None, f"{spec.class_name} answers no request"
    return request


def requests(g: Generated, spec: Message) -> st.SearchStrategy[Any]:
    """Random requests a message answers, drawn as every message is (tests/strategies.py); None where it is read
    alone."""
    if not needs_request(g, spec):
        return st.none()
    request = request_spec(g, spec)
    cls = message_class(g, request)
    return message_fields(g.protocol, request).map(lambda fields: cls.from_fields(fields))


def fitted(message: Message, fields: dict[str, Any], request: Any) -> dict[str, Any]:
    """A reply's fields with its last bytes as many as its request asks for, where a field of the request says how
    many (`size_from`: the encoder refuses another number where nothing else in the frame sizes them)."""
    last = message.fields[-1] if message.fields else None
    if request is None or not isinstance(last, Bytes) or not last.size_from:
        return fields
    return {**fields, last.name: " ".join(["5a"] * (request.to_fields()[last.size_from] + last.size_from_adds))}


def a_request(g: Generated, spec: Message) -> Any:
    """One request a message answers, the same on every run: the spec's first example request of its command, else
    the simplest valid one; None where the message is read alone."""
    if not needs_request(g, spec):
        return None
    request = request_spec(g, spec)
    for example in g.protocol.examples:
        if (example.command, example.subcommand, example.direction) == (
            spec.command,
            spec.subcommand,
            request.direction,
        ):
            return g.package.decode(example.frame, Direction.REQUEST.value)
    # the first value derandomized generation draws is the simplest one (what shrinking would reach, without its
    # second or so per message)
    fields = find(
        message_fields(g.protocol, request),
        lambda _: True,
        settings=settings(database=None, derandomize=True, phases=[Phase.generate]),
    )
    return message_class(g, request).from_fields(fields)


def example_request(g: Generated, example: Example) -> Any:
    """The request an example answers: its `request:` example, else one of its command (a_request); None where the
    example is read alone."""
    spec = example_message(g, example)
    if not needs_request(g, spec):
        return None
    if example.request:
        asked = next(e for e in g.protocol.examples if e.name == example.request)
        return g.package.decode(asked.frame, Direction.REQUEST.value)
    return a_request(g, spec)


def awaited(g: Generated, direction: Direction | None) -> st.SearchStrategy[tuple[Any, Any]]:
    """For a stream parser of a direction whose frames are read with their request: a reply class to await and a
    random request it answers (the parser takes those replies alone; see expect()); (None, None) for others."""
    if direction is None or not (specs := [m for m in g.protocol.messages() if m.direction == direction]):
        return st.just((None, None))
    if not needs_request(g, specs[0]):
        return st.just((None, None))
    return st.sampled_from(specs).flatmap(lambda spec: st.tuples(st.just(message_class(g, spec)), requests(g, spec)))


def refusal(g: Generated) -> str:
    """What the C target (backends/c/emit.py refuse_by_request) says when it refuses a spec whose replies are read
    with their request; "" for any other spec. Its suite checks that a refused spec gets exactly this one line,
    rather than leaving it out silently. (The Wireshark dissector reads such replies with the last request before
    them in the capture.)"""
    if g.protocol.framing.from_request:
        return "a reply checksum over bytes of its request (`from_request`)"
    return ""


def refused_in_one_line(g: Generated, target: str, out: Path) -> str:
    """`serialspec generate SPEC --target TARGET --out OUT` for a spec the target refuses: exit 1, nothing written,
    and one line `SPEC:1:1: the TARGET target cannot generate this spec: REASON`; returns REASON."""
    import contextlib
    import io

    from serialspec.cli import main as serialspec_main

    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        assert (
            serialspec_main(["generate", str(ROOT / g.protocol.spec_path), "--target", target, "--out", str(out)]) == 1
        )
    line = err.getvalue()
    assert line.count("\n") == 1 and line.startswith(f"{g.protocol.spec_path}:1:1: "), line
    said = f"the {target} target cannot generate this spec: "
    assert said in line, line
    assert not out.exists() or not any(out.rglob("*.*")), sorted(out.rglob("*"))
    return line.split(said, 1)[1].strip()


def encode(g: Generated, message: Any, request: Any = None) -> bytes:
    """g.package.encode, with the request a reply answers where it needs one."""
    return g.package.encode(message) if request is None else g.package.encode(message, request)  # type: ignore[no-any-return]


def decode(g: Generated, frame: bytes, direction: str | None = None, expect: Any = None, request: Any = None) -> Any:
    """g.package.decode, with the request a reply answers where it needs one."""
    if request is None:
        return g.package.decode(frame, direction, expect)
    return g.package.decode(frame, direction, expect, request=request)


def expect(parser: Any, cls: Any, request: Any = None) -> None:
    """parser.expect(cls), and the request the replies answer where they need one."""
    if request is None:
        parser.expect(cls)
    else:
        parser.expect(cls, request)


def requested(g: Generated, element: FrameElement, request: Any) -> bytes:
    """The bytes of its request a reply's checksum element takes in before the frame's own (`from_request`)."""
    names = element.checksum.from_request if element.checksum is not None else ()
    if request is None or not names:
        return b""
    layout = g.protocol.layout(next(m for m in g.protocol.messages() if m.class_name == type(request).__name__))
    frame = g.package.encode(request)
    sizes = {e.name: e.size or 0 for e in layout.elements}
    return b"".join(frame[layout.offsets[name] : layout.offsets[name] + sizes[name]] for name in names)


def struct_context(g: Generated, spec: Message, request: Any = None) -> dict[str, Any] | None:
    """The construct frame struct's context for a reply read with its request: its layout and the request's frame
    (runtime/constructs.py Framed); None for every other frame."""
    if request is None:
        return None
    return {"layout": g.protocol.layout(spec).name, "request": g.package.encode(request)}


def example_message(g: Generated, example: Example) -> Message:
    """The message an example records."""
    return next(
        m
        for m in g.protocol.messages()
        if (m.command, m.subcommand, m.direction) == (example.command, example.subcommand, example.direction)
    )


def set_plain_byte(layout: FrameLayout, frame: bytes, offset: int, value: Callable[[int], int]) -> tuple[bytes, int]:
    """The frame with the byte at `offset` (counted in the frame's plain bytes, before any transform; negative: from
    the end) set to value(old), the transformed span written again (a hex-ASCII span gets another hex digit pair,
    not a non-hex byte), and that byte's wire offset (from the start)."""
    t = layout.transparency
    if t is None:
        at = offset % len(frame)
        return frame[:at] + bytes([value(frame[at])]) + frame[at + 1 :], at
    first, last = layout.index(t.first), layout.index(t.last)
    before = sum(e.size or 0 for e in layout.elements[:first])
    after = sum(e.size or 0 for e in layout.elements[last + 1 :])
    runtime = t.transform.runtime((first, last))
    plain = frame[:before] + runtime.decode(frame[before : len(frame) - after]) + frame[len(frame) - after :]
    at = offset % len(plain)
    if not before <= at < len(plain) - after:  # outside the span: on the wire as it is
        wire_at = at if at < before else len(frame) - (len(plain) - at)
        return frame[:wire_at] + bytes([value(frame[wire_at])]) + frame[wire_at + 1 :], wire_at
    changed = plain[:at] + bytes([value(plain[at])]) + plain[at + 1 :]
    span = runtime.encode(changed[before : len(changed) - after])
    wire_at = before + len(runtime.encode(plain[before:at]))
    return frame[:before] + span + frame[len(frame) - after :], wire_at


# What `make test-fast` leaves out: whole-program runs that take seconds each (wheels built and installed, the docs
# site, the vendors' SDKs and peers over pseudo-terminals, the new-user protocols' peers, the long concurrency runs).
# `make test` runs them all.
SLOW_FILES = frozenset({"test_wheel.py", "test_docs.py", "test_stress.py", "test_faults.py", "test_spec_fuzz.py"})


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        name = item.path.name
        if name in SLOW_FILES or name.startswith(("test_interop_", "test_newuser_")):
            item.add_marker(pytest.mark.slow)


# Devices to talk to, shared by the client, SDK and peer tests. A module says which spec and ids it wants:
#   SIM = ("feetech_sms.yaml", 1, 2, 3)          -> `port`: a `serialspec sim` process's pseudo-terminal path
#   SIMULATOR = (FeetechSmsSimulator, [1, 2, 3]) -> `sim`: the generated simulator in this process, started
@pytest.fixture(scope="module")
def port(request: pytest.FixtureRequest) -> Iterator[str]:
    from sim_process import serve

    spec, *ids = request.module.SIM
    with serve(spec, *ids) as path:
        yield path


@dataclass(frozen=True)
class Running:
    """A generated simulator serving on a pseudo-terminal in this process."""

    device: Any
    path: str


@pytest.fixture
def sim(request: pytest.FixtureRequest) -> Iterator[Running]:
    simulator_class, ids = request.module.SIMULATOR
    simulator = simulator_class(ids=ids)
    try:
        yield Running(simulator, simulator.start())
    finally:
        simulator.close()


_SCRATCH: list[Any] = []


def scratch_folder(prefix: str) -> Path:
    """A new temporary folder that lives as long as this test process (for builds cached across tests) and is removed
    when it exits: mkdtemp's folders would pile up under /tmp run after run."""
    import tempfile

    folder = tempfile.TemporaryDirectory(prefix=prefix)
    _SCRATCH.append(folder)  # kept alive until exit, when its finalizer removes it
    return Path(folder.name)


def text_examples_round_trip(package: ModuleType, spec: Path, end: bytes, direction: str | None = None) -> int:
    """Each of a text spec's examples: its printed line (with `end`) decodes to its command and its values (as
    text) and encodes back to the same characters; how many there are."""
    import yaml

    examples = yaml.safe_load(spec.read_text("utf-8"))["examples"]
    for name, example in examples.items():
        frame = example["printed"].encode() + end
        message = package.decode(frame, direction)
        assert (example["command"], example["direction"]) == (message.COMMAND, message.DIRECTION.value), name
        shown = {k: v if isinstance(v, tuple) else "" if v is None else str(v) for k, v in message.to_fields().items()}
        wanted = {k: v if isinstance(v, list) else str(v) for k, v in example["fields"].items()}
        assert shown.keys() == wanted.keys() and all(
            shown[k] == wanted[k] for k in shown if not isinstance(wanted[k], list)
        ), name
        assert package.encode(message) == frame, name
    return len(examples)


def package_fixture(spec: Path, name: str) -> Any:
    """A module fixture giving the package `name` generated once from `spec` (generate_afresh)."""

    @pytest.fixture(scope="module")
    def package(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
        return generate_afresh(spec, tmp_path_factory, name)

    return package


def generate_afresh(spec: Path, tmp_path_factory: pytest.TempPathFactory, name: str) -> ModuleType:
    """The package `name` generated from `spec` into a new temporary folder and imported, any package of that name
    imported before (another test's spec of the same protocol) forgotten first: a module fixture's one generation."""
    import sys

    for module in [m for m in sys.modules if m.partition(".")[0] == name]:
        del sys.modules[module]
    return generate_and_import(spec, tmp_path_factory.mktemp(name), name)


def generate_and_import(spec: Path, out: Path, name: str) -> ModuleType:
    """`serialspec generate SPEC --out OUT`, then the package `name` imported from OUT (a spec of a test's own)."""
    import sys

    from serialspec.cli import main as serialspec_main

    assert serialspec_main(["generate", str(spec), "--out", str(out)]) == 0
    sys.path.insert(0, str(out))
    try:
        return importlib.import_module(name)
    finally:
        sys.path.remove(str(out))


@contextmanager
def simulated(package: str) -> Iterator[str]:
    """The generated simulator of `package` (a protocol package already imported, e.g. by generate_and_import) serving
    its default devices on a pseudo-terminal in this process: its path, while the block runs."""
    module = importlib.import_module(f"{package}.simulator")
    simulator_class = next(
        value
        for name, value in vars(module).items()
        if name.endswith("Simulator") and value.__module__ == module.__name__
    )
    simulator = simulator_class()
    try:
        yield simulator.start()
    finally:
        simulator.close()


def spec_error(text: str, folder: Path) -> str:
    """The one line the loader refuses a spec's text with (written to FOLDER/spec.yaml): a test asserts its end."""
    from serialspec.lang import SpecErrors

    spec = folder / "spec.yaml"
    spec.write_text(text, "utf-8")
    with pytest.raises(SpecErrors) as caught:
        load_protocol(str(spec), "spec.yaml")
    lines = str(caught.value).splitlines()
    assert len(lines) == 1, lines
    return lines[0]
