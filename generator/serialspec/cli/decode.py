"""serialspec decode: frames (as hex) to their fields, as JSON or a readable field-by-field view."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from types import ModuleType

from serialspec.cli.protocols import SPEC_HELP, installed_package, open_spec, submodule
from serialspec.runtime.errors import DecodeError, SerialspecError, shown
from serialspec.runtime.hexbytes import parse_hex

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    import argparse
    from typing import Any

    from serialspec.cli.frames import Seen
    from serialspec.lang.model import Protocol
    from serialspec.runtime.message import Message


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help=SPEC_HELP)
    parser.add_argument(
        "hex",
        nargs="*",
        help="one frame per argument (as hex; a text protocol's sentence as typed too); - reads stdin, one per line",
    )
    parser.add_argument(
        "--file",
        metavar="FILE",
        help="a capture (monitor --save, sim --tap), a spy:// log or hex lines to replay; - for stdin",
    )
    parser.add_argument("--json", action="store_true", help="one JSON object per frame")
    parser.add_argument(
        "--direction",
        choices=("request", "response"),
        help="needed where requests and responses share a header",
    )
    parser.add_argument("--units", action="store_true", help="engineering units and enum names, not raw values")
    parser.add_argument(
        "--request",
        metavar="HEX",
        help="the request a response answers (shows registers by name; reads a text reply of values alone)",
    )


def run(args: argparse.Namespace) -> int:
    if not args.hex and not args.file:
        raise SerialspecError("give frames as hex arguments, - to read them from stdin, or --file CAPTURE")
    alone = None if args.file or args.request or args.units else package_alone(args.spec)
    if alone is not None and is_text(alone):  # the package answers alone: the spec's model is not loaded
        from serialspec.cli import textframes

        sentences = [line for line in sys.stdin if line.strip()] if args.hex == ["-"] else args.hex
        return textframes.decode(alone.PROTOCOL, alone, sentences, args.json, args.direction)
    if alone is not None:
        return decode_frames(
            args, lambda frame: alone.decode(frame, args.direction, None), lambda m, f: describe_alone(alone, m, f)
        )
    protocol, package = open_spec(args.spec)
    if protocol.text is not None:
        if args.units:
            raise SerialspecError("a text protocol's sentences carry no scaled values: --units is for binary frames")
        from serialspec.cli import textframes

        if args.file:
            return replay(args, protocol, package)
        sentences = [line for line in sys.stdin if line.strip()] if args.hex == ["-"] else args.hex
        reply = None  # with --request: the code of its reply, where that is its values alone
        if args.request:
            asked = package.decode(textframes.frame_of(package.FRAMING, args.request), "request")
            reply = package.CODEC.reply_code(asked.CODE) or asked.CODE  # known: no hint to give it
        return textframes.decode(protocol.name, package, sentences, args.json, args.direction, reply)
    from serialspec.cli.views import message_spec
    from serialspec.lang.model import replies_by_request, reply_to

    request = None
    expect = None  # the reply layout the request gets, where replies share a code
    if args.request:
        request = package.decode(_hex(args.request), "request")
        reply = reply_to(message_spec(protocol, request), replies_by_request(protocol.messages()))
        expect = next((c for c in package.MESSAGE_TYPES if reply and c.__name__ == reply.class_name), None)
    if args.file:
        return replay(args, protocol, package)

    def decode(frame: bytes) -> Message:
        if request is not None and protocol.framing.requesting:
            return package.decode(frame, args.direction, expect, request)  # type: ignore[no-any-return]
        return package.decode(frame, args.direction, expect)  # type: ignore[no-any-return]

    return decode_frames(args, decode, lambda m, f: describe(protocol, m, f, args.units, request))


def decode_frames(
    args: argparse.Namespace,
    decode: Callable[[bytes], Message],
    described: Callable[[Message, bytes], dict[str, Any]],
) -> int:
    """Decode the frames given as arguments (or one a line on stdin), each shown or its error told in one line."""
    frames = [line for line in sys.stdin if line.strip()] if args.hex == ["-"] else args.hex
    failed = 0
    for text in frames:
        try:
            frame = _hex(text)
            message = decode(frame)
        except (DecodeError, SerialspecError) as exc:
            hint = " (--direction request|response)" if str(exc).startswith("give the direction") else ""
            hint = " (--request HEX)" if str(exc).endswith("give the request") else hint
            given = text.strip()  # as typed, or quoted and cut short where it holds what a terminal would act on
            print(f"serialspec decode: {given if given.isprintable() else shown(given)}: {exc}{hint}", file=sys.stderr)
            failed += 1
            continue
        show(described(message, frame), args.json)
    return 1 if failed else 0


def package_alone(spec: str) -> ModuleType | None:
    """The generated package of a protocol given by name, when it answers `decode` alone: a text protocol's package,
    or a binary protocol's package that names the directions whose frames carry a checksum and its messages'
    register views (CHECKSUMMED, REGISTER_VIEWS). Then neither the spec's model nor the spec language is imported.
    None for a spec file (or a file of that name here), or a binary package generated before these names."""
    if not spec.isidentifier() or os.path.isfile(spec):
        return None
    package, _, _ = installed_package(spec)
    if is_text(package) or (hasattr(package, "CHECKSUMMED") and hasattr(package, "REGISTER_VIEWS")):
        return package
    return None


def is_text(package: ModuleType) -> bool:
    """Whether a generated package is a text protocol's (its FRAMING a runtime.text.TextFraming)."""
    return hasattr(package, "CODEC") and hasattr(getattr(package, "FRAMING", None), "sentences")


