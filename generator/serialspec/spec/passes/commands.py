"""Commands, their sub-commands and messages; command codes; which response answers which request."""

from __future__ import annotations

from typing import Any, Literal

from serialspec.spec.errors import SpecError
from serialspec.spec.loader import Path
from serialspec.spec.model import (
    Command,
    Direction,
    Field,
    Framing,
    Message,
    OptionalWhen,
    Scalar,
    Selector,
    Subcommand,
    Table,
    TableEntry,
    content_bounds,
    fixed_size,
)
from serialspec.spec.passes.base import camel
from serialspec.spec.passes.fields import FieldResolver

OPTIONAL_WHEN_OPS: dict[str, Literal["==", "!=", ">=", "<="]] = {
    "equals": "==",
    "not_equals": "!=",
    "at_least": ">=",
    "at_most": "<=",
}


class Commands(FieldResolver):
    """Resolve `commands:` and check their codes against the framing and their `answered_by` references."""

    def run(self) -> list[SpecError]:
        for key, value in (self.ctx.data.get("commands") or {}).items():
            command = self.guard(("commands", key), self.command, key, value, ("commands", key))
            if command:
                self.ctx.commands.append(command)
        if self.ctx.framing:
            self.check_codes(self.ctx.commands, self.ctx.framing)
        self.check_answered_by(self.ctx.commands)
        return self.problems

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
            group_class=self.class_name(camel(name, "commands"), path) if subcommands else "",
        )

    def check_answered_by(self, commands: list[Command]) -> None:
        responses = {m.key: m for c in commands for m in c.messages() if m.direction == Direction.RESPONSE}
        for command in commands:
            for message in command.messages():
                if message.answered_by and message.answered_by not in responses:
                    self.error(
                        ("commands", command.name, "request", "answered_by", "command"),
                        f"{message.answered_by!r} is not a command with a response",
                    )

    def check_codes(self, commands: list[Command], framing: Framing) -> None:
        for command in commands:
            directions = {m.direction for m in command.messages()}
            if command.code is not None and not any(framing.layouts[d].has_command for d in directions):
                self.error(
                    ("commands", command.name, "code"),
                    "its frames have no command field, so no code",
                )
        for direction, layout in framing.layouts.items():
            sharing: dict[int | None, list[tuple[Command, Message]]] = {}
            for command in commands:
                messages = [m for m in command.messages() if m.direction == direction]
                if not messages or any(m.error_reply for m in messages):
                    continue  # an error reply has the code of the request it refuses (see passes/errors.py)
                if layout.has_command and command.code is None:
                    self.error(
                        ("commands", command.name),
                        f"missing key 'code' ({direction.value} frames carry a command field)",
                    )
                code = command.code if layout.has_command else None
                sharing.setdefault(code, []).append((command, messages[0]))
            for code, users in sharing.items():
                if len(users) < 2:
                    continue
                what = f"code {code:#04x}" if code is not None else "a codeless reply"
                if direction == Direction.REQUEST or any(c.selector for c, _ in users):
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
        class_name = self.class_name(camel(command, subcommand or "", direction.value), path)
        answered_by = value.get("answered_by") or {}
        if direction == Direction.REQUEST:
            for field in fields:
                if isinstance(field, Scalar) and field.status_ok is not None:
                    self.error((*path, "fields", field.name, "status"), "a status is reported in a response")
        if answered_by and direction != Direction.REQUEST:
            self.error((*path, "answered_by"), "`answered_by` names the response that answers a request")
        if value.get("error_reply") and direction != Direction.RESPONSE:
            self.error((*path, "error_reply"), "an error reply is a response")
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
            source=str(value.get("source", "")),
            optional_when=self.optional_when(value.get("optional_when"), (*path, "optional_when")),
            after=self.after(value.get("after"), fields, direction, path),
            answered_by=str(answered_by.get("command", "")),
            default_reply=bool(value.get("default", False)),
            reply_when=self.optional_when(answered_by.get("optional_when"), (*path, "answered_by", "optional_when")),
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
