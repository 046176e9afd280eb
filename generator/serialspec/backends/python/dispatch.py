"""Which content decoder a frame's command code names, in each direction, and the codec's names of each message's
functions: shared by every frame shape."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from serialspec.lang.model import (
    Command,
    Direction,
    Discriminator,
    FrameLayout,
    Message,
    Protocol,
    discriminator,
    sized_apart,
    sizes_text,
    sizing_lead,
    sizing_message,
)


def message_function(verb: str, message: Message) -> str:
    """The codec's name of a function of one message (`_<verb>_<key>_<direction>`): its decoder, encoder, ..."""
    return f"_{verb}_{message.key.replace('.', '_')}_{message.direction.value}"


def decoder_name(message: Message) -> str:
    return message_function("decode", message)


def encoder_name(message: Message) -> str:
    return message_function("encode", message)


ERROR_REPLY = "ERROR_REPLY"  # the codes key of error replies (runtime.framing.ERROR_REPLY)


def value_arguments(layout: FrameLayout) -> dict[str, str]:
    return {
        "extra": "".join(f", {e.name}: int" for e in layout.value_elements)
        + "".join(f", {e.name}: bytes | None = None" for e in layout.optional),
        "args": "".join(f", {e.name}" for e in (*layout.value_elements, *layout.optional)),
    }


def direction_entry(
    command: Command, direction: Direction, byte_order: str = "little"
) -> tuple[str, int, int | None, dict[str, Any]] | None:
    """The decoder a command code dispatches to in one direction, the content size bounds, any sub-dispatch (its
    selector read as the integer of its type, in the protocol's `byte_order`: HCI's u16 opcode)."""
    if command.selector is None:
        message = command.request if direction == Direction.REQUEST else command.response
        if message is None:
            return None
        return decoder_name(message), message.min_size, message.max_size, {}
    messages = [
        m for s in command.subcommands if (m := s.request if direction == Direction.REQUEST else s.response) is not None
    ]
    if not messages:
        return None
    low = min(m.min_size for m in messages)
    high = None if any(m.max_size is None for m in messages) else max(m.max_size or 0 for m in messages)
    name = f"_decode_{command.name}_{direction.value}"
    table = f"_{command.name.upper()}_{direction.name}_SUBCOMMANDS"
    entries = [
        (f"{s.code:#04x}", decoder_name(m))
        for s in command.subcommands
        if (m := s.request if direction == Direction.REQUEST else s.response) is not None
    ]
    offset, selector = command.selector.offsets[direction], command.selector.type
    read = (
        f"buf[o + {offset}]"
        if selector.size == 1 and not selector.signed
        else f"int.from_bytes(buf[o + {offset} : o + {offset + selector.size}], {byte_order!r}"
        + (", signed=True)" if selector.signed else ")")
    )
    sub = {
        "name": name,
        "offset": offset,
        "end": offset + selector.size,
        "read": read,
        "table": table,
        "entries": entries,
        "where": f"{command.name} {direction.value}",
    }
    return name, low, high, sub


def size_dispatch(key: str, code: int | None, direction: Direction, messages: list[Message]) -> dict[str, Any]:
    """Requests (or replies none of which is the default) that share one code (`key` in the dispatch table, `code`
    the number or None for frames without one): the decoder that picks one by their leading constant or else by the
    content size (the resolver checked that no size fits two), for the code's entry in the dispatch table."""
    code_name = "none" if code is None else f"{code:02x}"
    lead = discriminator(messages)
    found: dict[str, Any] = {
        "name": f"_decode_{direction.value}_{code_name}_by_size",
        "ranges": [(m.min_size, m.max_size, decoder_name(m)) for m in sorted(messages, key=lambda m: m.min_size)],
        "where": f"{direction.value} {key}" if code is not None else f"{direction.value} without a code",
        "sizes": ", ".join(f"{m.command}: {sizes_text(m)}" for m in messages),
        "lead": None,
        "who": "Requests" if direction == Direction.REQUEST else "Replies",
    }
    if lead is not None:  # picked by their leading constant (lang/model/discriminator.py) rather than by size
        found["name"] = f"_decode_{direction.value}_{code_name}_by_{lead.name}"
        found["lead"] = {
            "size": lead.size,
            "endian": lead.endian,
            "shift": lead.shift,
            "mask": f"{lead.mask:#x}",
            "field": lead.name,
            "bits": lead.bits,
            "table": f"_{direction.name}_{code_name.upper()}_BY_{lead.name.upper()}",
            "entries": [(value, decoder_name(m)) for value, m in lead.values],
            "known": lead.known(),
            "mixed": len({bits for _, bits, _ in lead.picks}) > 1,
            "who": "Requests" if direction == Direction.REQUEST else "Replies",
        }
    return found