def describe_alone(package: ModuleType, message: Message, frame: bytes) -> dict[str, Any]:
    """`describe` (without units or a request) from what the generated package says."""
    registers = None
    view = package.REGISTER_VIEWS.get(type(message).__name__)
    if view is not None:
        field, start_name, constant = view
        start = message.to_fields().get(start_name)
        maps = submodule(package, "registers")
        if isinstance(start, int) and maps is not None:
            registers = dict(getattr(maps, constant).unpack(start, getattr(message, field)))
    checksummed = package.CHECKSUMMED  # directions, or (layouts chosen by command) message classes
    checksum = message.DIRECTION.value in checksummed or type(message).__name__ in checksummed
    return result(package.PROTOCOL, message, frame, message.to_fields(), checksum, registers, {})


def show(result: dict[str, Any], as_json: bool, lines: Callable[[dict[str, Any]], str] | None = None) -> None:
    """A decoded frame as JSON, or as `lines` writes it for a person (default: `readable`)."""
    if as_json:
        import json

        print(json.dumps(result, ensure_ascii=False), flush=True)
    else:
        print((lines or readable)(result), flush=True)


def replay(args: argparse.Namespace, protocol: Protocol, package: ModuleType) -> int:
    """Decode a capture: each direction's bytes joined again and split into frames (a text protocol's into
    sentences); bad bytes reported. A reply is shown with the last request before it when it answers that request
    (registers by name, as `--request` does)."""
    from serialspec.cli import capture, textframes
    from serialspec.cli.frames import Frames
    from serialspec.cli.views import message_spec
    from serialspec.lang.model import replies_by_request, reply_to

    text = protocol.text is not None
    address = protocol.device.address if protocol.device else None
    streams: dict[str | None, Frames] = {}
    failed = 0
    replies = replies_by_request(protocol.messages())
    asked: Message | None = None  # the last request seen
    awaited: str | None = None  # text: the code of a reply of values alone that the last request gets
    # binary frames read with their request (layouts chosen by command, a reply CRC over request bytes): the reply
    # class the last request gets, and that request, for the replies' own stream
    expecting: tuple[type, Message] | None = None
    stream = sys.stdin if args.file == "-" else capture.open_text(args.file)
    with stream:
        try:
            for number, chunk in capture.read(stream):
                direction = chunk.direction or args.direction
                frames = streams.get(direction) or streams.setdefault(direction, Frames(package, direction, address))
                if text and direction == "response" and awaited is not None:
                    frames.expect_text(awaited)  # the reply's own stream reads it as the answer, once
                    awaited = None
                if direction == "response" and expecting is not None:
                    frames.expect(*expecting)
                    expecting = None
                for seen in frames.feed(chunk.data, number):
                    if seen.message is None:
                        failed += 1
                        bad(seen, text)
                        continue
                    message, request = seen.message, None
                    if text:
                        code: str = getattr(message, "CODE")  # noqa: B009 (a text message; Frames types binary ones)
                        if message.DIRECTION.value == "request" and direction == "request":
                            awaited = package.CODEC.reply_code(code)
                        sentence = package.FRAMING.sentence(code, message.DIRECTION.value)
                        reply = code if sentence.bare else None  # a reply of values alone, read as one
                        result = textframes.describe(protocol.name, package, seen.data, message.DIRECTION.value, reply)
                    else:
                        if message.DIRECTION.value == "request":
                            asked = message
                            reply_spec = reply_to(message_spec(protocol, asked), replies)
                            if direction == "request" and reply_spec is not None and protocol.framing.requesting:
                                expecting = (getattr(package, reply_spec.class_name), asked)
                        elif asked is not None and reply_to(message_spec(protocol, asked), replies) is message_spec(
                            protocol, message
                        ):
                            request = asked
                        result = describe(protocol, message, seen.data, args.units, request)
                    result = {"time": chunk.when, **result} if chunk.when else result
                    show(result, args.json, textframes.readable if text else readable)
        except ValueError as exc:
            raise SerialspecError(f"{args.file}: {exc}") from None
    for frames in streams.values():
        for seen in frames.finish():
            failed += 1
            bad(seen, text)
        if frames.pending():
            failed += 1
            what = "a sentence" if text else "a frame"
            print(
                f"serialspec decode: {args.file} ends inside {what}: {_bytes(frames.pending(), text)}", file=sys.stderr
            )
    return 1 if failed else 0


