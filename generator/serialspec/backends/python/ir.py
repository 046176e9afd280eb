"""The statements the Python backend writes, as values: built by the emitters, rewritten by the optimisations that
make the generated code fast, and turned into source text once, at the end (`render`).

Expressions stay text (every piece of them built by the emitter from checked names and repr()), but each statement a
rewrite looks into is a node that says what it does: an unpack says which struct it unpacks where, a move of the
content cursor by how much, a size check which size. No rewrite reads generated source back.

The content decoders' cursor: `buf` holds the frame, `o` is the offset of the next content byte, `end` the content's
end. A statement that reads either says so (`cursor`), as the whole-frame decoders, which know every offset, take
only the ones that do not.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace
from typing import assert_never


@dataclass(frozen=True)
class Code:
    """A simple statement no rewrite looks into; `cursor`: it reads `o` or `end`; `reads`: the constant offsets of
    `buf` it reads."""

    text: str
    cursor: bool = False
    reads: tuple[int, ...] = ()

    def lines(self) -> list[str]:
        return [self.text]


@dataclass(frozen=True)
class Raise:
    """`raise <error>`."""

    error: str

    def lines(self) -> list[str]:
        return [f"raise {self.error}"]


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

    def lines(self) -> list[str]:
        return [f"{self.header}:", *indented(self.body)]


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
    """`size` bytes (an expression) must be left at the cursor, else `error` is raised."""

    size: str
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
    start: str = "o"
    stop: str = "end"

    def lines(self) -> list[str]:
        return [f"{self.target} = buf[{self.start}:{self.stop}]"]


@dataclass(frozen=True)
class SumCheck:
    """`return None` unless an 8-bit sum over all of `buf` but its first bytes (their sum taken off: `less`) holds:
    the covered bytes sum to the check byte at `check_at`, so the whole frame sums to twice it."""

    less: str
    check_at: str

    def lines(self) -> list[str]:
        return [f"if (sum(buf){self.less} - 2 * buf[{self.check_at}]) & 0xff:", "    return None"]


@dataclass(frozen=True)
class Unpack:
    """`targets = <struct>.unpack_from(buf, <at>)`; `tuple_target`: one target that takes the whole tuple (`t = `);
    `byte`: the struct is one unsigned byte, read by indexing once `indexed` (see fuse_unpack); `at` "": the struct
    is the whole of `buf`."""

    targets: tuple[str, ...]
    struct: str
    at: str = "o"
    tuple_target: bool = False
    byte: bool = False
    indexed: bool = False

    @property
    def call(self) -> str:
        return f"{self.struct}.unpack_from(buf, {self.at})" if self.at else f"{self.struct}.unpack(buf)"

    def lines(self) -> list[str]:
        if self.indexed:
            return [f"{self.targets[0]} = buf[{self.at}]"]
        if self.tuple_target:
            return [f"{self.targets[0]} = {self.call}"]
        comma = "," if len(self.targets) == 1 else ""
        return [f"{', '.join(self.targets)}{comma} = {self.call}"]


@dataclass(frozen=True)
class Advance:
    """The cursor moved past a field: by `size` bytes (an expression), or to `to` (an expression) where given."""

    size: str = ""
    to: str = ""

    def lines(self) -> list[str]:
        return [f"o = {self.to}" if self.to else f"o += {self.size}"]


@dataclass(frozen=True)
class LeftOver:
    """The check that no content is left after the last field; `less`: bytes the cursor stops short by (see
    fold_last_size_check)."""

    where: str
    less: str = ""

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
    | ContentSize
    | Needs
    | Expect
    | TakeRest
    | SumCheck
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


def raises(statements: Iterable[Statement]) -> bool:
    """Whether any of the statements raises an error (a check)."""
    return any(isinstance(s, Raise | ContentSize | Needs | Expect | LeftOver) for s in walk(statements))


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
        case Raise() | Expect() | SumCheck():
            return False
        case _:
            assert_never(statement)


def fold_last_size_check(body: Block) -> Block:
    """A decoder's statements with the size check of its last field, read up to the content's end, and the check
    that nothing is left after it made one comparison on the way of an intact frame (`end - o != size`), each error
    still raised as before; the cursor is not moved past the last field, as nothing reads it."""
    if len(body) < 5:
        return body
    needs, read, moved, left, returned = body[-5:]
    if not (isinstance(needs, Needs) and isinstance(moved, Advance) and isinstance(left, LeftOver)):
        return body
    if not isinstance(returned, ReturnNew) or reads_cursor(returned) or moved.to or moved.size != needs.size:
        return body
    if len(read.lines()) != 1:
        return body
    size = needs.size
    folded = If(f"end - o != {size}", (needs, replace(left, less=size).error), cursor=True)
    return [*body[:-5], folded, read, returned]


def fuse_unpack(body: Block) -> Block:
    """A decoder's final statements, made cheaper: an unpack into locals that are then built, in order, into the
    returned message becomes one statement, `return _new(Cls, _S.unpack_from(buf, o))` (the tuple struct gives is
    the message's); a lone unsigned byte is read by indexing, not unpacked (at any depth)."""
    out: Block = []
    for statement in body:
        last = out[-1] if out else None
        if (
            isinstance(statement, ReturnNew)
            and statement.unpacked is None
            and isinstance(last, Unpack)
            and not last.tuple_target
            and not last.indexed
            and statement.values == last.targets
        ):
            out[-1] = replace(statement, unpacked=last)
            continue
        out.append(statement)
    return [_indexed(statement) for statement in out]


def _indexed(statement: Statement) -> Statement:
    match statement:
        case Unpack(byte=True, tuple_target=False, targets=(_,)):
            return replace(statement, indexed=True)
        case If() | Loop():
            return replace(statement, body=tuple(_indexed(s) for s in statement.body))
        case _:
            return statement
