"""The length-byte case's whole-frame decoders: for each message of one size (and the frames that take the rest
of their content), a decoder of the whole frame made from its content decoder's statements (the content size check
dropped, the cursor made a constant offset), which checks the checksum the cheapest way its algorithm allows; the same
decoders at an offset of a buffer are the stream parser's (`stream`, `run_frames`, `stream_sum`)."""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from serialspec.backends.common.frames import runtime_layout
from serialspec.backends.python.checksum_code import checksum_lines, checksum_name
from serialspec.backends.python.dispatch import (
    decoder_name,
    message_function,
    shared_codes,
)
from serialspec.backends.python.ir import (
    RETURN_NONE,
    Advance,
    Block,
    Code,
    ContentSize,
    Expect,
    FrameTest,
    If,
    Loop,
    ReturnNew,
    Statement,
    TakeRest,
    Unpack,
    raises,
    reads_cursor,
    walk,
)
from serialspec.backends.python.kinds import takes_the_rest
from serialspec.backends.python.optimize import content_unpacked, fuse_unpack
from serialspec.lang.model import (
    Bytes,
    Checksum,
    Command,
    Direction,
    FrameLayout,
    Message,
    Protocol,
)

if TYPE_CHECKING:
    from serialspec.backends.python.content import PackageCode
from serialspec.backends.python.frames.decode import frame_sum_test

At = Callable[[int], int | str]  # a frame offset as the decoder reads it: a number, or `start + k` in a buffer


def fixed_frames(
    protocol: Protocol, layout: FrameLayout, bodies: dict[str, tuple[str, str, Block]], code: PackageCode
) -> list[tuple[str, int, dict[str, Any]]]:
    """Whole-frame decoders for the frames of one size whose content is one run of fixed fields: (size key, frame
    size, function). Each checks the checksum, unpacks the content in one call and builds the message: no
    dispatch, no size checks (the key is the command code and length byte, so the size is known), one call per
    frame. It returns None for a frame whose checksum fails, so callers word the error (decode) or count it (the
    stream parser); it raises nothing. Frames of any other kind keep the general path."""
    found = []
    for command in protocol.commands:
        message = command.request if layout.direction == Direction.REQUEST else command.response
        if command.selector is not None or message is None:
            continue
        made = frame_function(protocol, layout, command, message, bodies, code)
        if made is not None:
            key, size, function = made
            found.append((f"{key:#06x}", size, function))
    return found


def subcommand_frames(
    protocol: Protocol, layout: FrameLayout, bodies: dict[str, tuple[str, str, Block]], code: PackageCode
) -> tuple[list[dict[str, Any]], list[dict[str, Any]], list[tuple[str, int, dict[str, Any]]]]:
    """decode()'s whole-frame decoders of sub-command frames of one size (as fixed_frames, the sub-command's check
    dropped: its code picks the decoder) and, per command and frame size, the function that picks one by the
    sub-command byte: (decoders, pickers, decode's table entries of the pickers, as fixed_frames gives them)."""
    content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    functions: list[dict[str, Any]] = []
    pickers: list[dict[str, Any]] = []
    entries = []
    for command in protocol.commands:
        if command.selector is None or layout.direction not in command.selector.offsets:
            continue
        if command.selector.type.size != 1:  # a selector of several bytes: the general path reads it
            continue
        by_size: dict[tuple[int, int], list[tuple[int, dict[str, Any]]]] = {}
        for sub in command.subcommands:
            message = sub.request if layout.direction == Direction.REQUEST else sub.response
            if message is None:
                continue
            made = frame_function(protocol, layout, command, message, bodies, code, command.selector.name)
            if made is not None:
                key, size, function = made
                by_size.setdefault((key, size), []).append((sub.code, function))
        at = content_offset + command.selector.offsets[layout.direction]
        for (key, size), subs in by_size.items():
            picker = {
                "whole_name": f"_whole_{command.name}_{layout.direction.value}_{size}",
                "table": f"_{command.name.upper()}_{layout.direction.name}_WHOLE_{size}",
                "size": size,
                "where": f"{command.name} {layout.direction.value}",
                "entries": [(f"{c:#04x}", f["whole_name"]) for c, f in subs],
            }
            lines = picked_inline(subs, at)
            if lines is None:  # each sub-command's own decoder, from a table
                functions += [f for _, f in subs]
                lines = [
                    Code(f"whole = {picker['table']}.get(buf[{at}])"),
                    Code("return None if whole is None else whole(buf)"),
                ]
            else:
                picker["entries"] = []
            pickers.append(picker | {"lines": lines})
            entries.append((f"{key:#06x}", size, picker))
    return functions, pickers, entries


