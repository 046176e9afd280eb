"""Family 5: how long the `serialspec` command takes to start, side by side with a bare `python -c pass`.

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
import time
from pathlib import Path

from bench.timing import Table, times, verdict

ROOT = Path(__file__).resolve().parent.parent
RUNS = 25
TARGET = 3.0  # each command at most this many times a bare `python -c pass`
SERIALSPEC = str(Path(sys.executable).parent / "serialspec")
PING = "ff ff 01 02 01 fb"
COMMANDS: dict[str, list[str]] = {
    "python -c pass": [sys.executable, "-c", "pass"],
    "serialspec --help": [SERIALSPEC, "--help"],
    "serialspec decode feetech_sms HEX": [SERIALSPEC, "decode", "feetech_sms", PING, "--direction", "request"],
    "serialspec decode specs/feetech_sms.yaml HEX": [
        SERIALSPEC,
        "decode",
        str(ROOT / "specs" / "feetech_sms.yaml"),
        PING,
        "--direction",
        "request",
    ],
    "serialspec decode dynamixel_p2 HEX --json": [
        SERIALSPEC,
        "decode",
        "dynamixel_p2",
        "ff ff fd 00 01 07 00 55 00 06 04 26 65 5d",
        "--direction",
        "response",
        "--json",
    ],
}
#: The commands the target is for (the issue's); the others are shown for comparison.
TARGETED = ("serialspec --help", "serialspec decode feetech_sms HEX")


def environment() -> dict[str, str]:
    """A user's shell: Python reads and writes its .pyc files, serialspec its caches."""
    return {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed(command: list[str], env: dict[str, str]) -> tuple[float, float]:
    """Wall and CPU seconds of one fresh process."""
    cpu, started = child_cpu(), time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=ROOT)
    return time.perf_counter() - started, child_cpu() - cpu


def measure(runs: int = RUNS) -> dict[str, tuple[float, float]]:
    """Best wall and best CPU seconds of each command, run round-robin."""
    env = environment()
    for command in COMMANDS.values():  # writes the .pyc files and serialspec's caches
        subprocess.run(command, check=True, capture_output=True, env=env, cwd=ROOT)
    samples: dict[str, list[tuple[float, float]]] = {name: [] for name in COMMANDS}
    for _ in range(runs):
        for name, command in COMMANDS.items():
            samples[name].append(timed(command, env))
    return {name: (min(w for w, _ in values), min(c for _, c in values)) for name, values in samples.items()}


def run() -> Table:
    best = measure()
    bare_wall, bare_cpu = best["python -c pass"]
    rows = []
    for name, (wall, cpu) in best.items():
        wall_ratio, cpu_ratio = wall / bare_wall, cpu / bare_cpu
        target = f"≤ {TARGET:g}×" if name in TARGETED else "—"
        met = verdict(cpu_ratio <= TARGET) if name in TARGETED else ""
        rows.append(
            [f"`{name}`", f"{wall * 1000:.1f}", times(wall_ratio), f"{cpu * 1000:.1f}", times(cpu_ratio), target, met]
        )
    return Table(
        "Start-up: the command in a fresh process against a bare `python -c pass`",
        ["command", "wall ms (best)", "× bare", "CPU ms (best)", "× bare", "target", "verdict"],
        rows,
        [
            f"Best of {RUNS} fresh processes each, run round-robin after one warm-up run of each (.pyc files and "
            "serialspec's caches written), without PYTHONDONTWRITEBYTECODE as in a user's shell. The verdict is on "
            "CPU time (user + system): on a shared machine the time a process waits for a core is not its own; wall "
            "time is beside it.",
            "`decode PACKAGE` reads the spec the package ships and takes its resolved model from serialspec's cache "
            "(keyed by the spec's text and the language's modules), so it imports neither PyYAML nor the resolver; "
            "the generated package's `__init__` no longer imports the transport (pyserial).",
        ],
    )
