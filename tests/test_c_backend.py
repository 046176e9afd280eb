"""The C target (generated/c/<protocol>/) against the Python codec: compiled warning-free under the strict flags, every
example decoded to the same values and re-encoded byte for byte, random messages, mutated frames and noisy streams
in random pieces giving what the Python codec and stream parser give. A small C driver (tests/c/driver.c, hex in,
JSON out) built with the sanitizers runs the generated code; `make c-check` runs this file alone."""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
import subprocess
from collections.abc import Iterator
from functools import cache
from pathlib import Path
from typing import Any

import pytest
from conftest import (
    ALL,
    ROOT,
    Generated,
    a_request,
    by_protocol,
    example_class,
    example_request,
    examples,
    needs_request,
    refusal,
    refused_in_one_line,
    scratch_folder,
)
from conftest import decode as py_decode
from conftest import encode as py_encode
from conftest import expect as py_expect
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.backends.c import length_byte
from serialspec.backends.c.build import files as c_files
from serialspec.backends.c.emit import messages as c_messages
from serialspec.backends.c.emit import msg_id
from serialspec.lang.model import Direction, Message, TableValue, Text
from serialspec.runtime.errors import DecodeError
from strategies import message_fields

GCC = shutil.which("gcc")
GXX = shutil.which("g++")
CLANG = shutil.which("clang")
pytestmark = pytest.mark.skipif(GCC is None, reason="gcc is not installed")

FLAGS = [
    "-std=c99",
    "-Wall",
    "-Wextra",
    "-Werror",
    "-pedantic",
    "-Wconversion",
    "-Wsign-conversion",
    "-Wshadow",
    "-Wcast-align",
    "-Wcast-qual",
    "-Wundef",
    "-Wstrict-prototypes",
    "-Wmissing-prototypes",
    "-Wbad-function-cast",
    "-Wdouble-promotion",
    "-Wfloat-equal",
    "-Wformat=2",
    "-Wnull-dereference",
    "-Wpointer-arith",
    "-Wredundant-decls",
    "-Wswitch-default",
    "-Wvla",
]


def check_vectors(spec: Path, name: str, out: Path) -> str:
    """The spec's C (`generate --target c` into `out`) with its check_vectors program built under FLAGS (no warning)
    and run: what it prints (`<name>: N vectors, M refused frames, 0 failed`)."""
    from serialspec.cli import main as serialspec_main

    assert GCC is not None
    assert serialspec_main(["generate", str(spec), "--target", "c", "--out", str(out)]) == 0
    c = out / name
    sources = [str(c / file) for file in ("test/check_vectors.c", f"{name}.c", f"{name}_json.c")]
    built = subprocess.run([GCC, *FLAGS, *sources, "-o", str(out / "check")], capture_output=True, text=True)
    assert built.returncode == 0 and not built.stderr, built.stderr
    checked = subprocess.run([str(out / "check")], capture_output=True, text=True, timeout=60)
    return checked.stdout + checked.stderr


SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-g"]
# The compiler of the sanitized driver most tests build (command ()): clang where installed, whose
# -fsanitize=address,undefined build takes half gcc's time; gcc's sanitized programs run in the golden-vector test
# and on the other builds (gcc -m32, PowerPC), and in `make c-coverage` (gcov)
SANITIZING = str(CLANG or GCC)
#: the build name of a driver built with no command
DEFAULT_BUILD = "clang" if CLANG else "gcc"
GENERATED_C = ROOT / "generated" / "c"


def supported(g: Generated) -> bool:
    """The C target takes the spec: `serialspec generate` wrote its C (`make test` checks first that generated/ is
    what the generator writes; generating every spec's C again here cost each test process 3 s)."""
    return (GENERATED_C / g.protocol.name).is_dir()


C_SPECS = [g for g in ALL if supported(g)]
IDS = [g.protocol.name for g in C_SPECS]
REFUSED = [g for g in ALL if not supported(g)]


@pytest.mark.parametrize("g", REFUSED, ids=[g.protocol.name for g in REFUSED])
def test_a_shipped_spec_the_c_target_refuses_gets_one_line(g: Generated, tmp_path: Path) -> None:
    """A shipped spec the C target cannot take is not silently left out: `generate --target c` refuses it in one
    line naming the feature, and writes nothing; one whose replies are read with their request (RoboClaw) is
    refused for exactly that (the C decoder reads each frame alone)."""
    reason = refused_in_one_line(g, "c", tmp_path / "refused")
    assert reason == refusal(g) if refusal(g) else reason


@cache
def m32_builds() -> bool:
    """gcc -m32 links a program here (the 32-bit libc and libgcc installed)."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        source = Path(tmp) / "m.c"
        source.write_text("int main(void) { return 0; }\n")
        run = subprocess.run([str(GCC), "-m32", str(source), "-o", str(Path(tmp) / "m")], capture_output=True)
    return run.returncode == 0


# Besides gcc on this host: clang, gcc -m32 (a 32-bit size_t and long) and big-endian PowerPC (a cross gcc, the
# programs run under qemu-ppc). `make c-check` installs them as root (test-tools).
BUILDS = ["gcc", "clang", "gcc-m32", "powerpc-be"]
PPC_GCC = shutil.which("powerpc-linux-gnu-gcc")
QEMU_PPC = shutil.which("qemu-ppc")
# A compile-only build for 8-bit AVR (Arduino Mega): `int` is 16 bits and `double` 32, so an operation that leans on
# a 32-bit int warns there. Debian's avr-gcc 5.4 knows all of FLAGS but -Wnull-dereference (gcc 6).
AVR_GCC = shutil.which("avr-gcc")
AVR_LEAVES_OUT = {"-Wnull-dereference"}
SIMAVR = shutil.which("simavr")


def warning_flags(build: str) -> list[str]:
    """What a warnings-only compile adds for a build: clang's warnings all come from its front end (its analyses run
    on the syntax tree, not the optimiser's code), so `-fsyntax-only` gives every one of them in a fifth of a build's
    time; gcc's flow warnings (-Wmaybe-uninitialized, -Wstringop-overflow, ...) need its optimiser: a whole build."""
    return ["-fsyntax-only"] if build == "clang" else []


def compiler(build: str) -> list[str]:
    """The command that compiles for a build, or a skip that says what is missing."""
    assert GCC is not None
    if build == "clang":
        if CLANG is None:
            pytest.skip("clang is not installed (apt-get install clang; make c-check installs it as root)")
        return [CLANG]
    if build == "gcc-m32":
        if not m32_builds():
            pytest.skip(
                "gcc -m32 cannot link (apt-get install libc6-dev-i386 lib32gcc-12-dev; make generate installs them as "
                "root)"
            )
        return [GCC, "-m32"]
    if build == "powerpc-be":
        if PPC_GCC is None or QEMU_PPC is None:
            pytest.skip(
                "no big-endian build: powerpc-linux-gnu-gcc or qemu-ppc missing (apt-get install gcc-powerpc-linux-gnu "
                "libc6-dev-powerpc-cross qemu-user; make c-check installs them as root)"
            )
        return [PPC_GCC, "-static"]
    if build == "avr":
        if AVR_GCC is None:
            pytest.skip(
                "no AVR build: avr-gcc missing (apt-get install gcc-avr avr-libc; make generate installs it as root)"
            )
        return [AVR_GCC, "-mmcu=atmega2560"]
    return [GCC]


def runner(build: str) -> tuple[tuple[str, ...], list[str]]:
    """How a build's programs run (a prefix: qemu for another CPU) and the sanitizer flags it builds them with (none
    where the target has no sanitizer runtime)."""
    if build == "powerpc-be":
        assert QEMU_PPC is not None
        return (QEMU_PPC,), []
    return (), SANITIZE


def sources(g: Generated) -> tuple[Path, Path]:
    folder = GENERATED_C / g.protocol.name
    return folder / f"{g.protocol.name}.c", folder / f"{g.protocol.name}_json.c"


# `make c-check` (SERIALSPEC_C_CHECK=1) compiles at every level (-Og's flow analysis warns where -O2's does not: a
# variable set on every path that reads it, once); `make test` at -O2, where gcc and clang run the most analyses
# behind the warnings (-Wmaybe-uninitialized, -Wstringop-overflow, ...), to stay within its time.
C_CHECK = bool(os.environ.get("SERIALSPEC_C_CHECK"))
LEVELS = ["-O0", "-Og", "-Os", "-O2", "-O3"] if C_CHECK else ["-O2"]
# the builds whose warnings `make test` checks: big-endian PowerPC's are 32-bit gcc's (gcc -m32: the same type sizes,
# the same warnings; PowerPC's code runs in make test, test_examples_and_a_noisy_stream_give_the_same_on_other_builds)
# and `make c-check` compiles for it too
WARNING_BUILDS = [*(BUILDS if C_CHECK else [b for b in BUILDS if b != "powerpc-be"]), "avr"]


@pytest.mark.parametrize("build", WARNING_BUILDS)
@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_compiles_without_a_warning(g: Generated, level: str, build: str, tmp_path: Path) -> None:
    command = compiler(build)
    flags = [flag for flag in FLAGS if build != "avr" or flag not in AVR_LEAVES_OUT]
    for source in sources(g):
        run = subprocess.run(
            [*command, *flags, level, *warning_flags(build), "-c", str(source), "-o", str(tmp_path / "x.o")],
            capture_output=True,
        )
        assert run.returncode == 0, run.stderr.decode()
        assert not run.stderr, run.stderr.decode()


