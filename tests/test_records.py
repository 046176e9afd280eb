"""Messages are tuples underneath (runtime/message.py): nothing of the tuple may show.

Decoders build a message as a tuple subclass in one call; everything a frozen dataclass promised must still hold,
and nothing a tuple offers may leak: no equality with plain tuples, no length, indexing, iteration or ordering, and
a message with no fields is still true.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import pickle
from typing import Any

import pytest
from conftest import ALL, Generated, by_protocol, examples
from hypothesis import HealthCheck, given, settings
from serialspec.lang.model import Message
from serialspec.runtime.errors import EncodeError
from serialspec.runtime.message import Record, build, field_names, is_sequence, replace
from strategies import message_fields

MESSAGES = by_protocol([(g, m) for g in ALL for m in g.protocol.messages()])


def message_type(g: Generated, spec: Message) -> Any:
    return next(c for c in g.package.MESSAGE_TYPES if c.__name__ == spec.class_name)


def values(record: Record) -> tuple[Any, ...]:
    return tuple(getattr(record, name) for name in field_names(record))


@pytest.mark.parametrize(("g", "spec"), MESSAGES)
def test_a_message_behaves_as_a_frozen_record_not_a_tuple(g: Generated, spec: Message) -> None:
    cls = message_type(g, spec)

    @settings(max_examples=examples(10), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(message_fields(g.protocol, spec))
    def check(fields: dict[str, Any]) -> None:
        message = cls.from_fields(fields)
        plain = values(message)
        # built from its values in one call, it is the same message
        assert build(cls, plain) == message and type(build(cls, plain)) is cls
        # equal to its own class only: never to the tuple of its values, either way round
        assert message != plain and plain != message
        assert (message == plain, plain == message) == (False, False)
        assert (message == cls(*plain), message != cls(*plain)) == (True, False)
        assert hash(message) == hash(plain)  # as when it hashed the tuple of its values
        # true even without fields; no length, items, iteration or order
        assert bool(message) is True
        for use in (len, iter, list, lambda m: m[0], lambda m: 0 in m, lambda m: m + (), lambda m: 2 * m):
            with pytest.raises(TypeError, match="not a sequence"):
                use(message)
        for order in (lambda a, b: a < b, lambda a, b: a >= b):
            with pytest.raises(TypeError):
                order(message, message)
            with pytest.raises(TypeError):
                order(plain, message)
        assert not is_sequence(message)
        # frozen, pickled and copied by class and values
        for name in field_names(message):
            with pytest.raises(dataclasses.FrozenInstanceError):
                setattr(message, name, 0)
            with pytest.raises(dataclasses.FrozenInstanceError):
                delattr(message, name)
        for again in (pickle.loads(pickle.dumps(message)), copy.copy(message), copy.deepcopy(message)):
            assert again == message and type(again) is cls
        assert replace(message) == message
        assert cls.from_fields(message.to_fields()) == message
        assert repr(message).startswith(f"{cls.__qualname__}(")
        json.dumps(message.to_fields())  # the JSON form is the fields, by name

    check()


def test_a_message_without_fields_is_true_and_matches_by_class() -> None:
    from serialspec_protocols import fashionstar_uart as fs

    message = fs.BeginAsyncRequest()
    assert field_names(message) == () and bool(message) is True
    assert message == fs.BeginAsyncRequest() and message != ()
    match fs.RotateRequest(servo_id=2, angle=900, interval=500):
        case fs.RotateRequest(2, angle=900, power=0):
            pass
        case _:
            pytest.fail("class pattern did not match")


def test_a_record_where_a_number_or_list_belongs_is_refused_in_one_line() -> None:
    """A record is a tuple underneath; the runtime's list checks must not take it for a list of values."""
    from serialspec_protocols import fashionstar_uart as fs
    from serialspec_protocols import hiwonder_rrc as rrc

    stray = fs.PingRequest(servo_id=1)
    with pytest.raises(EncodeError, match="^rotate request: [^\n]*PingRequest[^\n]*$"):
        fs.encode(fs.RotateRequest(servo_id=1, angle=stray, interval=0))  # type: ignore[arg-type]
    with pytest.raises(EncodeError, match="motors must be a list"):
        rrc.MotorSetSpeedsRequest.from_fields({"motors": stray})
    with pytest.raises(EncodeError, match="motors must be a tuple"):
        rrc.encode(rrc.MotorSetSpeedsRequest(motors=stray))  # type: ignore[arg-type]
