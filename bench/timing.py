"""Timing and reporting shared by every benchmark family.

CPU-bound operations are timed side by side: the competitors of one comparison run round-robin, round after round,
so that noise from other processes on a shared machine falls on all of them alike. Each round times a tight loop of
`number` calls `function(*arguments)` (number calibrated like timeit's autorange); the figure reported is the best
round (noise only ever adds time), and the median round is kept beside it to show the spread.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

ROUND_SECONDS = 0.02  # each timed round lasts at least this long
ROUNDS = 7

Operation = tuple[Callable[..., Any], tuple[Any, ...]]  # a function and the arguments it is called with


@dataclass(frozen=True)
class Timing:
    best_ns: float  # per operation, best round
    median_ns: float  # per operation, median round


def _loop(operation: Operation, number: int) -> int:
    """Nanoseconds for `number` calls of the operation."""
    function, arguments = operation
    perf = time.perf_counter_ns
    started = perf()
    for _ in range(number):
        function(*arguments)
    return perf() - started


def calibrate(operation: Operation, seconds: float = ROUND_SECONDS) -> int:
    """The number of calls that takes at least `seconds` (1, 2, 5, 10, 20, 50, ... like timeit's autorange)."""
    scale = 1
    while True:
        for factor in (1, 2, 5):
            number = scale * factor
            if _loop(operation, number) >= seconds * 1e9:
                return number
        scale *= 10


def compare(operations: dict[str, Operation], rounds: int = ROUNDS) -> dict[str, Timing]:
    """Time every operation round-robin; nanoseconds per call, best and median of `rounds` rounds each."""
    numbers = {name: calibrate(operation) for name, operation in operations.items()}
    samples: dict[str, list[float]] = {name: [] for name in operations}
    for _ in range(rounds):
        for name, operation in operations.items():
            samples[name].append(_loop(operation, numbers[name]) / numbers[name])
    return {name: Timing(min(values), statistics.median(values)) for name, values in samples.items()}


def percentile(values: Sequence[float], fraction: float) -> float:
    """The value below which `fraction` of the values lie (nearest rank)."""
    ordered = sorted(values)
    rank = max(0, min(len(ordered) - 1, round(fraction * len(ordered) + 0.5) - 1))
    return ordered[rank]


def verdict(ok: bool) -> str:
    return "PASS" if ok else "MISS"


@dataclass
class Table:
    """One markdown table: a family's results, with notes that say exactly what was timed."""

    title: str
    header: list[str]
    rows: list[list[str]]
    notes: list[str]

    def markdown(self) -> str:
        lines = [f"### {self.title}", ""]
        lines.append("| " + " | ".join(self.header) + " |")
        lines.append("|" + "|".join(" --- " for _ in self.header) + "|")
        lines.extend("| " + " | ".join(row) + " |" for row in self.rows)
        if self.notes:
            lines.append("")
            lines.extend(f"- {note}" for note in self.notes)
        return "\n".join(lines) + "\n"


def us(nanoseconds: float) -> str:
    """Microseconds, to about three significant figures."""
    value = nanoseconds / 1000
    if value >= 100:
        return f"{value:.0f}"
    if value >= 10:
        return f"{value:.1f}"
    return f"{value:.2f}"


def times(value: float) -> str:
    """A ratio, as 1.23× or 45×."""
    return f"{value:.2f}×" if value < 10 else f"{value:.0f}×"
