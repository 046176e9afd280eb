"""Commands, their sub-commands and messages; command codes; which response answers which request."""

from __future__ import annotations

from dataclasses import replace
from typing import Any, Literal

from serialspec.checksums.seed import Seeded
from serialspec.lang import counts, expression
from serialspec.lang.errors import SpecError, listed
from serialspec.lang.loader import Path
from serialspec.lang.model import (
    MAX_FIXED_SIZE,
    Bytes,
    Command,
    Direction,
    Field,
    FrameElement,
    FrameLayout,
    Framing,
    List,
    Message,
    OptionalWhen,
    Scalar,
    Selector,
    Subcommand,
    Table,
    TableEntry,
    Varint,
    content_bounds,
    discriminator,
    fixed_size,
    leading_constant,
    replies_by_request,
    reply_to,
    sizes_text,
    sizing_lead,
    sizing_message,
    why_not_picked,
)
from serialspec.lang.model.sizes import rest_taker, sized_by_itself
from serialspec.lang.passes.base import camel
from serialspec.lang.passes.fields import FieldResolver

OPTIONAL_WHEN_OPS: dict[str, Literal["==", "!=", ">=", "<="]] = {
    "equals": "==",
    "not_equals": "!=",
    "at_least": ">=",
    "at_most": "<=",
}


