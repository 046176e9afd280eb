"""A frame checksum in the generated codec: its module-level function's name and the code that computes it, as its
algorithm (serialspec/checksums/) writes it. Shared by the content encoders, the frame engine's definitions
(frames/engine.py) and the straight-line frame code (frames/)."""

from __future__ import annotations

from serialspec.checksums.base import Import
from serialspec.lang.model import Checksum

Lines = list[str]


def checksum_name(checksum: Checksum) -> str:
    """The codec's module-level name of a checksum's function (backends/python/frames/engine.py defines them)."""
    return f"_CHECK_{(checksum.function or checksum.name).upper()}"


def checksum_call(checksum: Checksum) -> str:
    """The expression of a checksum over `{}` (a str.format template), as its algorithm writes it: in line, a C
    function called directly, or the module's checksum function (frames.checksum_definitions defines it)."""
    return checksum.algorithm.python_call(checksum_name(checksum))


def checksum_expression(checksum: Checksum, covered: str) -> str | None:
    """The one expression of a frame's checksum over the bytes `covered` (an expression) that checksum_lines
    assigns, where it is one; None where it takes statements."""
    return checksum.algorithm.python_expression(checksum_name(checksum), covered)


def checksum_lines(checksum: Checksum, covered: str, target: str) -> Lines:
    """Lines that compute a frame's checksum over the bytes `covered` (an expression) into `target`, as its
    algorithm writes them (serialspec/checksums/; checksum_setup gives what they rely on)."""
    return checksum.algorithm.python_lines(checksum_name(checksum), covered, target)


def checksum_setup(checksum: Checksum) -> tuple[list[Import], list[str]]:
    """The runtime imports and module-level definitions that `checksum_lines` relies on."""
    return checksum.algorithm.python_setup(checksum_name(checksum))
