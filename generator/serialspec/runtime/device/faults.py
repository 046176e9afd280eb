"""Fault injection: spoil a simulator's next replies (drop, corrupt, late, garbage, truncate, other_id)."""

from __future__ import annotations

import random
import threading
from dataclasses import dataclass


@dataclass
class Fault:
    kind: str  # one of FAULTS
    delay: float = 0.0
    answer_as: int | None = None  # other_id: the id to answer as (None: the next id up, or down at the top)

    def other_id(self, address: int, broadcast: int | None) -> int:
        if self.answer_as is not None:
            return self.answer_as
        return address + 1 if address + 1 != broadcast and address < 0xFF else address - 1


FAULTS = {
    "drop": "no reply",
    "corrupt": "the reply with a bad checksum",
    "late": "the reply `delay` s late",
    "garbage": "random bytes before the reply",
    "truncate": "only the first half of the reply",
    "other_id": "the reply as if from another id (`answer_as`)",
}


class FaultInjection:
    """The faults queued for the next replies; the engine applies them as it sends."""

    _lock: threading.Lock

    def __init__(self) -> None:
        self.faults: list[Fault] = []

    # --- fault injection ------------------------------------------------------------------------------------------

    def inject(self, kind: str, count: int = 1, delay: float = 0.5, answer_as: int | None = None) -> None:
        """Spoil the next `count` replies, one fault each, with a fault of FAULTS; `delay` for late ones."""
        if kind not in FAULTS:
            raise ValueError(f"unknown fault {kind!r} (expected one of {', '.join(FAULTS)})")
        with self._lock:
            self.faults.extend(Fault(kind, delay, answer_as) for _ in range(count))

    def _spoil(self, when: float, frame: bytes) -> list[tuple[float, bytes]]:
        if not self.faults:
            return [(when, frame)]
        fault = self.faults.pop(0)
        if fault.kind == "drop":
            return []
        if fault.kind == "corrupt":
            return [(when, frame[:-1] + bytes([(frame[-1] + 1) & 0xFF]))]
        if fault.kind == "late":
            return [(when + fault.delay, frame)]
        if fault.kind == "truncate":
            return [(when, frame[: len(frame) // 2])]
        garbage = bytes(random.randrange(256) for _ in range(7))
        return [(when, garbage + frame)]