class Commands(FieldResolver):
    """Resolve `commands:` and check their codes against the framing and their `answered_by` references."""

    def run(self) -> list[SpecError]:
        for key, value in self.section("commands").items():
            command = self.guard(("commands", key), self.command, key, value, ("commands", key))
            if command:
                self.ctx.commands.append(command)
        if self.ctx.framing:
            self.ctx.commands[:] = self.reply_codes(self.ctx.commands, self.ctx.framing)
            self.ctx.framing = self.wire_codes(self.ctx.commands, self.ctx.framing)
            self.check_codes(self.ctx.commands, self.ctx.framing)
            self.check_layouts(self.ctx.commands, self.ctx.framing)
            self.check_sizable(self.ctx.commands, self.ctx.framing)
            self.check_lengths(self.ctx.commands, self.ctx.framing)
            self.check_seeds(self.ctx.framing)
            self.ctx.framing = used_layouts(self.ctx.commands, self.ctx.framing)
            self.ctx.framing = replace(
                self.ctx.framing, codeless_replies=codeless_replies(self.ctx.commands, self.ctx.framing)
            )
        self.check_answered_by(self.ctx.commands)
        self.check_request_references(self.ctx.commands)
        self.check_matching(self.ctx.commands, self.ctx.framing)
        return self.problems

    def reply_codes(self, commands: list[Command], framing: Framing) -> list[Command]:
        """The command element's `reply_code`: each command's response code, computed from its code."""
        raw = self.section("framing")
        sources: list[tuple[Path, Any]] = [(("framing", "elements"), raw.get("elements"))]
        layouts = raw.get("layouts")
        for name, layout in layouts.items() if isinstance(layouts, dict) else ():
            if isinstance(layout, dict):
                sources.append((("framing", "layouts", name, "elements"), layout.get("elements")))
        found: list[tuple[Path, str]] = []
        coded: set[str] = set()  # the layouts whose command element gives it ("": the one layout)
        for path, elements in sources:
            for name, item in elements.items() if isinstance(elements, dict) else ():
                if isinstance(item, dict) and "reply_code" in item:
                    where = (*path, name, "reply_code")
                    if item.get("role") != "command":
                        self.error(where, "`reply_code` goes on the command element")
                    else:
                        found.append((where, str(item["reply_code"])))
                        coded.add(str(path[2]) if len(path) > 3 else "")
        if not found:
            return commands
        if len({text for _, text in found}) > 1:
            self.error(found[1][0], "every layout's command element must give the same `reply_code`")
        where, text = found[0]
        try:
            expr = expression.parse(text)
        except expression.ExpressionError as exc:
            self.error(where, str(exc))
            return commands
        if set(expression.names(expr)) != {"code"}:
            self.error(where, "an expression of `code` (the request's code), e.g. `code | 0x40`")
            return commands
        # where layouts are chosen by command, a layout without it (HLK-LD2410's reports beside its commands and
        # ACKs) carries its commands' own codes; otherwise every layout holds every command, and gives it
        by_layout = framing.by_command and len(framing.alternatives[Direction.RESPONSE]) > 1
        response_layouts = [
            layout
            for layout in framing.alternatives[Direction.RESPONSE]
            if not by_layout or layout.name in coded or (not layout.name and "" in coded)
        ]
        element = next((e for e in response_layouts[0].elements if e.role == "command"), None)
        if element is None or element.type is None or element.constant:
            self.error(where, "response frames carry no command code (the element is limited to requests or constant)")
            return commands
        low, high = int(element.type.minimum), int(element.type.maximum)
        # the codes the expression takes are the requests' (VISCA: a u16 request code, a u8 reply code)
        asked = next(
            (
                e
                for layout in framing.alternatives[Direction.REQUEST]
                for e in layout.elements
                if e.role == "command" and e.type is not None and not e.constant
            ),
            element,
        )
        assert asked.type is not None
        first, last = int(asked.type.minimum), int(asked.type.maximum)
        try:
            expression.bounds(expr, {"code": (first, last)})  # refuses what could grow without limit
        except expression.ExpressionError as exc:
            self.error(where, str(exc))
            return commands
        shown = " ".join(text.split())
        self.ctx.framing = replace(framing, reply_code=shown)
        resolved = []
        for command in commands:
            replies = any(
                m.direction == Direction.RESPONSE
                and (not by_layout or framing.layout_of(Direction.RESPONSE, m.layout) in response_layouts)
                for m in command.messages()
            )
            if (
                isinstance(command.code, int)
                and not isinstance(command.code, bool)
                and first <= command.code <= last
                and replies
            ):
                try:
                    code = expression.evaluate(expr, {"code": command.code})
                except (ZeroDivisionError, ValueError) as exc:
                    self.error(("commands", command.name, "code"), f"its reply code {shown}: {exc}")
                else:
                    if low <= code <= high:
                        command = replace(command, response_code=code)
                    else:
                        self.error(
                            ("commands", command.name, "code"),
                            f"its reply code {code} ({shown}) does not fit the {element.type.name} "
                            f"command element ({low}..{high})",
                        )
            resolved.append(command)
        return resolved

    def wire_codes(self, commands: list[Command], framing: Framing) -> Framing:
        """The command element's `code:` in a layout: each command's code in that layout's frames, computed from
        its code; two commands may not share one, and no code of a layout without a header may start as another
        layout's header does (a frame is told by its header; the headerless layout takes the rest)."""
        alternatives = {}
        for direction, layouts in framing.alternatives.items():
            alternatives[direction] = tuple(self.layout_codes(commands, layout, direction) for layout in layouts)
            headers = [(layout.name, layout.header) for layout in layouts if layout.header]
            for layout in alternatives[direction]:
                if not layout.header and headers and layout.elements and layout.elements[0].role == "command":
                    self.check_bare(commands, layout, direction, headers)
        return replace(framing, alternatives=alternatives, layouts={d: found[0] for d, found in alternatives.items()})

    def sent(self, commands: list[Command], direction: Direction) -> list[tuple[Command, int]]:
        """The commands with frames in `direction`, with the code those frames carry."""
        found = []
        for command in commands:
            code = command.wire_code(direction)
            sends = any(m.direction == direction for m in command.messages())
            if isinstance(code, int) and not isinstance(code, bool) and sends:
                found.append((command, code))
        return found

    def layout_codes(self, commands: list[Command], layout: FrameLayout, direction: Direction) -> FrameLayout:
        index = next((i for i, e in enumerate(layout.elements) if e.role == "command"), None)
        if index is None or not layout.elements[index].code:
            return layout
        element = layout.elements[index]
        place: Path = ("framing", "layouts", layout.name) if layout.name else ("framing",)
        where: Path = (*place, "elements", element.name, "code")
        try:
            expr = expression.parse(element.code)
        except expression.ExpressionError as exc:
            self.error(where, str(exc))
            return layout
        if set(expression.names(expr)) != {"code"}:
            self.error(where, "an expression of `code` (the command's code), e.g. `code & 0x7F`")
            return layout
        assert element.type is not None
        low, high = int(element.type.minimum), int(element.type.maximum)
        pairs: list[tuple[int, int]] = []
        taken: dict[int, str] = {}
        for command, code in self.sent(commands, direction):
            try:
                wire = expression.evaluate(expr, {"code": code})
            except (ZeroDivisionError, ValueError) as exc:
                self.error(
                    ("commands", command.name, "code"), f"its code in layout {layout.name} ({element.code}): {exc}"
                )
                continue
            if not low <= wire <= high:
                self.error(
                    ("commands", command.name, "code"),
                    f"its code in layout {layout.name}, {wire} ({element.code}), does not fit the "
                    f"{element.type.name} command element ({low}..{high})",
                )
            elif wire in taken and taken[wire] != command.name:
                self.error(
                    ("commands", command.name, "code"),
                    f"its code in layout {layout.name}, {wire:#04x} ({element.code}), is {taken[wire]}'s too: "
                    "a frame could not tell them apart",
                )
            else:
                taken[wire] = command.name
                pairs.append((code, wire))
        elements = list(layout.elements)
        elements[index] = replace(element, wire=tuple(sorted(set(pairs))))
        return replace(layout, elements=tuple(elements))

    def check_bare(
        self, commands: list[Command], layout: FrameLayout, direction: Direction, headers: list[tuple[str, bytes]]
    ) -> None:
        """No code the headerless layout sends starts as another layout's header does."""
        element = layout.elements[0]
        assert element.size is not None
        to_wire = dict(element.wire)
        for command, code in self.sent(commands, direction):
            wire = to_wire.get(code, code)
            if not 0 <= wire < 1 << (8 * element.size):
                continue  # said elsewhere
            sent = wire.to_bytes(element.size, "big" if element.endian == ">" else "little")
            for name, header in headers:
                if sent[: len(header)] == header[: len(sent)]:
                    self.error(
                        ("commands", command.name, "code"),
                        f"its {direction.value} frame in layout {layout.name} (no header) starts {sent.hex(' ')}, "
                        f"as layout {name}'s header {header.hex(' ')} does: a frame could not be told between them",
                    )

    def check_seeds(self, framing: Framing) -> None:
        """A command's `checksum_seed` belongs to a frame with a `seed: per_command` checksum."""
        layouts = [layout for found in framing.alternatives.values() for layout in found]
        if any(isinstance(c.algorithm, Seeded) for layout in layouts for c in layout.checksums):
            return
        for key, value in self.section("commands").items():
            if isinstance(value, dict) and "checksum_seed" in value:
                self.error(("commands", key, "checksum_seed"), "no checksum of the frame has `seed: per_command`")

    def check_lengths(self, commands: list[Command], framing: Framing) -> None:
        """Every message's smallest content must be countable by its frame's length element."""
        for command in commands:
            for message in command.messages():
                layout = framing.layouts[message.direction]
                length = layout.length
                if not layout.classic or length is None or length.type is None:
                    continue  # the frame engine's lengths count spans of their own (or the frame has none)
                countable = int(length.type.maximum) - layout.length_adds
                if message.min_size > countable:
                    self.error(
                        message_path(message),
                        f"content of at least {message.min_size} bytes is more than the {length.type.name} length "
                        f"element {length.name!r} can count ({countable})",
                    )

    def check_request_references(self, commands: list[Command]) -> None:
        """A response's `after`, `start: request.<field>`, `size_from` and `count_from` name fields of the requests it
        answers."""
        messages = [m for c in commands for m in c.messages()]
        replies = replies_by_request(messages)
        requests = {m.key: m for m in messages if m.direction == Direction.REQUEST}
        answered: dict[str, list[Message]] = {}
        for request in requests.values():
            response = reply_to(request, replies)
            if response is not None:
                answered.setdefault(response.key, []).append(request)
        for message in messages:
            if message.direction != Direction.RESPONSE:
                continue
            path = message_path(message)
            if message.answers and message.answers not in requests:
                known = listed(requests, "none")
                self.error((*path, "answers"), f"unknown request {message.answers!r} (expected one of: {known})")
            asked = answered.get(message.key, [])
            wanted: list[tuple[Path, str]] = []
            if message.after:
                wanted.append(((*path, "after"), message.after))
            for f in message.fields:
                if isinstance(f, Bytes) and f.start_in_request:
                    wanted.append(((*path, "fields", f.name, "start"), f.start))
                if isinstance(f, Bytes) and f.size_from:
                    wanted.append(((*path, "fields", f.name, "size_from"), f.size_from))
                if isinstance(f, List) and f.count_from:
                    wanted.append(((*path, "fields", f.name, "count_from"), f.count_from))
            for where, name in wanted:
                if name in self.ctx.broken:
                    continue
                if not any(integer_field(r, name) for r in asked):
                    names = sorted({f.name for r in asked for f in r.fields if isinstance(f, Scalar)})
                    known = listed(names, "none")
                    self.error(
                        where,
                        f"no request this response answers has an integer field {name!r} (they have: {known})",
                    )

    def check_matching(self, commands: list[Command], framing: Framing | None) -> None:
        """`matching.by` names frame elements or fields that requests and their replies carry."""
        names = {e.name for layout in (framing.layouts.values() if framing else ()) for e in layout.value_elements}
        names |= {f.name for c in commands for m in c.messages() for f in m.fields}
        names |= {"command", "subcommand"}  # the message's own command and sub-command
        if framing is None:
            return  # the frame's elements are unknown: its problems are reported
        names |= self.ctx.broken
        roles = {e.name: e.role for layout in framing.layouts.values() for e in layout.elements}
        for index, name in enumerate(self.ctx.matching):
            if name in names:
                continue
            if roles.get(name) == "command":
                message = f"{name!r} is the command element: a reply's command is matched as `command`"
            elif name in roles:
                message = f"{name!r} is the frame's {roles[name]}, not a value a reply repeats from its request"
            else:
                message = f"unknown field {name!r} (no frame element or field has it)"
            self.error(("matching", "by", index), message)

    def command(self, name: str, value: dict[str, Any], path: Path) -> Command:
        self.name(name, path, "command name")
        selector = None
        subcommands: list[Subcommand] = []
        if "subcommands" in value:
            raw_selector = value.get("selector")
            if raw_selector is None:
                raise self.fail(
                    path, "a command with subcommands needs `selector: {type, offset: {request, response}}`"
                )
            selector = Selector(
                name=self.name(raw_selector.get("name", "subcommand_code"), (*path, "selector", "name")),
                type=self.scalar_type(raw_selector.get("type", "u8"), (*path, "selector", "type"), False),
                offsets={Direction(k): v for k, v in raw_selector["offset"].items() if k in ("request", "response")},
            )
            codes: dict[int, str] = {}
            for sub_name, sub in value["subcommands"].items():
                sub_path = (*path, "subcommands", sub_name)
                self.name(sub_name, sub_path, "subcommand name")
                if sub["code"] in codes:
                    self.error(
                        (*sub_path, "code"),
                        f"code {sub['code']:#04x} is already used by {codes[sub['code']]!r}",
                    )
                codes[sub["code"]] = sub_name
                if not selector.type.minimum <= sub["code"] <= selector.type.maximum:
                    self.error(
                        (*sub_path, "code"),
                        f"code {sub['code']} does not fit the {selector.type.name} selector "
                        f"({selector.type.minimum:g}..{selector.type.maximum:g})",
                    )
                messages = {
                    d: self.guard(
                        (*sub_path, d.value),
                        self.message,
                        name,
                        sub_name,
                        d,
                        sub[d.value],
                        (*sub_path, d.value),
                        selector,
                        sub["code"],
                    )
                    for d in Direction
                    if d.value in sub
                }
                subcommands.append(
                    Subcommand(
                        sub_name,
                        sub["code"],
                        str(sub.get("title", "")),
                        str(sub.get("title_cn", "")),
                        str(sub.get("description", "")),
                        messages.get(Direction.REQUEST),
                        messages.get(Direction.RESPONSE),
                        str(sub.get("source", "")),
                    )
                )
            for direction in ("request", "response"):
                if direction in value:
                    self.error((*path, direction), "a command with subcommands describes content in each subcommand")
        messages = {
            d: self.guard((*path, d.value), self.message, name, None, d, value[d.value], (*path, d.value), None, None)
            for d in Direction
            if d.value in value and "subcommands" not in value
        }
        if "layout" in value:
            chosen = self.layout_names(value["layout"], (*path, "layout"))
            if not chosen:  # said: its messages' layouts are not checked further (one mistake, one line)
                self.ctx.broken.add(name)
            messages = {d: replace(m, layout=chosen.get(d, "")) for d, m in messages.items()}
            subcommands = [
                replace(
                    sub,
                    request=sub.request and replace(sub.request, layout=chosen.get(Direction.REQUEST, "")),
                    response=sub.response and replace(sub.response, layout=chosen.get(Direction.RESPONSE, "")),
                )
                for sub in subcommands
            ]
        probe = bool(value.get("probe", False))
        if probe and ("subcommands" in value or "request" not in value):
            self.error((*path, "probe"), "a probe is a command with a request (and a reply), not sub-commands")
        elif probe and "response" not in value and "answered_by" not in (value["request"] or {}):
            self.error((*path, "probe"), "a probe needs a reply: a `response`, or `answered_by` on its request")
        if isinstance(value.get("code"), str):
            code = value["code"].strip()
            try:  # a number in quotes ("0x01"): YAML reads it as text
                hint = f"write it without quotes: {code}" if int(code, 0) >= 0 else ""
            except ValueError:
                hint = ""
            hint = hint or "text codes belong to `framing: {kind: text}`"
            self.error((*path, "code"), f"expected an integer, got text ({hint})")
        return Command(
            name=name,
            code=value.get("code"),
            title=str(value.get("title", "")),
            title_cn=str(value.get("title_cn", "")),
            description=str(value.get("description", "")),
            broadcast=str(value.get("broadcast", "")),
            source=str(value.get("source", "")),
            request=messages.get(Direction.REQUEST),
            response=messages.get(Direction.RESPONSE),
            selector=selector,
            subcommands=tuple(subcommands),
            group_class=self.client_class_name(camel(name, "commands"), path) if subcommands else "",
            probe=probe,
        )

    def layout_names(self, raw: Any, path: Path) -> dict[Direction, str]:
        """A command's `layout`: one layout name for both directions, or a mapping direction -> name; each a
        layout of `framing.layouts` whose frames of that direction can carry the command's messages."""
        framing = self.ctx.framing
        if framing is None:
            return {}
        names = [layout.name for layout in framing.alternatives[Direction.REQUEST]]
        if not framing.by_command or names == [""]:
            self.error(path, "`layout` chooses one of `framing.layouts`, and the framing has one layout")
            return {}
        pairs = raw.items() if isinstance(raw, dict) else [(d.value, raw) for d in Direction]
        chosen: dict[Direction, str] = {}
        for key, name in pairs:
            where = (*path, key) if isinstance(raw, dict) else path
            if key not in ("request", "response"):
                self.error(where, f"expected request or response, not {key!r}")
                return {}
            if name not in names:
                self.error(where, f"unknown layout {name!r} (the framing has {', '.join(names)})")
                return {}
            chosen[Direction(key)] = name
        return chosen

    def check_layouts(self, commands: list[Command], framing: Framing) -> None:
        """Each message's layout has a content where the message has fields."""
        if not framing.by_command:
            return
        for command in commands:
            if command.name in self.ctx.broken:
                continue
            for message in command.messages():
                layout = framing.layout_of(message.direction, message.layout)
                where = f"layout {layout.name!r}"
                has_content = any(e.role == "content" for e in layout.elements)
                if not has_content and (message.max_size is None or message.max_size > 0):
                    self.error(
                        ("commands", command.name, message.direction.value),
                        f"the {message.direction.value} frames of {where} have no content, and this "
                        f"{message.direction.value} has fields",
                    )

    def check_sizable(self, commands: list[Command], framing: Framing) -> None:
        """A content whose size varies, in a layout with no length element, trailer or transform, is sized by its own
        bytes (model/sizes.py): a count by an expression must be of the form a stream parser sizes it by, and no
        field may take the rest (a stream parser could not tell where the frame ends: it would drop every one)."""
        for command in commands:
            if command.name in self.ctx.broken:
                continue
            for message in command.messages():
                layout = framing.layout_of(message.direction, message.layout)
                fields = message.fields
                if layout.length is not None or layout.trailer or layout.transparency is not None:
                    continue
                low, high = content_bounds(fields)
                if low == high:
                    continue
                where: Path = ("commands", command.name)
                if message.subcommand is not None:
                    where = (*where, "subcommands", message.subcommand)
                where = (*where, message.direction.value, "fields")
                said = [p for p in self.ctx.reported if p[: len(where)] == where]
                if why := counts.unsized(fields):
                    if not any(p[: len(where) + 1] == (*where, why[0]) for p in said):  # one mistake, one line
                        self.error((*where, why[0], why[1]), why[2])
                elif not sized_by_itself(fields) and (vlen := [f for f in fields if isinstance(f, Varint)]):
                    self.error(
                        (*where, vlen[0].name, "encoding"),
                        "a varint cannot size a frame that has no length element, trailer or transform: a stream "
                        "parser could not tell where it ends (give the frame a length element)",
                    )
                elif not sized_by_itself(fields) and (rest := rest_taker(fields)):
                    if any(p[: len(where) + 1] == (*where, rest[0].name) for p in said):
                        continue  # its size said wrong already (a `size_from` it could not read): one line
                    self.error(
                        (*where, rest[0].name, rest[1]),
                        f"`{rest[1]}: rest` cannot size a frame that has no length element, trailer or transform: a "
                        "stream parser could not tell where it ends (give the frame a length element, or the field "
                        f"a {rest[1]} a field or a number says)",
                    )

    def check_answered_by(self, commands: list[Command]) -> None:
        responses = {m.key: m for c in commands for m in c.messages() if m.direction == Direction.RESPONSE}
        for command in commands:
            for message in command.messages():
                path = (*message_path(message), "answered_by")
                if message.answered_by and message.answered_by not in responses:
                    self.error((*path, "command"), f"{message.answered_by!r} is not a command with a response")
                if message.asks_in and not any(
                    isinstance(c.code, int) and m.direction == Direction.RESPONSE
                    for c in commands
                    for m in c.messages()
                ):
                    self.error((*path, "command_in"), "no command has a response to ask for")
                if message.asks_in and command.name in responses:
                    self.error(
                        path, f"{command.name} has a response of its own: leave out `answered_by` or the response"
                    )
                for index, name in enumerate(message.refused_by):
                    if name not in responses:
                        self.error((*path, "refused_by", index), f"{name!r} is not a command with a response")
                    elif name == (message.answered_by or message.key):
                        self.error((*path, "refused_by", index), f"{name!r} is the reply that answers it")

    def check_codes(self, commands: list[Command], framing: Framing) -> None:
        for command in commands:
            if command.code is not None and not isinstance(command.code, int):
                continue  # not a number: the structural check has said so
            directions = {m.direction for m in command.messages()}
            broken = command.name in self.ctx.broken  # a message failed to resolve: its problem is reported
            layouts = {m.direction: framing.layout_of(m.direction, m.layout) for m in command.messages()}
            if command.code is not None and not broken and not any(layouts[d].has_command for d in directions):
                self.error(
                    ("commands", command.name, "code"),
                    "its frames have no command field, so no code",
                )
            # in each direction, the code its frames carry fits the command element of some layout it may travel
            # in (alternatives told apart by header: encode sends it in the first that holds it, MSP v2's u16 codes
            # beside v1's u8 ones); a request's u16 code is not carried by a u8 element of replies (VISCA)
            for d in sorted(directions, key=lambda d: d.value != "request"):
                elements = [
                    e
                    for layout in (
                        (layouts[d],) if framing.by_command else framing.alternatives.get(d, (framing.layouts[d],))
                    )
                    for e in layout.elements
                    if e.role == "command" and e.type is not None and not layout.error and d in e.directions
                ]
                code = command.wire_code(d)
                if any(m.error_reply for m in command.messages() if m.direction == d):
                    continue  # an error reply carries the code of the request it refuses
                if elements and code is not None and not any(fits(e, code) for e in elements):
                    element = elements[0]
                    assert element.type is not None
                    low, high = element.type.minimum, element.type.maximum
                    reply = d == Direction.RESPONSE and command.response_code is None and len(directions) > 1
                    self.error(
                        ("commands", command.name, "code"),
                        f"code {code} does not fit the {element.type.name} command element"
                        f"{' of ' + d.value + ' frames' if len(element.directions) < 2 else ''} ({low:g}..{high:g})"
                        + (
                            "; give that element a `reply_code` (the code replies carry, as an expression of `code`)"
                            if reply
                            else ""
                        ),
                    )
                    break
        for direction, layout in framing.layouts.items():
            sharing: dict[int | None, list[tuple[Command, Message]]] = {}
            for command in commands:
                messages = [m for m in command.messages() if m.direction == direction]
                if not messages or any(m.error_reply for m in messages):
                    continue  # an error reply has the code of the request it refuses (see passes/errors.py)
                layout = framing.layout_of(direction, messages[0].layout)
                if command.code is not None and not isinstance(command.code, int):
                    continue  # not a number: the structural check has said so
                if layout.has_command and command.code is None:
                    self.error(
                        ("commands", command.name),
                        f"missing key 'code' ({direction.value} frames carry a command field)",
                    )
                code = command.wire_code(direction) if layout.has_command else None
                sharing.setdefault(code, []).append((command, messages[0]))
            for code, users in sharing.items():
                if len(users) < 2 or (code is None and framing.by_request(direction)):
                    continue  # replies without a code read in the layout of their request: chosen by it
                what = f"code {code:#04x}" if code is not None else "a codeless reply"
                by_size = direction == Direction.REQUEST or not any(m.default_reply for _, m in users)
                if by_size and not any(c.selector for c, _ in users):
                    alike = [m for _, m in users]
                    if discriminator(alike) is not None and (sizing_lead(alike) or sizing_message(alike)):
                        # picked by a leading constant, each sized by its own bytes (Kondo ICS), or of one fixed
                        # size (iRobot's sensor queries): no length needed
                        continue
                    kind = direction.value
                    if any(
                        alt.length is None and not alt.trailer and alt.transparency is None
                        for alt in framing.alternatives.get(direction, (layout,))
                    ):
                        shared = (
                            f"{what} in {kind} frames is already used by {users[0][0].name!r}; {kind}s that share "
                            "a code"
                            if code is not None
                            else f"{users[0][0].name!r} already sends {kind}s without a code (the {kind} frame has "
                            f"no command element); such {kind}s"
                        )
                        other = (
                            ""
                            if direction == Direction.REQUEST
                            else " (or mark one `default: true`: the reply a frame is decoded as when its request is "
                            "unknown, the others chosen by the request they answer)"
                        )
                        reason = why_not_picked(alike)
                        self.error(
                            ("commands", users[1][0].name),
                            f"{shared} are told apart by their content size, which needs a length element, a trailer "
                            f"or a transform{reason}"
                            f"{other}",
                        )
                    elif discriminator([m for _, m in users]) is None:
                        self.check_sizes_differ(what, users, code is not None, direction)
                    continue
                if any(c.selector for c, _ in users):
                    for command, _ in users[1:]:
                        self.error(
                            ("commands", command.name),
                            f"{what} in {direction.value} frames is already used by {users[0][0].name!r}",
                        )
                    continue
                defaults = [c.name for c, m in users if m.default_reply]
                if len(defaults) != 1:
                    names = ", ".join(c.name for c, _ in users)
                    self.error(
                        ("commands", users[-1][0].name, "response"),
                        f"{what} is shared by the replies of {names}: mark one of them `default: true` (the "
                        "layout a reply is decoded as when its request is unknown)",
                    )

    def check_sizes_differ(
        self, what: str, users: list[tuple[Command, Message]], coded: bool, direction: Direction
    ) -> None:
        """Requests (or replies none of which is the `default`) that share a code are told apart by their content
        size: no size may fit two of them."""
        kind = direction.value
        for index, (command, message) in enumerate(users):
            for other, earlier in users[:index]:
                low = max(message.min_size, earlier.min_size)
                highs = [h for h in (message.max_size, earlier.max_size) if h is not None]
                if not highs or low <= min(highs):
                    plural = "" if low == 1 else "s"
                    used = (
                        f"{what} in {kind} frames is already used by {other.name!r}"
                        if coded
                        else f"{other.name!r} also sends {kind}s without a code"
                    )
                    apart = f"{kind}s that share a code" if coded else f"{kind}s without a code"
                    if direction == Direction.RESPONSE:
                        apart += ", none of them `default: true`,"
                    self.error(
                        ("commands", command.name),
                        f"{used}, and a content of {low} byte{plural} fits both ({apart} are told apart by their "
                        f"content size: {sizes_text(earlier)} and {sizes_text(message)}"
                        f"{clash_text(users, earlier, message)})",
                    )
                    break  # one line a command

    def message(
        self,
        command: str,
        subcommand: str | None,
        direction: Direction,
        value: dict[str, Any],
        path: Path,
        selector: Selector | None,
        code: int | None,
    ) -> Message:
        fields = self.fields(value.get("fields") or {}, (*path, "fields"), parent=None)
        framing = self.ctx.framing
        frame_values = {e.name for e in framing.layouts[direction].value_elements} if framing else set()
        for field in fields:
            if field.name in frame_values:
                self.error(
                    (*path, "fields", field.name),
                    f"{field.name!r} is already a frame element of every {direction.value}; name the field otherwise",
                )
        if selector is not None and code is not None:
            fields = self.insert_selector(fields, selector, direction, code, path)
        self.check_rest(fields, (*path, "fields"))
        low, high = content_bounds(fields)
        if low > MAX_FIXED_SIZE and all((fixed_size(f) or 0) <= MAX_FIXED_SIZE for f in fields):  # else said per field
            self.error((*path, "fields"), f"at least {low} bytes: more than a content can hold ({MAX_FIXED_SIZE})")
        padded = None
        if framing is not None and framing.layouts[direction].truncates and high != 0:
            if low != high:
                self.error(
                    (*path, "fields"),
                    "a truncated content (`truncate: trailing_zeros`) has one size; this one's size varies",
                )
            else:
                padded, low = high, 1
        class_name = self.class_name(camel(command, subcommand or "", direction.value), path)
        struct_name = self.class_name(f"{class_name}Content", path)
        answered_by = value.get("answered_by") or {}
        if direction == Direction.REQUEST:
            for field in fields:
                if isinstance(field, Scalar) and field.status_ok is not None:
                    self.error((*path, "fields", field.name, "status"), "a status is reported in a response")
        if answered_by and direction != Direction.REQUEST:
            self.error((*path, "answered_by"), "`answered_by` names the response that answers a request")
        if answered_by.get("then") or answered_by.get("many"):
            self.error(
                (*path, "answered_by", "then" if answered_by.get("then") else "many"),
                "`then` and `many` are for text frames; a binary reply that follows another is matched by its content "
                "(`request_code`) or sent on its own (`device.sends` with `after`)",
            )
        if value.get("error_reply") and direction != Direction.RESPONSE:
            self.error((*path, "error_reply"), "an error reply is a response")
        if "text" in value:
            self.error((*path, "text"), "`text` belongs to messages of text frames (`framing: {kind: text}`)")
        if "values_only" in value:
            self.error(
                (*path, "values_only"),
                "`values_only` belongs to text frames; a binary reply without a code is a command element that only "
                "requests carry (`directions: [request]`)",
            )
        return Message(
            command=command,
            subcommand=subcommand,
            direction=direction,
            class_name=class_name,
            title=str(value.get("title", "")),
            description=str(value.get("description", "")),
            fields=fields,
            optional=str(value.get("optional", "")),
            unsolicited=bool(value.get("unsolicited", False)),
            answers=str(value.get("answers", "")),
            min_size=low,
            max_size=high,
            padded=padded,
            source=str(value.get("source", "")),
            optional_when=self.optional_when(value.get("optional_when"), (*path, "optional_when")),
            after=self.after(value.get("after"), fields, direction, path),
            answered_by=str(answered_by.get("command", "")),
            asks_in=self.asks_in(answered_by, fields, (*path, "answered_by")),
            refused_by=tuple(str(name) for name in answered_by.get("refused_by") or ()),
            request_code=self.request_code(value.get("request_code"), fields, direction, path),
            default_reply=bool(value.get("default", False)),
            reply_when=self.optional_when(answered_by.get("optional_when"), (*path, "answered_by", "optional_when")),
            struct_name=struct_name,
            error_reply=bool(value.get("error_reply", False)),
        )

    def table_entry(self, text: str, path: Path) -> tuple[Table, TableEntry]:
        """A table entry named `entry` (searched in every table) or `table.entry`."""
        table_name, _, entry_name = text.rpartition(".")
        tables = [self.tables[table_name]] if table_name in self.tables else list(self.tables.values())
        for table in tables:
            for entry in table.entries:
                if entry.name == entry_name:
                    return table, entry
        raise self.fail(path, f"unknown table entry {text!r}")

    def optional_when(self, value: Any, path: Path) -> OptionalWhen | None:
        if value is None:
            return None
        table, entry = self.table_entry(value["parameter"], (*path, "parameter"))
        given = [(key, op) for key, op in OPTIONAL_WHEN_OPS.items() if key in value]
        if len(given) != 1:
            raise self.fail(path, f"give one comparison: {', '.join(OPTIONAL_WHEN_OPS)}")
        key, op = given[0]
        return OptionalWhen(table.name, entry.name, entry.key, int(value[key]), op)

    def request_code(self, value: Any, fields: tuple[Field, ...], direction: Direction, path: Path) -> str:
        if value is None:
            return ""
        if direction != Direction.RESPONSE:
            self.error((*path, "request_code"), "`request_code` names a field of a response")
        elif not any(isinstance(f, Scalar) and not (f.hidden or f.type.is_float) and f.name == value for f in fields):
            names = ", ".join(f.name for f in fields if isinstance(f, Scalar) and not f.hidden) or "none"
            self.error((*path, "request_code"), f"no integer field {value!r} in this response (it has: {names})")
        return str(value)

    def asks_in(self, answered_by: dict[str, Any], fields: tuple[Field, ...], path: Path) -> str:
        """`answered_by.command_in`: the request's integer field holding the code of the command that answers."""
        name = answered_by.get("command_in")
        if not answered_by:
            return ""
        if name is None:
            if "command" not in answered_by:
                self.error(
                    path, "give the command that answers (`command`) or the field holding its code (`command_in`)"
                )
            return ""
        if "command" in answered_by:
            self.error((*path, "command_in"), "give `command` or `command_in`, not both")
        if not any(isinstance(f, Scalar) and not (f.hidden or f.type.is_float) and f.name == name for f in fields):
            names = ", ".join(f.name for f in fields if isinstance(f, Scalar) and not f.hidden) or "none"
            self.error((*path, "command_in"), f"no integer field {name!r} in this request (it has: {names})")
        return str(name)

    def after(self, value: Any, fields: tuple[Field, ...], direction: Direction, path: Path) -> str:
        if value is None:
            return ""
        if direction != Direction.RESPONSE:
            self.error((*path, "after"), "`after` describes when a response is sent")
        return str(value)

    def insert_selector(
        self, fields: tuple[Field, ...], selector: Selector, direction: Direction, code: int, path: Path
    ) -> tuple[Field, ...]:
        offset = selector.offsets.get(direction)
        if offset is None:
            raise self.fail(path, f"the selector has no offset for {direction.value}")
        const = Scalar(
            selector.name,
            "sub-command selector",
            "",
            "",
            selector.type,
            self.endian,
            "",
            None,
            selector.type.minimum,
            selector.type.maximum,
            code,
            None,
            None,
            None,
            (),
            "",
            False,
        )
        position = 0
        for index, field in enumerate(fields):
            if position == offset:
                return (*fields[:index], const, *fields[index:])
            size = fixed_size(field)
            if size is None:
                break
            position += size
        if position == offset:
            return (*fields, const)
        raise self.fail(path, f"the selector's offset {offset} does not fall between fixed-size fields")


