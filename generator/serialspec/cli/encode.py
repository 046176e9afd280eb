"""serialspec encode: a JSON object (the shape decode prints) to a frame as hex."""

from __future__ import annotations

import argparse
import json
from typing import Any

from serialspec.cli.protocols import SPEC_HELP, message_type, open_spec
from serialspec.runtime.errors import DecodeError, EncodeError
from serialspec.runtime.hexbytes import parse_hex
from serialspec.runtime.message import takes_request


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help=SPEC_HELP)
    parser.add_argument(
        "--json",
        required=True,
        metavar="OBJ",
        help="the object decode --json prints; length, checksum, counts and hex may be left out",
    )
    parser.add_argument("--direction", choices=("request", "response"), help="overrides the object's direction")
    parser.add_argument("--hex", action="store_true", help="a text protocol's sentence as hex, not as text")
    parser.add_argument(
        "--request", metavar="HEX", help="the request a response answers, where its frame is made with it (RoboClaw)"
    )


def only_direction(package: Any, data: dict[str, Any]) -> str:
    """The direction a command goes in when the object names none: its only one (a receiver's unsolicited frame is
    a response), else a request."""
    found = {
        cls.DIRECTION.value
        for cls in getattr(package, "MESSAGE_TYPES", ())
        if (data["command"], data.get("subcommand")) == (cls.COMMAND, cls.SUBCOMMAND)
    }
    return found.pop() if len(found) == 1 else "request"


def run(args: argparse.Namespace) -> int:
    protocol, package = open_spec(args.spec)
    try:
        data: Any = json.loads(args.json)
    except json.JSONDecodeError as exc:
        raise EncodeError(f"--json is not valid JSON: {exc.msg} at column {exc.colno}") from None
    except (ValueError, RecursionError) as exc:  # a number of thousands of digits, lists nested thousands deep
        raise EncodeError(f"--json cannot be read: {str(exc).split(';')[0]}") from None
    if not isinstance(data, dict) or "command" not in data:
        raise EncodeError("--json must be an object with at least `command` and `fields`")
    direction = args.direction or data.get("direction") or only_direction(package, data)
    if direction not in ("request", "response"):
        raise EncodeError(f"`direction` must be 'request' or 'response', got {direction!r}")
    if protocol.text is not None:
        from serialspec.cli import textframes

        return textframes.encode(package, data, args.direction or data.get("direction"), args.hex)
    cls = message_type(package, data["command"], data.get("subcommand"), direction)
    fields = data.get("fields", {})
    if not isinstance(fields, dict):
        raise EncodeError("`fields` must be an object")
    printed = {"protocol", "direction", "command", "subcommand", "fields", "checksum_ok", "hex", "units", "registers"}
    astray = sorted(set(data) - printed - {"time"})  # what decode --json (and a capture's lines) print
    if astray:  # {"command": "drive", "velocity": -200}: the field values belong in `fields`
        keys = ", ".join(astray)
        raise EncodeError(f"--json: unknown key{'s' if len(astray) > 1 else ''} {keys} (field values go in `fields`)")
    message = cls.from_fields(fields)  # type: ignore[attr-defined]
    if args.request and takes_request(package.encode):  # a reply made with its request (a checksum over its bytes)
        try:
            request = package.decode(parse_hex(args.request), "request")
        except (ValueError, DecodeError) as exc:
            raise EncodeError(f"--request: {exc}") from None
        print(package.encode(message, request).hex(" "))
        return 0
    try:
        print(package.encode(message).hex(" "))
    except EncodeError as exc:
        hint = " (--request HEX)" if str(exc).endswith("give the request this reply answers") else ""
        raise EncodeError(f"{exc}{hint}") from None
    return 0
