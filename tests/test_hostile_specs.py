"""The hostile-spec corpus (tests/hostile_cases.py): every malformed spec gives its one error line, every valid one
generates a package that imports, runs its examples and carries hostile text inert; a few pass ruff and mypy."""

from __future__ import annotations

import ast
import copy
import importlib
import logging
import os
import re
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

import pytest
from hostile_cases import CASES, HOSTILE, Mutation, Text, both, put
from hostile_run import BASES, base, outcome
from serialspec.backends.python.memory import imported
from serialspec.lang import SpecErrors, load_protocol

LINE = re.compile(r"^(?P<file>[\w.]+\.yaml):(?P<line>[1-9]\d*):(?P<column>[1-9]\d*): (?P<rest>.+)$")
ROOT = Path(__file__).resolve().parent.parent


def test_the_corpus_covers_every_class_with_150_cases() -> None:
    assert len(CASES) >= 150
    assert len({case[0] for case in CASES}) == len(CASES)
    assert sum(1 for case in CASES if case[3] is None) >= 10


@pytest.mark.parametrize(("base_name", "mutation", "expected"), [pytest.param(*c[1:], id=c[0]) for c in CASES])
def test_hostile_spec(base_name: str, mutation: Mutation | Text, expected: str | None) -> None:
    lines, files = outcome(base_name, mutation)
    if expected is not None:
        assert len(lines) == 1, lines
        match = LINE.match(lines[0])
        assert match, lines[0]
        assert match["rest"] == expected
        return
    assert lines == []
    inert(files)


NESTING = [pytest.param(*c[1:], id=c[0]) for c in CASES if c[3] and ("nested" in c[3] or "YAML syntax" in c[3])]


