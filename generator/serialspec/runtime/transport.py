"""A bus to a device over pyserial: one transaction at a time, replies matched to requests by the spec's rule.

`Bus` opens a device path or any pyserial URL (`loop://`, `socket://host:port`, `rfc2217://...`, `spy://...`)
with the protocol's serial settings as defaults. Reads block on the port with a deadline (pyserial's read
timeout: no sleeping, no polling) and return as soon as the generated stream parser holds a complete reply that
matches the request. Frames that answer nothing meanwhile go to subscribers. Every failure is a typed exception
(Timeout, CorruptReply, DeviceError, PortError) after which the bus is ready for the next transaction: a port that
failed (the device went away) or was closed under the bus is reopened by the next transaction, so a USB adapter
unplugged and plugged back in (or a symlink such as /dev/serial/by-id/... pointed at a new device) just works.
"""

from __future__ import annotations

import operator
import os
import select
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Generator, Iterator, Mapping, Sequence
from contextlib import suppress
from dataclasses import dataclass, field
from enum import Enum, IntEnum, IntFlag
from typing import Any, TypeVar

import serial

from serialspec.runtime.errors import (
    CorruptReply,
    DeviceError,
    EchoMismatch,
    EncodeError,
    PortError,
    RangeError,
    Timeout,
    shown,
)
from serialspec.runtime.message import Direction, Message, Record, takes_request
from serialspec.runtime.settings import SerialSettings as SerialSettings  # packages generated before import it here
from serialspec.runtime.stream import StreamParser

M = TypeVar("M", bound=Message)
T = TypeVar("T")
S = TypeVar("S")
R = TypeVar("R")


def drive(steps: Generator[S, R, T], step: Callable[[S], R]) -> T:
    """Run a transaction's steps (a generator that yields what it needs, a wait or a read, and is sent what came
    back) with a blocking `step`; an exception `step` raises is thrown into the steps. runtime/aio.py drives the
    same steps with awaits."""
    try:
        wanted = next(steps)
        while True:
            try:
                got = step(wanted)
            except Exception as exc:
                wanted = steps.throw(exc)
            else:
                wanted = steps.send(got)
    except StopIteration as stop:
        result: T = stop.value
        return result


_PARITY = {"none": serial.PARITY_NONE, "even": serial.PARITY_EVEN, "odd": serial.PARITY_ODD}

# What pyserial raises when the device goes away: termios.error (not an OSError) comes from setting the read
# timeout on a hung-up POSIX port.
_PORT_FAILURES: tuple[type[Exception], ...]
try:
    import termios

    _PORT_FAILURES = (serial.SerialException, OSError, termios.error)
except ImportError:  # Windows
    _PORT_FAILURES = (serial.SerialException, OSError)
# The port class whose reads and writes the bus may do itself on the descriptor (see FdLink): pyserial's own POSIX
# port, and spy:// (which only logs around it). Other subclasses override read/write and keep going through pyserial.
_POSIX_SERIAL: type | None = getattr(getattr(serial, "serialposix", None), "Serial", None)
_OPEN_FAILURES: tuple[type[Exception], ...] = (*_PORT_FAILURES, ValueError)  # ValueError: a bad setting
_RESET_FAILURES: tuple[type[Exception], ...] = (*_PORT_FAILURES, NotImplementedError)  # URLs without a buffer


@dataclass(frozen=True)
class ErrorReplies:
    """A protocol's error reply (Modbus exception): its class, the member holding the code of the request it
    refuses, the member saying why, and each command's code. The bus raises DeviceError when one answers."""

    response: type[Message]
    code_field: str
    reason_field: str
    codes: dict[str, int]  # command name -> code

    def refuses(self, request: Message, reply: Message) -> bool:
        code = self.codes.get(request.COMMAND)
        return isinstance(reply, self.response) and code is not None and getattr(reply, self.code_field) == code

    def describe(self, request: Message, reply: Message) -> str:
        if not self.reason_field:  # an error reply that says no more than that (MSP's `$M!`)
            return f"{request.COMMAND}: the device refuses it"
        reason: Any = getattr(reply, self.reason_field)
        if isinstance(reason, Record):  # a status of bit fields (`error_bits`): each that is not zero
            said = [(f"{self.reason_field}.{k}", getattr(reason, k)) for k in reason.__match_args__]
            said = [(k, v) for k, v in said if v] or said
        else:
            said = [(self.reason_field, reason)]
        text = ", ".join(f"{k} = {f'{v.name.lower()} ({v.value})' if isinstance(v, Enum) else v}" for k, v in said)
        return f"{request.COMMAND}: the device refuses it: {text}"


@dataclass(frozen=True)
class Binding:
    """What a bus needs of one generated protocol package (the generated client builds it)."""

    protocol: str
    serial: SerialSettings
    encode: Callable[[Message], bytes]
    parser: Callable[[], StreamParser]  # a parser for what the host receives (responses)
    match_by: tuple[str, ...]  # `command`, `subcommand` or field names, from the spec's `matching.by`
    status: tuple[str, ...] = ()  # reply fields whose non-zero value is a device error (frame status elements)
    status_ok: Mapping[str, frozenset[int]] = field(default_factory=dict)  # status -> its success values, if not 0
    address: str = ""  # the request field holding the device id: a Timeout names it, also where replies do not
    describe_status: Callable[[str, int], str] = field(default=lambda name, value: f"{name} = {value:#04x}")
    errors: ErrorReplies | None = None  # the protocol's error reply, if it has one
    # decode(frame, "response", expect): one whole reply, or DecodeError; a transaction's read of exactly the size
    # the last reply of its type had is decoded at once, without the stream parser's scan
    decode: Callable[[bytes, str, type[Message] | None], Message] | None = None
    # request class -> the codec's encoder of that class, which `encode` calls: the bus calls it at once, and
    # `encode` only for a request that one refuses (for encode's one-line error)
    encoders: Mapping[type, Callable[[Any], bytes]] = field(default_factory=dict)
    # request class -> the reply classes of other commands that answer or refuse it (the spec's `answered_by`): they
    # match it whatever `command` matching says
    answered_by: Mapping[type, tuple[type, ...]] = field(default_factory=dict)
    # request class -> the reply classes that refuse it (`refused_by`): the bus raises DeviceError naming them
    refused_by: Mapping[type, tuple[type, ...]] = field(default_factory=dict)
    # reply class -> its field holding the code of the request it answers (`request_code`), and each command's code
    code_fields: Mapping[type, str] = field(default_factory=dict)
    codes: Mapping[str, int] = field(default_factory=dict)
    # request class -> the replies that answer it besides the one a transaction expects: replies that share that
    # one's code, told apart by their content size (`answers`); the bus returns whichever comes
    alternatives: Mapping[type, tuple[type, ...]] = field(default_factory=dict)


