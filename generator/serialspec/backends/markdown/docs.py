"""Emit the markdown reference of one protocol: frames, checksum, commands, tables, examples, errata.

Every piece of spec text goes through `cell()` or `text()`, so a `|`, `<` or newline in a description can
neither break a table nor inject HTML into the rendered page, a `{` cannot add attributes (`{: onclick=...}` under
the site's attr_list extension), and a link may only lead to http, https or mailto (`[x](javascript:...)` shows as
text).
"""

from __future__ import annotations

import re
from collections import Counter
from typing import Any, assert_never

from serialspec.backends.common import render as common
from serialspec.backends.common.frames import runtime_layouts
from serialspec.backends.common.numbers import number
from serialspec.backends.common.text import collapse
from serialspec.backends.markdown.kinds import anchor, bit_lines, kind, scalar_range
from serialspec.collection import without_cycle_collection
from serialspec.encodings import bit_run
from serialspec.lang import expression
from serialspec.lang.frozen import mutable
from serialspec.lang.model import (
    VALUE_ROLES,
    Array,
    Bytes,
    Checksum,
    Command,
    Device,
    DeviceModel,
    Direction,
    Discriminator,
    ErratumCheck,
    Example,
    Field,
    FrameElement,
    FrameLayout,
    Group,
    List,
    Message,
    Packed,
    Protocol,
    Scalar,
    TableBlock,
    TableEntry,
    TableValue,
    Text,
    Varint,
    discriminator,
    fixed_size,
    sized_apart,
)
from serialspec.lang.names import mangled, python_name
from serialspec.runtime.errors import SerialspecError

# A `]` that closes a link's text, with the destination after it: `[x](dest` (and `[x]: dest`, see DEFINITION)
LINK_END = re.compile(r"\](?=\s*[(:]\s*(?:&lt;)?\s*([^\s)]*))")
# A reference definition, `[x]: dest` at the start of a line (the text's): it would vanish from the page and turn
# `[y][x]` anywhere on it into a link, so it shows as text
DEFINITION = re.compile(r"\[[^\]]*\]:")
SCHEME = re.compile(r"([A-Za-z][A-Za-z0-9+.-]*):")
SAFE_SCHEMES = frozenset({"http", "https", "mailto"})


def _link_end(match: re.Match[str]) -> str:
    scheme = SCHEME.match(match[1].replace("\\", ""))
    return "\\]" if scheme and scheme[1].lower() not in SAFE_SCHEMES else "]"


def python_package_words(import_name: str) -> str:
    """How a reference page names the Python package to import; a project with a namespace moves the package, and
    the page's words with it (cli/project.py)."""
    return f"Python package: `{import_name}`"


def text(value: str) -> str:
    """Spec text for a markdown paragraph: one line, HTML-significant characters escaped, attribute lists and links
    to other schemes than http, https and mailto (javascript:, data:, vbscript:, ...) shown as text."""
    escaped = collapse(value).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace("{", "\\{")
    escaped = LINK_END.sub(_link_end, escaped)
    return "\\" + escaped if DEFINITION.match(escaped) else escaped


def cell(value: object) -> str:
    """A value for a markdown table cell."""
    return text(str(value)).replace("|", "\\|") or " "


def erratum_check_words(check: ErratumCheck) -> str:
    """What tells the printed reading from the correct one, in words: the reader's own generated code can repeat it."""
    frame = code_span(check.frame.hex(" ").upper() if check.frame is not None else check.frame_text)
    direction = f" (as a {check.direction.value})" if check.direction else ""
    if check.kind == "frame_fails":
        return f"decoding {frame}{direction} fails with an error containing “{check.error}”"
    if check.kind == "frame_decodes_as":
        target = f"`{check.command}`" + (f" / `{check.subcommand}`" if check.subcommand else "")
        return f"{frame}{direction} decodes as {target}"
    if check.kind == "checksum_value":
        wrong = check.claimed if isinstance(check.claimed, str) else f"{check.claimed:#04x}"
        return f"{frame}{direction} verifies with its checksum {check.actual:#04x}; with {wrong} it fails"
    if check.kind == "crc_parameters":
        parameters = check.claimed.items() if isinstance(check.claimed, dict) else ()
        named = ", ".join(
            f"{k} {v:#04X}".replace("0X", "0x") if isinstance(v, int) else f"{k} {v}" for k, v in parameters
        )
        examples = f"{len(check.examples)} examples'" if check.examples else "the examples'"
        return f"the CRC with the claimed parameters ({named or check.claimed}) does not give {examples} check bytes"
    return "none: the correction is explained in words"


def code_span(value: str) -> str:
    """Text shown as printed (an erratum's quote of a document): a code span, so nothing in it is markup, whatever
    backticks it holds (the fence is longer than any run of them inside)."""
    value = collapse(value)
    runs = [len(run) for run in "".join(c if c == "`" else " " for c in value).split()]
    fence = "`" * (max(runs, default=0) + 1)
    padded = f" {value} " if value.startswith("`") or value.endswith("`") else value
    return f"{fence}{padded or ' '}{fence}"


def type_name(f: Field) -> str:
    return kind(f).type_name(f)


def range_text(f: Field) -> str:
    return kind(f).range_text(f)


def meaning(f: Field) -> str:
    parts = [f.description, *kind(f).meaning(f)]
    if mangled(f.name) and not (isinstance(f, Scalar) and f.hidden):  # a hidden field is no attribute
        parts.append(f"(In Python: `{python_name(f.name)}`.)")
    if f.inferred:
        parts.append(f"**Inferred layout:** {f.inferred}")
    return " ".join(p for p in parts if p)