def shared_codes(protocol: Protocol, direction: Direction) -> set[int]:
    """The codes several messages of a direction share, told apart by their content size: requests' codes, and
    replies' where none of those sharing it is the `default`."""
    users: dict[int, list[Message]] = {}
    for command in protocol.commands:
        message = command.request if direction == Direction.REQUEST else command.response
        code = command.wire_code(direction)
        if message is not None and code is not None and not message.error_reply:
            users.setdefault(code, []).append(message)
    return {code for code, messages in users.items() if sized_apart(messages)}


def code_key(command: Command, layout: FrameLayout) -> str:
    """A command's key in its direction's table of decoders: its code as the frame carries it, "None" for a frame
    without one, ERROR_REPLY for error replies (any code with the error flag: runtime.framing)."""
    if any(m.error_reply for m in command.messages()):
        return ERROR_REPLY
    code = command.wire_code(layout.direction)
    return "None" if code is None or not layout.has_command else f"{code:#04x}"


@dataclass
class DirectionDispatch:
    """One direction's decoders by code, whatever the frame shape: the table (code key -> decoder), each code's
    content size bounds, the message of each code only one message has, the replies chosen by the request they
    answer (class, code key, decoder), and the sub-command and content-size dispatchers the table names."""

    dispatch: list[tuple[str, str]] = field(default_factory=list)
    sizes: list[tuple[str, int, int | None]] = field(default_factory=list)
    single: dict[str, Message] = field(default_factory=dict)
    # each code's content size rule's message: its one message, or one of the requests sharing it, all of one fixed
    # size (picked by a leading constant: iRobot's sensor queries, 8E and a packet id)
    # or the leading constant that picks the message sizing it, each of its own size (Kondo ICS)
    sized: dict[str, Message | Discriminator] = field(default_factory=dict)
    expected: list[tuple[str, str, str]] = field(default_factory=list)
    dispatchers: list[dict[str, Any]] = field(default_factory=list)
    size_dispatchers: list[dict[str, Any]] = field(default_factory=list)


def direction_dispatch(protocol: Protocol, direction: Direction) -> DirectionDispatch:
    """The direction's decoders by code (see DirectionDispatch)."""
    layout = protocol.framing.layouts[direction]
    found = DirectionDispatch()
    by_code: dict[str, list[tuple[Message | None, str, int, int | None]]] = {}
    codes: dict[str, int | None] = {}  # each key's code (None: frames without one)
    # each key's messages whose size rules may size its frames: a command's, or its sub-commands' in the direction
    # (the sensor queries of iRobot's OI: 8E and a packet id, sub-commands by that id, all two bytes)
    sizers: dict[str, list[Message]] = {}
    for command in protocol.commands:
        entry = direction_entry(command, direction, protocol.byte_order)
        if entry is None:
            continue
        target, low, high, sub_dispatch = entry
        # its own layout, where layouts are chosen by command (`layout:`): frames of a layout without a command
        # element carry no code, and it carries its own frame values
        own = protocol.layout(next(m for m in command.messages() if m.direction == direction))
        if sub_dispatch:
            found.dispatchers.append(sub_dispatch | value_arguments(own))
        message = None if sub_dispatch else command.request if direction == Direction.REQUEST else command.response
        key = code_key(command, own)
        by_code.setdefault(key, []).append((message, target, low, high))
        codes[key] = command.wire_code(direction) if own.has_command else None
        if sub_dispatch:
            sizers.setdefault(key, []).extend(m for m in command.messages() if m.direction == direction)
        elif message is not None:
            sizers.setdefault(key, []).append(message)
    for key, users in by_code.items():
        # the resolver allows several only for plain replies, one of them marked default, and for requests told
        # apart by their content size
        chosen = next((u for u in users if u[0] is not None and u[0].default_reply), users[0])
        # requests, and replies none of which is the default (unless read in their request's layout), that share a
        # code: told apart by their content size
        messages = [m for m, _, _, _ in users if m is not None]
        by_size = len(users) > 1 and sized_apart(
            messages, codes[key] is None and protocol.framing.by_request(direction)
        )
        if by_size:
            sized = size_dispatch(key, codes[key], direction, messages)
            found.size_dispatchers.append(sized | value_arguments(layout))
            chosen = (None, sized["name"], 0, None)
        found.dispatch.append((key, chosen[1]))
        highs = [u[3] for u in users]
        found.sizes.append((key, min(u[2] for u in users), None if None in highs else max(h or 0 for h in highs)))
        if len(users) == 1 and users[0][0] is not None:
            found.single[key] = users[0][0]
        messages = [m for m, _, _, _ in users if m is not None]
        if len(messages) == len(users):
            sizing = sizing_message(messages) or sizing_lead(messages)
        else:  # sub-commands: sized where they are all of one fixed size
            subs = sizers.get(key, [])
            sizing = sizing_message(subs) if len(subs) > 1 and all(m.subcommand is not None for m in subs) else None
        if sizing is not None:
            found.sized[key] = sizing
        if direction == Direction.RESPONSE and not by_size:
            found.expected += [(m.class_name, key, t) for m, t, _, _ in users if m is not None and len(users) > 1]
    return found
