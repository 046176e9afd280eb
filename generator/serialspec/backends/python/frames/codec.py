"""The codec template's frames part, its one entry (`frames_codec_context`): each direction's frame functions
(`direction_functions`: straight-line code where its layouts allow it, else the engine's), with the length-byte
case's tables (length_byte.py) where every layout has that shape."""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Any

from serialspec.backends.common.frames import optional_elements, runtime_layouts
from serialspec.backends.python.dispatch import (
    ERROR_REPLY,
    decoder_name,
    direction_dispatch,
)
from serialspec.backends.python.frames.engine import checksum_definitions, codec_lines, reply_refusals
from serialspec.backends.python.ir import (
    ContentSize,
)
from serialspec.backends.python.optimize import content_unpacked
from serialspec.backends.python.simulator import import_order
from serialspec.lang.model import (
    Direction,
    Discriminator,
    Message,
    Protocol,
    replies_by_request,
    reply_to,
)
from serialspec.transforms import runtime_classes

if TYPE_CHECKING:
    from serialspec.backends.python.content import PackageCode
from serialspec.backends.python.frames.decode import choice_lines, decode_lines, engine_lines, whole_frames
from serialspec.backends.python.frames.encode import LayoutEncoding, wrap_lines, wrap_parts
from serialspec.backends.python.frames.layouts import Lines, Target, registry, straight_direction, stuffing_of
from serialspec.backends.python.frames.length_byte import length_byte_codec_context


def direction_functions(
    protocol: Protocol,
    direction: Direction,
    target: Target,
    structs: dict[str, str],
    plain: list[tuple[int, int, str, str, str]],
) -> tuple[Lines, Lines]:
    """Module-level code of one direction's frame functions (`_decode_<d>`, `_wrap_<d>` and what they use), and
    the lines of `decode()` that decode a frame `data` of this direction (`plain`: see whole_frames)."""
    found = straight_direction(protocol, direction)
    d = direction.value
    if found is None:
        decode, wrap = engine_lines(runtime_layouts(protocol, direction), target)
        request = ", request" if target.requesting else ""
        return [*decode, "", "", *wrap], [f"return _decode_{d}(bytes(data), expect{request})"]
    layouts = found.layouts
    several = len(layouts) > 1
    lines: Lines = []
    divert: Lines = []
    if found.diverts:  # a frame with an optional element's flag bit set: the engine's (its functions, renamed)
        decode, wrap = engine_lines(runtime_layouts(protocol, direction), target, "_engine")
        lines += [*decode, "", "", *wrap, "", ""]
        tests = [
            f"frame[{offset}] & {mask:#04x}"
            if size == 1
            else f"int.from_bytes(frame[{offset} : {offset + size}], {endian!r}) & {mask:#x}"
            for offset, size, endian, mask in found.diverts
        ]
        shortest = max(offset + size for offset, size, _, _ in found.diverts)
        divert = [
            f"if len(frame) >= {shortest} and ({' or '.join(tests)}):  # optional elements sent: the frame engine's",
            f"    return _decode_{d}_engine(frame, expect)",
        ]
    wraps: list[LayoutEncoding] = []
    refusals: list[LayoutEncoding] = []  # the error header's layouts: only the error reply is sent in them
    bodies: list[Lines] = []
    for layout, checks, algorithms in zip(layouts, found.checks, found.algorithms, strict=True):
        suffix = f"_{layout.name}" if several else ""
        stuffing = f"_{target.upper}{suffix.upper()}_TRANSPARENCY"
        t = stuffing_of(layout)
        if t is not None:
            pairs = ", ".join(f"({plain!r}, {wire!r})" for plain, wire in t.replace)
            lines += [f"{stuffing} = Transparency({t.span}, ({pairs},))", "", ""]
        # of several layouts, each is decoded once its header has chosen it (choice_lines)
        function, body = decode_lines(layout, f"_decode_{d}{suffix}", target, checks, stuffing, several, algorithms)
        function = [*function[:2], *(f"    {line}" for line in divert), *function[2:]]
        lines += [*function, "", ""]
        bodies.append(body)
        (refusals if layout.error else wraps).append(wrap_parts(layout, target, checks, stuffing, registry(structs)))
    if several:
        choice = choice_lines(layouts, d)
        lines += [
            f"def _decode_{d}(frame: bytes, expect: type[Message] | None = None) -> Message:",
            f'    """One complete {d} frame, in the layout its header names."""',
            *(f"    {line}" for line in choice),
            "",
            "",
        ]
    # decode() chooses the layout and checks the frame itself: one call less
    table, fast = whole_frames(found, d, plain, structs)
    call = [
        "frame = data if data.__class__ is bytes else bytes(data)",
        *divert,
        *fast,
        *choice_lines(layouts, d, bodies),
    ]
    lines += [*table, "", ""] if table else []
    lines += wrap_lines(d, wraps, target)
    lines += ["", "", *wrap_lines(f"{d}_error", refusals, target)] if refusals else []
    return lines, call