@mutable
class Row:
    offset: str
    name: str
    type: str
    unit: str
    range: str
    meaning: str


def field_rows(fields: tuple[Field, ...], start: int | None, prefix: str = "") -> list[Row]:
    rows = []
    offset = start
    for f in fields:
        size = fixed_size(f)
        where = "" if offset is None else (str(offset) if size in (None, 1) else f"{offset}..{offset + size - 1}")
        if offset is not None and size is None:
            where = f"{offset}.."
        if isinstance(f, Scalar) and (place := f.bit_place) is not None:  # its bytes and bits of its run
            start = None if offset is None else offset if place.first else offset - place.size  # counted at the first
            where = "" if start is None else bit_run.markdown_where(start, place.bits, place.shift, place.size)
        rows.append(Row(where, prefix + f.name, type_name(f), kind(f).unit(f), range_text(f), meaning(f)))
        match f:  # the rows of what it holds
            case Group():
                rows += field_rows(f.fields, None, prefix + f.name + "[].")
            case TableBlock():
                rows += [
                    Row(
                        "",
                        f"{prefix}{f.name}.{e.name}",
                        e.type.name,
                        e.unit,
                        scalar_range(e.type, e.minimum, e.maximum),
                        f"{f.table.key_name} {e.key}: {e.description}",
                    )
                    for e in f.entries
                ]
            case Scalar() | Varint() | Array() | Packed() | List() | Text() | Bytes() | TableValue():
                pass  # one row
            case _:
                assert_never(f)
        offset = None if offset is None or size is None else offset + size
    return rows


def message_context(protocol: Protocol, message: Message | None) -> dict[str, Any] | None:
    if message is None:
        return None
    layout = protocol.layout(message)
    content = next((e.name for e in layout.elements if e.role == "content"), None)
    content_offset = layout.offsets[content] if content is not None else layout.overhead  # a bare frame: none
    size = size_text(message.min_size, message.max_size, content_limit(layout))
    if message.padded is not None:
        size = f"{size_text(message.padded, message.padded, None)}, sent without its trailing zero bytes (at least 1)"
    rows = [
        Row(_value_offset(layout, e), e.name, e.type.name if e.type else "", "", "", e.description)
        if any(x.name == e.name for x in layout.elements)
        else _partial_row(protocol, message, e)
        for e in layout.value_elements
    ]
    rows += field_rows(message.fields, content_offset)
    rows += [
        Row(
            "after the content",
            e.name,
            f"{e.size} bytes or none",
            "",
            "",
            f"bit {e.present_if[1]:#04x} of `{e.present_if[0]}` set: sent; None: not sent. {e.description}",
        )
        for e in layout.optional
    ]
    return {
        "direction": message.direction.value,
        "rows": [{k: cell(v) for k, v in vars(r).items()} for r in rows],
        "size": size,
        "optional": text(message.optional),
        "unsolicited": message.unsolicited or sends_text(protocol, message) != "",
        "sends": sends_text(protocol, message),
        "answers": message.answers,
        "reply": "; ".join(
            part
            for part in (
                f"in layout `{protocol.layout(message).name}`" if protocol.framing.by_command else "",
                shared_request_text(protocol, message),
                reply_text(message, protocol) or error_reply_text(protocol, message),
            )
            if part
        ),
        "description": text(message.description),
    }


def shared_request_text(protocol: Protocol, message: Message) -> str:
    """A request that shares its code with others (or, in frames without a command element, the frame with them),
    or a reply that does where none of them is the `default`: picked by its leading constant
    (lang/model/discriminator.py), else told apart by its content size."""
    if message.subcommand is not None or message.error_reply:
        return ""
    direction = message.direction
    command = protocol.command(message.command)
    coded = protocol.layout(message).has_command
    code = command.wire_code(direction) if coded else None
    sharing = [
        m
        for c in protocol.commands
        if (m := c.request if direction == Direction.REQUEST else c.response) is not None
        and not c.selector
        and not m.error_reply
        and (c.wire_code(direction) if protocol.layout(m).has_command else None) == code
    ]
    others = [m.command for m in sharing if m.command != message.command]
    if not others or not (isinstance(code, int) or code is None):
        return ""
    if not sized_apart(sharing, code is None and protocol.framing.by_request(direction)):
        return ""
    names = ", ".join(f"`{name}`" for name in others)
    shares = f"shares code {code:#04x} with {names}" if code is not None else f"sent without a code as {names} are"
    lead = discriminator(sharing)
    if lead is not None:
        return f"{shares}, {picked_text(lead, message)}"
    return f"{shares}, told apart by the content size"


def picked_text(lead: Discriminator, message: Message) -> str:
    """How a message sharing its code is picked by its leading constant (lang/model/discriminator.py)."""
    value, bits = next((v, b) for v, b, m in lead.picks if m.key == message.key)
    shown = f"{value:#x}" if len({b for _, b, _ in lead.picks}) > 1 else str(value)
    return f"chosen by its {message.fields[0].name} ({shown}, the content's first {bits} bits)"


def _partial_row(protocol: Protocol, message: Message, element: FrameElement) -> Row:
    """A frame value some alternative layout does not carry (the Pololu form's device number): where it sits in
    the layouts carrying it; None in the others, a message giving it sent in a layout that carries it."""
    alternatives = protocol.framing.alternatives[message.direction]
    carrying = [layout for layout in alternatives if any(x.name == element.name for x in layout.elements)]
    where = "; ".join(
        f"{_value_offset(layout, layout.elements[layout.index(element.name)])} ({layout.name} frame)"
        for layout in carrying
    )
    others = ", ".join(layout.name for layout in alternatives if layout not in carrying)
    said = f"None in the {others} frame: a message giving it is sent in the {carrying[0].name} frame."
    description = f"{element.description} {said}" if element.description else said
    return Row(where, element.name, element.type.name if element.type else "", "", "", description)


