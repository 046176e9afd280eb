"""Sizes computed from fields, for the resolver and every backend: fixed sizes, content bounds, size terms."""

from __future__ import annotations

from serialspec.lang import expression
from serialspec.lang.expression import Expr
from serialspec.lang.model.fields import (
    Array,
    Bytes,
    Counted,
    Field,
    Group,
    List,
    Packed,
    Scalar,
    TableBlock,
    TableValue,
    Text,
    Varint,
)


def fixed_size(field: Field) -> int | None:
    if isinstance(field, Scalar) and field.bit_place is not None:  # the run's bytes, counted at its first field
        return field.bit_place.size if field.bit_place.first else 0
    if isinstance(field, Scalar):
        return field.type.size
    if isinstance(field, Array):
        return field.item.size * field.count
    if isinstance(field, Packed):
        return field.byte_size
    if isinstance(field, Bytes | Text):
        return field.size if isinstance(field.size, int) else None
    if isinstance(field, List):
        return field.byte_size(field.count) if isinstance(field.count, int) else None
    if isinstance(field, Group):
        if isinstance(field.count, int) and field.item_size is not None:
            return field.count * field.item_size
        return None
    if isinstance(field, TableBlock):
        return sum(e.type.size for e in field.entries)
    return None


def sum_sizes(fields: tuple[Field, ...]) -> int | None:
    total = 0
    for item in fields:
        size = fixed_size(item)
        if size is None:
            return None
        total += size
    return total


def content_bounds(fields: tuple[Field, ...]) -> tuple[int, int | None]:
    """Smallest and largest content size (None: unbounded) the fields allow."""
    low = 0
    high: int | None = 0
    by_name = {f.name: f for f in fields}
    for item in fields:
        size = fixed_size(item)
        if size is not None:
            low += size
            high = None if high is None else high + size
            continue
        if isinstance(item, List | Group | Bytes | Text) and isinstance(c := counted_by(item), Counted):
            if isinstance(item, List):
                high = None if high is None else high + item.byte_size(c.high)
            elif isinstance(item, Group):
                high = None if high is None or item.item_size is None else high + c.high * item.item_size
            else:
                high = None if high is None else high + c.high
        elif isinstance(item, Varint):  # one byte at least, as many as its widest value needs at most
            low += 1
            high = None if high is None else high + item.most_bytes
        elif isinstance(item, TableValue):
            sizes = [e.type.size for e in item.table.entries if not e.reserved]
            low += min(sizes)
            high = None if high is None else high + max(sizes)
        elif isinstance(item, Group) and isinstance(item.count, str) and item.count != "rest" and item.item_size:
            counter = by_name.get(item.count)
            most = int(counter.maximum) if isinstance(counter, Scalar) else None
            high = None if high is None or most is None else high + most * item.item_size
        elif isinstance(item, List) and (item.size or item.count not in ("", "rest")):
            counter = by_name.get(item.size or str(item.count))
            most = int(counter.maximum) if isinstance(counter, Scalar) else None
            high = None if high is None or most is None else high + (most if item.size else item.byte_size(most))
        elif isinstance(item, Text) and item.terminated:
            low += 1
            high = None
        elif isinstance(item, Bytes | Text) and isinstance(item.size, str) and item.size != "rest":
            counter = by_name.get(item.size)
            most = int(counter.maximum) if isinstance(counter, Scalar) else None
            high = None if high is None or most is None else high + most
        else:
            high = None
    return low, high


def counted_by(item: List | Group | Bytes | Text) -> int | str | Counted | None:
    """What gives the number of items (lists, groups) or bytes (bytes, text) of a field."""
    return item.count if isinstance(item, List | Group) else item.size


def linear(count: Counted) -> tuple[str, int, int] | None:
    """(field, times, plus) when the count is `times * field + plus` with times >= 1 and plus >= 0 (`n + 1`, `2 * n`),
    the forms a stream parser sizes a frame by; else None."""
    expr = count.expr
    plus = 0
    if isinstance(expr, expression.BinOp) and expr.op == "+":
        const, rest = (expr.left, expr.right) if isinstance(expr.left, expression.Const) else (expr.right, expr.left)
        if not isinstance(const, expression.Const) or const.value < 0:
            return None
        plus, expr = const.value, rest
    times = 1
    if isinstance(expr, expression.BinOp) and expr.op == "*":
        const, rest = (expr.left, expr.right) if isinstance(expr.left, expression.Const) else (expr.right, expr.left)
        if not isinstance(const, expression.Const) or const.value < 1:
            return None
        times, expr = const.value, rest
    return (expr.name, times, plus) if isinstance(expr, expression.Name) else None


