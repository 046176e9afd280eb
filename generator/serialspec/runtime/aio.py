"""The bus for asyncio: what generated `<protocol>.aio` clients run on.

`AsyncBus` opens a port as `Bus` does (a device path or any pyserial URL, the protocol's serial settings as
defaults) and keeps every rule of `Bus`: the transaction's steps (`Bus._reading`, `Bus._echoing`), reply matching,
status and error replies, subscribers, reopening a port that failed. Only the waiting differs: a pyserial POSIX port
(a tty, a pty) is waited on with the event loop's reader API (`loop.add_reader` on its descriptor), so a task waiting
for a reply blocks nothing; any other port (`socket://`, `rfc2217://`, Windows) reads in a worker thread.

One `asyncio.Lock` per bus: transactions from concurrent tasks (several devices on one bus) never interleave, so a
reply always reaches the task that asked for it. A task cancelled during a transaction (`asyncio.timeout`,
`wait_for`) leaves the bus ready for the next one: input already read is forgotten, a late reply goes to
subscribers.
"""

from __future__ import annotations

import asyncio
import time
from collections.abc import AsyncIterator, Awaitable, Callable, Generator, Mapping, Sequence
from typing import Any, TypeVar

import serial

from serialspec.runtime.errors import Timeout
from serialspec.runtime.message import Message
from serialspec.runtime.transport import Binding, Bus, ClientState, FdLink, Link, Subscriber

M = TypeVar("M", bound=Message)
T = TypeVar("T")
S = TypeVar("S")
R = TypeVar("R")


async def drive(steps: Generator[S, R, T], step: Callable[[S], Awaitable[R]]) -> T:
    """`transport.drive` with an awaited step: the same transaction steps, run without blocking the loop."""
    try:
        wanted = next(steps)
        while True:
            try:
                got = await step(wanted)
            except Exception as exc:
                wanted = steps.throw(exc)
            else:
                wanted = steps.send(got)
    except StopIteration as stop:
        result: T = stop.value
        return result


def _wake(ready: asyncio.Future[None]) -> None:
    if not ready.done():
        ready.set_result(None)


async def read_available(link: Link, port: Any, wait: float) -> bytes:
    """What arrives on `port` (read through `link`) within `wait` seconds, b"" if nothing: the loop watches a
    POSIX port's descriptor; other ports read in a worker thread."""
    if not isinstance(link, FdLink):
        return await asyncio.to_thread(link.read, wait)
    fd = port.fd
    if fd is None:
        raise serial.SerialException("the port is closed")
    loop = asyncio.get_running_loop()
    ready: asyncio.Future[None] = loop.create_future()
    loop.add_reader(fd, _wake, ready)
    deadline = loop.call_later(wait, _wake, ready)  # woken by the first byte or the deadline, whichever comes
    try:
        await ready
    finally:
        deadline.cancel()
        loop.remove_reader(fd)
    return link.read(0.0)  # what is there (b"" at the deadline); a port that hung up fails here


