"""Family 4: how long generation takes, stage by stage, for the real specs and synthetic ones of 100..5,000 commands.

Stages are the ones `serialspec generate` runs for each spec whose outputs it has not cached
(serialspec.cli.project._generate): load (YAML with positions), resolve (grammar check, resolution into the immutable
model), emit the package (messages, codec, structs, client, simulator), emit the docs; then write the files, here
into a temporary directory. Also: the time of the whole `serialspec generate` command in a fresh process on a
temporary copy of the project's specs (specs unchanged, every spec edited, caches off), and the import time of each
generated client. Times are CPU time (process or child-process user + system): the work is single-threaded, and on a
shared machine the time spent waiting for a core is not the generator's.
"""

from __future__ import annotations

import cProfile
import os
import pstats
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from serialspec.backends.markdown.docs import emit_docs
from serialspec.backends.python.package import emit_package
from serialspec.lang.loader import load_text
from serialspec.lang.model import Protocol
from serialspec.lang.resolve import resolve

from bench.synthetic import synthetic_yaml
from bench.timing import Table, verdict

ROOT = Path(__file__).resolve().parent.parent
REAL_SPECS = ("fashionstar_uart", "hiwonder_rrc", "feetech_sms")
SYNTHETIC_SIZES = {100: 3, 1000: 1, 5000: 1}  # commands -> runs (the median run); 5,000 alone takes ~1 min
COMPOSE_SIZE = 1000  # the synthetic spec whose YAML composition is timed with both PyYAML loaders
REAL_RUNS = 3
IMPORT_RUNS = 7
CLI_RUNS = 5
GENERATE_TARGET = 0.2  # seconds: `serialspec generate` of the shipped specs, and their stages summed
IMPORT_TARGET = 0.030  # seconds: import of a generated client
STAGES = ("load", "resolve", "emit package", "emit docs", "write")
LINEAR_LIMIT = 1.3  # per-command time may grow this much from 1,000 to 5,000 commands and still count as linear


def generate_once(spec: Path, output: Path) -> tuple[dict[str, float], Protocol]:
    """Seconds per stage for one spec, generated into `output`; and its model."""
    seconds: dict[str, float] = {}

    def timed(stage: str, step: Callable[[], Any]) -> Any:
        started = time.process_time()  # CPU time: on a shared machine, waiting for a core is not generating
        result = step()
        seconds[stage] = time.process_time() - started
        return result

    # the text read and composed beneath the file-size guard (lang/limits.py: a hostile file's limit), which the
    # 5,000-command synthetic spec is over
    located = timed("load", lambda: load_text(spec.read_text(encoding="utf-8"), spec.name))
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