def counted_term(item: List | Group | Bytes | Text) -> tuple[str, int, int] | None:
    """A field counted by an expression, as a stream parser sizes it: (field, bytes per unit of it, bytes more), for
    `k * n + m` items of a fixed size (`n + 1` u16s: 2 per n, 2 more); None for another expression or items of
    varying size (or bits)."""
    count = counted_by(item)
    assert isinstance(count, Counted)
    found = linear(count)
    unit = 1 if isinstance(item, Bytes | Text) else item.item_size if isinstance(item, Group) else None
    if isinstance(item, List) and item.item is not None:
        unit = item.item.size
    if found is None or unit is None:
        return None
    return found[0], found[1] * unit, found[2] * unit


def byte_size_expression(item: List) -> Expr | None:
    """The size in bytes of a list counted by a field, as an expression of that field (ceil(n / 8), n * 2)."""
    if not isinstance(item.count, str) or item.count in ("", "rest"):
        return None
    count = expression.Name(item.count)
    if item.item is None:
        return expression.Ceil(count, expression.Const(8))
    return count if item.item.size == 1 else expression.BinOp("*", expression.Const(item.item.size), count)


def size_terms(fields: tuple[Field, ...]) -> tuple[int, tuple[tuple[int, int, str, int], ...]] | None:
    """A content's size from its own leading fields, for frames that carry no length (Modbus RTU): fixed bytes
    plus, for each part sized by an earlier field at a fixed offset, (offset, size, byte order, bytes per unit).
    None when the size cannot be told that way (a part that takes the rest, a NUL-terminated text)."""
    fixed = 0
    terms: list[tuple[int, int, str, int]] = []
    offsets: dict[str, tuple[int, Scalar]] = {}
    offset: int | None = 0
    for item in fields:
        if isinstance(item, Scalar) and offset is not None:
            offsets[item.name] = (offset, item)
        size = fixed_size(item)
        if size is not None:
            fixed += size
            offset = None if offset is None else offset + size
            continue
        offset = None
        sizer: str = ""
        factor = 1
        if isinstance(item, List | Group | Bytes | Text) and isinstance(counted_by(item), Counted):
            term = counted_term(item)
            if term is None:
                return None
            sizer, factor, plus = term
            fixed += plus
        elif isinstance(item, List):
            wanted = byte_size_expression(item)
            same = next((name for name, (_, f) in offsets.items() if wanted is not None and f.value == wanted), "")
            sizer = item.size or same
            if not sizer and isinstance(item.count, str) and item.count not in ("", "rest") and item.item is not None:
                sizer, factor = item.count, item.item.size
        elif isinstance(item, Bytes | Text) and isinstance(item.size, str) and item.size != "rest":
            sizer = item.size
        elif isinstance(item, Group) and isinstance(item.count, str) and item.count != "rest" and item.item_size:
            sizer, factor = item.count, item.item_size
        if sizer not in offsets:
            return None
        where, scalar = offsets[sizer]
        terms.append((where, scalar.type.size, "big" if scalar.endian == ">" else "little", factor))
    return fixed, tuple(terms)


#: The most bytes a field or a content may have for certain (its fixed size, its least): more is a mistake in a
#: spec for a serial line, and no 32-bit C size_t or Python struct could hold it.
MAX_FIXED_SIZE = 2**31 - 1


def nul_ended(fields: tuple[Field, ...]) -> int | None:
    """The offset of a content's NUL-terminated text where fixed fields come before it and nothing after it
    (RoboClaw's version string, in a frame that carries no length): its size is then told by its NUL."""
    if not fields or not isinstance(fields[-1], Text) or not fields[-1].terminated:
        return None
    sizes = [fixed_size(item) for item in fields[:-1]]
    return None if any(size is None for size in sizes) else sum(size or 0 for size in sizes)


def takes_rest(field: Field) -> str | None:
    """The key by which a field takes the rest of its content (`size: rest`, `count: rest`), or None."""
    match field:
        case Bytes() | Text() if field.size == "rest":
            return "size"
        case List() | Group() if field.count == "rest":
            return "count"
        case _:
            return None


def rest_taker(fields: tuple[Field, ...]) -> tuple[Field, str] | None:
    """The field that takes the rest of the content and its key, where nothing else tells its size (a response's
    bytes `size_from` a request field are sized by the request)."""
    for field in fields:
        key = takes_rest(field)
        if key is not None and not (isinstance(field, Bytes) and field.size_from):
            return field, key
    return None


def sized_by_itself(fields: tuple[Field, ...]) -> bool:
    """Whether a content's size follows from its own bytes (a fixed size, a count at a fixed offset, a NUL): what
    sizes a frame that carries no length."""
    return size_terms(fields) is not None or nul_ended(fields) is not None
