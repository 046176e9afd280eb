"""Run a spec's examples and errata through the package just generated from it (in memory).

`generate` and `check` report an example that does not decode to its recorded values (or whose values do not encode
back to its bytes), and an erratum whose check does not hold, as spec errors at the example's or check's line.
The package is imported from the generated text in memory (serialspec.backends.python.memory). `generate` still
writes the files and exits 1, so that the package can show what a failing example's frame holds.
"""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import Any

from serialspec.backends.python.memory import imported
from serialspec.checksums.crc import Crc, crc_function
from serialspec.lang.errors import SpecError
from serialspec.lang.model import Erratum, Example, Protocol, TextExample, TextFrame
from serialspec.runtime.errors import SerialspecError
from serialspec.runtime.fields import UnknownFieldError
from serialspec.runtime.hexbytes import parse_hex
from serialspec.runtime.text import texts


def _difference(found: dict[str, Any], recorded: dict[str, object], message: object = None) -> str:
    names = [*recorded, *(k for k in found if k not in recorded)]
    wrong = [
        f"{name} is {found[name]!r}, not {recorded[name]!r}{_raw_hint(getattr(message, name, None), recorded[name])}"
        if name in found and name in recorded
        else (f"{name} is not in the frame" if name in recorded else f"{name}={found[name]!r} is not recorded")
        for name in names
        if found.get(name, ...) != recorded.get(name, ...)
    ]
    return "; ".join(wrong)


def _computed_given(message: Any, found: dict[str, Any], recorded: dict[str, object]) -> str | None:
    """Where the recorded values are the message's and, beside them, values that encode computes and messages leave
    out (a constant such as WitMotion's unlock key, a count, a `value:` expression), as a document prints them: ""
    when each is the value the frame holds, as JSON may give them (`from_fields`), else the one-line refusal naming
    the value; None where other values differ."""
    if any(name not in recorded or recorded[name] != value for name, value in found.items()):
        return None
    try:
        built = type(message).from_fields(recorded)
    except UnknownFieldError:
        return None
    except SerialspecError as exc:
        return f"the frame decodes to other values: {exc}"
    return "" if built == message else None


def _raw_hint(found: object, recorded: object) -> str:
    """Where a value was recorded by its enum member's name (`found`: the decoded message's member): examples record
    what the wire carries."""
    name = getattr(found, "name", None)
    if (
        isinstance(found, int)
        and isinstance(recorded, str)
        and isinstance(name, str)
        and name.lower() == recorded.lower()
    ):
        return f" (examples record wire values: write {int(found)}, which is {recorded})"
    return ""


class _Checker:
    def __init__(self, protocol: Protocol, package: ModuleType, message_types: tuple[Any, ...]) -> None:
        self.protocol = protocol
        self.package = package  # the codec: decode, encode
        self.classes: dict[tuple[str, str | None, str], Any] = {}
        for cls in reversed(message_types):  # the first of any two alike wins, as a search in order finds
            self.classes[cls.COMMAND, cls.SUBCOMMAND, cls.DIRECTION.value] = cls

    def message_class(self, command: str, subcommand: str | None, direction: str) -> Any:
        return self.classes.get((command, subcommand, direction))

    def decodes_as(
        self, frame: bytes, direction: str, command: str, subcommand: str | None, fields: Any, request: Any = None
    ) -> str:
        """What is wrong with reading `frame` as the given message with the given values ("" if nothing);
        `request`: the request it answers, where replies are read with it."""
        expect = self.message_class(command, subcommand, direction)  # the reply layout, where replies share a code
        asked = () if request is None else (request,)
        try:
            message = self.package.decode(frame, direction, expect, *asked)
        except SerialspecError as exc:
            return f"the frame does not decode: {exc}"
        if (command, subcommand) != (message.COMMAND, message.SUBCOMMAND):
            found = ".".join(p for p in (message.COMMAND, message.SUBCOMMAND) if p)
            return f"the frame decodes as {found}, not {'.'.join(p for p in (command, subcommand) if p)}"
        # an optional frame element not sent (None) need not be recorded
        found_fields = {k: v for k, v in message.to_fields().items() if v is not None or k in fields}
        if found_fields != fields and found_fields != self.as_written(message, fields):
            refused = _computed_given(message, found_fields, fields)
            if refused is None:
                return f"the frame decodes to other values: {_difference(found_fields, fields, message)}"
            return refused
        return ""

    @staticmethod
    def as_written(message: Any, fields: Any) -> Any:
        """The recorded values as the message's own JSON writes them (bytes in any hex form people write, `7929edff`
        for `79 29 ed ff`, as `frame:` takes them), or None where they do not make a message."""
        try:
            written = type(message).from_fields(fields).to_fields()
        except (SerialspecError, ValueError, TypeError, KeyError):
            return None
        return {k: v for k, v in written.items() if v is not None or k in fields}

    def asked(self, example: Example) -> Any:
        """The request a reply example answers (its `request` example, decoded), where replies are read with it."""
        framing = self.protocol.framing
        if not example.request or not framing.requesting:
            return None
        found = next((e for e in self.protocol.examples if e.name == example.request), None)
        try:
            return None if found is None else self.package.decode(found.frame, found.direction.value)
        except SerialspecError:
            return None  # that example's own check says why

    def example(self, example: Example) -> str:
        direction = example.direction.value
        request = self.asked(example)
        asked = () if request is None else (request,)
        fields = example.fields
        wrong = self.decodes_as(example.frame, direction, example.command, example.subcommand, fields, request)
        if wrong:
            return wrong
        cls = self.message_class(example.command, example.subcommand, direction)
        try:
            encoded = self.package.encode(cls.from_fields(example.fields), *asked)
        except SerialspecError as exc:
            return f"its values do not encode: {exc}"
        if encoded != example.frame:
            return f"its values encode to {encoded.hex(' ')}, not the frame"
        return ""

    def erratum(self, erratum: Erratum) -> str:
        check = erratum.check
        direction = check.direction.value if check.direction else None
        if check.kind == "frame_fails":
            try:
                self.package.decode(parse_hex(check.frame_text), direction)
            except (SerialspecError, ValueError) as exc:
                return "" if check.error in str(exc) else f"the frame fails with {str(exc)!r}, not {check.error!r}"
            return "the frame decodes: it does not fail"
        if check.kind == "frame_decodes_as" and check.frame is not None and direction is not None:
            return self.decodes_as(check.frame, direction, check.command, check.subcommand, check.fields)
        if check.kind == "checksum_value" and check.frame is not None:
            if check.frame[-1] != check.actual or check.actual == check.claimed:
                return f"the frame ends in {check.frame[-1]:#04x}: `actual` must be it, and differ from `claimed`"
            return self.decodes_as_anything(check.frame, direction)
        if check.kind == "crc_parameters":
            return self.claimed_crc(erratum)
        return ""

    def decodes_as_anything(self, frame: bytes, direction: str | None) -> str:
        try:
            self.package.decode(frame, direction)
        except SerialspecError as exc:
            return f"the frame does not decode: {exc}"
        return ""

    def claimed_crc(self, erratum: Erratum) -> str:
        checksum = self.protocol.framing.checksum
        crc = checksum.algorithm if checksum is not None else None
        claimed = erratum.check.claimed
        if not isinstance(crc, Crc) or not isinstance(claimed, dict):
            return ""  # the erratum is about a CRC's parameters: the check's own validation says so
        parameters = {
            "width": crc.width,
            "poly": crc.poly,
            "init": crc.init,
            "refin": crc.refin,
            "refout": crc.refout,
            "xorout": crc.xorout,
        }
        try:
            claimed_crc = crc_function(**{**parameters, **claimed})
        except (TypeError, ValueError) as exc:
            return f"the claimed parameters are no CRC: {exc}"
        names = erratum.check.examples
        examples = [e for e in self.protocol.examples if e.name in names] if names else list(self.protocol.examples)
        layouts = self.protocol.framing.layouts
        for example in examples:
            covered = example.frame[layouts[example.direction].covered_from : -1]
            if claimed_crc(covered) == example.frame[-1]:
                return f"example {example.name} verifies with the claimed CRC too"
        return ""


