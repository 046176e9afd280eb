"""Commands, sub-commands and their messages (one direction each), and how requests pair with replies."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Literal

from serialspec.lang.frozen import frozen
from serialspec.lang.model.fields import Field, ScalarType
from serialspec.runtime.message import Direction


@frozen
class OptionalWhen:
    """A response the device sends only while one of its parameters (a table entry) compares true with a value."""

    table: str
    entry: str
    key: int
    equals: int  # the value compared with
    op: Literal["==", "!=", ">=", "<="] = "=="

    @property
    def symbol(self) -> str:
        """The comparison as people write it: =, ≠, ≥ or ≤."""
        return {"==": "=", "!=": "≠", ">=": "≥", "<=": "≤"}[self.op]


@frozen
class Message:
    """One direction of a command or sub-command."""

    command: str
    subcommand: str | None
    direction: Direction
    class_name: str
    title: str
    description: str
    fields: tuple[Field, ...]  # content fields in wire order, selector included
    optional: str
    unsolicited: bool
    answers: str
    min_size: int  # content length bounds, for decoding and stream plausibility
    max_size: int | None
    source: str
    optional_when: OptionalWhen | None = None  # a response sent only when a device parameter has a value
    after: str = ""  # a response sent once the request's field of this name (ms) has elapsed
    answered_by: str = ""  # a request answered by another command's response (its key)
    # a request answered by the response of the command whose code its field of this name holds (`command_in`)
    asks_in: str = ""
    error_reply: bool = False  # the reply a device sends instead of any other (Modbus exceptions: code | flag)
    reply_when: OptionalWhen | None = None  # a request whose reply is sent only when a device parameter has a value
    struct_name: str = ""  # the construct struct of its content
    default_reply: bool = False  # among replies sharing a code: the one a frame is decoded as without its request
    refused_by: tuple[str, ...] = ()  # a request: the commands whose responses refuse it (it raises DeviceError)
    request_code: str = ""  # a response: its field holding the code of the request it answers (u-blox ACK)
    # a content sent without its trailing zero bytes (`truncate: trailing_zeros`): its full size, to which decoding
    # pads it (min_size is then the smallest size sent); None where the frame sends contents whole
    padded: int | None = None
    layout: str = ""  # the name of the layout its frames travel in, where layouts are chosen by command ("": first)

    @property
    def key(self) -> str:
        return f"{self.command}.{self.subcommand}" if self.subcommand else self.command


def sizes_text(message: Message) -> str:
    """A message's content sizes, as people read them: 4 bytes, 0..8 bytes, 2 bytes or more."""
    low, high = message.min_size, message.max_size
    if low == high:
        return f"{low} byte" + ("" if low == 1 else "s")
    return f"{low}..{high} bytes" if high is not None else f"{low} byte{'' if low == 1 else 's'} or more"


def sized_apart(messages: Iterable[Message], by_request: bool = False) -> bool:
    """Whether the messages that share a code (or, in frames without a command element, all of a direction's) are
    told apart by their content size, or a leading constant (lang/model/discriminator.py): requests always; replies
    when none of them is the `default` (the one decoded without its request, the others chosen by the request they
    answer), unless they carry no code and are read in the layout of their request (`by_request`)."""
    found = list(messages)
    if len(found) < 2:
        return False
    if found[0].direction == Direction.REQUEST:
        return True
    return not by_request and not any(m.default_reply for m in found)


def replies_by_request(responses: Iterable[Message]) -> dict[str, Message]:
    """Responses by the request they answer: their own command's, or the one they say they `answers`.

    A response the device also sends on its own (`unsolicited`) answers only the request it names in `answers`,
    and a request whose `answered_by` names it (a sensor's measurement, streamed, or sent when polled: SDS011,
    PMS5003 in passive mode); never its own command's request, which a device streaming it does not await."""
    messages = list(responses)
    requests = {m.key for m in messages if m.direction == Direction.REQUEST}
    index: dict[str, Message] = {}
    for response in messages:
        if response.direction != Direction.RESPONSE:
            continue
        if not response.unsolicited:
            index.setdefault(response.answers or response.key, response)
            if response.answers and response.key not in requests:  # and an `answered_by` naming it, as it says
                index.setdefault(response.key, response)
        elif response.answers:
            index.setdefault(response.answers, response)
        elif response.key not in requests:
            index.setdefault(response.key, response)  # reached only by an `answered_by` naming it
    return index


def reply_to(request: Message, replies: dict[str, Message]) -> Message | None:
    """The response that answers a request (from `replies_by_request`), or the one it is `answered_by`."""
    return replies.get(request.answered_by or request.key)


def refusals_of(request: Message, replies: dict[str, Message]) -> tuple[Message, ...]:
    """The responses that refuse a request (its `refused_by`), from `replies_by_request`."""
    return tuple(replies[name] for name in request.refused_by if name in replies)


def reply_condition(request: Message, response: Message | None) -> OptionalWhen | None:
    """The device parameter that switches a request's reply on and off, if any."""
    return request.reply_when or (response.optional_when if response else None)


@frozen
class Selector:
    name: str
    type: ScalarType
    offsets: dict[Direction, int]


@frozen
class Subcommand:
    name: str
    code: int
    title: str
    title_cn: str
    description: str
    request: Message | None
    response: Message | None
    source: str


@frozen
class Command:
    name: str
    code: int | None
    title: str
    title_cn: str
    description: str
    broadcast: str
    source: str
    request: Message | None
    response: Message | None
    selector: Selector | None
    subcommands: tuple[Subcommand, ...]
    group_class: str = ""  # the client's class grouping the sub-commands' methods ("" without sub-commands)
    probe: bool = False  # asks whether a device is there: clients return True/False, never raise Timeout
    response_code: int | None = None  # the code of its response frames, where it differs (HerkuleX: code | 0x40)

    def wire_code(self, direction: Direction) -> int | None:
        """The code its frames of one direction carry: `code`, or in responses the command element's `reply_code`."""
        if direction == Direction.RESPONSE and self.response_code is not None:
            return self.response_code
        return self.code

    def messages(self) -> tuple[Message, ...]:
        found = [m for m in (self.request, self.response) if m]
        for sub in self.subcommands:
            found.extend(m for m in (sub.request, sub.response) if m)
        return tuple(found)
