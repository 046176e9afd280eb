"""Counts and sizes given by an expression: `count: max_moving_gate + 1` (HLK LD2410's engineering report: N + 1
energies after N), `size: length - 2`, `count: 2 * n`.

A count or size is a number, `rest`, the name of an earlier count field (which becomes derived: encode writes the
list's length, messages leave it out), or, here, an expression of the `value:` grammar (serialspec/lang/expression.py)
over earlier integer fields. Those fields STAY in the message as ordinary fields (LD2410's N means the farthest
gate, beyond the count): decode works the expression out to know how many items or bytes follow, refusing a
negative count in one line; encode refuses a list, group, bytes or text whose length differs from the expression's
value before writing a byte, naming the field and the count expected.

This module owns the feature: parsing and checking it (`parse`, `resolve`; `unsized` where a frame without a length
cannot be sized by it), the Python codec's source of its value and of its refusals (`python_value`, `python_reason`,
`python_encode_reason`), construct's count (`construct_count`), the simulator's blank (`python_blank`, runtime
CountedBlank), the dissector's Lua (`LUA`, `lua_function`, `lua_refusal`). The model holds it as `Counted`
(model/fields.py), the stream parsers' sizing as a linear count (model/sizes.py `linear`); the C renders it with the
C backend's expression renderer (backends/c/emit.py count_size, check_fields).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any, assert_never

from serialspec.lang import expression
from serialspec.lang.model.fields import Bytes, Counted, Field, Group, List, Scalar, Text, Varint
from serialspec.lang.model.sizes import counted_term, sized_by_itself


class CountError(ValueError):
    """A count or size expression a spec may not have; the message is one spec error line."""


def parse(value: str) -> str | expression.Expr:
    """A count or size given as text: `rest` or a field name as it is, else the expression (CountError if it is
    none)."""
    try:
        parsed = expression.parse(value)
    except expression.ExpressionError as exc:
        raise CountError(f"{exc} (a count or size is a number, `rest`, a field name or an expression)") from None
    return parsed.name if isinstance(parsed, expression.Name) else parsed


def resolve(expr: expression.Expr, earlier: Sequence[Field], later: Iterable[str]) -> Counted:
    """The count of an expression over earlier fields: each named field an earlier plain integer field of the same
    content, kept in the message; its values bounded (the expression limits, and at least one value not negative)."""
    shown = expression.show(expr)
    by_name = {f.name: f for f in earlier}
    bounds: dict[str, expression.Bounds] = {}
    for node in expression.nodes(expr):
        if isinstance(node, expression.Length):
            raise CountError(f"{shown!r}: a count names integer fields, not len() (a list's length is its count)")
        if not isinstance(node, expression.Name):
            continue
        field = by_name.get(node.name)
        if field is None:
            where = "a later field" if node.name in later else "unknown field"
            raise CountError(f"{where} {node.name!r} in {shown!r}: a count or size names earlier integer fields")
        if isinstance(field, Text):
            raise CountError(f"{node.name!r} in {shown!r} is text: a count or size names earlier integer fields")
        if isinstance(field, Varint):
            raise CountError(f"{node.name!r} in {shown!r} is a varint: a count or size names fixed-size integer fields")
        if not isinstance(field, Scalar) or field.type.is_float:
            raise CountError(f"{node.name!r} in {shown!r} is not an integer field")
        plain = not (field.bits or field.scale is not None or field.offset is not None or field.flags)
        if field.hidden or not plain:
            why = "constant or derived" if field.hidden else "scaled, flags or bit fields"
            raise CountError(f"{node.name!r} in {shown!r} is {why}: a count names plain integer fields of the message")
        bounds[node.name] = (int(field.type.minimum), int(field.type.maximum))
    if not bounds:
        raise CountError(f"{shown!r} names no field: give the number itself")
    if expression.fails(expr):
        raise CountError(
            f"{shown!r} may divide by 0 or shift by a negative count: a count divides and shifts by numbers"
        )
    try:
        low, high = expression.bounds(expr, bounds)
    except expression.ExpressionError as exc:
        raise CountError(str(exc)) from None
    if high < 0:
        raise CountError(f"{shown!r} is always negative ({low}..{high}): no count")
    return Counted(expr, low, high)


def counted(field: Field) -> Counted | None:
    """The field's count or size when an expression gives it."""
    match field:
        case List(count=Counted() as c) | Group(count=Counted() as c) | Bytes(size=Counted() as c):
            return c
        case Text(size=Counted() as c):
            return c
    return None


def unit(field: Field) -> str:
    """What the count counts: items or bytes."""
    return "items" if isinstance(field, List | Group) else "bytes"


