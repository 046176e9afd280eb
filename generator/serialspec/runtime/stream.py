"""Splitting a byte stream into frames, for every protocol the spec language describes.

A candidate frame starts at a header. Before it is accepted it must be plausible: a known command whose content
size fits the length byte, frame-level values (an address) within their declared range; then its checksum must
verify. Whenever a candidate fails, scanning resumes one byte after its header, so a stray header or a truncated
frame never swallows the intact frame that follows it.

One rule decides between candidates that overlap, whatever the reads: the frame that completes first wins (of two
ending on the same byte, the one that starts first), as a scan fed one byte at a time finds it. A candidate, complete
or still waiting for bytes, never hides a valid frame that starts inside it and ends before it: that frame is
delivered, and the candidate counted as garbage (a false candidate whose 8-bit sum matches by chance cannot swallow
the real frame inside it). So any split of a stream into reads gives the same frames, errors and skipped bytes.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from itertools import accumulate, compress, islice

from serialspec.runtime.errors import DecodeError
from serialspec.runtime.message import TYPE_CHECKING, Message, build

# frame-level values with a declared range: (offset, size, byte order, signed, low, high, also allowed or None)
if TYPE_CHECKING:
    from typing import Literal

    ValueRanges = tuple[tuple[int, int, Literal["little", "big"], bool, int, int, int | None], ...]
else:  # the same without importing typing for Literal
    ValueRanges = tuple[tuple[int, int, str, bool, int, int, int | None], ...]


class FrameFormat:
    """What the stream parser needs of one direction's frame; generated from the spec. Frozen (a plain class: the
    dataclass it was made importing dataclasses cost a generated package's import more than the rest of it)."""

    __slots__ = (
        "header",
        "overhead",
        "length_offset",
        "length_adds",
        "command_offset",
        "content_sizes",
        "decode_at",
        "fixed",
        "value_ranges",
        "summed",
        "runs",
        "units",
    )

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
    # Frames of one size decoded whole, by size key: (frame size, decoder(buffer, start) -> message, or None when
    # its checksum fails). The parser uses them before decode_at; frames not here take decode_at.
    fixed: dict[int, tuple[int, Callable[[bytes, int], Message | None]]]
    value_ranges: ValueRanges  # a candidate with a value outside its range is no frame
    # Where the checksum is the frame's last byte, the 8-bit sum of its bytes from `summed[0]` on (inverted when
    # summed[1]): the frames decoded in runs, by size key: runs[key](frames) gives the messages of frames of that key
    # laid end to end without their headers, each checked already (their message is their content as unpacked).
    summed: tuple[int, bool] | None
    runs: dict[int, Callable[[bytes], Iterable[Message]]]
    # The same frames one at a time, by size key: (unpack_from of the bytes after the header giving the values of its
    # message, its class); the parser checks the sum and builds the message itself, with no call per frame.
    units: dict[int, tuple[Callable[[bytes], tuple[object, ...]], type[Message]]]

    def __init__(
        self,
        header: bytes,
        overhead: int,
        length_offset: int,
        length_adds: int,
        command_offset: int | None,
        content_sizes: dict[int | None, tuple[int, int | None]],
        decode_at: Callable[[bytes, int, int], Message],
        fixed: dict[int, tuple[int, Callable[[bytes, int], Message | None]]] | None = None,
        value_ranges: ValueRanges = (),
        summed: tuple[int, bool] | None = None,
        runs: dict[int, Callable[[bytes], Iterable[Message]]] | None = None,
        units: dict[int, tuple[Callable[[bytes], tuple[object, ...]], type[Message]]] | None = None,
    ) -> None:
        values: tuple[object, ...] = (header, overhead, length_offset, length_adds, command_offset, content_sizes)
        values += (decode_at, {} if fixed is None else fixed, value_ranges, summed, {} if runs is None else runs)
        values += ({} if units is None else units,)
        for name, value in zip(self.__slots__, values, strict=True):
            object.__setattr__(self, name, value)

    def __setattr__(self, name: str, value: object) -> None:
        raise AttributeError(f"FrameFormat is frozen: cannot assign to {name!r}")

    def __repr__(self) -> str:
        values = ", ".join(f"{name}={getattr(self, name)!r}" for name in self.__slots__)
        return f"FrameFormat({values})"


# A frame whose sum _lean checks and whose message it builds itself: the unpack of its values after the header, its
# class, the slice of the bytes after the header that its sum adds up, and where its check byte is there.
_Unit = tuple[Callable[[bytes], tuple[object, ...]], type[Message], slice, int]
# a key's frames as _lean reads them (see _Candidate.lean)
_LeanEntry = tuple[int, int, Callable[[bytes, int], "Message | None"] | None, _Unit | None]
# what _sieve checks a key's frames with (see _Candidate.sieves)
_Sieve = tuple[bytes, int, int, Callable[[bytes], Iterable[Message]], tuple[tuple[int, bytes], ...]]


