"""The length-byte case (layer 3 of the package docstring): decode()'s tables of whole frames, looked up by a
frame's first bytes (`lookup_lines`) before the general checks of decode.py, and the stream parser's FrameFormat
(`frame_decode_lines`, `value_ranges`, the whole-frame decoders of whole.py)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from serialspec.backends.common.frames import length_limits
from serialspec.backends.python.checksum_code import checksum_lines, checksum_setup
from serialspec.backends.python.dispatch import (
    direction_dispatch,
)
from serialspec.backends.python.frames.engine import checksum_definitions, import_lines
from serialspec.backends.python.ir import (
    lines_of,
)
from serialspec.backends.python.optimize import fuse_unpack
from serialspec.lang.model import (
    Direction,
    FrameLayout,
    Protocol,
)

if TYPE_CHECKING:
    from serialspec.backends.python.content import PackageCode
from serialspec.backends.python.frames.decode import decode_lines
from serialspec.backends.python.frames.layouts import Lines, Target, straight_direction
from serialspec.backends.python.frames.whole import (
    exact_struct,
    exact_whole,
    fixed_frames,
    rest_frames,
    stream_sum,
    subcommand_frames,
    subcommand_rest_frames,
    whole_frame_test,
)


def length_byte_codec_context(protocol: Protocol, code: PackageCode) -> dict[str, Any]:
    """The codec template's part for frames of the length-byte shape: decode()'s tables of whole frames, the
    whole-frame decoders and the straight-line frame checks."""
    assert protocol.framing.checksum is not None
    checksum = protocol.framing.checksum
    assert checksum is not None  # length-byte frames have one
    checksum_imports, definitions = checksum_setup(checksum)
    directions = []
    dispatchers = []
    frame_functions: list[dict[str, Any]] = []
    whole_functions: list[dict[str, Any]] = []
    whole_pickers: list[dict[str, Any]] = []
    decoder_bodies = {name: (returns, extra, body) for name, returns, extra, body in code.decoders}
    size_dispatchers: list[dict[str, Any]] = []
    for direction, layout in protocol.framing.layouts.items():
        table = direction_dispatch(protocol, direction)
        dispatchers += table.dispatchers
        size_dispatchers += table.size_dispatchers
        dispatch, sizes = table.dispatch, table.sizes
        fixed = fixed_frames(protocol, layout, decoder_bodies, code)
        runs = [(key, function["run"]["name"]) for key, _, function in fixed if function.get("run")]
        units = [(key, f["run"]["unpack"], f["run"]["returns"]) for key, _, f in fixed if f.get("run")]
        sub_functions, pickers, sub_entries = subcommand_frames(protocol, layout, decoder_bodies, code)
        whole = length_byte_whole_frames(layout, [*fixed, *sub_entries])
        rests = rest_frames(protocol, layout, decoder_bodies, code) if whole or fixed else []
        stream_rests = rest_frames(protocol, layout, decoder_bodies, code, stream=True)
        whole_functions += stream_rests
        whole_functions += rests
        sub_rests = subcommand_rest_frames(protocol, layout, decoder_bodies) if whole else []
        whole_functions += sub_rests
        if whole:  # decode() looks frames up by their first bytes
            whole_functions += [f | {"whole_lines": fuse_unpack(f["whole_lines"])} for f in sub_functions]
            whole_pickers += pickers
        range_checks = value_range_checks(layout, protocol.byte_order)
        # decode() looks these frames up before any other check: where each decoder refuses a frame of another size
        # itself (struct.error from an unpack of the whole frame), decode() need not compare sizes first
        whole_size = max(layout.length_offset, layout.command_offset or 0) + 1
        content_offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
        exact = bool(whole) and not sub_entries and not rests and not sub_rests and not range_checks
        bodies = {f["whole_name"]: fuse_unpack(f["whole_lines"]) for _, _, f in fixed}
        if exact:
            bodies = {
                name: exact_whole(body, size, whole_size, code)
                for (_, size, f), (name, body) in zip(fixed, bodies.items(), strict=True)
            }
            whole = [
                (
                    key,
                    size,
                    name,
                    None if plain is None else (plain[0], exact_struct(plain[1], size, content_offset, code)),
                )
                for key, size, name, plain in whole
            ]
        frame_functions += [
            f | {"lines": fuse_unpack(f["lines"]), "whole_lines": bodies[f["whole_name"]], "exact": exact}
            for _, _, f in fixed
        ]
        slice_key = None if whole else key_slice(layout)
        # past the lookups, a frame is checked and dispatched as every framing's is (decode.py)
        straight = straight_direction(protocol, direction)
        assert straight is not None and len(straight.layouts) == 1  # a length-byte layout is straight-line
        only = dispatch[0][1] if layout.command_offset is None and len(dispatch) == 1 else ""
        frames = Target(direction.name, tuple(e.name for e in layout.value_elements), only=only)
        engine, checks, algorithms = straight.layouts[0], straight.checks[0], straight.algorithms[0]
        _, general = decode_lines(engine, f"_decode_{direction.value}", frames, checks, "", algorithms=algorithms)
        directions.append(
            {
                "slice_key": slice_key,
                # (only where the command code and length byte lie side by side: key_slice)
                "slice_fixed": [(slice_bytes(layout, key), size, f["whole_name"]) for key, size, f in fixed]
                if slice_key
                else [],
                "slice_rests": [slice_rest(layout, r) for r in rests] if slice_key else [],
                "accepted": [inside for _, inside, _ in range_checks],
                "exact": exact,
                "fixed": [(key, size, function["name"]) for key, size, function in fixed],
                # before the frames of one size: where a length byte names both, those keep their decoder
                "stream_rests": [rest_key(layout, r, False) for r in stream_rests],
                "runs": runs,
                "units": units,
                "summed": stream_sum(protocol, layout) if runs else None,
                "fixed_whole": [(key, size, function["whole_name"]) for key, size, function in fixed],
                "rest_keys": [rest_key(layout, r, bool(whole)) for r in rests],
                # before the frames of one size: where a length byte names both, those keep their decoder
                "sub_rest_keys": [rest_key(layout, r, True) for r in sub_rests],
                "whole_frames": whole,
                "unpacked": any(plain for *_, plain in whole),
                "whole_check": whole_frame_test(protocol, layout),
                "content_offset": content_offset,
                "whole_size": whole_size,
                "key": frame_key(layout, "data"),
                "name": direction.value,
                "upper": direction.name,
                "header": repr(layout.header),
                "header_hex": layout.header.hex(" "),
                "header_size": len(layout.header),
                "overhead": layout.overhead,
                "length_offset": layout.length_offset,
                "length_adds": layout.length_adds,
                "command_offset": layout.command_offset,
                "value_ranges": value_ranges(layout, protocol.byte_order),
                "range_checks": [
                    line for refused, _, error in range_checks for line in (f"if {refused}:", f"    raise {error}")
                ],
                "dispatch": dispatch,
                "sizes": sizes,
                "general": general,
                "at": frame_decode_lines(protocol, layout, dispatch),
            }
        )
        directions[-1]["call"] = [
            *lookup_lines(directions[-1]),
            "frame = data if data.__class__ is bytes else bytes(data)",
            *general,
        ]
        directions[-1]["headers"] = [repr(layout.header)]
    layouts = protocol.framing.layouts
    header_choices = " or ".join(layouts[d].header.hex(" ") for d in Direction)
    either = f"give the direction: requests and responses share the header {layouts[Direction.REQUEST].header.hex(' ')}"
    width = len(layouts[Direction.REQUEST].header)
    for function in frame_functions:
        function["lines"], function["whole_lines"] = lines_of(function["lines"]), lines_of(function["whole_lines"])
    for function in whole_functions:
        function["whole_lines"] = lines_of(function["whole_lines"])
    for picker in whole_pickers:
        picker["lines"] = lines_of(picker["lines"])
    imports = import_lines(checksum_imports)
    if checksum.algorithm.python_calls_function():
        # the general path calls the checksum's function (as every framing's does): defined with what it needs
        imports, definitions = checksum_definitions(protocol)
    return {
        "length_byte_frames": True,
        "requesting": False,
        "reply_to": [],
        "checksum_imports": imports,
        "checksum_definitions": definitions,
        "directions": directions,
        "frame_functions": frame_functions,
        "runs": any(d["runs"] for d in directions),
        "whole_functions": whole_functions,
        "whole_pickers": whole_pickers,
        "dispatchers": dispatchers,
        "size_dispatchers": size_dispatchers,
        "header_choices": header_choices,
        "either": either if protocol.framing.shared_header else "",
        "no_header": f"f\"header is {{data[:{width}].hex(' ')}}, expected {header_choices}\"",
    }


def frame_key(layout: FrameLayout, buf: str, start: str = "") -> str:
    """The expression of a frame's size key (command code and length byte) as the stream parser's tables use it."""
    at = f"{start} + " if start else ""
    length = f"{buf}[{at}{layout.length_offset}]"
    if layout.command_offset is None:
        return length
    return f"{buf}[{at}{layout.command_offset}] << 8 | {length}"


def key_slice(layout: FrameLayout) -> str | None:
    """Where a frame's command code and length byte are neighbours after its header (FEETECH: an id between): the
    slice of `data` holding them, decode()'s key for its whole frames (a short frame's is shorter: it matches
    none, so the lookup comes before any check). None where they are not neighbours."""
    if layout.command_offset is None:
        return None
    low = min(layout.command_offset, layout.length_offset)
    if max(layout.command_offset, layout.length_offset) != low + 1 or low < len(layout.header):
        return None
    return f"data[{low}:{low + 2}]"


def slice_bytes(layout: FrameLayout, key: str) -> str:
    """A size key (command code << 8 | length byte, as fixed_frames makes it) as the bytes key_slice reads."""
    value = int(key, 16)
    assert layout.command_offset is not None  # key_slice holds it
    by_offset = {layout.command_offset: value >> 8, layout.length_offset: value & 0xFF}
    return repr(bytes(by_offset[o] for o in sorted(by_offset)))


def slice_rest(layout: FrameLayout, rest: dict[str, Any]) -> dict[str, Any]:
    """rest_key's entries as the bytes key_slice reads: the key's expression in the length byte `n`."""
    assert layout.command_offset is not None  # key_slice holds it
    by_offset = {layout.command_offset: f"{rest['code'] or 0:#04x}", layout.length_offset: "n"}
    key = f"bytes(({', '.join(by_offset[o] for o in sorted(by_offset))}))"
    low, high = rest["lengths"]
    return {"key": key, "low": low, "high": high, "adds": rest["adds"], "name": rest["whole_name"]}


def rest_key(layout: FrameLayout, rest: dict[str, Any], by_bytes: bool) -> dict[str, Any]:
    """decode()'s table entries of a frame that takes the rest (rest_frames), one per length byte `n`: the key's
    expression in `n` (first bytes as whole_frames makes them, or the size key as frame_key), the range of `n`,
    and the frame size less `n`."""
    code = rest["code"] or 0
    if by_bytes:  # header, then command code and length byte in offset order
        key = " + ".join(
            [
                repr(layout.header),
                *(
                    "bytes((n,))" if o == layout.length_offset else repr(bytes([code]))
                    for o in sorted(o for o in (layout.command_offset, layout.length_offset) if o is not None)
                ),
            ]
        )
    else:
        key = f"{code:#04x} << 8 | n" if layout.command_offset is not None else "n"
    low, high = rest["lengths"]
    return {"key": key, "low": low, "high": high, "adds": rest["adds"], "name": rest["whole_name"]}


def length_byte_whole_frames(
    layout: FrameLayout, fixed: list[tuple[str, int, dict[str, Any]]]
) -> list[tuple[str, int, str, tuple[str, str] | None]]:
    """decode()'s table of the frames decoded whole, keyed by their first bytes when those are the header, command
    code and length byte (one slice, one lookup, and the header is checked with them); [] where they are not."""
    width = len(layout.header)
    offsets = sorted(o for o in (layout.command_offset, layout.length_offset) if o is not None)
    if offsets != list(range(width, width + len(offsets))):
        return []
    entries = []
    for key, size, function in fixed:
        value = int(key, 16)
        bytes_at = {layout.length_offset: value & 0xFF}
        if layout.command_offset is not None:
            bytes_at[layout.command_offset] = value >> 8
        key_bytes = repr(layout.header + bytes(bytes_at[o] for o in offsets))
        entries.append((key_bytes, size, function["whole_name"], function.get("plain")))
    return entries


def frame_decode_lines(protocol: Protocol, layout: FrameLayout, dispatch: list[tuple[str, str]]) -> Lines:
    """Checksum check, then dispatch to the content decoder, of a frame buf[start:stop] whose header and length the
    stream parser has checked (decode() checks whole frames as every framing does: decode.decode_lines)."""
    size = layout.checksum_offset_from_end
    offset = layout.offsets[next(e.name for e in layout.elements if e.role == "content")]
    after = layout.overhead - offset

    def at(position: int) -> str:
        return f"buf[start + {position}]"

    checksum = protocol.framing.checksum
    assert checksum is not None  # length-byte frames have one
    first = f"start + {layout.covered_from}" if layout.covered_from else "start"
    covered = f"buf[{first} : stop - {layout.covered_to_end}]"
    stored = "buf[stop - 1]" if size == 1 else f"int.from_bytes(buf[stop - {size} : stop], 'little')"
    content = f"start + {offset}, stop - {after}"
    args = f"buf, {content}" + "".join(f", {at(layout.offsets[e.name])}" for e in layout.value_elements)
    lines = [f"check = {stored}"]  # read once: the sum and the comparison both use it
    lines += checksum_lines(checksum, covered, "expected")
    lines += [
        "if expected != check:",
        # as wide as the checksum: a u16 that reads 0 is 0x0000
        f'    raise ChecksumError(f"bad checksum: the frame has {{check:#0{2 + 2 * size}x}}, '
        f'its bytes give {{expected:#0{2 + 2 * size}x}}")',
    ]
    if layout.command_offset is None:  # the one codeless command of this direction, if any
        if not dispatch:
            return [*lines, f'raise DecodeError("no {layout.direction.value} is defined")']
        return [*lines, f"return {dispatch[0][1]}({args})"]
    code = at(layout.command_offset)
    return [
        *lines,
        f"decoder = _{layout.direction.name}_DECODERS.get({code})",
        "if decoder is None:",
        f'    raise DecodeError(f"unknown command {{{code}:#04x}}")',
        f"return decoder({args})",
    ]


def value_ranges(layout: FrameLayout, byte_order: str) -> str:
    """The frame-level values whose declared range is narrower than their type (an address 0..253, broadcast 254),
    as FrameFormat.value_ranges: (offset, size, byte order, signed, low, high, also allowed); a stream candidate
    holding a value outside its range is no frame."""
    ranges = [
        f"({layout.offsets[e.name]}, {e.type.size}, {byte_order!r}, {e.type.signed}, {int(e.minimum)}, "
        f"{int(e.maximum)}, {e.broadcast})"
        for e in layout.value_elements
        if e.type is not None and not e.type.is_float and (e.minimum, e.maximum) != (e.type.minimum, e.type.maximum)
    ]
    length = layout.length
    limits = None if length is None else length_limits(length)
    if length is not None and limits is not None:  # a length byte outside its range: no frame either
        ranges.append(f"({layout.length_offset}, 1, {byte_order!r}, False, {limits[0]}, {limits[1]}, None)")
    return "(" + ", ".join(ranges) + ("," if len(ranges) == 1 else "") + ")"


def value_range_checks(layout: FrameLayout, byte_order: str) -> list[tuple[str, str, str]]:
    """`decode`'s tests of the frame-level values whose declared range is narrower than their type, as the stream
    parser (value_ranges) makes them; decode checks the header before them. Each: the condition that the value is
    outside its range, the condition that it is inside, and the error raised for it."""
    checks = []
    for e in layout.value_elements:
        if e.type is None or e.type.is_float or (e.minimum, e.maximum) == (e.type.minimum, e.type.maximum):
            continue
        offset, size = layout.offsets[e.name], e.type.size
        indexed = size == 1 and not e.type.signed
        value = (
            f"data[{offset}]"
            if indexed
            else f"int.from_bytes(data[{offset}:{offset + size}], {byte_order!r}, signed={e.type.signed})"
        )
        low, high = int(e.minimum), int(e.maximum)
        shown = f" (or {e.broadcast})" if e.broadcast is not None else ""
        lowest, highest = low, high
        if e.broadcast in (low - 1, high + 1):  # next to the range: one comparison
            lowest, highest = min(low, e.broadcast), max(high, e.broadcast)
        also = f" or {value} == {e.broadcast}" if e.broadcast is not None and lowest == low and highest == high else ""
        if lowest <= e.type.minimum and not also:  # no value of the type is below it
            refused = f"{value} > {highest}"
            inside = f"{value} <= {highest}" if indexed else f"not {refused}"
        elif highest >= e.type.maximum and not also:
            refused = f"{value} < {lowest}"
            inside = f"{value} >= {lowest}" if indexed else f"not {refused}"
        else:
            inside = f"({lowest} <= {value} <= {highest}{also})"
            refused = f"not {inside}"
        error = f'DecodeError(f"{e.name} = {{{value}}} is outside its range {low}..{high}{shown}")'
        checks.append((refused, inside, error))
    return checks


def lookup_lines(d: dict[str, Any]) -> Lines:
    """decode()'s lines, for one direction of the length-byte case, that look a frame `data` up in its table of
    frames decoded whole (by its first bytes, or its command code and length byte) before the general checks; a
    frame the table does not take, or whose decoder refuses it, goes on to them, which say why."""
    accepted = "".join(f" and {c}" for c in d["accepted"])
    early = d["whole_frames"] and not d["range_checks"]
    table, size = f"_{d['upper']}_WHOLE", d["whole_size"]
    by_first_bytes = f"fixed = {table}.get(data[:{size}])  # no key is shorter: a short frame matches none"
    decoded = [
        "    message = fixed[1](data)",
        "    if message is not None:",
        "        return message",
    ]
    if early and d["unpacked"] and d["exact"]:
        return [
            by_first_bytes,
            "if fixed is not None:",
            "    _, whole, unpack, cls = fixed",
            "    try:  # each unpacks the whole frame, so one of another size raises struct.error: no size compared"
            " here",
            "        if unpack is None:",
            "            message = whole(data)",
            "            if message is not None:",
            "                return message",
            f"        elif {d['whole_check']}:  # its message is its content as unpacked: built here, no call",
            "            return _new(cls, unpack(data))",
            "    except struct.error:",
            "        pass  # not the size its first bytes say: the checks below say what is wrong",
        ]
    if early and d["unpacked"]:
        return [
            by_first_bytes,
            "if fixed is not None and fixed[0] == len(data):",
            "    _, whole, unpack, cls = fixed",
            "    if unpack is None:",
            "        message = whole(data)",
            "        if message is not None:",
            "            return message",
            f"    elif {d['whole_check']}:  # its message is its content as unpacked: built here, no call",
            f"        return _new(cls, unpack(data, {d['content_offset']}))",
        ]
    if early:
        return [by_first_bytes, "if fixed is not None and fixed[0] == len(data):", *decoded]
    if d["whole_frames"]:
        return [by_first_bytes, f"if fixed is not None and fixed[0] == len(data){accepted}:", *decoded]
    if d["fixed"] and d["slice_key"]:
        return [
            f"fixed = {table}.get({d['slice_key']})  # a short frame's slice is shorter: it matches none",
            f"if fixed is not None and fixed[0] == len(data) and data[:{d['header_size']}] == {d['header']}{accepted}:",
            *decoded,
        ]
    if d["fixed"]:
        return [
            f"fixed = {table}.get({d['key']}) if len(data) >= {d['overhead']} else None",
            f"if fixed is not None and fixed[0] == len(data) and data[:{d['header_size']}] == {d['header']}{accepted}:",
            *decoded,
        ]
    return []