def check_status(request: Message, reply: Message, name: str, ok: int, match_by: tuple[str, ...]) -> None:
    """A reply whose status field (the spec's `status: {ok: N}`) does not hold N is a device error."""
    value = getattr(reply, name)
    if value != ok:
        shown = f"{value.name.lower()} ({int(value)})" if isinstance(value, IntEnum) else str(value)
        raise DeviceError(f"{_asked(request, reply, match_by)}: the device reports {name} = {shown}", reply)


def check_echoes(request: Message, reply: Message, names: tuple[str, ...], match_by: tuple[str, ...]) -> None:
    """A reply field named like a request field repeats it: one that holds another value is an EchoMismatch."""
    for name in names:
        sent, got = getattr(request, name), getattr(reply, name)
        if got != sent:
            asked = _asked(request, reply, match_by)
            raise EchoMismatch(f"{asked}: the reply's {name} is {shown(got)}, not the {shown(sent)} sent", reply)


def _asked(request: Message, reply: Message, match_by: tuple[str, ...]) -> str:
    """The command and the device a reply answers, for an error line: `read to id=1`."""
    command = ".".join(part for part in (reply.COMMAND, reply.SUBCOMMAND) if part)
    ids = " ".join(f"{n}={getattr(request, n)}" for n in match_by if hasattr(request, n))
    return f"{command} to {ids}" if ids else command


def table_key(table: dict[str, int], name: str) -> int:
    """The key of a table entry given by name (a client's parameters by name)."""
    try:
        return table[name]
    except KeyError:
        raise EncodeError(f"unknown entry {name!r} (expected one of {', '.join(table)})") from None


def asked_reply(replies: Mapping[int, type[Message]], command: str, field_name: str, code: object) -> type[Message]:
    """The reply a request asking for a command by its code gets (`answered_by: {command_in: FIELD}`), refused
    before a byte is written when no command with a reply has that code."""
    found = replies.get(code) if isinstance(code, int) and not isinstance(code, bool) else None
    if found is None:
        known = ", ".join(str(c) for c in sorted(replies))
        raise RangeError(f"{command}: {field_name} = {code!r} is the code of no command with a reply (one of {known})")
    return found


def flag_names(flags: dict[str, type[IntFlag]]) -> Callable[[str, int], str]:
    """A `describe_status` that names a status byte's set bits by the spec's flags: `error = overheat (0x04)`."""

    def describe(name: str, value: int) -> str:
        kind = flags.get(name)
        names = [f.name.lower() for f in kind if f.name and value & f] if kind else []
        return f"{name} = {'|'.join(names) or 'unnamed bits'} ({value:#04x})"

    return describe


Subscriber = Callable[[Message], None]
# How a bus checks a reply of one type to one request type (Bus._rule): request type, whether it can answer, the
# getter of the fields to match, whether the reply is an error reply, the reply's status fields (each with the
# zeros of its bit fields, or None for a plain number).
_Rule = tuple[type, bool, Callable[[Any], Any] | None, bool, tuple[tuple[str, tuple[int, ...] | None], ...]]
# A record's field values against a plain tuple, as tuples (a record's own != says a record never equals a tuple).
_differ: Callable[[Any, tuple[int, ...]], bool] = tuple.__ne__
_ABSENT = object()  # an attribute a message does not have
_RESPONSE = Direction.RESPONSE  # what decode is told: its member, which generated codecs tell by identity first
# A parameter's `optional_when` condition (runtime.message.compare) as one C call; None never gets here.
_COMPARE: dict[str, Callable[[Any, Any], bool]] = {
    "==": operator.eq,
    "!=": operator.ne,
    ">=": operator.ge,
    "<=": operator.le,
}


class Link:
    """How a bus moves bytes through a port: pyserial's own calls, for any port or URL pyserial opens.

    Three operations make a transaction: `write` a frame, `read_waiting` (what arrived between transactions,
    without waiting) and `read` (whatever arrives, blocking up to a deadline for the first byte: no sleeping, no
    polling); `transact` does the three in one call. Port failures propagate as pyserial raises them; the bus turns
    them into PortError.
    """

    __slots__ = ("port", "doing")

    def __init__(self, port: Any) -> None:
        self.port = port
        self.doing = "read"  # the step of `transact` under way: what failed, when it raises

    def write(self, data: bytes) -> None:
        self.port.write(data)

    def read_waiting(self) -> bytes:
        port = self.port
        waiting = port.in_waiting
        if not waiting:
            return b""
        port.timeout = 0
        data: bytes = port.read(waiting)
        return data

    def transact(self, frame: bytes, wait: float) -> tuple[bytes, bytes | None]:
        """A transaction's I/O in one call, for a bus that reads back no echo (it waits out any gap before).

        Bytes that arrived since the last transaction come first: if there are any, they are returned with None
        and nothing is written (the bus hands them to subscribers, then writes). Otherwise `frame` is written and
        the first read of the reply returned (see `read`). On an exception, `doing` names the step that failed.
        """
        self.doing = "read"
        stale = self.read_waiting()
        if stale:
            return stale, None
        self.doing = "write"
        self.write(frame)
        self.doing = "read"
        return stale, self.read(wait)

    def read(self, wait: float) -> bytes:
        port = self.port
        if port.timeout != wait:
            port.timeout = wait
        # Blocks until the first byte or the deadline; then takes whatever else has arrived.
        chunk: bytes = port.read(1)
        waiting = port.in_waiting if chunk else 0
        return chunk + port.read(waiting) if waiting else chunk