def _value_offset(layout: FrameLayout, element: FrameElement) -> str:
    """Where a frame-level value sits: its offset, or (after a content whose size varies) its place from the end."""
    if element.name in layout.offsets:
        return str(layout.offsets[element.name])
    index = layout.elements.index(element)
    back = sum(e.size or 0 for e in layout.elements[index:])
    return f"{back} from the end"


def device_rule_text(protocol: Protocol, name: str) -> str:
    """What the device's rules say of one memory entry: what it reads as, and when it cannot be written."""
    device = protocol.device
    if device is None or device.memory is None:
        return ""
    found = ""
    if name in device.derived:
        found += f" Reads as {expression.show(device.derived[name])}."
    if name in device.locks:
        found += f" Not writable while {device.locks[name]} is non-zero."
    return found


def sends_text(protocol: Protocol, message: Message) -> str:
    """When the device sends this response on its own (`device.sends`), or ""."""
    device = protocol.device
    send = next((s for s in device.sends if s.command == message.key), None) if device else None
    if send is None or message.direction != Direction.RESPONSE:
        return ""
    when = [f"every {period_text(send.every)} ms"] if send.every else []
    when += [f"after the reply to {', '.join(f'`{n}`' for n in send.after)}"] if send.after else []
    when += [f"when {', '.join(f'`{n}`' for n in send.changes)} changes"] if send.changes else []
    return " or ".join(when) + (f", while `{send.while_}` is non-zero" if send.while_ else "")


def period_text(every: int | expression.Expr) -> str:
    """`every` as the docs show it: a number of ms, or the expression that gives it (`1000 / rate_hz`)."""
    return str(every) if isinstance(every, int) else f"`{expression.show(every)}`"


def content_limit(layout: FrameLayout) -> int | None:
    """The most content bytes the frame's length element can count (None: no length element)."""
    length = next((e for e in layout.elements if e.role == "length" and e.type is not None), None)
    return None if length is None or length.type is None else (1 << 8 * length.type.size) - 1 - layout.length_adds


def size_text(low: int, high: int | None, limit: int | None) -> str:
    if limit is not None and (high is None or high > limit):
        high = limit
    if high == low:
        return f"{low} byte" + ("" if low == 1 else "s")
    return f"{low}..{high} bytes" if high is not None else f"{low} bytes or more"


def reply_text(message: Message, protocol: Protocol | None = None) -> str:
    """For a request answered by another command's response: which, and the parameter that switches it; for a
    response that shares its code with other replies: how a reply is told to have this layout."""
    if message.direction == Direction.RESPONSE and protocol is not None:
        parts = [shared_reply_text(protocol, message)]
        if message.request_code:
            parts.append(f"`{message.request_code}` holds the code of the request it answers")
        return "; ".join(p for p in parts if p)
    if not message.answered_by and not message.asks_in and not message.refused_by:
        return ""
    switch = message.reply_when
    when = f", sent only while `{switch.entry}` {switch.symbol} {switch.equals}" if switch else ""
    refusals = ", ".join(f"`{name}`" for name in message.refused_by)
    refused = f"; refused by the {refusals} response (the client raises DeviceError)" if refusals else ""
    if message.asks_in:
        return f"answered by the response of the command whose code `{message.asks_in}` holds{when}{refused}"
    return f"answered by the `{message.answered_by or message.key}` response{when}{refused}"


def error_reply_text(protocol: Protocol, message: Message) -> str:
    """For the error reply: the code it is sent under, and what it carries besides its fields."""
    error = protocol.error_reply
    if not message.error_reply or error is None:
        return ""
    if error.status:
        return (
            f"sent instead of any request's reply, with one of the bits {error.bits:#04x} set in `{error.status}` and "
            f"`{error.element}` = the request's code (the message holds it as `{error.element}`)"
        )
    if not error.flag:
        return (
            f"sent instead of any request's reply, under the header {error.header.hex(' ')} with `{error.element}` = "
            f"the request's code (the message holds it as `{error.element}`)"
        )
    return (
        f"sent instead of any request's reply, with `{error.element}` = the request's code | {error.flag:#04x} "
        f"(the message holds the request's code as `{error.element}`)"
    )


def shared_reply_text(protocol: Protocol, message: Message) -> str:
    """A reply layout that shares its code (or its having none) with others: chosen by the request it answers."""
    layout = protocol.layout(message)  # its own, where layouts are chosen by command
    code = protocol.command(message.command).wire_code(Direction.RESPONSE) if layout.has_command else None
    sharing, asking = reply_sharing(protocol)
    if protocol.framing.by_command and protocol.framing.by_request(Direction.RESPONSE):
        return "read in the layout of the request it answers (decoding it needs that request)"
    if sharing[code] < 2 or shared_request_text(protocol, message):
        return ""  # alone, or told apart by its size (shared_request_text says so)
    askers = sorted(asking.get(message.key, ()))
    answers = ", ".join(f"`{a}`" for a in askers) or "no request"
    peers = [
        m
        for c in protocol.commands
        if (m := c.response) is not None and not m.error_reply and not c.selector
        if (c.wire_code(Direction.RESPONSE) if protocol.layout(m).has_command else None) == code
    ]
    lead = discriminator(peers)
    if lead is not None:  # (read alone, whatever the request)
        return f"the layout of the replies to {answers}; {picked_text(lead, message)}"
    default = (
        "; a reply decoded without its request is read with this layout"
        if message.default_reply
        else "; chosen by the request it answers (the replies share their code)"
    )
    # one layout that cannot size a code-less reply: the reply awaited does
    sized = "; a stream parser takes it only while awaiting it" if protocol.framing.codeless_replies else ""
    return f"the layout of the replies to {answers}{default}{sized}"