def warm_environment() -> dict[str, str]:
    """The environment of a user's shell: Python writes and reads its .pyc files (and serialspec its compiled
    templates beside them), whatever PYTHONDONTWRITEBYTECODE the benchmark itself runs with."""
    return {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


@dataclass(frozen=True)
class CliTimes:
    first: float  # CPU seconds of the first run, the caches as the project left them
    warm: float  # best CPU seconds, unchanged specs, every cache warm
    warm_wall: float
    edited: float  # best CPU seconds after an edit to every spec: each generated again, compiled code from the cache
    uncached: float  # best CPU seconds with serialspec's caches off (SERIALSPEC_CACHE_DIR=""), .pyc files warm


def cli_generate_seconds(workdir: Path) -> CliTimes:
    """`serialspec generate --root` over a copy of specs/ in a fresh process (startup and imports too), CPU time: the
    first run, then the best of CLI_RUNS in each case after it (noise only adds time)."""
    root = workdir / "project"
    shutil.copytree(ROOT / "specs", root / "specs")
    command = [str(Path(sys.executable).parent / "serialspec"), "generate", "--root", str(root)]

    def timed(env: dict[str, str]) -> tuple[float, float]:
        started, cpu = time.perf_counter(), child_cpu()
        subprocess.run(command, check=True, capture_output=True, env=env)
        return child_cpu() - cpu, time.perf_counter() - started

    warm_env = warm_environment()
    first, _ = timed(warm_env)
    warm = [timed(warm_env) for _ in range(CLI_RUNS)]
    edited = []
    for run in range(CLI_RUNS + 1):  # the first edit writes the cache entries of the edited specs' compiled code
        for spec in (root / "specs").glob("*.yaml"):
            with spec.open("a", encoding="utf-8") as stream:
                stream.write(f"# edit {run}\n")  # the spec is generated again: its text is part of the cache key
        edited.append(timed(warm_env)[0])
    uncached = [timed({**warm_env, "SERIALSPEC_CACHE_DIR": ""})[0] for _ in range(CLI_RUNS)]
    return CliTimes(
        first=first,
        warm=min(cpu for cpu, _ in warm),
        warm_wall=min(wall for _, wall in warm),
        edited=min(edited[1:]),
        uncached=min(uncached),
    )


IMPORT_SCRIPT = "import time; c = time.process_time(); import {}.client; print(time.process_time() - c)"


def import_times(package: str) -> tuple[float, float]:
    """Best of IMPORT_RUNS fresh processes (after one that writes the .pyc files; noise only adds time): the CPU
    seconds `import <package>.client` takes, and the cumulative microseconds `-X importtime` reports for it."""
    cpus, cumulative = [], []
    env = warm_environment()
    subprocess.run([sys.executable, "-c", f"import {package}.client"], check=True, env=env)
    for _ in range(IMPORT_RUNS):
        done = subprocess.run(
            [sys.executable, "-X", "importtime", "-c", IMPORT_SCRIPT.format(package)],
            check=True,
            capture_output=True,
            text=True,
            env=env,
        )
        cpus.append(float(done.stdout))
        line = next(x for x in done.stderr.splitlines() if x.rstrip().endswith(f"| {package}.client"))
        cumulative.append(float(re.split(r"\s*\|\s*", line)[1]))
    return min(cpus), min(cumulative)


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
        real_totals: list[float] = []
        for spec, runs in specs:
            seconds, protocol = median_run(spec, output, runs)
            commands = command_count(protocol)
            total = sum(seconds.values())
            if spec.stem.startswith("synthetic_"):
                per_command[commands] = total / commands
            if spec.stem == f"synthetic_{COMPOSE_SIZE}":
                profiled = protocol
            if spec.stem in REAL_SPECS:
                real_totals.append(total)
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
        f"`{name}.client` {cpu * 1000:.0f} ms (≤ {IMPORT_TARGET * 1000:.0f} ms: {verdict(cpu <= IMPORT_TARGET)}; "
        f"{cumulative / 1000:.0f} ms by -X importtime)"
        for name, (cpu, cumulative) in imports.items()
    )
    shipped = sum(real_totals)
    return Table(
        title="Generation: CPU seconds per stage (median run), for the real specs and synthetic specs",
        header=["spec", "commands", "runs", *(f"{stage} s" for stage in STAGES), "total s", "ms per command"],
        rows=rows,
        notes=[
            "commands counts sub-commands (each a request and a response). Synthetic specs: bench/synthetic.py, "
            "Fashion Star framing, 50 sub-commands per command code, 1..5 fields each.",
            f"Per-command time at {sizes[-1]:,} commands ÷ at {sizes[1]:,}: {growth:.2f}× "
            f"({'linear' if linear else 'super-linear'}: 1.0× is linear; above {LINEAR_LIMIT}× is super-linear)."
            + cause,
            f"The {len(REAL_SPECS)} servo specs above, every stage: {shipped:.3f} s "
            f"(≤ {GENERATE_TARGET} s: {verdict(shipped <= GENERATE_TARGET)}).",
            f"YAML composition of the {COMPOSE_SIZE:,}-command spec: {compiled:.2f} s with libyaml's CSafeLoader "
            f"(what the loader uses where PyYAML has libyaml), {pure:.2f} s with PyYAML's pure-Python SafeLoader.",
            f"`serialspec generate` on a copy of specs/ ({len(list((ROOT / 'specs').glob('*.yaml')))} specs), fresh "
            "process (startup, imports, schema, writes), CPU time, best of "
            f"{CLI_RUNS}: unchanged specs, warm .pyc files and serialspec caches (each spec's outputs and the verdict "
            f"of its examples, keyed by its text and the generator): {cli.warm:.2f} s (≤ {GENERATE_TARGET} s: "
            f"{verdict(cli.warm <= GENERATE_TARGET)}), {cli.warm_wall:.2f} s wall; after an edit to every spec (each "
            "loaded, resolved, emitted and its examples run through its package again; compiled templates and "
            f"modules from the cache): {cli.edited:.2f} s (≤ {GENERATE_TARGET} s: "
            f'{verdict(cli.edited <= GENERATE_TARGET)}); serialspec\'s caches off (SERIALSPEC_CACHE_DIR=""): '
            f"{cli.uncached:.2f} s; the first run, with the caches as the project left them: {cli.first:.2f} s.",
            f"Import of a generated client in a fresh process, CPU time (best of {IMPORT_RUNS}): {import_text}.",
        ],
    )
