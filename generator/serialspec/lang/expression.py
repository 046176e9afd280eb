"""Integer expressions in specs: derived values such as Modbus `byte_count = 2 * quantity` or
`ceil(quantity / 8)`.

An expression is parsed once, when the spec is resolved, into a small immutable tree; emitters render the tree
(never the spec's text) and the runtime may evaluate it. The language is deliberately small: integers, the names
of earlier fields, `len(list_field)`, `+ - * / % & | << >>`, `ceil(a / b)`, `min`, `max` and parentheses.
`/` is integer division (exact division is what specs mean; a decoder recomputes every derived value and
refuses a frame whose value differs, so an inexact division cannot pass unnoticed); `ceil(a / b)` rounds up.

Limits, so that no spec and no frame can make an expression exhaust the checker or a decoder: at most MAX_TEXT
characters and MAX_DEPTH levels of nesting (a flat chain of 3,000 `*` is refused in one line, not by Python's
recursion limit), and every value it can take for any values of its fields' types, intermediate results included,
within MAX_BITS bits (`bounds`): `1 << (n * 100000000)` is refused when the spec is checked, since one wire byte
could ask for a 3 GB integer. What only the wire decides (a divisor that can be 0, a shift count that can be
negative: `fails`) is a DecodeError of the frame, an EncodeError of the message.
"""

from __future__ import annotations

import ast
import keyword
import re
from collections.abc import Callable, Iterator, Mapping

from serialspec.lang.frozen import frozen

_OPERATORS: dict[type[ast.operator], str] = {
    ast.Add: "+",
    ast.Sub: "-",
    ast.Mult: "*",
    ast.Div: "/",
    ast.FloorDiv: "/",
    ast.Mod: "%",
    ast.BitAnd: "&",
    ast.BitOr: "|",
    ast.LShift: "<<",
    ast.RShift: ">>",
}
_FUNCTIONS = ("ceil", "len", "min", "max")
MAX_TEXT = 500  # characters
MAX_DEPTH = 50  # levels of nesting
MAX_BITS = 512  # of any value an expression can take, intermediate results included
MAX_ITEMS = 1 << 16  # what len() of a field can be, at most (more than any frame holds)


class ExpressionError(ValueError):
    """The text is not an expression of the spec language; the message says why, for one spec error line."""


@frozen
class Const:
    value: int


@frozen
class Name:
    """The value of an earlier field of the same message."""

    name: str


@frozen
class Length:
    """The number of items of a list field (`len(values)`)."""

    name: str


@frozen
class BinOp:
    op: str
    left: Expr
    right: Expr


@frozen
class Invert:
    """`~a`: every bit flipped (a Python int's ~, so -a - 1; whoever stores it masks it to its width)."""

    operand: Expr


@frozen
class Ceil:
    """`ceil(numerator / denominator)`: integer division rounding up."""

    numerator: Expr
    denominator: Expr


@frozen
class MinMax:
    function: str  # "min" or "max"
    args: tuple[Expr, ...]


Expr = Const | Name | Length | BinOp | Invert | Ceil | MinMax


