"""Family 4: how long generation takes, stage by stage, for the real specs and synthetic ones of 100..5,000 commands.

Stages are the ones `serialspec generate` runs for each spec (serialspec.cli.project.expected_files): load (YAML with
positions), resolve (grammar check, resolution into the immutable model), emit the package (messages, codec,
structs, client, simulator), emit the docs; then write the files, here into a temporary directory. Also: the wall
time of the whole `serialspec generate` command in a fresh process on a temporary copy of the project's specs, and
the import time of each generated package.
"""

from __future__ import annotations

import cProfile
import pstats
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import yaml
from serialspec.emit.markdown.docs import emit_docs
from serialspec.emit.python.package import emit_package
from serialspec.spec.loader import load_file
from serialspec.spec.model import Protocol
from serialspec.spec.resolve import resolve

from bench.synthetic import synthetic_yaml
from bench.timing import Table

ROOT = Path(__file__).resolve().parent.parent
REAL_SPECS = ("fashionstar_uart", "hiwonder_rrc", "feetech_sms")
SYNTHETIC_SIZES = {100: 3, 1000: 1, 5000: 1}  # commands -> runs (the median run); 5,000 alone takes ~1 min
COMPOSE_SIZE = 1000  # the synthetic spec whose YAML composition is timed with both PyYAML loaders
REAL_RUNS = 3
IMPORT_RUNS = 5
STAGES = ("load", "resolve", "emit package", "emit docs", "write")
LINEAR_LIMIT = 1.3  # per-command time may grow this much from 1,000 to 5,000 commands and still count as linear


def generate_once(spec: Path, output: Path) -> tuple[dict[str, float], Protocol]:
    """Seconds per stage for one spec, generated into `output`; and its model."""
    seconds: dict[str, float] = {}

    def timed(stage: str, step: Callable[[], Any]) -> Any:
        started = time.perf_counter()
        result = step()
        seconds[stage] = time.perf_counter() - started
        return result

    located = timed("load", lambda: load_file(str(spec), spec.name))
    protocol = timed("resolve", lambda: resolve(located))
    package = timed("emit package", lambda: emit_package(protocol))
    docs = timed("emit docs", lambda: emit_docs(protocol))

    def write() -> None:
        folder = output / protocol.name
        folder.mkdir(parents=True, exist_ok=True)
        for name, text in package.items():
            (folder / name).write_text(text, encoding="utf-8")
        (output / f"{protocol.name}.md").write_text(docs, encoding="utf-8")

    timed("write", write)
    return seconds, protocol


def command_count(protocol: Protocol) -> int:
    """Commands, counting each sub-command as one."""
    return sum(max(1, len(c.subcommands)) for c in protocol.commands)


def hot_spots(protocol: Protocol, count: int = 3) -> str:
    """The functions that take the most time of their own while emitting, by cProfile."""
    profile = cProfile.Profile()
    profile.runcall(lambda: (emit_package(protocol), emit_docs(protocol)))
    stats = pstats.Stats(profile)
    total = stats.total_tt  # type: ignore[attr-defined]
    ranked = sorted(stats.stats.items(), key=lambda item: item[1][2], reverse=True)  # type: ignore[attr-defined]
    spots = []
    for (file, line, function), (_, calls, own, _, _) in ranked[:count]:
        where = Path(file).relative_to(ROOT) if Path(file).is_relative_to(ROOT) else Path(file).name
        spots.append(f"`{where}:{line}` {function} ({calls:,} calls, {own / total:.0%} of the time)")
    return "; ".join(spots)


