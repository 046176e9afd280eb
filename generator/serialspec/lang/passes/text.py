"""Text protocols (`framing: {kind: text}`): the frame, the commands' text codes and fields, and the examples.

A text spec runs this pass instead of the binary ones (framing, commands, errors, examples, device): keys that only
binary frames have yet are refused one line each, so that nothing a spec says is silently ignored.
"""

from __future__ import annotations

import math
import string
from dataclasses import replace
from decimal import Decimal
from typing import Any, Literal, cast

from serialspec import checksums
from serialspec.checksums import ChecksumProblem
from serialspec.lang import expression
from serialspec.lang.errors import SpecError
from serialspec.lang.loader import Path
from serialspec.lang.model import (
    Direction,
    Framing,
    TextAnswer,
    TextDevice,
    TextExample,
    TextField,
    TextFrame,
    TextLayout,
    TextMessage,
    TextRepeat,
    Unsolicited,
)
from serialspec.lang.passes.base import Bad, Pass, camel

KINDS = ("decimal", "integer", "angle", "char", "text", "time", "date")
# Keys a text field may have, by kind (besides type, use, description, unit)
KIND_KEYS = {
    "decimal": {"precision", "width", "range"},
    "integer": {"width", "range", "base", "case"},
    "angle": {"precision", "width", "range"},
    "char": {"letters"},
    "text": {"size"},
    "time": {"precision"},
    "date": set(),
}
COMMON_KEYS = {"type", "use", "description", "unit", "label"}
BINARY_ONLY = ("elements", "layouts", "transparency", "gap", "turnaround")
TEXT_ONLY_FRAMING = ("start", "separator", "end", "checksum", "talker", "max_length", "address")
NOT_YET = ("matching", "enums", "flags", "tables", "errata")
# What a text device may say (the binary device's memory, ids, models and behaviours are not available yet)
DEVICE_KEYS = ("description", "state", "reply", "sends", "commands")
SEND_KEYS = ("every", "step", "while", "values", "description")
ANSWER_KEYS = ("description", "stores", "sets", "reports", "echoes")


# a text code's characters: letters, digits and the punctuation commands use (GRBL's `$H`, `$$`, `?`, `!`, `~`);
# not spaces, quotes, backslashes, `*` or `|`, which the outputs' strings, comments and tables would need escaped
CODE_PUNCTUATION = "$!?~#%&+-./:;=@^_"
CODE_CHARACTERS = string.ascii_letters + string.digits + CODE_PUNCTUATION


# a text number's range bounds: as many significant digits (and fraction digits) as a signed 64-bit integer holds
DIGITS = 18


def _fits_digits(bound: float) -> bool:
    """Whether a range bound is a decimal of at most DIGITS digits, none of them beyond the DIGITS-th decimal."""
    if not math.isfinite(bound):
        return True  # not a number of digits at all: the grammar's line says so
    number = (Decimal(bound) if isinstance(bound, int) else Decimal(repr(float(bound)))).normalize()
    exponent = number.as_tuple().exponent
    assert isinstance(exponent, int)
    return abs(number) < Decimal(10) ** DIGITS and -exponent <= DIGITS and len(number.as_tuple().digits) <= DIGITS


def is_text(data: Any) -> bool:
    framing = data.get("framing") if isinstance(data, dict) else None
    return isinstance(framing, dict) and framing.get("kind") == "text"


