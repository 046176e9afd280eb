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
#: Each command's target: at most this many times a bare `python -c pass` (the issue's: --help, and `decode PACKAGE
#: HEX` of every shipped package, see `shipped_frames`), and where asked for, a stretch beside it (--help within 2×:
#: about what importing argparse alone costs).
TARGET = 3.0
STRETCH = {"serialspec --help": 2.0}
PING = "ff ff 01 02 01 fb"


def shipped_frames() -> dict[str, tuple[str, str]]:
    """Each shipped protocol (specs/*.yaml) -> a frame of its spec's first example as `decode` takes it (hex, or a
    text protocol's sentence as typed) and its direction: one row per package, every framing family."""
    from serialspec.lang import load_protocol

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


def decode_row(name: str) -> str:
    return f"serialspec decode {name} HEX"


def commands(bin: Path) -> dict[str, list[str]]:
    """The commands timed, run by the environment whose scripts are in `bin`."""
    serialspec = str(bin / "serialspec")
    return {
        "python -c pass": [str(bin / "python"), "-c", "pass"],
        "serialspec --help": [serialspec, "--help"],
        **{
            decode_row(name): [serialspec, "decode", name, frame, "--direction", direction]
            for name, (frame, direction) in shipped_frames().items()
        },
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
    decoded = {decode_row(name) for name in shipped_frames()}
    rows = []
    for name, (wall, cpu) in best.items():
        wall_ratio, cpu_ratio = wall / bare_wall, cpu / bare_cpu
        targeted = name == "serialspec --help" or name in decoded
        target = f"≤ {TARGET:g}×" if targeted else "—"
        met = verdict(cpu_ratio <= TARGET) if targeted else ""
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
            "`decode PACKAGE` decodes with the generated package alone (a binary package names the directions whose "
            "frames carry a checksum and its register views; a text package needs only its framing and codec), one "
            "row per shipped package, each with its spec's first example: it imports neither the spec's model nor "
            "the language, pickle, dataclasses, inspect, typing or pkgutil (tests/test_cache.py). Message classes, "
            "serial settings and stream frame formats are plain classes; the frame engine's layouts, checksum "
            "algorithms, frame transforms and text messages are frozen value classes (serialspec.runtime.values) "
            "whose __init__ is not compiled per class; a 16-bit CRC goes byte by byte before it builds its "
            "65,536-entry word table (after 64 KiB), any other CRC goes bit by bit before it builds its 256-entry "
            "table (after 256 bytes); a codec imports its frame transform from the transform's module alone; "
            "generated enum and flag classes are built by enum._simple_enum (the same classes, about half the time), "
            "binascii is loaded only by a CRC that uses crc_hqx, and modules are imported without the importlib "
            "package. "
            "`decode NAME HEX... [--direction D] [--json]` is read without argparse and writes list and bit-field "
            "values without json; hex and text fields are checked without regular expressions. A spec file (or "
            "--units, --request, --file) takes the resolved model from serialspec's cache. Other command lines go "
            "through argparse, its parser built for the chosen verb alone (`--help` builds none of the verbs' "
            "parsers), its texts looked up in gettext's catalogue once.",
            "What is left is mostly Python's own: pip's `serialspec` script imports re (with enum, functools and "
            "collections) before serialspec, and `import argparse` (with gettext) costs about 1.8× a bare start by "
            "itself with that, so --help within 2× would need a top-level command line without argparse.",
        ],
    )