def clash_text(users: list[tuple[Command, Message]], earlier: Message, message: Message) -> str:
    """Why a leading constant does not pick between two requests whose sizes overlap (lang/model/discriminator.py):
    the words to add to the size error, or "" where no message of them begins with one."""
    firsts = [leading_constant(m) for _, m in users]
    if all(f is None for f in firsts):
        return ""
    one, other = leading_constant(earlier), leading_constant(message)
    if one is not None and other is not None and one == other:
        return f"; both begin with {message.fields[0].name} = {one[1]}, which cannot pick one"
    return (
        "; a leading constant picks a message only where every one of them begins with a constant integer field of "
        "the same width, no two equal"
    )


def codeless_replies(commands: list[Command], framing: Framing) -> bool:
    """One response layout without a command element, length, terminator or transform, whose replies (all awaited,
    none unsolicited) differ in size: the frame cannot size a reply, the reply awaited does (Framing.by_request).
    Replies a leading constant picks, each of a size its own bytes tell (Kondo ICS), need none; FEETECH's and
    DYNAMIXEL's status replies carry a length: both are read alone."""
    layouts = framing.alternatives.get(Direction.RESPONSE, ())
    if framing.by_command or len(layouts) != 1:
        return False
    layout = layouts[0]
    if layout.has_command or layout.length is not None or layout.trailer or layout.transparency is not None:
        return False
    replies = [m for c in commands for m in c.messages() if m.direction == Direction.RESPONSE]
    if not replies or any(m.unsolicited for m in replies) or sizing_lead(replies) is not None:
        return False  # (replies picked by a leading constant, each sized by its own bytes, are read alone)
    if len(replies) == 1:  # the one reply: as long as its request says (`size_from`, `count_from`), or read alone
        return any(
            isinstance(f, Bytes) and f.size_from or isinstance(f, List) and f.count_from for f in replies[0].fields
        )
    return len({(m.min_size, m.max_size) for m in replies}) > 1 or replies[0].min_size != replies[0].max_size


