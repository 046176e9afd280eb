"""Which response answers which request."""

from __future__ import annotations

from serialspec.lang.model import Direction, Message, Protocol, replies_by_request, reply_to


def request_response_pairs(protocol: Protocol) -> list[tuple[Message, Message | None]]:
    """Every request with the response that answers it (None where the device stays silent)."""
    messages = protocol.messages()
    replies = replies_by_request(messages)
    return [(m, reply_to(m, replies)) for m in messages if m.direction == Direction.REQUEST]
