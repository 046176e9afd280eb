"""`refusing://PATH`: a POSIX serial port whose driver refuses even parity with EINVAL, like a real one would."""

from __future__ import annotations

import errno
import termios

import serial
from serial import serialposix


class Serial(serialposix.Serial):
    def open(self) -> None:
        self.portstr = str(self.portstr).removeprefix("refusing://")
        super().open()

    def _reconfigure_port(self, force_update: bool = False) -> None:
        if self._parity == serial.PARITY_EVEN:
            raise termios.error(errno.EINVAL, "Invalid argument")
        super()._reconfigure_port(force_update)
