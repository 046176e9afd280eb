"""Line-oriented text frames (NMEA 0183: `$GPGGA,…*hh\\r\\n`) and the text fields they carry.

A text frame is a start character, an address field (a frame-level value such as NMEA's talker, then the text code
that chooses the message), fields separated by a delimiter, optionally a checksum written as hex digits after a
marker, and a line ending. Everything here is driven by descriptors (what generated code declares from a spec); no
protocol fact lives in this module.

Decoded values keep the digits a device sent, so re-encoding a decoded sentence gives the same text: decimals are
`Fixed` (a `Decimal` that remembers its leading zeros: "000.90" stays "000.90"), times are `Clock` (a
`datetime.time` that remembers its fraction digits), ddmm.mmmm coordinates are `Angle` (degrees and `Decimal`
minutes), and a sentence remembers how many fields it had (trailing empty fields included). An empty field is
`None`.
"""

from __future__ import annotations

import datetime
from collections.abc import AsyncIterator, Callable, Generator, Iterable, Iterator, Mapping
from decimal import Decimal, InvalidOperation
from enum import Enum

from serialspec.runtime.errors import ChecksumError, DecodeError, EncodeError, RangeError, shown
from serialspec.runtime.message import Direction
from serialspec.runtime.values import asdict, dataclass, field, fields, replace

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any, ClassVar, Literal

    TextKind = Literal["decimal", "integer", "angle", "char", "text", "time", "date"]
else:
    TextKind = str  # what it is at run time (typing's Literal is not imported)


class Clock(datetime.time):
    """A time of day read from text (hhmmss[.ss]); `digits` is how many fraction digits of a second it was sent
    with, so encoding it again writes the same text."""

    digits: int

    def __new__(cls, hour: int, minute: int, second: int, microsecond: int = 0, digits: int = 0) -> Clock:
        self = super().__new__(cls, hour, minute, second, microsecond)
        self.digits = digits
        return self

    def __reduce__(self) -> Any:
        return (Clock, (self.hour, self.minute, self.second, self.microsecond, self.digits))


class Fixed(Decimal):
    """A decimal read from text; `width` is how many digits it was sent with before the point (000.5 has 3), so
    encoding it again writes the same leading zeros. Arithmetic gives plain Decimals."""

    width: int

    def __new__(cls, text: str) -> Fixed:
        self = super().__new__(cls, text)
        self.width = len(text.lstrip("+-").split(".")[0])
        return self

    def __reduce__(self) -> Any:
        return (Fixed, (_padded(format(self, "f"), self.width),))


def _padded(text: str, width: int) -> str:
    """`text` (a number) with zeros after its sign so that its integer part has at least `width` digits."""
    sign = text[:1] if text[:1] in "+-" else ""
    digits = text[len(sign) :]
    whole = len(digits.split(".")[0])
    return sign + "0" * (width - whole) + digits


@dataclass(frozen=True)
class Angle:
    """A coordinate written as degrees and minutes (NMEA ddmm.mmmm latitude, dddmm.mmmm longitude); the sign is a
    separate hemisphere field. `minutes` keeps the digits the device sent."""

    degrees: int
    minutes: Decimal

    @property
    def value(self) -> float:
        """Decimal degrees (unsigned)."""
        return self.degrees + float(self.minutes) / 60

    @classmethod
    def from_degrees(cls, value: float, digits: int) -> Angle:
        """The angle of `value` decimal degrees, its minutes rounded to `digits` fraction digits."""
        degrees = int(value)
        minutes = round(Decimal(repr(value - degrees)) * 60, digits)
        if minutes >= 60:
            degrees, minutes = degrees + 1, minutes - 60
        return cls(degrees, minutes)


@dataclass(frozen=True)
class TextField:
    """One text field: its kind and how it is written.

    precision: decimal, angle (of the minutes), time (of the seconds): fraction digits written for a value that
    does not carry its own (a float, an int, a `datetime.time`). width: integer, decimal: digits before the point,
    zero-padded, for a value that does not carry its own; angle: digits of the degrees (2 for a latitude, 3 for a
    longitude). letters: char: the enum whose values are the letters allowed.
    """

    name: str
    kind: TextKind
    precision: int = 0
    width: int = 0  # integer, decimal: integer digits, zero-padded; angle: digits of the degrees
    minimum: float | None = None
    maximum: float | None = None
    letters: type[Enum] | None = None
    label: str = ""  # in a message with its own layout (TextLayout.named): the label its value follows
    address: bool = False  # every message's first field, its digits right after the start, before the code (LSS's id)
    rest: bool = False  # text: the rest of the line, separators included (`size: rest`: Marlin's `Error:...`)
    base: int = 10  # integer: its digits' base (16: hex digits, read in either case: an ELM327's `1A F8`)
    lower: bool = False  # integer of base 16: its hex digits written in lower case


@dataclass(frozen=True)
class TextRepeat:
    """Fields repeated as a group: `count` groups always (GSA's twelve satellite ids, empty ones included), or up to
    `maximum` groups at the end of a sentence (GSV's satellites). Its value is a list of dicts, one per group."""

    name: str
    fields: tuple[TextField, ...]
    count: int = 0  # fixed number of groups (0: as many as the sentence has, up to maximum)
    maximum: int = 0
    label: str = ""  # in a message with its own layout: the label its values follow (joined by TextLayout.list)


@dataclass(frozen=True)
class TextLayout:
    """A message's own text inside the frame (GRBL's status report `<Idle|MPos:1.000,2.000,3.000|FS:0,0>`):
    `start` + code + `separator`-joined fields + `end`. With `named`, each field is its label, `named` and its
    value, found by the label in any order (an absent label: None), the field labelled with the code right after
    the code (`Hold:0`); a repeat's values are joined by `list`."""

    start: str = ""
    end: str = ""
    separator: str = ","
    named: str = ""
    list: str = ""
    after_code: str | None = None  # between the code and the first field (None: the separator; "": glued: `D1800`)
    glued: bool = False  # labels glued to their values (`named: ""`): G-code's `X10.5`, LSS's `D1800T1500`

    @property
    def labelled(self) -> bool:
        """Whether its fields are found by their labels (`named`, or labels glued to their values)."""
        return bool(self.named) or self.glued

    @property
    def follows_code(self) -> str:
        """What is written between the code and the first field: `after_code`, else the separator."""
        return self.separator if self.after_code is None else self.after_code


@dataclass(frozen=True)
class TextSentence:
    """One message: the text code that chooses it (NMEA's sentence id) and its fields in order."""

    code: str
    fields: tuple[TextField | TextRepeat, ...]
    name: str = ""
    #: "request" or "response": a code may name one message each way (a command and its answer)
    direction: str = "response"
    layout: TextLayout | None = None  # its own text inside the frame, where it has one
    bare: bool = False  # a reply of its values alone, no code: read as the answer to the request before it

    @property
    def where(self) -> str:
        return self.name or self.code


class DirectionNeeded(DecodeError):
    """A frame whose code names a request and a response, decoded without saying which."""

    def __init__(self, code: str) -> None:
        super().__init__(f"give the direction: {code!r} is both a request and a response")
        self.code = code


@dataclass(frozen=True)
class Sentence:
    """A decoded frame: the frame-level value (talker), the message's code, its values and how many fields the
    frame had (so encoding it again writes the same trailing empty fields)."""

    talker: str
    code: str
    values: dict[str, Any]
    sent: int = -1  # fields after the address (-1: every declared field)
    direction: str = "response"
    unchecked: bool = False  # sent without its (optional) checksum: encoding it again leaves the checksum out