def straight_codec_context(protocol: Protocol, code: PackageCode) -> dict[str, Any]:
    """Frames of any other shape: straight-line frame functions per direction where the layouts allow them (see
    frames/), else the runtime's frame engine; one FrameCodec per direction either way (the stream parser's),
    decoders by code (and by class)."""
    # layouts chosen by command, checksums over request bytes: the engine's code only (no straight-line checks)
    engine_only = protocol.framing.requesting
    imports, definitions = checksum_definitions(protocol, straight=not engine_only)
    directions: list[dict[str, Any]] = []
    dispatchers = []
    size_dispatchers: list[dict[str, Any]] = []
    frame_structs: dict[str, str] = {}
    # the runtime.framing names the codec uses: the FrameCodecs' (the straight-line functions' Transparency objects are
    # those of the same layouts) and ERROR_REPLY where error replies are told by their flag
    names = {"EngineFormat"}
    transform_classes = runtime_classes()
    for direction, layout in protocol.framing.layouts.items():
        table = direction_dispatch(protocol, direction)
        dispatchers += table.dispatchers
        size_dispatchers += table.size_dispatchers
        dispatch, sizes, single, expected = table.dispatch, table.sizes, table.single, table.expected
        sized: dict[str, Message | Discriminator] = {
            key: single.get(key) or table.sized[key] for key, _ in dispatch if key in single or key in table.sized
        }
        only = dispatch[0][1] if not layout.has_command and len(dispatch) == 1 and not expected else ""
        values = tuple(e.name for e in layout.value_elements)
        requesting = protocol.framing.requesting
        optional = tuple(e.name for e in optional_elements(protocol, direction))
        refusals = (
            sorted({r for rs in reply_refusals(protocol).values() for r in rs}) if direction.name == "RESPONSE" else []
        )
        frames = Target(
            direction.name,
            values,
            expected=bool(expected),
            only=only,
            requesting=requesting,
            optional=optional,
            refusals=tuple(refusals),
        )
        if protocol.error_reply is not None and direction == Direction.RESPONSE:
            element = next(e for e in layout.elements if e.name == protocol.error_reply.element)
            assert element.type is not None
            mask = (1 << (8 * element.type.size)) - 1
            error = protocol.error_reply
            flag = error.flag
            frames = replace(
                frames,
                error_flag=flag,
                error_keep=mask & ~flag,
                refusing=error.by_header,
                error_status=error.status,
                error_bits=error.bits,
            )
        told = frames.error_flag or frames.error_bits
        plain = unpacked_messages(single, code) if not expected and not told else []
        functions, call = direction_functions(protocol, direction, frames, frame_structs, plain)
        names |= {ERROR_REPLY} if frames.error_flag or frames.refusing or frames.error_bits else set()
        if protocol.framing.by_request(direction):  # content sizes and size rules by reply class
            answering = [m for m in protocol.messages() if m.direction == direction]
            sizes = [(repr(m.class_name), m.min_size, m.max_size) for m in answering]
            sized = {repr(m.class_name): m for m in answering}
        frame_codec, used = codec_lines(protocol, direction, sizes, sized)
        if refusals:  # the classes the frame engine names (Unwrapped.reply)
            shown = ", ".join(f"{name!r}: {name}" for name in refusals)
            frame_codec = [f"_{direction.name}_REFUSALS: dict[str, type[Message]] = {{{shown}}}", *frame_codec]
        names |= used
        directions.append(
            {
                "name": direction.value,
                "upper": direction.name,
                "dispatch": dispatch,
                "expected": expected,
                "frames": frame_codec,
                "functions": functions,
                "call": call,
                "headers": sorted({layout.header for layout in protocol.framing.alternatives[direction]}),
            }
        )
    headers = [h for d in directions for h in d["headers"]]
    shared = {cls for d in directions for cls, _, _ in d["expected"]}
    replies = replies_by_request(protocol.messages())
    reply_layouts = [
        (m.class_name, reply.class_name)
        for m in protocol.messages()
        if m.direction == Direction.REQUEST
        and (reply := reply_to(m, replies)) is not None
        and reply.class_name in shared
        and not reply.default_reply
    ]
    code.structs.update(frame_structs)  # listed with the content's structs (common_codec_context)
    by_header = all(headers) and len(set(headers)) == len(headers)
    requesting = protocol.framing.requesting
    return {
        "length_byte_frames": False,
        "requesting": requesting,
        "reply_to": [
            (m.class_name, reply.class_name)
            for m in protocol.messages()
            if m.direction == Direction.REQUEST and (reply := reply_to(m, replies)) is not None
        ]
        if requesting
        else [],
        "reply_layouts": reply_layouts,
        # a transform's runtime class from its own module (runtime.framing would import every transform to find it)
        "framing_imports": sorted(names - set(transform_classes), key=import_order),
        "transform_imports": sorted(
            f"from {transform_classes[name][0]} import {name}" for name in names & set(transform_classes)
        ),
        # the straight-line frame checks raise it (the engine raises its own)
        "checksum_error": any(
            element.kind == "checksum"
            for direction in protocol.framing.layouts
            if (straight := code.straight(direction)) is not None
            for layout in straight.layouts
            for element in layout.elements
        ),
        "checksum_imports": imports,
        "checksum_definitions": definitions,
        "directions": directions,
        "dispatchers": dispatchers,
        "size_dispatchers": size_dispatchers,
        "by_header": by_header,
        "either": ""
        if by_header
        else "give the direction: requests and responses cannot be told apart by their first bytes",
        "no_header": "f\"frame starts {data[:4].hex(' ')}, which is neither a request nor a response header\"",
    }


def unpacked_messages(single: dict[str, Message], code: PackageCode) -> list[tuple[int, int, str, str, str]]:
    """(code, content size, class, struct's name stem, its format) of the messages of one size whose decoder, past its
    size check, is one struct's unpack of the content as their message (decode.whole_frames decodes them
    whole)."""
    bodies = {name: body for name, _, _, body in code.decoders}
    found = []
    for key, message in single.items():
        body = bodies[decoder_name(message)]
        if key in ("None", ERROR_REPLY) or message.min_size != message.max_size or len(body) < 2:
            continue
        if not (isinstance(body[0], ContentSize) and body[0].exact):
            continue
        unpacked = content_unpacked(body[1:])
        if unpacked is not None:
            cls, struct = unpacked
            found.append((int(key, 16), message.min_size or 0, cls, code.stems[struct], code.structs[struct]))
    return found


def frames_codec_context(protocol: Protocol, code: PackageCode) -> dict[str, Any]:
    """The codec template's frames part: each direction's frame checks, dispatch and encoders' wraps; with the
    length-byte case's tables where every layout has that shape."""
    if protocol.framing.classic:
        return length_byte_codec_context(protocol, code)
    return straight_codec_context(protocol, code)