class _Candidate:
    """A FrameFormat as the scanning loop reads it: the size of every plausible frame, by command and length byte."""

    __slots__ = (
        "frame_format",
        "header",
        "prefix",
        "command_offset",
        "length_offset",
        "frame_sizes",
        "decode",
        "fixed",
        "splittable",
        "ranges",
        "pieces",
        "shifts",
        "byte_at",
        "value_at",
        "command_at",
        "entries",
        "allowed",
        "wide",
        "runs",
        "key_bytes",
        "sum_from",
        "sum_table",
        "smallest",
        "tails",
        "leading",
        "lean",
        "sieves",
        "short_tables",
        "lane_sums",
    )

    def __init__(self, frame_format: FrameFormat) -> None:
        self.frame_format = frame_format  # kept alive: the cache below is keyed by its id
        header = self.header = frame_format.header
        # bytes needed before the command code and the length byte can be read
        self.prefix = (
            max(
                frame_format.length_offset,
                frame_format.command_offset or 0,
                *(offset + size - 1 for offset, size, *_ in frame_format.value_ranges),
            )
            + 1
        )
        self.ranges = frame_format.value_ranges
        self.command_offset = frame_format.command_offset
        self.length_offset = frame_format.length_offset
        self.decode = frame_format.decode_at
        self.fixed = {key: decode for key, (_, decode) in frame_format.fixed.items()}
        # One lookup per candidate instead of a range check: the length byte has only 256 values, so every
        # (command, length byte) pair whose content size the command allows maps to its frame size.
        self.frame_sizes: dict[int, int] = {}
        for code, (low, high) in frame_format.content_sizes.items():
            for length_byte in range(256):
                content = length_byte - frame_format.length_adds
                if low <= content and (high is None or content <= high):
                    key = length_byte if code is None else code << 8 | length_byte
                    self.frame_sizes[key] = frame_format.overhead + content
        # The batch scan splits the buffer at every header and reads the command code and length byte in the piece
        # after it, so they must come after the header. A header that can overlap itself (FEETECH's FF FF: FF FF FF
        # holds two) hides the occurrences that start inside one split at: `shifts` are where those can start, after
        # an occurrence's first byte; the batch scan looks there whenever the candidate at the split is not a frame.
        width = len(header)
        after = min(frame_format.length_offset, frame_format.command_offset or width)
        self.splittable = bool(header) and after >= width
        self.shifts = tuple(k for k in range(1, width) if header[k:] == header[: width - k])
        # a piece (the bytes after a header) starting with one of these holds a header overlapping the one before it
        self.tails = tuple(header[width - k :] for k in self.shifts)
        self.smallest = min(self.frame_sizes.values(), default=1 << 30)  # the smallest plausible frame
        # Every plausible frame as the batch scan reads it: size key -> (frame size, its bytes after the header, the
        # decoder of the frames decoded whole, or None for decode_at).
        self.pieces = {key: (size, size - width, self.fixed.get(key)) for key, size in self.frame_sizes.items()}
        # the same for the walk (_walk): size key -> (frame size, decoder of the frames decoded whole, or None)
        self.entries = {key: (size, self.fixed.get(key)) for key, size in self.frame_sizes.items()}
        self.command_at = -1 if frame_format.command_offset is None else frame_format.command_offset
        # The usual value range (one unsigned byte after the header: an address) as a table of 256 yes/no bytes
        # read in the piece; other ranges (`wide`) go through plausible().
        single = [r for r in self.ranges if r[1] == 1 and not r[3] and r[0] >= width]
        self.wide = len(single) != len(self.ranges) or len(single) > 1
        self.byte_at, self.value_at, self.allowed = -1, -1, None
        if len(single) == 1:
            offset, _, _, _, low, high, also = single[0]
            self.byte_at, self.value_at = offset - width, offset
            self.allowed = bytes(low <= value <= high or value == also for value in range(256))
        # Runs of frames of one size key, checked together (see _run): where each key byte is in the piece, the
        # first byte the checksum sums there, and a table taking a sum of the piece's bytes to the check byte.
        summed = frame_format.summed
        self.runs = frame_format.runs if summed is not None and self.splittable and not self.ranges else {}
        self.key_bytes = tuple(
            (offset - width, shift)
            for offset, shift in ((frame_format.command_offset, 8), (frame_format.length_offset, 0))
            if offset is not None
        )
        # Where the key's bytes are the first bytes after the header (Fashion Star: command code, length byte) and
        # the header cannot overlap itself, _lean reads the key as those bytes: `lean` maps them to the frame's size
        # and decoder (None: decode_at), for the candidates the scan decides on the spot.
        key_at = {frame_format.length_offset: 0}  # each key byte's offset: its shift in the size key
        if frame_format.command_offset is not None:
            key_at[frame_format.command_offset] = 8
        leading = sorted(key_at) == list(range(width, width + len(key_at)))
        self.leading = len(key_at) if leading and self.splittable and not self.shifts and not self.ranges else 0
        # (size, bytes after the header, decoder or None, _Unit or None)
        self.lean: dict[bytes, _LeanEntry] = {}
        # The sieve (see _sieve), for the keys whose frames are checked in runs: their bytes -> (those bytes, frame
        # size, bytes after the header, run decoder, and for each key byte its offset in the piece and a translate
        # table taking its value to 1 and any other to 0).
        self.sieves: dict[bytes, _Sieve] = {}
        if self.leading:
            for key, size in self.frame_sizes.items():
                first = bytes(key >> key_at[offset] & 0xFF for offset in sorted(key_at))
                unit = frame_format.units.get(key) if self.runs else None
                rest = size - width
                sums = slice(max(0, frame_format.summed[0] - width) if frame_format.summed else 0, rest - 1)
                self.lean[first] = (size, rest, self.fixed.get(key), None if unit is None else (*unit, sums, rest - 1))
                run = self.runs.get(key)
                if run is not None and self.leading < size - width <= 257:  # no 16-bit lane of _sieve's sums overflows
                    tables = tuple((at, bytes(value == byte for value in range(256))) for at, byte in enumerate(first))
                    self.sieves[first] = (first, size, size - width, run, tables)
        # by frame size after the header: a translate table from a piece's first bytes' length to 1 when shorter
        self.short_tables = {rest: bytes(n < rest for n in range(256)) for _, _, rest, *_ in self.sieves.values()}
        self.sum_from, self.sum_table = 0, b""
        if summed is not None:
            covered_from, invert = summed
            constant = sum(header[covered_from:])
            self.sum_from = max(0, covered_from - width)
            self.sum_table = bytes((constant + value) & 0xFF ^ (0xFF if invert else 0) for value in range(256))
        # by count of bytes summed: 1 + L + L^2 + ..., L a 16-bit lane
        self.lane_sums = {
            rest - 1 - self.sum_from: sum(1 << 16 * i for i in range(rest - 1 - self.sum_from))
            for _, _, rest, *_ in self.sieves.values()
        }

    def plausible(self, buffer: bytes, position: int) -> bool:
        """Every frame-level value with a declared range holds a value in it (or the one also allowed)."""
        for offset, size, byte_order, signed, low, high, also in self.ranges:
            at = position + offset
            value = (
                buffer[at]
                if size == 1 and not signed
                else int.from_bytes(buffer[at : at + size], byte_order, signed=signed)
            )
            if not low <= value <= high and value != also:
                return False
        return True

    def take(self, key: int, buffer: bytes, start: int, stop: int) -> Message | None:
        """The frame buffer[start:stop] of size key `key` decoded, or None when it fails its checks."""
        whole = self.fixed.get(key)
        if whole is not None:
            return whole(buffer, start)
        try:
            return self.decode(buffer, start, stop)
        except DecodeError:
            return None


