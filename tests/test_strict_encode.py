"""Strict encode in the messages and the clients (the CLI's is in test_cli_fuzz.py): a value of the wrong type or out
of range is refused with one line naming the field, before a byte is written; True is not 1, NaN is not a number."""

from __future__ import annotations

import select
from collections.abc import Iterator
from typing import Any

import pytest
from conftest import ALL, Generated, by_protocol
from serialspec.lang.model import Example, Scalar
from serialspec.runtime.errors import EncodeError
from serialspec.runtime.message import field_names
from test_captures import pty_pair

BAD = [True, False, 1.5, float("nan"), float("inf"), "1", None, [1], {"a": 1}, 10**40, -(10**40)]


def scalar_fields(g: Generated, example: Example) -> list[str]:
    """The example's integer fields a caller gives: frame values (an address) and the message's own scalars."""
    messages = [
        m
        for m in g.protocol.messages()
        if (m.command, m.subcommand, m.direction)
        == (
            example.command,
            example.subcommand,
            example.direction,
        )
    ]
    names = [e.name for e in g.protocol.framing.layouts[example.direction].value_elements]
    names += [f.name for f in messages[0].fields if isinstance(f, Scalar) and not f.hidden and not f.bits]
    return [n for n in names if n in example.fields and isinstance(example.fields[n], int)]


EXAMPLES = by_protocol([(g, e) for g in ALL for e in g.protocol.examples])


def message_class(g: Generated, example: Example) -> Any:
    return next(
        c
        for c in g.package.MESSAGE_TYPES
        if (c.COMMAND, c.SUBCOMMAND, c.DIRECTION.value) == (example.command, example.subcommand, example.direction)
    )


@pytest.mark.parametrize(("g", "example"), EXAMPLES)
def test_messages_from_data_refuse_wrong_values(g: Generated, example: Example) -> None:
    cls = message_class(g, example)
    for name in scalar_fields(g, example):
        for bad in BAD:
            with pytest.raises(EncodeError) as failure:
                g.package.encode(cls.from_fields({**example.fields, name: bad}))
            text = str(failure.value)
            assert name in text and "\n" not in text, text
            assert "not supported between" not in text and "argument" not in text, text


def replaced(message: Any, name: str, value: Any) -> Any:
    """A copy of a message with one field changed, through its keyword constructor."""
    return type(message)(**{**{n: getattr(message, n) for n in field_names(message)}, name: value})


@pytest.mark.parametrize(("g", "example"), EXAMPLES)
def test_messages_built_in_python_refuse_wrong_values(g: Generated, example: Example) -> None:
    message = message_class(g, example).from_fields(example.fields)
    for name in scalar_fields(g, example):
        for bad in BAD:
            with pytest.raises(EncodeError) as failure:
                g.package.encode(replaced(message, name, bad))
            text = str(failure.value)
            assert name in text and "\n" not in text, text


def test_flags_take_members_or_in_range_integers() -> None:
    sms = next(g for g in ALL if g.protocol.name == "feetech_sms")
    reply = sms.package.messages.ReplyResponse
    for bad, words in ((-1, "error = -1 is outside its range 0..255"), (256, "256 is outside"), (True, "integer")):
        with pytest.raises(EncodeError, match=words):
            sms.package.encode(reply.from_fields({"id": 1, "error": bad, "data": ""}))
    frame = sms.package.encode(reply.from_fields({"id": 1, "error": 0x24, "data": ""}))
    assert sms.package.decode(frame, "response").error == 0x24


@pytest.fixture
def line() -> Iterator[tuple[int, str]]:
    """A pseudo-terminal: the controller end (to see what a client writes) and the device path it opens."""
    with pty_pair() as pair:
        yield pair


def nothing_written(controller: int) -> bool:
    readable, _, _ = select.select([controller], [], [], 0)
    return not readable


@pytest.mark.parametrize("bad", [True, 1.5, float("nan"), "90", None, 10**40, 40000])
def test_client_refuses_before_writing(line: tuple[int, str], bad: Any) -> None:
    from serialspec_protocols.fashionstar_uart.client import FashionstarUartClient

    controller, path = line
    with FashionstarUartClient(path, timeout=0.05) as client, pytest.raises(EncodeError) as failure:
        client.rotate(1, bad, 500)
    assert "angle" in str(failure.value) and "\n" not in str(failure.value)
    assert nothing_written(controller)


@pytest.mark.parametrize("bad", [True, 1.5, "1", None, 10**40, 300])
def test_a_request_awaiting_its_reply_is_refused_before_writing(line: tuple[int, str], bad: Any) -> None:
    """Bus.request calls the command's encoder at once; what it refuses is refused as encode refuses it."""
    from serialspec_protocols.fashionstar_uart.client import FashionstarUartClient

    controller, path = line
    with FashionstarUartClient(path, timeout=0.05) as client, pytest.raises(EncodeError) as failure:
        client.read_angle(bad)
    assert "servo_id" in str(failure.value) and "\n" not in str(failure.value)
    assert nothing_written(controller)


def test_feetech_client_writes_a_register_named_like_its_address_parameter(line: tuple[int, str]) -> None:
    """`write(id, /, **values)`: the register `id` is a keyword, the servo id positional; range checked first."""
    from serialspec_protocols.feetech_sms.client import FeetechSmsClient

    controller, path = line
    with FeetechSmsClient(path, timeout=0.05) as client:
        with pytest.raises(EncodeError, match="id"):
            client.write(1, id=254)  # 254 is the broadcast id: no servo can have it (the register's range)
        assert nothing_written(controller)
        with pytest.raises(EncodeError):
            client.write(1, id=True)
        assert nothing_written(controller)


def test_an_enum_value_without_a_range_takes_only_its_declared_span() -> None:
    """Fashion Star's response_switch is 0 or 1 (enum response_switch, no `range:`): 7 never reaches the wire."""
    fs = next(g for g in ALL if g.protocol.name == "fashionstar_uart")
    request = fs.package.messages.WriteDataRequest
    with pytest.raises(EncodeError, match="data = 7 is outside its range 0..1"):
        fs.package.encode(request.from_fields({"servo_id": 1, "data_id": 33, "data": 7}))
    assert fs.package.encode(request.from_fields({"servo_id": 1, "data_id": 33, "data": 1}))