class FdLink(Link):
    """pyserial's POSIX port (a tty, a pty), driven on its descriptor: one `os.write` per frame, one `poll` and one
    `os.read` per chunk read. pyserial keeps no buffer of its own there and opens the descriptor non-blocking, so
    this sees exactly the bytes it would, without a `select` after every write, an `in_waiting` ioctl per
    transaction, or a `tcsetattr` to change the read timeout. The descriptor is taken from the port at every call:
    a port closed under the bus fails its next call (fd None) instead of reading a stale descriptor. A spy://
    port (pyserial's logging subclass) keeps this path: its logger is handed the bytes as its own read and write
    would hand them.
    """

    __slots__ = ("_fd", "_poll", "_spy")

    def __init__(self, port: Any, spy: Any = None) -> None:
        super().__init__(port)
        self._fd = -1
        # poll() is the cheaper wait; macOS's does not work on terminal devices, so there it is select()
        self._poll = select.poll() if sys.platform.startswith("linux") else None
        self._spy = spy  # spy://'s formatter (its tx and rx log the bytes), or None

    def write(self, data: bytes) -> None:
        if self._spy is not None:
            self._spy.tx(data)
        try:
            written = os.write(self.port.fd, data)
        except BlockingIOError:
            written = 0
        if written < len(data):  # the output buffer is full: pyserial waits for room (and keeps its write_timeout)
            _POSIX_SERIAL.write(self.port, data[written:])  # type: ignore[union-attr]  # not spy's: logged above

    def read_waiting(self) -> bytes:
        # pyserial sets VMIN = VTIME = 0: a read with nothing there returns b"" at once (one syscall, the usual
        # case). A device that went away fails here or at the write that follows.
        try:
            data = os.read(self.port.fd, 4096)
        except BlockingIOError:
            return b""
        return self._rest(data) if data else data

    def _rest(self, data: bytes) -> bytes:
        """The bytes waiting, given the first read of them (more may wait: a read that fills the buffer is rare)."""
        fd = self.port.fd
        while len(data) % 4096 == 0:
            try:
                more = os.read(fd, 4096)
            except BlockingIOError:
                break
            if not more:
                break
            data += more
        if self._spy is not None:
            self._spy.rx(data)
        return data

    def transact(self, frame: bytes, wait: float) -> tuple[bytes, bytes | None]:
        # Link.transact's three steps inline: the usual transaction in one Python call and four system calls
        # (poll for what waits, write, poll, read). What waits is asked with a poll that does not wait: a read of
        # nothing raises BlockingIOError, whose making and catching costs five times the poll.
        self.doing = "read"
        fd = self.port.fd
        poll = self._poll
        if poll is None or fd != self._fd or poll.poll(0):  # bytes wait, the other end hung up, or first use
            try:
                stale = os.read(fd, 4096)
            except BlockingIOError:
                stale = b""
            if stale:
                return self._rest(stale), None
        self.doing = "write"
        if self._spy is not None:
            self.write(frame)
        else:  # write() inline
            try:
                written = os.write(fd, frame)
            except BlockingIOError:
                written = 0
            if written < len(frame):
                _POSIX_SERIAL.write(self.port, frame[written:])  # type: ignore[union-attr]
        self.doing = "read"
        if poll is None or fd != self._fd or self._spy is not None:
            return b"", self.read(wait)
        # read() inline: the descriptor is registered and open (it was read or polled above)
        if not poll.poll(wait * 1000):  # milliseconds, rounded up: never before the deadline
            return b"", self.read(0.0)  # the deadline passed: read() tells a port closed meanwhile from silence
        try:
            data = os.read(fd, 4096)
        except BlockingIOError:  # woken, but another reader took the bytes
            return b"", b""
        if not data:  # readable but empty: the other end hung up
            raise serial.SerialException("device disconnected")
        return b"", data

    def read(self, wait: float) -> bytes:
        fd = self.port.fd
        if fd is None:
            raise serial.SerialException("the port is closed")
        if self._poll is None:
            ready = bool(select.select([fd], [], [], wait)[0])
        else:
            if fd != self._fd:  # first read, or the port was reopened
                if self._fd >= 0:
                    self._poll.unregister(self._fd)
                self._poll.register(fd, select.POLLIN)
                self._fd = fd
            ready = bool(self._poll.poll(wait * 1000))  # milliseconds, rounded up: never before the deadline
        if not ready:
            if self.port.fd is None:  # closed by another thread while this one waited
                raise serial.SerialException("the port is closed")
            return b""
        try:
            data = os.read(fd, 4096)
        except BlockingIOError:  # woken, but another reader took the bytes
            return b""
        if not data:  # readable but empty: the other end hung up
            raise serial.SerialException("device disconnected")
        if self._spy is not None:
            self._spy.rx(data)
        return data


def link(port: Any) -> Link:
    """The fastest link that sees (and, for spy://, logs) exactly what pyserial would for this port."""
    if _POSIX_SERIAL is not None and isinstance(port, _POSIX_SERIAL):
        if type(port) is _POSIX_SERIAL:
            return FdLink(port)
        spy = getattr(port, "formatter", None)
        if type(port).__module__ == "serial.urlhandler.protocol_spy" and spy is not None:
            return FdLink(port, spy)
    return Link(port)


