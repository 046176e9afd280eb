"""decode and encode for text protocols (`framing: {kind: text}`): a sentence as typed or as hex, to the JSON shape
binary frames have (command, direction, fields), each field as the text the device sent; and back."""

from __future__ import annotations

import sys
from types import ModuleType

from serialspec.runtime.errors import DecodeError, EncodeError, SerialspecError
from serialspec.runtime.hexbytes import parse_hex
from serialspec.runtime.text import DirectionNeeded, TextFraming, from_texts, texts

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any


def frame_of(framing: TextFraming, given: str) -> bytes:
    """A frame given on the command line: as typed (starting with the start character; the line ending may be
    left out, or written as \\r\\n) or as hex."""
    text = given.strip()
    if text.startswith((framing.start, framing.response_start or framing.start)):
        text = text.replace("\\r", "\r").replace("\\n", "\n")
        try:
            return text.encode("ascii")
        except UnicodeEncodeError:
            raise DecodeError(f"{text[:20]!r}... holds a character that is not ASCII") from None
    try:
        return parse_hex(text)
    except ValueError as exc:
        raise DecodeError(f"neither a sentence starting with {framing.start!r} nor hex: {exc}") from None


def describe(
    protocol: str, package: ModuleType, frame: bytes, direction: str | None = None, reply: str | None = None
) -> dict[str, Any]:
    """A frame of the text protocol named `protocol` as `decode --json` prints it (the package alone answers).
    `reply`: the code of the reply awaited, where it is its values alone (`decode --request`)."""
    framing: TextFraming = package.FRAMING
    sentence = framing.decode(frame, direction, reply)
    cls = package.CODEC.classes[sentence.code, sentence.direction]
    body = frame.decode("latin-1")  # ASCII, its line ending perhaps not
    # the talker where the frames carry one (a protocol without has no such key)
    talker = {"talker": sentence.talker} if framing.talker else {}
    return {
        "protocol": protocol,
        "direction": cls.DIRECTION.value,
        "command": cls.COMMAND,
        "subcommand": None,
        **talker,
        "fields": texts(framing.sentence(sentence.code, sentence.direction), sentence.values),
        "sent": sentence.sent,
        # a frame whose checksum fails does not decode; one without a checksum (none in the framing, or left out
        # where `required: false` allows it) was not checked
        "checksum_ok": True
        if framing.checksum is not None and framing.marker in body and sentence.direction in framing.checksummed
        else None,
        "text": body.removesuffix(framing.end_of(sentence.direction)),
    }


def decode(
    protocol: str,
    package: ModuleType,
    frames: list[str],
    as_json: bool,
    direction: str | None = None,
    reply: str | None = None,
) -> int:
    failed = 0
    for given in frames:
        try:
            result = describe(protocol, package, frame_of(package.FRAMING, given), direction, reply)
        except (DecodeError, SerialspecError) as exc:
            hint = " (--direction request|response)" if isinstance(exc, DirectionNeeded) else ""
            hint = " (--request SENTENCE)" if str(exc).endswith("give the request") else hint
            print(f"serialspec decode: {given.strip()}: {exc}{hint}", file=sys.stderr)
            failed += 1
            continue
        if as_json:
            import json

            print(json.dumps(result, ensure_ascii=False), flush=True)
        else:
            print(readable(result), flush=True)
    return 1 if failed else 0


def readable(result: dict[str, Any]) -> str:
    when = f"{result['time']} " if result.get("time") else ""
    lines = [f"{when}{result['protocol']} {result['direction']} {result['command']}  {result['text']}"]
    if result.get("talker"):
        lines.append(f"  {'talker':<20} {result['talker']}")
    for name, value in result["fields"].items():
        if isinstance(value, list):
            for index, row in enumerate(value):
                shown = " ".join(f"{k}={v}" for k, v in row.items())
                lines.append(f"  {f'{name}[{index}]':<20} {shown}")
        else:
            lines.append(f"  {name:<20} {value}")
    return "\n".join(lines)


def encode(package: ModuleType, data: dict[str, Any], direction: str | None, as_hex: bool) -> int:
    """The JSON object decode --json prints (fields as their texts; talker, sent and checksum_ok may be left out)
    -> the frame, as text (without its line ending) or as hex."""
    framing: TextFraming = package.FRAMING
    command = data["command"]
    cls = next(
        (c for c in package.MESSAGE_TYPES if command == c.COMMAND and direction in (None, c.DIRECTION.value)),
        None,
    )
    if cls is None:
        names = ", ".join(sorted(c.COMMAND for c in package.MESSAGE_TYPES if direction in (None, c.DIRECTION.value)))
        raise EncodeError(f"no {direction or 'message'} of command {command!r} (it has {names or 'none'})")
    fields = data.get("fields", {})
    if not isinstance(fields, dict):
        raise EncodeError("`fields` must be an object")
    talker = data.get("talker", cls.talker)
    sent = data.get("sent", -1)
    if not isinstance(talker, str) or isinstance(sent, bool) or not isinstance(sent, int):
        raise EncodeError("`talker` must be text and `sent` an integer")
    try:
        values = from_texts(framing.sentence(cls.CODE, cls.DIRECTION.value), fields)
    except DecodeError as exc:
        raise EncodeError(str(exc)) from None
    # what decode --json says of a frame sent without its optional checksum (`"checksum_ok": null`) leaves it out
    unchecked = "checksum_ok" in data and data["checksum_ok"] is None and not framing.required
    frame = framing.encode(cls.CODE, values, talker, sent, cls.DIRECTION.value, unchecked)
    if as_hex:
        print(frame.hex(" "))
    else:
        print(frame.decode("latin-1").removesuffix(framing.end_of(cls.DIRECTION.value)))
    return 0