def rest_frames(
    protocol: Protocol,
    layout: FrameLayout,
    bodies: dict[str, tuple[str, str, Block]],
    code: PackageCode,
    stream: bool = False,
) -> list[dict[str, Any]]:
    """decode()'s whole-frame decoders of the frames whose content is fixed fields then bytes to its end (FEETECH
    WRITE: an address, then the data): any length byte from the smallest such content up names one, so decode()'s
    table holds a key per length byte. Each checks the checksum, reads the fields at constant offsets and the bytes
    up to the frame's tail: no dispatch, no content decoder's call. Others keep the general path.

    `stream`: the same decoders for the stream parser's table of frames decoded whole (FrameFormat.fixed), of the
    frame at buf[start:] (its end from its length byte), also for contents of any size (FEETECH's reply: an
    error byte in the frame, then the data), which have no size check to drop: one call per frame."""
    checksum = protocol.framing.checksum
    length = layout.length
    if checksum is None or length is None or length.type is None:
        return []
    content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    tail = layout.overhead - content_offset  # bytes after the content
    found = []
    shared = shared_codes(protocol, layout.direction)
    for command in protocol.commands:
        if command.wire_code(layout.direction) in shared:
            continue  # its length bytes may name a request of the same code: its size dispatch picks
        message = command.request if layout.direction == Direction.REQUEST else command.response
        if command.selector is not None or message is None or message.max_size is not None or not message.fields:
            continue
        if not (isinstance(message.fields[-1], Bytes) and takes_the_rest(message.fields[-1])):
            continue
        returns, extra, decoder = bodies[decoder_name(message)]
        if decoder and isinstance(decoder[0], ContentSize) and decoder[0].high is None:
            statements = decoder[1:]  # the size check: the key implies it
        elif stream and not message.min_size and not any(isinstance(s, ContentSize) for s in walk(decoder)):
            statements = decoder
        else:
            continue

        def at(offset: int) -> int | str:
            return f"start + {offset}" if stream else offset

        offset, body = content_offset, []
        for statement in statements:
            if isinstance(statement, Advance) and isinstance(statement.size, int) and not statement.to:
                offset += statement.size
                continue
            if isinstance(statement, Unpack) and statement.at == "o":
                statement = replace(statement, at=at(offset))
            elif isinstance(statement, TakeRest):
                statement = replace(statement, start=at(offset), stop=f"stop - {tail}" if stream else f"-{tail}")
            if raises([statement]) or any(reads_cursor(s) for s in walk([statement])):
                break  # checked beyond its size, or read at a cursor: the general path
            body.append(statement)
        else:
            values = [Code(f"{e.name} = buf[{at(layout.offsets[e.name])}]") for e in layout.value_elements]
            lowest = (message.min_size or 0) + layout.length_adds
            check = stream_rest_check(protocol, layout) if stream else rest_check(protocol, layout)
            found.append(
                {
                    "whole_name": message_function("stream" if stream else "whole", message),
                    "stream": stream,
                    "returns": returns,
                    "where": f"{message.key} {message.direction.value}",
                    "whole_lines": fuse_unpack([*check, *values, *body]),
                    "code": command.wire_code(layout.direction),
                    "lengths": (lowest, length.type.maximum),
                    "adds": layout.overhead - layout.length_adds,  # frame size = length byte + this
                }
            )
    return found