class Bus:
    """A serial port shared by every device on it; one lock, so transactions from threads never interleave."""

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
        """`echo`: a one-wire half-duplex adapter that hears its own transmission; every frame written is read
        back and checked before any reply is looked for (a mismatch or a missing echo is a PortError)."""
        self.binding = binding
        self.timeout = timeout
        self.echo = echo
        self._closed = False  # by close(): no transaction reopens the port after that
        self._lock = threading.RLock()
        self._subscribers: list[Subscriber] = []
        self._unsolicited: deque[Message] = deque(maxlen=1024)
        self._backlog: deque[Message] = deque()  # frames read after a reply within the same transaction
        self._parser = binding.parser()
        # whether the parser reads replies by the request's reply class (classic ones do not: a call saved)
        self._expects = type(self._parser).expect is not StreamParser.expect
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
            self._port = _open_port(port, options)
        self.port_name = str(getattr(self._port, "name", None) or getattr(self._port, "port", "") or port)
        self._link = link(self._port)
        self._gap = _gap_seconds(binding.serial.gap, self._port)
        self._last_io = 0.0  # when a byte was last written or read (for the inter-frame gap)
        self._turnaround = binding.serial.turnaround  # the wait after a request no device answers
        self._quiet_until = 0.0  # nothing is written before then (the turnaround after such a request)
        self._paced = bool(self._gap or self._turnaround)  # whether a write may have to wait
        # the spec's matching rule, split once: compare the command, the sub-command, then these fields
        match_by = binding.match_by
        self._match_command = "command" in match_by
        self._match_subcommand = "subcommand" in match_by
        self._match_fields = tuple(name for name in match_by if name not in ("command", "subcommand"))
        self._decode = binding.decode
        # a codec that reads replies with the request they answer (layouts chosen by command): given it
        self._asks = binding.decode is not None and takes_request(binding.decode)
        self._encoders = binding.encoders
        self._sizes: dict[type, int] = {}  # the size of the last reply of each type read whole (see request)
        self._rules: dict[type, _Rule] = {}  # the latest rule of each reply type
        self._all_rules: dict[tuple[type, type], _Rule] = {}

    # --- lifetime -------------------------------------------------------------------------------------------------

    def close(self) -> None:
        with self._lock:
            self._closed = True
            if self._port.is_open:
                self._port.close()

    def _ensure_open(self) -> None:
        """Reopen the port if it failed or was closed under the bus; refuse once the bus itself is closed."""
        if self._closed:
            raise PortError(f"{self.port_name}: the bus is closed")
        if self._port.is_open:
            return
        try:
            self._port.open()
        except _OPEN_FAILURES as exc:
            reason = _refused_setting(self._port.port, _settings_of(self._port)) or _reason(exc)
            raise PortError(f"cannot reopen {self.port_name}: {reason}") from None
        self._parser = self.binding.parser()
        self._link = link(self._port)

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
            self._ensure_open()
            self._drain()
            self._write(frame)
            if self._turnaround:  # no device answers: every one carries it out before the next request
                self._quiet_until = time.monotonic() + self._turnaround

    def request(
        self, request: Message, expect: type[M], *, timeout: float | None = None, frame: bytes | None = None
    ) -> M:
        """Send a request and return its reply: the first frame of type `expect` that matches the request.

        `frame`: the request as the codec encoded it before (a client sending one read again): not encoded again."""
        if frame is None:
            encoder = self._encoders.get(request.__class__)
            try:
                frame = encoder(request)  # type: ignore[misc]  # None: encode says why
            except Exception:  # encode raises it again, as one line naming the field (EncodeError, RangeError),
                frame = None  # outside this handler: one error, not two chained
            if frame is None:
                frame = self.binding.encode(request)
        wait = self.timeout if timeout is None else timeout
        lock = self._lock
        lock.acquire()  # not `with`: half the cost, at tens of microseconds per transaction
        try:
            if self._closed or not self._port.is_open:
                self._ensure_open()
            if self._backlog:
                self._flush_backlog()
            # The usual transaction inline (nothing waiting, the reply whole in the first read): every call less
            # matters. Anything else goes through _read_until.
            parser = self._parser
            # where replies share a code, the parser is told the layout this request's reply has before it is fed
            # (a reply decoded at once is told by its argument)
            expects = self._expects
            started = time.monotonic()
            chunk: bytes | None = None
            if not self.echo:
                parser.errors = 0
                link = self._link
                if self._paced:
                    self._wait_gap()
                try:
                    stale, chunk = link.transact(frame, wait)
                except Exception as exc:
                    self._port_failed(link.doing, exc)
                    raise
                if chunk is None:  # bytes came between transactions: to subscribers, then the request
                    if expects:
                        parser.expect(expect, request)
                    self._stale(stale)
            if chunk is None:  # the general path: an echo, or bytes that came before the request
                self._drain()
                parser = self._parser  # a subscriber's own request may have reset it
                parser.expect(expect, request)
                self._write(frame)
                started = time.monotonic()
                try:
                    chunk = self._link.read(wait) if not self._backlog else b""  # an echo check may have read it
                except Exception as exc:
                    self._port_failed("read", exc)
                    raise
            if self._gap:
                self._last_io = time.monotonic()  # the reply's end (no reply: the wait's, later than needed)
            if chunk:
                size = len(chunk)
                messages: list[Message] | None = None
                if size == self._sizes.get(expect) and not parser.pending():
                    # the size the last reply of this type had: most likely that reply, whole; decoded at once
                    try:
                        found: Message | None = (
                            self._decode(chunk, _RESPONSE, expect, request)  # type: ignore[misc, call-arg]
                            if self._asks
                            else self._decode(chunk, _RESPONSE, expect)  # type: ignore[misc]
                        )
                    except Exception:  # anything else is for the parser, which counts it and resynchronises
                        found = None
                else:
                    if expects:
                        parser.expect(expect, request)
                    messages = parser.feed(chunk)
                    found = messages[0] if len(messages) == 1 else None
                if found is not None and found.__class__ is expect:
                    rule = self._rules.get(expect)
                    if rule is None or rule[0] is not request.__class__:
                        rule = self._rule(request.__class__, found)
                    _, possible, getter, refusals, statuses = rule
                    if possible and (getter is None or getter(found) == getter(request)):
                        if messages is not None and self._decode is not None:
                            self._sizes[expect] = size
                        if refusals:
                            self._refused(request, found)
                        for name, zero in statuses:  # _check_status raises DeviceError
                            # an int's comparison (a flag's truth is a Python call); bit fields (a record) compared
                            # with their zeros as tuples, in one C call
                            if (getattr(found, name) != 0) if zero is None else _differ(getattr(found, name), zero):
                                self._check_status(found)
                        return found  # its class is expect
                if messages is None:  # decoded at once but no reply to this request: the parser takes it
                    if expects:
                        parser.expect(expect, request)
                    messages = parser.feed(chunk)
                self._backlog.extend(messages)  # _read_until takes them first
            if expects:
                self._parser.expect(expect, request)
            reply = self._read_until(wait - (time.monotonic() - started), request, expect, errors=0, timeout=wait)
            if self._backlog:
                self._flush_backlog()
        finally:
            lock.release()
        self._refused(request, reply)
        assert isinstance(reply, expect) or reply.__class__ in self.binding.alternatives.get(request.__class__, ())
        self._check_status(reply)
        return reply

    def _refused(self, request: Message, reply: Message) -> None:
        """An error reply that refuses the request (the spec's `errors:`), or a reply it is `refused_by`, is a
        DeviceError."""
        errors = self.binding.errors
        if errors is not None and errors.refuses(request, reply):
            raise DeviceError(errors.describe(request, reply), reply)
        if reply.__class__ in self.binding.refused_by.get(request.__class__, ()):
            what = ".".join(part for part in (reply.COMMAND, reply.SUBCOMMAND) if part)
            raise DeviceError(f"{request.COMMAND}: the device refuses it: {what}", reply)

    def _refusal(self, request: Message, reply: Message) -> bool:
        """Whether `reply`, not of the expected type, is an error reply refusing `request` (from the same device)."""
        errors = self.binding.errors
        if reply.__class__ in self.binding.refused_by.get(request.__class__, ()):
            return self.matches(request, reply)
        if errors is None or not errors.refuses(request, reply):
            return False
        return all(
            getattr(request, name) == getattr(reply, name)
            for name in self._match_fields
            if hasattr(request, name) and hasattr(reply, name)
        )

    def request_each(
        self, request: Message, expect: type[M], answers: list[dict[str, Any]], *, timeout: float | None = None
    ) -> list[M]:
        """Send one request that several devices answer in turn (FEETECH SYNC READ): one reply per entry of
        `answers`, in order, each the first frame of type `expect` whose attributes equal the entry's values.
        Each reply has the whole timeout; a missing one raises Timeout naming it."""
        frame = self.binding.encode(request)
        wait = self.timeout if timeout is None else timeout
        replies: list[M] = []
        with self._lock:
            self._ensure_open()
            self._drain()
            self._parser.expect(expect, request)
            self._write(frame)
            for key in answers:
                try:
                    reply = self._read_until(wait, request, expect, key)
                except Timeout:
                    raise Timeout(request.COMMAND, " ".join(f"{k}={v}" for k, v in key.items()), wait) from None
                replies.append(reply)
            self._flush_backlog()
        for reply in replies:
            self._check_status(reply)
        return replies

    def matches(self, request: Message, reply: Message) -> bool:
        """The spec's matching rule: the named attributes are equal where both messages have them. A reply of
        another command that the spec says answers the request matches its command; one that carries the code of
        the request it answers (`request_code`) matches when the code is the request's."""
        binding = self.binding
        if (
            self._match_command
            and reply.COMMAND != request.COMMAND
            and reply.__class__ not in binding.answered_by.get(request.__class__, ())
        ):
            return False
        code_field = binding.code_fields.get(reply.__class__)
        if code_field is not None and getattr(reply, code_field) != binding.codes.get(request.COMMAND):
            return False
        if self._match_subcommand and reply.SUBCOMMAND != request.SUBCOMMAND:
            return False
        for name in self._match_fields:
            mine = getattr(request, name, _ABSENT)
            if mine is not _ABSENT and getattr(reply, name, mine) != mine:
                return False
        return True

    def _rule(self, request_type: type, reply: Message) -> _Rule:
        """The matching rule for a reply of exactly the type of `reply` to a request of `request_type`, worked
        out once; the latest one of each reply type is at hand in `_rules` (a reply type usually answers one
        request type). It says whether the reply can answer at all (command, sub-command); gives a getter of the
        fields both have (None: none); whether it is the protocol's error reply; the reply's status fields, each
        with the zeros of its parts when it is made of bit fields (a Record; an error when any part is not 0)."""
        reply_type = type(reply)
        rule = self._all_rules.get((request_type, reply_type))
        if rule is None:
            binding = self.binding
            possible = (
                not (
                    self._match_command
                    and getattr(reply_type, "COMMAND", None) != getattr(request_type, "COMMAND", None)
                    and reply_type not in binding.answered_by.get(request_type, ())
                )
                and not (
                    self._match_subcommand
                    and getattr(reply_type, "SUBCOMMAND", None) != getattr(request_type, "SUBCOMMAND", None)
                )
                # a reply carrying its request's code is matched by `matches`, the code compared each time
                and reply_type not in binding.code_fields
            )
            names = [n for n in self._match_fields if hasattr(request_type, n) and hasattr(reply_type, n)]
            getter = operator.attrgetter(*names) if names else None
            statuses = tuple(
                (n, (0,) * len(value.__match_args__) if isinstance(value, Record) else None)
                for n in self.binding.status
                if (value := getattr(reply, n, _ABSENT)) is not _ABSENT
            )
            errors = self.binding.errors  # a reply that is no error reply refuses nothing
            refusals = errors is not None and isinstance(reply, errors.response)
            rule = (request_type, possible, getter, refusals, statuses)
            self._all_rules[(request_type, reply_type)] = rule
        self._rules[reply_type] = rule
        return rule

    def receive(self, timeout: float | None = None) -> Message | None:
        """The next frame that answered no request (the device's own reports), or None after the timeout."""
        with self._lock:
            if self._unsolicited:
                return self._unsolicited.popleft()
            self._ensure_open()
            try:
                self._read_until(self.timeout if timeout is None else timeout, None, Message, keep=True)
            except Timeout:
                return None
            self._flush_backlog()
            return self._unsolicited.popleft() if self._unsolicited else None

    def messages(self, timeout: float | None = None) -> Iterator[Message]:
        """Frames the device sends on its own, as they come; stops after `timeout` seconds of silence."""
        while (message := self.receive(timeout)) is not None:
            yield message

    # --- reading and writing --------------------------------------------------------------------------------------

    def _port_failed(self, doing: str, exc: Exception) -> None:
        """Raise PortError for a port failure; anything else is left for the caller to re-raise as it is.

        A port closed by another thread while a read waits makes pyserial fail with TypeError (its descriptor is
        None by then): that is a closed port too, not a bug. The failed port is closed so that the next
        transaction reopens it.
        """
        closed_under_the_bus = not self._port.is_open
        if not closed_under_the_bus and not isinstance(exc, _PORT_FAILURES):
            return
        reason = "the port was closed" if closed_under_the_bus else str(exc) or type(exc).__name__
        self._parser = self.binding.parser()
        with suppress(*_PORT_FAILURES):
            self._port.close()
        raise PortError(f"{self.port_name}: {doing} failed: {reason}") from None

    def _wait_gap(self) -> None:
        """The one wait the bus makes: the silence a protocol needs before a frame (3.5 characters for Modbus), or
        the turnaround after a request no device answers, whichever ends later."""
        wait = max(self._last_io + self._gap, self._quiet_until) - time.monotonic()
        if wait > 0:
            time.sleep(wait)

    def _write(self, frame: bytes) -> None:
        if self._paced:
            self._wait_gap()
        try:
            self._link.write(frame)
        except Exception as exc:
            self._port_failed("write", exc)
            raise
        if self._gap:
            self._last_io = time.monotonic()
        if self.echo:
            self._check_echo(frame)

    def _check_echo(self, frame: bytes) -> None:
        """Read back the echo of a frame just written; frames in the bytes after it (the reply) go to the backlog,
        which the read that follows takes first."""
        drive(self._echoing(frame), self._read_chunk)

    def _echoing(self, frame: bytes) -> Generator[float, bytes, None]:
        """_check_echo's steps: yields how long to wait for the next chunk and is sent it (see `drive`)."""
        deadline = time.monotonic() + self.timeout
        echoed = b""
        while len(echoed) < len(frame):
            remaining = deadline - time.monotonic()
            chunk = (yield remaining) if remaining > 0 else b""
            if not chunk:
                self._reset()
                raise PortError(
                    f"{self.port_name}: no echo of the {len(frame)} bytes written within {self.timeout:g} s "
                    f"(got {len(echoed)}: {echoed.hex(' ') or 'nothing'}); is echo=True right for this adapter?"
                )
            echoed += chunk
        if echoed[: len(frame)] != frame:
            self._reset()
            raise PortError(
                f"{self.port_name}: the echo differs from the bytes written: wrote {frame.hex(' ')}, "
                f"read back {echoed[: len(frame)].hex(' ')}"
            )
        rest = echoed[len(frame) :]
        if rest:
            self._backlog.extend(self._parser.feed(rest))

    def _read_chunk(self, wait: float) -> bytes:
        """What arrives within `wait` seconds (b"" if nothing); a port failure is a PortError."""
        try:
            return self._link.read(wait)
        except Exception as exc:
            self._port_failed("read", exc)
            raise

    def _drain(self) -> None:
        """Hand bytes that arrived between transactions (late replies, reports) to subscribers, without waiting."""
        try:
            chunk = self._link.read_waiting()
        except Exception as exc:
            self._port_failed("read", exc)
            raise
        self._stale(chunk)
        self._parser.errors = 0

    def _stale(self, chunk: bytes) -> None:
        """Frames held from the last transaction, then those in bytes that came between transactions: to
        subscribers."""
        if self._backlog:
            self._flush_backlog()
        if chunk:
            for message in self._parser.feed(chunk):
                self._unmatched(message)

    def _flush_backlog(self) -> None:
        """Frames that came with a reply but answer nothing go to subscribers now, not at the next transaction."""
        while self._backlog:
            self._unmatched(self._backlog.popleft())

    def _wanted(self, message: Message, request: Message | None, expect: type[M], key: dict[str, Any] | None) -> bool:
        """Whether `message` is what the transaction waits for: the reply to `request` (or, with `key`, the reply
        whose attributes equal the key's values); any frame when there is no request."""
        if not isinstance(message, expect):
            if request is None or key is not None:
                return False
            if message.__class__ in self.binding.alternatives.get(request.__class__, ()):
                return self.matches(request, message)
            return self._refusal(request, message)
        if key is not None:
            return all(getattr(message, k, None) == v for k, v in key.items())
        return request is None or self.matches(request, message)

    def _read_until(
        self,
        wait: float,
        request: Message | None,
        expect: type[M],
        key: dict[str, Any] | None = None,
        keep: bool = False,
        errors: int | None = None,
        timeout: float | None = None,
    ) -> M:
        """Read until the wanted frame has come: `_reading`'s steps, driven by blocking reads."""
        return drive(self._reading(wait, request, expect, key, keep, errors, timeout), self._read_chunk)

    def _reading(
        self,
        wait: float,
        request: Message | None,
        expect: type[M],
        key: dict[str, Any] | None = None,
        keep: bool = False,
        errors: int | None = None,
        timeout: float | None = None,
    ) -> Generator[float, bytes, M]:
        """Read until the wanted frame (see _wanted) has come, for up to `wait` seconds. Frames that came after it
        in the same read stay in the backlog (the next reply of a request_each); every other frame goes to
        subscribers, and to them too the wanted one when `keep`. Frames that fail their checks after the parser
        counted `errors` (by default: from now on) make it a CorruptReply. A Timeout names `timeout`, the whole
        transaction's (by default `wait`: what is left of it when part was spent before, maybe less than nothing)."""
        backlog = self._backlog
        while backlog:  # frames that came with the previous reply of this transaction
            message = backlog.popleft()
            if self._wanted(message, request, expect, key):
                if keep:
                    self._unmatched(message)
                return message  # type: ignore[return-value]  # _wanted checked its type
            self._unmatched(message)
        monotonic = time.monotonic
        deadline = monotonic() + wait
        parser = self._parser
        if errors is None:
            errors = parser.errors
        chunk = b""
        while True:
            if chunk:
                found = None
                for message in parser.feed(chunk):
                    if found is not None:
                        backlog.append(message)  # maybe the next reply of a request_each
                    elif self._wanted(message, request, expect, key):
                        found = message
                        if keep:
                            self._unmatched(message)
                    else:
                        self._unmatched(message)
                if found is not None:
                    return found  # type: ignore[return-value]  # _wanted checked its type
            if parser.errors > errors:
                bad = parser.errors - errors
                self._reset()
                what = f" to {request.COMMAND} from {self._device(request)}" if request else ""
                raise CorruptReply(f"corrupt reply{what}: {bad} frame(s) failed their checksum or content check")
            now = monotonic()
            if now >= deadline:
                pending = parser.pending()
                self._reset()
                if timeout is None:
                    timeout = wait
                if request is None:
                    raise Timeout("", "", timeout)
                if pending:
                    raise CorruptReply(
                        f"incomplete reply to {request.COMMAND} from {self._device(request)}: {pending.hex(' ')}"
                    )
                raise Timeout(request.COMMAND, self._device(request), timeout)
            chunk = yield deadline - now
            if chunk and self._gap:
                self._last_io = monotonic()

    def _device(self, request: Message) -> str:
        """The device a request went to, as its Timeout names it: the fields replies are matched by, and its id."""
        names = list(self.binding.match_by)
        if self.binding.address and self.binding.address not in names:
            names.append(self.binding.address)
        parts = [f"{n}={getattr(request, n)}" for n in names if hasattr(request, n)]
        return " ".join(parts)

    def _check_status(self, reply: Message) -> None:
        """A reply whose status fields (the spec's frame status elements) are not all zero (or not one of their `ok`
        values) is a DeviceError."""
        for name in self.binding.status:
            value = getattr(reply, name, 0)
            ok = self.binding.status_ok.get(name)
            if ok is not None:
                if int(value) not in ok:
                    raise DeviceError(
                        f"{reply.COMMAND}: the device reports {self.binding.describe_status(name, int(value))}", reply
                    )
            elif isinstance(value, Record):  # a status made of bit fields: an error when any is non-zero
                parts = {field: getattr(value, field) for field in value.__match_args__}
                if any(parts.values()):
                    text = ", ".join(f"{k} = {v.name.lower() if isinstance(v, Enum) else v}" for k, v in parts.items())
                    raise DeviceError(f"{reply.COMMAND}: the device reports {name} {text}", reply)
            elif value != 0:  # not `if value`: a flag's truth is a Python call, its comparison is int's
                text = self.binding.describe_status(name, int(value))
                raise DeviceError(f"{reply.COMMAND}: the device reports {text}", reply)

    def _reset(self) -> None:
        """Forget partial input so the next transaction starts clean."""
        self._parser = self.binding.parser()
        try:
            if self._port.is_open:
                self._port.reset_input_buffer()
        except _RESET_FAILURES:
            pass  # a port that has failed reports it on the next read or write


