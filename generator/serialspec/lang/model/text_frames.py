"""Text protocols (`framing: text`): sentences of delimited fields, their examples and the device answering them."""

from __future__ import annotations

from dataclasses import field
from typing import Literal

from serialspec.checksums.base import Algorithm
from serialspec.lang.expression import Expr
from serialspec.lang.frozen import frozen
from serialspec.lang.model.device import Unsolicited
from serialspec.runtime.message import Direction


@frozen
class TextField:
    """One field of a text frame (runtime/text.py's TextField, as declared)."""

    name: str
    kind: Literal["decimal", "integer", "angle", "char", "text", "time", "date"]
    description: str = ""
    unit: str = ""
    precision: int = 0
    width: int = 0
    minimum: float | None = None
    maximum: float | None = None
    letters: tuple[tuple[str, str], ...] = ()  # char: (label, letter)
    letters_class: str = ""  # char with letters: the generated Enum's name
    label: str = ""  # in a message with its own text layout (`named`): the label its value follows
    address: bool = False  # the framing's `address`: every message's first field, written before the code
    rest: bool = False  # text `size: rest`: the rest of the line, separators included (the last field)
    base: Literal[10, 16] = 10  # integer: its digits' base (16: hex digits, an ELM327's `1A F8`)
    lower: bool = False  # integer with base 16: hex digits written in lower case (`case: lower`)


@frozen
class TextRepeat:
    """A group of text fields repeated `count` times, or up to `max_count` times at the end of a message."""

    name: str
    fields: tuple[TextField, ...]
    description: str = ""
    count: int = 0
    max_count: int = 0
    label: str = ""  # in a message with its own text layout: the label its values follow (joined by `list`)


@frozen
class TextLayout:
    """A message's own text inside the frame (`text:`): start + code + separated fields + end; with `named`, fields
    found by their labels (label, `named`, value), a repeat's values joined by `list`."""

    start: str = ""
    end: str = ""
    separator: str = ","
    named: str = ""
    list: str = ""
    after_code: str | None = None  # between the code and the first field (None: the separator; "": glued)
    glued: bool = False  # labels glued to their values (`named: ""`): G-code's `X10.5`, LSS's `D1800T1500`

    @property
    def labelled(self) -> bool:
        """Whether its fields are found by their labels (`named`, or labels glued to their values)."""
        return bool(self.named) or self.glued

    @property
    def follows_code(self) -> str:
        """What is written between the code and the first field: `after_code`, else the separator."""
        return self.separator if self.after_code is None else self.after_code


@frozen
class TextMessage:
    """One direction of a command in a text protocol: chosen by its text code."""

    key: str  # the command's name
    code: str  # the code its frames carry: the command's, or its `text: {code}` (an ELM327's reply `41 0C`)
    title: str
    description: str
    direction: Direction
    class_name: str
    fields: tuple[TextField | TextRepeat, ...]
    unsolicited: bool = False
    source: str = ""
    answered_by: str = ""  # a request answered by another command's response (its key): GRBL's `ok`
    refused_by: tuple[str, ...] = ()  # commands whose responses refuse the request instead: GRBL's `error:N`
    then: str = ""  # a request: the command whose response ends its answer, after the reply (an AT command's `OK`)
    many: bool = False  # with `then`: the reply comes any number of times before it (AT+CWLAP's access points)
    layout: TextLayout | None = None  # its own text inside the frame (`text:`): GRBL's `<Idle|MPos:…>`
    values_only: bool = False  # a reply of its values alone, no code: read as the answer to the request before it

    @property
    def code_labelled(self) -> bool:
        """Whether a field is labelled with the message's own code (GRBL's sub-state `Hold:0`, LSS's `D1800`): its
        value is written right after the code."""
        return self.layout is not None and self.layout.labelled and any(f.label == self.code for f in self.fields)

    @property
    def read_after_code(self) -> str:
        """What a frame of it found by its code has between the code and its fields: nothing where its labels are
        glued to their values and one is the code (the value right after it, LSS's `D1800`), else `follows_code`."""
        assert self.layout is not None
        return "" if self.layout.glued and self.code_labelled else self.layout.follows_code


@frozen
class TextExample:
    """A frame as a document prints it (text) and the text of each field it carries."""

    name: str
    source: str
    description: str
    direction: Direction
    printed: str
    command: str
    fields: dict[str, object]
    position: tuple[int, int] = (1, 1)  # line and column in the spec, for errors found after resolution