def subcommand_rest_frames(
    protocol: Protocol, layout: FrameLayout, bodies: dict[str, tuple[str, str, Block]]
) -> list[dict[str, Any]]:
    """decode()'s whole-frame decoders of the sub-command frames of more than one size (a list its count sizes), one
    per command: any length byte from the smallest such content up names it (a key per length byte, as rest_frames).
    Each checks the checksum, then picks the sub-command by its byte and runs that sub-command's content decoder's
    statements in place: no dispatch and no call. It returns None where the checksum fails or no such sub-command has
    the code (decode()'s general path then says why); a frame its statements refuse raises what the general path
    raises, as that path, with the same checks passed, runs the same statements."""
    checksum = protocol.framing.checksum
    length = layout.length
    if checksum is None or length is None or length.type is None or layout.value_elements:
        return []
    content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    tail = layout.overhead - content_offset  # bytes after the content
    found = []
    for command in protocol.commands:
        if command.selector is None or layout.direction not in command.selector.offsets:
            continue
        if command.selector.type.size != 1:  # a selector of several bytes: the general path reads it
            continue
        at = command.selector.offsets[layout.direction]
        subs = []
        for sub in command.subcommands:
            message = sub.request if layout.direction == Direction.REQUEST else sub.response
            if message is None or message.min_size == message.max_size:
                continue  # none, or of one size (subcommand_frames)
            returns, extra, body = bodies[decoder_name(message)]
            if not extra:
                subs.append((sub.code, message, body))
        if not subs:
            continue
        lines: Block = [*rest_check(protocol, layout), Code(f"sub = buf[{content_offset + at}]")]
        for sub_code, _, body in subs:
            cursor = Code(f"o, end = {content_offset}, len(buf) - {tail}")
            lines.append(If(f"sub == {sub_code:#04x}", (cursor, *body)))
        smallest = min(message.min_size or 0 for _, message, _ in subs)
        sizes = [message.max_size for _, message, _ in subs]
        largest = length.type.maximum if None in sizes else max(s for s in sizes if s is not None) + layout.length_adds
        found.append(
            {
                "whole_name": f"_whole_{command.name}_{layout.direction.value}",
                "returns": "Message",
                "where": f"{command.name} {layout.direction.value}",
                "whole_lines": [*lines, RETURN_NONE],
                "code": command.wire_code(layout.direction),
                # the sub-command's byte lies within the content: no smaller content reaches the picker
                "lengths": (max(smallest, at + 1) + layout.length_adds, min(largest, length.type.maximum)),
                "adds": layout.overhead - layout.length_adds,  # frame size = length byte + this
            }
        )
    return found


def rest_check(protocol: Protocol, layout: FrameLayout) -> Block:
    """The checksum test of a whole frame of any size (`buf` is the frame), returning None when it fails."""
    checksum = protocol.framing.checksum
    assert checksum is not None  # length-byte frames have one
    size = layout.checksum_offset_from_end
    stored = "buf[-1]" if size == 1 else f"int.from_bytes(buf[-{size}:], 'little')"
    header = layout.header[: layout.covered_from]
    test = checksum.algorithm.frame_test("sum(buf)", sum(header), "buf[-1]")
    if test is not None and size == 1 == layout.covered_to_end and len(header) == layout.covered_from:
        return [FrameTest(test, test)]
    covered = f"buf[{layout.covered_from}:-{layout.covered_to_end}]"
    check = [Code(line) for line in checksum_lines(checksum, covered, "expected")]
    return [*check, If(f"expected != {stored}", (RETURN_NONE,))]


def stream_rest_check(protocol: Protocol, layout: FrameLayout) -> Block:
    """The checksum test of the frame of any size at buf[start:], its end (`stop`) from its length byte, returning
    None when it fails."""
    checksum = protocol.framing.checksum
    assert checksum is not None  # length-byte frames have one
    size = layout.checksum_offset_from_end
    stored = "buf[stop - 1]" if size == 1 else f"int.from_bytes(buf[stop - {size} : stop], 'little')"
    first = f"start + {layout.covered_from}" if layout.covered_from else "start"
    covered = f"buf[{first} : stop - {layout.covered_to_end}]"
    adds = layout.overhead - layout.length_adds  # frame size = length byte + this
    check = [Code(line) for line in checksum_lines(checksum, covered, "expected")]
    stop = Code(f"stop = start + {adds} + buf[start + {layout.length_offset}]")
    return [stop, *check, If(f"expected != {stored}", (RETURN_NONE,))]


