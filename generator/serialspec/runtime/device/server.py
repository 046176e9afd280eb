"""Serving a simulator on a file descriptor: a pseudo-terminal answered from a background thread."""

from __future__ import annotations

import heapq
import os
import select
import sys
import threading
import time
import tty
from collections import deque
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

from serialspec.runtime.device.engine import DeviceSpec, Engine
from serialspec.runtime.message import Message
from serialspec.runtime.stream import StreamParser

_TCGETS2 = 0x802C542A  # Linux: the termios with the line's speeds in bits per second (what pyserial sets)


def line_rate(fd: int) -> int | None:
    """The baud rate a terminal's line is set to (on a pseudo-terminal, by its client); None where unknown."""
    if sys.platform.startswith("linux"):
        import array
        import fcntl

        buf = array.array("i", [0] * 64)  # struct termios2 (44 bytes on Linux), room to spare
        try:
            fcntl.ioctl(fd, _TCGETS2, buf)
        except OSError:
            return None
        return buf[10]  # c_ospeed
    import termios

    try:
        speed = termios.tcgetattr(fd)[5]
    except termios.error:
        return None
    rates = {getattr(termios, name): int(name[1:]) for name in dir(termios) if name[1:].isdigit() and name[0] == "B"}
    return rates.get(speed)


@dataclass(order=True)
class _Scheduled:
    when: float
    seq: int
    data: bytes = field(compare=False)


class Simulator(Engine):
    """Virtual devices on one bus, served on a pseudo-terminal (or fed bytes directly, as an Engine)."""

    def __init__(
        self,
        spec: DeviceSpec,
        ids: Iterable[int],
        *,
        encode: Callable[[Message], bytes],
        parser: Callable[[], StreamParser],
        clock: Callable[[], float] | None = None,
        model: str | Mapping[int, str] | None = None,
        sizes: dict[str, int] | None = None,
    ) -> None:
        super().__init__(
            spec, ids, encode=encode, parser=parser, clock=clock or time.monotonic, model=model, sizes=sizes
        )
        self._emitted: deque[bytes] = deque()  # frames emit() hands to the serving thread
        self._outbox: list[_Scheduled] = []
        self._seq = 0
        self._wake_r, self._wake_w = os.pipe()
        # A plain flag, not a threading.Event: stop() runs in signal handlers (`sim` on SIGTERM), and an Event's set()
        # takes a lock that the interrupted thread may be holding inside its own wait() (a deadlock).
        self._stopping = False
        self._released = False  # close() has closed the pseudo-terminal and the wake-up pipe
        # Like a one-wire half-duplex adapter: every byte the client sends comes back to it before any reply.
        self.echo = False
        # A device set to one baud rate: bytes that come while the line is set to another are noise to it, so they
        # are dropped (what the pseudo-terminal's client set with tcsetattr; None: every rate is heard).
        self.baudrate: int | None = None
        # Called with ("request", bytes read) and ("response", bytes written) as they cross the pseudo-terminal:
        # replies, reports sent on the device's own (`device.sends`) and emit()ted frames alike (`sim --tap`).
        self.tap: Callable[[str, bytes], None] | None = None

    def emit(self, message: Message) -> None:
        """Send a message on the device's own initiative (a report, a key event) as soon as possible."""
        self._emitted.append(self.encode(message))  # encoding checks every value here, in the caller's thread
        os.write(self._wake_w, b"x")

    # --- serving on a file descriptor (a pseudo-terminal) ---------------------------------------------------------

    def serve(self, fd: int) -> None:
        """Answer requests read from `fd` until stop(); replies are written at their time (no polling)."""
        sends = bool(self.spec.sends)
        while not self._stopping:
            if sends:
                for when, frame in self.due():
                    self._seq += 1
                    heapq.heappush(self._outbox, _Scheduled(when, self._seq, frame))
            now = self.clock()
            while self._outbox and self._outbox[0].when <= now:
                frame = heapq.heappop(self._outbox).data
                os.write(fd, frame)
                if self.tap is not None:
                    self.tap("response", frame)
            times = [self._outbox[0].when] if self._outbox else []
            times += [t for t in [self.next_due() if sends else None] if t is not None]
            wait = max(0.0, min(times) - now) if times else None
            readable, _, _ = select.select([fd, self._wake_r], [], [], wait)
            if self._wake_r in readable:
                os.read(self._wake_r, 64)
            # Before any request read now: what emit() queued before the request was sent goes out before its reply.
            while self._emitted:
                self._seq += 1
                heapq.heappush(self._outbox, _Scheduled(self.clock(), self._seq, self._emitted.popleft()))
            if fd in readable:
                try:
                    data = os.read(fd, 4096)
                except OSError:  # the other side closed (EIO on a pty): wait for a new peer
                    data = b""
                if not data:
                    time.sleep(0.01)
                    continue
                if self.tap is not None:
                    self.tap("request", data)
                if self.echo:
                    os.write(fd, data)
                if self.baudrate is not None and line_rate(getattr(self, "_device_fd", fd)) != self.baudrate:
                    continue  # sent at another rate: noise to the device, which answers nothing
                for when, frame in self.feed(data):
                    self._seq += 1
                    heapq.heappush(self._outbox, _Scheduled(when, self._seq, frame))

    def stop(self) -> None:
        self._stopping = True
        if not self._released:
            os.write(self._wake_w, b"x")

    def open_pty(self) -> tuple[int, str]:
        """A pseudo-terminal pair in raw mode: the controller fd this simulator serves and the device path."""
        controller, device = os.openpty()
        tty.setraw(device)
        tty.setraw(controller)
        path = os.ttyname(device)
        self._device_fd = device  # kept open so the pty survives clients that come and go
        return controller, path

    def start(self) -> str:
        """Serve on a new pseudo-terminal from a background thread; returns the device path."""
        controller, path = self.open_pty()
        self._controller_fd = controller
        self._thread = threading.Thread(target=self.serve, args=(controller,), daemon=True, name="serialspec-sim")
        self._thread.start()
        return path

    def close(self) -> None:
        """Stop serving and release the pseudo-terminal: its path goes away and clients on it see a hang-up."""
        if self._released:
            return
        self.stop()
        thread = getattr(self, "_thread", None)
        if thread is not None:
            thread.join(2)
            if thread.is_alive():
                return  # still serving (stuck in a write): never close descriptors under it
        self._released = True
        pty = (getattr(self, "_controller_fd", None), getattr(self, "_device_fd", None))
        for fd in (*pty, self._wake_r, self._wake_w):
            if fd is not None:
                os.close(fd)
