"""Splitting a byte stream into frames, for every protocol the spec language describes.

A candidate frame starts at a header. Before it is accepted it must be plausible: a known command whose content
size fits the length byte, frame-level values (an address) within their declared range; then its checksum must
verify. Whenever a candidate fails, scanning resumes one byte after its header, so a stray header or a truncated
frame never swallows the intact frame that follows it. A candidate still waiting for bytes never hides a complete,
valid frame that starts inside it: that frame is delivered, and the candidate counted as garbage.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

from serialspec.runtime.errors import DecodeError
from serialspec.runtime.message import Message

# frame-level values with a declared range: (offset, size, byte order, signed, low, high, also allowed or None)
ValueRanges = tuple[tuple[int, int, Literal["little", "big"], bool, int, int, int | None], ...]


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
    # decode_at(buffer, start, stop): the frame buffer[start:stop], whose header and length byte the parser has
    # checked: verifies the checksum and decodes; raises DecodeError (ChecksumError) for a corrupt frame.
    decode_at: Callable[[bytes, int, int], Message]
    value_ranges: ValueRanges = ()  # a candidate with a value outside its range is no frame


class _Candidate:
    """A FrameFormat as the scanning loop reads it: the size of every plausible frame, by command and length byte."""

    __slots__ = ("header", "prefix", "command_offset", "length_offset", "frame_sizes", "decode", "ranges", "byte")

    def __init__(self, frame_format: FrameFormat) -> None:
        self.header = frame_format.header
        # bytes needed before the command code and the length byte can be read
        self.prefix = (
            max(
                frame_format.length_offset,
                frame_format.command_offset or 0,
                *(offset + size - 1 for offset, size, *_ in frame_format.value_ranges),
            )
            + 1
        )
        # The usual case, one unsigned byte (an address 0..253 with broadcast 254), is checked inline by the scanning
        # loop as (offset, low, high, also); any other ranges go through _in_range.
        self.byte = (-1, 0, 0, -1)
        self.ranges = frame_format.value_ranges
        if len(self.ranges) == 1 and self.ranges[0][1] == 1 and not self.ranges[0][3]:
            offset, _, _, _, lowest, highest, broadcast = self.ranges[0]
            self.byte = (offset, lowest, highest, -1 if broadcast is None else broadcast)
            self.ranges = ()
        self.command_offset = frame_format.command_offset
        self.length_offset = frame_format.length_offset
        self.decode = frame_format.decode_at
        # One lookup per candidate instead of a range check: the length byte has only 256 values, so every
        # (command, length byte) pair whose content size the command allows maps to its frame size.
        self.frame_sizes: dict[int, int] = {}
        for code, (low, high) in frame_format.content_sizes.items():
            for length_byte in range(256):
                content = length_byte - frame_format.length_adds
                if low <= content and (high is None or content <= high):
                    key = length_byte if code is None else code << 8 | length_byte
                    self.frame_sizes[key] = frame_format.overhead + content


class StreamParser:
    """Feed bytes as they arrive; get back the complete messages found so far, in order.

    Corrupt candidates (bad checksum, content that does not decode) are counted in `errors`, never raised.
    """

    def __init__(self, *formats: FrameFormat) -> None:
        if not formats:
            raise ValueError("a stream parser needs at least one frame format")
        self._candidates = tuple(_Candidate(f) for f in formats)
        self._pending = b""
        self._keep = max(len(f.header) for f in formats) - 1  # a tail that could be the start of a header
        self.errors = 0
        self.garbage = 0  # bytes skipped that belonged to no accepted frame

    def feed(self, data: bytes | bytearray | memoryview) -> list[Message]:
        # Work on immutable bytes: decoders slice their `bytes` fields straight out of the buffer.
        buffer = self._pending + data if self._pending else bytes(data)
        end = len(buffer)
        found: list[Message] = []
        append = found.append
        find = buffer.find
        candidates = self._candidates
        single = len(candidates) == 1
        # one frame format (the usual case): its parameters stay in locals for the whole scan
        current = candidates[0]
        header, prefix, command_offset, length_offset = (
            current.header,
            current.prefix,
            current.command_offset,
            current.length_offset,
        )
        frame_sizes, decode, ranges = current.frame_sizes, current.decode, current.ranges
        byte_offset, byte_low, byte_high, byte_also = current.byte
        garbage = errors = start = 0
        while True:
            if single:
                position = find(header, start)
            else:
                position, current = self._next_header(buffer, start)
                header, prefix, command_offset, length_offset = (
                    current.header,
                    current.prefix,
                    current.command_offset,
                    current.length_offset,
                )
                frame_sizes, decode, ranges = current.frame_sizes, current.decode, current.ranges
                byte_offset, byte_low, byte_high, byte_also = current.byte
            if position < 0:
                cut = max(start, end - self._keep)
                garbage += cut - start
                self._pending = buffer[cut:]
                break
            garbage += position - start
            if end - position < prefix:  # plausible so far but incomplete: wait for more bytes
                self._pending = buffer[position:]
                break
            if command_offset is None:
                size = frame_sizes.get(buffer[position + length_offset])
            else:
                size = frame_sizes.get(buffer[position + command_offset] << 8 | buffer[position + length_offset])
            if (
                size is None
                or (
                    byte_offset >= 0
                    and not byte_low <= buffer[position + byte_offset] <= byte_high
                    and buffer[position + byte_offset] != byte_also
                )
                or (ranges and not _in_range(buffer, position, ranges))
            ):
                # implausible (unknown command, a content size it never has, a value out of range): no frame start
                start = position + 1
                garbage += 1
                continue
            stop = position + size
            if stop > end:
                inner = self._complete_frame_after(buffer, position + 1)
                if inner < 0:
                    self._pending = buffer[position:]
                    break
                garbage += inner - position  # a stray header: the complete frame inside it is the real one
                start = inner
                continue
            try:
                append(decode(buffer, position, stop))
            except DecodeError:
                errors += 1
                start = position + 1
                garbage += 1
                continue
            start = stop
        self.garbage += garbage
        self.errors += errors
        return found

    def _complete_frame_after(self, buffer: bytes, start: int) -> int:
        """Where the first complete frame that decodes starts at or after `start`; -1 if there is none."""
        end = len(buffer)
        while True:
            position, candidate = self._next_header(buffer, start)
            if position < 0 or end - position < candidate.prefix:
                return -1
            if candidate.command_offset is None:
                size = candidate.frame_sizes.get(buffer[position + candidate.length_offset])
            else:
                key = buffer[position + candidate.command_offset] << 8 | buffer[position + candidate.length_offset]
                size = candidate.frame_sizes.get(key)
            offset, low, high, also = candidate.byte
            plausible = (
                size is not None
                and (offset < 0 or low <= buffer[position + offset] <= high or buffer[position + offset] == also)
                and (not candidate.ranges or _in_range(buffer, position, candidate.ranges))
            )
            if plausible and size is not None and position + size <= end:
                try:
                    candidate.decode(buffer, position, position + size)
                except DecodeError:
                    pass
                else:
                    return position
            start = position + 1

    def _next_header(self, buffer: bytes, start: int) -> tuple[int, _Candidate]:
        best, best_candidate = -1, self._candidates[0]
        for candidate in self._candidates:
            position = buffer.find(candidate.header, start)
            if position >= 0 and (best < 0 or position < best):
                best, best_candidate = position, candidate
        return best, best_candidate

    def expect(self, cls: type[Message] | None) -> None:
        """The reply class the next frames answer; classic frames have one layout per code, so it changes nothing."""

    def pending(self) -> bytes:
        """Bytes held back, waiting to complete a frame."""
        return self._pending


def _in_range(buffer: bytes, position: int, ranges: ValueRanges) -> bool:
    for offset, size, byte_order, signed, low, high, also in ranges:
        at = position + offset
        value = (
            buffer[at]
            if size == 1 and not signed
            else int.from_bytes(buffer[at : at + size], byte_order, signed=signed)
        )
        if not low <= value <= high and value != also:
            return False
    return True
