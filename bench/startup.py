"""Family 5: how long the `serialspec` command takes to start, side by side with a bare `python -c pass`.

Measured as a user sees it: the wheel built from this tree, installed with pip into a fresh virtual environment in
a temporary folder (outside the repository, so nothing of it is importable; not the development environment, whose
editable install's import hook inflates even the bare start), the commands run from a folder of their own. pip gets
the dependencies as it is configured (the wheel's folder as --find-links; pip's cache or the package registry for
the rest).

Each command runs in a fresh process, as a user's shell runs it (.pyc files and serialspec's caches warm: one run of
each first, outside the timing), round-robin with the others for RUNS rounds so that noise from other processes falls
on all of them alike. Reported: the best wall time and the best CPU time (user + system of the child) of each, and
their ratios to `python -c pass` run by the same interpreter (the same site-packages, so the same start-up work).
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench.timing import Table, times, verdict

ROOT = Path(__file__).resolve().parent.parent
RUNS = 25
#: Each command's target: at most this many times a bare `python -c pass` (the issue's), and where asked for, a
#: stretch beside it (--help within 2×: below what importing argparse alone costs, about 1.9×).
TARGETS = {"serialspec --help": 3.0, "serialspec decode feetech_sms HEX": 3.0}
STRETCH = {"serialspec --help": 2.0}
PING = "ff ff 01 02 01 fb"


def commands(bin: Path) -> dict[str, list[str]]:
    """The commands timed, run by the environment whose scripts are in `bin`."""
    serialspec = str(bin / "serialspec")
    return {
        "python -c pass": [str(bin / "python"), "-c", "pass"],
        "serialspec --help": [serialspec, "--help"],
        "serialspec decode feetech_sms HEX": [serialspec, "decode", "feetech_sms", PING, "--direction", "request"],
        "serialspec decode specs/feetech_sms.yaml HEX": [
            serialspec,
            "decode",
            str(ROOT / "specs" / "feetech_sms.yaml"),
            PING,
            "--direction",
            "request",
        ],
        "serialspec decode dynamixel_p2 HEX --json": [
            serialspec,
            "decode",
            "dynamixel_p2",
            "ff ff fd 00 01 07 00 55 00 06 04 26 65 5d",
            "--direction",
            "response",
            "--json",
        ],
    }


def wheel_environment(where: Path) -> Path:
    """The wheel of this tree installed with pip into a fresh environment in `where`; returns its scripts' folder."""
    dist = where / "dist"
    build = [sys.executable, "-m", "pip", "wheel", "--no-build-isolation", "--no-deps", "-q", "-w", str(dist)]
    subprocess.run([*build, str(ROOT)], check=True, capture_output=True)
    wheel = next(dist.glob("serialspec-*.whl"))
    subprocess.run([sys._base_executable, "-m", "venv", str(where / "venv")], check=True)  # type: ignore[attr-defined]
    bin = where / "venv" / "bin"
    install = [str(bin / "python"), "-m", "pip", "install", "-q", "--disable-pip-version-check"]
    result = subprocess.run([*install, "--find-links", str(dist), str(wheel)], capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"bench startup: pip could not install {wheel.name} and its dependencies:\n{result.stderr}")
    return bin


def environment() -> dict[str, str]:
    """A user's shell: Python reads and writes its .pyc files, serialspec its caches."""
    return {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed(command: list[str], env: dict[str, str], home: Path) -> tuple[float, float]:
    """Wall and CPU seconds of one fresh process."""
    cpu, started = child_cpu(), time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=home)
    return time.perf_counter() - started, child_cpu() - cpu


def measure(bin: Path, home: Path, runs: int = RUNS) -> dict[str, tuple[float, float]]:
    """Best wall and best CPU seconds of each command, run round-robin from the folder `home`."""
    env = environment()
    env.pop("VIRTUAL_ENV", None)
    env.pop("PYTHONPATH", None)
    timed_commands = commands(bin)
    for command in timed_commands.values():  # writes the .pyc files and serialspec's caches
        subprocess.run(command, check=True, capture_output=True, env=env, cwd=home)
    samples: dict[str, list[tuple[float, float]]] = {name: [] for name in timed_commands}
    for _ in range(runs):
        for name, command in timed_commands.items():
            samples[name].append(timed(command, env, home))
    return {name: (min(w for w, _ in values), min(c for _, c in values)) for name, values in samples.items()}


def run() -> Table:
    with tempfile.TemporaryDirectory(prefix="serialspec-startup-") as folder:
        home = Path(folder, "home")
        home.mkdir()
        best = measure(wheel_environment(Path(folder)), home)
    bare_wall, bare_cpu = best["python -c pass"]
    rows = []
    for name, (wall, cpu) in best.items():
        wall_ratio, cpu_ratio = wall / bare_wall, cpu / bare_cpu
        target = f"≤ {TARGETS[name]:g}×" if name in TARGETS else "—"
        met = verdict(cpu_ratio <= TARGETS[name]) if name in TARGETS else ""
        if name in STRETCH:
            target += f" (stretch ≤ {STRETCH[name]:g}×)"
            met += f" (stretch {verdict(cpu_ratio <= STRETCH[name])})"
        rows.append(
            [f"`{name}`", f"{wall * 1000:.1f}", times(wall_ratio), f"{cpu * 1000:.1f}", times(cpu_ratio), target, met]
        )
    return Table(
        "Start-up: the command in a fresh process against a bare `python -c pass`",
        ["command", "wall ms (best)", "× bare", "CPU ms (best)", "× bare", "target", "verdict"],
        rows,
        [
            "The wheel built from this tree, pip-installed into a fresh virtual environment in a temporary folder "
            "(not the development one, whose editable install slows even the bare start), run from a folder of its "
            "own; the ratios are to that environment's `python -c pass`.",
            f"Best of {RUNS} fresh processes each, run round-robin after one warm-up run of each (.pyc files and "
            "serialspec's caches written), without PYTHONDONTWRITEBYTECODE as in a user's shell. The verdict is on "
            "CPU time (user + system): on a shared machine the time a process waits for a core is not its own; wall "
            "time is beside it.",
            "`decode PACKAGE` decodes with the generated package alone (which names the directions whose frames carry "
            "a checksum and its register views): it imports neither the spec's model nor the language, pickle or "
            "dataclasses; message classes, serial settings and the stream parser's frame formats are plain classes. "
            "A spec file (or --units, --request, --file) takes the resolved model from serialspec's cache. The "
            "parser is built for the chosen verb alone, argparse's texts looked up in gettext once each.",
            "What is left is Python's own: `import argparse` (with re, enum, gettext) costs about 1.9× a bare start "
            "by itself, so --help within 2× would need a command line without argparse.",
        ],
    )
