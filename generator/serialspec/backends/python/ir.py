"""The statements the Python backend writes, as values: built by the emitters, rewritten by the optimisations that
make the generated code fast (optimize.py), and turned into source text once, at the end (`lines_of`).

Expressions stay text (every piece of them built by the emitter from checked names and repr()), but each statement a
rewrite looks into is a node that says what it does: an unpack says which struct it unpacks where, a move of the
content cursor by how much, a size check which size. No rewrite reads generated source back.

The content decoders' cursor: `buf` holds the frame, `o` is the offset of the next content byte, `end` the content's
end. A statement that reads either says so (`cursor`), as the whole-frame decoders, which know every offset, take
only the ones that do not.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import assert_never


@dataclass(frozen=True)
class Code:
    """A simple statement no rewrite looks into; `cursor`: it reads `o` or `end`; `reads`: the constant offsets of
    `buf` it reads; `checks`: it calls a runtime helper that may refuse the value (raises DecodeError: text that is
    not UTF-8), so a decoder that must raise nothing (the whole-frame decoders) cannot hold it."""

    text: str
    cursor: bool = False
    reads: tuple[int, ...] = ()
    lists: tuple[str, ...] = ()  # the lists of numbers whose items it packs (PackItems), by their expressions
    checks: bool = False

    def lines(self) -> list[str]:
        return [self.text]


@dataclass(frozen=True)
class Raise:
    """`raise <error>`; "" re-raises the exception being handled."""

    error: str

    def lines(self) -> list[str]:
        return [f"raise {self.error}" if self.error else "raise"]


@dataclass(frozen=True)
class If:
    """`if <condition>:` and its body."""

    condition: str
    body: tuple[Statement, ...]
    cursor: bool = False  # the condition reads `o` or `end`
    reads: tuple[int, ...] = ()  # the constant offsets of `buf` the condition reads
    comment: str = ""

    def lines(self) -> list[str]:
        comment = f"  # {self.comment}" if self.comment else ""
        return [f"if {self.condition}:{comment}", *indented(self.body)]


@dataclass(frozen=True)
class Loop:
    """A `for` or `while` statement (`header`, without its colon) and its body."""

    header: str
    body: tuple[Statement, ...]
    cursor: bool = False  # the header reads `o` or `end`
    variable: str = ""  # a `for` loop's one target, where rewrites may look at it

    def lines(self) -> list[str]:
        return [f"{self.header}:", *indented(self.body)]


@dataclass(frozen=True)
class ItemsCheck:
    """A loop over a list of numbers (`items`) that raises `error` at the first not within low..high or a bool;
    `deferrable`: struct.pack refuses what the loop would (the range is the item type's), so the loop may run only
    when the pack fails (deferred_item_checks); `chained`: the error is raised from None (in an except clause)."""

    item: str
    items: str
    low: str
    high: str
    error: str
    deferrable: bool = False
    chained: bool = False

    def lines(self) -> list[str]:
        raised = f"raise {self.error}" + (" from None" if self.chained else "")
        return [
            f"for {self.item} in {self.items}:",
            f"    if not {self.low} <= {self.item} <= {self.high} or {self.item}.__class__ is bool:",
            f"        {raised}",
        ]


@dataclass(frozen=True)
class Try:
    """`try:` its body, `except <caught>:` the handler."""

    body: tuple[Statement, ...]
    caught: str
    handler: tuple[Statement, ...]
    comment: str = ""

    def lines(self) -> list[str]:
        comment = f"  # {self.comment}" if self.comment else ""
        return ["try:", *indented(self.body), f"except {self.caught}:{comment}", *indented(self.handler)]


@dataclass(frozen=True)
class ContentSize:
    """A content decoder's first check: the content's size within the message's bounds (`high` None: no upper)."""

    low: int
    high: int | None
    where: str

    @property
    def exact(self) -> bool:
        return self.low == self.high

    def lines(self) -> list[str]:
        low, high = self.low, self.high
        if low == high:
            condition = f"end - o != {low}"
        elif high is None:
            condition = f"end - o < {low}"
        else:
            condition = f"not {low} <= end - o <= {high}"
        return [f"if {condition}:", f"    raise content_size_error({self.where}, end - o, {low}, {high})"]


@dataclass(frozen=True)
class Needs:
    """`size` bytes (a number, or the local that holds it) must be left at the cursor, else `error` is raised."""

    size: int | str
    error: str

    def lines(self) -> list[str]:
        return [f"if end - o < {self.size}:", f"    raise {self.error}"]


@dataclass(frozen=True)
class Expect:
    """An unpacked value that must be one constant (a fixed field, a sub-command's code): else `error` is raised."""

    name: str
    value: str
    error: str

    def lines(self) -> list[str]:
        return [f"if {self.name} != {self.value}:", f"    raise {self.error}"]


@dataclass(frozen=True)
class TakeRest:
    """`target = buf[start:stop]`: bytes up to the content's end (`stop`)."""

    target: str
    start: int | str = "o"
    stop: int | str = "end"

    def lines(self) -> list[str]:
        return [f"{self.target} = buf[{self.start}:{self.stop}]"]


@dataclass(frozen=True)
class FrameTest:
    """`return None` unless a whole frame's checksum holds: `condition` (an int expression, 0 exactly when it does)
    reads the check byte at its offset; `from_end` is the same test reading it from the frame's end (for a decoder
    whose frame size nothing checked, see exact_whole)."""

    condition: str
    from_end: str

    def lines(self) -> list[str]:
        return [f"if {self.condition}:", "    return None"]


@dataclass(frozen=True)
class Unpack:
    """`targets = <struct>.unpack_from(buf, <at>)`; `tuple_target`: one target that takes the whole tuple (`t = `);
    `byte`: the struct is one unsigned byte, read by indexing once `indexed` (see fuse_unpack); `at` "": the struct
    is the whole of `buf`; a number: a constant offset of the frame."""

    targets: tuple[str, ...]
    struct: str
    at: int | str = "o"
    tuple_target: bool = False
    byte: bool = False
    indexed: bool = False

    @property
    def call(self) -> str:
        return f"{self.struct}.unpack(buf)" if self.at == "" else f"{self.struct}.unpack_from(buf, {self.at})"

    def lines(self) -> list[str]:
        if self.indexed:
            return [f"{self.targets[0]} = buf[{self.at}]"]
        if self.tuple_target:
            return [f"{self.targets[0]} = {self.call}"]
        comma = "," if len(self.targets) == 1 else ""
        return [f"{', '.join(self.targets)}{comma} = {self.call}"]


@dataclass(frozen=True)
class Advance:
    """The cursor moved past a field: by `size` bytes (a number, or the local that holds it), or to `to` (an
    expression) where given."""

    size: int | str = 0
    to: str = ""

    def lines(self) -> list[str]:
        return [f"o = {self.to}" if self.to else f"o += {self.size}"]


@dataclass(frozen=True)
class LeftOver:
    """The check that no content is left after the last field; `less`: bytes the cursor stops short by (see
    fold_last_size_check)."""

    where: str
    less: int | str = 0

    @property
    def error(self) -> Raise:
        left = f"end - o - {self.less}" if self.less else "end - o"
        return Raise(f"DecodeError({self.where} + f': {{{left}}} bytes left after the last field')")

    def lines(self) -> list[str]:
        return ["if o != end:", *indented([self.error])]


@dataclass(frozen=True)
class ReturnNew:
    """`return _new(<cls>, (values...))`: a generated class's instance made from its field values (see
    PackageCode.build); `unpacked`: the values are the tuple this unpack gives (see fuse_unpack)."""

    cls: str
    values: tuple[str, ...]
    unpacked: Unpack | None = None

    def lines(self) -> list[str]:
        if self.unpacked is not None:
            return [f"return _new({self.cls}, {self.unpacked.call})"]
        return [f"return _new({self.cls}, {values_tuple(list(self.values))})"]


Statement = (
    Code
    | Raise
    | If
    | Loop
    | ItemsCheck
    | Try
    | ContentSize
    | Needs
    | Expect
    | TakeRest
    | FrameTest
    | Unpack
    | Advance
    | LeftOver
    | ReturnNew
)
RETURN_NONE = Code("return None")
Block = list[Statement]


def values_tuple(values: list[str]) -> str:
    """A tuple display of expressions: `(a, b)`, `(a,)`, `()`."""
    return f"({values[0]},)" if len(values) == 1 else f"({', '.join(values)})"


def indented(statements: Iterable[Statement], prefix: str = "    ") -> list[str]:
    return [prefix + line for statement in statements for line in statement.lines()]


def lines_of(statements: Iterable[Statement]) -> list[str]:
    """The source lines of statements, at the indentation of their block."""
    return [line for statement in statements for line in statement.lines()]


def walk(statements: Iterable[Statement]) -> Iterator[Statement]:
    """Every statement, and every statement inside one, in source order."""
    for statement in statements:
        yield statement
        if isinstance(statement, If | Loop):
            yield from walk(statement.body)
        elif isinstance(statement, Try):
            yield from walk(statement.body)
            yield from walk(statement.handler)


def single_line(statement: Statement) -> bool:
    """Whether a statement is one line of source: no block, no check."""
    match statement:
        case Code() | Raise() | Unpack() | Advance() | TakeRest() | ReturnNew():
            return True
        case If() | Loop() | ItemsCheck() | Try() | ContentSize() | Needs() | Expect() | FrameTest() | LeftOver():
            return False
        case _:
            assert_never(statement)


def raises(statements: Iterable[Statement]) -> bool:
    """Whether any of the statements raises an error (a check, or a helper that checks)."""
    checks = Raise | ContentSize | Needs | Expect | LeftOver | ItemsCheck
    return any(isinstance(s, checks) or (isinstance(s, Code) and s.checks) for s in walk(statements))


def reads_cursor(statement: Statement) -> bool:
    """Whether a statement (its own text, not its body's) reads or moves the content cursor or reads `end`."""
    match statement:
        case Code() | If() | Loop():
            return statement.cursor
        case Unpack():
            return statement.at == "o"
        case TakeRest():
            return statement.start == "o" or statement.stop == "end"
        case ReturnNew():
            return statement.unpacked is not None and statement.unpacked.at == "o"
        case ContentSize() | Needs() | Advance() | LeftOver():
            return True
        case Raise() | Expect() | FrameTest() | ItemsCheck() | Try():
            return False
        case _:
            assert_never(statement)


def packed_lists(parts: Iterable[str]) -> tuple[str, ...]:
    """The lists of numbers that byte parts of a content pack (PackItems), by their expressions."""
    return tuple(part.items for part in parts if isinstance(part, PackItems))


# --- expressions a rewrite looks into ------------------------------------------------------------------------------
# Each is the expression's text (a str: it goes anywhere an expression goes) that also says what it is made of.


class Simple(str):
    """An expression that is a name, an attribute or a non-negative number: cheap to give twice."""

    __slots__ = ()


class Calls(str):
    """An expression with the runtime helpers it calls, by the names generated code gives them (`_get`, ...): the
    module that holds it imports those (package.field_imports)."""

    __slots__ = ("helpers",)
    helpers: frozenset[str]

    def __new__(cls, text: str, helpers: Iterable[str], *inner: str) -> Calls:
        """`text` calls `helpers` and holds the expressions `inner` (their helpers are its too)."""
        made = super().__new__(cls, text)
        made.helpers = frozenset(helpers).union(*(helpers_of(part) for part in inner))
        return made


def helpers_of(expression: str) -> frozenset[str]:
    """The runtime helpers an expression calls (none unless it is a Calls)."""
    return expression.helpers if isinstance(expression, Calls) else frozenset()


class Literal(str):
    """A bytes literal, its bytes kept."""

    __slots__ = ("data",)
    data: bytes

    def __new__(cls, data: bytes) -> Literal:
        made = super().__new__(cls, repr(data))
        made.data = data
        return made


class Pack(str):
    """`<struct>.pack(<arguments>)`: bytes of fixed-size values in one struct call."""

    __slots__ = ("arguments", "struct")
    struct: str
    arguments: tuple[str, ...]

    def __new__(cls, struct: str, arguments: Iterable[str]) -> Pack:
        arguments = tuple(arguments)
        made = super().__new__(cls, f"{struct}.pack({', '.join(arguments)})")
        made.struct, made.arguments = struct, arguments
        return made


class PackItems(str):
    """`struct.pack(f'<order>{len(items)}<char>', *items)`: a list of numbers whose count is known at run time."""

    __slots__ = ("char", "items", "order")
    order: str
    char: str
    items: str

    def __new__(cls, order: str, char: str, items: str) -> PackItems:
        made = super().__new__(cls, f"struct.pack(f'{order}{{len({items})}}{char}', *{items})")
        made.order, made.char, made.items = order, char, items
        return made

    @property
    def counted_format(self) -> str:
        """The struct format's text after the byte order, as an f-string's part."""
        return f"{{len({self.items})}}{self.char}"
