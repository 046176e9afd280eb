"""serialspec decode: frames (as hex) to their fields, as JSON or a readable field-by-field view."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from serialspec.cli.protocols import open_spec
from serialspec.cli.views import engineering, message_spec, register_view
from serialspec.runtime.errors import DecodeError, SerialspecError
from serialspec.runtime.hexbytes import parse_hex
from serialspec.runtime.message import Message
from serialspec.spec.model import Protocol, replies_by_request, reply_to

HELP = "decode frames given as hex ('12 4c 08', '0x12 0x4c', '124c08', '12:4c:08'); one frame per argument"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help="the protocol's spec file, e.g. specs/fashionstar_uart.yaml")
    parser.add_argument("hex", nargs="+", help="one frame per argument")
    parser.add_argument("--json", action="store_true", help="one JSON object per frame")
    parser.add_argument(
        "--direction",
        choices=("request", "response"),
        help="needed where requests and responses share a header",
    )
    parser.add_argument("--units", action="store_true", help="engineering units and enum names, not raw values")
    parser.add_argument("--request", metavar="HEX", help="the request a response answers (shows registers by name)")


def run(args: argparse.Namespace) -> int:
    protocol, package = open_spec(args.spec)
    request = None
    expect = None  # the reply layout the request gets, where replies share a code
    if args.request:
        request = package.decode(_hex(args.request), "request")
        reply = reply_to(message_spec(protocol, request), replies_by_request(protocol.messages()))
        expect = next((c for c in package.MESSAGE_TYPES if reply and c.__name__ == reply.class_name), None)
    failed = 0
    for text in args.hex:
        try:
            frame = _hex(text)
            message = package.decode(frame, args.direction, expect)
        except (DecodeError, SerialspecError) as exc:
            print(f"serialspec decode: {text.strip()}: {exc}", file=sys.stderr)
            failed += 1
            continue
        result = describe(protocol, message, frame, args.units, request)
        if args.json:
            print(json.dumps(result, ensure_ascii=False))
        else:
            print(readable(result))
    return 1 if failed else 0


def _hex(text: str) -> bytes:
    try:
        return parse_hex(text)
    except ValueError as exc:
        raise DecodeError(str(exc)) from None


def describe(
    protocol: Protocol, message: Message, frame: bytes, units: bool, request: Message | None
) -> dict[str, Any]:
    fields = message.to_fields()
    if units:
        fields = engineering(protocol, message, fields)
    result: dict[str, Any] = {
        "protocol": protocol.name,
        "direction": message.DIRECTION.value,
        "command": message.COMMAND,
        "subcommand": message.SUBCOMMAND,
        "fields": fields,
        "checksum_ok": True,  # a frame whose checksum fails does not decode
        "hex": frame.hex(" "),
    }
    registers = register_view(protocol, message, request)
    if registers is not None:
        result["registers"] = registers
    return result


def readable(result: dict[str, Any]) -> str:
    title = result["command"] + (f".{result['subcommand']}" if result["subcommand"] else "")
    lines = [f"{result['protocol']} {result['direction']} {title}  [{result['hex']}]"]
    for name, value in result["fields"].items():
        lines.append(f"  {name:<20} {_value(value)}")
    for name, value in (result.get("registers") or {}).items():
        lines.append(f"  register {name:<11} {_value(value)}")
    return "\n".join(lines)


def _value(value: Any) -> str:
    if isinstance(value, dict | list):
        return json.dumps(value, ensure_ascii=False)
    return str(value)
