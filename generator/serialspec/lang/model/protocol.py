"""The protocol: everything above, resolved, as one value every backend reads."""

from __future__ import annotations

from functools import cached_property
from typing import Literal

from serialspec.lang.frozen import frozen
from serialspec.lang.model.commands import Command, Message, replies_by_request, reply_to, sized_apart
from serialspec.lang.model.device import Device
from serialspec.lang.model.examples import Erratum, Example
from serialspec.lang.model.fields import EnumDef, FlagsDef, Table
from serialspec.lang.model.framing import ErrorReply, FrameLayout, Framing, Serial
from serialspec.lang.model.text_frames import TextFrame
from serialspec.runtime.message import Direction


@frozen
class Protocol:
    name: str
    title: str
    description: str
    spec_path: str
    sources: dict[str, str]
    byte_order: Literal["little", "big"]
    serial: Serial
    framing: Framing
    matching: tuple[str, ...]
    matching_description: str
    enums: tuple[EnumDef, ...]
    flags: tuple[FlagsDef, ...]
    tables: tuple[Table, ...]
    commands: tuple[Command, ...]
    examples: tuple[Example, ...]
    errata: tuple[Erratum, ...]
    device: Device | None = None
    client_class: str = ""  # the generated client's and simulator's class names
    simulator_class: str = ""
    error_reply: ErrorReply | None = None
    text: TextFrame | None = None  # framing kind text: its frames and messages (commands is then empty)

    def messages(self) -> tuple[Message, ...]:
        return tuple(m for c in self.commands for m in c.messages())

    def command(self, name: str) -> Command:
        return self._commands_by_name[name]

    @cached_property
    def _commands_by_name(self) -> dict[str, Command]:  # emitters look commands up per message
        return {c.name: c for c in self.commands}

    def reply_alternatives(self, request: Message) -> tuple[Message, ...]:
        """The replies that answer `request` besides its own (`reply_to`'s): the others that share its code, none of
        them the `default`, told apart by their content size (sized_apart), and answer the same request
        (`answers`). SPS30's
        Read Measured Values: 40 bytes of floats, 20 of integers or none at all. A client returns whichever
        comes."""
        reply = reply_to(request, replies_by_request(self.messages()))
        return self._sized_replies.get(reply.key, ()) if reply is not None else ()

    @cached_property
    def _sized_replies(self) -> dict[str, tuple[Message, ...]]:
        groups: dict[int | None, list[Message]] = {}
        for command in self.commands:
            reply = command.response
            if reply is None or reply.error_reply:
                continue
            code = command.wire_code(Direction.RESPONSE) if self.layout(reply).has_command else None
            groups.setdefault(code, []).append(reply)
        found: dict[str, tuple[Message, ...]] = {}
        for code, group in groups.items():
            if not sized_apart(group, code is None and self.framing.by_request(Direction.RESPONSE)):
                continue
            for reply in group:
                asked = reply.answers or reply.key
                others = [m for m in group if m is not reply and not m.unsolicited and (m.answers or m.key) == asked]
                if others and not reply.unsolicited:
                    found[reply.key] = tuple(others)
        return found

    def layout(self, message: Message) -> FrameLayout:
        """The layout a message's frames travel in (its command's `layout`, else its direction's first; the error
        reply's, where a header tells error replies: theirs)."""
        if message.error_reply and self.error_reply is not None and self.error_reply.layout:
            return self.framing.layout_of(message.direction, self.error_reply.layout)
        return self.framing.layout_of(message.direction, message.layout)
