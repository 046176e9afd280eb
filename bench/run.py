"""Run every benchmark family, print one markdown table per family, and write them all to bench/results.md.

Usage: `make bench`, or `.venv/bin/python -m bench.run [family ...]` from the project root (families: codec,
stream, latency, generation, startup, c-size, c-groups, c-speed, c-stack; default all). A full run rewrites
bench/results.md; a run of some families (`make bench-c`: the C target's) replaces their tables in it, each noting
when and where it ran.
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import sys
import time
from collections.abc import Callable
from pathlib import Path

from bench import c_stack, c_target, codec, generation, latency, startup, stream
from bench.timing import Table

RESULTS = Path(__file__).resolve().parent / "results.md"
FAMILIES: dict[str, Callable[[], Table]] = {
    "codec": codec.run,
    "stream": stream.run,
    "latency": latency.run,
    "generation": generation.run,
    "startup": startup.run,
    "c-size": c_target.sizes,
    "c-groups": c_target.groups,
    "c-speed": c_target.throughput,
    "c-stack": c_stack.run,
}


def cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as cpuinfo:
            for line in cpuinfo:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine() -> str:
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return (
        f"{cpu_model()}, {os.cpu_count()} cores, Python {platform.python_version()} "
        f"({platform.python_implementation()}), {platform.system()} {platform.release()}; load average at start {load}"
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("families", nargs="*", choices=[*FAMILIES, []], help="families to run (default: all)")
    args = parser.parse_args(argv)
    chosen = args.families or list(FAMILIES)
    header = [
        "# serialspec benchmarks",
        "",
        f"- Machine: {machine()}",
        f"- Date: {datetime.datetime.now().astimezone().isoformat(timespec='seconds')}",
        "- Reproduce: `make bench` (or `.venv/bin/python -m bench.run`) from the project root",
        "- Figures are side by side in one run; ratios compare them. See bench/README.md for what each family times.",
        "",
    ]
    print("\n".join(header), flush=True)
    sections = []
    started = time.perf_counter()
    for name in chosen:
        family_started = time.perf_counter()
        table = FAMILIES[name]()
        text = table.markdown()
        print(text, flush=True)
        print(f"({name}: {time.perf_counter() - family_started:.0f} s)\n", file=sys.stderr, flush=True)
        sections.append(text)
    if chosen == list(FAMILIES):
        elapsed = f"- Whole run: {time.perf_counter() - started:.0f} s"
        RESULTS.write_text("\n".join([*header[:-1], elapsed, "", *sections]), encoding="utf-8")
    elif RESULTS.is_file():
        stamp = f"- Run alone (`python -m bench.run {' '.join(chosen)}`): {header[3][2:]}; {header[2][2:]}.\n"
        text = RESULTS.read_text(encoding="utf-8")
        for section in sections:
            text = replace_section(text, section + stamp)
        RESULTS.write_text(text, encoding="utf-8")
    else:
        return 0
    print(f"written to {RESULTS.relative_to(Path.cwd()) if RESULTS.is_relative_to(Path.cwd()) else RESULTS}")
    return 0


def replace_section(text: str, section: str) -> str:
    """results.md with the table of the same title (its `### ` line) replaced by `section`, or `section` added at
    the end."""
    title = section.split("\n", 1)[0] + "\n"
    start = text.find(title)
    if start < 0:
        return text.rstrip("\n") + "\n\n" + section
    stop = text.find("\n### ", start + len(title))
    return text[:start] + section + ("" if stop < 0 else text[stop:])


if __name__ == "__main__":
    raise SystemExit(main())
