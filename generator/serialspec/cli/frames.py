"""Splitting the bytes seen on a port into frames of both directions, for `monitor` and `decode --file`.

Where requests and responses have different headers the generated StreamParser takes both at once. Where they
share one (RRC, SMS) a frame is tried as both: after a request, first as its reply (a reply that names the same
device as the request), otherwise first as a request; so a session's requests and replies are told apart.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType
from typing import Any

from serialspec.runtime.errors import DecodeError
from serialspec.runtime.framing import EngineFormat
from serialspec.runtime.message import Message
from serialspec.runtime.stream import FrameFormat


@dataclass(frozen=True)
class Seen:
    """What a chunk of bytes held: a frame (message and bytes), or bad bytes (message None, the bytes themselves)
    with a reason; `origin` is what the caller gave with the chunk the (first) bytes came from (a line number)."""

    message: Message | None
    data: bytes
    reason: str = ""
    origin: object = None


@dataclass
class _Run:
    """Bad bytes in a row: the first one's origin, and how many failed frames they hold."""

    data: bytes
    origin: object
    failed: int

    def seen(self) -> Seen:
        if self.failed:
            return Seen(None, self.data, f"{self.failed} frame(s) failed their checksum or content check", self.origin)
        return Seen(None, self.data, f"{len(self.data)} byte(s) outside any frame", self.origin)


class Frames:
    def __init__(self, package: ModuleType, direction: str | None, address: str | None = None) -> None:
        self.package = package
        self.address = address
        self._paired: _Paired | None = None
        try:
            self._parser: Any = package.StreamParser(direction)
        except ValueError:
            codec = package.codec
            self._paired = _Paired(codec.REQUEST_FORMAT, codec.RESPONSE_FORMAT, address)
            self._paired.reply_layouts = getattr(codec, "REPLY_LAYOUTS", {})
            self._parser = self._paired
        # The bytes the parser holds back (a frame's start, or what may be one) with the origins of the chunks they
        # came from, as (offset, origin); and the bad bytes just before them, not reported yet: held bytes that turn
        # out bad too are reported with them, once, under the first one's origin.
        self._held = b""
        self._origins: list[tuple[int, object]] = []
        self._run: _Run | None = None

    def _encoded(self, message: Message) -> bytes:
        """A message's frame again (its bytes in the stream): a reply read with its request, encoded with it (its
        checksum may take in bytes of the request)."""
        request = getattr(self._parser, "request", None)
        return self.package.encode(message) if request is None else self.package.encode(message, request)  # type: ignore[no-any-return]

    def expect(self, cls: type, request: Message) -> None:
        """The reply class the next frames answer and the request they answer (binary frames read with their
        request: layouts chosen by command, a reply checksum over request bytes), seen in the other direction's
        stream."""
        if self._paired is None:
            self._parser.expect(cls, request)

    def expect_text(self, reply: str) -> None:
        """A text protocol's reply of values alone (`values_only`) with this code answers the request just seen
        in the other direction's stream: the next line is read as it."""
        self._parser.expect(reply)

    def feed(self, chunk: bytes, origin: object = None) -> list[Seen]:
        """The frames and bad bytes that `chunk` completes, in stream order: each run of bad bytes once, as the
        bytes themselves, under the origin of the chunk its first byte came from (`de ad`, then a valid frame in
        the next chunk: 2 bad bytes from the first, none blamed on the second)."""
        errors = self._parser.errors
        stream = self._held + chunk
        origins = [*self._origins, (len(self._held), origin)]
        if self._paired is not None:
            frames = self._paired.feed(chunk)
        else:
            frames = [(message, self._encoded(message)) for message in self._parser.feed(chunk)]
        failed = self._parser.errors - errors
        held = self.pending()
        end = len(stream) - len(held)  # the bytes held back are the stream's last
        seen: list[Seen] = []
        cursor = 0
        for message, data in frames:
            position = stream.find(data, cursor, end)
            if position < 0:  # not there as the codec encodes it (sent another way): its place is not known
                position = cursor
            if position > cursor:
                seen += self._bad(stream[cursor:position], _at(origins, cursor), cursor == 0, failed)
                failed = 0
            seen += self.finish()  # a frame ends a run of bad bytes
            seen.append(Seen(message, data, origin=_at(origins, position)))
            cursor = max(cursor, position + len(data))
        if cursor < end or failed:
            seen += self._bad(stream[cursor:end], _at(origins, cursor), cursor == 0, failed)
        if not held:  # nothing held back can join the run
            seen += self.finish()
        self._held = held
        self._origins = [(max(0, offset - end), o) for offset, o in origins if _reaches(origins, offset, end, stream)]
        return seen

    def _bad(self, data: bytes, origin: object, follows: bool, failed: int) -> list[Seen]:
        """Bad bytes, added to the run carried from before where they follow it; a run they do not follow is
        reported."""
        if self._run is not None and follows:
            self._run = _Run(self._run.data + data, self._run.origin, self._run.failed + failed)
            return []
        seen = self.finish()
        self._run = _Run(data, origin, failed)
        return seen

    def finish(self) -> list[Seen]:
        """The run of bad bytes not reported yet (at the end of a capture: nothing more can join it)."""
        run, self._run = self._run, None
        return [run.seen()] if run is not None else []

    def pending(self) -> bytes:
        return self._paired.buffer if self._paired is not None else bytes(self._parser.pending())


