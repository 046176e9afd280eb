"""Which content decoder a frame's command code names, in each direction: shared by every frame shape."""

from __future__ import annotations

from typing import Any

from serialspec.backends.python.content import decoder_name
from serialspec.lang.model import Command, Direction, FrameLayout, Message, Protocol, sizes_text


def value_arguments(layout: FrameLayout) -> dict[str, str]:
    return {
        "extra": "".join(f", {e.name}: int" for e in layout.value_elements),
        "args": "".join(f", {e.name}" for e in layout.value_elements),
    }


def direction_entry(command: Command, direction: Direction) -> tuple[str, int, int | None, dict[str, Any]] | None:
    """The decoder a command code dispatches to in one direction, the content size bounds, any sub-dispatch."""
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
    sub = {
        "name": name,
        "offset": command.selector.offsets[direction],
        "table": table,
        "entries": entries,
        "where": f"{command.name} {direction.value}",
    }
    return name, low, high, sub


def size_dispatch(key: str, direction: Direction, messages: list[Message]) -> dict[str, Any]:
    """Requests that share one code, told apart by their content size (the resolver checked that no size fits two):
    the decoder that picks one by the size, for the code's entry in the dispatch table."""
    code = "none" if key == "None" else key.removeprefix("0x")
    return {
        "name": f"_decode_{direction.value}_{code}_by_size",
        "ranges": [(m.min_size, m.max_size, decoder_name(m)) for m in sorted(messages, key=lambda m: m.min_size)],
        "where": f"{direction.value} {key}",
        "sizes": ", ".join(f"{m.command}: {sizes_text(m)}" for m in messages),
    }


def shared_codes(protocol: Protocol, direction: Direction) -> set[int]:
    """The codes several requests share (told apart by their content size); none in responses."""
    if direction != Direction.REQUEST:
        return set()
    seen: set[int] = set()
    shared: set[int] = set()
    for command in protocol.commands:
        if command.request is not None and command.code is not None:
            (shared if command.code in seen else seen).add(command.code)
    return shared
