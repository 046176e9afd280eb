"""What the verbs that listen to a port share (monitor, watch): opening it with the spec's settings, and stopping
cleanly on Ctrl-C or SIGTERM."""

from __future__ import annotations

import signal
from types import FrameType
from typing import Any

import serial


def open_port(url: str, baudrate: int | None, settings: Any, timeout: float) -> serial.Serial:
    """A device path or pyserial URL opened with the spec's serial settings (`baudrate` over the spec's); a failure
    is a PortError with the reason in words, naming the setting the port refused if it was one."""
    from serialspec.runtime.transport import _open_port

    options = {
        "baudrate": baudrate or settings.baudrate,
        "bytesize": settings.bytesize,
        "parity": {"none": "N", "even": "E", "odd": "O"}.get(settings.parity, "N"),
        "stopbits": settings.stopbits,
        "timeout": timeout,
    }
    return _open_port(url, options)  # type: ignore[no-any-return]


class Stopping:
    """True once Ctrl-C (SIGINT) or SIGTERM came: the listening loop ends and the verb finishes normally."""

    def __init__(self) -> None:
        self.requested = False
        signal.signal(signal.SIGINT, self._stop)
        signal.signal(signal.SIGTERM, self._stop)

    def _stop(self, signum: int, frame: FrameType | None) -> None:
        self.requested = True

    def __bool__(self) -> bool:
        return self.requested
