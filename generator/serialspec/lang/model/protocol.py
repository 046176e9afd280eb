"""The protocol: everything above, resolved, as one value every backend reads."""

from __future__ import annotations

from functools import cached_property
from typing import Literal

from serialspec.lang.frozen import frozen
from serialspec.lang.model.commands import Command, Message
from serialspec.lang.model.device import Device
from serialspec.lang.model.examples import Erratum, Example
from serialspec.lang.model.fields import EnumDef, FlagsDef, Table
from serialspec.lang.model.framing import ErrorReply, FrameLayout, Framing, Serial
from serialspec.lang.model.text_frames import TextFrame


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

    def layout(self, message: Message) -> FrameLayout:
        """The layout a message's frames travel in (its command's `layout`, else its direction's first; the error
        reply's, where a header tells error replies: theirs)."""
        if message.error_reply and self.error_reply is not None and self.error_reply.layout:
            return self.framing.layout_of(message.direction, self.error_reply.layout)
        return self.framing.layout_of(message.direction, message.layout)