@dataclass(frozen=True)
class TextFraming:
    """The frame: `start` + address (talker + code) + separator-joined fields + [marker + checksum as hex] + `end`.

    checksum: the function over the characters between start and marker (from the checksum registry), written as
    `digits` upper-case hex digits or, with `decimal`, in decimal digits without leading zeros (G-code's `*71`);
    `required` says whether a frame without one is refused. talker: how many leading characters of the address are the
    frame-level value (0: none). max_length: longest frame the stream parser waits for, in characters.
    """

    start: str
    separator: str
    end: str
    sentences: tuple[TextSentence, ...]
    checksum: Callable[[bytes], int] | None = None
    marker: str = "*"
    digits: int = 2
    required: bool = True
    talker: int = 0
    talkers: tuple[str, ...] = ()  # the talker values encode accepts (empty: any)
    max_length: int = 82
    decimal: bool = False  # the checksum written in decimal (G-code: `N1 G28*18`), not as `digits` hex digits
    checksummed: tuple[str, ...] = ("request", "response")  # the directions whose frames carry the checksum
    separated: tuple[str, ...] = ()  # the directions whose frames write the separator before the checksum's marker
    response_start: str = ""  # the responses' own start, where it differs from the requests' (`start`): LSS's `*`
    response_end: str = ""  # the responses' own line ending, where it differs from the requests' (`end`): ELM327's
    # code -> direction -> its sentence
    by_code: dict[str, dict[str, TextSentence]] = field(init=False, repr=False, compare=False)

    layouts: tuple[TextLayout, ...] = field(init=False, repr=False, compare=False)  # the messages' own, each once
    # the messages found by their code alone (their own text without a start), the longest code first
    alone: tuple[TextSentence, ...] = field(init=False, repr=False, compare=False)
    # every message's first field where it is an address written before the code (LSS's servo id), else None
    address: TextField | None = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        by_code: dict[str, dict[str, TextSentence]] = {}
        for sentence in self.sentences:
            by_code.setdefault(sentence.code, {})[sentence.direction] = sentence
        object.__setattr__(self, "by_code", by_code)
        layouts = {s.layout: None for s in self.sentences if s.layout is not None and s.layout.start}
        object.__setattr__(self, "layouts", tuple(layouts))
        alone = [s for s in self.sentences if s.layout is not None and not s.layout.start]
        object.__setattr__(self, "alone", tuple(sorted(alone, key=lambda s: -len(s.code))))
        firsts = [s.fields[0] for s in self.sentences if s.fields]
        object.__setattr__(self, "address", next((f for f in firsts if isinstance(f, TextField) and f.address), None))

    def sentence(self, code: str, direction: str | None = None, asked: bool = False) -> TextSentence:
        """The message a code names, in `direction` where the code names one each way; DecodeError where there is
        none, or where the code names two and no direction is given. `asked`: the request before the frame is known
        (the refusal then does not ask for it)."""
        found = self.by_code.get(code)
        if not found:
            hint = ""
            if direction != "request" and not asked and any(s.bare for s in self.sentences):
                hint = "; a reply of values alone is read with the request it answers: give the request"
            raise DecodeError(f"unknown text code {code!r} (expected one of {', '.join(self.by_code)}){hint}")
        if len(found) == 1:  # the code says the direction (an answer-only code read by a request parser too)
            return next(iter(found.values()))
        if direction is None:
            coded = [s for s in found.values() if not s.bare]
            if len(coded) == 1:  # beside a reply of values alone, which never starts with its code
                return coded[0]
            raise DirectionNeeded(code)
        return found[direction]

    # --- decoding --------------------------------------------------------------------------------------------------

    def decode(self, frame: bytes | str, direction: str | None = None, reply: str | None = None) -> Sentence:
        """One frame (with or without its line ending) -> its sentence; DecodeError says in one line why not.
        `direction` is needed only for a code that names a request and a response. `reply`: the code of the reply
        awaited (the answer to the request before this frame; given, the request is known): where that reply is its
        values alone (`bare`), a frame that does not start with another message's code is read as it."""
        text = _ascii(frame, self.end, self.response_end)
        if self.response_end:  # each direction its own line ending: the longest that ends the frame is taken off
            ending = self._ending(text, direction)
            text = text[: len(text) - len(ending)]
        elif text.endswith(self.end):
            text = text[: -len(self.end)]
        if self.response_start:  # each direction its own start: the start says the direction
            said = "response" if text.startswith(self.response_start) else "request"
            start = self.start_of(said)
            if not text.startswith(start) or direction not in (None, said):
                wanted = f"{self.start!r} (a request) or {self.response_start!r} (a response)"
                if direction is not None:
                    wanted = repr(self.start_of(direction))
                raise DecodeError(f"text frame does not start with {wanted}: {shown(text[:20])}")
            direction = said
        elif not text.startswith(self.start):
            raise DecodeError(f"text frame does not start with {self.start!r}: {shown(text[:20])}")
        body = text[len(self.start) :]
        if self.checksum is None or len(self.checksummed) == 2:
            return self._decode_checked(body, direction, reply)
        # a checksum in one direction only: a frame of the other is all text (its fields may hold the marker)
        if direction is not None and direction not in self.checksummed:
            return self._decode_body(body, direction, reply)
        if direction is None:  # a frame that reads as the other direction's whole is one
            try:
                whole = self._decode_body(body, None, reply)
            except DecodeError:
                whole = None
            if whole is not None and whole.direction not in self.checksummed:
                return whole
        return self._decode_checked(body, direction, reply)

    def _decode_checked(self, body: str, direction: str | None, reply: str | None) -> Sentence:
        """A frame of a direction that carries the checksum; one sent without it (where it may be left out) says so,
        so that it encodes again without it."""
        covered = self._checked(body, direction)
        sentence = self._decode_body(covered, direction, reply)
        if self.checksum is not None and sentence.direction not in self.checksummed:
            # a code of the other direction alone (asked for as this one): it carries no checksum, all its text
            return self._decode_body(body, sentence.direction, reply)
        if self.checksum is not None and covered == body:
            return replace(sentence, unchecked=True)
        return sentence

    def _decode_body(self, body: str, direction: str | None, reply: str | None) -> Sentence:
        """The text between start and checksum (the checksum checked) -> its sentence; the address first, where
        every message has one (its digits, right after the start)."""
        if self.address is None:
            return self._decode_rest(body, direction, reply)
        digits = 0
        while digits < len(body) and body[digits] in _DIGITS:
            digits += 1
        value = decode_field("address", self.address, body[:digits])
        sentence = self._decode_rest(body[digits:], direction, reply)
        return replace(sentence, values={self.address.name: value, **sentence.values})

    def _decode_rest(self, body: str, direction: str | None, reply: str | None) -> Sentence:
        """The text after the address (all of it where the messages have none) -> its sentence."""
        for layout in self.layouts:
            if body.startswith(layout.start) and body[len(layout.start) :].endswith(layout.end):
                return self._decode_in(layout, body[len(layout.start) : len(body) - len(layout.end)], direction)
        parts = body.split(self.separator)
        address = parts[0]
        talker, code = address[: self.talker], address[self.talker :]
        if self.alone and not self._plain(code, direction):
            found = self._decode_alone(talker, body[self.talker :], direction)
            if found is not None:
                return found
        if reply is not None and direction != "request":
            bare = self.by_code.get(reply, {}).get("response")
            if bare is not None and bare.bare and not self._coded(code, direction):
                return Sentence("", reply, _decode_fields(bare, parts, self.separator), _count(bare, parts), "response")
        sentence = self.sentence(code, direction, reply is not None)
        values = _decode_fields(sentence, parts[1:], self.separator)
        return Sentence(talker, code, values, _count(sentence, parts[1:]), sentence.direction)

    def _plain(self, code: str, direction: str | None) -> bool:
        """Whether `code` is that of a message sent in the framing's own text (no layout of its own), in
        `direction` (None: either)."""
        found = self.by_code.get(code, {}).values()
        return any(s.layout is None and not s.bare and direction in (None, s.direction) for s in found)

    def _decode_alone(self, talker: str, text: str, direction: str | None) -> Sentence | None:
        """A frame of a message found by its code alone (its own text without a start): the longest such code the
        text starts with, then the layout's `after_code` and fields; None when no such code fits."""
        matched: list[tuple[TextSentence, str | None]] = []
        for sentence in self.alone:
            layout = sentence.layout
            if layout is None or direction not in (None, sentence.direction) or not text.startswith(sentence.code):
                continue
            if matched and len(sentence.code) < len(matched[0][0].code):
                break
            rest = text[len(sentence.code) :]
            after = layout.follows_code
            if layout.glued and any(item.label == sentence.code for item in _sent(sentence)):
                after = ""  # the value labelled with the code follows it (LSS's `D1800`)
            if not rest:
                matched.append((sentence, None))
            elif rest.startswith(after) and rest.endswith(layout.end):
                matched.append((sentence, rest[len(after) : len(rest) - len(layout.end)]))
        if not matched:
            return None
        if len(matched) > 1:
            raise DirectionNeeded(matched[0][0].code)
        sentence, inner = matched[0]
        layout = sentence.layout
        assert layout is not None  # every message in `alone` has its own text
        if layout.glued:  # the code is the label of the value right after it, where a field has it as its label
            own = any(item.label == sentence.code for item in _sent(sentence))
            values = _labelled_values(
                sentence, layout, _glued(sentence, layout, (sentence.code if own else "") + (inner or ""))
            )
            return Sentence(talker, sentence.code, values, -1, sentence.direction)
        texts = inner.split(layout.separator) if inner else []  # the code alone: no fields
        if layout.named:
            values = _decode_labelled(sentence, layout, texts)
        else:
            values = _decode_fields(sentence, [t for p in texts for t in _split(p, layout.list)], layout.separator)
        return Sentence(talker, sentence.code, values, -1, sentence.direction)

    def _coded(self, code: str, direction: str | None) -> bool:
        """Whether a frame's first field is the code of a message sent with its code, in `direction` (None: either;
        a stream of both directions may hold a request that got no reply where its reply was awaited)."""
        found = self.by_code.get(code, {}).values()
        return any(not s.bare and direction in (None, s.direction) for s in found)

    def _decode_in(self, layout: TextLayout, inner: str, direction: str | None) -> Sentence:
        """A frame in a message's own layout (its start and end taken off)."""
        parts = inner.split(layout.separator)
        talker, address = parts[0][: self.talker], parts[0][self.talker :]
        # with labels, the code may carry a value as a label does (GRBL's `Hold:0`): the field labelled with the code
        code, after = (address.partition(layout.named)[0], address) if layout.named else (address, "")
        sentence = self.sentence(code, direction)
        if sentence.layout != layout:
            raise DecodeError(f"{sentence.where} is not sent as {layout.start}…{layout.end}")
        if layout.named:
            values = _decode_labelled(sentence, layout, [after, *parts[1:]] if after != code else parts[1:])
        else:
            values = _decode_fields(sentence, [t for p in parts[1:] for t in _split(p, layout.list)], layout.separator)
        return Sentence(talker, code, values, -1, sentence.direction)

    def _checked(self, body: str, direction: str | None) -> str:
        """The text before the checksum, the checksum checked (and the separator before its marker taken off, in a
        direction that writes one there)."""
        covered = self._covered(body)
        if covered != body and self.separated and direction in (None, *self.separated):
            return covered.removesuffix(self.separator)
        return covered

    def _covered(self, body: str) -> str:
        if self.checksum is None:
            return body
        at = body.rfind(self.marker)
        if at < 0:
            if self.required:
                raise ChecksumError(f"text frame has no checksum (no {self.marker!r})")
            return body
        written, covered = body[at + len(self.marker) :], body[:at]
        computed = self.checksum(covered.encode("ascii"))
        if self.decimal:
            if not 1 <= len(written) <= 3 or any(c not in _DIGITS for c in written):
                hint = self._line_end(written)
                raise ChecksumError(f"checksum {shown(written)} is not a decimal number of 1 to 3 digits{hint}")
            if int(written) != computed:
                raise ChecksumError(f"bad checksum: the frame has {written}, its text gives {computed}")
            return covered
        if len(written) != self.digits or not written or any(c not in _HEX_DIGITS for c in written):
            raise ChecksumError(f"checksum {shown(written)} is not {self.digits} hex digits{self._line_end(written)}")
        if int(written, 16) != computed:
            raise ChecksumError(f"bad checksum: the frame has {written}, its text gives {computed:0{self.digits}X}")
        return covered

    def _line_end(self, text: str) -> str:
        """Where `text` (after the checksum's marker) ends with CR or LF that is not the protocol's line ending (a
        device's CR LF where the spec says CR, a terminal's LF): a hint naming the spec's; "" otherwise."""
        if not text.endswith(("\r", "\n")):
            return ""
        ends = " or ".join(repr(e) for e in dict.fromkeys((self.end, self.response_end)) if e)
        return f" (a line ending? this protocol's lines end with {ends}, `framing.end`)"

    # --- encoding --------------------------------------------------------------------------------------------------

    def encode(
        self,
        code: str,
        values: Mapping[str, Any],
        talker: str = "",
        sent: int = -1,
        direction: str | None = None,
        unchecked: bool = False,
    ) -> bytes:
        """A sentence's values -> the frame; EncodeError (RangeError) names the field at fault before any text is
        written. `sent` is the number of fields to write (a decoded Sentence's); -1 writes every declared one."""
        try:
            sentence = self.sentence(code, direction)
        except DecodeError as exc:
            raise EncodeError(str(exc)) from None
        if talker and not self.talker:
            raise EncodeError(f"{sentence.where}: talker {talker!r} given, but these frames carry no talker")
        if len(talker) != self.talker or (self.talkers and talker not in self.talkers):
            allowed = ", ".join(self.talkers) if self.talkers else f"{self.talker} characters"
            raise EncodeError(f"{sentence.where}: talker {talker!r} is not one of {allowed}")
        unknown = set(values) - {f.name for f in sentence.fields}
        if unknown:
            raise EncodeError(f"{sentence.where}: unknown field {sorted(unknown)[0]!r}")
        address = ""
        if self.address is not None:  # its digits before everything else
            address = encode_field(sentence.where, self.address, values.get(self.address.name))
        if sentence.layout is not None:
            forbidden = self._forbidden(sentence.direction)
            inner = _encode_in(sentence, sentence.layout, values, talker + code, forbidden, self.separator)
            return self.frame(address + inner, sentence.direction, unchecked)
        parts = _encode_fields(sentence, values, self._forbidden(sentence.direction), self.separator)
        if sent >= 0:
            if any(parts[sent:]):
                raise EncodeError(f"{sentence.where}: {sent} fields asked for, but field {sent + 1} has a value")
            parts = (parts + [""] * sent)[:sent]
        body = self.separator.join(parts if sentence.bare else [talker + code, *parts])
        return self.frame(address + body, sentence.direction, unchecked)

    def _ending(self, text: str, direction: str | None) -> str:
        """The line ending `text` ends with (of `direction`, or the longest of either; "" for none)."""
        ends = [self.end_of(direction)] if direction is not None else [self.end, self.response_end]
        return max((e for e in ends if text.endswith(e)), key=len, default="")

    def end_of(self, direction: str | None) -> str:
        """The line ending of a frame in `direction` (the requests' where the responses have none of their own)."""
        return self.response_end if direction == "response" and self.response_end else self.end

    def start_of(self, direction: str | None) -> str:
        """The start of a frame in `direction` (the requests' where the responses have none of their own)."""
        return self.response_start if direction == "response" and self.response_start else self.start

    def frame(self, body: str, direction: str | None = None, unchecked: bool = False) -> bytes:
        """The text between start and checksum marker, framed (with its checksum where `direction` has one, unless
        `unchecked`: left out, where the framing lets it be)."""
        text = self.start_of(direction) + body
        written = not (unchecked and not self.required)
        if self.checksum is not None and written and (direction is None or direction in self.checksummed):
            if direction in self.separated:  # ODrive's `r vbus_voltage *93`: covered with the rest
                text, body = text + self.separator, body + self.separator
            value = self.checksum(body.encode("ascii"))
            text += f"{self.marker}{value}" if self.decimal else f"{self.marker}{value:0{self.digits}X}"
        # the line ending may hold bytes above 0x7F (Nextion's FF FF FF)
        return (text + self.end_of(direction)).encode("latin-1")

    def encode_sentence(self, sentence: Sentence) -> bytes:
        return self.encode(
            sentence.code, sentence.values, sentence.talker, sentence.sent, sentence.direction, sentence.unchecked
        )

    def _forbidden(self, direction: str) -> str:
        """The framing's own characters, which no field of a frame in `direction` may hold (the checksum's marker
        only where that direction carries a checksum)."""
        marker = self.marker if self.checksum is not None and direction in self.checksummed else ""
        ends = {*self.end, *self.response_end}
        return "".join({self.start, self.response_start, self.separator, marker, *ends} - {""})


