"""The caches generation keeps (serialspec.cache): compiled generated modules and compiled templates.

A cache may only ever save time: an entry built from other text, by other settings, or damaged in any way is
rebuilt, never used; and an unwritable or forbidden cache folder changes nothing but the time.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import jinja2
import pytest
from serialspec import cache
from serialspec.backends.common import render
from serialspec.cli import protocols
from serialspec.lang import load_protocol


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """An empty cache folder of the test's own, caches written (whatever PYTHONDONTWRITEBYTECODE says)."""
    where = tmp_path / "cache"
    monkeypatch.setenv("SERIALSPEC_CACHE_DIR", str(where))
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    cache.folder.cache_clear()
    yield where
    cache.folder.cache_clear()


def run(source: str, filename: str = "<test>") -> Any:
    namespace: dict[str, Any] = {}
    exec(cache.compiled(source, filename, "pkg.module.py"), namespace)
    return namespace["VALUE"]


def entries(folder: Path) -> list[Path]:
    return sorted(p for p in folder.rglob("*") if p.is_file())


def refuse_to_compile(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("compiled although the cache holds the code")

    monkeypatch.setattr(cache, "compile", refuse, raising=False)  # the module's `compile`, ahead of the builtin


def test_a_module_compiled_once_is_read_back_from_the_cache(folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert run("VALUE = 1") == 1
    assert len(entries(folder)) == 1
    refuse_to_compile(monkeypatch)
    assert run("VALUE = 1") == 1


def test_a_changed_source_is_compiled_again_and_replaces_its_entry(folder: Path) -> None:
    assert run("VALUE = 1") == 1
    assert run("VALUE = 2") == 2  # same module, same file name: the entry's key no longer matches
    assert len(entries(folder)) == 1
    assert run("VALUE = 2") == 2
    assert run("VALUE = 1") == 1


def test_the_file_name_the_code_reports_is_part_of_the_key(folder: Path) -> None:
    code = cache.compiled("VALUE = 1", "<a.yaml>", "pkg.module.py")
    assert cache.compiled("VALUE = 1", "<b.yaml>", "pkg.module.py").co_filename == "<b.yaml>"
    assert cache.compiled("VALUE = 1", "<a.yaml>", "pkg.module.py").co_filename == code.co_filename == "<a.yaml>"


def test_no_future_flags_leak_from_the_cache_module_into_generated_code(folder: Path) -> None:
    # serialspec.cache has `from __future__ import annotations`; a generated module without it must see its
    # annotations evaluated, as when Python imports its file.
    namespace: dict[str, Any] = {}
    exec(cache.compiled("x: int = 1\nVALUE = __annotations__", "<t>", "pkg.module.py"), namespace)
    assert namespace["VALUE"] == {"x": int}


@pytest.mark.parametrize(
    "damage",
    [
        lambda data: data[: len(data) // 2],  # truncated
        lambda data: b"",
        lambda data: b"\x00" * len(data),
        lambda data: data[:-1] + bytes([data[-1] ^ 0xFF]),  # one bit pattern changed in the marshalled code
        lambda data: data[:30] + bytes([data[30] ^ 0xFF]) + data[31:],  # in the key
    ],
    ids=["truncated", "empty", "zeroed", "payload", "key"],
)
def test_a_damaged_entry_is_ignored_and_rewritten(folder: Path, damage: Any) -> None:
    assert run("VALUE = 'first'") == "first"
    [entry] = entries(folder)
    intact = entry.read_bytes()
    entry.write_bytes(damage(intact))
    assert run("VALUE = 'first'") == "first"
    assert entry.read_bytes() == intact


def test_an_entry_that_is_a_folder_or_unreadable_changes_nothing_but_the_time(folder: Path) -> None:
    assert run("VALUE = 1") == 1
    [entry] = entries(folder)
    entry.unlink()
    entry.mkdir()  # neither readable nor replaceable as a file
    assert run("VALUE = 1") == 1
    assert run("VALUE = 3") == 3


def test_a_folder_keeps_the_entries_written_last(folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    for number in range(5):
        cache.store(f"some/{number}", cache.key(str(number)), b"payload", keep=3)
    assert sorted(p.name for p in (folder / "some").iterdir()) == ["2", "3", "4"]
    assert cache.load("some/4", cache.key("4")) == b"payload"
    monkeypatch.setattr(cache, "MAX_FOLDER_BYTES", 2 * len((folder / "some" / "4").read_bytes()))
    cache.store("some/5", cache.key("5"), b"payload", keep=3)
    assert sorted(p.name for p in (folder / "some").iterdir()) == ["4", "5"]  # the size limit, before the count


def test_nothing_is_written_when_python_may_not_write_bytecode(folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    assert run("VALUE = 1") == 1
    assert entries(folder) == []


@pytest.mark.parametrize("setting", ["", "{tmp}/file/cache"], ids=["empty", "under-a-file"])
def test_no_cache_folder_changes_nothing_but_the_time(
    setting: str, monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    (tmp_path / "file").write_text("not a folder")
    monkeypatch.setenv("SERIALSPEC_CACHE_DIR", setting.format(tmp=tmp_path))  # empty: the caches are off
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    cache.folder.cache_clear()
    try:
        assert cache.folder() is None
        assert run("VALUE = 1") == 1
    finally:
        cache.folder.cache_clear()


# --- compiled templates -------------------------------------------------------------------------------------------


def environment(templates: dict[str, str], **settings: Any) -> jinja2.Environment:
    """An environment like the targets' (serialspec.backends.common.render), over templates held in memory."""
    env = jinja2.Environment(loader=jinja2.DictLoader(templates), **{**render._SETTINGS, **settings})
    env.bytecode_cache = render._Cache(env)
    return env


def test_a_compiled_template_is_read_back_from_the_cache(folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert environment({"t": "{{ x }}!"}).get_template("t").render(x=1) == "1!"
    assert len(entries(folder)) == 1

    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("compiled although the cache holds the template")

    monkeypatch.setattr(jinja2.Environment, "compile", refuse)
    assert environment({"t": "{{ x }}!"}).get_template("t").render(x=2) == "2!"


def test_an_edited_template_is_never_rendered_from_its_old_entry(folder: Path) -> None:
    assert environment({"t": "old {{ x }}"}).get_template("t").render(x=1) == "old 1"
    assert environment({"t": "new {{ x }}"}).get_template("t").render(x=1) == "new 1"
    assert environment({"t": "new {{ x }}"}).get_template("t").render(x=1) == "new 1"


def test_other_environment_settings_do_not_use_the_entry(folder: Path) -> None:
    source = {"t": "{% if x %}\n  yes\n{% endif %}\n"}
    assert environment(source).get_template("t").render(x=1) == "  yes\n"
    untrimmed = environment(source, trim_blocks=False, lstrip_blocks=False)
    assert untrimmed.get_template("t").render(x=1) == "\n  yes\n\n"


def test_a_damaged_template_entry_is_compiled_afresh(folder: Path) -> None:
    assert environment({"t": "{{ x }}"}).get_template("t").render(x=1) == "1"
    [entry] = entries(folder)
    entry.write_bytes(entry.read_bytes()[:-10])
    assert environment({"t": "{{ x }}"}).get_template("t").render(x=2) == "2"
    entry.write_bytes(b"garbage")
    assert environment({"t": "{{ x }}"}).get_template("t").render(x=3) == "3"


# --- a spec's outputs ---------------------------------------------------------------------------------------------

ROOT = Path(__file__).resolve().parent.parent


def generate(project: Path, cache_folder: str, verb: str = "generate") -> subprocess.CompletedProcess[str]:
    """`serialspec generate` (or `check`) of a project in a fresh process, with a cache folder of its own."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["SERIALSPEC_CACHE_DIR"] = cache_folder
    command = [sys.executable, "-m", "serialspec", verb, "--root", str(project)]
    return subprocess.run(command, capture_output=True, text=True, env=env)


def tree(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and "__pycache__" not in p.parts
    }


@pytest.fixture
def project(tmp_path: Path) -> Path:
    shutil.copytree(ROOT / "specs", tmp_path / "project" / "specs")
    return tmp_path / "project"


def test_outputs_from_the_cache_are_the_files_generation_writes_without_it(project: Path, tmp_path: Path) -> None:
    assert generate(project, "").returncode == 0  # no cache at all
    fresh = tree(project / "generated")
    shutil.rmtree(project / "generated")
    folder = tmp_path / "cache"
    assert generate(project, str(folder)).returncode == 0  # fills the cache
    assert sorted(p.name.split(".")[0] for p in (folder / "outputs").iterdir()) == sorted(
        p.stem for p in (project / "specs").glob("*.yaml")
    )
    shutil.rmtree(project / "generated")
    from_cache = generate(project, str(folder))
    assert from_cache.returncode == 0, from_cache.stderr
    assert tree(project / "generated") == fresh
    assert generate(project, str(folder), "check").returncode == 0


def test_an_edited_spec_is_generated_again(project: Path, tmp_path: Path) -> None:
    folder = str(tmp_path / "cache")
    assert generate(project, folder).returncode == 0
    spec = project / "specs" / "fashionstar_uart.yaml"
    spec.write_text(spec.read_text(encoding="utf-8").replace("Ping servo 3.", "Ping servo number 3."))
    assert generate(project, folder, "check").returncode == 1  # stale, not answered from the cache
    assert generate(project, folder).returncode == 0
    assert "Ping servo number 3." in (project / "generated" / "docs" / "fashionstar_uart.md").read_text()
    assert generate(project, folder, "check").returncode == 0


def test_a_failing_example_is_reported_on_every_run(project: Path, tmp_path: Path) -> None:
    folder = str(tmp_path / "cache")
    spec = project / "specs" / "fashionstar_uart.yaml"
    text = spec.read_text(encoding="utf-8")
    spec.write_text(text.replace("    fields: {servo_id: 3}\n", "    fields: {servo_id: 4}\n", 1))
    line = text[: text.index("  ping_request:\n")].count("\n") + 2  # the example's first key
    reported = [generate(project, folder) for _ in range(2)]
    for result in reported:
        assert result.returncode == 1
        assert f"specs/fashionstar_uart.yaml:{line}:5: examples.ping_request: the frame decodes to other values: " in (
            result.stderr
        )
    assert reported[0].stderr == reported[1].stderr


def test_damaged_output_entries_are_ignored(project: Path, tmp_path: Path) -> None:
    folder = tmp_path / "cache"
    assert generate(project, str(folder)).returncode == 0
    written = tree(project / "generated")
    for entry in (folder / "outputs").iterdir():
        entry.write_bytes(entry.read_bytes()[:-7])
    result = generate(project, str(folder))
    assert result.returncode == 0 and " 0 changed" in result.stdout
    assert tree(project / "generated") == written


def test_the_generator_key_covers_every_source_and_template_of_the_package(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    package = Path(cache.__file__).parent
    copy = tmp_path / "serialspec"
    shutil.copytree(package, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(cache, "_PACKAGE", copy)
    fingerprint = cache.generator.__wrapped__
    before = fingerprint()
    (copy / "__pycache__").mkdir()
    (copy / "__pycache__" / "x.py").write_text("# not a source\n")
    assert fingerprint() == before
    for changed in (copy / "backends" / "markdown" / "templates" / "docs.md.j2", copy / "runtime" / "checksums.py"):
        original = changed.read_bytes()
        changed.write_bytes(original + b"\n")
        assert fingerprint() != before, changed
        changed.write_bytes(original)
    assert fingerprint() == before


def test_the_shipped_spec_is_the_text_as_a_text_file_reads_it(tmp_path: Path) -> None:
    """Generation reads a spec's bytes once (what it generates is what its cache key names); the copy a package
    ships is still the spec as `open(..., encoding="utf-8")` reads it, which `decode SPEC` compares it with."""
    from serialspec.cli.project import shipped_spec

    raw = "\ufeffprotocol: x\r\ntitle: é\rdescription: y\n".encode()
    spec = tmp_path / "x.yaml"
    spec.write_bytes(raw)
    assert shipped_spec("x.yaml", raw).partition("\n")[2] == spec.read_text(encoding="utf-8")


# --- the resolved model (serialspec.cli.protocols.resolved) ---------------------------------------------------------
# The commands that read a spec (`decode`) take its model from the cache: it must only ever save time, equal to a
# fresh resolution, missed by any other text, name or language, and rebuilt when damaged.

SPECS = sorted((ROOT / "specs").glob("*.yaml"))


def refuse_to_resolve(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*args: object) -> None:
        raise AssertionError("resolved although the cache holds the model")

    monkeypatch.setattr("serialspec.lang.resolve.load_protocol", refuse)


@pytest.mark.parametrize("spec", SPECS, ids=lambda p: p.stem)
def test_a_cached_model_equals_the_resolved_one(folder: Path, spec: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    data = spec.read_bytes()
    fresh = protocols.resolved(str(spec), spec.name, data)
    assert list((folder / "model").iterdir())
    refuse_to_resolve(monkeypatch)
    cached = protocols.resolved(str(spec), spec.name, data)
    assert cached == fresh == load_protocol(str(spec), spec.name)
    assert cached is not fresh


def test_other_text_another_name_or_another_language_misses(folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    spec = ROOT / "specs" / "fashionstar_uart.yaml"
    data = spec.read_bytes()
    first = protocols.resolved(str(spec), "fs.yaml", data)
    renamed = protocols.resolved(str(spec), "other.yaml", data)
    assert (first.spec_path, renamed.spec_path) == ("fs.yaml", "other.yaml")
    edited = folder.parent / "edited.yaml"
    edited.write_bytes(data.replace(b"title: Check that a servo is online", b"title: Is it there?"))
    assert protocols.resolved(str(edited), "fs.yaml", edited.read_bytes()).command("ping").title == "Is it there?"
    # an edit to the spec language (a module of lang/ changed): the stored model is not used
    calls = []
    real = load_protocol

    def counting(*args: str) -> object:
        calls.append(args)
        return real(*args)

    monkeypatch.setattr("serialspec.lang.resolve.load_protocol", counting)
    monkeypatch.setattr(cache, "language", lambda: b"another language")
    protocols.resolved(str(spec), "fs.yaml", data)
    assert len(calls) == 1


def test_a_damaged_model_entry_is_resolved_again(folder: Path) -> None:
    spec = ROOT / "specs" / "vesc.yaml"
    data = spec.read_bytes()
    fresh = protocols.resolved(str(spec), "vesc.yaml", data)
    (entry,) = (folder / "model").iterdir()
    entry.write_bytes(entry.read_bytes()[:-20])
    assert protocols.resolved(str(spec), "vesc.yaml", data) == fresh


def _decode_imports(tmp_path: Path, *options: str) -> list[str]:
    """The output of `decode feetech_sms PING` in a fresh process, then which of the heavy modules it imported."""
    code = (
        "import sys\n"
        "from serialspec.cli import main\n"
        f"main(['decode', 'feetech_sms', 'ff ff 01 02 01 fb', '--direction', 'request', *{options!r}])\n"
        "print(sorted(m for m in sys.modules if m in ('yaml', 'serialspec.lang.resolve', 'serialspec.lang.model', "
        "'serial', 'shutil', 'serialspec.runtime.transport', 'serialspec.runtime.device', 'dataclasses', 'inspect', "
        "'pickle')))\n"
    )
    env = {"SERIALSPEC_CACHE_DIR": str(tmp_path / "cache"), "PATH": ""}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True).stdout


def test_decode_by_package_name_imports_neither_the_model_nor_dataclasses(tmp_path: Path) -> None:
    """The start-up work `decode PACKAGE HEX` does (bench/startup.py times it): the generated package answers alone,
    without the spec's model (not even from the cache: no pickle), the language, dataclasses or inspect."""
    for _ in range(2):  # the first run too: nothing is resolved
        assert _decode_imports(tmp_path).splitlines() == [
            "feetech_sms request ping  [ff ff 01 02 01 fb]",
            "  id                   1",
            "[]",
        ]


def shipped_frames() -> dict[str, tuple[str, str]]:
    """Each shipped protocol (specs/*.yaml) -> a frame of its first example as `decode` takes it (hex, or a text
    protocol's sentence as typed) and its direction."""
    frames = {}
    for path in sorted((ROOT / "specs").glob("*.yaml")):
        protocol = load_protocol(str(path))
        if protocol.text is not None:
            text = protocol.text.examples[0]
            frames[protocol.name] = (text.printed, text.direction.value)
        else:
            example = protocol.examples[0]
            frames[protocol.name] = ((example.printed_text or example.frame).hex(" "), example.direction.value)
    return frames


def test_decode_of_every_shipped_package_imports_neither_the_model_nor_dataclasses(tmp_path: Path) -> None:
    """`decode PACKAGE HEX` of every shipped protocol (byte framings, COBS, escaping, optional elements, hex-ASCII,
    text) answers from the generated package alone, as bench/startup.py times it: in one fresh process, after each
    decode, none of the heavy modules (the model, the language, YAML, dataclasses, inspect, typing, pkgutil, pickle)
    has been imported, nor argparse (the command line `decode NAME HEX --direction D` is read without it) or json
    (list and bit-field values are written without it)."""
    frames = shipped_frames()
    code = (
        "import contextlib, io, sys\n"
        "from serialspec.cli import main\n"
        f"for name, (frame, direction) in {frames!r}.items():\n"
        "    out = io.StringIO()\n"
        "    with contextlib.redirect_stdout(out):\n"
        "        code = main(['decode', name, frame, '--direction', direction])\n"
        "    heavy = sorted(m for m in sys.modules if m in ('yaml', 'serialspec.lang.resolve', "
        "'serialspec.lang.model', 'dataclasses', 'inspect', 'typing', 'pkgutil', 'pickle', 'argparse', 'json'))\n"
        "    print(name, code, out.getvalue().split()[:2], heavy)\n"
    )
    env = {"SERIALSPEC_CACHE_DIR": str(tmp_path / "cache"), "PATH": ""}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True).stdout
    assert len(frames) >= 12
    assert out.splitlines() == [f"{name} 0 [{name!r}, {direction!r}] []" for name, (_, direction) in frames.items()]


def test_decode_with_units_takes_the_model_from_the_cache(tmp_path: Path) -> None:
    """What needs the spec (--units, --request, --file) reads its model, resolved once and then from the cache."""
    first = _decode_imports(tmp_path, "--units").splitlines()
    assert "'serialspec.lang.resolve', " in first[-1] and "'yaml'" in first[-1]  # resolved once, and stored
    again = _decode_imports(tmp_path, "--units").splitlines()
    assert again[:2] == ["feetech_sms request ping  [ff ff 01 02 01 fb]", "  id                   1"]
    assert "resolve" not in again[-1] and "yaml" not in again[-1] and "'serialspec.lang.model'" in again[-1]


def test_decode_by_package_says_what_decode_by_spec_says(capsys: pytest.CaptureFixture[str]) -> None:
    """`decode PACKAGE` (from the generated package alone) and `decode SPEC` print the same JSON for every example of
    every shipped binary spec that decodes alone (not a reply read with its request). Found: RoboClaw's read
    requests, whose layout has no CRC, were `"checksum_ok": true` from the package and null from the spec."""
    from serialspec.cli import main as serialspec_main

    compared = 0
    for path in sorted((ROOT / "specs").glob("*.yaml")):
        protocol = load_protocol(str(path))
        if protocol.text is not None:
            continue
        for example in protocol.examples:
            if example.request:
                continue
            frame = example.frame.hex(" ")
            shown = []
            for source in (protocol.name, str(path)):
                assert serialspec_main(["decode", source, frame, "--direction", example.direction.value, "--json"]) == 0
                shown.append(json.loads(capsys.readouterr().out))
            assert shown[0] == shown[1], (path.name, example.name)
            compared += 1
    assert compared > 50
