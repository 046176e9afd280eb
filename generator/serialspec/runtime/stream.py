"""Splitting a byte stream into frames, for every protocol the spec language describes.

A candidate frame starts at a header. Before it is accepted it must be plausible: a known command whose content
size fits the length byte; then its checksum must verify. Whenever a candidate fails, scanning resumes one byte
after its header, so a stray header or a truncated frame never swallows the intact frame that follows it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from serialspec.runtime.errors import DecodeError
from serialspec.runtime.message import Message


@dataclass(frozen=True)
class FrameFormat:
    """What the stream parser needs of one direction's frame; generated from the spec."""

    header: bytes
    overhead: int  # frame size minus content size
    length_offset: int
    length_adds: int
    command_offset: int | None
    # content size bounds by command code (None: the one codeless command); max None = unbounded
    content_sizes: dict[int | None, tuple[int, int | None]]
    checksum_ok: Callable[[bytes], bool]
    decode: Callable[[bytes], Message]


class StreamParser:
    """Feed bytes as they arrive; get back the complete messages found so far, in order.

    Corrupt candidates (bad checksum, content that does not decode) are counted in `errors`, never raised.
    """

    def __init__(self, *formats: FrameFormat) -> None:
        if not formats:
            raise ValueError("a stream parser needs at least one frame format")
        self._formats = formats
        self._buffer = bytearray()
        self.errors = 0
        self.garbage = 0  # bytes skipped that belonged to no accepted frame
        self._prefix = min(f.overhead for f in formats)

    def feed(self, data: bytes) -> list[Message]:
        buffer = self._buffer
        buffer += data
        found: list[Message] = []
        start = 0
        while True:
            position, frame_format = self._next_header(buffer, start)
            if frame_format is None:
                # keep a tail that could be the start of a header
                keep = max(len(f.header) for f in self._formats) - 1
                cut = max(start, len(buffer) - keep)
                self.garbage += cut - start
                del buffer[:cut]
                return found
            self.garbage += position - start
            size = self._candidate_size(buffer, position, frame_format)
            if size == 0:  # implausible: not a frame start
                start = position + 1
                self.garbage += 1
                continue
            if size < 0:  # plausible but incomplete: wait for more bytes
                del buffer[:position]
                return found
            frame = bytes(buffer[position : position + size])
            if not frame_format.checksum_ok(frame):
                self.errors += 1
                start = position + 1
                self.garbage += 1
                continue
            try:
                found.append(frame_format.decode(frame))
            except DecodeError:
                self.errors += 1
                start = position + 1
                self.garbage += 1
                continue
            start = position + size

    def _next_header(self, buffer: bytearray, start: int) -> tuple[int, FrameFormat | None]:
        best, best_format = -1, None
        for frame_format in self._formats:
            position = buffer.find(frame_format.header, start)
            if position >= 0 and (best < 0 or position < best):
                best, best_format = position, frame_format
        return best, best_format

    @staticmethod
    def _candidate_size(buffer: bytearray, position: int, frame_format: FrameFormat) -> int:
        """Frame size if plausible and complete; -1 if plausible so far but incomplete; 0 if implausible."""
        available = len(buffer) - position
        needed = max(frame_format.length_offset, frame_format.command_offset or 0) + 1
        if available < needed:
            return -1
        code = buffer[position + frame_format.command_offset] if frame_format.command_offset is not None else None
        sizes = frame_format.content_sizes.get(code)
        if sizes is None:
            return 0
        content = buffer[position + frame_format.length_offset] - frame_format.length_adds
        low, high = sizes
        if content < low or (high is not None and content > high):
            return 0
        size = frame_format.overhead + content
        return size if available >= size else -1

    def pending(self) -> bytes:
        """Bytes held back, waiting to complete a frame."""
        return bytes(self._buffer)