# Candidates are immutable and built once per frame format (a size table is thousands of entries): a parser is
# created on every reset and reopen of a bus, so creating one must cost next to nothing.
_CANDIDATES: dict[int, _Candidate] = {}

# Runs (see StreamParser._run). A run costs a few microseconds whatever its length, so one shorter than
# _SHORTEST_RUN frames does not pay: after one, or a run refused, no run is tried for the next `backoff` pieces,
# which doubles each time (up to _LONGEST_RUN) and is back to _SHORTEST_RUN after a run that paid. Where frames of
# different keys alternate, the stream takes the usual path, at most one try in _LONGEST_RUN pieces lost. A run takes
# _FIRST_RUN pieces at most at first, and twice as many after each run that took at least half of them.
# Buffers of _SPLIT_FROM bytes or more take the batch scan (StreamParser._split), shorter ones the walk (_walk).
_SPLIT_FROM = 512
_RUNS_AGAIN = 8
_SHORTEST_RUN = 24
_FIRST_RUN = 32
_LONGEST_RUN = 1024
# The sieve (see _sieve) decides the reads of more than _SIEVE_FROM headers (its fixed cost, a few dozen calls in C,
# is about that many frames through the loop); after a read it is not for (frames of other keys in it, ...), the
# next _SIEVE_AGAIN reads take the plain loop.
_SIEVE_FROM = 64
_SIEVE_AGAIN = 8
_ZERO_ONLY = bytes((1, *bytes(255)))  # a translate table: 0 -> 1, any other byte -> 0


