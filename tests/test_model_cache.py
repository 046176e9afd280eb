"""The resolved model's cache (serialspec.cli.protocols.resolved): the commands that read a spec (`decode`) take its
model from there, so it must only ever save time: equal to a fresh resolution, missed by any other text, name or
language, and rebuilt when damaged."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from serialspec import cache
from serialspec.cli import protocols
from serialspec.lang import load_protocol

ROOT = Path(__file__).resolve().parent.parent
SPECS = sorted((ROOT / "specs").glob("*.yaml"))


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    where = tmp_path / "cache"
    monkeypatch.setenv("SERIALSPEC_CACHE_DIR", str(where))
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    cache.folder.cache_clear()
    yield where
    cache.folder.cache_clear()


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


def test_decode_by_package_name_imports_neither_yaml_nor_the_resolver(tmp_path: Path) -> None:
    """The start-up work `decode PACKAGE HEX` does, once the model is cached (bench/startup.py times it)."""
    code = (
        "import sys\n"
        "from serialspec.cli import main\n"
        "main(['decode', 'feetech_sms', 'ff ff 01 02 01 fb', '--direction', 'request'])\n"
        "print(sorted(m for m in sys.modules if m in ('yaml', 'serialspec.lang.resolve', 'serial', 'shutil',"
        " 'serialspec.runtime.transport', 'serialspec.runtime.device')))\n"
    )
    env = {"SERIALSPEC_CACHE_DIR": str(tmp_path / "cache"), "PATH": ""}
    first = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert first.stdout.splitlines()[-1] == "['serialspec.lang.resolve', 'yaml']"  # resolved once, and stored
    again = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert again.stdout.splitlines()[:2] == [
        "feetech_sms request ping  [ff ff 01 02 01 fb]",
        "  id                   1",
    ]
    assert again.stdout.splitlines()[-1] == "[]"