class TextPass(Pass):
    """Resolve a text protocol's framing, commands and examples into `ctx.text`."""

    def run(self) -> list[SpecError]:
        data = self.ctx.data
        for key in NOT_YET:
            if key in data:
                self.error((key,), f"`{key}` is not available in text frames yet")
        framing = data.get("framing") or {}
        frame = self.guard(("framing",), self.frame, framing)
        messages = []
        for name, command in self.section("commands").items():
            path = ("commands", name)
            self.name(name, path, "command name")
            for direction in Direction:
                if isinstance(command, dict) and direction.value in command:
                    message = self.guard((*path, direction.value), self.message, name, command, direction, frame)
                    if message is not None:
                        messages.append(message)
        codes: dict[str, TextMessage] = {}
        commands = self.section("commands")
        for message in messages:  # a command's request and response share its code, unless one has its own
            other = codes.setdefault(message.code, message)
            if other.key != message.key:
                own = message.code != (commands.get(message.key) or {}).get("code")
                where: Path = ("commands", message.key, *((message.direction.value, "text") if own else ()), "code")
                self.error(where, f"code {message.code!r} is also {other.key}'s")
        self.found_by_code(messages)
        responses = {m.key for m in messages if m.direction == Direction.RESPONSE}
        for message in messages:
            asked: Path = ("commands", message.key, "request", "answered_by")
            if message.answered_by and message.answered_by not in responses:
                self.error((*asked, "command"), f"{message.answered_by!r} is not a command with a response")
            for index, name in enumerate(message.refused_by):
                if name not in responses:
                    self.error((*asked, "refused_by", index), f"{name!r} is not a command with a response")
                elif name == message.answered_by:
                    self.error((*asked, "refused_by", index), f"{name!r} is the reply that answers it")
            if message.many and not message.then:
                self.error((*asked, "many"), "`many` needs `then`: the response that ends the replies")
            if message.then and message.then not in responses:
                self.error((*asked, "then"), f"{message.then!r} is not a command with a response")
            elif message.then and message.then in (message.answered_by or message.key, *message.refused_by):
                self.error((*asked, "then"), f"{message.then!r} is the reply or a refusal: `then` names what ends it")
        if frame is not None:
            frame = replace(frame, messages=tuple(messages))
            examples = tuple(self.examples(frame))
            device = self.guard(("device",), self.device, data["device"], frame) if "device" in data else None
            self.ctx.text = replace(frame, examples=examples, device=device)
            self.ctx.framing = Framing(
                description=frame.description, layouts={}, checksum=None, shared_header=False, alternatives={}
            )
        return self.problems

    def frame(self, raw: dict[str, Any]) -> TextFrame:
        path: Path = ("framing",)
        for key in BINARY_ONLY:
            if key in raw:
                self.error((*path, key), f"`{key}` belongs to binary framing, not `kind: text`")
        for key in ("separator", "end"):
            if not raw.get(key):
                self.error(path, f"missing key {key!r} (a text frame needs `separator` and `end`)")
        given = raw.get("start") or ""  # none: every line is a frame
        start, response_start = str(given), ""
        if isinstance(given, dict):  # one per direction: LSS's `#` requests and `*` replies
            start, response_start = str(given.get("request") or ""), str(given.get("response") or "")
            if not start or not response_start or start == response_start:
                self.error((*path, "start"), "give each direction its own start, two different characters")
        # a separator or end missing or not text (said above, or by the grammar): stand-ins that clash with nothing,
        # so that no second line blames the characters of a value that is not there
        ends = raw.get("end")
        response_end = ""
        if isinstance(ends, dict):  # one per direction: an ELM327's CR after a request, `\r\r>` after a reply
            raw = {**raw, "end": str(ends.get("request") or "")}
            response_end = str(ends.get("response") or "")
            if not raw["end"] or not response_end or raw["end"] == response_end:
                self.error((*path, "end"), "give each direction its own line ending, two different texts")
                response_end = ""
        separator, end = (
            raw[k] if isinstance(raw.get(k), str) and raw[k] else stand_in
            for k, stand_in in (("separator", "\x1f"), ("end", "\x1e"))
        )
        if len(start) > 1 or len(response_start) > 1 or len(separator) != 1:
            self.error(path, "`start` (when given) and `separator` must be one character each")
        checksum_raw = raw.get("checksum")
        algorithm = None
        marker = "*"
        required = True
        written: Literal["hex2", "decimal"] = "hex2"
        carried: tuple[str, ...] = ("request", "response")
        separated: tuple[str, ...] = ()
        if isinstance(checksum_raw, dict):
            separated = tuple(d for d in ("request", "response") if d in (checksum_raw.get("separated") or ()))
            if checksum_raw.get("directions"):
                carried = tuple(d for d in ("request", "response") if d in checksum_raw["directions"])
            marker = str(checksum_raw.get("marker", "*"))
            required = bool(checksum_raw.get("required", True))
            written = "decimal" if checksum_raw.get("format") == "decimal" else "hex2"
            where = (*path, "checksum")
            try:
                algorithm = checksums.from_spec(checksum_raw, 1, "u8", lambda at, text: self.error((*where, *at), text))
            except ChecksumProblem as problem:
                self.error((*where, *problem.keys), problem.message)
            if len(marker) != 1:
                self.error((*where, "marker"), "the marker must be one character")
        talker = raw.get("talker") or {}
        size = int(talker.get("size", 0))
        talkers = tuple(str(t) for t in talker.get("values") or ())
        for index, value in enumerate(talkers):
            if len(value) != size:
                self.error((*path, "talker", "values", index), f"talker {value!r} is not {size} characters")
        if any(not " " <= c <= "~" for c in (start, response_start, separator) if c):
            self.error(path, "`start` and `separator` are printable ASCII characters")
        if any(c > "\xff" for c in end + response_end):
            self.error((*path, "end"), "the line ending's characters are bytes: U+0000 to U+00FF (Nextion: \\xFF)")
        ending = set(end) | set(response_end)
        special = [*([start] if start else []), *([response_start] if response_start else []), separator, *ending]
        special += [marker] if algorithm is not None else []
        if len(set(special)) != len(special):
            self.error(path, "`start`, `separator`, the checksum's `marker` and the characters of `end` must differ")
        return TextFrame(
            description=str(raw.get("description", "")),
            start=start,
            separator=separator,
            end=end,
            checksum=algorithm,
            marker=marker,
            required=required,
            talker=size,
            talkers=talkers,
            talker_description=str(talker.get("description", "")),
            max_length=int(raw.get("max_length", 82)),
            messages=(),
            checksum_format=written,
            checksum_directions=carried,
            checksum_separated=separated,
            response_start=response_start,
            address=self.address(raw["address"]) if "address" in raw else None,
            response_end=response_end,
        )

    def address(self, name: Any) -> TextField | None:
        """`framing.address`: the shared integer field every message carries first, before its code."""
        path: Path = ("framing", "address")
        if str(name) not in self.shared_fields:
            self.error(path, f"no shared field {name!r} in `fields:`")
            return None
        found = self.guard(path, self.field, str(name), str(name), path, True)
        if found is None:
            return None
        if not isinstance(found, TextField) or found.kind != "integer":
            self.error(path, f"the address {name!r} is an integer field (its digits are read before the code)")
            return None
        if found.minimum is not None and found.minimum < 0:
            self.error(path, f"the address {name!r} is written as digits alone: its range starts at 0 or above")
        if found.base != 10:
            self.error(path, f"the address {name!r} is read as the decimal digits before the code: not `base: 16`")
        return replace(found, address=True)

    def message(self, key: str, command: dict[str, Any], direction: Direction, frame: TextFrame | None) -> TextMessage:
        path: Path = ("commands", key)
        for bad in ("subcommands", "selector", "probe", "broadcast"):
            if bad in command:
                self.error((*path, bad), f"`{bad}` is not available in text frames yet")
        code = command.get("code")
        # the framing's own characters would cut the code out of its frame (`$` starts NMEA sentences)
        framing = (
            {frame.start, frame.response_start, frame.separator, frame.marker, *frame.end, *frame.response_end} - {""}
            if frame is not None
            else set()
        )
        allowed = set(CODE_CHARACTERS) - framing
        if not isinstance(code, str) or not code or not set(code) <= allowed:
            shown = "".join(sorted(set(CODE_PUNCTUATION) - framing))
            raise self.fail(
                (*path, "code"), f"a text command needs a text `code` (letters, digits and {shown}), got {code!r}"
            )
        raw = command.get(direction.value) or {}
        where = (*path, direction.value)
        for bad in ("answers", "error_reply", "optional_when", "after", "default", "optional"):
            if bad in raw:
                self.error((*where, bad), f"`{bad}` is not available in text frames yet")
        answered_by = raw.get("answered_by") or {}
        if answered_by and direction != Direction.REQUEST:
            self.error((*where, "answered_by"), "`answered_by` belongs to a request")
        if "command_in" in answered_by:
            self.error((*where, "answered_by", "command_in"), "`command_in` is not available in text frames yet")
        elif answered_by and "command" not in answered_by:
            self.error((*where, "answered_by"), "give the command that answers (`command`)")
        if "optional_when" in answered_by:
            self.error((*where, "answered_by", "optional_when"), "`optional_when` is not available in text frames yet")
        if answered_by and "response" in command:
            self.error(
                (*where, "answered_by"),
                f"{key} has a response of its own: leave out `answered_by` or the response",
            )
        fields = self.fields(raw.get("fields") or {}, (*where, "fields"), top=True)
        if frame is not None and frame.address is not None:  # every message's first field, before its code
            if any(item.name == frame.address.name for item in fields):
                self.error((*where, "fields", frame.address.name), "the framing's `address` is every message's already")
            fields = (frame.address, *fields)
        if isinstance(raw.get("text"), dict) and "code" in raw["text"]:  # a code of its own: ELM327's reply `41 0C`
            code = self.own_code(raw["text"], (*where, "text"), frame, allowed) or code
        layout = (
            self.layout(raw["text"], code, fields, (*where, "text"), frame)
            if "text" in raw and isinstance(raw["text"], dict)
            else None
        )
        if layout is None:
            for item in fields:
                if item.label:
                    self.error((*where, "fields", item.name, "label"), "a label needs `text: {named: ...}`")
        values_only = bool(raw.get("values_only", False))
        if values_only:
            at = (*where, "values_only")
            if direction != Direction.RESPONSE or "request" not in command:
                self.error(at, "`values_only` belongs to a response, which its command's request gets")
            elif raw.get("unsolicited"):
                self.error(at, "a reply of values alone is read as the answer to its request: it is not unsolicited")
            elif "text" in raw:
                self.error(at, "a reply of values alone has no text layout of its own (`text:`)")
        class_name = camel(key, direction.value)
        self.class_name(class_name, where)
        return TextMessage(
            key=key,
            code=code,
            title=str(command.get("title", "")),
            description=str(raw.get("description") or command.get("description", "")),
            direction=direction,
            class_name=class_name,
            fields=fields,
            unsolicited=bool(raw.get("unsolicited", False)),
            source=str(raw.get("source") or command.get("source", "")),
            answered_by=str(answered_by.get("command", "")),
            refused_by=tuple(str(name) for name in answered_by.get("refused_by") or ()),
            then=str(answered_by.get("then", "")),
            many=bool(answered_by.get("many", False)),
            layout=layout,
            values_only=values_only,
        )

    def own_code(self, raw: dict[str, Any], path: Path, frame: TextFrame | None, allowed: set[str]) -> str:
        """A message's code of its own (`text: {code}`): a code's characters, and the message's separator between
        words where it has no `start` of its own (it is found by the code at the start of the frame). "" where it
        is not one (said): the message keeps its command's, so that nothing else about it is reported again."""
        code = raw["code"]
        separator = str(raw.get("separator", frame.separator if frame is not None else ","))
        words = code.split(separator) if isinstance(code, str) and separator and not raw.get("start") else [code]
        if not isinstance(code, str) or not all(w and set(w) <= allowed for w in words):
            shown = "".join(sorted(set(CODE_PUNCTUATION) & allowed))
            between = f", words between single {separator!r}" if separator and not raw.get("start") else ""
            if raw.get("start") and isinstance(code, str) and separator and separator in code:
                between = f" (words between {separator!r} only in a message found by its code: no `start`)"
            self.error((*path, "code"), f"a text code is letters, digits and {shown}{between}; got {code!r}")
            return ""
        return code

    def found_by_code(self, messages: list[TextMessage]) -> None:
        """Each message found by its code alone (its own text without a `start`) is told from every other code: the
        code and what follows it (`after_code`, else the separator) begin no other code, unless the code is glued
        to a number and the other code goes on with no digit or sign (LSS's `Q6` beside `QD1800`)."""
        codes = {m.code for m in messages}
        for message in messages:
            layout = message.layout
            if layout is None or layout.start:
                continue
            after = layout.follows_code
            sent = [f for f in message.fields if not (isinstance(f, TextField) and f.address)]
            first = sent[0] if sent else None
            # a decimal number (hex digits could go on as another code's letters)
            numeric = isinstance(first, TextField) and first.kind in ("integer", "decimal") and first.base == 10
            for other in sorted(codes):
                if other == message.code or not other.startswith(message.code + after):
                    continue
                if after == "" and numeric and other[len(message.code)] not in "0123456789+-.":
                    continue
                where = ("commands", message.key, message.direction.value, "text")
                self.error(
                    where,
                    f"the code {message.code!r} then {after!r} begins the code {other!r}: a frame could be either"
                    + (" (glue only a number to a code another code begins with)" if after == "" else ""),
                )

    def layout(
        self,
        raw: dict[str, Any],
        code: str,
        fields: tuple[TextField | TextRepeat, ...],
        path: Path,
        frame: TextFrame | None,
    ) -> TextLayout:
        """A message's own `text:` layout, checked against the framing's characters, its code and its fields."""
        framing = (
            {frame.start, frame.response_start, frame.marker, *frame.end, *frame.response_end} - {""}
            if frame is not None
            else set()
        )
        given = {k: str(raw[k]) for k in ("start", "end", "separator", "named", "list", "after_code") if k in raw}
        given.setdefault("separator", frame.separator if frame is not None else ",")
        glued = given.get("named") == ""  # labels glued to their values: G-code's `X10.5`, LSS's `D1800T1500`
        layout = TextLayout(**given, glued=glued)
        fields = tuple(f for f in fields if not (isinstance(f, TextField) and f.address))  # the address: before
        if layout.start and layout.start[0] in CODE_CHARACTERS:
            self.error((*path, "start"), "a message's text starts with a character no text code has (GRBL: `<`)")
        for key in ("separator", "named", "list"):
            value = getattr(layout, key)
            if key in raw and len(value) != 1 and not (glued and key in ("named", "separator") and value == ""):
                self.error((*path, key), f"`{key}` is one character")
        if glued:
            self.glued(layout, code, fields, path)
        if layout.after_code is not None and len(layout.after_code) > 1:
            self.error((*path, "after_code"), "`after_code` is one character, or empty (the value glued to the code)")
        single = [c for c in (layout.separator, layout.named, layout.list) if c]
        if len(set(single)) != len(single) or set(single) & framing:
            self.error(path, "`separator`, `named` and `list` differ from each other and from the framing's characters")
        if set(layout.after_code or "") & framing:
            self.error((*path, "after_code"), "`after_code` differs from the framing's characters")
        if set(code) & set(single + [layout.after_code or ""]) - {"", "" if layout.start else layout.separator}:
            self.error(path, f"the code {code!r} holds one of the message's own characters")
        if not layout.start and not glued and any(item.label == code for item in fields):
            self.error(path, "a field labelled with the code needs the message's own `start`")
        for item in fields:
            where = (*path[:-1], "fields", item.name)
            if layout.labelled and not item.label:
                self.error(where, "with `text.named` every field needs a `label`")
            if isinstance(item, TextRepeat) and layout.named and not layout.list:
                self.error(where, "a labelled repeat needs `text.list` between its values")
            if isinstance(item, TextRepeat) and any(f.label for f in item.fields):
                self.error(where, "a label goes on the repeat, not on its fields")
            if isinstance(item, TextField) and item.rest and (layout.labelled or layout.list):
                self.error((*where, "size"), "the rest of the line in a message whose fields have labels or lists")
            if isinstance(item, TextRepeat) and item.label == code:
                self.error((*where, "label"), "the field after the code (labelled with the code) is one value")
        labels = [item.label for item in fields if item.label]
        if len(set(labels)) != len(labels):
            self.error((*path[:-1], "fields"), "two fields share a label")
        for label in labels:
            if set(label) & set(single) or not label.isprintable() or " " in label:
                self.error((*path[:-1], "fields"), f"label {label!r} holds a character the message's text uses")
        return layout

    def glued(self, layout: TextLayout, code: str, fields: tuple[TextField | TextRepeat, ...], path: Path) -> None:
        """Labels glued to their values (`named: ""`): a message found by its code, each value told by its label
        (the longest that fits), and without a separator each value a number (it ends where a label begins)."""
        if layout.start:
            self.error((*path, "named"), 'labels glued to their values (`named: ""`) need a message found by its code')
        labels = [item.label for item in fields if item.label]
        for item in fields:
            where = (*path[:-1], "fields", item.name)
            if isinstance(item, TextRepeat):
                self.error(where, 'a repeat in a message whose labels are glued to their values (`named: ""`)')
            elif not layout.separator and (item.kind not in ("integer", "decimal") or item.base != 10):
                self.error(
                    where, "without a separator, a value glued between labels is a decimal number (integer, decimal)"
                )
        for label in labels:
            if any(other != label and other.startswith(label) for other in labels):
                self.error((*path[:-1], "fields"), f"label {label!r} begins another label: a value could follow either")
            if not layout.separator and (not label or set(label) & set("0123456789+-.")):
                self.error((*path[:-1], "fields"), f"label {label!r} holds a number's character: it could be a value")

    def declared(self, message: TextMessage) -> set[str]:
        """The field names the spec gives a message, resolved or not: a reference to one that did not resolve is
        not a second mistake (its own line says why)."""
        command = (self.ctx.data.get("commands") or {}).get(message.key)
        part = command.get(message.direction.value) if isinstance(command, dict) else None
        fields = part.get("fields") if isinstance(part, dict) else None
        return {str(name) for name in fields} if isinstance(fields, dict) else set()

    def fields(self, raw: dict[str, Any], path: Path, top: bool) -> tuple[TextField | TextRepeat, ...]:
        found: list[TextField | TextRepeat] = []
        for name, value in raw.items():
            item = self.guard((*path, name), self.field, name, value, (*path, name), top)
            if item is not None:
                found.append(item)
        variable = [i for i, f in enumerate(found) if isinstance(f, TextRepeat) and not f.count]
        if variable and variable[0] != len(found) - 1:
            self.error((*path, found[variable[0]].name), "a repeat with `max_count` must be the last field")
        rest = [i for i, f in enumerate(found) if isinstance(f, TextField) and f.rest]
        if rest and rest[0] != len(found) - 1:
            self.error((*path, found[rest[0]].name, "size"), "the rest of the line (`size: rest`) is the last field")
        return tuple(found)

    def field(self, name: str, value: Any, path: Path, top: bool) -> TextField | TextRepeat:
        self.name(name, path, "field name")
        spec: dict[str, Any] = {"type": value} if isinstance(value, str) else dict(value)
        origin = name  # what a letter Enum is named after: the shared field it comes from, else the field
        if "use" in spec:
            origin = spec.pop("use")
            shared = self.shared_fields.get(origin)
            if shared is None:
                raise self.fail((*path, "use"), f"no shared field {origin!r} in `fields:`")
            spec = {**({"type": shared} if isinstance(shared, str) else shared), **spec}
        elif isinstance(value, str) and value not in (*KINDS, "repeat"):
            origin = value
            shared = self.shared_fields.get(value)
            if shared is None:
                raise self.fail(path, f"unknown text field type {value!r} (expected one of {', '.join(KINDS)})")
            spec = {"type": shared} if isinstance(shared, str) else dict(shared)
        kind = spec.get("type")
        if kind == "repeat":
            if not top:
                raise self.fail(path, "a repeat inside a repeat is not available")
            count, most = int(spec.get("count", 0)), int(spec.get("max_count", 0))
            if bool(count) == bool(most):
                raise self.fail(path, "a repeat needs `count` (always sent) or `max_count` (at the end), not both")
            inner = self.fields(spec.get("fields") or {}, (*path, "fields"), top=False)
            return TextRepeat(
                name,
                cast(tuple[TextField, ...], inner),
                str(spec.get("description", "")),
                count,
                most,
                label=str(spec.get("label", "")),
            )
        if kind not in KINDS:
            raise self.fail(path, f"unknown text field type {kind!r} (expected one of {', '.join(KINDS)}, repeat)")
        for key in spec:
            if key not in COMMON_KEYS and key not in KIND_KEYS[kind]:
                self.error((*path, key), f"`{key}` does not apply to a {kind} field in a text frame")
        low, high = (spec.get("range") or (None, None))[:2]
        if low is not None and high is not None and low > high:
            self.error((*path, "range"), f"range [{low}, {high}] is empty")
        for bound in (low, high):
            if bound is not None and not _fits_digits(bound):
                self.error((*path, "range"), f"range bound {bound} has more than {DIGITS} digits (C holds 64 bits)")
        letters = tuple((str(label), str(letter)) for label, letter in (spec.get("letters") or {}).items())
        for label, letter in letters:
            self.name(label, (*path, "letters", label), "letter label")
            if len(letter) != 1:
                self.error((*path, "letters", label), f"{letter!r} is not one letter")
        if len({letter for _, letter in letters}) != len(letters):
            self.error((*path, "letters"), "two labels share a letter")
        letters_class = ""
        if letters:
            letters_class = self.class_name(camel(origin), path, identity=letters, scoped=True)
        return TextField(
            name=name,
            kind=kind,
            description=str(spec.get("description", "")),
            unit=str(spec.get("unit", "")),
            precision=int(spec.get("precision", 0)),
            width=int(spec.get("width", 0)),
            minimum=low,
            maximum=high,
            letters=letters,
            letters_class=letters_class,
            label=str(spec.get("label", "")),
            rest=self.rest(spec, path, top),
            base=16 if spec.get("base") == 16 else 10,
            lower=self.lower(spec, path),
        )

    def lower(self, spec: dict[str, Any], path: Path) -> bool:
        """`case: lower` (hex digits written in lower case), which only an integer of `base: 16` has."""
        if "case" in spec and spec.get("base") != 16:
            self.error((*path, "case"), "`case` is that of hex digits: it needs `base: 16`")
        return spec.get("case") == "lower"

    def rest(self, spec: dict[str, Any], path: Path, top: bool) -> bool:
        """A text field's `size: rest`: the rest of the line, separators included (the last field of a message)."""
        if "size" not in spec:
            return False
        if spec["size"] != "rest":
            self.error((*path, "size"), "a text field's size is `rest` (the rest of the line), or not given")
        elif not top:
            self.error((*path, "size"), "the rest of the line is a message's last field, not a repeat's")
        return spec["size"] == "rest" and top

    def device(self, raw: dict[str, Any], frame: TextFrame) -> TextDevice:
        """`device:` the state, the values every sentence carries and the sentences sent on their own."""
        path: Path = ("device",)
        for key in raw:
            if key not in DEVICE_KEYS:
                self.error((*path, key), f"`{key}` is not available in a text protocol's device yet")
        state = {str(k): float(v) for k, v in (raw.get("state") or {}).items()}
        messages = {m.key: m for m in frame.messages}
        names = {f.name for m in frame.messages for f in m.fields} | ({"talker"} if frame.talker else set())
        reply: dict[str, str | float] = {}
        for name, value in (raw.get("reply") or {}).items():
            if name not in names:
                self.error((*path, "reply", name), f"no sentence has a field {name!r}")
            if isinstance(value, list):
                self.error((*path, "reply", name), "a text device's reply values are numbers or text, not lists")
                continue
            reply[str(name)] = value if isinstance(value, str) else float(value)
        if frame.talkers and reply.get("talker", frame.talkers[0]) not in frame.talkers:
            self.error(
                (*path, "reply", "talker"), f"talker {reply['talker']!r} is not one of {', '.join(frame.talkers)}"
            )
        sends = []
        for key, item in (raw.get("sends") or {}).items():
            where = (*path, "sends", key)
            message = messages.get(key)
            if message is None:
                self.error(where, f"unknown command {key!r}")
                continue
            for bad in item:
                if bad not in SEND_KEYS:
                    self.error((*where, bad), f"`{bad}` is not available in a text protocol's device yet")
            if "every" not in item:
                self.error(where, "says not when: give `every`")
            for named in ("step", "while"):
                if named in item and str(item[named]) not in state:
                    self.error((*where, named), f"unknown state variable {item[named]!r}")
            fields = {f.name for f in message.fields if isinstance(f, TextField)}
            values = {}
            for name, source in (item.get("values") or {}).items():
                at = (*where, "values", name)
                if name not in fields:
                    if name not in self.declared(message):
                        self.error(at, f"{key} has no field {name!r}")
                    else:  # a field its own line refused: its value is still checked
                        self.of_state(source, at, state)
                    continue
                parsed = self.of_state(source, at, state)
                if parsed is not None:
                    values[str(name)] = parsed
            every: int | expression.Expr = 0
            if isinstance(item.get("every"), str):  # a period worked out from the state (a rate)
                every = self.of_state(item["every"], (*where, "every"), state) or 0
            elif "every" in item:
                every = int(item["every"])
            sends.append(
                Unsolicited(
                    str(key),
                    every,
                    while_=str(item.get("while", "")),
                    values=values,
                    description=str(item.get("description", "")),
                    step=str(item.get("step", "")),
                )
            )
        answers = self.answers(raw.get("commands") or {}, frame, state)
        return TextDevice(str(raw.get("description", "")), state, reply, tuple(sends), answers)

    def of_state(self, source: Any, at: Path, state: dict[str, float]) -> expression.Expr | None:
        """An expression of the device's state variables, or None (each mistake said)."""
        try:
            parsed = expression.parse(str(source))
        except expression.ExpressionError as exc:
            self.error(at, str(exc))
            return None
        unknown = sorted(set(expression.names(parsed)) - set(state))
        for used in unknown:
            self.error(at, f"unknown name {used!r} (not a state variable)")
        return None if unknown else parsed

    def answers(self, raw: dict[str, Any], frame: TextFrame, state: dict[str, float]) -> tuple[TextAnswer, ...]:
        """`device.commands`: how the device answers each command's request (a command with a request and a
        response and no entry here is answered too: its response's fields from the state variables of the same
        name and `reply`)."""
        path: Path = ("device", "commands")
        if not isinstance(raw, dict):
            self.error(path, "expected a mapping: command -> what the device does with its request")
            return ()
        found = []
        for key, item in raw.items():
            where = (*path, str(key))
            request = frame.request(str(key))
            response = frame.answer(request) if request is not None else None
            if request is None:
                self.error(where, f"{key!r} is not a command with a request")
                continue
            item = item or {}
            if not isinstance(item, dict):
                self.error(where, "expected a mapping (stores, sets, reports, echoes, description)")
                continue
            for bad in item:
                if bad not in ANSWER_KEYS:
                    self.error((*where, bad), f"`{bad}` is not available in a text protocol's device yet")
                elif bad in ("reports", "echoes") and response is None:
                    self.error(
                        (*where, bad), f"{key!r} has no response: the device keeps what it is sent and answers nothing"
                    )
            asked = {f.name for f in request.fields}
            answered = {f.name for f in response.fields} if response is not None else set()
            stores = {}
            for name, variable in (item.get("stores") or {}).items():
                if name not in asked:
                    if name not in self.declared(request):  # else its own line said why it is not a field
                        self.error((*where, "stores", name), f"{key}'s request has no field {name!r}")
                elif str(variable) not in state:
                    self.error((*where, "stores", name), f"unknown state variable {variable!r}")
                else:
                    stores[str(name)] = str(variable)
            sets = {}
            for variable, value in (item.get("sets") or {}).items():
                if variable not in state:
                    self.error((*where, "sets", variable), f"unknown state variable {variable!r}")
                elif isinstance(value, bool) or not isinstance(value, int | float):
                    self.error((*where, "sets", variable), f"expected a number, got {value!r}")
                else:
                    sets[str(variable)] = float(value)
            reports = {}
            for name, source in (item.get("reports") or {}).items():
                at = (*where, "reports", name)
                if name not in answered:
                    if response is None or name not in self.declared(response):
                        self.error(at, f"{key}'s response has no field {name!r}")
                    else:  # a field its own line refused: what it reports is still checked
                        self.of_state(source, at, state)
                    continue
                parsed = self.of_state(source, at, state)
                if parsed is not None:
                    reports[str(name)] = parsed
            echoes = []
            for index, name in enumerate(item.get("echoes") or ()):
                if name not in asked or name not in answered:
                    self.error(
                        (*where, "echoes", index), f"{name!r} is not a field of both {key}'s request and response"
                    )
                else:
                    echoes.append(str(name))
            found.append(TextAnswer(str(key), str(item.get("description", "")), stores, sets, reports, tuple(echoes)))
        if frame.address is not None:  # every answer carries the request's address (the servo asked answers)
            name = frame.address.name
            found = [replace(a, echoes=(name, *a.echoes)) if name not in a.echoes else a for a in found]
            entries = {a.command for a in found}
            for request in frame.messages:
                if request.direction == Direction.REQUEST and request.key not in entries and frame.answer(request):
                    found.append(TextAnswer(request.key, echoes=(name,)))
        return tuple(found)

    def examples(self, frame: TextFrame) -> list[TextExample]:
        found = []
        by_key = {(m.key, m.direction.value) for m in frame.messages}
        for name, raw in self.section("examples").items():
            path = ("examples", name)
            try:
                for bad in ("frame", "printed_span", "erratum", "completed", "subcommand", "request"):
                    if bad in raw:
                        self.error((*path, bad), f"`{bad}` is not available in text frames yet")
                if (raw["command"], raw["direction"]) not in by_key:
                    raise self.fail((*path, "command"), f"no {raw['direction']} of command {raw['command']!r}")
                found.append(
                    TextExample(
                        name=name,
                        source=str(raw.get("source", "")),
                        description=str(raw.get("description", "")),
                        direction=Direction(raw["direction"]),
                        printed=str(raw["printed"]),
                        command=str(raw["command"]),
                        fields=dict(raw.get("fields") or {}),
                        position=self.doc.where(path),
                    )
                )
            except (Bad, KeyError, TypeError, ValueError):
                if not self.ctx.malformed_near(path) and not self.problems:
                    raise
        return found