def parse(text: str) -> Expr:
    """Parse an expression; raises ExpressionError naming what is not allowed."""
    if not isinstance(text, str):
        raise ExpressionError(f"expected an expression as text, got {text!r}")
    if len(text) > MAX_TEXT:
        raise ExpressionError(f"an expression of {len(text)} characters is too long (at most {MAX_TEXT})")
    # a field named after a Python keyword (`len(from)`): parsed under another name, named back in _convert
    text = _IDENTIFIER.sub(lambda m: m[0] + _KEYWORD_MARK if keyword.iskeyword(m[0]) else m[0], text)
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError:
        raise ExpressionError(f"{text[:60]!r} is not an expression") from None
    except (RecursionError, MemoryError):  # Python's own parser, on deep nesting within the length limit
        raise ExpressionError(f"{text[:60]!r}... is nested too deeply (at most {MAX_DEPTH} levels)") from None
    # depth first, without recursion: the conversion below recurses once per level
    stack: list[tuple[ast.AST, int]] = [(tree.body, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise ExpressionError(f"{text[:60]!r}... is nested too deeply (at most {MAX_DEPTH} levels)")
        stack.extend((child, depth + 1) for child in ast.iter_child_nodes(node))
    return _convert(tree.body, text)


_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_KEYWORD_MARK = "__keyword"  # appended to a keyword for Python's parser


def _field(name: str) -> str:
    """A name as the spec gives it: a keyword marked by parse() unmarked."""
    base = name.removesuffix(_KEYWORD_MARK)
    return base if base != name and keyword.iskeyword(base) else name


def _convert(node: ast.expr, text: str) -> Expr:
    if isinstance(node, ast.Constant) and isinstance(node.value, int) and not isinstance(node.value, bool):
        return Const(node.value)
    if isinstance(node, ast.Name):
        return Name(_field(node.id))
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        return BinOp("-", Const(0), _convert(node.operand, text))
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Invert):
        return Invert(_convert(node.operand, text))
    if isinstance(node, ast.BinOp) and type(node.op) in _OPERATORS:
        return BinOp(_OPERATORS[type(node.op)], _convert(node.left, text), _convert(node.right, text))
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and not node.keywords:
        function, args = node.func.id, node.args
        if function == "len" and len(args) == 1 and isinstance(args[0], ast.Name):
            return Length(_field(args[0].id))
        if function == "ceil" and len(args) == 1:
            inner = args[0]
            if isinstance(inner, ast.BinOp) and isinstance(inner.op, ast.Div | ast.FloorDiv):
                return Ceil(_convert(inner.left, text), _convert(inner.right, text))
            raise ExpressionError(f"{text!r}: ceil takes one division, as in ceil(quantity / 8)")
        if function in ("min", "max") and len(args) >= 2:
            return MinMax(function, tuple(_convert(arg, text) for arg in args))
        if function in _FUNCTIONS:
            raise ExpressionError(f"{text!r}: wrong arguments to {function}()")
        raise ExpressionError(f"{text!r}: unknown function {function!r} (expected one of {', '.join(_FUNCTIONS)})")
    shown = ast.get_source_segment(text, node) or type(node).__name__
    raise ExpressionError(
        f"{text!r}: {shown!r} is not allowed (integers, field names, len(), ceil(a / b), min(), max(), "
        "+ - * / % & | << >> ~)"
    )


def names(expr: Expr) -> Iterator[str]:
    """The field names an expression reads (a `len(x)` reads x)."""
    if isinstance(expr, Name | Length):
        yield expr.name
    elif isinstance(expr, BinOp):
        yield from names(expr.left)
        yield from names(expr.right)
    elif isinstance(expr, Invert):
        yield from names(expr.operand)
    elif isinstance(expr, Ceil):
        yield from names(expr.numerator)
        yield from names(expr.denominator)
    elif isinstance(expr, MinMax):
        for arg in expr.args:
            yield from names(arg)


def nodes(expr: Expr) -> list[Expr]:
    """Every node of an expression tree."""
    found: list[Expr] = [expr]
    if isinstance(expr, BinOp):
        found += nodes(expr.left) + nodes(expr.right)
    elif isinstance(expr, Ceil):
        found += nodes(expr.numerator) + nodes(expr.denominator)
    elif isinstance(expr, MinMax):
        for arg in expr.args:
            found += nodes(arg)
    elif isinstance(expr, Invert):
        found += nodes(expr.operand)
    return found


def with_lengths(expr: Expr, lengths: Mapping[str, int]) -> Expr:
    """The expression with `len(field)` of the fields whose length is known (a fixed array's count, fixed bytes'
    size) replaced by that number: a decoder that reads such a field in a run of fixed fields has no list of it."""
    if isinstance(expr, Length) and expr.name in lengths:
        return Const(lengths[expr.name])
    if isinstance(expr, BinOp):
        return BinOp(expr.op, with_lengths(expr.left, lengths), with_lengths(expr.right, lengths))
    if isinstance(expr, Invert):
        return Invert(with_lengths(expr.operand, lengths))
    if isinstance(expr, Ceil):
        return Ceil(with_lengths(expr.numerator, lengths), with_lengths(expr.denominator, lengths))
    if isinstance(expr, MinMax):
        return MinMax(expr.function, tuple(with_lengths(arg, lengths) for arg in expr.args))
    return expr


def render(expr: Expr, name: Callable[[str], str]) -> str:
    """Python source for the expression; `name(field)` gives the source of a field's value. Integer arithmetic
    only: `/` is `//`, ceil(a / b) is -(-a // b)."""
    if isinstance(expr, Const):
        return str(expr.value)
    if isinstance(expr, Name):
        return name(expr.name)
    if isinstance(expr, Length):
        return f"len({name(expr.name)})"
    if isinstance(expr, BinOp):
        op = "//" if expr.op == "/" else expr.op
        return f"({render(expr.left, name)} {op} {render(expr.right, name)})"
    if isinstance(expr, Invert):
        return f"(~{render(expr.operand, name)})"
    if isinstance(expr, Ceil):
        return f"(-(-{render(expr.numerator, name)} // {render(expr.denominator, name)}))"
    return f"{expr.function}({', '.join(render(arg, name) for arg in expr.args)})"


def show(expr: Expr) -> str:
    """The expression as people write it, for docs and error messages."""
    if isinstance(expr, Const):
        return str(expr.value)
    if isinstance(expr, Name):
        return expr.name
    if isinstance(expr, Length):
        return f"len({expr.name})"
    if _negation(expr):
        assert isinstance(expr, BinOp)
        return f"-({show(expr.right)})" if isinstance(expr.right, BinOp) else f"-{show(expr.right)}"
    if isinstance(expr, BinOp):
        return f"{_operand(expr.left)} {expr.op} {_operand(expr.right)}"
    if isinstance(expr, Invert):
        return f"~{_operand(expr.operand)}"
    if isinstance(expr, Ceil):
        return f"ceil({_operand(expr.numerator)} / {_operand(expr.denominator)})"
    return f"{expr.function}({', '.join(show(arg) for arg in expr.args)})"


def _operand(expr: Expr) -> str:
    return f"({show(expr)})" if isinstance(expr, BinOp) and not _negation(expr) else show(expr)


def _negation(expr: Expr) -> bool:
    """Whether the expression is a minus sign (`-x`, which parse() reads as `0 - x`): it binds tighter than every
    operator, so it needs no parentheses."""
    return isinstance(expr, BinOp) and expr.op == "-" and expr.left == Const(0)


def evaluate(expr: Expr, values: Mapping[str, object]) -> int:
    """The expression's value, with field values (lists for `len`) by name."""
    if isinstance(expr, Const):
        return expr.value
    if isinstance(expr, Name):
        value = values[expr.name]
        assert isinstance(value, int), f"{expr.name} = {value!r} is not an integer"
        return value
    if isinstance(expr, Length):
        items = values[expr.name]
        assert isinstance(items, list | tuple), f"{expr.name} = {items!r} is not a list"
        return len(items)
    if isinstance(expr, BinOp):
        left, right = evaluate(expr.left, values), evaluate(expr.right, values)
        return _APPLY[expr.op](left, right)
    if isinstance(expr, Invert):
        return ~evaluate(expr.operand, values)
    if isinstance(expr, Ceil):
        return -(-evaluate(expr.numerator, values) // evaluate(expr.denominator, values))
    found = [evaluate(arg, values) for arg in expr.args]
    return min(found) if expr.function == "min" else max(found)


_APPLY: dict[str, Callable[[int, int], int]] = {
    "+": lambda a, b: a + b,
    "-": lambda a, b: a - b,
    "*": lambda a, b: a * b,
    "/": lambda a, b: a // b,
    "%": lambda a, b: a % b,
    "&": lambda a, b: a & b,
    "|": lambda a, b: a | b,
    "<<": lambda a, b: a << b,
    ">>": lambda a, b: a >> b,
}


Bounds = tuple[int, int]


def bounds(expr: Expr, names: Mapping[str, Bounds]) -> Bounds:
    """The least and greatest values the expression can take when each name's value lies within its bounds (and
    each len() within 0..MAX_ITEMS), worked out without computing anything large: ExpressionError when a value, an
    intermediate one included, could need more than MAX_BITS bits. A division by a divisor that can be 0, or a shift
    by a count that can be negative, leaves that value out (`fails` says whether it can happen)."""
    if isinstance(expr, Const):
        return _fits(expr.value, expr.value, expr)
    if isinstance(expr, Name):
        return names[expr.name]
    if isinstance(expr, Length):
        return 0, MAX_ITEMS
    if isinstance(expr, Invert):
        low, high = bounds(expr.operand, names)
        return -high - 1, -low - 1
    if isinstance(expr, MinMax):
        found = [bounds(arg, names) for arg in expr.args]
        pick = min if expr.function == "min" else max
        return pick(b[0] for b in found), pick(b[1] for b in found)
    if isinstance(expr, Ceil):
        low, high = bounds(expr.numerator, names)
        below, above = _divide((-high, -low), bounds(expr.denominator, names))
        return -above, -below
    a, b = bounds(expr.left, names), bounds(expr.right, names)
    op = expr.op
    if op == "+":
        return _fits(a[0] + b[0], a[1] + b[1], expr)
    if op == "-":
        return _fits(a[0] - b[1], a[1] - b[0], expr)
    if op == "*":
        if _bits(a) + _bits(b) > MAX_BITS + 1:
            raise _too_large(expr)
        products = [x * y for x in a for y in b]
        return _fits(min(products), max(products), expr)
    if op == "/":
        return _divide(a, b)
    if op == "%":
        low, high = b
        return (low + 1 if low < 0 else 0), (high - 1 if high > 0 else 0)
    if op in ("&", "|"):
        top = 1 << max(_bits(a), _bits(b))
        return (-top if min(a[0], b[0]) < 0 else 0), top - 1
    low, high = max(b[0], 0), max(b[1], 0)  # a negative count fails: `fails` says so
    if op == "<<":
        if _bits(a) + high > MAX_BITS + 1:
            raise _too_large(expr)
        shifted = [x << y for x in a for y in (low, high)]
        return _fits(min(shifted), max(shifted), expr)
    shifted = [x >> min(y, MAX_BITS + 1) for x in a for y in (low, high)]
    return min(shifted), max(shifted)


def fails(expr: Expr) -> bool:
    """Whether the expression may have no value for some field values: a division (`/`, `%`, ceil) by anything but
    a constant other than 0, a shift by anything but a constant of at least 0. Decided from its form alone."""
    if isinstance(expr, BinOp):
        right = expr.right
        if expr.op in ("/", "%") and not (isinstance(right, Const) and right.value != 0):
            return True
        if expr.op in ("<<", ">>") and not (isinstance(right, Const) and right.value >= 0):
            return True
        return fails(expr.left) or fails(right)
    if isinstance(expr, Ceil):
        divisor = expr.denominator
        return not (isinstance(divisor, Const) and divisor.value != 0) or fails(expr.numerator) or fails(divisor)
    if isinstance(expr, Invert):
        return fails(expr.operand)
    if isinstance(expr, MinMax):
        return any(fails(arg) for arg in expr.args)
    return False


def _bits(b: Bounds) -> int:
    return max(b[0].bit_length(), b[1].bit_length())


def _fits(low: int, high: int, expr: Expr) -> Bounds:
    if max(low.bit_length(), high.bit_length()) > MAX_BITS:
        raise _too_large(expr)
    return low, high


def _too_large(expr: Expr) -> ExpressionError:
    shown = show(expr)
    shown = shown if len(shown) <= 60 else shown[:57] + "..."
    if next(names(expr), None) is None:
        return ExpressionError(f"{shown!r} is a number of more than {MAX_BITS} bits")
    return ExpressionError(f"{shown!r} can exceed {MAX_BITS} bits for some values of its fields (the wire's)")


def _divide(a: Bounds, b: Bounds) -> Bounds:
    """Bounds of a // b over the divisors other than 0 (floor division is monotonic in each operand on either side
    of 0, so the corners hold the extremes)."""
    divisors = [d for d in (b[0], min(b[1], -1), max(b[0], 1), b[1]) if d != 0 and b[0] <= d <= b[1]]
    if not divisors:
        return 0, 0  # always a division by 0: `fails` says so
    quotients = [x // d for x in a for d in divisors]
    return min(quotients), max(quotients)