def failed_check(body: Block) -> int | None:
    """The index of a whole-frame decoder's checksum test (the first `if ...: return None`), or None."""
    return next((i for i, s in enumerate(body) if isinstance(s, If | FrameTest) and returns_none(s)), None)


def returns_none(statement: If | FrameTest) -> bool:
    return isinstance(statement, FrameTest) or statement.body == (RETURN_NONE,)


def picked_inline(subs: list[tuple[int, dict[str, Any]]], at: int) -> Block | None:
    """One function's statements for the sub-command frames of one size, where their checksum does not depend on
    their fields (a sum or CRC over the bytes, the same statements for all, given the key): the check once, then each
    sub-command's unpacking under an `if` on its code. None where the check is made from the unpacked values."""
    first: Block = subs[0][1]["whole_lines"]
    index = failed_check(first)
    if index is None:
        return None
    checks = first[: index + 1]
    if any(isinstance(s, Unpack) for s in walk(checks)):
        return None
    if any(f["whole_lines"][: len(checks)] != checks for _, f in subs):
        return None
    lines: Block = [*checks, Code(f"sub = buf[{at}]")]
    for sub_code, f in subs:
        lines.append(If(f"sub == {sub_code:#04x}", tuple(fuse_unpack(f["whole_lines"][len(checks) :]))))
    return [*lines, RETURN_NONE]


def frame_function(
    protocol: Protocol,
    layout: FrameLayout,
    command: Command,
    message: Message,
    bodies: dict[str, tuple[str, str, Block]],
    code: PackageCode,
    selector: str | None = None,
) -> tuple[int, int, dict[str, Any]] | None:
    """The whole-frame decoders of one message (see fixed_frames): size key, frame size, function; None where the
    message's frames need the general path. `selector`: the sub-command field, whose check the key makes."""
    checksum = protocol.framing.checksum
    if checksum is None or message.min_size != message.max_size:
        return None  # length-byte frames have a checksum
    content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    returns, extra, decoder = bodies[decoder_name(message)]
    if not (decoder and isinstance(decoder[0], ContentSize) and decoder[0].exact):
        return None
    body = decoder[1:]  # the content size check: the key implies the size
    if selector is not None:  # the sub-command's check: the picker chose this decoder by it
        at = next((i for i, s in enumerate(body) if isinstance(s, Expect) and s.name == f"v_{selector}"), None)
        if at is None:
            return None
        body = body[:at] + body[at + 1 :]
    unpacks = [s for s in walk(body) if isinstance(s, Unpack) and s.at == "o"]
    cursor = any(reads_cursor(s) for s in walk(body) if not isinstance(s, Unpack))
    if len(unpacks) > 1 or cursor or raises(body):
        return None  # content read at a moving cursor, or checked beyond its size: the general path
    size = layout.overhead + (message.min_size or 0)
    length_byte = (message.min_size or 0) + layout.length_adds
    known = dict(enumerate(layout.header)) | {layout.length_offset: length_byte}
    if layout.command_offset is not None:
        known[layout.command_offset] = command.wire_code(layout.direction) or 0

    def statements(at: At, whole: bool) -> tuple[Block, bool]:
        """The decoder's statements with frame offsets `at` (buf[start:] or all of buf: `whole`), and whether its
        checksum is checked from the unpacked values (sum_from_values)."""
        values: Block = [
            Code(f"{e.name} = buf[{at(layout.offsets[e.name])}]", reads=(layout.offsets[e.name],))
            for e in layout.value_elements
        ]
        summed = sum_from_values(
            protocol, layout, command.wire_code(layout.direction), length_byte, size, body, code, at
        )
        if summed is not None:
            return [*values, *summed, *body[1:]], True
        check = whole_frame_check(protocol, layout, size, known, at) if whole else None
        if check is None:
            check = frame_check(checksum, layout, size, at)
        return [*check, *values, *at_offset(body, at(content_offset))], False

    lines, summed = statements(lambda offset: f"start + {offset}", False)
    function: dict[str, Any] = {
        "name": message_function("frame", message),
        "whole_name": message_function("whole", message),
        "returns": returns,
        "where": f"{message.key} {message.direction.value}",
        "lines": lines,
        "whole_lines": statements(lambda offset: offset, True)[0],
    }
    # built in decode() itself (no call): one sum over the frame and one unpack cost less than a call that checks
    # the sum from the unpacked values (the READ_ANGLE reply was 2.6x the minimal decoder that way)
    plain = unpacked_frame(protocol, layout, body)
    function["plain"] = plain
    function["run"] = run_frames(layout, message, size, plain, code)
    key = (
        length_byte if layout.command_offset is None else (command.wire_code(layout.direction) or 0) << 8 | length_byte
    )
    return key, size, function


