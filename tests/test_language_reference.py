"""The spec language's reference and the JSON Schema's hover help come from the grammar: every key is described."""

from __future__ import annotations

import json
import re
from typing import Any

from conftest import ROOT
from serialspec.lang.grammar import json_schema
from serialspec.lang.reference import NAME, dotted, keys, reference_markdown, undocumented


def test_every_key_of_the_grammar_has_a_description() -> None:
    assert undocumented() == [], "describe these keys where lang/grammar.py declares them"


def _schema_nodes(node: Any, path: str = "") -> list[tuple[str, dict[str, Any]]]:
    found = []
    if isinstance(node, dict):
        if "type" in node or "anyOf" in node:
            found.append((path, node))
        for key, value in node.get("properties", {}).items():
            found += _schema_nodes(value, f"{path}.{key}")
        for part in ("additionalProperties", "items"):
            if isinstance(node.get(part), dict):
                found += _schema_nodes(node[part], f"{path}.{part}")
        for index, option in enumerate(node.get("anyOf", [])):
            found += _schema_nodes(option, f"{path}.anyOf[{index}]")
    return found


def test_the_json_schema_has_no_key_without_a_description() -> None:
    nodes = _schema_nodes(json_schema())
    assert len(nodes) > 400
    assert [path for path, node in nodes if not node.get("description")] == []


def test_the_committed_schema_is_the_grammars() -> None:
    committed = json.loads((ROOT / "specs" / "serialspec.schema.json").read_text(encoding="utf-8"))
    assert committed == json_schema()


def test_the_reference_shows_every_key_with_its_description() -> None:
    text = reference_markdown([])
    for key in keys():
        name = key.path[-1]
        if name != NAME:
            assert f"| `{name}` |" in text, dotted(key.path)
        assert key.description.split("\n")[0][:40].replace("|", "\\|") in text, dotted(key.path)


def test_the_reference_takes_examples_from_specs() -> None:
    text = reference_markdown([{"serial": {"baudrate": 4242}}])
    assert "| `baudrate` | integer | required | Bits per second. | `4242` |" in text


def test_every_plain_key_of_the_committed_reference_has_an_example() -> None:
    # From the shipped specs, else from the grammar's `example=`: a key no spec uses needs one in grammar.py.
    text = (ROOT / "docs" / "language.md").read_text(encoding="utf-8")
    rows = [row.split(" | ") for row in text.splitlines() if row.startswith("| `")]
    assert len(rows) > 150
    missing = [row[0] for row in rows if row[4].startswith("—") and "See [" not in row[3]]
    assert missing == [], "no spec uses these keys: give their shapes in lang/grammar.py an example= value"


def test_the_reference_names_no_path_inside_this_repository() -> None:
    """A user reads the reference beside their own specs: no source file or repo folder they do not have."""
    text = reference_markdown([])
    assert not re.findall(r"\w+\.py\b|specs/|generator/|serialspec/spec", text)