_SHARING: dict[int, tuple[Protocol, Counter[int | None], dict[str, set[str]]]] = {}


def reply_sharing(protocol: Protocol) -> tuple[Counter[int | None], dict[str, set[str]]]:
    """Worked out once per protocol (once per message was quadratic in the number of commands): how many plain
    replies share each code (None: replies without one), and the commands whose requests each reply layout
    answers."""
    cached = _SHARING.get(id(protocol))
    if cached is None or cached[0] is not protocol:
        sharing: Counter[int | None] = Counter()
        asking: dict[str, set[str]] = {}
        for m in protocol.messages():
            if m.direction == Direction.REQUEST:
                asking.setdefault(m.answered_by or m.key, set()).add(m.command)
            elif not m.unsolicited and not protocol.command(m.command).subcommands:
                code = protocol.command(m.command).wire_code(Direction.RESPONSE)
                sharing[code if protocol.layout(m).has_command else None] += 1
        _SHARING.clear()  # one protocol at a time: the cache never holds on to old models
        cached = _SHARING[id(protocol)] = (protocol, sharing, asking)
    return cached[1], cached[2]


def code_text(command: Command) -> str:
    """A command's code as the reference shows it, with its replies' own where the command element computes one."""
    if command.code is None:
        return "—"
    reply = command.wire_code(Direction.RESPONSE)
    return f"{command.code:#04x}" + (f", reply {reply:#04x}" if reply != command.code else "")


def command_context(protocol: Protocol, command: Command) -> dict[str, Any]:
    subs = []
    for sub in command.subcommands:
        subs.append(
            {
                "name": sub.name,
                "code": f"{sub.code:#04x}",
                "title": text(sub.title),
                "title_cn": text(sub.title_cn),
                "description": text(sub.description),
                "source": text(sub.source),
                "anchor": anchor("command", command.name, sub.name),
                "messages": same_once(
                    [m for m in (message_context(protocol, sub.request), message_context(protocol, sub.response)) if m]
                ),
                "examples": examples_for(protocol, command.name, sub.name),
            }
        )
    return {
        "name": command.name,
        "code": code_text(command),
        "title": text(command.title),
        "title_cn": text(command.title_cn),
        "description": text(command.description),
        "broadcast": text(command.broadcast),
        "probe": command.probe,
        "source": text(command.source),
        "anchor": anchor("command", command.name),
        "messages": same_once(
            [m for m in (message_context(protocol, command.request), message_context(protocol, command.response)) if m]
        ),
        "subcommands": subs,
        "examples": examples_for(protocol, command.name, None),
    }


