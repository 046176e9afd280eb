"""The generator's modules import each other one way: the import graph of generator/serialspec, read from the source
with ast (every import: at the top, inside a function, under TYPE_CHECKING), has no circle but the allowed ones.

A module's imports of a package's submodule count as an arrow to that submodule, not to the package's __init__ (which
Python runs first, but which only hands names on); `from package import name` is an arrow to package/name.py where
that file exists, else to the package.
"""

from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent / "generator"
PACKAGE = ROOT / "serialspec"

# Circles that stay, each with its reason. Keep it short: a new circle is a module in the wrong place.
ALLOWED: dict[frozenset[str], str] = {
    frozenset({"serialspec.backends.markdown.docs", "serialspec.backends.markdown.text"}): (
        "a text protocol's page (text.py) takes the binary page's text helpers, and emit_docs hands text protocols "
        "to it: the helpers belong in a module of their own"
    ),
}


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules() -> dict[str, Path]:
    return {module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def imports(path: Path, name: str, known: dict[str, Path]) -> set[str]:
    """The modules of the package that a module imports, anywhere in it."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, *([base] if base else [])])
            for alias in node.names:
                submodule = f"{base}.{alias.name}"
                found.add(submodule if submodule in known else base)
    return {target for target in found if target in known and target != name}


@cache  # two tests read it: the package is parsed once
def graph() -> dict[str, set[str]]:
    known = modules()
    return {name: imports(path, name, known) for name, path in known.items()}


def circles(edges: dict[str, set[str]]) -> list[frozenset[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[frozenset[str]] = []
    for root in edges:
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, targets = work[-1]
            target = next(targets, None)
            if target is not None:
                if target not in index:
                    index[target] = low[target] = len(index)
                    stack.append(target)
                    on_stack.add(target)
                    work.append((target, iter(sorted(edges[target]))))
                elif target in on_stack:
                    low[node] = min(low[node], index[target])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = set()
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.add(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(frozenset(component))
    return found


def test_the_finder_sees_a_circle() -> None:
    edges = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": set()}
    assert circles(edges) == [frozenset({"a", "b", "c"})]
    assert circles({"a": {"b"}, "b": set()}) == []


def test_the_graph_reads_the_imports() -> None:
    edges = graph()
    assert "serialspec.backends.c.emit" in edges["serialspec.backends.c.files"]
    assert "serialspec.backends.c.packed" in edges["serialspec.backends.c.emit"]  # `from package import module`


def test_no_circle_of_imports() -> None:
    edges = graph()
    found = circles(edges)
    unexpected = []
    for component in found:
        if component in ALLOWED:
            continue
        ties = sorted(f"{a} -> {b}" for a in component for b in edges[a] if b in component)
        unexpected.append(f"{len(component)} modules import each other: " + "; ".join(ties))
    assert not unexpected, "\n".join(unexpected)
    stale = [sorted(component) for component in ALLOWED if component not in found]
    assert not stale, f"allowed circles that are gone (drop them from ALLOWED): {stale}"
