"""Checksums as C: each algorithm of the registry (serialspec/checksums/) writes its own C (Algorithm.c_code, beside
its Python and docs); the C target takes it, or refuses the spec where the algorithm has none (Unsupported)."""

from __future__ import annotations

from serialspec.backends import Unsupported
from serialspec.checksums.base import CCode, NoCode
from serialspec.lang.model import Checksum


def c_checksum(prefix: str, checksum: Checksum) -> CCode:
    """The C of one checksum: its algorithm's incremental function, with the protocol's prefix."""
    try:
        return checksum.algorithm.c_code(prefix)
    except NoCode as exc:
        raise Unsupported(f"checksum {checksum.name}: {exc}") from None