# The serial settings a port may refuse, in the order they are tried when opening fails.
_SETTINGS = ("baudrate", "bytesize", "parity", "stopbits")
_PARITY_NAMES = {value: name for name, value in _PARITY.items()}


def _gap_seconds(characters: float, port: Any) -> float:
    """A silence of `characters` character times at the port's settings (start, data, parity and stop bits)."""
    if not characters:
        return 0.0
    baudrate = getattr(port, "baudrate", 0) or 0
    if baudrate <= 0:
        return 0.0
    bits = 1 + int(getattr(port, "bytesize", 8)) + (getattr(port, "parity", "N") != "N") + float(port.stopbits)
    return characters * bits / baudrate


def _reason(exc: BaseException) -> str:
    """Why a port failed, in words: the system's reason alone where there is one (pyserial's own message repeats the
    path and the errno twice: `[Errno 2] could not open port X: [Errno 2] No such file or directory: 'X'`)."""
    number = getattr(exc, "errno", None)
    if isinstance(exc, OSError) and isinstance(number, int) and number > 0:
        return os.strerror(number)
    return str(exc) or type(exc).__name__


def _settings_of(port: Any) -> dict[str, Any]:
    return {name: getattr(port, name) for name in _SETTINGS if hasattr(port, name)}


def _open_port(url: str, options: dict[str, Any]) -> Any:
    """Open a port with its settings; a failure is a PortError naming the setting the port refused, if one was."""
    try:
        return serial.serial_for_url(url, **options)
    except _OPEN_FAILURES as exc:  # termios.error among them: never a raw one
        reason = _refused_setting(url, options) or _reason(exc)
        raise PortError(f"cannot open {url}: {reason}") from None