@frozen
class TextAnswer:
    """How a text device answers one command's request (`device.commands.NAME`): request fields kept in state
    variables, state variables set, and the answer's fields from expressions of the state or from the request."""

    command: str
    description: str = ""
    stores: dict[str, str] = field(default_factory=dict)  # request field -> state variable
    sets: dict[str, float] = field(default_factory=dict)  # state variable -> value
    reports: dict[str, Expr] = field(default_factory=dict)  # response field -> expression of state variables
    echoes: tuple[str, ...] = ()  # response fields that repeat the request's field of the same name


@frozen
class TextDevice:
    """A text protocol's virtual device (`device:`): its state variables, the values every sentence it sends
    carries (`reply`), the sentences it sends on its own, and how it answers requests (`commands`: every command
    with a request and a response is answered, as its entry there says)."""

    description: str
    state: dict[str, float]
    reply: dict[str, str | float]
    sends: tuple[Unsolicited, ...]
    commands: tuple[TextAnswer, ...] = ()


@frozen
class TextFrame:
    """Line-oriented text frames: start + talker + code + separated fields + [marker + checksum as hex] + end."""

    description: str
    start: str
    separator: str
    end: str
    checksum: Algorithm | None
    marker: str
    required: bool
    talker: int  # characters of the talker at the start of the address field (0: none)
    talkers: tuple[str, ...]
    talker_description: str
    max_length: int
    messages: tuple[TextMessage, ...]
    examples: tuple[TextExample, ...] = ()
    digits: int = 2
    device: TextDevice | None = None
    checksum_format: Literal["hex2", "decimal"] = "hex2"  # how the checksum is written after the marker
    checksum_directions: tuple[str, ...] = ("request", "response")  # the directions whose frames carry it
    checksum_separated: tuple[str, ...] = ()  # the directions that write the separator before the marker
    response_start: str = ""  # the responses' own start where it differs from the requests' (`start`): LSS's `*`
    address: TextField | None = None  # every message's first field, its digits before the code (LSS's servo id)
    response_end: str = ""  # the responses' own line ending where it differs from the requests' (`end`): ELM327's

    def end_of(self, direction: Direction) -> str:
        """The line ending of a frame in `direction` (the requests' where the responses have none of their own)."""
        return self.response_end if direction == Direction.RESPONSE and self.response_end else self.end

    def message(self, key: str, direction: Direction = Direction.RESPONSE) -> TextMessage:
        """The command's message in `direction` (its response by default: what a device sends)."""
        return next(m for m in self.messages if m.key == key and m.direction == direction)

    def request(self, key: str) -> TextMessage | None:
        return next((m for m in self.messages if m.key == key and m.direction == Direction.REQUEST), None)

    def response(self, key: str) -> TextMessage | None:
        return next((m for m in self.messages if m.key == key and m.direction == Direction.RESPONSE), None)

    def answer(self, request: TextMessage) -> TextMessage | None:
        """The response that answers a request: its own command's, or the one it is `answered_by`."""
        return self.response(request.answered_by or request.key)

    def answers(self) -> dict[str, tuple[tuple[str, ...], ...]]:
        """Each request code answered by another command (`answered_by`) or under a code of its own (`text.code`),
        refused by some (`refused_by`), or whose answer ends with another's response (`then`) -> the codes of the
        responses that answer it, of those that refuse it, and (with `then`) of the one that ends the answer."""
        codes = {m.key: m.code for m in self.messages if m.direction == Direction.RESPONSE}
        return {
            m.code: ((codes[m.answered_by or m.key],), tuple(codes[k] for k in m.refused_by))
            + (((codes[m.then],),) if m.then else ())
            for m in self.messages
            if m.direction == Direction.REQUEST
            and (m.answered_by or m.refused_by or m.then or codes.get(m.key, m.code) != m.code)
        }

    def letter_sets(self) -> dict[str, tuple[tuple[str, str], ...]]:
        """Each generated letter Enum's name -> its (label, letter) pairs, in order of first use."""
        found: dict[str, tuple[tuple[str, str], ...]] = {}
        for message in self.messages:
            for item in message.fields:
                for f in item.fields if isinstance(item, TextRepeat) else (item,):
                    if f.letters_class:
                        found.setdefault(f.letters_class, f.letters)
        return found