# --- fields -------------------------------------------------------------------------------------------------------

# The fields' forms are checked with str methods, not regular expressions: compiling one costs more than decoding
# a sentence, and `serialspec decode PACKAGE SENTENCE` would compile each on every start. A digit is what \d matches
# (str.isdecimal: any Unicode decimal digit, as int() and Decimal() read them).
_HEX_DIGITS = frozenset("0123456789ABCDEFabcdef")
_DIGITS = frozenset("0123456789")
_NUMBER = frozenset("0123456789+-.")  # what a number glued between labels may hold


def _unsigned(text: str) -> str:
    """The text after one leading sign."""
    return text[1:] if text[:1] in ("+", "-") else text


def _split(text: str, by: str) -> list[str]:
    return text.split(by) if by else [text]


def _glued(sentence: TextSentence, layout: TextLayout, text: str) -> list[tuple[str, str, bool]]:
    """(label, value, found) of each labelled value glued to its label (`named: ""`): the longest label a piece
    starts with; without a separator, a value is the run of number characters after its label (`D1800T1500`)."""
    labels = sorted((item.label for item in _sent(sentence)), key=len, reverse=True)
    found: list[tuple[str, str, bool]] = []
    if layout.separator:
        for piece in text.split(layout.separator) if text else ():
            label = next((lb for lb in labels if piece.startswith(lb)), None)
            found.append((label, piece[len(label) :], True) if label is not None else (piece, "", False))
        return found
    at = 0
    while at < len(text):
        label = next((lb for lb in labels if text.startswith(lb, at)), None)
        if label is None:
            return [*found, (text[at:], "", False)]
        end = at + len(label)
        while end < len(text) and text[end] in _NUMBER:
            end += 1
        found.append((label, text[at + len(label) : end], True))
        at = end
    return found


