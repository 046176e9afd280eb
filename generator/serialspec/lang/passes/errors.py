"""Error replies: a command element's `error_flag` and the one response marked `error_reply` (Modbus exceptions)."""

from __future__ import annotations

from collections.abc import Sequence

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
        status = [(name, e) for name, e in raw.items() if isinstance(e, dict) and "error_bits" in e]
        if status:
            return self.by_status(status, flagged, replies)
        if refusing:
            return self.by_header(refusing[0], replies)
        if not flagged:
            for name, _ in replies[:1]:
                self.error(
                    ("commands", name, "response", "error_reply"),
                    "an error reply needs `error_flag` on the framing's command element, `error_value` on its header "
                    "or `error_bits` on its status",
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

    def by_status(
        self,
        status: list[tuple[str, dict[str, object]]],
        flagged: Sequence[tuple[str, object]],
        replies: list[tuple[str, Message]],
    ) -> list[SpecError]:
        """Error replies told by their status (`error_bits`: SHDLC's state byte): the `error_reply` response is their
        content, the command element carries the refused request's code as it is."""
        for other, item in status:
            if item.get("role") != "status":
                self.error(("framing", "elements", other, "error_bits"), "`error_bits` goes on the status element")
        status = [(other, item) for other, item in status if item.get("role") == "status"]
        if not status:
            return self.problems
        name, element = status[0]
        path = ("framing", "elements", name, "error_bits")
        for other, _ in status[1:]:
            self.error(("framing", "elements", other, "error_bits"), f"only one status marks error replies: {name!r}")
        for other, _ in flagged:
            self.error(
                ("framing", "elements", other, "error_flag"), "give either `error_flag` or the status's `error_bits`"
            )
        if any(lay.error for lay in (self.ctx.framing.alternatives[Direction.RESPONSE] if self.ctx.framing else ())):
            self.error(path, "give either the header's `error_value` or the status's `error_bits`")
        if self.problems:
            return self.problems
        bits = element["error_bits"]
        kind = str(element.get("type", "u8"))
        width = int(kind[1:]) if kind[1:].isdigit() else 8
        if not isinstance(bits, int) or isinstance(bits, bool) or bits <= 0 or bits >= 1 << width:
            self.error(path, f"the error bits must be a non-zero bit mask that fits the status's {width} bits")
            return self.problems
        framing = self.ctx.framing
        if framing is None:
            return self.problems
        for layout in framing.alternatives[Direction.RESPONSE]:
            names = [e.name for e in layout.elements]
            roles = [e.role for e in layout.elements]
            if name not in names:
                self.error(path, f"the status {name!r} must be in every response frame")
                return self.problems
            if "content" in roles and names.index(name) > roles.index("content"):
                self.error(path, f"the status {name!r} must come before the content: it says how to read it")
                return self.problems
            if "command" not in roles:
                self.error(path, "an error reply told by its status carries the refused code in a command element")
                return self.problems
        if not replies:
            self.error(path, "`error_bits` needs a command whose response is marked `error_reply: true`")
            return self.problems
        layout = framing.layouts[Direction.RESPONSE]
        command_element = next(e.name for e in layout.elements if e.role == "command")
        command, message = replies[0]
        if any(f.name == command_element for f in message.fields):
            self.error(
                ("commands", command, "response", "fields", command_element),
                f"the error reply carries the refused code as {command_element!r} already",
            )
        self.ctx.error_reply = ErrorReply(0, command_element, command, status=name, bits=bits)
        return self.problems