class AsyncBus:
    """A serial port shared by every device on it, for asyncio; one lock, so transactions from concurrent tasks
    never interleave. The same arguments as `Bus`; every method that moves bytes is a coroutine."""

    def __init__(
        self,
        port: str | serial.SerialBase,
        binding: Binding,
        *,
        timeout: float = 0.1,
        baudrate: int | None = None,
        echo: bool = False,
        **serial_options: Any,
    ) -> None:
        # The blocking bus opens the port and holds the state and rules; this one only waits differently.
        self.sync = Bus(port, binding, timeout=timeout, baudrate=baudrate, echo=echo, **serial_options)
        self.binding = binding
        self.port_name = self.sync.port_name
        self._lock = asyncio.Lock()

    @property
    def timeout(self) -> float:
        return self.sync.timeout

    @timeout.setter
    def timeout(self, value: float) -> None:
        self.sync.timeout = value

    def close(self) -> None:
        self.sync.close()

    async def __aenter__(self) -> AsyncBus:
        return self

    async def __aexit__(self, *exc: object) -> None:
        self.close()

    def subscribe(self, callback: Subscriber) -> Callable[[], None]:
        """Call `callback` with every frame that answers no request; returns a function that unsubscribes."""
        return self.sync.subscribe(callback)

    def matches(self, request: Message, reply: Message) -> bool:
        return self.sync.matches(request, reply)

    def _device(self, request: Message) -> str:
        return self.sync._device(request)

    # --- transactions ---------------------------------------------------------------------------------------------

    async def send(self, request: Message) -> None:
        """Encode (checking every value first) and write a request that expects no reply."""
        frame = self.binding.encode(request)  # raises EncodeError/RangeError before a byte is written
        async with self._lock:
            self.sync._ensure_open()
            self.sync._drain()
            await self._write(frame)
            if self.sync._turnaround:  # no device answers: every one carries it out before the next request
                self.sync._quiet_until = time.monotonic() + self.sync._turnaround

    async def request(
        self, request: Message, expect: type[M], *, timeout: float | None = None, frame: bytes | None = None
    ) -> M:
        """Send a request and return its reply: the first frame of type `expect` that matches the request.

        `frame`: the request as the codec encoded it before (a client sending one read again): not encoded again."""
        bus = self.sync
        if frame is None:
            frame = self.binding.encode(request)  # raises EncodeError/RangeError before a byte is written
        wait = bus.timeout if timeout is None else timeout
        async with self._lock:
            bus._ensure_open()
            bus._drain()
            bus._parser.expect(expect, request)
            await self._write(frame)
            reply = await self._until(bus._reading(wait, request, expect))
            bus._flush_backlog()
        bus._refused(request, reply)
        bus._check_status(reply)
        return reply

    async def request_each(
        self, request: Message, expect: type[M], answers: list[dict[str, Any]], *, timeout: float | None = None
    ) -> list[M]:
        """Send one request that several devices answer in turn (see `Bus.request_each`)."""
        bus = self.sync
        frame = self.binding.encode(request)
        wait = bus.timeout if timeout is None else timeout
        replies: list[M] = []
        async with self._lock:
            bus._ensure_open()
            bus._drain()
            bus._parser.expect(expect, request)
            await self._write(frame)
            for key in answers:
                try:
                    reply = await self._until(bus._reading(wait, request, expect, key))
                except Timeout:
                    raise Timeout(request.COMMAND, " ".join(f"{k}={v}" for k, v in key.items()), wait) from None
                replies.append(reply)
            bus._flush_backlog()
        for reply in replies:
            bus._check_status(reply)
        return replies

    async def receive(self, timeout: float | None = None) -> Message | None:
        """The next frame that answered no request (the device's own reports), or None after the timeout."""
        bus = self.sync
        async with self._lock:
            if bus._unsolicited:
                return bus._unsolicited.popleft()
            bus._ensure_open()
            try:
                await self._until(bus._reading(bus.timeout if timeout is None else timeout, None, Message, keep=True))
            except Timeout:
                return None
            bus._flush_backlog()
            return bus._unsolicited.popleft() if bus._unsolicited else None

    async def messages(self, timeout: float | None = None) -> AsyncIterator[Message]:
        """Frames the device sends on its own, as they come; stops after `timeout` seconds of silence."""
        while (message := await self.receive(timeout)) is not None:
            yield message

    # --- waiting --------------------------------------------------------------------------------------------------

    async def _until(self, steps: Generator[float, bytes, T]) -> T:
        """Run a transaction's steps; a cancelled task leaves no half-read frame behind."""
        try:
            return await drive(steps, self._read_chunk)
        except asyncio.CancelledError:
            self.sync._reset()
            raise

    async def _read_chunk(self, wait: float) -> bytes:
        try:
            return await self._read(wait)
        except Exception as exc:
            self.sync._port_failed("read", exc)
            raise

    async def _read(self, wait: float) -> bytes:
        return await read_available(self.sync._link, self.sync._port, wait)

    async def _write(self, frame: bytes) -> None:
        bus = self.sync
        if bus._paced:  # the silence the protocol needs before a frame, slept without blocking the loop
            wait = max(bus._last_io + bus._gap, bus._quiet_until) - time.monotonic()
            if wait > 0:
                await asyncio.sleep(wait)
        try:
            bus._link.write(frame)
        except Exception as exc:
            bus._port_failed("write", exc)
            raise
        if bus._gap:
            bus._last_io = time.monotonic()
        if bus.echo:
            await self._until(bus._echoing(frame))


class AsyncClientBase(ClientState):
    """What every generated asyncio client shares: `ClientState`'s rules over an AsyncBus; an async context manager
    (`async with`)."""

    bus: AsyncBus

    def __init__(self, bus: AsyncBus, optional_replies: bool | None) -> None:
        super().__init__(bus, optional_replies)

    async def __aenter__(self) -> AsyncClientBase:
        return self

    async def __aexit__(self, *exc: object) -> None:
        self.close()

    async def _ask(self, request: Message, expect: type[M], after: str = "") -> M:
        if not after:
            return await self.bus.request(request, expect)
        return await self.bus.request(request, expect, timeout=self.bus.timeout + float(getattr(request, after)) / 1000)

    async def _maybe(
        self, request: Message, expect: type[M], optional: tuple[int, int, str] | None, after: str = ""
    ) -> M | None:
        """A reply unless the device stays silent: broadcast, or an optional reply its parameter switches off."""
        if self._is_broadcast(request) or (optional is not None and not await self._answers(request, optional)):
            await self.bus.send(request)  # which checks every value before a byte is written
            return None
        return await self._ask(request, expect, after)

    async def _from_new_address(
        self, request: Message, expect: type[Message], address: int, optional: tuple[int, int, str] | None
    ) -> bool | None:
        """A write of the device's own id, whose reply comes (if it is due) from the new id: True once it has."""
        if self._is_broadcast(request) or (optional is not None and not await self._answers(request, optional)):
            await self.bus.send(request)
            return None
        try:
            await self.bus.request_each(request, expect, [{self.ADDRESS: address}])
        except Timeout as exc:
            raise self._new_address_timeout(request, address, exc) from None
        return True

    async def _answers(self, request: Message, optional: tuple[int, int, str]) -> bool:
        return await drive(self._answering(request, optional), self._read_parameter)

    async def _read_parameter(self, where: tuple[int, int]) -> float:
        return await self._read_key(*where)

    async def _carry(
        self,
        requests: Sequence[Message],
        carried: Mapping[type[Message], tuple[int, type[Message] | None]],
        content: slice,
        build: Callable[[int, list[bytes]], Message],
    ) -> list[Message]:
        """Send requests of one command inside one carrier request (a sync command); the replies, if any are due."""
        request, reply, keys = self._carrier(requests, carried, content, build)
        if reply is None:
            await self.bus.send(request)
            return []
        return list(await self.bus.request_each(request, reply, keys))

    async def _read_key(self, address: int, key: int) -> float:
        """Read one table entry by key (generated clients whose spec can read entries override this)."""
        raise NotImplementedError("this protocol cannot read the parameter that switches its optional replies")