@pytest.mark.parametrize("composer", ["libyaml", "pure-Python"])
@pytest.mark.parametrize(("base_name", "mutation", "expected"), NESTING)
def test_yaml_errors_do_not_depend_on_the_pyyaml_build(
    base_name: str, mutation: Mutation | Text, expected: str | None, composer: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same line, path included, whether PyYAML has libyaml or not (the pure composer recurses per level)."""
    import yaml
    from serialspec.lang import loader

    if composer == "libyaml" and not hasattr(yaml, "CSafeLoader"):
        pytest.skip("this PyYAML has no libyaml")
    monkeypatch.setattr(loader, "_COMPOSER", yaml.CSafeLoader if composer == "libyaml" else yaml.SafeLoader)
    lines, _ = outcome(base_name, mutation)
    assert [LINE.match(line)["rest"] for line in lines if LINE.match(line)] == [expected]  # type: ignore[index]


def inert(files: dict[str, str]) -> None:
    """The package imports, every module; spec text stayed text in the code and markdown in the docs."""
    package = next(path.partition("/")[0] for path in files if path.endswith("/__init__.py"))
    modules = {path.partition("/")[2]: text for path, text in files.items() if path.startswith(package + "/")}
    with imported(package, modules):
        for name in modules:
            if name.endswith(".py") and name != "__init__.py":
                importlib.import_module(f"{package}.{name.removesuffix('.py')}")
    for name, source in modules.items():
        if name.endswith(".py"):
            tree = ast.parse(source, name)
            imported_names = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
            assert "os" not in imported_names, name
            assert not any(isinstance(n, ast.Attribute) and n.attr == "system" for n in ast.walk(tree)), name
    docs = files[f"docs/{package}.md"]
    assert "<script>" not in docs and "</td>" not in docs


# --- generated code of valid but unusual specs passes the project's own gate ----------------------------------------

LINTED = {
    "tiny_hostile": both(
        put("description", HOSTILE),
        put("commands/move/description", HOSTILE),
        put("commands/move/request/fields/angle/description", HOSTILE),
        put("enums/mode/values/fast", {"value": 1, "text": HOSTILE}),
        put("tables/regs/entries/speed/unit", HOSTILE),
    ),
    "tiny_minimal": next(c[2] for c in CASES if c[0] == "minimal spec"),  # type: ignore[misc]
    "tiny_close": next(c[2] for c in CASES if c[0] == "command named like a runtime method"),  # type: ignore[misc]
    "tiny_register_id": next(c[2] for c in CASES if c[0] == "register named id"),  # type: ignore[misc]
    "tiny_reply_bits": next(c[2] for c in CASES if c[0] == "reply with bits"),  # type: ignore[misc]
}


def test_generated_code_of_unusual_specs_passes_ruff_and_mypy(tmp_path: Path) -> None:
    for name, mutation in LINTED.items():
        lines, files = outcome("tiny", both(mutation, put("protocol", name)))  # type: ignore[arg-type]
        assert lines == [], lines
        for path, text in files.items():
            if path.startswith(name + "/"):
                (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
                (tmp_path / path).write_text(text, encoding="utf-8")
    config = str(ROOT / "pyproject.toml")
    packages = [str(tmp_path / name) for name in LINTED]
    ruff = subprocess.run(
        # generated code may have long lines (pyproject's per-file rule for generated/, which tmp_path is not under)
        [sys.executable, "-m", "ruff", "check", "--no-cache", "--config", config, "--ignore", "E501", *packages],
        capture_output=True,
        text=True,
    )
    assert ruff.returncode == 0, ruff.stdout + ruff.stderr
    environment = {**os.environ, "MYPYPATH": str(ROOT / "generator")}
    mypy = subprocess.run(
        [sys.executable, "-m", "mypy", "--config-file", config, "--no-incremental", *packages],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=environment,
    )
    assert mypy.returncode == 0, mypy.stdout + mypy.stderr


# --- what the loader, the CLI and the simulator do with what the table cannot express --------------------------------


def test_a_folder_or_a_missing_file_is_one_line(tmp_path: Path) -> None:
    missing = "cannot read the spec: No such file or directory"
    for path, words in ((tmp_path, "is a folder, not a spec file"), (tmp_path / "none.yaml", missing)):
        with pytest.raises(SpecErrors) as failure:
            load_protocol(str(path), "x.yaml")
        assert str(failure.value) == f"x.yaml:1:1: {words}"


def test_cli_refuses_hostile_files_without_traceback(tmp_path: Path) -> None:
    (tmp_path / "specs").mkdir()
    bomb = next(c[2] for c in CASES if c[0] == "alias bomb")
    assert isinstance(bomb, Text)
    (tmp_path / "specs" / "bomb.yaml").write_bytes(bomb.make(BASES["tiny"].read_text(encoding="utf-8")))
    (tmp_path / "specs" / "latin.yaml").write_bytes(b"protocol: caf\xe9\n")
    result = subprocess.run(
        [sys.executable, "-m", "serialspec", "check", "--root", str(tmp_path)], capture_output=True, text=True
    )
    assert result.returncode == 1
    assert "Traceback" not in result.stderr
    assert "specs/bomb.yaml:" in result.stderr and "YAML bomb" in result.stderr
    assert "specs/latin.yaml:1:14: not UTF-8 text: byte 0xe9" in result.stderr
    decode = subprocess.run(
        [sys.executable, "-m", "serialspec", "decode", str(tmp_path / "specs"), "00"], capture_output=True, text=True
    )
    assert decode.returncode != 0 and "Traceback" not in decode.stderr
    assert len(decode.stderr.splitlines()) == 1 and str(tmp_path / "specs") in decode.stderr


def test_a_reply_the_simulator_cannot_build_is_logged(caplog: pytest.LogCaptureFixture) -> None:
    # no value the device knows, and its kind's blank (0) is outside the field's range
    mutation = put("commands/move/response/fields/ok", {"type": "u8", "range": [5, 10]})
    lines, files = outcome("tiny", mutation)
    assert lines == []
    modules = {path.partition("/")[2]: text for path, text in files.items() if path.startswith("tiny/")}
    with imported("tiny", modules) as package:
        simulator = importlib.import_module("tiny.simulator").SIMULATOR(ids=[1])
        try:
            request = package.messages.MoveRequest(id=1, angle=0, mode=0, time=0)
            with caplog.at_level(logging.WARNING, logger="serialspec.sim"):
                assert simulator.feed(package.encode(request)) == []
        finally:
            simulator.close()
    assert [r.getMessage() for r in caplog.records] == [
        caplog.records[0].getMessage()
    ] and "no MoveResponse reply" in caplog.records[0].getMessage()


def test_the_base_specs_are_valid() -> None:
    for name in BASES:
        data = copy.deepcopy(base(name).data)
        assert data["protocol"]
        assert outcome(name, lambda _data: None)[0] == []


def test_sim_refuses_ids_no_device_can_have() -> None:
    for spec, argv, words in (
        ("feetech_sms", ["--id", "300"], "--id 300 is outside the spec's id range 0..253"),
        ("feetech_sms", ["--id", "254"], "(254 is the broadcast id)"),
        ("feetech_sms", ["--id", "-1"], "--id -1 is outside"),
        ("modbus_rtu", ["--id", "248"], "--id 248 is outside the spec's id range 1..247"),  # the frame element's range
        ("vesc", ["--id", "3"], "--id: vesc frames carry no device address"),
    ):
        result = subprocess.run(
            [sys.executable, "-m", "serialspec", "sim", str(ROOT / "specs" / f"{spec}.yaml"), *argv],
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert result.returncode == 1 and result.stdout == ""
        assert result.stderr.strip().splitlines() == [result.stderr.strip()] and words in result.stderr


# --- spec text in the documentation site: no live link to a script, no attribute of its own --------------------------

LINKS = (
    "[a](javascript:alert(1)) [b](data:text/html,x) [c]( VBScript:msgbox(1)) ![d](JAVA\\script:1)"
    ' [e](http://x.example){: onclick="alert(2)" } [f][r] {: onmouseover=alert(3) }'
)
TEXT_KEYS = {"description", "title", "title_cn", "name_cn", "text", "unit", "source", "notes", "optional", "inferred"}


class Attributes(HTMLParser):
    """Every attribute of every element of a page, as (tag, name, value)."""

    def __init__(self) -> None:
        super().__init__()
        self.found: list[tuple[str, str, str]] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.found.extend((tag, name, value or "") for name, value in attrs)


def linked(node: Any, key: str = "") -> Any:
    """The spec's data with every free text (and every source document's name) replaced by LINKS, the first of
    them opening with a reference definition."""
    if isinstance(node, dict):
        return {k: LINKS if key == "sources" else linked(v, k) for k, v in node.items()}
    if isinstance(node, list):
        return [linked(v, key) for v in node]
    return LINKS if isinstance(node, str) and key in TEXT_KEYS else node


@pytest.mark.parametrize("base_name", sorted(BASES))
def test_spec_text_in_the_docs_site_links_nowhere_unsafe(base_name: str) -> None:
    """`[x](javascript:...)` in a description used to be a live link in the site (and `{: onclick=...}` an attribute
    under its attr_list extension): links to other schemes than http, https and mailto, reference definitions and
    attribute lists in spec text are shown as text, on the page rendered as `make docs` renders it."""
    import markdown

    def mutate(data: dict[str, Any]) -> None:
        changed = linked(data)
        changed["description"] = "[r]: javascript:alert(4) " + LINKS
        data.clear()
        data.update(changed)

    lines, files = outcome(base_name, mutate)
    assert lines == []
    page = next(text for path, text in files.items() if path.startswith("docs/") and path.endswith(".md"))
    html = markdown.markdown(page, extensions=["tables", "attr_list", "toc"])
    parser = Attributes()
    parser.feed(html)
    assert parser.found
    for tag, name, value in parser.found:
        assert not name.startswith("on"), (tag, name, value)
        if name in {"href", "src"}:
            scheme = re.match(r"\s*([a-z][a-z0-9+.-]*):", value.replace("\\", ""), re.IGNORECASE)
            assert scheme is None or scheme[1].lower() in {"http", "https", "mailto"}, (tag, name, value)
    assert "javascript:alert(1)" in html  # shown, as text
