"""construct pieces the generated structs need beyond construct's own."""

from __future__ import annotations

from typing import Any

from construct import Adapter


class SignMagnitude(Adapter):  # type: ignore[misc]
    """An unsigned integer whose top bit is the sign and the rest the magnitude (FEETECH position/speed)."""

    def __init__(self, subcon: Any, bits: int) -> None:
        super().__init__(subcon)
        self.sign = 1 << (bits - 1)

    def _decode(self, obj: int, context: Any, path: Any) -> int:
        return -(obj & (self.sign - 1)) if obj & self.sign else obj

    def _encode(self, obj: int, context: Any, path: Any) -> int:
        return (-obj) | self.sign if obj < 0 else obj
