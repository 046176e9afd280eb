"""Integer expressions in specs: derived values such as Modbus `byte_count = 2 * quantity` or
`ceil(quantity / 8)`.

An expression is parsed once, when the spec is resolved, into a small immutable tree; emitters render the tree
(never the spec's text) and the runtime may evaluate it. The language is deliberately small: integers, the names
of earlier fields, `len(list_field)`, `+ - * / % & | << >>`, `ceil(a / b)`, `min`, `max` and parentheses.
`/` is integer division (exact division is what specs mean; a decoder recomputes every derived value and
refuses a frame whose value differs, so an inexact division cannot pass unnoticed); `ceil(a / b)` rounds up.
"""

from __future__ import annotations

import ast
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
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError:
        raise ExpressionError(f"{text!r} is not an expression") from None
    return _convert(tree.body, text)


def _convert(node: ast.expr, text: str) -> Expr:
    if isinstance(node, ast.Constant) and isinstance(node.value, int) and not isinstance(node.value, bool):
        return Const(node.value)
    if isinstance(node, ast.Name):
        return Name(node.id)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        return BinOp("-", Const(0), _convert(node.operand, text))
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Invert):
        return Invert(_convert(node.operand, text))
    if isinstance(node, ast.BinOp) and type(node.op) in _OPERATORS:
        return BinOp(_OPERATORS[type(node.op)], _convert(node.left, text), _convert(node.right, text))
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and not node.keywords:
        function, args = node.func.id, node.args
        if function == "len" and len(args) == 1 and isinstance(args[0], ast.Name):
            return Length(args[0].id)
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
    if isinstance(expr, BinOp):
        return f"{_operand(expr.left)} {expr.op} {_operand(expr.right)}"
    if isinstance(expr, Invert):
        return f"~{_operand(expr.operand)}"
    if isinstance(expr, Ceil):
        return f"ceil({_operand(expr.numerator)} / {_operand(expr.denominator)})"
    return f"{expr.function}({', '.join(show(arg) for arg in expr.args)})"


def _operand(expr: Expr) -> str:
    return f"({show(expr)})" if isinstance(expr, BinOp) else show(expr)


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