def _sieve(
    current: _Candidate, buffer: bytes, pieces: list[bytes]
) -> tuple[list[Message], int, int, int] | tuple[()] | None:
    """Every piece of a read (the bytes after each header) decided at once, in C, as `_lean` decides them one by one,
    where the read holds frames of one size key (that of one of its first pieces) and cut frame starts: (the
    messages, corrupt candidates, bytes taken, where the bytes held back begin); None where it holds anything else
    (a frame of another key, ...), and () where this read has what a few do (a candidate whose bytes are not all
    here), which `_lean`'s loop decides.

    A piece holding a whole frame of the key is a candidate as it is; a shorter one (a cut frame start, or bytes
    that name no frame) is one with the bytes after it, the next header's included, as the byte-by-byte scan reads
    it: no frame from the next header can end before it (it would be decided first otherwise: None). Each key byte
    is a column of the candidates laid end to end, checked against its value; each 8-bit sum is read from one big
    integer (see below); the candidates of the key whose checksum holds are the read's frames, their messages
    unpacked at once by the run decoder. A last piece too short for its frame waits for its bytes."""
    leading = current.leading
    end = len(buffer)
    for piece in islice(pieces, 1, 4):
        entry = current.sieves.get(piece[:leading])
        if entry is not None:
            break
    else:
        return None
    first, size, rest, run, tables = entry
    header = current.header
    width = len(header)
    last = pieces[-1]
    held = len(last) < rest  # the last candidate waits for its bytes
    if held and len(last) >= leading and last[:leading] != first:
        return ()  # the last piece may be whole (another key) or no frame
    body = pieces[1:-1] if held else pieces[1:]
    count = len(body)
    framed = [piece[:rest] for piece in body]
    short = bytes(map(len, framed)).translate(current.short_tables[rest])  # 1 where a piece holds no whole frame
    at = short.find(1)
    after: list[int] = []  # where each piece begins, once a piece is short
    if at >= 0:
        shortest = (
            rest - current.smallest
        )  # a frame from the next header may end before a candidate from a shorter piece
        if shortest > 0 and min(len(piece) for piece in body if len(piece) < rest) < shortest:
            return None
        after = list(accumulate(map(width.__add__, map(len, pieces))))
        while (
            at >= 0
        ):  # the candidate's bytes run on into the next header and piece, as the byte-by-byte scan reads them
            framed[at] = buffer[after[at] : after[at] + rest]
            at = short.find(1, at + 1)
    frames = b"".join(framed)
    if len(frames) != count * rest:
        return ()  # a cut frame start's candidate needs bytes not here yet
    keyed = -1  # a byte per candidate, as an integer: 1 where its key is the sieve's
    for at, table in tables:  # each key byte, a column of the candidates
        keyed &= int.from_bytes(frames[at::rest].translate(table), "little")
    # Each candidate's 8-bit sum: its bytes spread to 16-bit lanes of one big integer, times 1 + L + L^2 + ... (L
    # a lane), so that the lane of its last summed byte adds up its summed bytes (no lane overflows into the next).
    lanes = bytearray(2 * len(frames))
    lanes[::2] = frames
    summed = rest - 1 - current.sum_from
    sums = (int.from_bytes(lanes, "little") * current.lane_sums[summed]).to_bytes(2 * (len(frames) + summed), "little")
    sums = sums[2 * (rest - 2) :: 2 * rest][:count].translate(current.sum_table)
    differ = int.from_bytes(sums, "little") ^ int.from_bytes(frames[rest - 1 :: rest], "little")
    checked = int.from_bytes(differ.to_bytes(count, "little").translate(_ZERO_ONLY), "little")
    passed = keyed & checked
    ones = int.from_bytes(b"\x01" * count, "little")
    other = ones & ~keyed
    if other:  # candidates of another key: no frame, unless the key is another frame's
        flags = other.to_bytes(count, "little")
        at = flags.find(1)
        while at >= 0:
            if framed[at][:leading] in current.lean:
                return None
            at = flags.find(1, at + 1)
    corrupt = keyed & ~checked
    stop = -1  # where the last frame taken ends, once a cut frame start is taken (-1: none is)
    taken = passed & int.from_bytes(short, "little")
    if taken:
        # A cut frame start whose checksum holds (one in 256): a frame, which takes the bytes of the pieces whose
        # header lies inside it (their own frames and errors do not count), as the byte-by-byte scan does.
        good_flags, corrupt_flags = bytearray(passed.to_bytes(count, "little")), corrupt.to_bytes(count, "little")
        errors = corrupt.bit_count()
        taken_flags = taken.to_bytes(count, "little")
        at = taken_flags.find(1)
        while at >= 0:
            if good_flags[at]:  # (not inside a frame taken before it)
                stop = after[at] - width + size
                inside = at + 1
                while inside < count and after[inside] - width < stop:
                    good_flags[inside] = 0
                    errors -= corrupt_flags[inside]
                    inside += 1
                if held and inside == count and after[count] - width < stop:  # the last piece too: no candidate
                    held = False
            at = taken_flags.find(1, at + 1)
        good = bytes(good_flags)
    else:
        good = passed.to_bytes(count, "little")
        errors = corrupt.bit_count()
    messages = list(compress(run(frames), good))
    if held:
        cut = end - width - len(last)
    else:  # keep a tail that could begin a header, unless the last frame taken ends after it begins
        cut = max(end - width + 1, stop)
        if good[-1]:
            cut = max(cut, end - len(last) + rest)
    return messages, errors, len(messages) * size, cut


def _candidate(frame_format: FrameFormat) -> _Candidate:
    found = _CANDIDATES.get(id(frame_format))
    if found is None or found.frame_format is not frame_format:
        found = _CANDIDATES[id(frame_format)] = _Candidate(frame_format)
    return found


