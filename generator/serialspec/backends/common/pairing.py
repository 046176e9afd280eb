"""Which response answers which request."""

from __future__ import annotations

from serialspec.backends.common.frames import layout_index
from serialspec.lang.model import Command, Direction, Message, Protocol, refusals_of, replies_by_request, reply_to


def request_response_pairs(protocol: Protocol) -> list[tuple[Message, Message | None]]:
    """Every request with the response that answers it (None where the device stays silent)."""
    messages = protocol.messages()
    replies = replies_by_request(messages)
    return [(m, reply_to(m, replies)) for m in messages if m.direction == Direction.REQUEST]


def asked_commands(protocol: Protocol) -> list[Command]:
    """What a request with `answered_by: {command_in: FIELD}` may ask for: every command with a code and a response
    of its own (commands with sub-commands, error replies and acknowledgements of other requests left out)."""
    return [
        c
        for c in protocol.commands
        if isinstance(c.code, int)
        and c.response is not None
        and not c.subcommands
        and not c.response.error_reply
        and not c.response.request_code  # an acknowledgement answers other requests; nothing asks for it
    ]


def layout_refusals(protocol: Protocol) -> list[tuple[Message, tuple[Message, ...]]]:
    """Replies read in the layout of their request (they carry no code): each reply with the replies that may refuse
    its request (`refused_by`) in another layout, which starts with a header of its own. A frame that is not the
    reply awaited is read as such a refusal when it starts with that header (BNO055: `EE status` refuses a read
    answered by `BB length data`)."""
    if not protocol.framing.by_request(Direction.RESPONSE):
        return []
    layouts = protocol.framing.alternatives[Direction.RESPONSE]
    replies = replies_by_request(protocol.messages())
    found: dict[str, tuple[Message, list[Message]]] = {}
    for request, response in request_response_pairs(protocol):
        if response is None:
            continue
        _, others = found.setdefault(response.key, (response, []))
        for refusal in refusals_of(request, replies):
            index = layout_index(protocol, refusal)
            if index != layout_index(protocol, response) and layouts[index].header and refusal not in others:
                others.append(refusal)
    return [(reply, tuple(others)) for reply, others in found.values() if others]