def _decode_labelled(sentence: TextSentence, layout: TextLayout, parts: list[str]) -> dict[str, Any]:
    """Fields found by their labels (`label` + `named` + value), in any order; an absent one is None (a repeat: [])."""
    pairs = (
        _glued(sentence, layout, layout.separator.join(parts))
        if layout.glued
        else [(lb, text, bool(found)) for lb, found, text in (p.partition(layout.named) for p in parts)]
    )
    return _labelled_values(sentence, layout, pairs)


def _labelled_values(sentence: TextSentence, layout: TextLayout, pairs: list[tuple[str, str, bool]]) -> dict[str, Any]:
    items = {item.label: item for item in _sent(sentence)}
    values: dict[str, Any] = {item.name: [] if isinstance(item, TextRepeat) else None for item in _sent(sentence)}
    seen: set[str] = set()
    for label, text, found in pairs:
        item = items.get(label)
        if not found or item is None:
            expected = ", ".join(items) or "none"
            raise DecodeError(f"{sentence.where}: unknown label {shown(label)} (expected one of {expected})")
        if label in seen:
            raise DecodeError(f"{sentence.where}: label {label!r} sent twice")
        seen.add(label)
        if isinstance(item, TextField):
            values[item.name] = decode_field(sentence.where, item, text)
            continue
        texts = _split(text, layout.list)
        size = len(item.fields)
        if len(texts) % size or (item.count and len(texts) != item.count * size):
            expected = f"{item.count * size}" if item.count else f"a multiple of {size}"
            raise DecodeError(f"{sentence.where}: {item.name} has {len(texts)} values, expected {expected}")
        if item.maximum and len(texts) > item.maximum * size:
            raise DecodeError(f"{sentence.where}: {item.name} has {len(texts)} values, at most {item.maximum * size}")
        values[item.name] = [
            {f.name: decode_field(sentence.where, f, texts[at + i]) for i, f in enumerate(item.fields)}
            for at in range(0, len(texts), size)
        ]
    return values


def _encode_in(
    sentence: TextSentence, layout: TextLayout, values: Mapping[str, Any], address: str, forbidden: str, outer: str = ""
) -> str:
    """The text of a message in its own layout: start, address, fields (labelled ones only where they have a value),
    end."""
    forbidden += "".join(
        {layout.start, layout.end, layout.separator, layout.named, layout.list, layout.after_code or ""} - {""}
    )
    parts = [address]
    for item in _sent(sentence):
        value = values.get(item.name)
        if isinstance(item, TextField):
            allowed = forbidden
            if item.rest:  # the rest of the line: the message's own characters too (not the framing's)
                for own in (layout.separator, layout.after_code or "", outer):
                    allowed = allowed.replace(own, "") if own else allowed
            text = encode_field(sentence.where, item, value, allowed)
            if layout.labelled and item.label == sentence.code:  # the code's own value, right after it (`Hold:0`)
                parts[0] += f"{layout.named}{text}" if value is not None else ""
            elif value is not None or not layout.labelled:
                parts.append(f"{item.label}{layout.named}{text}" if layout.labelled else text)
            continue
        if not value and layout.labelled:
            continue  # an absent label
        single = TextSentence(sentence.code, (item,), sentence.where)
        texts = _encode_fields(single, {item.name: value}, forbidden)
        if not texts:
            continue  # a repeat of no groups (at the end, `max_count`): nothing, not an empty field
        joined = (layout.list or layout.separator).join(texts)
        parts.append(f"{item.label}{layout.named}{joined}" if layout.labelled else joined)
    after = layout.follows_code
    joined = layout.separator.join(parts[1:])
    # found by its code alone: a frame whose fields have no text is the code alone
    fields = after + joined if len(parts) > 1 and (joined or layout.start) else ""
    return layout.start + parts[0] + fields + layout.end


def _sent(sentence: TextSentence) -> tuple[TextField | TextRepeat, ...]:
    """The fields written after the code: all but an address (written before it)."""
    first = sentence.fields[0] if sentence.fields else None
    return sentence.fields[1:] if isinstance(first, TextField) and first.address else sentence.fields


def _count(sentence: TextSentence, parts: list[str]) -> int:
    """How many fields a frame of these parts had (a text to the end of the line, separators and all, is one)."""
    fields = _sent(sentence)
    if fields and isinstance(fields[-1], TextField) and fields[-1].rest:
        return min(len(parts), len(fields))
    return len(parts)