def used_layouts(commands: list[Command], framing: Framing) -> Framing:
    """Where commands name their layouts, each direction's layouts that some message of it travels in (and the
    error replies'): a layout no request uses is no request layout (BNO055: `EE status` frames are replies only),
    so no frame is read in it as a request."""
    if not framing.by_command:
        return framing
    alternatives = dict(framing.alternatives)
    for direction, layouts in framing.alternatives.items():
        used = {m.layout or layouts[0].name for c in commands for m in c.messages() if m.direction == direction}
        kept = tuple(layout for layout in layouts if layout.name in used or layout.error)
        if kept and len(kept) < len(layouts):
            alternatives[direction] = kept
    first = {d: alternatives[d][0] if alternatives.get(d) else framing.layouts[d] for d in framing.layouts}
    return replace(framing, alternatives=alternatives, layouts=first)


def message_path(message: Message) -> Path:
    """Where a message is in the spec."""
    if message.subcommand is not None:
        return ("commands", message.command, "subcommands", message.subcommand, message.direction.value)
    return ("commands", message.command, message.direction.value)


def integer_field(message: Message, name: str) -> bool:
    return any(isinstance(f, Scalar) and not f.type.is_float and f.name == name for f in message.fields)


def fits(element: FrameElement, code: int) -> bool:
    """The command element holds the code (one with a `code` expression: its wire code is checked by layout)."""
    assert element.type is not None
    return bool(element.code) or element.type.minimum <= code <= element.type.maximum