def verify(protocol: Protocol, files: dict[str, str]) -> list[SpecError]:
    """Every example and erratum of the protocol checked against its generated package (`files` by file name)."""
    if not protocol.examples and not protocol.errata:
        return []
    problems: list[SpecError] = []
    # The codec (and the messages it imports) is what the checks run: the package's __init__ (which brings in the
    # serial transport for the client) is not needed for them.
    codec_files = {name: text for name, text in files.items() if name != "__init__.py"}
    with imported(protocol.name, codec_files, protocol.spec_path, "codec") as codec:  # not importing: a bug, raised
        messages = importlib.import_module(f"{protocol.name}.messages")  # the codec's own import of it
        checker = _Checker(protocol, codec, messages.MESSAGE_TYPES)
        for example in protocol.examples:
            if wrong := checker.example(example):
                line, column = example.position
                problems.append(SpecError(protocol.spec_path, line, column, f"examples.{example.name}", wrong))
        for erratum in protocol.errata:
            if wrong := checker.erratum(erratum):
                line, column = erratum.position
                problems.append(SpecError(protocol.spec_path, line, column, f"errata.{erratum.name}.check", wrong))
    return problems


def verify_text(protocol: Protocol, text: TextFrame, files: dict[str, str]) -> list[SpecError]:
    """Every example of a text protocol: its printed frame decodes to the text of each field it records, and the
    message encodes back to the frame."""
    problems: list[SpecError] = []
    if not text.examples:
        return problems
    with imported(protocol.name, files, protocol.spec_path, "__init__") as package:
        for example in text.examples:
            if wrong := _text_example(package, text, example):
                line, column = example.position
                problems.append(SpecError(protocol.spec_path, line, column, f"examples.{example.name}", wrong))
    return problems


def _text_example(package: ModuleType, text: TextFrame, example: TextExample) -> str:
    model = next(m for m in text.messages if m.key == example.command and m.direction == example.direction)
    # a reply of values alone is read as the answer to its command's request
    expect = package.CODEC.classes[model.code, "response"] if model.values_only else None
    try:
        message = package.decode(example.printed, example.direction.value, expect)
    except SerialspecError as exc:
        return f"the frame does not decode: {exc}"
    if example.command != message.COMMAND or example.direction != message.DIRECTION:
        return f"the frame decodes as {message.COMMAND} {message.DIRECTION.value}, not {example.command}"
    try:  # decode takes any value; encode refuses one outside its range
        found = texts(package.FRAMING.sentence(message.CODE, message.DIRECTION.value), message.to_fields())
        recorded = {name: _recorded(value) for name, value in example.fields.items()}
        if found != recorded:
            return f"the frame decodes to other values: {_difference(found, recorded)}"
        encoded = package.encode(message)
    except SerialspecError as exc:
        return f"its values do not encode: {exc}"
    if encoded != (example.printed + text.end_of(example.direction)).encode("latin-1"):
        return f"its values encode to {encoded!r}, not the frame"
    return ""


def _recorded(value: object) -> Any:
    if isinstance(value, list):
        return [{str(k): _recorded(v) for k, v in row.items()} if isinstance(row, dict) else row for row in value]
    return "" if value is None else str(value)