NEW_USER_SPECS = sorted((ROOT / "tests" / "specs").glob("*.yaml"))


@pytest.mark.skipif(not C_CHECK, reason="make c-check compiles the new-user specs' C (make test: their own tests)")
@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("spec", NEW_USER_SPECS, ids=[s.stem for s in NEW_USER_SPECS])
def test_new_user_specs_compile_without_a_warning(spec: Path, level: str, tmp_path: Path) -> None:
    """The specs written from the docs alone (tests/specs) at every level, gcc and clang: their shapes differ from
    the shipped ones' (gcc -Os once saw an element's bounds used uninitialised in Kondo ICS's encoder)."""
    from serialspec.backends import Unsupported  # noqa: PLC0415
    from serialspec.lang import load_protocol  # noqa: PLC0415
    from serialspec.lang.errors import SpecErrors  # noqa: PLC0415

    try:
        files = c_files(load_protocol(spec))
    except Unsupported as refused:
        pytest.skip(f"the C target refuses it: {refused}")
    except SpecErrors as refused:  # a strict xfail's spec (VE.Direct): its test says what the language lacks
        pytest.skip(f"the spec is refused: {str(refused).splitlines()[0]}")
    for path, text in files.items():
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text(text, encoding="utf-8")
    (folder,) = {(tmp_path / path).parent for path in files if path.endswith("_json.c")}
    for compiler_ in (GCC, CLANG):
        if compiler_ is None:
            continue
        for source in sorted(folder.glob("*.c")):
            run = subprocess.run(
                [compiler_, *FLAGS, level, "-I", str(folder), "-c", str(source), "-o", str(tmp_path / "x.o")],
                capture_output=True,
            )
            assert run.returncode == 0 and not run.stderr, run.stderr.decode()


CONTENT_ALONE = """
protocol: lonely
title: Frames of content alone (no header, code, length or checksum)
byte_order: little
serial: {baudrate: 9600}
framing:
  elements:
    content: {role: content}
commands:
  level: {title: Level, request: {fields: {level: {type: u8}}}}
"""


def test_a_frame_of_content_alone_compiles_without_a_warning(tmp_path: Path) -> None:
    """Its unwrap has no least size to check (it wrote `n < 0u`, an error under -Wextra's -Wtype-limits)."""
    from serialspec.lang.loader import load_text  # noqa: PLC0415
    from serialspec.lang.resolve import resolve  # noqa: PLC0415

    for path, text in c_files(resolve(load_text(CONTENT_ALONE, "lonely.yaml"))).items():
        (tmp_path / Path(path).name).write_text(text, encoding="utf-8")
    run = subprocess.run(
        [GCC, *FLAGS, "-fsyntax-only", "-I", str(tmp_path), str(tmp_path / "lonely.c")], capture_output=True, text=True
    )
    assert run.returncode == 0 and not run.stderr, run.stderr


@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_headers_compile_as_cpp11(g: Generated) -> None:
    if GXX is None:
        pytest.skip("g++ is not installed")
    header = GENERATED_C / g.protocol.name / f"{g.protocol.name}_json.h"
    flags = ["-std=c++11", "-pedantic", "-Wall", "-Wextra", "-Werror", "-x", "c++", "-fsyntax-only", str(header)]
    run = subprocess.run([GXX, *flags], capture_output=True)
    assert run.returncode == 0, run.stderr.decode()


ARM_GCC = shutil.which("arm-none-eabi-gcc")


@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_the_readme_gives_the_compilers_struct_sizes_and_every_macro(g: Generated, tmp_path: Path) -> None:
    """generated/c/<p>/README.md (written from the model and the emitter's data, not from the header): every
    message's struct size and p_msg_t's are what gcc says on LP64 and arm-none-eabi-gcc on the 32-bit ARM EABI,
    and every capacity macro of the header is in its table with the header's default."""
    import re

    p = g.protocol.name
    folder = GENERATED_C / p
    readme = (folder / "README.md").read_text(encoding="utf-8")
    sizes = dict(re.findall(r"^`(\w+_t)`, (\d+ B / \d+) B;", readme, re.M))
    msg = re.search(r"union of every message's struct: (\d+) B / (\d+) B", readme)
    assert msg is not None and len(sizes) == len(list(g.protocol.messages())), readme[:2000]
    sizes[f"{p}_msg_t"] = f"{msg[1]} B / {msg[2]}"
    for compiler_, column in ((ARM_GCC, 0), (GCC, 1)):
        if compiler_ is None:
            continue
        checks = [
            f"typedef char check_{i}[(sizeof({name}) == {size.split(' B / ')[column]}u) ? 1 : -1];"
            for i, (name, size) in enumerate(sizes.items())
        ]
        source = tmp_path / "sizes.c"
        source.write_text(f'#include "{p}.h"\n' + "\n".join(checks) + "\n", encoding="utf-8")
        run = subprocess.run([compiler_, "-std=c99", "-I", str(folder), "-c", str(source), "-o", os.devnull])
        assert run.returncode == 0, f"{compiler_}: a struct's size differs from the README's"
    header = (folder / f"{p}.h").read_text(encoding="utf-8")
    for macro, default in re.findall(r"^#define (\w+_MAX) (\d+)u$", header, re.M):
        assert f"| `{macro}` | {default} |" in readme


def test_several_protocols_link_into_one_program(tmp_path: Path) -> None:
    """Every external name is prefixed: all the protocols' objects link together."""
    assert GCC is not None
    main = tmp_path / "main.c"
    main.write_text("int main(void) { return 0; }\n")
    objects = [str(main)] + [str(s) for g in C_SPECS for s in sources(g)]
    run = subprocess.run([GCC, "-std=c99", *objects, "-o", str(tmp_path / "all")], capture_output=True)
    assert run.returncode == 0, run.stderr.decode()