def at_offset(body: Block, at: int | str) -> Block:
    """A content decoder's statements with the unpack at the cursor made at `at` (a frame offset)."""
    return [replace(s, at=at) if isinstance(s, Unpack) and s.at == "o" else s for s in body]


def frame_check(checksum: Checksum, layout: FrameLayout, size: int, at: At) -> Block:
    """A whole frame's checksum test, returning None when it fails: the checksum over the covered bytes compared
    with the stored one (frame offsets `at`)."""
    reads: tuple[int, ...] = ()
    if layout.checksum_offset_from_end == 1:
        stored, reads = f"buf[{at(size - 1)}]", (size - 1,)
    else:
        stored, reads = f"int.from_bytes(buf[{at(size - layout.checksum_offset_from_end)} : {at(size)}], 'little')", ()
    covered = f"buf[{at(layout.covered_from)} : {at(size - layout.covered_to_end)}]"
    check = [Code(line) for line in checksum_lines(checksum, covered, "expected")]
    return [*check, If(f"expected != {stored}", (RETURN_NONE,), reads=reads)]


_MOST_UNROLLED = 12  # CRC-8 steps written out one by one in a whole-frame decoder; more take a loop


def whole_frame_check(
    protocol: Protocol, layout: FrameLayout, size: int, known: dict[int, int], at: At
) -> Block | None:
    """decode()'s version of a whole-frame decoder's checksum test, where it is cheaper than frame_check's: `buf` is
    exactly the frame (decode checked its size), so a checksum that is a sum over all but a constant header is
    tested on the sum of the whole frame (no slice is made: the algorithm's frame_test); one computed by table steps
    starts from its state after the covered bytes that the frame's key fixes (`known`: offset -> byte; header,
    command code, length byte), and a few steps are written out. None where neither applies."""
    checksum = protocol.framing.checksum
    assert checksum is not None  # length-byte frames have one
    steps = checksum.algorithm.byte_table(checksum_name(checksum), "expected")
    if steps is not None:
        state = steps.start
        first, stop = layout.covered_from, size - layout.covered_to_end
        while first in known and first < stop - 1:
            state = steps.entries[state ^ known[first]]
            first += 1
        stepped: Block
        if stop - first > _MOST_UNROLLED:
            stepped = [
                Code(f"expected = {state:#x}"),
                Loop(f"for byte in buf[{first} : {stop}]", (Code(f"expected = {steps.table}[expected ^ byte]"),)),
            ]
        else:  # a few bytes: one table step each, no slice and no loop
            stepped = [Code(f"expected = {steps.table}[{state:#x} ^ buf[{first}]]", reads=(first,))]
            stepped += [
                Code(f"expected = {steps.table}[expected ^ buf[{offset}]]", reads=(offset,))
                for offset in range(first + 1, stop)
            ]
        stepped += [Code(line) for line in steps.finish]
        return [*stepped, frame_check(checksum, layout, size, at)[-1]]
    header = layout.header[: layout.covered_from]
    test = checksum.algorithm.frame_test("sum(buf)", sum(header), f"buf[{size - 1}]")
    whole = layout.checksum_offset_from_end == 1 and layout.covered_to_end == 1 and len(header) == layout.covered_from
    if test is None or not whole:
        return None
    return [FrameTest(test, checksum.algorithm.frame_test("sum(buf)", sum(header), "buf[-1]") or test)]


