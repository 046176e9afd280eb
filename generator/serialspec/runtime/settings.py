"""A protocol's serial line settings: what a generated package declares, without importing pyserial."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class SerialSettings:
    """The spec's `serial:` section: defaults for opening a port."""

    baudrate: int
    bytesize: int = 8
    parity: str = "none"
    stopbits: float = 1
    gap: float = 0.0  # silence the protocol needs between frames, in character times (Modbus RTU: 3.5)