class StreamParser:
    """Feed bytes as they arrive; get back the complete messages found so far, in order.

    Corrupt candidates (bad checksum, content that does not decode) are counted in `errors`, never raised.
    """

    def __init__(self, *formats: FrameFormat) -> None:
        if not formats:
            raise ValueError("a stream parser needs at least one frame format")
        self._candidates = tuple(_candidate(f) for f in formats)
        self._single = self._candidates[0] if len(self._candidates) == 1 else None
        self._pending = b""
        self._keep = max(len(f.header) for f in formats) - 1  # a tail that could be the start of a header
        self._header = formats[0].header  # (of the one format, where `_need` is used)
        self._need = 0  # the size of the candidate held back while feed() waits for its bytes (0: none)
        self._smallest = min(c.smallest for c in self._candidates)
        # runs: pieces the next one takes at most, pieces to wait before it is tried, the wait after the next failure
        self._block, self._wait, self._backoff = _FIRST_RUN, 0, _SHORTEST_RUN
        # whether the last batch scan took half of its frames or more in runs; frames runs took in it; long reads
        # the lean scan took since (see feed)
        self._runs_pay, self._ran, self._lean_reads = True, 0, 0
        self._sieve_wait = 0  # reads the sieve skips (see _lean)
        self.errors = 0
        self.garbage = 0  # bytes skipped that belonged to no accepted frame

    def feed(self, data: bytes | bytearray | memoryview) -> list[Message]:
        # Work on immutable bytes: decoders slice their `bytes` fields straight out of the buffer.
        pending = self._pending
        if pending:
            buffer = pending + data
            need = self._need
            if need:  # a candidate held back, its bytes not all here: nothing can change before they are
                # unless a header comes in the new bytes (a frame inside the candidate may complete first); the
                # candidate starts the bytes held, so a new header starts after its first byte
                if len(buffer) < need and buffer.find(self._header, len(pending) - self._keep) < 0:
                    self._pending = buffer
                    return []
                self._need = 0
        else:
            buffer = data if data.__class__ is bytes else bytes(data)
        single = self._single
        if single is None:
            return self._scan(buffer)
        end = len(buffer)
        header = single.header
        first = buffer.find(header)
        if first:
            if first < 0 and end < 64:  # a short read of garbage (or of a header's first bytes)
                cut = max(0, end - self._keep)
                self.garbage += cut
                self._pending = buffer[cut:]
                return []
        elif buffer.find(header, 1) < 0:
            # One candidate, from the first byte on (no header after it: no frame inside it), as small reads bring
            # it: it waits for its bytes without a scan, and a transaction's read of one whole frame is decoded
            # without one. A frame that fails goes through the scan, which counts it and resynchronises.
            if end < single.prefix:
                self._pending, self._need = buffer, single.prefix
                return []
            key = buffer[single.length_offset]
            if single.command_at >= 0:
                key |= buffer[single.command_at] << 8
            entry = single.entries.get(key)
            if entry is not None and (not single.ranges or single.plausible(buffer, 0)):
                size = entry[0]
                if end < size:
                    self._pending, self._need = buffer, size
                    return []
                if end == size:
                    message = single.take(key, buffer, 0, end)
                    if message is not None:
                        self._pending = b""
                        return [message]
        if single.splittable and end >= _SPLIT_FROM and (not single.leading or self._runs_pay or self._retry_runs()):
            self._ran = 0
            found = self._split(buffer, single)
            # where runs took less than half of the frames, the lean scan costs less: it takes the long reads too
            # (the batch scan, tried again every _RUNS_AGAIN long reads, tells when runs pay again)
            self._runs_pay = 2 * self._ran >= len(found)
        elif single.leading:
            found = self._lean(buffer, single)
        else:
            found = self._walk(buffer, single)
        held = self._pending
        if held.startswith(single.header) and held.find(single.header, 1) < 0:
            # the candidate held back, with no header after its first byte: feed() waits for its bytes (or for the
            # bytes that say how many there are)
            if len(held) < single.prefix:
                self._need = single.prefix
            else:
                key = held[single.length_offset]
                if single.command_offset is not None:
                    key |= held[single.command_offset] << 8
                self._need = single.frame_sizes.get(key, 0)
        return found

    def _walk(self, buffer: bytes, current: _Candidate) -> list[Message]:
        """The byte-by-byte scan (`_scan`) of one frame format, with `_decide`'s usual outcomes in line: a candidate
        whose frame is all here, with no header where a frame ending before it could start, is taken or refused on
        the spot (one search, one lookup, one call); an implausible one is skipped. Only a candidate that must wait
        for bytes or holds a header that may start an earlier frame goes through `_decide`. The search for the next
        header, from one byte after this one, also tells whether one lies inside this candidate. A short read (a few
        frames) costs little to set up, where the batch scan (`_split`) pays off on long ones."""
        header = current.header
        find = buffer.find
        end = len(buffer)
        entries = current.entries
        length_at, command_at, prefix = current.length_offset, current.command_at, current.prefix
        decode_at = current.decode
        allowed, value_at, wide = current.allowed, current.value_at, current.wide
        reach = len(header) - 1 - current.smallest  # a frame ending before `stop` starts before `stop + reach`
        found: list[Message] = []
        append = found.append
        start = taken = errors = 0  # start: where the scan would look next once no header is left
        position = find(header)
        while position >= 0:
            after = find(header, position + 1)
            if end - position >= prefix:
                key = buffer[position + length_at]
                if command_at >= 0:
                    key |= buffer[position + command_at] << 8
                entry = entries.get(key)
                if (
                    entry is None
                    or (allowed is not None and not allowed[buffer[position + value_at]])
                    or (wide and not current.plausible(buffer, position))
                ):  # no frame: look again one byte on
                    position = after
                    continue
                size, decode = entry
                stop = position + size
                if stop <= end and (after < 0 or after >= stop + reach):
                    if decode is not None:
                        message = decode(buffer, position)
                    else:
                        try:
                            message = decode_at(buffer, position, stop)
                        except DecodeError:
                            message = None
                    if message is None:  # corrupt: look again one byte on
                        errors += 1
                        position = after
                        continue
                    append(message)
                    taken += size
                    start = stop
                    position = after if after >= stop or after < 0 else find(header, stop)
                    continue
                if after < 0 and stop > end:  # the last candidate, not all here: wait for its bytes
                    cut = position
                    break
            elif after < 0:  # the last candidate, too short to be sized: wait for its bytes
                cut = position
                break
            decided = self._decide(buffer, position, current)
            if decided is None:  # incomplete, and no frame completes inside it: wait for more bytes
                cut = position
                break
            message, where, stop = decided
            if message is not None:  # this candidate, or a frame inside it that completes first
                append(message)
                taken += stop - where
                start = stop
                position = find(header, stop)
            else:
                errors += stop  # 1: a corrupt frame; 0: no frame
                position = after
        else:  # keep a tail that could begin a header
            cut = max(start, end - len(header) + 1)
        self._pending = buffer[cut:]
        self.garbage += cut - taken
        self.errors += errors
        return found

    def _retry_runs(self) -> bool:
        """Whether this long read tries the batch scan again (every _RUNS_AGAIN-th since runs stopped paying)."""
        self._lean_reads += 1
        if self._lean_reads < _RUNS_AGAIN:
            return False
        self._lean_reads = 0
        return True

    def _lean(self, buffer: bytes, current: _Candidate) -> list[Message]:
        """The byte-by-byte scan (`_scan`) of a format whose header cannot overlap itself and whose size key is the
        bytes right after it, for a read of a few frames: split at every header, the usual piece (the bytes after a
        header) begins with a whole frame: one slice and one lookup find its size and decoder, and its length says
        no header starts inside it (no frame can complete before it), so it is taken or refused on the spot. A
        piece whose key bytes name no frame is no frame. Every other candidate goes through `_decide`.

        Where the format's frames are checked in runs, `_sieve` first tries to decide every piece at once."""
        header = current.header
        width = len(header)
        pieces = buffer.split(header)
        if len(pieces) > _SIEVE_FROM and current.sieves:
            if self._sieve_wait:
                self._sieve_wait -= 1
            else:
                sieved = _sieve(current, buffer, pieces)
                if sieved:
                    messages, errors, taken, cut = sieved
                    self._pending = buffer[cut:]
                    self.garbage += cut - taken
                    self.errors += errors
                    return messages
                if sieved is None:  # a read it is not for: the loop below for a while
                    self._sieve_wait = _SIEVE_AGAIN
        lean, leading = current.lean, current.leading
        sum_table = current.sum_table
        decode_at = current.decode
        smallest, end = self._smallest, len(buffer)
        found: list[Message] = []
        append = found.append
        position = len(pieces[0])  # of the header before the piece
        start = taken = errors = 0  # start: where the scan would look next (the end of the last frame taken)
        for piece in islice(pieces, 1, None):
            if position >= start:
                entry = lean.get(piece[:leading])
                after = len(piece)  # bytes before the next header (or the end)
                if entry is not None:
                    size, rest, decode, unit = entry
                    if unit is not None and rest <= after:  # the usual frame: its sum checked, its message built
                        unpack, cls, summed, check = unit
                        if sum_table[sum(piece[summed]) & 0xFF] == piece[check]:
                            append(build(cls, unpack(piece)))
                            taken += size
                            start = position + size
                        else:  # corrupt: look again at the next header
                            errors += 1
                        position += width + after
                        continue
                    # the whole frame, and no header inside it; or a header inside it, too late for a frame from
                    # there to complete first (a cut frame start: the frame that follows it is no inner frame)
                    if rest <= after or (after + smallest >= rest and position + size <= end):
                        if decode is not None:
                            message = decode(buffer, position)
                        else:
                            try:
                                message = decode_at(buffer, position, position + size)
                            except DecodeError:
                                message = None
                        if message is None:  # corrupt: look again at the next header
                            errors += 1
                        else:
                            append(message)
                            taken += size
                            start = position + size
                        position += width + after
                        continue
                    if position + width + after == end:  # the last candidate, not all here: wait for its bytes
                        cut = position
                        break
                elif after >= leading:  # its key bytes name no frame
                    position += width + after
                    continue
                elif position + width + after == end:  # the last candidate, its key not all here: wait for it
                    cut = position
                    break
                decided = self._decide(buffer, position, current)
                if decided is None:  # incomplete, and no frame completes inside it: wait for more bytes
                    cut = position
                    break
                message, where, stop = decided
                if message is not None:  # this candidate, or a frame inside it that completes first
                    append(message)
                    taken += stop - where
                    start = stop
                else:
                    errors += stop  # 1: a corrupt frame; 0: no frame
            position += width + len(piece)
        else:  # keep a tail that could begin a header
            cut = max(start, end - width + 1)
        self._pending = buffer[cut:]
        self.garbage += cut - taken
        self.errors += errors
        return found

    def _split(self, buffer: bytes, current: _Candidate) -> list[Message]:
        """The batch scan of one frame format: split the buffer at every header (one pass in C) and take the pieces
        in turn, which saves a search and most bookkeeping per frame. It accepts, rejects, counts and holds back
        exactly what the byte-by-byte scan (`_scan`) would: a candidate that fails resumes at the next header (one
        that overlaps its own header included), an accepted frame skips any header inside it.

        The usual piece holds one plausible frame, then perhaps garbage: that takes one lookup and one call (no
        header starts inside that frame, so no frame can complete before it). Anything else (a frame cut by the next
        header, a value out of range, a corrupt frame, headers overlapping one another, the end of the buffer) takes
        the general path below it, which decides each candidate as the byte-by-byte scan does (`_decide`).
        """
        header = current.header
        width = len(header)
        pieces = buffer.split(header)
        end = len(buffer)
        whole = current.pieces
        decode_at = current.decode
        length_at = current.length_offset - width  # the key's bytes in the piece after the header
        command_at = -1 if current.command_offset is None else current.command_offset - width
        byte_at, allowed = current.byte_at, current.allowed
        wide = current.wide
        shifts, tails = current.shifts, current.tails
        found: list[Message] = []
        append = found.append
        position = len(pieces[0])  # of the header before the piece
        start = 0  # where the byte-by-byte scan would look for the next header
        taken = errors = 0  # bytes in accepted frames; corrupt candidates
        cut = -1  # where the bytes held back begin, once a candidate must wait for more
        runs = current.runs
        last = len(pieces) - 1  # the piece the buffer ends with: never in a run (its frame may be cut)
        block, retry = self._block, 1 + self._wait  # pieces the next run takes at most; none tried before `retry`
        walk = enumerate(islice(pieces, 1, None), 1)
        for index, piece in walk:
            if position >= start:
                try:  # a piece too short for the key: the general path decides
                    key = piece[length_at] if command_at < 0 else piece[command_at] << 8 | piece[length_at]
                except IndexError:
                    key = -1
                entry = whole.get(key)
                if entry is not None:
                    size, rest, decode = entry
                    run = runs.get(key) if runs and index >= retry and last - index >= _SHORTEST_RUN else None
                    if run is not None:  # this frame and the ones after it with the same key, checked together
                        count, frames = self._run(current, pieces, index, min(last, index + block), key, rest)
                        if count >= _SHORTEST_RUN:
                            self._backoff = _SHORTEST_RUN
                            if count > block // 2:
                                block = self._block = min(2 * block, _LONGEST_RUN)
                        else:  # too short to pay, or refused: the usual path for a while
                            retry = index + max(count, 1) + self._backoff
                            self._backoff = min(2 * self._backoff, _LONGEST_RUN)
                            block = self._block = _FIRST_RUN
                        if count > 1:
                            self._ran += count
                            found.extend(run(frames))
                            taken += count * size
                            # the header of the run's last frame, its end, and the header after it
                            position += count * width + sum(map(len, pieces[index : index + count - 1])) - width
                            start = position + size
                            position += width + len(pieces[index + count - 1])
                            next(islice(walk, count - 1, count - 1), None)  # the pieces taken
                            continue
                    after = len(piece)  # bytes between this header and the next one (or the end)
                    # the frame ends before the next header (so the bytes its values are read from are there too)
                    if (
                        rest <= after
                        and (allowed is None or allowed[piece[byte_at]])
                        and (not wide or current.plausible(buffer, position))
                        and (not tails or not piece.startswith(tails))  # no header overlapping it: none inside
                    ):
                        if decode is not None:
                            message = decode(buffer, position)
                        else:
                            try:
                                message = decode_at(buffer, position, position + size)
                            except DecodeError:
                                message = None
                        if message is not None:  # the usual frame
                            append(message)
                            taken += size
                            start = position + size
                            position += width + after
                            continue
                # the general path: this candidate, then the headers overlapping its header
                ats = (position, *(position + k for k in shifts)) if shifts else (position,)
            elif shifts and position + width > start:  # a header overlapping this one may start after the frame
                ats = tuple(position + k for k in shifts)
            else:  # a header inside an accepted frame
                position += width + len(piece)
                continue
            for at in ats:
                if at < start or (at != position and not buffer.startswith(header, at)):
                    continue
                decided = self._decide(buffer, at, current)
                if decided is None:  # incomplete, and no frame completes inside it: wait for more bytes
                    cut = at
                    break
                message, where, stop = decided
                if message is not None:  # this candidate, or a frame inside it that completes first
                    append(message)
                    taken += stop - where
                    start = stop
                else:
                    errors += stop  # 1: a corrupt frame; 0: no frame
                    start = at + 1
            if cut >= 0:
                break
            position += width + len(piece)
        else:  # every header taken: keep a tail that could begin one
            cut = max(start, end - width + 1)
        self._pending = buffer[cut:]
        self.garbage += cut - taken
        self.errors += errors
        self._wait = max(0, retry - len(pieces))  # carried to the next read's pieces
        return found

    @staticmethod
    def _run(current: _Candidate, pieces: list[bytes], first: int, stop: int, key: int, rest: int) -> tuple[int, bytes]:
        """How many of pieces[first:stop] (each after a header), from the first on, begin with a frame of size key
        `key` whose checksum holds; and those frames end to end, headers left out, for the run decoder.

        The checks are made on all the frames at once, in C: each key byte is a column of the joined frames (a
        strided slice) matched against its value; each frame's checksum, an 8-bit sum of its bytes, is read from
        16-bit lanes of one big integer, one per frame, that add up the frame's bytes (no lane can overflow into the
        next): a column of the frames' bytes in every other byte of a big integer, one column after
        another added up.
        """
        block = pieces[first:stop]
        count = len(block)
        frames = b"".join([piece[:rest] for piece in block])
        if len(frames) != count * rest:  # a piece too short for its frame: the run ends before it
            count = next(i for i, piece in enumerate(block) if len(piece) < rest)
            frames = frames[: count * rest]
        for at, shift in current.key_bytes:
            column = frames[at::rest]
            count = min(count, len(column) - len(column.lstrip(bytes((key >> shift & 0xFF,)))))
        for tail in current.tails:  # a header overlapping a frame's own one may start a frame inside it: not a run
            column = frames[::rest]
            index = column.find(tail[0], 0, count)
            while index >= 0 and not frames.startswith(tail, index * rest):
                index = column.find(tail[0], index + 1, count)
            if index >= 0:
                count = index
        if count < 2:
            return 0, b""
        frames = frames[: count * rest]
        lanes = bytearray(2 * count)
        total = 0
        for at in range(current.sum_from, rest - 1):
            lanes[::2] = frames[at::rest]
            total += int.from_bytes(lanes, "little")
        sums = total.to_bytes(2 * count, "little")[::2].translate(current.sum_table)
        checks = frames[rest - 1 :: rest]
        if sums != checks:  # the run ends at the first frame whose checksum fails
            differ = int.from_bytes(sums, "little") ^ int.from_bytes(checks, "little")
            count = ((differ & -differ).bit_length() - 1) // 8
            frames = frames[: count * rest]
        return count, frames

    def _decide(self, buffer: bytes, at: int, current: _Candidate) -> tuple[Message | None, int, int] | None:
        """The candidate whose header is at `at`, as the byte-by-byte scan decides it: (message, start, end) of the
        frame taken (this one, or the one inside it that completes first); (None, at, 1) when it is corrupt and
        (None, at, 0) when it is no frame (implausible); None when it must wait for more bytes."""
        end = len(buffer)
        size = None
        if end - at >= current.prefix:
            key = buffer[at + current.length_offset]
            if current.command_offset is not None:
                key |= buffer[at + current.command_offset] << 8
            size = current.frame_sizes.get(key)
            if size is None or (current.ranges and not current.plausible(buffer, at)):
                return None, at, 0
            if at + size > end:
                size = None
        # a frame inside this candidate that ends before it (or before the bytes run out) completes first
        inner = self._earliest(buffer, at + 1, end + 1 if size is None else at + size)
        if inner is not None:
            return inner
        if size is None:
            return None
        message = current.take(key, buffer, at, at + size)
        return (None, at, 1) if message is None else (message, at, at + size)

    def _earliest(self, buffer: bytes, first: int, bound: int) -> tuple[Message, int, int] | None:
        """The frame that completes first (of two ending together, the first) among the valid frames that start at
        or after `first` and end before `bound` (at most len(buffer) + 1): (message, start, end), or None."""
        best = None
        end = len(buffer)
        single = self._single
        smallest = self._smallest
        while True:
            if single is not None:  # only headers where a frame ending before `bound` can start
                position = buffer.find(single.header, first, bound - 1 - smallest + len(single.header))
                candidate = single
            else:
                position, candidate = self._next_header(buffer, first)
            if position < 0 or position + smallest >= bound:
                return best
            if end - position >= candidate.prefix:
                key = buffer[position + candidate.length_offset]
                if candidate.command_offset is not None:
                    key |= buffer[position + candidate.command_offset] << 8
                size = candidate.frame_sizes.get(key)
                if (
                    size is not None
                    and position + size < bound
                    and (not candidate.ranges or candidate.plausible(buffer, position))
                ):
                    message = candidate.take(key, buffer, position, position + size)
                    if message is not None:
                        best, bound = (message, position, position + size), position + size
            first = position + 1

    def _scan(self, buffer: bytes) -> list[Message]:
        """The byte-by-byte scan: the nearest header of any frame format, then `_decide`."""
        end = len(buffer)
        single = self._single
        found: list[Message] = []
        append = found.append
        current = self._candidates[0]
        garbage = errors = start = 0
        while True:
            if single is not None:
                position = buffer.find(current.header, start)
            else:
                position, current = self._next_header(buffer, start)
            if position < 0:
                cut = max(start, end - self._keep)
                garbage += cut - start
                self._pending = buffer[cut:]
                break
            decided = self._decide(buffer, position, current)
            if decided is None:  # wait for more bytes
                garbage += position - start
                self._pending = buffer[position:]
                break
            message, where, stop = decided
            if message is None:  # no frame, or a corrupt one: resume one byte after its header
                errors += stop
                garbage += position + 1 - start
                start = position + 1
                continue
            append(message)
            garbage += where - start
            start = stop
        self.garbage += garbage
        self.errors += errors
        return found

    def _next_header(self, buffer: bytes, start: int) -> tuple[int, _Candidate]:
        best, best_candidate = -1, self._candidates[0]
        for candidate in self._candidates:
            position = buffer.find(candidate.header, start)
            if position >= 0 and (best < 0 or position < best):
                best, best_candidate = position, candidate
        return best, best_candidate

    def expect(self, cls: type[Message] | None, request: Message | None = None) -> None:
        """The reply class the next frames answer (and the request they answer); classic frames have one layout
        per code, so it changes nothing."""

    def gap(self) -> None:
        """The line went idle (a Modbus 3.5-character pause, a UART IDLE interrupt, a read that timed out): no frame
        spans it, so the bytes held (candidates waiting for bytes that will not come, a tail that could begin a
        header) are dropped and counted as garbage. The bytes held never hold a complete frame: it would have been
        taken."""
        self.garbage += len(self._pending)
        self._pending = b""
        self._need = 0

    def pending(self) -> bytes:
        """Bytes held back, waiting to complete a frame."""
        return self._pending
