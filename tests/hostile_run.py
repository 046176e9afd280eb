"""Run one hostile case: its error lines, or the files its valid spec generates (shared by the tests and by hand)."""

from __future__ import annotations

import copy
from functools import cache
from pathlib import Path

from hostile_cases import CASES, Mutation, Text
from serialspec.backends import emitters
from serialspec.lang import SpecErrors
from serialspec.lang.loader import Located, decode_text, load_file, load_text
from serialspec.lang.resolve import resolve

HERE = Path(__file__).resolve().parent
BASES = {
    "tiny": HERE / "hostile" / "tiny.yaml",
    "feetech": HERE.parent / "specs" / "feetech_sms.yaml",
    "rrc": HERE.parent / "specs" / "hiwonder_rrc.yaml",
    "fashionstar": HERE.parent / "specs" / "fashionstar_uart.yaml",
    "dynamixel": HERE.parent / "specs" / "dynamixel_p2.yaml",
}


@cache
def base(name: str) -> Located:
    return load_file(str(BASES[name]), f"{name}.yaml")


def outcome(base_name: str, mutation: Mutation | Text) -> tuple[list[str], dict[str, str]]:
    """The spec's error lines (empty when valid) and, when valid, the files every target generates from it."""
    located = base(base_name)
    try:
        if isinstance(mutation, Text):
            raw = mutation.make(BASES[base_name].read_text(encoding="utf-8"))
            located = load_text(decode_text(raw, f"{base_name}.yaml"), f"{base_name}.yaml")
        else:
            data = copy.deepcopy(located.data)
            mutation(data)
            located = Located(located.file, data, located.marks, located.key_marks)
    except SpecErrors as exc:
        return str(exc).splitlines(), {}
    return generated(located)


def generated(located: Located) -> tuple[list[str], dict[str, str]]:
    """A loaded spec's error lines (empty when valid) and, when valid, the files every target generates from it."""
    try:
        protocol = resolve(located)
        files: dict[str, str] = {}
        problems = []
        for emitter in emitters():
            emitted = emitter.files(protocol)
            files.update(emitted)
            if emitter.verify is not None:
                problems.extend(emitter.verify(protocol, emitted))
        if problems:
            raise SpecErrors(problems)
    except SpecErrors as exc:
        return str(exc).splitlines(), {}
    return [], files


if __name__ == "__main__":
    for case_id, base_name, mutation, _expected in CASES:
        lines, files = outcome(base_name, mutation)
        print(f"{case_id!r}: {lines if lines else 'OK'}")