def bad(seen: Seen, text: bool) -> None:
    """Bad bytes of a capture, under the line their first byte is on."""
    print(f"serialspec decode: line {seen.origin}: {seen.reason} in {_bytes(seen.data, text)}", file=sys.stderr)


def _bytes(data: bytes, text: bool) -> str:
    """Bytes in a message: characters in quotes for a text protocol, hex in brackets for a binary one."""
    return "'" + data.decode("ascii", "backslashreplace") + "'" if text else f"[{data.hex(' ')}]"


def _hex(text: str) -> bytes:
    try:
        return parse_hex(text)
    except ValueError as exc:
        raise DecodeError(str(exc)) from None


def _has_checksum(protocol: Protocol, direction: str) -> bool:
    """Whether the frames of a direction carry a checksum (in any of its layouts)."""
    return any(
        layout.checksums
        for d, layouts in protocol.framing.alternatives.items()
        if d.value == direction
        for layout in layouts
    )


def describe(
    protocol: Protocol, message: Message, frame: bytes, units: bool, request: Message | None
) -> dict[str, Any]:
    from serialspec.cli.views import engineering, message_spec, register_view, unit_symbols

    fields = message.to_fields()
    symbols = {}
    if units:
        fields = engineering(protocol, message, fields)
        symbols = unit_symbols(protocol, message)
    checksum = _has_checksum(protocol, message.DIRECTION.value)
    if protocol.framing.by_command:  # layouts chosen by command: whether the message's own layout carries one
        checksum = bool(protocol.layout(message_spec(protocol, message)).checksums)
    return result(protocol.name, message, frame, fields, checksum, register_view(protocol, message, request), symbols)


def result(
    protocol: str,
    message: Message,
    frame: bytes,
    fields: dict[str, Any],
    checksum: bool,
    registers: dict[str, Any] | None,
    symbols: dict[str, str],
) -> dict[str, Any]:
    """A decoded frame as `--json` prints it."""
    result: dict[str, Any] = {
        "protocol": protocol,
        "direction": message.DIRECTION.value,
        "command": message.COMMAND,
        "subcommand": message.SUBCOMMAND,
        "fields": fields,
        # a frame whose checksum fails does not decode; null where its direction's frames carry none (where layouts
        # are chosen by command: where the message's layout carries none, RoboClaw's read requests)
        "checksum_ok": True if checksum else None,
        "hex": frame.hex(" "),
    }
    if symbols:
        result["units"] = symbols
    if registers is not None:
        result["registers"] = registers
    return result


def readable(result: dict[str, Any]) -> str:
    title = result["command"] + (f".{result['subcommand']}" if result["subcommand"] else "")
    when = f"{result['time']} " if result.get("time") else ""
    lines = [f"{when}{result['protocol']} {result['direction']} {title}  [{result['hex']}]"]
    units = result.get("units", {})
    for name, value in result["fields"].items():
        text = _with_unit(_value(value), units[name]) if name in units else _value(value)
        lines.append(f"  {name:<20} {text}")
    for name, value in (result.get("registers") or {}).items():
        lines.append(f"  register {name:<11} {_value(value)}")
    return "\n".join(lines)


def _with_unit(value: str, unit: str) -> str:
    from serialspec.cli.views import with_unit

    return with_unit(value, unit)


def _value(value: Any) -> str:
    if isinstance(value, list) and type(value) is not list:  # views.FlagNames (--units): the flags' names as words
        return str(value)
    if isinstance(value, dict | list):
        return _json(value)
    return str(value)


def _json(value: Any) -> str:
    """json.dumps(value, ensure_ascii=False): lists and objects of plain integers, names and null (list fields, bit
    fields) written here, the json module imported for anything else (importing it is a tenth of the start of
    `decode PACKAGE HEX`, bench/startup.py)."""
    written = _plain_json(value)
    if written is not None:
        return written
    import json

    return json.dumps(value, ensure_ascii=False)


def _plain_json(value: Any) -> str | None:
    """What json.dumps(value, ensure_ascii=False) writes, for integers, booleans, None, strings without a character
    it escapes, and lists and str-keyed dicts of them; None for anything else."""
    kind = type(value)
    if kind is int:
        return str(value)
    if kind is str:
        plain = '"' not in value and "\\" not in value and all(c >= " " for c in value)
        return f'"{value}"' if plain else None
    if value is None or kind is bool:
        return "null" if value is None else "true" if value else "false"
    if kind is list:
        items = [_plain_json(item) for item in value]
        return None if None in items else "[" + ", ".join(items) + "]"  # type: ignore[arg-type]
    if kind is dict:
        keys = [_plain_json(key) if type(key) is str else None for key in value]
        items = [_plain_json(item) for item in value.values()]
        if None in keys or None in items:
            return None
        return "{" + ", ".join(f"{key}: {item}" for key, item in zip(keys, items, strict=True)) + "}"
    return None
