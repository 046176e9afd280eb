"""Which response answers which request."""

from __future__ import annotations

from serialspec.lang.model import Command, Direction, Message, Protocol, replies_by_request, reply_to


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
