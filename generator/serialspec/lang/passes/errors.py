"""Error replies: a command element's `error_flag` and the one response marked `error_reply` (Modbus exceptions)."""

from __future__ import annotations

from serialspec.lang.errors import SpecError
from serialspec.lang.model import Direction, ErrorReply, FrameLayout, Message
from serialspec.lang.passes.base import Pass


class ErrorReplies(Pass):
    """Pair the command element's `error_flag` with the `error_reply` response; check that the flag fits."""

    def run(self) -> list[SpecError]:
        framing = self.ctx.framing
        elements = self.section("framing").get("elements")
        raw = elements if isinstance(elements, dict) else {}  # malformed: the structural check has said so
        flagged = [(name, e) for name, e in raw.items() if isinstance(e, dict) and "error_flag" in e]
        replies = [(c.name, m) for c in self.ctx.commands for m in c.messages() if m.error_reply]
        for name, _ in replies[1:]:
            self.error(("commands", name, "response", "error_reply"), f"only one error reply: {replies[0][0]!r} is one")
        refusing = [lay for lay in framing.alternatives[Direction.RESPONSE] if lay.error] if framing else []
        if refusing:
            return self.by_header(refusing[0], replies)
        if not flagged:
            for name, _ in replies[:1]:
                self.error(
                    ("commands", name, "response", "error_reply"),
                    "an error reply needs `error_flag` on the framing's command element or `error_value` on its header",
                )
            return self.problems
        for name, element in flagged:
            if element.get("role") != "command":
                self.error(("framing", "elements", name, "error_flag"), "`error_flag` goes on the command element")
        flagged = [(name, e) for name, e in flagged if e.get("role") == "command"]
        if not flagged:
            return self.problems
        element_name, element = flagged[0]
        path = ("framing", "elements", element_name, "error_flag")
        flag = element["error_flag"]
        kind = str(element.get("type", "u8"))
        width = int(kind[1:]) if kind[1:].isdigit() else 8
        if not isinstance(flag, int) or flag <= 0 or flag >= 1 << width:
            self.error(path, f"the flag must be a non-zero bit mask that fits the command's {width} bits")
            return self.problems
        for other in self.ctx.commands:
            if isinstance(other.code, int) and other.code & flag:
                self.error(("commands", other.name, "code"), f"code {other.code:#04x} has the error flag set")
        if not replies:
            self.error(path, "`error_flag` needs a command whose response is marked `error_reply: true`")
            return self.problems
        command, message = replies[0]
        if framing is not None and any(e.name == element_name for e in framing.layouts[Direction.RESPONSE].elements):
            if any(f.name == element_name for f in message.fields):
                self.error(
                    ("commands", command, "response", "fields", element_name),
                    f"the error reply carries the refused code as {element_name!r} already",
                )
            self.ctx.error_reply = ErrorReply(flag, element_name, command)
        return self.problems

    def by_header(self, layout: FrameLayout, replies: list[tuple[str, Message]]) -> list[SpecError]:
        """Error replies told by their header (`error_value`): the `error_reply` response is their content."""
        header = layout.elements[0].name
        element = next(e.name for e in layout.elements if e.role == "command")
        path = ("framing", "elements", header, "error_value")
        if not replies:
            self.error(path, "`error_value` needs a command whose response is marked `error_reply: true`")
            return self.problems
        command, message = replies[0]
        if any(f.name == element for f in message.fields):
            self.error(
                ("commands", command, "response", "fields", element),
                f"the error reply carries the refused code as {element!r} already",
            )
        self.ctx.error_reply = ErrorReply(0, element, command, layout.header, layout.name)
        return self.problems
