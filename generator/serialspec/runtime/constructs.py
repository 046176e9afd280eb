"""construct pieces the generated structs need beyond construct's own."""

from __future__ import annotations

from typing import Any

from construct import Adapter, Container, GreedyBytes


class SignMagnitude(Adapter):  # type: ignore[misc]
    """An unsigned integer whose top bit is the sign and the rest the magnitude (FEETECH position/speed)."""

    def __init__(self, subcon: Any, bits: int) -> None:
        super().__init__(subcon)
        self.sign = 1 << (bits - 1)

    def _decode(self, obj: int, context: Any, path: Any) -> int:
        return -(obj & (self.sign - 1)) if obj & self.sign else obj

    def _encode(self, obj: int, context: Any, path: Any) -> int:
        return (-obj) | self.sign if obj < 0 else obj


class Framed(Adapter):  # type: ignore[misc]
    """A whole frame of any layout (stuffing, lengths and checksums anywhere), by the runtime's frame engine.

    Parses to a Container of `layout` (its name), `code`, `values` (the address/status elements) and `content`; builds
    from the same keys. Construct has no byte stuffing, so frames that are not of the classic shape use this.
    """

    def __init__(self, codec: Any) -> None:
        super().__init__(GreedyBytes)
        self.codec = codec

    def _decode(self, obj: bytes, context: Any, path: Any) -> Container:
        unwrapped = self.codec.unwrap(bytes(obj))
        return Container(
            layout=unwrapped.layout.name, code=unwrapped.code, values=list(unwrapped.values), content=unwrapped.content
        )

    def _encode(self, obj: Any, context: Any, path: Any) -> bytes:
        return bytes(self.codec.wrap(bytes(obj["content"]), obj["code"], tuple(obj["values"])))
