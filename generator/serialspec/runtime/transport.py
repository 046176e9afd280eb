"""A bus to a device over pyserial: one transaction at a time, replies matched to requests by the spec's rule.

`Bus` opens a device path or any pyserial URL (`loop://`, `socket://host:port`, `rfc2217://...`, `spy://...`)
with the protocol's serial settings as defaults. Reads block on the port with a deadline (pyserial's read
timeout: no sleeping, no polling) and return as soon as the generated stream parser holds a complete reply that
matches the request. Frames that answer nothing meanwhile go to subscribers. Every failure is a typed exception
(Timeout, CorruptReply, DeviceError, PortError) after which the bus is ready for the next transaction.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any, TypeVar

import serial

from serialspec.runtime.errors import CorruptReply, DeviceError, PortError, Timeout
from serialspec.runtime.message import Message
from serialspec.runtime.stream import StreamParser

M = TypeVar("M", bound=Message)

_PARITY = {"none": serial.PARITY_NONE, "even": serial.PARITY_EVEN, "odd": serial.PARITY_ODD}


@dataclass(frozen=True)
class SerialSettings:
    """The spec's `serial:` section: defaults for opening a port."""

    baudrate: int
    bytesize: int = 8
    parity: str = "none"
    stopbits: float = 1


@dataclass(frozen=True)
class Binding:
    """What a bus needs of one generated protocol package (the generated client builds it)."""

    protocol: str
    serial: SerialSettings
    encode: Callable[[Message], bytes]
    parser: Callable[[], StreamParser]  # a parser for what the host receives (responses)
    match_by: tuple[str, ...]  # `command`, `subcommand` or field names, from the spec's `matching.by`
    status: tuple[str, ...] = ()  # reply fields whose non-zero value is a device error (frame status elements)
    describe_status: Callable[[str, int], str] = field(default=lambda name, value: f"{name} = {value:#04x}")


Subscriber = Callable[[Message], None]


class Bus:
    """A serial port shared by every device on it; one lock, so transactions from threads never interleave."""

    def __init__(
        self,
        port: str | serial.SerialBase,
        binding: Binding,
        *,
        timeout: float = 0.1,
        baudrate: int | None = None,
        **serial_options: Any,
    ) -> None:
        self.binding = binding
        self.timeout = timeout
        self._lock = threading.RLock()
        self._subscribers: list[Subscriber] = []
        self._unsolicited: deque[Message] = deque(maxlen=1024)
        self._parser = binding.parser()
        self._port: Any  # a pyserial port; the stubs' SerialBase lacks in_waiting and reset_input_buffer
        if isinstance(port, serial.SerialBase):
            self._port = port
        else:
            settings = binding.serial
            options: dict[str, Any] = {
                "baudrate": baudrate or settings.baudrate,
                "bytesize": settings.bytesize,
                "parity": _PARITY.get(settings.parity, serial.PARITY_NONE),
                "stopbits": settings.stopbits,
                "timeout": timeout,
            }
            options.update(serial_options)
            try:
                self._port = serial.serial_for_url(port, **options)
            except (serial.SerialException, OSError, ValueError) as exc:
                raise PortError(f"cannot open {port}: {exc}") from None
        self.port_name = str(getattr(self._port, "name", None) or getattr(self._port, "port", "") or port)

    # --- lifetime -------------------------------------------------------------------------------------------------

    def close(self) -> None:
        with self._lock:
            if self._port.is_open:
                self._port.close()

    def __enter__(self) -> Bus:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- subscribers ----------------------------------------------------------------------------------------------

    def subscribe(self, callback: Subscriber) -> Callable[[], None]:
        """Call `callback` with every frame that answers no request; returns a function that unsubscribes."""
        self._subscribers.append(callback)
        return lambda: self._subscribers.remove(callback) if callback in self._subscribers else None

    def _unmatched(self, message: Message) -> None:
        self._unsolicited.append(message)
        for callback in list(self._subscribers):
            callback(message)

    # --- transactions ---------------------------------------------------------------------------------------------

    def send(self, request: Message) -> None:
        """Encode (checking every value first) and write a request that expects no reply."""
        frame = self.binding.encode(request)  # raises EncodeError/RangeError before a byte is written
        with self._lock:
            self._drain()
            self._write(frame)

    def request(self, request: Message, expect: type[M], *, timeout: float | None = None) -> M:
        """Send a request and return its reply: the first frame of type `expect` that matches the request."""
        frame = self.binding.encode(request)
        wait = self.timeout if timeout is None else timeout
        with self._lock:
            self._drain()
            self._write(frame)
            reply = self._read_until(lambda m: isinstance(m, expect) and self.matches(request, m), wait, request)
        assert isinstance(reply, expect)
        self._check_status(reply)
        return reply

    def matches(self, request: Message, reply: Message) -> bool:
        """The spec's matching rule: the named attributes are equal where both messages have them."""
        for name in self.binding.match_by:
            if name == "command":
                if reply.COMMAND != request.COMMAND:
                    return False
            elif name == "subcommand":
                if reply.SUBCOMMAND != request.SUBCOMMAND:
                    return False
            elif hasattr(request, name) and hasattr(reply, name) and getattr(request, name) != getattr(reply, name):
                return False
        return True

    def receive(self, timeout: float | None = None) -> Message | None:
        """The next frame that answered no request (the device's own reports), or None after the timeout."""
        with self._lock:
            if self._unsolicited:
                return self._unsolicited.popleft()
            try:
                self._read_until(lambda m: True, self.timeout if timeout is None else timeout, None, keep=True)
            except Timeout:
                return None
            return self._unsolicited.popleft() if self._unsolicited else None

    def messages(self, timeout: float | None = None) -> Iterator[Message]:
        """Frames the device sends on its own, as they come; stops after `timeout` seconds of silence."""
        while (message := self.receive(timeout)) is not None:
            yield message

    # --- reading and writing --------------------------------------------------------------------------------------

    def _write(self, frame: bytes) -> None:
        try:
            self._port.write(frame)
        except (serial.SerialException, OSError) as exc:
            self._reset()
            raise PortError(f"{self.port_name}: write failed: {exc}") from None

    def _drain(self) -> None:
        """Hand bytes that arrived between transactions (late replies, reports) to subscribers, without waiting."""
        try:
            waiting = self._port.in_waiting
            if waiting:
                self._port.timeout = 0
                for message in self._parser.feed(self._port.read(waiting)):
                    self._unmatched(message)
        except (serial.SerialException, OSError) as exc:
            self._reset()
            raise PortError(f"{self.port_name}: read failed: {exc}") from None
        self._parser.errors = 0

    def _read_until(
        self, wanted: Callable[[Message], bool], wait: float, request: Message | None, keep: bool = False
    ) -> Message:
        deadline = time.monotonic() + wait
        errors = self._parser.errors
        while True:
            remaining = deadline - time.monotonic()
            try:
                if remaining <= 0:
                    chunk = b""
                else:
                    self._port.timeout = remaining
                    # Blocks until the first byte or the deadline; then takes whatever else has arrived.
                    chunk = self._port.read(1)
                    waiting = self._port.in_waiting if chunk else 0
                    if waiting:
                        chunk += self._port.read(waiting)
            except (serial.SerialException, OSError) as exc:
                self._reset()
                raise PortError(f"{self.port_name}: read failed: {exc}") from None
            found = None
            for message in self._parser.feed(chunk) if chunk else []:
                if found is None and wanted(message):
                    found = message
                    if keep:
                        self._unmatched(message)
                else:
                    self._unmatched(message)
            if found is not None:
                return found
            if self._parser.errors > errors:
                bad = self._parser.errors - errors
                self._reset()
                what = f" to {request.COMMAND} from {self._device(request)}" if request else ""
                raise CorruptReply(f"corrupt reply{what}: {bad} frame(s) failed their checksum or content check")
            if remaining <= 0 or (not chunk and time.monotonic() >= deadline):
                pending = self._parser.pending()
                self._reset()
                if request is None:
                    raise Timeout("", "", wait)
                if pending:
                    raise CorruptReply(
                        f"incomplete reply to {request.COMMAND} from {self._device(request)}: {pending.hex(' ')}"
                    )
                raise Timeout(request.COMMAND, self._device(request), wait)

    def _device(self, request: Message) -> str:
        parts = [f"{n}={getattr(request, n)}" for n in self.binding.match_by if hasattr(request, n)]
        return " ".join(parts)

    def _check_status(self, reply: Message) -> None:
        for name in self.binding.status:
            value = getattr(reply, name, 0)
            if value:
                text = self.binding.describe_status(name, int(value))
                raise DeviceError(f"{reply.COMMAND}: the device reports {text}", reply)

    def _reset(self) -> None:
        """Forget partial input so the next transaction starts clean."""
        self._parser = self.binding.parser()
        try:
            if self._port.is_open:
                self._port.reset_input_buffer()
        except (serial.SerialException, OSError, NotImplementedError):
            pass