def exact_struct(name: str, size: int, content_offset: int, code: PackageCode) -> str:
    """A struct of a whole frame of `size` bytes that unpacks what struct `name` unpacks at the content's offset,
    the bytes around it skipped: its unpack refuses (struct.error) a frame of any other size."""
    fmt = code.structs[name]
    after = size - content_offset - struct.calcsize(fmt)
    whole = f"{fmt[0]}{content_offset}x{fmt[1:]}" + (f"{after}x" if after else "")
    exact = f"{name}_IN_{size}"
    code.structs[exact] = whole
    return exact


def exact_whole(body: Block, size: int, known: int, code: PackageCode) -> Block:
    """A whole-frame decoder that refuses a frame of another size than `size` by itself: its one unpack made of the
    whole frame (struct.error), a sum's check byte read from the end; else a size check first, returning None.
    `known`: the bytes decode() has matched (its key), which any frame it is given holds."""
    body = [replace(s, condition=s.from_end) if isinstance(s, FrameTest) else s for s in body]
    unpacks = [i for i, s in enumerate(body) if _unpack_at_offset(s) is not None]
    before = body[: unpacks[0] if unpacks else len(body)]
    if len(unpacks) != 1 or any(offset >= known for offset in _constant_reads(before)):
        return [If(f"len(buf) != {size}", (RETURN_NONE,)), *body]
    found = body[unpacks[0]]
    unpack = _unpack_at_offset(found)
    assert unpack is not None and isinstance(unpack.at, int)
    whole = replace(unpack, struct=exact_struct(unpack.struct, size, unpack.at, code), at="")
    body[unpacks[0]] = replace(found, unpacked=whole) if isinstance(found, ReturnNew) else whole
    return body


def _unpack_at_offset(statement: Statement) -> Unpack | None:
    """The struct unpack a statement makes at a constant offset of the frame, if any."""
    if isinstance(statement, ReturnNew):
        unpack = statement.unpacked
    else:
        unpack = statement if isinstance(statement, Unpack) else None
    return unpack if unpack is not None and not unpack.indexed and isinstance(unpack.at, int) else None


def _constant_reads(body: Block) -> list[int]:
    """The constant offsets of `buf` that statements read (an unpack's struct aside)."""
    reads: list[int] = []
    for statement in walk(body):
        if isinstance(statement, Code | If):
            reads += statement.reads
        elif isinstance(statement, Unpack) and statement.indexed and isinstance(statement.at, int):
            reads.append(statement.at)
    return reads


def stream_sum(protocol: Protocol, layout: FrameLayout) -> str | None:
    """The stream parser's `summed`: (first byte covered, inverted) where the checksum is an 8-bit sum of every byte
    from there to the last, which it is; None for other checksums."""
    checksum = protocol.framing.checksum
    inverted = checksum.algorithm.summed() if checksum is not None else None
    if inverted is None or whole_frame_test(protocol, layout) is None:
        return None
    return f"({layout.covered_from}, {inverted})"


def whole_frame_test(protocol: Protocol, layout: FrameLayout) -> str | None:
    """decode()'s test that a whole frame `data` (its size known) holds its checksum, where it is one expression
    over the frame's bytes (decode.frame_sum_test, as every framing's checks make it). None for others."""
    engine = runtime_layout(layout)
    test = frame_sum_test(engine, len(engine.elements) - 1, protocol.framing.checksum, "data")
    return None if test is None else f"not {test}"


