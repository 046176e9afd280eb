"""A protocol's serial line settings: what a generated package declares, without importing pyserial."""

from __future__ import annotations

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any, Self


class SerialSettings:
    """The spec's `serial:` section: defaults for opening a port. Frozen, compared and hashed by its values (a plain
    class rather than a dataclass: importing dataclasses would cost a generated package's import more than the rest)."""

    __slots__ = ("baudrate", "bytesize", "parity", "stopbits", "gap", "turnaround")
    __match_args__ = ("baudrate", "bytesize", "parity", "stopbits", "gap", "turnaround")

    baudrate: int
    bytesize: int
    parity: str
    stopbits: float
    gap: float  # silence the protocol needs between frames, in character times (Modbus RTU: 3.5)
    turnaround: float  # seconds a client waits after a request no device answers (a broadcast) before the next

    def __init__(
        self,
        baudrate: int,
        bytesize: int = 8,
        parity: str = "none",
        stopbits: float = 1,
        gap: float = 0.0,
        turnaround: float = 0.0,
    ) -> None:
        values = (baudrate, bytesize, parity, stopbits, gap, turnaround)
        for name, value in zip(self.__slots__, values, strict=True):
            object.__setattr__(self, name, value)

    def _values(self) -> tuple[Any, ...]:
        return (self.baudrate, self.bytesize, self.parity, self.stopbits, self.gap, self.turnaround)

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        assert isinstance(other, SerialSettings)
        return self._values() == other._values()

    def __hash__(self) -> int:
        return hash(self._values())

    def __repr__(self) -> str:
        values = ", ".join(f"{name}={value!r}" for name, value in zip(self.__slots__, self._values(), strict=True))
        return f"{type(self).__qualname__}({values})"

    def __setattr__(self, name: str, value: Any) -> None:
        from dataclasses import FrozenInstanceError  # what assigning to the frozen dataclass it was raised

        raise FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self, name: str) -> None:
        from dataclasses import FrozenInstanceError

        raise FrozenInstanceError(f"cannot delete field {name!r}")

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), self._values())

    def replace(self, **changes: Any) -> Self:
        """A copy with some settings changed (what dataclasses.replace gave)."""
        values = dict(zip(self.__slots__, self._values(), strict=True))
        unknown = sorted(set(changes) - set(values))
        if unknown:
            raise TypeError(f"SerialSettings has no field {', '.join(map(repr, unknown))}")
        return type(self)(**(values | changes))
