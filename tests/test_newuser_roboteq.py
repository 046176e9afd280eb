"""Roboteq motor controllers' ASCII commands, tried by a new user from the docs: a query `?A 1` (code, a space, the
channel) is answered by `A=12` (the code without its `?`, `=`, the values separated by `:`), and a command `!G 1 500`
by `+`. The reply is a line under another code whose fields follow `=` and are separated by `:`: a message's own
`text:` without a `start`, found by its code (`text: {separator: "=", list: ":"}`)."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import generate_and_import
from serialspec.lang import SpecErrors, load_protocol

REQUESTS = """
protocol: roboteq_requests
title: Roboteq motor controllers' serial commands
serial: {baudrate: 115200}
framing:
  kind: text
  separator: " "
  end: "\\r"
commands:
  motor_amps:
    code: "?A"
    request:
      fields:
        channel: {type: integer, range: [1, 2]}
  go:
    code: "!G"
    request:
      fields:
        channel: {type: integer, range: [1, 2]}
        value: {type: integer, range: [-1000, 1000]}
"""

REPLY = """
  amps:
    code: A
    response:
      text: {separator: "=", list: ":"}
      fields:
        amps: {type: repeat, max_count: 2, fields: {value: {type: integer, unit: dA}}}
"""


def test_the_requests(tmp_path: Path) -> None:
    path = tmp_path / "roboteq_requests.yaml"
    path.write_text(REQUESTS, "utf-8")
    module = generate_and_import(path, tmp_path / "out", "roboteq_requests")
    assert module.encode(module.GoRequest(channel=1, value=500)) == b"!G 1 500\r"
    assert module.decode(b"?A 1\r", module.Direction.REQUEST) == module.MotorAmpsRequest(channel=1)


def test_a_reply_under_another_code_with_its_own_separators(tmp_path: Path) -> None:
    """Found here: a message's own text needed a `start` no code has, so `A=12:13` could not be described; without
    one the message is found by its code, then its own separator."""
    path = tmp_path / "roboteq_replies.yaml"
    answered = REQUESTS.replace(
        'code: "?A"\n    request:', 'code: "?A"\n    request:\n      answered_by: {command: amps}'
    )
    path.write_text(answered.replace("protocol: roboteq_requests", "protocol: roboteq_replies") + REPLY, "utf-8")
    module = generate_and_import(path, tmp_path / "out", "roboteq_replies")
    reply = module.decode(b"A=12:13\r", module.Direction.RESPONSE)
    assert [item.value for item in reply.amps] == [12, 13]
    assert module.encode(reply) == b"A=12:13\r"
    assert module.decode(b"A=-5\r").amps[0].value == -5  # one motor
    assert module.CODEC.replies("?A") == ((module.AmpsResponse,), ())
    with pytest.raises(SpecErrors, match=r"commands\.amps\.response\.text\.after_code: `after_code` is one"):
        broken = REPLY.replace('separator: "="', 'separator: "=", after_code: "=="')
        load_protocol_text(REQUESTS + broken, tmp_path)


def load_protocol_text(text: str, tmp_path: Path) -> None:
    path = tmp_path / "broken.yaml"
    path.write_text(text, "utf-8")
    load_protocol(str(path))