def _at(origins: list[tuple[int, object]], offset: int) -> object:
    """The origin of the byte at `offset`: that of the last chunk starting at or before it."""
    found = origins[0][1]
    for start, origin in origins:
        if start > offset:
            break
        found = origin
    return found


def _reaches(origins: list[tuple[int, object]], offset: int, end: int, stream: bytes) -> bool:
    """Whether the chunk starting at `offset` has bytes from `end` on (among those held back)."""
    following = [start for start, _ in origins if start > offset]
    return end < len(stream) and (min(following) if following else len(stream)) > end


class _Direction:
    """One direction's frame format as the pairing splitter reads it: the frame size a header position implies."""

    def __init__(self, frame_format: FrameFormat | EngineFormat) -> None:
        self.format = frame_format
        if isinstance(frame_format, EngineFormat):  # frames of any layout: the frame engine sizes them
            self.prefix = 1
            self.size = frame_format.size  # type: ignore[method-assign]
            return
        self.prefix = max(frame_format.length_offset, frame_format.command_offset or 0) + 1  # bytes to size a frame

    def size(self, buffer: bytes, position: int) -> int | None:
        """The frame's size if the bytes at `position` start a plausible frame (known command, fitting length)."""
        f = self.format
        assert isinstance(f, FrameFormat)
        content = buffer[position + f.length_offset] - f.length_adds
        code = None if f.command_offset is None else buffer[position + f.command_offset]
        bounds = f.content_sizes.get(code)
        if bounds is None or content < bounds[0] or (bounds[1] is not None and content > bounds[1]):
            return None
        return f.overhead + content


class _Paired:
    """Both directions of a shared-header protocol in one stream, requests paired with their replies."""

    def __init__(
        self, request: FrameFormat | EngineFormat, response: FrameFormat | EngineFormat, address: str | None
    ) -> None:
        self.request, self.response = _Direction(request), _Direction(response)
        self.header = request.header
        self.address = address
        self.buffer = b""
        self.awaiting: Message | None = None  # the last request, until a reply comes
        self.reply_layouts: dict[type[Message], type[Message]] = {}  # request -> reply class, where codes are shared
        self.errors = 0
        self.garbage = 0

    def feed(self, data: bytes) -> list[tuple[Message, bytes]]:
        buffer = self.buffer + data
        found: list[tuple[Message, bytes]] = []
        start = 0
        while True:
            position = buffer.find(self.header, start)
            if position < 0:
                cut = max(start, len(buffer) - len(self.header) + 1)
                self.garbage += cut - start
                self.buffer = buffer[cut:]
                return found
            self.garbage += position - start
            result = self._frame(buffer, position)
            if isinstance(result, str):  # "wait": plausible so far, incomplete
                self.buffer = buffer[position:]
                return found
            if result is None:
                start = position + 1
                self.garbage += 1
                continue
            message, stop = result
            found.append((message, buffer[position:stop]))
            self.awaiting = message if message.DIRECTION.value == "request" else None
            start = stop

    def _frame(self, buffer: bytes, position: int) -> tuple[Message, int] | str | None:
        order = (self.response, self.request) if self.awaiting is not None else (self.request, self.response)
        failed = False
        fallback: tuple[Message, int] | None = None
        for candidate in order:
            if len(buffer) - position < candidate.prefix:
                return "wait"
            size = candidate.size(buffer, position)
            if size is None:
                continue
            if position + size > len(buffer):
                return "wait"
            try:
                if isinstance(candidate.format, EngineFormat) and candidate is self.response:
                    # where replies share a code, the layout the request waiting for its reply gets
                    expect = self.reply_layouts.get(type(self.awaiting)) if self.awaiting else None
                    message = candidate.format.decode_at(buffer, position, position + size, expect)
                else:
                    message = candidate.format.decode_at(buffer, position, position + size)
            except DecodeError:
                failed = True
                continue
            if candidate is self.response and not self._answers(message):
                fallback = fallback or (message, position + size)
                continue
            return message, position + size
        if fallback is None and failed:
            self.errors += 1
        return fallback

    def _answers(self, reply: Message) -> bool:
        if self.awaiting is None or not self.address:
            return True
        asked, answered = self.awaiting.to_fields().get(self.address), reply.to_fields().get(self.address)
        return asked is None or answered is None or asked == answered