def _refused_setting(url: str, options: dict[str, Any]) -> str:
    """Which serial setting a port refuses: open it with pyserial's defaults, then apply the settings one at a
    time. "" when even that open fails (the port itself is the problem) or every setting is accepted alone."""
    try:
        port: Any = serial.serial_for_url(url, do_not_open=True)
        port.open()
    except _OPEN_FAILURES:
        return ""
    try:
        for name in _SETTINGS:
            if name not in options:
                continue
            value = options[name]
            try:
                setattr(port, name, value)
            except _OPEN_FAILURES as exc:
                shown = _PARITY_NAMES.get(value, value) if name == "parity" else value
                return f"the port refuses {name} = {shown} ({_reason(exc)})"
        return ""
    finally:
        with suppress(*_PORT_FAILURES):
            port.close()


class ClientState:
    """What every generated client shares, blocking or asyncio (runtime/aio.py): broadcast, the parameters that
    switch optional replies, the checks made before a byte is written. Its subclasses do the I/O."""

    ADDRESS: str = ""  # the field holding the device id
    BROADCAST: int | None = None
    bus: Any  # a Bus (ClientBase) or an AsyncBus

    def __init__(self, bus: Any, optional_replies: bool | None) -> None:
        self.bus = bus
        self.optional_replies = optional_replies
        self._parameters: dict[tuple[int, int], float | None] = {}  # None while being read
        # (address, register name) -> request, its frame, the value from the reply's bytes, the key of `_due` for a
        # reply a parameter may switch off (else ()): reads by name checked and encoded once (only a request the
        # codec accepted is here), then sent as they are
        self._reads: dict[tuple[int, str], tuple[Message, bytes, Callable[[bytes], int], tuple[Any, ...]]] = {}
        # (address, optional condition) -> whether those replies are due, from the parameters as last read or
        # written (emptied whenever they change): what a read sent again asks, without a call
        self._due: dict[tuple[Any, ...], bool] = {}
        self._read_was_optional = False  # the parameter read under way asked whether its own reply is due
        self._sequences: dict[str, int] = {}  # frame value -> the last sequence number sent in it

    def _sequence(self, name: str, low: int, high: int) -> int:
        """The next sequence number of a frame value the client fills in: `low` first, then one more each time,
        back to `low` past `high`."""
        last = self._sequences.get(name)
        value = low if last is None or last >= high else last + 1
        self._sequences[name] = value
        return value

    def close(self) -> None:
        self.bus.close()

    def subscribe(self, callback: Subscriber) -> Callable[[], None]:
        """Call `callback` with every frame that answers no request (device reports, stray replies)."""
        subscribed: Callable[[], None] = self.bus.subscribe(callback)
        return subscribed

    def _is_broadcast(self, request: Message) -> bool:
        return self.BROADCAST is not None and getattr(request, self.ADDRESS, None) == self.BROADCAST

    def _answering(self, request: Message, optional: tuple[int, int, str]) -> Generator[tuple[int, int], float, bool]:
        """Whether an optional reply is due. Steps (see `drive`): yields (address, key) of the parameter to read
        when it is not known yet, and is sent its value (or thrown the read's Timeout)."""
        if self.optional_replies is not None:
            return self.optional_replies
        key, value, op = optional
        address = getattr(request, self.ADDRESS, 0)
        current: Any = self._parameters.get((address, key), _ABSENT)
        if current is _ABSENT:
            self.bus.binding.encode(request)  # check every value before any byte (even a parameter read) is written
            address = int(address)
            # While the parameter is read, that read is asked as if it were answered (the read may itself be an
            # optional reply: DYNAMIXEL READ at status_return_level 0); no answer means no optional replies.
            self._due.clear()
            self._parameters[(address, key)] = None
            self._read_was_optional = False
            try:
                current = self._parameters[(address, key)] = yield address, key
            except Timeout as exc:
                del self._parameters[(address, key)]
                if not self._read_was_optional:  # a read that is always answered was not: no device is there
                    raise Timeout(request.COMMAND, self.bus._device(request), exc.timeout) from None
                return False  # silence may be the parameter's doing (DYNAMIXEL status_return_level 0)
            finally:
                self._due.clear()
        if current is None:
            self._read_was_optional = True
            return True
        due = self._due[(address, optional)] = _COMPARE[op](current, value)
        return due

    def _carrier(
        self,
        requests: Sequence[Message],
        carried: Mapping[type[Message], tuple[int, type[Message] | None]],
        content: slice,
        build: Callable[[int, list[bytes]], Message],
    ) -> tuple[Message, type[Message] | None, list[dict[str, Any]]]:
        """Requests of one command inside one carrier request (a sync command): the carrier, the reply class each
        device answers with (None: no reply), and the key of each reply.

        `carried`: request class -> (its command code, the reply class each device answers with, or None);
        `content`: where a request's content sits in its encoded frame; `build`: the carrier from code and contents.
        """
        kinds = {type(r) for r in requests}
        if len(kinds) != 1:
            raise EncodeError("a sync command carries requests of one command: give one or more, all of one type")
        kind = kinds.pop()
        if kind not in carried:
            raise EncodeError(
                f"{kind.__name__} cannot be carried (expected one of {', '.join(c.__name__ for c in carried)})"
            )
        code, reply = carried[kind]
        request = build(code, [self.bus.binding.encode(r)[content] for r in requests])
        return request, reply, [{self.ADDRESS: getattr(r, self.ADDRESS)} for r in requests]

    def _new_address_timeout(self, request: Message, address: int, exc: Timeout) -> Timeout:
        """The Timeout of a write of the id, naming the device written to and the id it was to answer from."""
        return Timeout(request.COMMAND, f"{self.bus._device(request)} (as {self.ADDRESS}={address})", exc.timeout)

    def _remember(self, address: int, key: int, value: float) -> None:
        self._due.clear()
        if self.BROADCAST is not None and address == self.BROADCAST:
            self._parameters = {k: v for k, v in self._parameters.items() if k[1] != key}
        else:
            self._parameters[(address, key)] = value


