"""Errata and examples: recorded frames, with the mistakes of the documents they come from."""

from __future__ import annotations

from typing import Any

from serialspec.lang.errors import SpecError
from serialspec.lang.loader import Path
from serialspec.lang.model import (
    Command,
    Direction,
    Erratum,
    ErratumCheck,
    Example,
)
from serialspec.lang.passes.base import Bad, Pass
from serialspec.runtime.hexbytes import parse_hex


class Examples(Pass):
    """Resolve `errata:` then `examples:` (an example may name an erratum; an erratum may check examples)."""

    def run(self) -> list[SpecError]:
        commands = self.ctx.commands
        errata = tuple(
            e
            for key, value in self.section("errata").items()
            if (e := self.guard(("errata", key), self.erratum, key, value, ("errata", key), commands))
        )
        examples = tuple(
            e
            for key, value in self.section("examples").items()
            if (e := self.guard(("examples", key), self.example, key, value, ("examples", key), commands, errata))
        )
        names = {e.name for e in examples} | self.ctx.broken
        for example in examples:
            if example.request and example.request not in names:
                self.error(("examples", example.name, "request"), f"unknown example {example.request!r}")
        for erratum in errata:
            for example_name in erratum.check.examples:
                if isinstance(example_name, str) and example_name not in names:
                    self.error(("errata", erratum.name, "check", "examples"), f"unknown example {example_name!r}")
        self.ctx.errata, self.ctx.examples = errata, examples
        return self.problems

    def frame_bytes(self, text: str, path: Path) -> bytes:
        try:
            return parse_hex(text)
        except ValueError as exc:
            raise self.fail(path, f"not a frame: {exc}") from None

    def find_message(
        self, commands: list[Command], command: str, subcommand: str | None, direction: Direction, path: Path
    ) -> None:
        found = next((c for c in commands if c.name == command), None)
        if found is None and command in self.ctx.broken:
            raise Bad  # the command failed to resolve: its problem is reported
        if found is None:
            raise self.fail((*path, "command"), f"unknown command {command!r}")
        if subcommand is not None:
            sub = next((s for s in found.subcommands if s.name == subcommand), None)
            if sub is None:
                raise self.fail((*path, "subcommand"), f"unknown subcommand {subcommand!r} of {command}")
            message = sub.request if direction == Direction.REQUEST else sub.response
        else:
            if found.subcommands:
                raise self.fail(path, f"{command} has subcommands: name one with `subcommand:`")
            message = found.request if direction == Direction.REQUEST else found.response
        raw = self.ctx.data["commands"][command]
        raw = raw["subcommands"][subcommand] if subcommand is not None else raw
        if message is None and direction.value in raw:
            raise Bad  # it has one, which failed to resolve: its problem is reported
        if message is None:
            raise self.fail(path, f"{command} has no {direction.value}")

    def example(
        self,
        name: str,
        value: dict[str, Any],
        path: Path,
        commands: list[Command],
        errata: tuple[Erratum, ...],
    ) -> Example:
        self.name(name, path, "example name")
        direction = Direction(value["direction"])
        self.find_message(commands, value["command"], value.get("subcommand"), direction, path)
        printed = value["printed"]
        as_text = value.get("printed_as") == "text"
        if as_text and not str(printed).isascii():
            raise self.fail((*path, "printed"), "`printed_as: text` takes ASCII characters only")
        text = str(printed).encode("ascii") + self.trailer(direction) if as_text else b""
        if as_text and "frame" not in value:
            frame = text
        else:
            frame = self.frame_bytes(value.get("frame", printed), (*path, "frame" if "frame" in value else "printed"))
        erratum = str(value.get("erratum", ""))
        span = self.printed_span(value.get("printed_span"), direction, len(frame), (*path, "printed_span"))
        before, after = span
        try:
            shown = text if as_text else parse_hex(printed)
            printed_ok = shown == frame[before : len(frame) - after]
        except ValueError:
            printed_ok = False
        completed = str(value.get("completed", ""))
        if not printed_ok and not erratum and not completed:
            self.error(
                path, "`frame` differs from `printed`: name the erratum that explains it, or say it is `completed`"
            )
        if completed and erratum:
            self.error((*path, "completed"), "an example is `completed` or corrected by an `erratum`, not both")
        if erratum and erratum not in {e.name for e in errata}:
            self.error((*path, "erratum"), f"unknown erratum {erratum!r}")
        return Example(
            name,
            str(value["source"]),
            str(value.get("description", "")),
            direction,
            printed,
            frame,
            erratum,
            value["command"],
            value.get("subcommand"),
            str(value.get("request", "")),
            dict(value["fields"]),
            completed,
            span,
            self.doc.where(path),
            text if as_text else None,
        )

    def trailer(self, direction: Direction) -> bytes:
        """The trailer of the direction's frames (b"" for none): what an example printed as text leaves out."""
        if self.ctx.framing is None:
            return b""
        last = self.ctx.framing.layouts[direction].elements[-1]
        return last.constant if last.role == "trailer" else b""

    def printed_span(self, span: Any, direction: Direction, size: int, path: Path) -> tuple[int, int]:
        """Bytes before and after the frame elements first..last that a document prints (the content among them)."""
        if span is None or self.ctx.framing is None:
            return 0, 0
        layout = self.ctx.framing.layouts[direction]
        names = [e.name for e in layout.elements]
        first, last = span
        for name in span:
            if name not in names:
                raise self.fail(path, f"unknown frame element {name!r} (expected one of {', '.join(names)})")
        start, stop = names.index(first), names.index(last)
        content = next(i for i, e in enumerate(layout.elements) if e.role == "content")
        if not start <= content <= stop:
            raise self.fail(path, f"the span {first}..{last} must hold the content")
        before = sum(e.size or 0 for e in layout.elements[:start])
        after = sum(e.size or 0 for e in layout.elements[stop + 1 :])
        if before + after > size:
            raise self.fail(path, f"the frame is shorter than the elements around {first}..{last}")
        return before, after

    def erratum(self, name: str, value: dict[str, Any], path: Path, commands: list[Command]) -> Erratum:
        self.name(name, path, "erratum name")
        check = value["check"]
        check_path = (*path, "check")
        kind = check["kind"]
        frame = None
        if kind in ("frame_fails", "frame_decodes_as", "checksum_value"):
            if "frame" not in check or "direction" not in check:
                raise self.fail(check_path, f"a {kind} check needs `frame:` and `direction:`")
            frame = self.frame_bytes(check["frame"], (*check_path, "frame")) if kind != "frame_fails" else None
            if kind == "frame_fails":
                try:
                    frame = parse_hex(check["frame"])
                except ValueError:
                    frame = None  # a frame that is not even hex: the failure is in reading it
        if kind == "frame_fails" and not check.get("error"):
            self.error(check_path, "a frame_fails check needs `error:` (words the decode error contains)")
        if kind == "frame_decodes_as":
            if "command" not in check or "fields" not in check:
                raise self.fail(check_path, "a frame_decodes_as check needs `command:` and `fields:`")
            self.find_message(
                commands, check["command"], check.get("subcommand"), Direction(check["direction"]), check_path
            )
        if kind == "checksum_value" and ("claimed" not in check or "actual" not in check):
            self.error(check_path, "a checksum_value check needs `claimed:` and `actual:`")
        elif kind == "checksum_value" and (
            not isinstance(claimed := check["claimed"], int | str) or isinstance(claimed, bool) or claimed == ""
        ):  # (`actual` is an integer by the grammar; `claimed` any value: what the document prints, a number or words)
            self.error(
                (*check_path, "claimed"), f"expected the value the document prints, a number or text; got {claimed!r}"
            )
        if kind == "crc_parameters" and not isinstance(check.get("claimed"), dict):
            self.error(check_path, "a crc_parameters check needs `claimed:` with the claimed parameters")
        return Erratum(
            name,
            str(value["source"]),
            str(value["printed"]),
            str(value["correct"]),
            ErratumCheck(
                kind=kind,
                frame=frame,
                frame_text=str(check.get("frame", "")),
                direction=Direction(check["direction"]) if "direction" in check else None,
                error=str(check.get("error", "")),
                command=str(check.get("command", "")),
                subcommand=check.get("subcommand"),
                fields=dict(check.get("fields") or {}),
                claimed=check.get("claimed"),
                actual=check.get("actual"),
                examples=tuple(check.get("examples") or ()),
            ),
            self.doc.where(check_path),
        )