def python_value(count: Counted, name: Any) -> str:
    """Python source of the count's value; `name(field)` gives the source of a field's value."""
    return expression.render(count.expr, name)


def python_reason(field: Field, count: Counted, local: str) -> str:
    """The text (an f-string's, the count in `local`) of a decoded count that is negative."""
    shown = expression.show(count.expr).replace("{", "{{").replace("}", "}}")
    return f"{field.name} has {shown} = {{{local}}} {unit(field)}: a count cannot be negative"


def python_encode_reason(field: Field, count: Counted, expected: str, got: str) -> str:
    """The text (an f-string's) of a list whose length is not its count."""
    shown = expression.show(count.expr).replace("{", "{{").replace("}", "}}")
    return f"{field.name} needs {shown} = {{{expected}}} {unit(field)}, got {{{got}}}"


def construct_count(count: Counted) -> str:
    """A construct count or size (a function of the context) of the expression."""
    return f"lambda ctx: {expression.render(count.expr, lambda name: f'ctx.{name}')}"


def python_blank(count: Counted, item: str) -> str:
    """A simulator's blank of a counted field (runtime/device CountedBlank): as many `item`s as the reply's earlier
    values make the count."""
    return f"CountedBlank(lambda reply: {expression.render(count.expr, lambda name: f'reply[{name!r}]')}, {item})"


def names(count: Counted) -> list[str]:
    """The fields the count names."""
    return sorted(set(expression.names(count.expr)))


def least(count: Counted, values: dict[str, int]) -> int:
    """The count for these values of its fields (0 where negative): a blank group item's."""
    return max(expression.evaluate(count.expr, values), 0)


def unsized(fields: Sequence[Field]) -> tuple[str, str, str] | None:
    """Where a frame with no length, trailer or stuffing is sized by its content's own bytes: the first count by
    an expression the stream parser cannot size it by (not `k * field + m` items of a fixed size, model/sizes.py
    counted_term) where the content does not size itself, as (field, key, the one line saying so); else None."""
    if sized_by_itself(tuple(fields)):
        return None
    for field in fields:
        count = counted(field)
        if isinstance(field, List | Group | Bytes | Text) and count is not None and counted_term(field) is None:
            key = "count" if isinstance(field, List | Group) else "size"
            return (
                field.name,
                key,
                (
                    f"{expression.show(count.expr)!r} cannot size a frame that has no length element (a stream parser "
                    "sizes such frames by a count `k * field + m` of items of one size before them)"
                ),
            )
    return None


# The dissector's reading of a count by expression (its `count` or `size` a function of the fields read before it)
LUA = """-- a count or size given by an expression of the fields read before it (lang/counts.py): refused when negative
local function counted(f, count, scope)
  local n = count(scope)
  if n < 0 then error(string.format("%s: a negative count (%d)", f.name, n), 0) end
  return n
end"""


def lua_function(count: Counted) -> str | None:
    """A Lua function of the dissector's scope (field name -> value) giving the count; None where the expression has
    bit operators (Lua 5.2 has none: the dissector refuses it)."""
    body = _lua(count.expr)
    return None if body is None else f"function(s) return {body} end"


def _lua(expr: expression.Expr) -> str | None:
    match expr:
        case expression.Const():
            return str(expr.value)
        case expression.Name():
            return f"s[{expr.name!r}]"
        case expression.BinOp() if expr.op in ("+", "-", "*", "/", "%"):
            left, right = _lua(expr.left), _lua(expr.right)
            if left is None or right is None:
                return None
            return f"math.floor({left} / {right})" if expr.op == "/" else f"({left} {expr.op} {right})"
        case expression.Ceil():
            top, bottom = _lua(expr.numerator), _lua(expr.denominator)
            return None if top is None or bottom is None else f"math.ceil({top} / {bottom})"
        case expression.MinMax():
            args = [_lua(arg) for arg in expr.args]
            return None if None in args else f"math.{expr.function}({', '.join(a or '' for a in args)})"
        case expression.BinOp() | expression.Invert() | expression.Length():
            return None
        case _:
            assert_never(expr)


def lua_refusal(fields: Iterable[Field]) -> str | None:
    """The one line the Wireshark dissector says for a count by an expression with bit operators, or None."""
    for field in fields:
        count = counted(field)
        if count is not None and lua_function(count) is None:
            key = "count" if isinstance(field, List | Group) else "size"
            return f"a {key} by an expression with bit operators (`{field.name}`: `{key}: {count}`): Lua 5.2 has none"
        if isinstance(field, Group):
            inner = lua_refusal(field.fields)
            if inner is not None:
                return inner
    return None