class ClientBase:
    """What every generated client shares: the bus, the context manager, broadcast and optional replies."""

    ADDRESS: str = ""  # the field holding the device id
    BROADCAST: int | None = None

    def __init__(self, bus: Bus, optional_replies: bool | None) -> None:
        self.bus = bus
        self.optional_replies = optional_replies
        self._parameters: dict[tuple[int, int], float] = {}

    def close(self) -> None:
        self.bus.close()

    def __enter__(self) -> ClientBase:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def subscribe(self, callback: Subscriber) -> Callable[[], None]:
        """Call `callback` with every frame that answers no request (device reports, stray replies)."""
        return self.bus.subscribe(callback)

    def _is_broadcast(self, request: Message) -> bool:
        return self.BROADCAST is not None and getattr(request, self.ADDRESS, None) == self.BROADCAST

    def _ask(self, request: Message, expect: type[M], after: str = "") -> M:
        extra = float(getattr(request, after)) / 1000 if after else 0.0
        return self.bus.request(request, expect, timeout=self.bus.timeout + extra)

    def _maybe(self, request: Message, expect: type[M], optional: tuple[int, int] | None, after: str = "") -> M | None:
        """A reply unless the device stays silent: broadcast, or an optional reply its parameter switches off."""
        self.bus.binding.encode(request)  # check every value before any byte (even a parameter read) is written
        if self._is_broadcast(request) or (optional is not None and not self._answers(request, optional)):
            self.bus.send(request)
            return None
        return self._ask(request, expect, after)

    def _answers(self, request: Message, optional: tuple[int, int]) -> bool:
        if self.optional_replies is not None:
            return self.optional_replies
        key, value = optional
        address = int(getattr(request, self.ADDRESS, 0))
        if (address, key) not in self._parameters:
            self._parameters[(address, key)] = self._read_key(address, key)
        return self._parameters[(address, key)] == value

    def _read_key(self, address: int, key: int) -> float:
        """Read one table entry by key (generated clients whose spec can read entries override this)."""
        raise NotImplementedError("this protocol cannot read the parameter that switches its optional replies")

    def _remember(self, address: int, key: int, value: float) -> None:
        if self.BROADCAST is not None and address == self.BROADCAST:
            self._parameters = {k: v for k, v in self._parameters.items() if k[1] != key}
        else:
            self._parameters[(address, key)] = value