def median_run(spec: Path, output: Path, runs: int) -> tuple[dict[str, float], Protocol]:
    results = [generate_once(spec, output) for _ in range(runs)]
    results.sort(key=lambda result: sum(result[0].values()))
    return results[len(results) // 2]


def cli_generate_seconds(workdir: Path) -> float:
    """Wall time of `serialspec generate --root` over a copy of specs/ (fresh process: startup and imports too)."""
    root = workdir / "project"
    shutil.copytree(ROOT / "specs", root / "specs")
    command = [str(Path(sys.executable).parent / "serialspec"), "generate", "--root", str(root)]
    started = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    return time.perf_counter() - started


def import_times(package: str) -> tuple[float, float]:
    """Median over fresh processes: wall seconds of `import <package>.client` beyond a bare interpreter start,
    and the cumulative microseconds `-X importtime` reports for that module."""
    walls, cumulative = [], []
    for _ in range(IMPORT_RUNS):
        started = time.perf_counter()
        subprocess.run([sys.executable, "-c", "pass"], check=True)
        bare = time.perf_counter() - started
        started = time.perf_counter()
        done = subprocess.run(
            [sys.executable, "-X", "importtime", "-c", f"import {package}.client"],
            check=True,
            capture_output=True,
            text=True,
        )
        walls.append(time.perf_counter() - started - bare)
        line = next(x for x in done.stderr.splitlines() if x.rstrip().endswith(f"| {package}.client"))
        cumulative.append(float(re.split(r"\s*\|\s*", line)[1]))
    return statistics.median(walls), statistics.median(cumulative)


def yaml_compose_seconds(spec: Path, loader: type[Any]) -> float:
    text = spec.read_text(encoding="utf-8")
    started = time.perf_counter()
    yaml.compose(text, Loader=loader)
    return time.perf_counter() - started


def run() -> Table:
    rows = []
    per_command: dict[int, float] = {}
    with tempfile.TemporaryDirectory(prefix="serialspec-bench-") as temporary:
        workdir = Path(temporary)
        output = workdir / "generated"
        generate_once(ROOT / "specs" / "fashionstar_uart.yaml", workdir / "warmup")  # jinja compiles its templates
        specs = [(ROOT / "specs" / f"{name}.yaml", REAL_RUNS) for name in REAL_SPECS]
        for size, runs in SYNTHETIC_SIZES.items():
            path = workdir / f"synthetic_{size}.yaml"
            path.write_text(synthetic_yaml(size), encoding="utf-8")
            specs.append((path, runs))
        profiled: Protocol | None = None
        for spec, runs in specs:
            seconds, protocol = median_run(spec, output, runs)
            commands = command_count(protocol)
            total = sum(seconds.values())
            if spec.stem.startswith("synthetic_"):
                per_command[commands] = total / commands
            if spec.stem == f"synthetic_{COMPOSE_SIZE}":
                profiled = protocol
            rows.append(
                [
                    spec.stem,
                    str(commands),
                    str(runs),
                    *(f"{seconds[stage]:.3f}" for stage in STAGES),
                    f"{total:.3f}",
                    f"{total / commands * 1000:.2f}",
                ]
            )
        composed = workdir / f"synthetic_{COMPOSE_SIZE}.yaml"
        pure = yaml_compose_seconds(composed, yaml.SafeLoader)
        compiled = yaml_compose_seconds(composed, getattr(yaml, "CSafeLoader", yaml.SafeLoader))
        cli = cli_generate_seconds(workdir)
    sizes = sorted(per_command)
    growth = per_command[sizes[-1]] / per_command[sizes[1]]
    linear = growth < LINEAR_LIMIT
    assert profiled is not None
    cause = ""
    if not linear:
        cause = f" Emitting the {COMPOSE_SIZE:,}-command spec, cProfile's top own time: {hot_spots(profiled)}."
    imports = {name: import_times(name) for name in REAL_SPECS}
    import_text = "; ".join(
        f"`{name}.client` {wall * 1000:.0f} ms ({cumulative / 1000:.0f} ms by -X importtime)"
        for name, (wall, cumulative) in imports.items()
    )
    return Table(
        title="Generation: seconds per stage (median run), for the real specs and synthetic specs",
        header=["spec", "commands", "runs", *(f"{stage} s" for stage in STAGES), "total s", "ms per command"],
        rows=rows,
        notes=[
            "commands counts sub-commands (each a request and a response). Synthetic specs: bench/synthetic.py, "
            "Fashion Star framing, 50 sub-commands per command code, 1..5 fields each.",
            f"Per-command time at {sizes[-1]:,} commands ÷ at {sizes[1]:,}: {growth:.2f}× "
            f"({'linear' if linear else 'super-linear'}: 1.0× is linear; above {LINEAR_LIMIT}× is super-linear)."
            + cause,
            f"YAML composition of the {COMPOSE_SIZE:,}-command spec: {pure:.2f} s with PyYAML's pure-Python "
            f"SafeLoader (what the loader uses), {compiled:.2f} s with libyaml's CSafeLoader.",
            f"`serialspec generate` on a copy of the 3 specs, fresh process (startup, imports, schema, writes): "
            f"{cli:.2f} s.",
            f"Import in a fresh process, beyond bare interpreter start (median of {IMPORT_RUNS}): {import_text}.",
        ],
    )
