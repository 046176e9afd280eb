"""Two pseudo-terminals joined back to back, like a null-modem cable between two serial ports.

Each side opens its own device path with its own serial settings (pyserial sets them on a pseudo-terminal as on a
real port); what one side writes, the other reads. Used where both peers insist on opening a port by path.
"""

from __future__ import annotations

import os
import select
import threading
import tty
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def pty_pair() -> Iterator[tuple[str, str]]:
    """Yield two device paths joined to each other; the bytes between them are copied by a thread."""
    first_controller, first_device = os.openpty()
    second_controller, second_device = os.openpty()
    for fd in (first_device, second_device):
        tty.setraw(fd)
    stop_reader, stop_writer = os.pipe()
    route = {first_controller: second_controller, second_controller: first_controller}

    def copy() -> None:
        while True:
            ready, _, _ = select.select([first_controller, second_controller, stop_reader], [], [])
            if stop_reader in ready:
                return
            for fd in ready:
                try:
                    data = os.read(fd, 4096)
                except OSError:  # no side has the device open at the moment
                    continue
                os.write(route[fd], data)

    thread = threading.Thread(target=copy, daemon=True)
    thread.start()
    try:
        yield os.ttyname(first_device), os.ttyname(second_device)
    finally:
        os.write(stop_writer, b"x")
        thread.join(5)
        for fd in (first_controller, first_device, second_controller, second_device, stop_reader, stop_writer):
            os.close(fd)


@contextmanager
def answering_line(asked: bytes, answer: bytes) -> Iterator[str]:
    """Yield a device path whose other side reads one line, checks that it is `asked` (its line ending included,
    the last byte of `asked`), and writes `answer`: a device that answers a client's request as the test says."""
    controller, device = os.openpty()
    seen: list[bytes] = []

    def reply() -> None:
        line = b""
        while not line.endswith(asked[-1:]):
            line += os.read(controller, 64)
        seen.append(line)
        os.write(controller, answer)

    thread = threading.Thread(target=reply, daemon=True)
    thread.start()
    try:
        yield os.ttyname(device)
    finally:
        thread.join(5)
        os.close(controller)
        os.close(device)
    assert seen == [asked], seen
