"""serialspec encode: a JSON object (the shape decode prints) to a frame as hex."""

from __future__ import annotations

import argparse
import json
from typing import Any

from serialspec.cli.protocols import SPEC_HELP, message_type, open_binary_spec
from serialspec.runtime.errors import EncodeError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help=SPEC_HELP)
    parser.add_argument(
        "--json",
        required=True,
        metavar="OBJ",
        help="the object decode --json prints; length, checksum, counts and hex may be left out",
    )
    parser.add_argument("--direction", choices=("request", "response"), help="overrides the object's direction")


def run(args: argparse.Namespace) -> int:
    _, package = open_binary_spec(args.spec, "encode")
    try:
        data: Any = json.loads(args.json)
    except json.JSONDecodeError as exc:
        raise EncodeError(f"--json is not valid JSON: {exc.msg} at column {exc.colno}") from None
    except (ValueError, RecursionError) as exc:  # a number of thousands of digits, lists nested thousands deep
        raise EncodeError(f"--json cannot be read: {str(exc).split(';')[0]}") from None
    if not isinstance(data, dict) or "command" not in data:
        raise EncodeError("--json must be an object with at least `command` and `fields`")
    direction = args.direction or data.get("direction") or "request"
    if direction not in ("request", "response"):
        raise EncodeError(f"`direction` must be 'request' or 'response', got {direction!r}")
    cls = message_type(package, data["command"], data.get("subcommand"), direction)
    fields = data.get("fields", {})
    if not isinstance(fields, dict):
        raise EncodeError("`fields` must be an object")
    message = cls.from_fields(fields)  # type: ignore[attr-defined]
    print(package.encode(message).hex(" "))
    return 0