class Driver:
    """The driver program for one protocol, built with the sanitizers, kept running: one command a line."""

    def __init__(
        self,
        name: str,
        source: Path,
        folder: Path,
        command: tuple[str, ...] = (),
        build: str = DEFAULT_BUILD,
        big_buffer: bool = True,
        defines: tuple[str, ...] = (),
    ) -> None:
        """Build tests/c/driver.c with the C of protocol `name` found in `source`, into `folder`, and start it;
        with `command` (a compiler and its flags: clang, gcc -m32) for `build` (BUILDS), else SANITIZING; with the
        spec's own P_MAX_FRAME when not `big_buffer`."""
        prefix, sanitize = runner(build)
        assert GCC is not None
        exe = folder / f"driver_{name}"
        coverage = os.environ.get("SERIALSPEC_C_COVERAGE")  # `make c-coverage`: a gcc --coverage build per process
        if coverage and not command and source.resolve().parent == GENERATED_C.resolve():
            folder = Path(coverage) / name / f"{abs(hash((defines, big_buffer))):x}-{os.getpid()}"
            folder.mkdir(parents=True, exist_ok=True)
            exe = folder / f"driver_{name}"
            sanitize = [*sanitize, "--coverage"]
            command = (GCC,)
        c, j = source / f"{name}.c", source / f"{name}_json.c"
        # replies read with their request: the driver's `req` command gives it (p_decode_reply, p_encode_reply, ...)
        replies = ["-DDRIVER_REPLIES"] if "_decode_reply(" in (source / f"{name}.h").read_text() else []
        # no frame the tests make exceeds the parser's buffer
        big = [f"-D{name.upper()}_MAX_FRAME=70000u"] if big_buffer else []
        command = [
            *(command or (SANITIZING,)),
            "-std=c99",
            *sanitize,
            *big,
            *defines,
            *replies,
            "-I",
            str(c.parent),
            f"-DPROTO={name}",
            f"-DPROTO_UPPER={name.upper()}",
            "-include",
            f"{name}_json.h",
            str(ROOT / "tests" / "c" / "driver.c"),
            str(c),
            str(j),
            "-o",
            str(exe),
        ]
        run = subprocess.run(command, capture_output=True)
        assert run.returncode == 0, run.stderr.decode()
        self.process = subprocess.Popen(
            [*prefix, str(exe)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1
        )

    def close(self) -> None:
        assert self.process.stdin is not None
        self.process.stdin.close()
        self.process.wait(10)

    def ask(self, line: str) -> list[str]:
        assert self.process.stdin is not None and self.process.stdout is not None
        self.process.stdin.write(line + "\n")
        self.process.stdin.flush()
        answers = []
        while True:
            answer = self.process.stdout.readline()
            assert answer, f"the driver stopped (sanitizer report above?) on: {line}"
            answers.append(answer.rstrip("\n"))
            if not line.startswith(("stream", "push")) or answer.startswith("end "):
                return answers


@cache
def driver(name: str, command: tuple[str, ...] = (), build: str = DEFAULT_BUILD) -> Driver:
    return Driver(name, GENERATED_C / name, scratch_folder("serialspec-c-"), command, build)


def spec_driver(spec: Path, name: str, folder: Path) -> Driver:
    """The driver of a spec of a test's own (its C generated into `folder`), for a test that decodes a few frames."""
    from serialspec.cli import main as serialspec_main

    assert serialspec_main(["generate", str(spec), "--out", str(folder), "--target", "c"]) == 0
    return Driver(name, folder / name, folder)


@cache
def spec_buffer_driver(name: str) -> Driver:
    """The driver with the spec's own P_MAX_FRAME (the buffer a firmware has: the parser moves the bytes it holds to
    its front when its end is reached)."""
    return Driver(name, GENERATED_C / name, scratch_folder("serialspec-c-"), big_buffer=False)


@contextlib.contextmanager
def answering(run: Driver, g: Generated, request: Any) -> Iterator[None]:
    """The driver given the request the replies decoded, encoded and parsed meanwhile answer (`req`; None: none)."""
    if request is None:
        yield
        return
    (answer,) = run.ask(f"req request {py_encode(g, request).hex()}")
    assert answer == "ok", answer
    try:
        yield
    finally:
        run.ask("req request -")


def agrees_with_python(run: Driver, g: Generated, spec: Message, fields: dict[str, Any], request: Any = None) -> bytes:
    """One message through the Python codec and the C: the same values, the same bytes again; its frame. A reply read
    with its request is given `request`, else one it answers (conftest.a_request)."""
    cls = message_class(g, spec)
    kind = kind_of(g, cls)
    if request is None and needs_request(g, spec):
        request = a_request(g, spec)
    frame: bytes = py_encode(g, cls.from_fields(fields), request)
    expected = python_json(py_decode(g, frame, spec.direction.value, cls, request))
    with answering(run, g, request):
        (answer,) = run.ask(f"dec {spec.direction.value} {frame.hex()} {kind}")
        assert answer.startswith("ok ") and json.loads(answer[3:]) == expected, (answer, expected)
        (answer,) = run.ask(f"rt {spec.direction.value} {frame.hex()} {kind}")
        assert answer == f"ok {frame.hex()}"
    return frame


def stream_agrees_with_python(
    run: Driver,
    g: Generated,
    direction: Direction,
    stream: bytes,
    sizes: str,
    expect: Message | None = None,
    gaps: tuple[int, ...] = (),
    request: Any = None,
) -> None:
    """A stream fed to the C parser in pieces of `sizes` gives what the Python parser fed byte by byte gives, with
    the parser expecting the reply `expect` (parser_expect; with `request`, the request it answers:
    parser_expect_reply) and told of a gap in the line before each offset of `gaps` (parser_gap); each message's raw
    frame (parser_frame) is the stream's next bytes that decode to it."""
    kind = "-" if expect is None else kind_of(g, message_class(g, expect))
    where = ",".join(map(str, gaps))
    with answering(run, g, request):
        answers = run.ask(f"stream {direction.value} {sizes} {stream.hex() or '-'} {kind} {where}".rstrip())
    messages = [json.loads(a[4:]) for a in answers if a.startswith("msg ")]
    counters = tuple(int(x) for x in answers[-1].split()[1:])
    assert (messages, counters) == python_stream(g, direction, stream, expect, gaps, request)
    frames = [bytes.fromhex(a[6:]) for a in answers if a.startswith("frame ")]
    assert len(frames) == len(messages)
    at = 0
    cls = None if expect is None else message_class(g, expect)
    for frame, message in zip(frames, messages, strict=True):
        found = stream.find(frame, at)
        assert found >= 0, (frame.hex(), stream[at:].hex())
        at = found + len(frame)
        assert python_json(py_decode(g, frame, direction.value, cls, request)) == message


def c_decode(g: Generated, frame: bytes, direction: Direction, kind: str = "") -> dict[str, Any] | str:
    """The C decoder's message as JSON data, or its error's name."""
    (answer,) = driver(g.protocol.name).ask(f"dec {direction.value} {frame.hex() or '-'} {kind}".rstrip())
    status, _, rest = answer.partition(" ")
    return json.loads(rest) if status == "ok" else rest


def python_json(message: Any) -> dict[str, Any]:
    return {
        "command": message.COMMAND,
        "subcommand": message.SUBCOMMAND,
        "direction": message.DIRECTION.value,
        "fields": message.to_fields(),
    }


def kind_of(g: Generated, cls: Any) -> str:
    message = next(m for m in g.protocol.messages() if m.class_name == cls.__name__)
    return f"{message.key.replace('.', '_')}_{message.direction.value}"


EXAMPLES = by_protocol([(g, e) for g in C_SPECS for e in g.protocol.examples])


@pytest.mark.parametrize(("g", "example"), EXAMPLES)
def test_every_example_decodes_to_the_spec_values_and_encodes_back(g: Generated, example: Any) -> None:
    cls = example_class(g, example)
    request = example_request(g, example)  # a reply read with its request (RoboClaw): the one it answers
    expected = py_decode(g, example.frame, example.direction.value, cls, request)
    run = driver(g.protocol.name)
    with answering(run, g, request):
        decoded = c_decode(g, example.frame, example.direction, kind_of(g, cls))
        assert decoded == python_json(expected)
        (answer,) = run.ask(f"rt {example.direction.value} {example.frame.hex()} {kind_of(g, cls)}")
    assert answer == f"ok {example.frame.hex()}"


# clang's and -m32's builds are `make c-check`'s alone (their warnings are checked in every run); `make test` runs
# the build where sizes and byte order differ most: big-endian PowerPC, 32-bit as -m32 is (or -m32 where PowerPC's
# gcc or qemu is missing)
OTHER_BUILDS = BUILDS[1:] if C_CHECK else ["powerpc-be" if PPC_GCC and QEMU_PPC else "gcc-m32"]


@pytest.mark.parametrize("build", OTHER_BUILDS)
@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_examples_and_a_noisy_stream_give_the_same_on_other_builds(g: Generated, build: str) -> None:
    """The driver built with clang and with gcc -m32 (32-bit size_t and long), both with the sanitizers, and for
    big-endian PowerPC (run under qemu-ppc): every example decoded to the spec's values and encoded back, and the
    examples in a noisy stream cut in pieces parsed as Python parses them."""
    run = driver(g.protocol.name, tuple(compiler(build)), build)
    for example in g.protocol.examples:
        cls = example_class(g, example)
        kind = kind_of(g, cls)
        request = example_request(g, example)
        with answering(run, g, request):
            (answer,) = run.ask(f"dec {example.direction.value} {example.frame.hex()} {kind}")
            expected = python_json(py_decode(g, example.frame, example.direction.value, cls, request))
            assert answer.startswith("ok ") and json.loads(answer[3:]) == expected, (answer, expected)
            (answer,) = run.ask(f"rt {example.direction.value} {example.frame.hex()} {kind}")
        assert answer == f"ok {example.frame.hex()}"
    for direction in (Direction.REQUEST, Direction.RESPONSE):
        frames = [e.frame for e in g.protocol.examples if e.direction == direction]
        stream = b"\x00\xff".join(frames) + bytes([0xFF, 0x55]) + b"".join(frames)
        stream_agrees_with_python(run, g, direction, stream, "1,2,3,5,8,13")


MESSAGES = by_protocol([(g, m) for g in C_SPECS for m in g.protocol.messages()])


def message_class(g: Generated, spec: Message) -> Any:
    return next(c for c in g.package.MESSAGE_TYPES if c.__name__ == spec.class_name)


@pytest.mark.parametrize(("g", "spec"), MESSAGES)
def test_random_messages_encode_and_decode_as_python_does(g: Generated, spec: Message) -> None:
    request = a_request(g, spec)  # (None but for a reply read with its request)

    @settings(max_examples=examples(5), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(message_fields(g.protocol, spec), st.data())
    def agree(fields: dict[str, Any], data: st.DataObject) -> None:
        run = driver(g.protocol.name)
        frame = agrees_with_python(run, g, spec, fields, request)
        with answering(run, g, request):
            # never past cap: every capacity short of the frame is refused, canaries intact (the driver checks them)
            cap = data.draw(st.integers(0, len(frame) - 1))
            (answer,) = run.ask(f"enc1 {spec.direction.value} {frame.hex()} {cap}")
            assert answer == "err E_BUFFER 0"
            # mutated frames: the same accept/reject and the same values
            mutated = mutate(frame, data)
            check_decode_agrees(g, mutated, spec.direction, request and message_class(g, spec), request)

    agree()


TABLE_VALUES = by_protocol(
    [(g, m) for g in C_SPECS for m in g.protocol.messages() if any(isinstance(f, TableValue) for f in m.fields)]
)


@pytest.mark.parametrize(("g", "spec"), TABLE_VALUES)
def test_every_key_of_a_table_value_encodes_and_decodes_as_python_does(g: Generated, spec: Message) -> None:
    """A value typed by a table (FashionStar's data by data_id): each key's type at its least and greatest value
    through the Python codec and the C (a few random messages reach only a few of the keys' cases)."""

    @settings(max_examples=1, deadline=None, derandomize=True)
    @given(message_fields(g.protocol, spec))
    def each_key(fields: dict[str, Any]) -> None:
        for f in spec.fields:
            if isinstance(f, TableValue):
                for entry in (e for e in f.table.entries if not e.reserved):
                    for value in (entry.minimum, entry.maximum):
                        number = value if entry.type.is_float else int(value)
                        agrees_with_python(
                            driver(g.protocol.name), g, spec, {**fields, f.key: entry.key, f.name: number}
                        )

    each_key()


WIDE = "é€😀"  # UTF-8 of 2, 3 and 4 bytes


def wide_text(f: Any) -> bool:
    """A text the wide characters fit: NUL-terminated, the rest of the content, or padded to room for them."""
    return isinstance(f, Text) and (
        f.size in (None, "rest") or (isinstance(f.size, int) and f.pad is not None and f.size >= 9)
    )


WIDE_TEXTS = by_protocol([(g, m) for g in C_SPECS for m in g.protocol.messages() if any(map(wide_text, m.fields))])


@pytest.mark.parametrize(("g", "spec"), WIDE_TEXTS)
def test_text_of_characters_past_ascii_encodes_and_decodes_as_python_does(g: Generated, spec: Message) -> None:
    """Texts of 2-, 3- and 4-byte UTF-8 characters through the Python codec and the C (random texts are ASCII:
    the C's UTF-8 check of each longer form ran nowhere else)."""

    @settings(max_examples=1, deadline=None, derandomize=True)
    @given(message_fields(g.protocol, spec))
    def wide(fields: dict[str, Any]) -> None:
        texts = {f.name: WIDE for f in spec.fields if wide_text(f)}
        agrees_with_python(driver(g.protocol.name), g, spec, {**fields, **texts})

    wide()


def mutate(frame: bytes, data: st.DataObject) -> bytes:
    how = data.draw(st.sampled_from(["flip", "cut", "grow", "byte"]))
    if how == "flip" and frame:
        at = data.draw(st.integers(0, len(frame) - 1))
        bit = data.draw(st.integers(0, 7))
        return frame[:at] + bytes([frame[at] ^ (1 << bit)]) + frame[at + 1 :]
    if how == "cut" and frame:
        return frame[: data.draw(st.integers(0, len(frame) - 1))]
    if how == "grow":
        return frame + data.draw(st.binary(min_size=1, max_size=3))
    at = data.draw(st.integers(0, len(frame)))
    return frame[:at] + data.draw(st.binary(min_size=1, max_size=1)) + frame[at:]


def check_decode_agrees(g: Generated, frame: bytes, direction: Direction, cls: Any = None, request: Any = None) -> None:
    """The C decoder accepts the frame exactly when Python's does, with the same values (a reply read with its
    request: as the reply `cls` to `request`, the driver given it already)."""
    try:
        expected: dict[str, Any] | None = python_json(py_decode(g, frame, direction.value, cls, request))
    except DecodeError:
        expected = None
    got = c_decode(g, frame, direction)
    if expected is None:
        assert isinstance(got, str), f"C accepts {frame.hex()}, Python refuses it"
    else:
        assert got == expected, frame.hex()


@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_random_bytes_are_refused_or_decoded_as_python_does(g: Generated) -> None:
    @settings(max_examples=examples(40), deadline=None)
    @given(st.binary(max_size=24), st.sampled_from(list(g.protocol.framing.layouts)))
    def agree(frame: bytes, direction: Direction) -> None:
        header = g.protocol.framing.layouts[direction].header
        check_decode_agrees(g, header + frame, direction)

    agree()


@cache
def _fixed_requests(name: str) -> dict[str, Any]:
    g = next(g for g in C_SPECS if g.protocol.name == name)
    return {m.class_name: a_request(g, m) for m in g.protocol.messages()}


def fixed_requests(g: Generated) -> dict[str, Any]:
    """conftest.a_request of each message (None but for replies read with their request), worked out once per
    protocol: call it before a @given whose strategies ask it (a_request draws with hypothesis itself)."""
    return _fixed_requests(g.protocol.name)


def frames_of(g: Generated, direction: Direction) -> st.SearchStrategy[bytes]:
    """Valid frames of any message of one direction, encoded by the Python codec."""
    choices = []
    for spec in g.protocol.messages():
        if spec.direction != direction:
            continue
        cls = message_class(g, spec)
        request = fixed_requests(g)[spec.class_name]  # a reply read with its request: a fixed one (the tests await it)
        choices.append(
            message_fields(g.protocol, spec).map(
                lambda f, cls=cls, request=request: py_encode(g, cls.from_fields(f), request)
            )
        )
    return st.one_of(choices)


def noisy_stream(g: Generated, direction: Direction) -> st.SearchStrategy[bytes]:
    header = g.protocol.framing.layouts[direction].header
    piece = st.one_of(
        frames_of(g, direction),
        frames_of(g, direction).flatmap(lambda f: st.integers(0, len(f) - 1).map(lambda k: f[:k])),  # cut
        frames_of(g, direction).flatmap(  # a flipped byte
            lambda f: st.tuples(st.integers(0, len(f) - 1), st.integers(1, 255)).map(
                lambda x: f[: x[0]] + bytes([f[x[0]] ^ x[1]]) + f[x[0] + 1 :]
            )
        ),
        st.binary(max_size=6),  # garbage
        st.just(header),  # a stray header
    )
    return st.lists(piece, max_size=8).map(b"".join)


def python_stream(
    g: Generated,
    direction: Direction,
    data: bytes,
    expect: Message | None = None,
    gaps: tuple[int, ...] = (),
    request: Any = None,
) -> tuple[list[dict[str, Any]], tuple[int, ...]]:
    parser = g.package.StreamParser(direction.value)
    if expect is not None:
        py_expect(parser, message_class(g, expect), request)
    found = []
    for at, byte in enumerate(data):  # byte at a time: the frame that completes first wins
        for _ in range(gaps.count(at)):
            parser.gap()
        found += [python_json(m) for m in parser.feed(bytes([byte]))]
    for _ in range(sum(1 for at in gaps if at >= len(data))):
        parser.gap()
    return found, (len(found), parser.garbage, parser.errors, len(parser.pending()))


@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_noisy_streams_in_random_pieces_give_what_python_gives(g: Generated) -> None:
    directions = list(g.protocol.framing.layouts)

    fixed_requests(g)  # (worked out before the @given: its strategies ask it)

    @settings(max_examples=examples(10), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(st.sampled_from(directions).flatmap(lambda d: st.tuples(st.just(d), noisy_stream(g, d))), st.data())
    def agree(case: tuple[Direction, bytes], data: st.DataObject) -> None:
        direction, stream = case
        sizes = data.draw(st.lists(st.integers(0, 9), min_size=1, max_size=6))
        if not any(sizes):
            sizes.append(1)
        stream_agrees_with_python(driver(g.protocol.name), g, direction, stream, ",".join(map(str, sizes)))

    agree()


@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_a_tail_that_begins_a_header_is_held_as_python_holds_it(g: Generated) -> None:
    """Garbage, then a header's first bytes (`00 ff` before DYNAMIXEL's ff ff fd): the bytes held and the garbage
    counted are Python's (C held every byte a header could still fill; Python holds from where a header begins)."""
    for direction, layout in g.protocol.framing.layouts.items():
        header = layout.header or b""
        for k in range(1, len(header)):
            for garbage in (b"\x00", b"\x01\x00\x02", header[k : k + 1] or b"\x00"):
                stream_agrees_with_python(driver(g.protocol.name), g, direction, garbage + header[:k], "1")


@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_the_parser_without_its_whole_frame_path_gives_what_python_gives(g: Generated, tmp_path: Path) -> None:
    """P_PARSER_WHOLE_FRAMES=0 (every byte through push, for the smallest flash) and, for frames of the length-byte
    shape, P_PARSER_SMALL=1 (the smallest parser; the default push is held to Python by the other stream tests): noisy
    streams in random pieces still give the Python parser's messages and counters."""
    if g.protocol.text is not None:
        pytest.skip("a text protocol's parser has no whole-frame path")
    name = g.protocol.name
    if f"#define {name.upper()}__HEADERS 0" in (GENERATED_C / name / f"{name}.c").read_text() and not (
        length_byte.applies(g.protocol)
    ):
        pytest.skip("frames without a header: the parser has no whole-frame path (the default build is this one)")
    defines = (f"-D{name.upper()}_PARSER_WHOLE_FRAMES=0",)
    if length_byte.applies(g.protocol):
        defines += (f"-D{name.upper()}_PARSER_SMALL=1",)
    one = Driver(name, GENERATED_C / name, tmp_path, defines=defines)
    directions = list(g.protocol.framing.layouts)
    try:
        fixed_requests(g)  # (worked out before the @given: its strategies ask it)

        @settings(max_examples=examples(5), deadline=None, suppress_health_check=[HealthCheck.too_slow])
        @given(st.sampled_from(directions).flatmap(lambda d: st.tuples(st.just(d), noisy_stream(g, d))), st.data())
        def agree(case: tuple[Direction, bytes], data: st.DataObject) -> None:
            direction, stream = case
            sizes = data.draw(st.lists(st.integers(0, 300), min_size=1, max_size=4))
            if not any(sizes):
                sizes.append(1)
            stream_agrees_with_python(one, g, direction, stream, ",".join(map(str, sizes)))

        agree()
    finally:
        one.close()


@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_gaps_and_expected_replies_give_what_python_gives(g: Generated) -> None:
    """parser_gap (the line idle: the bytes held dropped as garbage) and parser_expect (the reply the next frames
    answer) against the Python parser's gap() and expect(), on noisy streams in random pieces with gaps at random
    offsets; parser_frame gives each message's own bytes."""
    if g.protocol.text is not None:
        pytest.skip("the text parser's gap is held to Python's in test_c_text.py")
    directions = list(g.protocol.framing.layouts)
    replies = [m for m in g.protocol.messages() if m.direction == Direction.RESPONSE]
    asked = fixed_requests(g)

    fixed_requests(g)  # (worked out before the @given: its strategies ask it)

    @settings(max_examples=examples(15), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(st.sampled_from(directions).flatmap(lambda d: st.tuples(st.just(d), noisy_stream(g, d))), st.data())
    def agree(case: tuple[Direction, bytes], data: st.DataObject) -> None:
        direction, stream = case
        sizes = data.draw(st.lists(st.integers(1, 9), min_size=1, max_size=6))
        gaps = tuple(sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=4))))
        expect = None
        if direction == Direction.RESPONSE and replies:
            expect = data.draw(st.none() | st.sampled_from(replies))
        request = None if expect is None else asked[expect.class_name]  # the one frames_of's replies answer
        stream_agrees_with_python(
            driver(g.protocol.name), g, direction, stream, ",".join(map(str, sizes)), expect, gaps, request
        )

    agree()


def test_a_frame_of_an_unknown_command_with_a_good_checksum_is_counted_as_python_counts_it() -> None:
    """No message and no event for a frame whose checksum is good but whose command the spec does not have: where
    the frame's size comes from its length field alone (DYNAMIXEL's general framing) it is a corrupt candidate (an
    error, its bytes garbage), where the command decides the size (FEETECH's length-byte frames) it is no frame
    (garbage only); the C parser counts it as the Python parser does, and the frame after it is found."""
    by_name = {g.protocol.name: g for g in C_SPECS}
    cases = {
        # instruction 0x7F, CRC-16 good; then a PING
        "dynamixel_p2": ("fffffd000103007f1d4f", "fffffd0001030001194e", (1, 10, 1)),
        # instruction 0x55, sum good; then a PING
        "feetech_sms": ("ffff010255a7", "ffff010201fb", (1, 6, 0)),
    }
    for name, (unknown, ping, (frames, garbage, errors)) in cases.items():
        g = by_name[name]
        stream = bytes.fromhex(unknown + ping)
        with pytest.raises(DecodeError, match="unknown command"):
            g.package.decode(bytes.fromhex(unknown), "request")
        found, counters = python_stream(g, Direction.REQUEST, stream)
        assert counters == (frames, garbage, errors, 0), name
        for sizes in ("1", "3", "64"):
            stream_agrees_with_python(driver(name), g, Direction.REQUEST, stream, sizes)


def _frame_codec(g: Generated, direction: Direction) -> Any:
    """The Python codec's FrameCodec of a direction (general framing), or None (classic length-byte frames)."""
    return getattr(getattr(g.package, "codec", None), f"_{direction.name}_FRAMES", None)


# where a frame's size comes from its length field alone: a frame of an unknown command is a candidate the parser
# judges, and parser_push reports it (FEETECH's and the other length-byte frames trust a length only with a command)
# (not where layouts are chosen by command: a code no layout sends is no candidate there)
UNKNOWN_SPECS = [
    g for g in C_SPECS if _frame_codec(g, Direction.REQUEST) is not None and not g.protocol.framing.by_command
]


def unknown_frames(g: Generated, direction: Direction) -> st.SearchStrategy[bytes]:
    """Valid frames sent again with a command code the spec does not have (the frame, its length and checksum built
    by the Python codec): each has a good checksum and an unknown command."""
    codec = _frame_codec(g, direction)
    codes = {c.code for c in g.protocol.commands}
    unused = next(code for code in range(1, 0x80) if code not in codes)

    def rewrap(frame: bytes) -> bytes:
        unwrapped = codec.unwrap(frame)
        return bytes(codec.wrap(unwrapped.content, unused, unwrapped.values))

    return frames_of(g, direction).map(rewrap)


def _coded(g: Generated, direction: Direction) -> bool:
    """The direction's frames carry a command code (DYNAMIXEL's status packets carry a constant instead)."""
    return all(layout.command is not None for layout in _frame_codec(g, direction).layouts)


def judged(g: Generated, direction: Direction, frame: bytes) -> bool:
    """The Python parser judges this frame of an unknown command a corrupt candidate (an error), as where a frame's
    size comes from its length field alone; where the command's content bounds size it, it is no candidate."""
    parser = g.package.StreamParser(direction.value)
    parser.feed(frame)
    return parser.errors == 1


def pushed(run: Driver, direction: Direction, stream: bytes) -> tuple[list[Any], list[bytes], tuple[int, ...], int]:
    """The stream through parser_push byte by byte: the messages, the FRAME_UNKNOWN events' frames, the counters
    (frames, garbage, errors, bytes held) and the `unknown` counter."""
    answers = run.ask(f"push {direction.value} {stream.hex() or '-'}")
    messages = [json.loads(a[4:]) for a in answers if a.startswith("msg ")]
    unknown = [bytes.fromhex(a[8:]) for a in answers if a.startswith("unknown ")]
    *counters, count = (int(x) for x in answers[-1].split()[1:])
    return messages, unknown, tuple(counters), count


@pytest.mark.parametrize("g", UNKNOWN_SPECS, ids=[g.protocol.name for g in UNKNOWN_SPECS])
def test_parser_push_reports_a_frame_of_an_unknown_command_and_otherwise_gives_what_python_gives(g: Generated) -> None:
    """p_parser_push on noisy streams holding frames of unknown commands: the messages and counters of the Python
    parser (the unknown frame stays a corrupt candidate to both), and an event for each frame of an unknown command
    it judges, whose bytes the Python codec refuses as "unknown command"; where such frames come between valid ones
    each is reported once, in order."""
    directions = [d for d in g.protocol.framing.layouts if _frame_codec(g, d) is not None and _coded(g, d)]
    # without a header every byte starts a candidate (Modbus RTU): which ones an unknown frame's bytes give is the
    # noisy property's alone
    headed = all(layout.header for d in directions for layout in _frame_codec(g, d).layouts)
    run = driver(g.protocol.name)

    def noisy(d: Direction) -> st.SearchStrategy[tuple[Direction, bytes]]:
        piece = st.one_of(unknown_frames(g, d), noisy_stream(g, d))
        return st.tuples(st.just(d), st.lists(piece, max_size=4).map(b"".join))

    def clean(d: Direction) -> st.SearchStrategy[tuple[Direction, list[bytes], list[bytes]]]:
        piece = st.one_of(unknown_frames(g, d).map(lambda f: (f, True)), frames_of(g, d).map(lambda f: (f, False)))
        return st.lists(piece, max_size=5).map(lambda ps: (d, [f for f, _ in ps], [f for f, u in ps if u]))

    @settings(max_examples=examples(10), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(st.sampled_from(directions).flatmap(noisy))
    def agree(case: tuple[Direction, bytes]) -> None:
        direction, stream = case
        messages, unknown, counters, count = pushed(run, direction, stream)
        assert (messages, counters) == python_stream(g, direction, stream)
        assert count >= len(unknown)
        for frame in unknown:
            assert frame in stream
            with pytest.raises(DecodeError, match="unknown command"):
                g.package.decode(frame, direction.value)

    @settings(max_examples=examples(10), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(st.sampled_from(directions).flatmap(clean))
    def each_once(case: tuple[Direction, list[bytes], list[bytes]]) -> None:
        direction, frames, injected = case
        stream = b"".join(frames)
        messages, unknown, counters, count = pushed(run, direction, stream)
        assert (messages, counters) == python_stream(g, direction, stream)
        expected = [f for f in injected if judged(g, direction, f)]
        assert unknown == expected and count == len(expected)

    agree()
    if headed:
        each_once()


def test_without_unknown_frames_the_parser_counts_them_and_reports_none(tmp_path: Path) -> None:
    """P_PARSER_UNKNOWN_FRAMES=0 leaves the event and the frame's copy out: the frame is still counted."""
    (g,) = [g for g in C_SPECS if g.protocol.name == "dynamixel_p2"]
    run = Driver(
        "dynamixel_p2", GENERATED_C / "dynamixel_p2", tmp_path, defines=("-DDYNAMIXEL_P2_PARSER_UNKNOWN_FRAMES=0",)
    )
    try:
        stream = bytes.fromhex("fffffd000103007f1d4ffffffd0001030001194e")
        messages, unknown, counters, count = pushed(run, Direction.REQUEST, stream)
        assert (messages, counters) == python_stream(g, Direction.REQUEST, stream)
        assert (unknown, count) == ([], 1)
        messages, unknown, counters, count = pushed(driver("dynamixel_p2"), Direction.REQUEST, stream)
        assert (unknown, count) == ([bytes.fromhex("fffffd000103007f1d4f")], 1)
    finally:
        run.close()


def test_parser_push_on_length_byte_frames_gives_what_feed_gives() -> None:
    """FEETECH (length-byte frames): parser_push gives the messages and counters of the Python parser, and no
    event for a frame of an unknown command (its length is trusted only with a known command, as in Python)."""
    (g,) = [g for g in C_SPECS if g.protocol.name == "feetech_sms"]
    stream = bytes.fromhex("ffff010255a7ffff010201fb00ffffff010201fb")
    messages, unknown, counters, count = pushed(driver("feetech_sms"), Direction.REQUEST, stream)
    assert (messages, counters) == python_stream(g, Direction.REQUEST, stream)
    assert (len(messages), unknown, count) == (2, [], 0)


@pytest.mark.parametrize("name", ["feetech_sms", "dynamixel_p2"])
def test_a_frame_cut_by_a_gap_is_dropped_and_the_next_one_found(name: str) -> None:
    """A frame split by a gap in the line is no frame: its first part is dropped as garbage at the gap, the rest is
    garbage too, and a frame after it is found (Python and C alike)."""
    g = next(g for g in C_SPECS if g.protocol.name == name)
    spec = next(m for m in g.protocol.messages() if m.direction == Direction.REQUEST and m.key == "ping")
    frame = g.package.encode(message_class(g, spec).from_fields({"id": 1}))
    stream = frame + frame
    found, counters = python_stream(g, Direction.REQUEST, stream, gaps=(3,))
    assert len(found) == 1 and counters == (1, len(frame), 0, 0)
    for sizes in ("1", "2", "64"):
        stream_agrees_with_python(driver(name), g, Direction.REQUEST, stream, sizes, gaps=(3,))


def test_the_checked_hand_written_baseline_reads_replies_as_python_where_no_frame_hides_in_another(
    tmp_path: Path,
) -> None:
    """bench/c/feetech_checked.c, the hand-written parser the flash of the generated one is compared with like for
    like (docs/c.md), is a real parser of the spec's replies: on streams of valid replies, replies with a bad sum and
    garbage it gives the Python parser's replies and counters (garbage with the bytes held at the end). Where a
    frame starts inside a candidate still waiting for its bytes it does not: it finds the frame only once that
    candidate fails (the case at the end)."""
    g = next(g for g in C_SPECS if g.protocol.name == "feetech_sms")
    exe = tmp_path / "checked"
    sources = [str(ROOT / "bench" / "c" / "feetech_checked.c"), str(ROOT / "tests" / "c" / "checked_driver.c")]
    assert GCC is not None
    build = subprocess.run([GCC, *FLAGS, *SANITIZE, *sources, "-o", str(exe)], capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    reply = next(m for m in g.protocol.messages() if m.direction == Direction.RESPONSE)
    cls = message_class(g, reply)

    def both(stream: bytes) -> tuple[Any, Any]:
        out = subprocess.run([str(exe)], input=stream.hex(), capture_output=True, text=True, check=True).stdout
        *lines, end = out.splitlines()
        parser = g.package.StreamParser("response")
        found = [m for byte in stream for m in parser.feed(bytes([byte]))]
        python = [f"{m.id} {m.error} {bytes(m.data).hex()}" for m in found]
        skipped = parser.garbage + len(parser.pending())
        return (lines, end.split()[1:]), (python, [str(len(found)), str(skipped), str(parser.errors)])

    frames = message_fields(g.protocol, reply).map(lambda f: g.package.encode(cls.from_fields(f)))
    piece = st.one_of(
        frames,
        frames.map(lambda f: f[:-1] + bytes([f[-1] ^ 0x5A])),  # a bad sum
        st.binary(max_size=5).map(lambda b: b.replace(b"\xff", b"")),  # garbage (no header byte)
    )

    @settings(max_examples=examples(20), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(st.lists(piece, max_size=8).map(b"".join))
    def agree(stream: bytes) -> None:
        checked, python = both(stream)
        assert checked == python

    agree()
    # a cut reply whose length byte promises 9 more bytes, then a whole reply: Python takes the reply as it ends
    ping = g.package.encode(cls.from_fields({"id": 1, "error": 0, "data": b""}))
    checked, python = both(bytes.fromhex("ffff0109") + ping)
    assert python[0] == ["1 0 "] and checked[0] == []


LENGTH_BYTE = [g for g in C_SPECS if length_byte.applies(g.protocol)]


def test_the_length_byte_parser_is_chosen_by_the_framing() -> None:
    """Frames of the length-byte shape (one layout a direction: header, length byte, content, final checksum) get the
    straight-line parser; every other framing keeps the general one (what decides is the model's framing)."""
    assert LENGTH_BYTE, "no shipped spec has length-byte frames"
    for g in C_SPECS:
        text = (GENERATED_C / g.protocol.name / f"{g.protocol.name}.c").read_text()
        straight = f"static int {g.protocol.name}__scan(" in text
        assert straight == (g.protocol.framing.classic and g in LENGTH_BYTE), g.protocol.name
        assert straight != (f"static int {g.protocol.name}__try(" in text), g.protocol.name


def header_runs(g: Generated, direction: Direction, longest: int) -> st.SearchStrategy[bytes]:
    """Streams that make the length-byte parser keep many candidates: runs of the header's first byte and of whole
    headers, frames cut after their length byte (a plausible candidate hiding what follows), valid and corrupt
    frames, garbage."""
    header = g.protocol.framing.layouts[direction].header
    frames = frames_of(g, direction)
    piece = st.one_of(
        frames,
        st.integers(1, longest).map(lambda k: header[:1] * k),
        st.integers(1, 8).map(lambda k: header * k),
        frames.map(lambda f: f[: len(header) + 3]),
        frames.flatmap(
            lambda f: st.tuples(st.integers(0, len(f) - 1), st.integers(1, 255)).map(
                lambda x: f[: x[0]] + bytes([f[x[0]] ^ x[1]]) + f[x[0] + 1 :]
            )
        ),
        st.binary(max_size=4),
    )
    return st.lists(piece, max_size=14).map(b"".join)


@pytest.mark.parametrize("g", LENGTH_BYTE, ids=[g.protocol.name for g in LENGTH_BYTE])
def test_length_byte_parser_gives_what_python_gives_on_runs_of_headers(g: Generated) -> None:
    """The length-byte parser against the Python parser fed byte by byte: runs of header bytes, candidates hiding
    frames, corrupt frames, in random pieces; long runs move the bytes held to the buffer's front many times."""
    directions = list(g.protocol.framing.layouts)

    @settings(max_examples=examples(12), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(
        st.sampled_from(directions).flatmap(lambda d: st.tuples(st.just(d), header_runs(g, d, 600))),
        st.lists(st.integers(0, 300), min_size=1, max_size=6),
    )
    def agree(case: tuple[Direction, bytes], sizes: list[int]) -> None:
        direction, stream = case
        if not any(sizes):
            sizes.append(1)
        stream_agrees_with_python(spec_buffer_driver(g.protocol.name), g, direction, stream, ",".join(map(str, sizes)))

    agree()


@pytest.mark.parametrize("g", LENGTH_BYTE, ids=[g.protocol.name for g in LENGTH_BYTE])
def test_length_byte_parser_finds_the_frames_behind_a_long_adversarial_run(g: Generated) -> None:
    """A kilobyte of the header's first byte, whole headers, a candidate cut after its length byte, then the examples:
    every example found, the counters Python's, fed one byte at a time and in pieces of every size up to 13."""
    for direction in g.protocol.framing.layouts:
        header = g.protocol.framing.layouts[direction].header
        frames = [e.frame for e in g.protocol.examples if e.direction == direction]
        if not frames:
            continue
        stream = header[:1] * 1000 + header * 40 + frames[0][: len(header) + 3] + b"".join(frames) + header[:1] * 300
        stream += b"".join(frames)
        found, _ = python_stream(g, direction, stream)
        assert len(found) >= 2 * len(frames) - 1
        for pieces in ("1", "2,3,5,7,11,13", "300"):
            stream_agrees_with_python(spec_buffer_driver(g.protocol.name), g, direction, stream, pieces)
            stream_agrees_with_python(driver(g.protocol.name), g, direction, stream, pieces)


@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_feature_switches_leave_out_encode_decode_or_parser_without_a_warning(g: Generated, tmp_path: Path) -> None:
    assert GCC is not None
    upper = g.protocol.name.upper()
    builds = (
        [f"-D{upper}_ENABLE_ENCODE=0"],  # decode and parser
        [f"-D{upper}_ENABLE_DECODE=0", f"-D{upper}_ENABLE_PARSER=0"],  # encode only
    )
    for switches in builds:
        command = [GCC, *FLAGS, "-Os", *switches, "-c", str(sources(g)[0]), "-o", str(tmp_path / "x.o")]
        run = subprocess.run(command, capture_output=True)
        assert run.returncode == 0 and not run.stderr, run.stderr.decode()


@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_the_api_refuses_null_pointers_and_values_outside_its_enums(g: Generated) -> None:
    """decode and encode given NULL, a direction or a kind no enum value names: E_ARG, nothing written; the names of
    no kind and no result: ""; to_json(NULL): null; a parser made for no direction finds nothing."""
    (answer,) = driver(g.protocol.name).ask("args request")
    words = answer.split(" ")
    assert words[:9] == ["args", *["E_ARG"] * 6, "0", "[]"], answer
    assert words[9:12] == ["[]", "[]", "[]"], answer
    assert words[12] == "null" and words[13].startswith("{"), answer
    assert words[-3:] == ["1", "0", "0"], answer  # the byte taken, no message, no event


ROLES = ("HOST", "DEVICE")
# `make c-check` builds every spec for both roles; `make test` each spec for one of them, in turn
ROLE_BUILDS = [
    pytest.param(g, role, id=f"{g.protocol.name}-{role}")
    for index, g in enumerate(C_SPECS)
    for role in ROLES
    if C_CHECK or role == ROLES[index % 2]
]


@pytest.mark.parametrize(("g", "role"), ROLE_BUILDS)
def test_a_build_for_one_role_keeps_its_side_and_refuses_the_other(g: Generated, role: str, tmp_path: Path) -> None:
    """P_ROLE=P_ROLE_HOST (sends requests, reads responses) or P_ROLE_DEVICE (the other way): compiled warning-free
    under the strict flags with each switch; the shipped vector check passes on the side the role reads; every example
    of that side decodes and parses as in the full build, every example of the side it sends encodes to the example's
    bytes (from the full build's message), and the other side's frames and messages are refused with E_ARG."""
    assert GCC is not None
    name, upper = g.protocol.name, g.protocol.name.upper()
    role_define = f"-D{upper}_ROLE={upper}_ROLE_{role}"
    # each feature switch beside the role at -O2 in `make c-check`; in `make test` the role's build of the vector
    # check below, under the same strict flags (at -O0), is its warning check
    switch_sets = [[f"-D{upper}_ENABLE_ENCODE=0"], [f"-D{upper}_ENABLE_DECODE=0", f"-D{upper}_ENABLE_PARSER=0"]]
    folder = GENERATED_C / name
    check = folder / "test" / "check_vectors.c"
    for switches in [*([[]] if C_CHECK or not check.exists() else []), *(switch_sets if C_CHECK else [])]:
        command = [GCC, *FLAGS, "-O2", role_define, *switches, "-c", str(sources(g)[0]), "-o", str(tmp_path / "x.o")]
        run = subprocess.run(command, capture_output=True)
        assert run.returncode == 0 and not run.stderr, run.stderr.decode()
    if check.exists():
        exe = tmp_path / "check_vectors"
        sources_ = [str(check), str(folder / f"{name}.c")]
        build = [GCC, *FLAGS, *SANITIZE, "-O0", role_define, "-I", str(folder), *sources_, "-o", str(exe)]
        built = subprocess.run(build, capture_output=True, text=True)
        assert built.returncode == 0 and not built.stderr, built.stderr
        run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120)
        assert run.returncode == 0 and run.stdout.endswith(" 0 failed\n"), run.stdout + run.stderr
    full = driver(name)
    each = tmp_path / "each.h"  # every message's own encoder, called with a zeroed message
    calls = [
        f'    {{ static {name}_{msg_id(m)}_t m; printf(" {msg_id(m)}=%s", '
        f"{name}_result_name({name}_encode_{msg_id(m)}(&m, b, sizeof(b), &n))); }}"
        for m in c_messages(g.protocol)
    ]
    each.write_text(
        "static void each_encoder(void)\n{\n    static uint8_t b[1 << 16];\n    size_t n;\n"
        '    printf("each");\n' + "\n".join(calls) + '\n    printf("\\n");\n}\n'
    )
    one = Driver(name, GENERATED_C / name, tmp_path, defines=(role_define, f'-DDRIVER_EACH="{each}"'))
    reads = Direction.RESPONSE if role == "HOST" else Direction.REQUEST
    try:
        # every kind, zeroed: the side the role sends encodes as in the full build, the other is refused, through
        # encode and through each message's own encoder
        (every,) = full.ask("kinds request")
        (kept,) = one.ask("kinds request")
        (own,) = one.ask("each request")
        for both, this, alone in zip(every.split()[1:], kept.split()[1:], own.split()[1:], strict=True):
            refused = both.split("=")[0].endswith(f"_{reads.value}")
            assert this == alone == (both.split("=")[0] + "=E_ARG" if refused else both), (both, this, alone)
        assert one.ask("args request") == full.ask("args request")
        for example in g.protocol.examples:
            if example_request(g, example) is not None:
                continue  # a reply read with its request: a one-role build cannot make that from its frame
            d, frame = example.direction.value, example.frame.hex()
            kind = kind_of(g, example_class(g, example))
            (raw,) = full.ask(f"raw {d} {frame} {kind}")
            assert raw.startswith("ok ")
            (encoded,) = one.ask(f"encraw {d} {raw[3:]}")
            (decoded,) = one.ask(f"dec {d} {frame} {kind}")
            stream = one.ask(f"stream {d} 1 {frame}")
            if example.direction == reads:
                assert decoded == full.ask(f"dec {d} {frame} {kind}")[0]
                assert stream == full.ask(f"stream {d} 1 {frame}")
                assert encoded == "err E_ARG"
            else:
                assert (decoded, stream) == ("err E_ARG", ["end 0 0 0 0"])
                assert encoded == f"ok {frame}"
    finally:
        one.close()


@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_fuzz_harness_finds_nothing_in_seeded_random_runs(g: Generated, tmp_path: Path) -> None:
    """tests/c/fuzz.c as gcc-only CI runs it: seeded random inputs under the sanitizers (with clang, the same file
    is a libFuzzer target: -fsanitize=fuzzer -DFUZZ_LIBFUZZER)."""
    assert GCC is not None
    name = g.protocol.name
    c, j = sources(g)
    exe = tmp_path / "fuzz"
    include = ["-I", str(c.parent), f"-DPROTO={name}", f"-DPROTO_UPPER={name.upper()}", "-include", f"{name}_json.h"]
    build = [GCC, "-std=c99", "-O1", *SANITIZE, *include, str(ROOT / "tests/c/fuzz.c"), str(c), str(j), "-o", str(exe)]
    run = subprocess.run(build, capture_output=True)
    assert run.returncode == 0, run.stderr.decode()
    run = subprocess.run([str(exe), str(examples(300)), "12345"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "no failure" in run.stdout


def test_example_host_program_talks_to_a_virtual_servo(tmp_path: Path) -> None:
    """examples/c/feetech_ping.c, built against the generated C, pings and reads a servo `serialspec sim` serves."""
    from sim_process import serve

    assert GCC is not None
    folder = GENERATED_C / "feetech_sms"
    exe = tmp_path / "feetech_ping"
    sources = [
        str(ROOT / "examples/c/feetech_ping.c"),
        str(folder / "feetech_sms.c"),
        str(folder / "feetech_sms_json.c"),
    ]
    run = subprocess.run([GCC, "-std=c99", "-Wall", "-Wextra", "-Werror", "-I", str(folder), *sources, "-o", str(exe)])
    assert run.returncode == 0
    with serve("feetech_sms.yaml", 1) as path:
        run = subprocess.run([str(exe), path, "1"], capture_output=True, text=True, timeout=30)
    assert run.returncode == 0, run.stderr
    ping, read = (json.loads(line) for line in run.stdout.splitlines())
    assert ping["fields"] == {"id": 1, "error": 0, "data": ""}
    assert read["command"] == "reply" and len(bytes.fromhex(read["fields"]["data"])) == 6


@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_the_golden_vectors_pass_on_an_8_bit_avr(g: Generated, tmp_path: Path) -> None:
    """<protocol>/test/check_vectors.c run on an ATmega1284P (a 16-bit `int`, a 32-bit `double`, 16 KiB of RAM)
    under simavr, built with the strict warnings: every example decodes to its message, encodes back byte for byte
    and is found by the parser, as on the host. The group capacities of 32 items are cut to 4 (`-D`, as a firmware
    author sizes them) so that the largest message fits beside the vectors, which AVR keeps in RAM."""
    if AVR_GCC is None or SIMAVR is None:
        pytest.skip("avr-gcc or simavr missing (apt-get install gcc-avr avr-libc simavr; make generate installs them)")
    name = g.protocol.name
    folder = GENERATED_C / name
    if not (folder / "test" / "check_vectors.c").exists():
        pytest.skip("no golden-vector program (a text protocol's C has none)")
    header = (folder / f"{name}.h").read_text()
    capacities = [f"-D{macro}=4" for macro in re.findall(r"#define (\w+_MAX) 32u", header)]
    flags = [flag for flag in FLAGS if flag not in AVR_LEAVES_OUT]
    program = [folder / "test" / "check_vectors.c", *sources(g), ROOT / "tests" / "c" / "avr_stdout.c"]
    elf = tmp_path / "check.elf"
    built = subprocess.run(
        [
            AVR_GCC,
            "-mmcu=atmega1284p",
            *flags,
            "-Os",
            *capacities,
            "-I",
            str(folder),
            *map(str, program),
            "-o",
            str(elf),
        ],
        capture_output=True,
        text=True,
    )
    assert built.returncode == 0 and not built.stderr, built.stderr
    run = subprocess.run(
        [SIMAVR, "-m", "atmega1284p", "-f", "16000000", str(elf)], capture_output=True, text=True, timeout=60
    )
    printed = re.sub(r"\x1b\[[0-9;]*m", "", run.stdout + run.stderr)  # simavr colours what the UART sends
    assert re.search(rf"^{name}: \d+ vectors, \d+ refused frames, 0 failed", printed, re.MULTILINE), printed


def test_the_avr_example_builds_as_its_comment_says_and_fits_an_arduino_mega(tmp_path: Path) -> None:
    """examples/c/avr_servo_follow.c (an ATmega2560 on a servo bus: a 16-bit int) built by the avr-gcc command its
    comment prints, with the strict warnings added: no warning, and its static RAM (.data + .bss) within a quarter of
    the chip's 8 KiB, as the comment's capacity overrides promise."""
    if AVR_GCC is None:
        pytest.skip("avr-gcc missing (apt-get install gcc-avr avr-libc; make generate installs it as root)")
    comment = (ROOT / "examples/c/avr_servo_follow.c").read_text().split("*/", 1)[0]
    printed = comment.split(" *   avr-gcc", 1)[1].split("\n *   avr-objcopy", 1)[0]
    words = ["avr-gcc", *printed.replace("\\\n *", " ").split()]
    assert words[-2] == "-o"
    flags = [flag for flag in FLAGS if flag not in AVR_LEAVES_OUT]
    run = subprocess.run([*words[:-1], str(tmp_path / "follow.elf"), *flags], cwd=ROOT, capture_output=True, text=True)
    assert run.returncode == 0 and not run.stderr, run.stderr
    sizes = subprocess.run(["avr-size", "-A", str(tmp_path / "follow.elf")], capture_output=True, text=True).stdout
    ram = sum(int(line.split()[1]) for line in sizes.splitlines() if line.startswith((".data", ".bss")))
    assert 0 < ram <= 2048, sizes


# gcc with the sanitizers in `make test` (the examples already run on the other builds through the driver: see
# test_examples_and_a_noisy_stream_give_the_same_on_other_builds); every build in `make c-check`
VECTOR_BUILDS = BUILDS if C_CHECK else BUILDS[:1]


@pytest.mark.parametrize("build", VECTOR_BUILDS)
@pytest.mark.parametrize("g", C_SPECS, ids=IDS)
def test_the_shipped_golden_vector_check_passes(g: Generated, build: str, tmp_path: Path) -> None:
    """<protocol>/test/check_vectors.c, the program a firmware developer builds beside the vendored C, built with the
    strict warnings (and the sanitizers where the target has them) at -O0: every example decodes to its message,
    encodes back byte for byte and is found by the parser fed byte by byte; every erratum frame is refused."""
    folder = GENERATED_C / g.protocol.name
    prefix, sanitize = runner(build)
    exe = tmp_path / "check_vectors"
    subprocess.run(
        [
            *compiler(build),
            *FLAGS,
            *sanitize,
            "-O0",
            "-I",
            str(folder),
            str(folder / "test" / "check_vectors.c"),
            str(folder / f"{g.protocol.name}.c"),
            "-o",
            str(exe),
        ],
        check=True,
        capture_output=True,
    )
    run = subprocess.run([*prefix, str(exe)], capture_output=True, text=True, timeout=120)
    examples = sum(1 for e in g.protocol.examples)
    refused = sum(1 for e in g.protocol.errata if e.check.kind == "frame_fails" and e.check.frame is not None)
    assert (run.returncode, run.stdout) == (
        0,
        f"{g.protocol.name}: {examples} vectors, {refused} refused frames, 0 failed\n",
    ), run.stdout + run.stderr


@pytest.mark.parametrize("case", ["bytes, size field of u64", "array, count field of u64"])
def test_a_64_bit_size_is_refused_not_cut_to_a_32_bit_size_t(case: str, tmp_path: Path) -> None:
    """A size or count field of u64 whose value a 32-bit size_t cannot hold (2**32 + 2): gcc -m32's C refuses the
    frame, as Python does, where casting it to size_t would read it as 2 and decode the frame."""
    from test_language_matrix import build, package

    built = build(case)
    source = tmp_path / "c"
    source.mkdir()
    for path, text in built.files.items():
        if path.startswith("c/matrix_case/"):
            (source / path.rsplit("/", 1)[1]).write_text(text, encoding="utf-8")
    run = Driver("matrix_case", source, tmp_path, tuple(compiler("gcc-m32")), "gcc-m32")
    try:
        with package(built) as g:
            request = next(m for m in g.protocol.messages() if m.direction == Direction.REQUEST)
            cls = message_class(g, request)
            fields = {"id": 1, "data": b"\x01\x02", "tail": 3} if "bytes" in case else {"id": 1, "items": [1, 2]}
            frame = bytearray(g.package.encode(cls.from_fields(fields)))
            layout = g.protocol.framing.layouts[Direction.REQUEST]
            at = layout.offsets["content"]
            assert frame[at : at + 8] == (2).to_bytes(8, "little")
            total = sum(frame[len(layout.header) : -1]) & 0xFF
            frame[at + 4] = 1  # n = 2**32 + 2: the sum of the covered bytes one more
            frame[-1] = (frame[-1] + 1) & 0xFF if total == frame[-1] else (frame[-1] - 1) & 0xFF
            with pytest.raises(DecodeError):
                g.package.decode(bytes(frame), "request")
            (answer,) = run.ask(f"dec request {bytes(frame).hex()}")
            assert answer.startswith("err "), answer
    finally:
        run.close()


@pytest.mark.skipif(GCC is None, reason="no gcc")
@pytest.mark.parametrize(
    ("fields", "frame", "expected"),
    [
        # check = 7 / n, n = 0 from the wire: no value (undefined in C), so no frame, not a crash
        ({"n": "u8", "check": {"type": "u8", "value": "7 / n"}}, "aa 55 01 02 00 00 03", "err E_CONTENT"),
        ({"n": "u8", "check": {"type": "u8", "value": "7 / n"}}, "aa 55 01 02 07 01 0b", 'ok {"n": 7}'),
        ({"n": "u8", "check": {"type": "u8", "value": "100 % (n - 1)"}}, "aa 55 01 02 01 00 04", "err E_CONTENT"),
        ({"n": "u8", "check": {"type": "u8", "value": "ceil(9 / n)"}}, "aa 55 01 02 00 00 03", "err E_CONTENT"),
        (
            {"n": "u8", "s": "i8", "check": {"type": "u8", "value": "n >> s"}},
            "aa 55 01 03 01 ff 00 04",
            "err E_CONTENT",
        ),
    ],
)
def test_a_value_with_no_value_for_the_wire_is_refused_not_undefined(
    fields: dict[str, Any], frame: str, expected: str, tmp_path: Path
) -> None:
    """A `value:` expression dividing by a field (or shifting by one) that the frame gives as 0 (or negative):
    the C decoder refuses the frame (E_CONTENT), as the Python codec raises DecodeError, where C's own division
    would be undefined (a SIGFPE, or the sanitizer's report)."""
    import yaml
    from serialspec.lang.loader import load_text
    from serialspec.lang.resolve import resolve

    spec = yaml.safe_load(
        (ROOT / "tests" / "adversarial" / "specs" / "derived_divides_by_a_wire_zero.yaml").read_text()
    )
    spec["commands"]["set"]["request"]["fields"] = fields
    protocol = resolve(load_text(yaml.safe_dump(spec, sort_keys=False), "divides.yaml"))
    source = tmp_path / "c"
    source.mkdir()
    for path, text in c_files(protocol).items():
        (source / Path(path).name).write_text(text, encoding="utf-8")
    run = Driver(protocol.name, source, tmp_path)
    try:
        (answer,) = run.ask(f"dec request {bytes.fromhex(frame).hex()}")
    finally:
        run.close()
    status, _, rest = answer.partition(" ")
    if expected.startswith("ok "):
        assert status == "ok" and json.loads(rest)["fields"] == json.loads(expected[3:]), answer
    else:
        assert answer.startswith("err ") and expected[4:] in answer, answer


@pytest.mark.skipif("modbus_ascii" not in IDS, reason="the C target refuses modbus_ascii")
def test_hex_ascii_frames_in_lower_case_and_cut_by_a_colon_read_as_python_reads_them() -> None:
    """Modbus ASCII (`method: hex_ascii`): lower-case digits decode as upper-case ones (and encode back in upper case);
    a frame cut short by a ':' (the next frame's start) and hex digits, CR LF or a lone CR around frames, fed byte by
    byte and in other pieces, give what the Python parser gives."""
    g = next(g for g in C_SPECS if g.protocol.name == "modbus_ascii")
    for example in g.protocol.examples:
        lower = example.frame[:1] + example.frame[1:-2].lower() + example.frame[-2:]
        assert lower != example.frame
        check_decode_agrees(g, lower, example.direction)
        (answer,) = driver("modbus_ascii").ask(f"rt {example.direction.value} {lower.hex()}")
        assert answer == f"ok {example.frame.hex()}"
    frames = [e.frame for e in g.protocol.examples if e.direction == Direction.REQUEST]
    pieces = [b"0A", frames[0][:7], frames[0], b"\r", frames[-1][:-1], b":", frames[-1], b"1\r\n", frames[0].lower()]
    for sizes in ("1", "2,3", "7,1,13", "64"):
        stream_agrees_with_python(driver("modbus_ascii"), g, Direction.REQUEST, b"".join(pieces), sizes)


@pytest.mark.skipif(GCC is None, reason="no gcc")
def test_cobs_without_a_code_after_a_last_full_run_writes_what_the_cobs_package_writes(tmp_path: Path) -> None:
    """`code_after_full_run: false`: a span that ends with a run of 254 non-zero bytes ends there, as the `cobs`
    package writes it, in Python and in C; both take the PacketSerial form (the code byte 01 after it) too."""
    from cobs import cobs
    from test_language_matrix import build, package

    built = build("transform: cobs, a last run of 254 bytes ended without the code byte 01 (the `cobs` package)")
    source = tmp_path / "c"
    source.mkdir()
    for path, text in built.files.items():
        if path.startswith("c/matrix_case/"):
            (source / path.rsplit("/", 1)[1]).write_text(text, encoding="utf-8")
    run = Driver("matrix_case", source, tmp_path)
    try:
        with package(built) as g:
            request = next(m for m in g.protocol.messages() if m.direction == Direction.REQUEST)
            cls = message_class(g, request)
            for size in (251, 250, 252, 0):  # the span: code, v (2 bytes), data
                message = cls.from_fields({"v": 0x0101, "data": b"\x11" * size})
                frame = g.package.encode(message)
                plain = cobs.decode(frame[:-1])
                assert 0 not in plain and frame == bytes(cobs.encode(plain)) + b"\x00"
                full = len(plain) % 254 == 0
                paper = frame[:-1] + b"\x01\x00" if full else frame  # the form with the code byte after the run
                for given in {frame, paper}:
                    assert g.package.decode(given, "request") == message
                    (answer,) = run.ask(f"rt request {given.hex()}")
                    assert answer == f"ok {frame.hex()}", (size, answer)
    finally:
        run.close()