class ClientBase(ClientState):
    """What every generated (blocking) client shares: the bus, the context manager, broadcast and optional replies."""

    bus: Bus

    def __init__(self, bus: Bus, optional_replies: bool | None) -> None:
        super().__init__(bus, optional_replies)

    def __enter__(self) -> ClientBase:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _ask(self, request: Message, expect: type[M], after: str = "") -> M:
        if not after:
            return self.bus.request(request, expect)
        return self.bus.request(request, expect, timeout=self.bus.timeout + float(getattr(request, after)) / 1000)

    def _maybe(
        self, request: Message, expect: type[M], optional: tuple[int, int, str] | None, after: str = ""
    ) -> M | None:
        """A reply unless the device stays silent: broadcast, or an optional reply its parameter switches off."""
        if self._is_broadcast(request) or (optional is not None and not self._answers(request, optional)):
            self.bus.send(request)  # which checks every value before a byte is written
            return None
        if after:
            return self._ask(request, expect, after)
        return self.bus.request(request, expect)

    def _from_new_address(
        self, request: Message, expect: type[Message], address: int, optional: tuple[int, int, str] | None
    ) -> bool | None:
        """A write of the device's own id, whose reply comes (if it is due) from the new id: True once it has."""
        if self._is_broadcast(request) or (optional is not None and not self._answers(request, optional)):
            self.bus.send(request)
            return None
        try:
            self.bus.request_each(request, expect, [{self.ADDRESS: address}])
        except Timeout as exc:
            raise self._new_address_timeout(request, address, exc) from None
        return True

    def _answers(self, request: Message, optional: tuple[int, int, str]) -> bool:
        return drive(self._answering(request, optional), self._read_parameter)

    def _read_parameter(self, where: tuple[int, int]) -> float:
        return self._read_key(*where)

    def _carry(
        self,
        requests: Sequence[Message],
        carried: Mapping[type[Message], tuple[int, type[Message] | None]],
        content: slice,
        build: Callable[[int, list[bytes]], Message],
    ) -> list[Message]:
        """Send requests of one command inside one carrier request (a sync command); the replies, if any are due
        (see `_carrier`)."""
        request, reply, keys = self._carrier(requests, carried, content, build)
        if reply is None:
            self.bus.send(request)
            return []
        return list(self.bus.request_each(request, reply, keys))

    def _read_key(self, address: int, key: int) -> float:
        """Read one table entry by key (generated clients whose spec can read entries override this)."""
        raise NotImplementedError("this protocol cannot read the parameter that switches its optional replies")