def same_once(parts: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """A request and a response (or two frames) that read exactly alike are shown once, for both directions."""
    if len(parts) == 2 and {**parts[0], "direction": ""} == {**parts[1], "direction": ""}:
        return [{**parts[0], "direction": f"{parts[0]['direction']} and {parts[1]['direction']}"}]
    return parts


def examples_for(protocol: Protocol, command: str, subcommand: str | None) -> list[str]:
    return [e.name for e in protocol.examples if (e.command, e.subcommand) == (command, subcommand)]


def frame_picture(protocol: Protocol) -> list[str]:
    """The frame of each direction on one line, columns aligned: `12 4C | cmd_id | length | content (n) | checksum`."""
    lines = []
    for layout in (lay for lays in protocol.framing.alternatives.values() for lay in lays):
        parts = []
        for e in layout.elements:
            if e.fixed:
                parts.append(e.constant.hex(" ").upper())
            elif e.role == "content":
                parts.append(f"{e.name} (n bytes)")
            elif e.role == "optional":
                parts.append(f"[{e.name} ({e.size} bytes)]")
            else:
                parts.append(e.name + (f" ({e.type.size} bytes)" if e.type and e.type.size > 1 else ""))
        lines.append((layout.direction.value + (f" {layout.name}" if layout.name else ""), parts))
    columns = max(len(parts) for _, parts in lines)
    widths = [max(len(p[i]) for _, p in lines if i < len(p)) for i in range(columns)]
    label = max(9, *(len(direction) for direction, _ in lines))
    return [
        direction.ljust(label) + " " + " | ".join(part.ljust(widths[i]) for i, part in enumerate(parts)).rstrip()
        for direction, parts in lines
    ]


def reply_coded(protocol: Protocol, layout: FrameLayout) -> bool:
    """Whether a response layout's command element carries the requests' codes as `reply_code` computes them: every
    layout's, unless layouts are chosen by command and none of this one's commands has a reply code (HLK-LD2410's
    reports beside its ACKs)."""
    framing = protocol.framing
    if not framing.reply_code:
        return False
    if not framing.by_command:
        return True
    return any(
        c.response_code is not None
        and c.response is not None
        and framing.layout_of(Direction.RESPONSE, c.response.layout) == layout
        for c in protocol.commands
    )


def frame_context(protocol: Protocol, layout: FrameLayout) -> dict[str, Any]:
    rows = []
    offset = 0
    variable = False  # past the content (or the stuffed span): offsets vary from frame to frame
    first_variable = layout.transparency.first if layout.transparency else None
    for e in layout.elements:
        size = e.size
        variable = variable or e.name == first_variable
        if e.role == "header" and layout.classic:
            description = " — ".join(p for p in (layout.header.hex(" ").upper(), e.description) if p)
        elif e.fixed:
            description = " — ".join(p for p in (e.constant.hex(" ").upper(), e.description) if p)
        elif e.role == "checksum" and not layout.classic and e.checksum is not None:
            # a byte order only where there are bytes to order
            endian = "" if e.checksum.type.size == 1 else ", big-endian" if e.endian == ">" else ", little-endian"
            left_out = ", ".join(f"`{name}`" for name in e.checksum.skips)
            skips = f" leaving out {left_out}" if left_out else ""
            asked = " and ".join(f"`{name}`" for name in e.checksum.from_request)
            after = f"the request's {asked} (bytes it answers), then " if asked else ""
            description = f"over {after}`{e.checksum.first}`..`{e.checksum.last}`{skips}{endian}. {e.description}"
        elif e.role == "command" and layout.direction == Direction.RESPONSE and reply_coded(protocol, layout):
            computed = f"the code of the request it answers, as `{protocol.framing.reply_code}`"
            description = ". ".join(p for p in (computed, e.description) if p)
        elif e.role == "command" and e.code:
            codes = ", ".join(f"{code:#04x} as {sent:#04x}" for code, sent in e.wire)
            computed = f"each command's code as `{e.code}`" + (f" ({codes})" if codes else "")
            if not layout.header:
                computed += "; this layout has no header: it takes every frame that starts with no other's header"
            description = ". ".join(p for p in (computed, e.description) if p)
        elif e.sequence:
            low, high = number(e.minimum), number(e.maximum)
            counts = f"sequence number the client fills in: {low} first, one more per request, {low} again after {high}"
            description = ". ".join(p for p in (counts, e.description) if p)
        elif e.role == "optional":
            flag, mask = e.present_if
            sent = f"sent only when bit {mask:#04x} of `{flag}` is set (messages: `{e.name}`, None when not sent)"
            description = ". ".join(p for p in (sent, e.description) if p)
        else:
            description = e.description
        if e.bits:
            description = " ".join(p for p in (description, *bit_lines(e.bits)) if p)
        kind = e.type.name if e.type else ("bytes" if e.fixed else "n bytes")
        kind = f"{e.size} bytes" if e.role == "optional" else kind
        if e.role == "length" and layout.classic:
            kind += f" = n + {layout.length_adds}" if layout.length_adds else " = n"
        elif e.role == "length":
            adds = f" {'+' if e.adds > 0 else '-'} {abs(e.adds)}" if e.adds else ""
            endian = ", big-endian" if e.endian == ">" and (e.size or 0) > 1 else ""
            kind += f" = bytes `{e.counts[0]}`..`{e.counts[1]}` as sent{adds}{endian}"
        if e.extended is not None:  # a long form after a marker (`extended:`)
            x = e.extended
            wide = f"u{8 * x.size}"
            long_form = (
                f"{x.short[0]}..{x.short[1]} in one byte; larger, the long form: {x.marker:#04x} then the value as a "
                f"big-endian {wide} ({x.long[0]}..{x.long[1]}), everything after it {x.size} bytes later"
                + (f", its count + {x.adds} (its own bytes)" if x.adds != e.adds else "")
            )
            description = ". ".join(p for p in (long_form, description) if p)
        where = f"{offset}.." if size is None else (str(offset) if size == 1 else f"{offset}..{offset + size - 1}")
        if e.role in ("checksum",) or (offset is None):
            where = "last" if e.role == "checksum" and e.name not in layout.offsets else where
        if variable and e.role not in ("content", "checksum"):
            where = "after the content" if e.role == "trailer" or layout.offsets.get(e.name) is None else where
        if e.role in (*VALUE_ROLES, "command", "length") and e.name not in layout.offsets:
            where = _value_offset(layout, e)  # after a content whose size varies
        if e.role == "optional":
            where = "after the content" if e.name not in layout.offsets else where
        rows.append(
            {
                "offset": cell(where),
                "name": cell(e.name),
                "role": e.role,
                "type": cell(kind),
                "meaning": cell(description),
            }
        )
        offset += size or 0
    title = layout.direction.value.capitalize() + (f" frame, layout `{layout.name}`" if layout.name else " frame")
    return {"direction": layout.direction.value, "title": title, "rows": rows}


def transparency_text(protocol: Protocol) -> str:
    """The byte stuffing or escaping rule, if the frames have one."""
    rules = {layout.transparency for layouts in protocol.framing.alternatives.values() for layout in layouts}
    found = [t for t in rules if t is not None]
    if not found:
        return ""
    t = found[0]
    return text(
        f"From `{t.first}` to `{t.last}`, {t.transform.describe()}: encode applies it, decode and the stream parser "
        f"remove it. A length or checksum over elements within the span counts and covers their plain bytes, one over "
        f"more than the span the bytes as sent. {t.description}"
    )


def checksums_context(protocol: Protocol) -> list[dict[str, Any]]:
    """Every checksum of the (first) layouts; a classic frame's one with a worked example."""
    if protocol.framing.classic:
        return [checksum_context(protocol)]
    found: dict[str, Checksum] = {}
    for layouts in protocol.framing.alternatives.values():
        for layout in layouts:
            for checksum in layout.checksums:
                found.setdefault(checksum.name, checksum)
    return [checksum_context(protocol, checksum) for checksum in found.values()]


def checksum_context(protocol: Protocol, general: Checksum | None = None) -> dict[str, Any]:
    checksum = general or protocol.framing.checksum
    assert checksum is not None
    example = next(iter(protocol.examples), None)
    worked = ""
    if general is not None and example is not None:
        verifies = f"every example's `{checksum.name}` verifies (e.g. `{example.name}`)"
        worked = general_worked(protocol, general) or verifies
    elif example is not None:
        layout = protocol.framing.layouts[example.direction]
        covered = example.frame[layout.covered_from : len(example.frame) - layout.covered_to_end]
        worked = f"{checksum.algorithm.worked(covered)} (example `{example.name}`)"
    label = f" `{checksum.name}`" if general is not None else ""
    return {
        "label": label,
        "what": checksum.algorithm.describe(),
        "first": checksum.first,
        "last": checksum.last,
        "skips": (
            " but for " + ", ".join(f"`{name}`" for name in checksum.skips) + " (checksums inside the span)"
            if checksum.skips
            else ""
        )
        + (
            ", after the bytes of the request's "
            + " and ".join(f"`{n}`" for n in checksum.from_request)
            + " (the request this reply answers)"
            if checksum.from_request
            else ""
        ),
        "worked": worked,
        "params": checksum.algorithm.parameters(),
    }


def general_worked(protocol: Protocol, checksum: Checksum) -> str:
    """The first example whose frame holds the checksum (and no stuffing), worked by the algorithm; "" for none."""
    for example in protocol.examples:
        layouts = runtime_layouts(protocol, example.direction)
        layout = next((lay for lay in layouts if example.frame.startswith(lay.header)), layouts[0])
        index = next((i for i, e in enumerate(layout.elements) if e.name == checksum.name), None)
        if index is None or layout.transparency is not None:
            continue
        try:
            layout = layout.variant(example.frame)
            parts = layout.unwrap(example.frame).parts
        except SerialspecError:
            continue
        index = next((i for i, e in enumerate(layout.elements) if e.name == checksum.name), None)
        if index is None:
            continue
        first, last = layout.elements[index].span
        skip = layout.elements[index].skip
        covered = b"".join(parts[i] for i in range(first, last + 1) if i not in skip)
        return f"{checksum.algorithm.worked(covered)} (example `{example.name}`)"
    return ""


def general_breakdown(protocol: Protocol, example: Example, message: Message | None) -> list[dict[str, str]]:
    """An example frame of any layout, element by element (unstuffed) and field by field, by the frame engine."""
    layouts = runtime_layouts(protocol, example.direction)
    layout = next((lay for lay in layouts if example.frame.startswith(lay.header)), layouts[0])
    try:
        layout = layout.variant(example.frame)  # with optional elements: the variant the frame is sent in
        unwrapped = layout.unwrap(example.frame)
    except SerialspecError as exc:  # the example verification reports it as a spec error; the page says it too
        return [{"bytes": example.frame.hex(" ").upper(), "field": "(frame)", "value": cell(f"does not decode: {exc}")}]
    rows: list[dict[str, str]] = []
    for e, part in zip(layout.elements, unwrapped.parts, strict=True):
        if e.kind == "content" and message is not None:
            rows += content_rows(message.fields, example.fields, part, 0, len(part), picking(protocol, example))
            continue
        value: Any = example.fields.get(e.name, "")
        if e.kind == "command":
            value = example.command
        elif e.kind == "length":
            counted = f"bytes `{layout.elements[e.span[0]].name}`..`{layout.elements[e.span[1]].name}`"
            long_form = f"; {part[0]:#04x}: the long form" if e.lead else ""  # (an extended length's marker byte)
            value = f"{e.unpack(part) - e.lead} ({counted}{long_form})"
        elif e.kind == "checksum":
            value = "verifies"
        elif e.kind == "extra":
            value = "(sent: its flag bit is set)"
        rows.append({"bytes": part.hex(" ").upper(), "field": e.name, "value": cell(_show(value))})
    return rows


def breakdown(protocol: Protocol, example: Example) -> list[dict[str, str]]:
    """Byte spans of an example frame, element by element and field by field, with the values."""
    if not protocol.framing.classic:
        command = protocol.command(example.command)
        holder = next((s for s in command.subcommands if s.name == example.subcommand), None) or command
        return general_breakdown(
            protocol, example, holder.request if example.direction == Direction.REQUEST else holder.response
        )
    layout = protocol.framing.layouts[example.direction]
    command = protocol.command(example.command)
    sub = next((s for s in command.subcommands if s.name == example.subcommand), None)
    holder = sub or command
    message = holder.request if example.direction == Direction.REQUEST else holder.response
    frame = example.frame
    if len(frame) < layout.overhead:  # the example verification reports it as a spec error; the page says it too
        short = f"does not decode: {len(frame)} bytes, fewer than the frame's {layout.overhead} without content"
        return [{"bytes": frame.hex(" ").upper(), "field": "(frame)", "value": cell(short)}]
    rows: list[dict[str, str]] = []
    offset = 0
    content_size = len(frame) - layout.overhead
    for e in layout.elements:
        size = content_size if e.role == "content" else (e.size or 0)
        if e.role == "content" and message is not None:
            rows += content_rows(
                message.fields, example.fields, frame, offset, offset + size, picking(protocol, example)
            )
        else:
            value = example.fields.get(e.name, "")
            if e.role == "command":
                value = f"{command.name}"
            elif e.role == "length":
                value = f"{frame[offset]} ({content_size} content bytes)"
            elif e.role == "checksum":
                value = "verifies"
            rows.append(
                {
                    "bytes": frame[offset : offset + size].hex(" ").upper(),
                    "field": e.name,
                    "value": cell(_show(value)),
                }
            )
        offset += size
    return rows


def picking(protocol: Protocol, example: Example) -> str:
    """Which of an example's constant fields pick its message: `all` in a sub-command (its selector), `first` where
    commands share its code (the first field, RTCM 3's message number), else `none` (a reserved or magic value)."""
    if example.subcommand is not None:
        return "all"
    code = protocol.command(example.command).code
    return "first" if sum(c.code == code for c in protocol.commands) > 1 else "none"


def content_rows(
    fields: tuple[Field, ...], values: dict[str, Any], frame: bytes, start: int, end: int, picks: str = "all"
) -> list[dict[str, str]]:
    rows = []
    offset = start
    for index, f in enumerate(fields):
        size = fixed_size(f)
        value: Any = values.get(f.name, "")
        if isinstance(f, Scalar) and f.const is not None:
            selects = picks == "all" or (picks == "first" and index == 0)
            value = f"{f.const:#04x} ({'selector' if selects else 'constant'})"
        elif isinstance(f, Scalar) and f.derived:
            target = values.get(f.derived[1], [])
            value = (
                f"{frame[offset] if offset < end else ''} (derived)"
                if f.derived[0] == "count" or not target
                else "derived"
            )
        if isinstance(f, Scalar) and (place := f.bit_place) is not None:  # the bytes it touches
            _, first, last = bit_run.span(place.bits, place.shift, place.size)
            shown = "derived" if f.derived else value
            rows.append(
                {
                    "bytes": frame[offset + first : offset + last + 1].hex(" ").upper(),
                    "field": f.name,
                    "value": cell(_show(shown)),
                }
            )
            offset += place.size if place.last else 0
            continue
        if size is None:
            if isinstance(f, Group):
                items = values.get(f.name)  # recorded values; a malformed record is a spec error of its own
                count = len(items) if isinstance(items, list) else 0
                item = f.item_size
                size = count * item if item is not None else end - offset
            else:  # the rest of the content
                size = end - offset
        rows.append(
            {
                "bytes": frame[offset : offset + size].hex(" ").upper(),
                "field": f.name,
                "value": cell(_show(value)),
            }
        )
        offset += size
    return rows


def _show(value: Any) -> str:
    if isinstance(value, bool):  # coils and other single bits, as the documents print them
        return str(int(value))
    if isinstance(value, dict):
        return ", ".join(f"{k}={_show(v)}" for k, v in value.items())
    if isinstance(value, list):
        return "[" + "; ".join(_show(v) for v in value) + "]"
    return str(value)


@without_cycle_collection
def emit_docs(protocol: Protocol) -> str:
    if protocol.text is not None:  # a text protocol's page (it takes this module's text helpers)
        from serialspec.backends.markdown.text import text_docs

        return text_docs(protocol, protocol.text)
    commands = [command_context(protocol, c) for c in protocol.commands]
    examples = [
        {
            "name": e.name,
            "source": text(e.source),
            "description": text(e.description),
            "direction": e.direction.value,
            "command": e.command + (f".{e.subcommand}" if e.subcommand else ""),
            "anchor": anchor("command", e.command, e.subcommand or ""),
            "printed": code_span(e.printed),
            "frame": e.frame.hex(" ").upper(),
            "text": e.printed_text is not None,
            "erratum": e.erratum,
            "partial": e.printed_span != (0, 0),
            "completed": text(e.completed),
            "rows": breakdown(protocol, e),
        }
        for e in protocol.examples
    ]
    tables = [
        {
            "name": t.name,
            "anchor": anchor("table", t.name),
            "title": text(t.title),
            "key": t.key_name,
            "description": text(t.description),
            "source": text(t.source),
            "rows": [
                {
                    "key": f"{e.key}" if t.key_name != "address" else f"{e.key:#04x}",
                    "name": cell("(reserved)" if e.reserved else e.name)
                    + (f"<br>{cell(e.name_cn)}" if e.name_cn else ""),
                    "type": e.type.name + sign_note(e) + (f", {cell(e.unit)}" if e.unit else ""),
                    "range": scalar_range(e.type, e.minimum, e.maximum),
                    "default": cell("" if e.default is None else e.default),
                    "access": e.access + (f", {e.memory}" if e.memory else ""),
                    "meaning": cell(
                        e.description
                        + (f" Values: [{e.enum.class_name}](#enum-{anchor(e.enum.name)})." if e.enum else "")
                        + device_rule_text(protocol, e.name)
                    ),
                }
                for e in t.entries
            ],
        }
        for t in protocol.tables
    ]
    enums = [
        {
            "name": e.name,
            "class_name": e.class_name,
            "anchor": anchor("enum", e.name),
            "description": text(e.description) or used_by(protocol, e),
            "values": [{"value": v.value, "name": v.name.lower(), "text": cell(v.text) or "—"} for v in e.values],
        }
        for e in protocol.enums
    ]
    flags = [
        {
            "name": f.name,
            "class_name": f.class_name,
            "anchor": anchor("flags", f.name),
            "description": text(f.description) or used_by(protocol, f),
            "bits": [{"bit": b.bit, "name": b.name.lower(), "text": cell(b.text) or "—"} for b in f.bits],
        }
        for f in protocol.flags
    ]
    errata = [
        {
            "name": e.name,
            "source": text(e.source),
            "printed": code_span(e.printed),
            "correct": text(e.correct),
            "check": erratum_check_words(e.check),
        }
        for e in protocol.errata
    ]
    serial = protocol.serial
    device = protocol.device
    return common.render(
        "serialspec.backends.markdown",
        "docs.md.j2",
        models=[model_context(device, m) for m in device.models] if device else [],
        model_entry=device.model_entry if device else "",
        protocol=protocol,
        python_package=python_package_words(protocol.name),
        title=text(protocol.title),
        description=text(protocol.description),
        sources=[(k, text(v)) for k, v in protocol.sources.items()],
        serial=[
            ("baud rate", serial.baudrate),
            *([("baud rates a device can be set to", ", ".join(map(str, serial.baudrates)))] * bool(serial.baudrates)),
            ("data bits", serial.bytesize),
            ("parity", serial.parity),
            ("stop bits", number(serial.stopbits)),
            ("byte order", protocol.byte_order + "-endian"),
        ],
        serial_notes=text(serial.notes),
        presence=presence_text(protocol),
        framing=text(protocol.framing.description),
        frames=same_once(
            [frame_context(protocol, lay) for lays in protocol.framing.alternatives.values() for lay in lays]
        ),
        frame_picture=frame_picture(protocol),
        transparency=transparency_text(protocol),
        shared_header=protocol.framing.shared_header,
        has_header=any(layout.header for layout in protocol.framing.layouts.values()),
        reply_code=text(protocol.framing.reply_code),
        gap=number(protocol.framing.gap) if protocol.framing.gap else "",
        turnaround=number(protocol.framing.turnaround) if protocol.framing.turnaround else "",
        checksums=checksums_context(protocol),
        matching=", ".join(protocol.matching),
        matching_description=text(protocol.matching_description),
        commands=commands,
        # the index's column of the titles as the (Chinese) documents print them, where a command has one
        titles_cn=any(c["title_cn"] or any(s["title_cn"] for s in c["subcommands"]) for c in commands),
        tables=tables,
        enums=enums,
        flags=flags,
        examples=examples,
        errata=errata,
    )


def presence_text(protocol: Protocol) -> str:
    """The device's `presence:` in words: what `serialspec scan` asks, which ids, and where the model is."""
    presence = protocol.device.presence if protocol.device else None
    if presence is None:
        return ""

    def request(key: str, values: dict[str, float]) -> str:
        given = ", ".join(f"{name} = {number(value)}" for name, value in values.items())
        return f"`{key}`" + (f" ({given})" if given else "")

    if presence.ids is not None:
        first, last = presence.ids
        each = f"{request(presence.request, presence.fields)} to each id {first}..{last}"
        asked = f"sends {each}"
        if presence.broadcast:
            asked = (
                f"sends {request(presence.request, presence.fields)} to the broadcast id once, which every device "
                f"answers in turn (and {each} when none does)"
            )
    else:
        asked = f"sends {request(presence.request, presence.fields)} (one device per port: no id)"
    words = [f"`serialspec scan {protocol.spec_path} --port PORT` {asked}; any reply, an error reply too, is a device."]
    if presence.model_field:
        where = f"`{presence.model_field}`"
        if presence.model_register is not None:
            where = f"register `{presence.model_register.name}` in {where}"
        source = (
            "its reply"
            if presence.model_request == presence.request and not presence.model_fields
            else (f"the reply to {request(presence.model_request, presence.model_fields)}")
        )
        words.append(f"The model is {where} of {source}.")
    if protocol.serial.baudrates:
        words.append("`--all-baudrates` tries every rate above.")
    if presence.description:
        words.append(text(presence.description))
    return " ".join(words)


def model_context(device: Device, model: DeviceModel) -> dict[str, Any]:
    """One model: its values and where its entries differ from the table, one row per entry, in table order."""
    table = {e.name: e for e in device.memory.entries} if device.memory else {}
    names = [n for n in table if n in model.initial or model.entry(n)]
    names += [n for n in model.initial if n not in table]  # state variables
    rows = []
    for name in names:
        entry, override = table.get(name), model.entry(name)
        bounds = override or entry
        rows.append(
            {
                "name": name,
                "value": number(model.initial[name]) if name in model.initial else "",
                "range": f"{number(bounds.minimum)}..{number(bounds.maximum)}" if bounds else "",
                "unit": cell(override.unit if override else entry.unit if entry else ""),
                "note": cell(override.description if override else ""),
            }
        )
    return {
        "name": model.name,
        "number": model.number,
        "anchor": anchor("model", model.name),
        "title": cell(model.title),
        "description": text(model.description),
        "source": text(model.source),
        "rows": rows,
    }


def used_by(protocol: Protocol, values: Any) -> str:
    """Where an enum or flag set is used, for one that has no description of its own."""
    users = dict.fromkeys(
        [
            f"`{m.key}` {m.direction.value} `{f.name}`"
            for m in protocol.messages()
            for f in m.fields
            if isinstance(f, Scalar) and values in (f.enum, f.flags)
        ]
        + [f"`{t.name}` entry `{e.name}`" for t in protocol.tables for e in t.entries if values in (e.enum, e.flags)]
    )
    return ("Values of " + ", ".join(users) + ".") if users else ""


def sign_note(entry: TableEntry) -> str:
    if not entry.sign_magnitude:
        return ""
    top = entry.type.size * 8 - 1
    return " sign-magnitude" + ("" if entry.sign_bit in (None, top) else f" (sign in bit {entry.sign_bit})")
