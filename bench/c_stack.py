"""The C target's worst-case stack on Cortex-M0+ and the line and branch coverage its golden vectors give
(c-target.md §4.6 and §5: "-fstack-usage maximums" and "maximum stack", "gcov coverage, reported").

Stack: each file is compiled as the flash table builds it (`-Os`, Cortex-M0+) with `-fcallgraph-info=su`, which
writes every function's own frame and the calls it makes. A public entry point's worst case is its frame plus its
deepest callee's, along the call graph; a call through a pointer (the frame writer's content encoder) is counted as
the deepest function of the file, so the figure is a bound. A recursive call would have no bound: it is named.
Coverage: gcc `--coverage` build of the protocol's test/check_vectors.c (the program a firmware developer builds
beside the vendored C), run once; gcov's line and branch figures of the generated .c.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import tempfile
from pathlib import Path

from bench.c_target import ARM, GENERATED, PROTOCOLS
from bench.timing import Table

ENTRY_POINTS = ("decode_expect", "encode", "parser_feed", "to_json")
_NODE = re.compile(r'node: \{ title: "([^"]+)" label: "([^"\\]+)(?:\\n[^"]*?)?(?:\\n(\d+) bytes \([^)]*\))?"')
_EDGE = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')


def _graph(text: str) -> tuple[dict[str, int], dict[str, set[str]], dict[str, str]]:
    """Frame size by node, callees by node, and node by function name, from a -fcallgraph-info file."""
    frames: dict[str, int] = {}
    names: dict[str, str] = {}
    calls: dict[str, set[str]] = {}
    for title, label, size in _NODE.findall(text):
        frames[title] = int(size) if size else 0
        names.setdefault(label.split(".")[0], title)
    for source, target in _EDGE.findall(text):
        calls.setdefault(source, set()).add(target)
    return frames, calls, names


def _worst(node: str, frames: dict[str, int], calls: dict[str, set[str]], path: tuple[str, ...] = ()) -> int:
    """A node's frame plus its deepest callee's; -1 on a cycle (no bound)."""
    if node in path:
        return -1
    deepest = 0
    for callee in calls.get(node, ()):
        if callee == "__indirect_call":  # the generated code's pointers are to its static (p__) functions
            seen = (*path, node)
            static = [n for n in frames if "__" in n.rsplit(":", 1)[-1] and n not in seen]
            below = max((_worst(n, frames, calls, seen) for n in static), default=0)
        else:
            below = _worst(callee, frames, calls, (*path, node))
        if below < 0:
            return -1
        deepest = max(deepest, below)
    return frames.get(node, 0) + deepest


def _stack(folder: Path, name: str) -> dict[str, int]:
    found: dict[str, int] = {}
    for source in (f"{name}.c", f"{name}_json.c"):
        out = folder / (Path(source).stem + ".o")
        command = ["arm-none-eabi-gcc", *ARM, "-fcallgraph-info=su", "-I", str(GENERATED / name)]
        subprocess.run([*command, "-c", str(GENERATED / name / source), "-o", str(out)], check=True, cwd=folder)
        frames, calls, names = _graph(out.with_suffix(".ci").read_text(encoding="utf-8"))
        for entry in ENTRY_POINTS:
            node = names.get(f"{name}_{entry}")
            if node is not None:
                found[entry] = _worst(node, frames, calls)
    return found


def _coverage(folder: Path, name: str) -> tuple[str, str]:
    """gcov's "Lines executed" and "Taken at least once" of the generated .c, run by the vector check."""
    exe = folder / "check"
    source = GENERATED / name / f"{name}.c"
    if not (GENERATED / name / "test" / "check_vectors.c").is_file():
        return "no vector check", "—"
    build = ["gcc", "-std=c99", "-O0", "--coverage", "-I", str(GENERATED / name)]
    subprocess.run(
        [*build, str(GENERATED / name / "test" / "check_vectors.c"), str(source), "-o", str(exe)],
        check=True,
        cwd=folder,
        capture_output=True,
    )
    subprocess.run([str(exe)], check=True, cwd=folder, capture_output=True)
    notes = folder / f"{exe.name}-{name}.gcda"  # gcc names a linked object's data after the program
    report = subprocess.run(["gcov", "-b", "-n", str(notes)], cwd=folder, capture_output=True, text=True).stdout
    part = report.split(f"File '{source}'", 1)[-1]
    lines = re.search(r"Lines executed:([\d.]+)% of (\d+)", part)
    branches = re.search(r"Taken at least once:([\d.]+)% of (\d+)", part)
    return (
        f"{float(lines[1]):.0f}% of {lines[2]}" if lines else "—",
        f"{float(branches[1]):.0f}% of {branches[2]}" if branches else "—",
    )


def run() -> Table:
    header = ["protocol", *(f"{e} stack (B)" for e in ENTRY_POINTS), "lines run by the vectors", "branches taken"]
    notes = [
        "Stack: worst case of each public entry point on Cortex-M0+ (`-Os`), its own frame and its deepest callee's "
        "along the call graph gcc writes (`-fcallgraph-info=su`); a call through a pointer counts as the file's "
        "deepest static function, so each figure is a bound; to_json is the optional formatter (<p>_json.c).",
        "Coverage: gcc `--coverage` of `<p>/test/check_vectors.c` (the spec's golden vectors through decode and "
        "encode), run once, gcov's figures for `<p>.c`: the parser and the error paths are left to the test suite's "
        "differential and fuzz runs (tests/test_c_backend.py), which these figures do not count.",
        "Reproduce: `.venv/bin/python -m bench.run c-stack`.",
    ]
    if shutil.which("arm-none-eabi-gcc") is None or shutil.which("gcov") is None:
        notes.insert(0, "arm-none-eabi-gcc or gcov is not installed here: no figures.")
        return Table("C target: stack and vector coverage", header, [], notes)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in PROTOCOLS:
            folder = Path(tmp) / name
            folder.mkdir()
            stack = _stack(folder, name)
            shown = [
                ("no bound: recursive" if stack[e] < 0 else str(stack[e])) if e in stack else "—" for e in ENTRY_POINTS
            ]
            rows.append([name, *shown, *_coverage(folder, name)])
    return Table("C target: stack and vector coverage", header, rows, notes)