def run_frames(
    layout: FrameLayout, message: Message, size: int, plain: tuple[str, str] | None, code: PackageCode
) -> dict[str, str] | None:
    """The stream parser's decoder of a run of a plain frame (unpacked_frame), checked already, laid end to end with
    their headers left out: one struct over the bytes after the header (the command code, length byte and checksum
    skipped as padding) and a message built from each tuple it unpacks. None where the content is not the whole of
    the frame between those."""
    if plain is None:
        return None
    cls, content = plain
    fmt = code.structs[content]
    width = len(layout.header)
    content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    if content_offset < width or content_offset + struct.calcsize(fmt) != size - 1:
        return None
    lead = content_offset - width
    after = fmt[0] + (f"{lead}x" if lead else "") + fmt[1:] + "x"
    frames = code.struct(code.stems[content] + "_after_header", after)
    names = [f.name for f in message.fields]
    return {
        "name": message_function("run", message),
        "build": code.build_all(cls, names, f"{frames}.iter_unpack(frames)"),
        "unpack": f"{frames}.unpack_from",  # one such frame's values, from the bytes after its header
        "returns": cls,
        "where": f"{message.key} {message.direction.value}",
    }


def unpacked_frame(protocol: Protocol, layout: FrameLayout, body: Block) -> tuple[str, str] | None:
    """(class, struct) of a frame whose message is the tuple one struct unpacks from its content, as it is, and
    whose checksum decode() tests in one expression (whole_frame_test): decode() builds it itself, with no call.
    None for others (frame values, conversions, checks)."""
    plain = content_unpacked(body)
    if plain is None or layout.value_elements or whole_frame_test(protocol, layout) is None:
        return None
    return plain


_BYTES_OF = {"B": 1, "b": 1, "H": 2, "h": 2, "I": 4, "i": 4, "Q": 8, "q": 8}


_MOST_TERMS = 4  # byte terms of a checksum computed from the values; beyond it the frame's bytes are summed


def sum_from_values(
    protocol: Protocol,
    layout: FrameLayout,
    command: int | None,
    length_byte: int,
    size: int,
    body: Block,
    code: PackageCode,
    at: At,
) -> Block | None:
    """For an 8-bit sum checksum right after integer-only content: statements that unpack the content and the
    checksum in one call (at frame offsets `at`) and check the sum from the values (a byte sum does not depend on
    byte order), so no slice of the frame is made and summed. The frame's other covered bytes must be the header,
    command code and length byte (constants, given the key) and one-byte frame values. None where the frame is not
    like that."""
    checksum = protocol.framing.checksum
    unpack = body[0] if body else None
    if checksum is None or checksum.algorithm.summed() is None:
        return None
    if not isinstance(unpack, Unpack) or unpack.at != "o" or unpack.tuple_target:
        return None
    if layout.checksum_offset_from_end != 1:
        return None
    fmt = code.structs[unpack.struct]
    targets = unpack.targets
    if len(targets) != len(fmt) - 1 or any(c not in _BYTES_OF for c in fmt[1:]):
        return None
    content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    if content_offset + sum(_BYTES_OF[c] for c in fmt[1:]) != size - 1:
        return None  # the checksum does not follow the content
    constant = 0
    terms = []
    for offset in range(layout.covered_from, size - layout.covered_to_end):
        if offset < len(layout.header):
            constant += layout.header[offset]
        elif offset == layout.command_offset:
            constant += command or 0
        elif offset == layout.length_offset:
            constant += length_byte
        elif content_offset <= offset < size - 1:
            continue  # the content's values, below
        else:
            element = next((e for e in layout.value_elements if layout.offsets[e.name] == offset and e.size == 1), None)
            if element is None:
                return None
            terms.append(element.name)
    for target, char in zip(targets, fmt[1:], strict=True):
        width = _BYTES_OF[char]
        if width == 1:
            terms.append(target if char == "B" else f"({target} & 0xff)")
        else:
            terms += [f"({target} & 0xff)", *(f"({target} >> {8 * i} & 0xff)" for i in range(1, width))]
    if len(terms) > _MOST_TERMS:
        return None  # summing a slice of the frame in C is cheaper than this many terms in Python
    with_check = code.struct(code.stems[unpack.struct] + "_and_check", fmt + "B")
    total = checksum.algorithm.byte_total(" + ".join([f"{constant:#x}", *terms]))
    assert total is not None  # an 8-bit byte sum's
    return [
        Unpack((*targets, "check"), with_check, at=at(content_offset)),
        If(f"{total} != check", (RETURN_NONE,)),
    ]