def _decode_fields(sentence: TextSentence, parts: list[str], separator: str = "") -> dict[str, Any]:
    values: dict[str, Any] = {}
    at = 0
    for item in _sent(sentence):
        if isinstance(item, TextField):
            text = separator.join(parts[at:]) if item.rest else parts[at] if at < len(parts) else ""
            values[item.name] = decode_field(sentence.where, item, text)
            at = max(at + 1, len(parts)) if item.rest else at + 1
            continue
        size = len(item.fields)
        groups = item.count or min(item.maximum, -(-(len(parts) - at) // size))
        rows = []
        for _ in range(max(groups, 0)):
            row = {
                f.name: decode_field(sentence.where, f, parts[at + i] if at + i < len(parts) else "")
                for i, f in enumerate(item.fields)
            }
            rows.append(row)
            at += size
        values[item.name] = rows
    if at < len(parts):
        raise DecodeError(f"{sentence.where}: {len(parts)} fields, expected at most {at}")
    return values


def decode_field(where: str, spec: TextField, text: str) -> Any:
    """One field's text -> its value (None when empty); DecodeError names the field and what it should look like."""
    if text == "":
        return None
    try:
        return _decoders[spec.kind](spec, text)
    except (ValueError, InvalidOperation):
        raise DecodeError(f"{where}: {spec.name} = {shown(text)} is not {_looks(spec)}") from None


def _decimal(spec: TextField, text: str) -> Fixed:
    whole, dot, fraction = _unsigned(text).partition(".")  # [+-]?(\d+\.?\d*|\.\d+)
    if not (whole.isdecimal() or not whole and dot and fraction) or fraction and not fraction.isdecimal():
        raise ValueError(text)
    return Fixed(text)


def _integer(spec: TextField, text: str) -> int:
    digits = _unsigned(text)
    if spec.base == 16:  # [+-]?[0-9A-Fa-f]+
        if not digits or not set(digits) <= _HEX_DIGITS:
            raise ValueError(text)
        return int(text, 16)
    if not digits.isdecimal():  # [+-]?\d+
        raise ValueError(text)
    return int(text)


def _angle(spec: TextField, text: str) -> Angle:
    width = spec.width or 2
    head, dot, fraction = text.partition(".")  # (\d{1,width})(\d\d(?:\.\d*)?): degrees, then minutes
    if not (3 <= len(head) <= width + 2 and head.isdecimal()) or fraction and not fraction.isdecimal():
        raise ValueError(text)
    minutes = Decimal(head[-2:] + dot + fraction)
    if minutes >= 60:
        raise ValueError(text)
    return Angle(int(head[:-2]), minutes)


def _char(spec: TextField, text: str) -> Any:
    if len(text) != 1:
        raise ValueError(text)
    return spec.letters(text) if spec.letters is not None else text


def _text(spec: TextField, text: str) -> str:
    return text


def _time(spec: TextField, text: str) -> Clock:
    head, _, fraction = text.partition(".")  # (\d\d)(\d\d)(\d\d)(?:\.(\d*))?
    if not (len(head) == 6 and head.isdecimal()) or fraction and not fraction.isdecimal():
        raise ValueError(text)
    micro = int((fraction + "000000")[:6]) if fraction else 0
    return Clock(int(head[:2]), int(head[2:4]), int(head[4:]), micro, len(fraction))


def _date(spec: TextField, text: str) -> datetime.date:
    if not (len(text) == 6 and text.isdecimal()):  # (\d\d)(\d\d)(\d\d)
        raise ValueError(text)
    return datetime.datetime.strptime(text, "%d%m%y").date()


_decoders: dict[str, Callable[[TextField, str], Any]] = {
    "decimal": _decimal,
    "integer": _integer,
    "angle": _angle,
    "char": _char,
    "text": _text,
    "time": _time,
    "date": _date,
}


def _looks(spec: TextField) -> str:
    match spec.kind:
        case "angle":
            return f"{'d' * (spec.width or 2)}mm.mmmm (degrees and minutes)"
        case "char" if spec.letters is not None:
            return "one of " + ", ".join(str(m.value) for m in spec.letters)
        case "char":
            return "one character"
        case "integer" if spec.base == 16:
            return "an integer in hex digits"
        case "time":
            return "hhmmss[.ss]"
        case "date":
            return "ddmmyy"
        case _:
            return f"a{'n' if spec.kind[0] in 'aeiou' else ''} {spec.kind}"


def _encode_fields(sentence: TextSentence, values: Mapping[str, Any], forbidden: str, separator: str = "") -> list[str]:
    parts: list[str] = []
    for item in _sent(sentence):
        value = values.get(item.name)
        if isinstance(item, TextField):
            # a text to the end of the line may hold the separator (and nothing else of the framing's)
            parts.append(
                encode_field(sentence.where, item, value, forbidden.replace(separator, "") if item.rest else forbidden)
            )
            continue
        rows = list(value or ())
        limit = item.count or item.maximum
        if len(rows) > limit:
            raise RangeError(f"{sentence.where}: {item.name} has {len(rows)} groups, at most {limit}")
        rows += [{}] * (item.count - len(rows))
        for index, row in enumerate(rows):
            if not isinstance(row, Mapping):
                raise EncodeError(f"{sentence.where}: {item.name}[{index}] must be a mapping, got {shown(row)}")
            for f in item.fields:
                where = f"{sentence.where}: {item.name}[{index}]"
                parts.append(encode_field(where, f, row.get(f.name), forbidden))
    return parts


def encode_field(where: str, spec: TextField, value: Any, forbidden: str = "") -> str:
    """One value -> its text ("" for None), refused with the field's name when it cannot be written."""
    if value is None:
        return ""
    where_name = f"{where}.{spec.name}" if ":" in where else f"{where}: {spec.name}"
    text = _encoders[spec.kind](spec, value, where_name)
    if bad := next((c for c in text if c in forbidden or not " " <= c <= "~"), None):
        raise EncodeError(f"{where_name}: {shown(value)} holds {bad!r}, which a text frame cannot carry")
    return text


def _number(spec: TextField, value: Any, where: str) -> Decimal:
    if isinstance(value, bool) or not isinstance(value, int | float | Decimal):
        raise EncodeError(f"{where} must be a number, got {shown(value)}")
    number = value if isinstance(value, Decimal) else Decimal(repr(value))
    if not number.is_finite():
        raise EncodeError(f"{where} must be a finite number, got {shown(value)}")
    low = -float("inf") if spec.minimum is None else spec.minimum
    high = float("inf") if spec.maximum is None else spec.maximum
    if not low <= number <= high:
        raise RangeError(f"{where} = {shown(value)} is outside its range {_bound(low)}..{_bound(high)}")
    return number


def _bound(value: float) -> str:
    return str(int(value)) if float(value).is_integer() else str(value)


def _put_decimal(spec: TextField, value: Any, where: str) -> str:
    number = _number(spec, value, where)
    if isinstance(value, Fixed):
        return _padded(format(number, "f"), value.width)
    if isinstance(value, Decimal) or not spec.precision:  # a float with no precision: its shortest form, unrounded
        return _padded(format(number, "f"), spec.width)
    return _padded(f"{number:.{spec.precision}f}", spec.width)


def _put_integer(spec: TextField, value: Any, where: str) -> str:
    if isinstance(value, bool) or not isinstance(value, int):
        raise EncodeError(f"{where} must be an integer, got {shown(value)}")
    _number(spec, value, where)
    sign = "-" if value < 0 else ""
    form = "d" if spec.base != 16 else "x" if spec.lower else "X"
    return f"{sign}{abs(value):0{spec.width}{form}}"


def _put_angle(spec: TextField, value: Any, where: str) -> str:
    if not isinstance(value, Angle):
        value = Angle.from_degrees(float(_number(spec, value, where)), spec.precision)
    else:
        _number(spec, value.value, where)
    if not 0 <= value.minutes < 60 or value.degrees < 0:
        raise RangeError(f"{where}: minutes {value.minutes} are outside 0..60")
    minutes = format(value.minutes, "f")
    whole = minutes.split(".")[0]
    return f"{value.degrees:0{spec.width or 2}d}{'0' * (2 - len(whole))}{minutes}"


def _put_char(spec: TextField, value: Any, where: str) -> str:
    if spec.letters is not None:
        if isinstance(value, spec.letters):
            return str(value.value)
        allowed = {str(m.value) for m in spec.letters}
        if isinstance(value, str) and value in allowed:
            return value
        # letters quoted as the value is shown: a number 3 is not the letter '3'
        raise EncodeError(f"{where} must be one of {', '.join(map(repr, sorted(allowed)))}, got {shown(value)}")
    if not isinstance(value, str) or len(value) != 1:
        raise EncodeError(f"{where} must be one character, got {shown(value)}")
    return value


def _put_text(spec: TextField, value: Any, where: str) -> str:
    if not isinstance(value, str):
        raise EncodeError(f"{where} must be text, got {shown(value)}")
    return value


def _put_time(spec: TextField, value: Any, where: str) -> str:
    if isinstance(value, int | float) and not isinstance(value, bool) and 0 <= value < 86400:
        # seconds since midnight (what a simulated device's expressions give)
        seconds = int(value)
        micro = round((value - seconds) * 1_000_000)
        value = datetime.time(seconds // 3600, seconds // 60 % 60, seconds % 60, min(micro, 999_999))
    if not isinstance(value, datetime.time):
        raise EncodeError(f"{where} must be a datetime.time (or seconds since midnight), got {shown(value)}")
    digits = value.digits if isinstance(value, Clock) else spec.precision
    text = f"{value.hour:02d}{value.minute:02d}{value.second:02d}"
    if digits:
        text += "." + f"{value.microsecond:06d}"[:digits].ljust(digits, "0")
    return text


def _put_date(spec: TextField, value: Any, where: str) -> str:
    if not isinstance(value, datetime.date):
        raise EncodeError(f"{where} must be a datetime.date, got {shown(value)}")
    return f"{value.day:02d}{value.month:02d}{value.year % 100:02d}"


_encoders: dict[str, Callable[[TextField, Any, str], str]] = {
    "decimal": _put_decimal,
    "integer": _put_integer,
    "angle": _put_angle,
    "char": _put_char,
    "text": _put_text,
    "time": _put_time,
    "date": _put_date,
}


def texts(sentence: TextSentence, values: Mapping[str, Any]) -> dict[str, Any]:
    """Each field's text as encode writes it ("" for None; a repeat as a list of dicts of texts)."""
    found: dict[str, Any] = {}
    for item in sentence.fields:
        value = values.get(item.name)
        if isinstance(item, TextField):
            found[item.name] = encode_field(sentence.where, item, value)
        else:
            rows = [row if isinstance(row, Mapping) else asdict(row) for row in value or ()]
            found[item.name] = [
                {f.name: encode_field(sentence.where, f, row.get(f.name)) for f in item.fields} for row in rows
            ]
    return found


def from_texts(sentence: TextSentence, texts: Mapping[str, Any]) -> dict[str, Any]:
    """Each field's value from its text (what `texts` gives; a missing field is empty): DecodeError names the field."""
    unknown = set(texts) - {f.name for f in sentence.fields}
    if unknown:
        raise DecodeError(f"{sentence.where}: unknown field {sorted(unknown)[0]!r}")
    values: dict[str, Any] = {}
    for item in sentence.fields:
        given = texts.get(item.name)
        if isinstance(item, TextField):
            values[item.name] = decode_field(sentence.where, item, _field_text(sentence, item.name, given))
            continue
        if not isinstance(given, list | tuple | type(None)):
            raise DecodeError(f"{sentence.where}: {item.name} must be a list of objects, got {shown(given)}")
        rows = []
        for index, row in enumerate(given or ()):
            if not isinstance(row, Mapping):
                raise DecodeError(f"{sentence.where}: {item.name}[{index}] must be an object, got {shown(row)}")
            where = f"{sentence.where}: {item.name}[{index}]"
            rows.append(
                {f.name: decode_field(where, f, _field_text(sentence, f.name, row.get(f.name))) for f in item.fields}
            )
        values[item.name] = rows
    return values


def _field_text(sentence: TextSentence, name: str, given: Any) -> str:
    if given is None:
        return ""
    if isinstance(given, bool) or not isinstance(given, str | int | float):
        raise DecodeError(f"{sentence.where}: {name} must be the field's text, got {shown(given)}")
    return given if isinstance(given, str) else str(given)


def _ascii(frame: bytes | str, end: str = "", other: str = "") -> str:
    """A frame's characters: ASCII, but for a line ending `end` that may hold bytes above 0x7F (Nextion's FF FF FF),
    each such byte a character of the same number."""
    if isinstance(frame, str):
        return frame
    text = bytes(frame).decode("latin-1")
    ending = max((e for e in (end, other) if e and text.endswith(e)), key=len, default="")
    body = text[: len(text) - len(ending)]
    if bad := next((c for c in body if c > "\x7f"), None):
        raise DecodeError(f"text frame holds a non-ASCII byte {ord(bad):02X}")
    return text


# --- the stream parser --------------------------------------------------------------------------------------------


class TextStreamParser:
    """Frames out of a byte stream read in any pieces: noise between frames is skipped, a frame cut short by a new
    start character or grown past `max_length` is dropped, and a frame that does not decode is counted in
    `corrupt` (its reason kept in `last_error`)."""

    def __init__(self, framing: TextFraming, direction: str | None = None) -> None:
        self.framing = framing
        self.direction = direction  # for codes that name a request and a response: which this stream carries
        self._asked: str | None = None  # the code of the request just read (both directions in one stream)
        self._awaited: str | None = None  # the code of the reply awaited (expect), where it is values alone
        self._overlong = False  # frames without a start character: the line being read was dropped as too long
        self._start = framing.start.encode("ascii")
        # every start a frame may have (one character each where the directions have their own)
        self._starts = tuple(s.encode("ascii") for s in dict.fromkeys((framing.start, framing.response_start)) if s)
        # the line endings a frame of this stream may end with (each direction its own: the direction's, or both)
        ends = (framing.end, framing.response_end) if direction is None else (framing.end_of(direction),)
        self._ends = tuple(e.encode("latin-1") for e in dict.fromkeys(ends) if e)
        self._end = max(self._ends, key=len)  # the longest (how far past max_length a frame may reach)
        self._buffer = b""
        self.corrupt = 0
        self.last_error = ""

    def feed(self, data: bytes | bytearray | memoryview) -> list[Sentence]:
        self._buffer += bytes(data)
        found: list[Sentence] = []
        limit = self.framing.max_length + len(self._end)
        if not self._start:
            return self._lines(found, limit)
        while True:
            start = self._find_start(0)
            if start < 0:
                self._buffer = self._buffer[-(len(self._start) - 1) :] if len(self._start) > 1 else b""
                return found
            self._buffer = self._buffer[start:]
            end, size = self._find_end(len(self._start))
            restart = self._find_start(len(self._start))
            if end < 0 or (0 <= restart < end):
                if restart >= 0 and (end < 0 or restart < end):
                    self._dropped("text frame cut short by a new start")
                    self._buffer = self._buffer[restart:]
                    continue
                if len(self._buffer) > limit:
                    self._dropped(f"no line ending within {self.framing.max_length} characters")
                    self._buffer = self._buffer[len(self._start) :]
                    continue
                return found
            if end + size - 1 > limit:  # it grew past max_length before its ending came: read in pieces,
                self._dropped(f"no line ending within {self.framing.max_length} characters")  # it is dropped too
                self._buffer = self._buffer[len(self._start) :]
                continue
            frame, self._buffer = self._buffer[: end + size], self._buffer[end + size :]
            try:
                found.append(self._decoded(frame))
            except DecodeError as error:
                self._dropped(str(error))

    def _find_end(self, at: int) -> tuple[int, int]:
        """Where the first line ending at or after `at` is in the buffer and its size, or (-1, 0). With two (each
        direction its own), the longest of those found first; none yet where the buffer stops inside a longer one
        there (`\\r` then, maybe, `\\r>`)."""
        if len(self._ends) == 1:
            return self._buffer.find(self._end, at), len(self._end)
        found = [(i, len(e)) for e in self._ends if (i := self._buffer.find(e, at)) >= 0]
        if not found:
            return -1, 0
        end, size = min(found, key=lambda f: (f[0], -f[1]))
        tail = self._buffer[end:]
        if any(len(e) > max(size, len(tail)) and e.startswith(tail) for e in self._ends):
            return -1, 0
        return end, size

    def _find_start(self, at: int) -> int:
        """Where the first start at or after `at` is in the buffer, or -1."""
        if len(self._starts) == 1:
            return self._buffer.find(self._start, at)
        found = [i for i in (self._buffer.find(s, at) for s in self._starts) if i >= 0]
        return min(found, default=-1)

    def _lines(self, found: list[Sentence], limit: int) -> list[Sentence]:
        """Frames without a start character: each line is a frame. A line that grows past `max_length` is dropped
        to its end; an empty line (a device's CR LF where the spec says CR) is skipped."""
        while True:
            end, size = self._find_end(0)
            if end < 0:
                if len(self._buffer) > limit:
                    self._dropped(f"no line ending within {self.framing.max_length} characters")
                    keep = len(self._end) - 1  # the start of a line ending split between reads
                    self._buffer, self._overlong = self._buffer[len(self._buffer) - keep :], True
                return found
            frame, self._buffer = self._buffer[: end + size], self._buffer[end + size :]
            if self._overlong:  # the rest of a line already dropped
                self._overlong = False
                continue
            if end + size - 1 > limit:  # it grew past max_length before its ending came (whatever the reads)
                self._dropped(f"no line ending within {self.framing.max_length} characters")
                continue
            if not frame[:end].strip():
                continue
            try:
                # CR or LF before a line: the rest of a line ending longer than the spec's (CR LF where it says CR)
                found.append(self._decoded(frame.lstrip(b"\r\n")))
            except DecodeError as error:
                self._dropped(str(error))

    def expect(self, reply: str | None) -> None:
        """The code of the reply the next frames answer (a client's request awaiting it; None: none): where that
        reply is its values alone, a line that starts with no other message's code is read as it, once."""
        self._awaited = reply

    def _decoded(self, frame: bytes) -> Sentence:
        """A frame's sentence. Both directions in one stream (a monitor's): a code that names a request and a
        response is the response right after that request, the request otherwise; so is a reply of values alone."""
        reply = self._awaited or self._asked
        try:
            sentence = self.framing.decode(frame, self.direction, reply)
        except DirectionNeeded as needed:
            # a line with the code of the request just read is its answer, unless that answer is values alone
            answer = self.framing.by_code[needed.code]["response"]
            direction = "response" if self._asked == needed.code and not answer.bare else "request"
            sentence = self.framing.decode(frame, direction, reply)
        if sentence.direction == "response" and sentence.code == self._awaited:
            self._awaited = None  # answered: the next line is read by its own code again
        self._asked = sentence.code if sentence.direction == "request" else None
        return sentence

    @property
    def errors(self) -> int:
        """Frames dropped (what binary stream parsers call errors)."""
        return self.corrupt

    def _dropped(self, reason: str) -> None:
        self.corrupt += 1
        self.last_error = reason

    def gap(self) -> None:
        """The line went idle: no frame spans it. A frame begun (its start character read; frames without one: a line
        with more than blanks) is dropped as cut short, counted in `corrupt`; the line ending that follows is noise."""
        begun = self._buffer.startswith(self._starts) if self._start else bool(self._buffer.strip(b"\r\n"))
        if begun and not self._overlong:
            self._dropped("text frame cut short by a gap in the line")
        self._buffer, self._overlong = b"", False

    def pending(self) -> bytes:
        return self._buffer


def frames(framing: TextFraming, sentences: Iterable[Sentence]) -> bytes:
    """Several sentences as one stream."""
    return b"".join(framing.encode_sentence(s) for s in sentences)


# --- generated messages -------------------------------------------------------------------------------------------


class TextRecord:
    """Base of the generated message classes of a text protocol (frozen value classes, serialspec.runtime.values):
    `talker`, the fields in order, and `sent` (how many fields the frame had; -1 writes every declared one)."""

    COMMAND: ClassVar[str]
    CODE: ClassVar[str]
    DIRECTION: ClassVar[Direction]
    SUBCOMMAND: ClassVar[str | None] = None
    GROUPS: ClassVar[dict[str, type]] = {}  # repeat field -> the class of one group
    FRAMING: ClassVar[TextFraming]
    talker: str
    sent: int
    # `unchecked` (a class of a framing whose checksum may be left out): sent without it, encoded again without it

    def to_fields(self) -> dict[str, Any]:
        """The field values by name (groups as dicts), without talker, sent and unchecked."""
        values = {}
        for f in fields(self):  # type: ignore[arg-type]
            if f.name in ("talker", "sent", "unchecked"):
                continue
            value = getattr(self, f.name)
            if f.name in self.GROUPS:
                value = [asdict(row) for row in value]
            values[f.name] = value
        return values

    @classmethod
    def from_fields(cls, values: Mapping[str, Any], talker: str = "", sent: int = -1, unchecked: bool = False) -> Any:
        known = {f.name for f in fields(cls)}  # type: ignore[arg-type]
        unknown = set(values) - known
        if unknown:
            raise EncodeError(f"{cls.CODE}: unknown field {sorted(unknown)[0]!r}")
        given = dict(values)
        # talker and sent may come with the values (a simulator builds a message from all its attributes)
        talker = str(given.pop("talker", None) or talker)
        sent = int(given.pop("sent", sent))
        unchecked = bool(given.pop("unchecked", unchecked))
        for name, group in cls.GROUPS.items():
            if name in given:
                given[name] = tuple(row if isinstance(row, group) else group(**row) for row in given[name])
        if talker:
            given["talker"] = talker
        if unchecked:
            if "unchecked" not in known:
                raise EncodeError(f"{cls.CODE}: its checksum cannot be left out")
            given["unchecked"] = True
        factory: Any = cls  # a generated value class: its fields are keyword arguments
        return factory(**given, sent=sent)

    def encode(self) -> bytes:
        unchecked = bool(getattr(self, "unchecked", False))
        return self.FRAMING.encode(self.CODE, self.to_fields(), self.talker, self.sent, self.DIRECTION.value, unchecked)


class TextCodec:
    """decode, encode and the stream parser of one text protocol, over its generated message classes."""

    def __init__(
        self,
        framing: TextFraming,
        classes: Iterable[type[TextRecord]],
        answers: Mapping[str, tuple[tuple[str, ...], ...]] | None = None,
    ) -> None:
        self.framing = framing
        self.classes = {(cls.CODE, cls.DIRECTION.value): cls for cls in classes}
        # request code -> the codes of the responses that answer it and of those that refuse it, where these are
        # not its own command's response (the spec's `answered_by`: GRBL answers every line with ok or error:N)
        self.answers = dict(answers or {})
        self._responses = {c: cls for (c, direction), cls in self.classes.items() if direction == "response"}

    def replies(self, code: str) -> tuple[tuple[type[TextRecord], ...], tuple[type[TextRecord], ...]]:
        """The response classes that answer a request of this code, and those that refuse it."""
        answering, refusing = self.answers.get(code, ((code,), ()))[:2]
        responses = self._responses
        return tuple(responses[c] for c in answering if c in responses), tuple(responses[c] for c in refusing)

    def final(self, code: str) -> type[TextRecord] | None:
        """The response that ends the answer to a request of this code, after its reply (`then`), or None."""
        ending = self.answers.get(code, ((), (), ()))[2:]  # (answers, refusals, (the final code,)): with `then`
        return self._responses[ending[0][0]] if ending and ending[0] else None

    def message(self, sentence: Sentence) -> Any:
        cls = self.classes[sentence.code, sentence.direction]
        return cls.from_fields(sentence.values, sentence.talker, sentence.sent, sentence.unchecked)

    def decode(self, frame: bytes | str, direction: str | None = None, expect: Any = None, request: Any = None) -> Any:
        """One frame -> its message; DecodeError (ChecksumError) says in one line why not. `direction` ("request"
        or "response") is needed only for a code that names both. A reply of values alone (`values_only`) is read
        as the answer to `request` (a message) or as `expect` (the reply class awaited)."""
        reply = expect.CODE if expect is not None else None
        if request is not None:  # the reply of values alone it gets, else its own code: the request is known
            reply = self.reply_code(request.CODE) or request.CODE
        return self.message(self.framing.decode(frame, direction, reply))

    def reply_code(self, code: str) -> str | None:
        """The code of the reply of values alone that answers a request of this code, or None."""
        for cls in self.replies(code)[0]:
            sentence = self.framing.by_code.get(cls.CODE, {}).get("response")
            if sentence is not None and sentence.bare:
                return cls.CODE
        return None

    def encode(self, message: TextRecord) -> bytes:
        """A message -> its frame; EncodeError (RangeError) names the field at fault before any text is written."""
        return message.encode()


class TextMessageParser(TextStreamParser):
    """The stream parser giving generated messages."""

    def __init__(self, codec: TextCodec, direction: str | None = None) -> None:
        super().__init__(codec.framing, direction)
        self.codec = codec

    def feed(self, data: bytes | bytearray | memoryview) -> list[Any]:
        return [self.codec.message(s) for s in super().feed(data)]


# --- the client ---------------------------------------------------------------------------------------------------


class TextClient:
    """A text device on a serial port (a path, any URL pyserial opens, or an open port): the messages it sends on
    its own, by iteration (`for message in client`, or `messages(timeout)`), and by callbacks subscribed with
    `on(callback, *types)`, called as the messages are read. `send` writes a message. Generated packages bind
    `CODEC` and `SERIAL` in their `Client`.

    `echo=True`: the device (or a one-wire adapter) sends every line written back before its answer (an AT module
    or an ELM327 with echo on, ATE1): the client takes the echo out of what it reads, so a request read back is
    never taken for its reply, and an echo that differs from the line written is a PortError."""

    CODEC: ClassVar[TextCodec]
    SERIAL: ClassVar[Any]

    def __init__(self, port: Any, *, baudrate: int | None = None, echo: bool = False) -> None:
        from serialspec.runtime.transport import _PARITY, link

        if isinstance(port, str):
            import serial

            settings = self.SERIAL
            port = serial.serial_for_url(
                port,
                baudrate=baudrate or settings.baudrate,
                bytesize=settings.bytesize,
                parity=_PARITY[settings.parity],
                stopbits=settings.stopbits,
                timeout=1.0,
            )
        self.port = port
        self._link = link(port)
        self.parser = TextMessageParser(self.CODEC, "response")
        self._callbacks: list[tuple[Callable[[Any], None], tuple[type, ...]]] = []
        self._unread: list[Any] = []  # messages read while waiting for an answer, for `messages()` and `read()`
        self.echo = echo
        self._echoed = b""  # with echo: the bytes written whose echo has not all come back yet

    def on(self, callback: Callable[[Any], None], *types: type) -> Callable[[], None]:
        """Call `callback(message)` for every message read (of these types; none given: all); returns a function
        that ends the subscription."""
        entry = (callback, types)
        self._callbacks.append(entry)
        return lambda: self._callbacks.remove(entry) if entry in self._callbacks else None

    def read(self, timeout: float = 1.0) -> list[Any]:
        """The messages complete in what arrives within `timeout` seconds of the first byte (callbacks called)."""
        from serialspec.runtime.transport import drive

        return drive(self._reading(timeout), self._link.read)

    def request(self, message: TextRecord, timeout: float = 1.0) -> Any:
        """Send a request and return the device's answer (its command's response); Timeout when none comes within
        `timeout` seconds. What else arrives meanwhile (messages the device sends on its own) goes to the
        callbacks at once and to `read()`/`messages()` later, in order."""
        from serialspec.runtime.transport import drive

        self.send(message)
        return drive(self._answer(message, timeout), self._link.read)

    def request_many(self, message: TextRecord, timeout: float = 1.0) -> tuple[Any, ...]:
        """Send a request whose reply comes any number of times (`answered_by: {many: true}`) and return the
        replies that came before the line that ends the answer (`then`), in order; Timeout when that line does not
        come within `timeout` seconds, DeviceError for a refusal."""
        from serialspec.runtime.transport import drive

        self.send(message)
        return drive(self._answer(message, timeout, many=True), self._link.read)

    def messages(self, timeout: float | None = None) -> Iterator[Any]:
        """The messages as they arrive; ends when none has come for `timeout` seconds (None: never)."""
        import time

        last = time.monotonic()
        while True:
            found = self.read(0.2 if timeout is None else max(0.0, min(0.2, last + timeout - time.monotonic())))
            yield from found
            now = time.monotonic()
            if found:
                last = now
            elif timeout is not None and now - last >= timeout:
                return

    def __iter__(self) -> Iterator[Any]:
        return self.messages()

    # The steps of reading and of waiting for an answer, as generators that yield how long to wait for bytes and
    # are sent what arrived: `transport.drive` runs them blocking, `AsyncTextClient` with awaits.

    def _reading(self, timeout: float) -> Generator[float, bytes, list[Any]]:
        if self._unread:  # read while a request waited for its answer: their callbacks were called then
            unread, self._unread = self._unread, []
            return unread
        return self._arrived((yield timeout))

    def _answer(self, message: TextRecord, timeout: float, many: bool = False) -> Generator[float, bytes, Any]:
        """The answer to a request just sent; `many` (a request whose reply comes any number of times before the
        line that ends the answer: `answered_by: {many: true}`): the tuple of them."""
        import time

        from serialspec.runtime.errors import DeviceError, Timeout

        answers, refusals = self.CODEC.replies(message.CODE)
        if not answers:
            return None  # a command the device does not answer
        final = self.CODEC.final(message.CODE)  # the response that ends the answer, after the reply (`then`)
        self.parser.expect(self.CODEC.reply_code(message.CODE))  # a reply of values alone is read as the answer
        answer = None
        replies: list[Any] = []
        try:
            deadline = time.monotonic() + timeout
            while (left := deadline - time.monotonic()) > 0:
                for arrived in self._arrived((yield min(left, 0.2))):
                    if many and final is not None and isinstance(arrived, answers):
                        replies.append(arrived)  # one more reply line, until the one that ends them
                    elif answer is None and isinstance(arrived, answers):
                        if final is None:
                            return arrived
                        answer = arrived  # the answer goes on to its final response
                        self.parser.expect(None)
                    elif isinstance(arrived, refusals):
                        raise DeviceError(
                            f"{message.COMMAND} ({message.CODE}): the device refused it: {arrived!r}", arrived
                        )
                    elif final is not None and isinstance(arrived, final):
                        if many:
                            return tuple(replies)
                        if answer is None:
                            raise DeviceError(
                                f"{message.COMMAND} ({message.CODE}): the device ended its answer ({arrived!r}) "
                                "without a reply",
                                arrived,
                            )
                        return answer
                    else:
                        self._unread.append(arrived)
            late = Timeout(f"{message.COMMAND} ({message.CODE})", "", timeout)
            if (answer is not None or replies) and final is not None:  # the reply came: say what did not
                late.args = (
                    f"{message.COMMAND} ({message.CODE}): its reply came, but not the {final.CODE!r} that ends the "
                    f"answer within {timeout * 1000:.0f} ms",
                )
            raise late
        finally:
            self.parser.expect(None)

    def _arrived(self, data: bytes) -> list[Any]:
        if self._echoed and data:  # the echo of what was written comes first: take it out
            from serialspec.runtime.errors import PortError

            take = min(len(data), len(self._echoed))
            if data[:take] != self._echoed[:take]:
                written, self._echoed = self._echoed, b""
                raise PortError(
                    f"{getattr(self.port, 'port', None) or 'the port'}: the echo differs from the line written: "
                    f"wrote {written!r}, read back {data[:take]!r}; is echo=True right for this device?"
                )
            data, self._echoed = data[take:], self._echoed[take:]
        messages = self.parser.feed(data)
        for message in messages:
            for callback, types in list(self._callbacks):
                if not types or isinstance(message, types):
                    callback(message)
        return messages

    def send(self, message: TextRecord) -> None:
        """Write one message (range checks first: nothing is written when a value is refused)."""
        frame = self.CODEC.encode(message)
        self._link.write(frame)
        if self.echo:
            self._echoed += frame

    def close(self) -> None:
        self.port.close()

    def __enter__(self) -> TextClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class AsyncTextClient:
    """TextClient for asyncio: the same port, parser, callbacks and answers, with every read awaited (a POSIX
    port's descriptor is watched by the event loop, other ports read in a worker thread; runtime/aio.py).
    Generated packages bind `CODEC` and `SERIAL` in their `AsyncClient`."""

    CODEC: ClassVar[TextCodec]
    SERIAL: ClassVar[Any]

    def __init__(self, port: Any, *, baudrate: int | None = None, echo: bool = False) -> None:
        bound = type("Client", (TextClient,), {"CODEC": self.CODEC, "SERIAL": self.SERIAL})
        self.sync: TextClient = bound(port, baudrate=baudrate, echo=echo)

    def on(self, callback: Callable[[Any], None], *types: type) -> Callable[[], None]:
        """`TextClient.on`: call `callback(message)` for every message read (of these types)."""
        return self.sync.on(callback, *types)

    async def read(self, timeout: float = 1.0) -> list[Any]:
        from serialspec.runtime.aio import drive

        return await drive(self.sync._reading(timeout), self._wait)

    async def request(self, message: TextRecord, timeout: float = 1.0) -> Any:
        """`TextClient.request`, awaited."""
        from serialspec.runtime.aio import drive

        await self.send(message)
        return await drive(self.sync._answer(message, timeout), self._wait)

    async def request_many(self, message: TextRecord, timeout: float = 1.0) -> tuple[Any, ...]:
        """`TextClient.request_many`, awaited."""
        from serialspec.runtime.aio import drive

        await self.send(message)
        return await drive(self.sync._answer(message, timeout, many=True), self._wait)

    async def messages(self, timeout: float | None = None) -> AsyncIterator[Any]:
        """The messages as they arrive; ends when none has come for `timeout` seconds (None: never)."""
        import time

        last = time.monotonic()
        while True:
            found = await self.read(0.2 if timeout is None else max(0.0, min(0.2, last + timeout - time.monotonic())))
            for message in found:
                yield message
            now = time.monotonic()
            if found:
                last = now
            elif timeout is not None and now - last >= timeout:
                return

    def __aiter__(self) -> AsyncIterator[Any]:
        return self.messages()

    async def send(self, message: TextRecord) -> None:
        """Write one message (range checks first: nothing is written when a value is refused)."""
        self.sync.send(message)

    async def _wait(self, wait: float) -> bytes:
        from serialspec.runtime.aio import read_available

        return await read_available(self.sync._link, self.sync.port, wait)

    def close(self) -> None:
        self.sync.close()

    async def __aenter__(self) -> AsyncTextClient:
        return self

    async def __aexit__(self, *exc: object) -> None:
        self.close()
