"""Hypothesis strategies for valid field values of any message, built from the spec model."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from hypothesis import strategies as st
from serialspec.lang import counts, expression
from serialspec.lang.model import (
    Array,
    BitField,
    Bytes,
    Direction,
    Field,
    Group,
    List,
    Message,
    Packed,
    Protocol,
    Scalar,
    ScalarType,
    TableBlock,
    TableValue,
    Text,
    Varint,
)

MAX_ITEMS = 4  # items per group: enough to cover counts, small enough to fit a length byte
MAX_LIST = 12  # items per list of varying count
TEXT = st.text(st.characters(min_codepoint=0x20, max_codepoint=0x7E), max_size=12)  # no NUL: it ends a cstring


def number(scalar: ScalarType, low: float, high: float) -> st.SearchStrategy[Any]:
    if scalar.is_float:
        return st.floats(low, high, width=scalar.size * 8, allow_nan=False, allow_infinity=False)
    return st.integers(int(low), int(high))


def bit_values(bit: BitField) -> st.SearchStrategy[int]:
    """A bit field's values: its constant alone where it has one."""
    return st.just(bit.const) if bit.const is not None else st.integers(0, bit.mask)


def scalar_value(f: Scalar) -> st.SearchStrategy[Any]:
    if f.bits:
        return st.fixed_dictionaries({b.name: bit_values(b) for b in f.bits})
    return number(f.type, f.minimum, f.maximum)


def allowed(name: str, scope: Mapping[str, Field], low: int, high: int) -> tuple[int, int]:
    """low..high narrowed to what the count or size field `name` may hold (its `range:`, else its type's): a drawn
    size outside it would be refused on encode (tests/test_strict_encode.py holds that apart). A range wholly above
    `high` gives its smallest value."""
    f = scope.get(name)
    if not isinstance(f, Scalar):
        return low, high
    smallest, largest = max(0, int(f.minimum)), int(f.maximum)
    if smallest > high:
        return smallest, smallest
    return max(low, smallest), min(high, largest)


def items_within(f: List, scope: Mapping[str, Field], most: int) -> tuple[int, int]:
    """How many items of a list sized in bytes (`size:` a field) its size field's range allows, at most `most`."""
    assert f.item is not None
    low, high = allowed(f.size, scope, 0, most * f.item.size)
    return -(-low // f.item.size), high // f.item.size


def fields_values(
    fields: tuple[Field, ...], rest_budget: int, outer: Mapping[str, Field] | None = None
) -> st.SearchStrategy[dict[str, Any]]:
    """Values of `fields`; sizes and counts given by a field stay within that field's range (`outer`: the fields
    of the enclosing message, for a group's items sized by one of them)."""
    return _fields_values(fields, rest_budget, {**(outer or {}), **{f.name: f for f in fields}})


# Decorated once, here: hypothesis reads a composite function's source when it decorates it (30 ms a time), which
# a decorator inside fields_values paid for every message a test drew
@st.composite
def _fields_values(
    draw: st.DrawFn, fields: tuple[Field, ...], rest_budget: int, scope: Mapping[str, Field]
) -> dict[str, Any]:
    values: dict[str, Any] = {}
    sizes: dict[str, int] = {}
    for f in fields:
        counted = counts.counted(f)
        if counted is not None:  # as many items or bytes as the expression makes of the values drawn before it
            values[f.name] = draw(counted_value(f, expression.evaluate(counted.expr, values), scope))
        elif isinstance(f, Scalar):
            if f.hidden:
                continue
            values[f.name] = draw(scalar_value(f))
        elif isinstance(f, Varint):  # the range's ends too: the most bytes, the sign's largest magnitude
            values[f.name] = draw(st.one_of(st.sampled_from((f.minimum, f.maximum)), st.integers(f.minimum, f.maximum)))
        elif isinstance(f, Array):
            values[f.name] = draw(st.lists(number(f.item, f.minimum, f.maximum), min_size=f.count, max_size=f.count))
        elif isinstance(f, Packed):
            items = st.integers(int(f.minimum), int(f.maximum))
            values[f.name] = draw(st.lists(items, min_size=f.count, max_size=f.count))
        elif isinstance(f, Bytes):
            if isinstance(f.size, int):
                size = f.size
            elif f.size == "rest":
                size = draw(st.integers(0, rest_budget))
            else:
                size = sizes.setdefault(f.size, draw(st.integers(*allowed(f.size, scope, 0, 6))))
            values[f.name] = draw(st.binary(min_size=size, max_size=size)).hex(" ")
        elif isinstance(f, List):
            values[f.name] = draw(list_value(f, fields, scope))
        elif isinstance(f, Text):
            if f.seven_bit:  # 14-bit characters (any, but the surrogates), two wire bytes each
                chars = st.characters(max_codepoint=0x3FFF, exclude_categories=("Cs",))
                least, most = (f.size // 2, f.size // 2) if isinstance(f.size, int) else (0, 6)
                values[f.name] = draw(st.text(chars, min_size=least, max_size=most))
            elif isinstance(f.size, int) and f.pad is not None:  # shorter text, never ending in the pad byte
                text = draw(st.text(st.characters(min_codepoint=0x20, max_codepoint=0x7E), max_size=f.size))
                values[f.name] = text.rstrip(chr(f.pad))
            elif isinstance(f.size, int):
                values[f.name] = draw(
                    st.text(st.characters(min_codepoint=0x20, max_codepoint=0x7E), min_size=f.size, max_size=f.size)
                )
            elif isinstance(f.size, str) and f.size != "rest":  # sized by a field: within its range
                size = sizes.setdefault(f.size, draw(st.integers(*allowed(f.size, scope, 0, 12))))
                values[f.name] = draw(
                    st.text(st.characters(min_codepoint=0x20, max_codepoint=0x7E), min_size=size, max_size=size)
                )
            else:
                values[f.name] = draw(TEXT)
        elif isinstance(f, Group):
            if isinstance(f.count, int):
                count = f.count
            else:
                most = MAX_ITEMS if f.count == "rest" else allowed(f.count, scope, 0, MAX_ITEMS)[1]
                least = 0 if f.count == "rest" else allowed(f.count, scope, 0, MAX_ITEMS)[0]
                count = draw(st.integers(least, most))
            item = fields_values(f.fields, 0, scope)
            items = []
            for _ in range(count):
                items.append(draw(item))
            # bytes sized by an outer field must have one size in every item
            sized = [i.name for i in f.fields if isinstance(i, Bytes) and isinstance(i.size, str) and i.size != "rest"]
            for name in sized:
                for it in items[1:]:
                    it[name] = items[0][name] if len(it[name]) != len(items[0][name]) else it[name]
            values[f.name] = items
        elif isinstance(f, TableValue):
            entries = [e for e in f.table.entries if not e.reserved]
            key = values.get(f.key)
            entry = f.table.entry(key) if isinstance(key, int) else None
            if entry is None or entry.reserved:
                entry = draw(st.sampled_from(entries))
                values[f.key] = entry.key
            values[f.name] = draw(number(entry.type, entry.minimum, entry.maximum))
        elif isinstance(f, TableBlock):
            values[f.name] = draw(
                st.fixed_dictionaries({e.name: number(e.type, e.minimum, e.maximum) for e in f.entries})
            )
    return values


def counted_value(f: Field, n: int, scope: Mapping[str, Field]) -> st.SearchStrategy[Any]:
    """A value of `n` items (a list, a group) or bytes (bytes, text): a field counted by an expression."""
    chars = st.characters(min_codepoint=0x20, max_codepoint=0x7E)
    match f:
        case List():
            item = st.booleans() if f.item is None else number(f.item, f.minimum, f.maximum)
            return st.lists(item, min_size=n, max_size=n)
        case Group():
            return st.lists(fields_values(f.fields, 0, scope), min_size=n, max_size=n)
        case Bytes():
            return st.binary(min_size=n, max_size=n).map(lambda b: b.hex(" "))
        case Text() if f.seven_bit:
            return st.text(chars, min_size=n // 2, max_size=n // 2)
        case Text():
            return st.text(chars, min_size=n, max_size=n)
    raise AssertionError(f"{f.name} is not counted")


def list_value(
    f: List, siblings: tuple[Field, ...], scope: Mapping[str, Field] | None = None
) -> st.SearchStrategy[list[Any]]:
    """Items of a list of varying count: as many as its count field's range allows (a few), or for a list sized in
    bytes as many as its size field's range allows; a list sized in bytes holds whole bytes of bits (decoding gives
    every bit of them back)."""
    scope = {**(scope or {}), **{c.name: c for c in siblings}}
    low, high = 0, MAX_LIST
    if isinstance(f.count, int):
        low = high = f.count
    elif f.count and f.count != "rest":
        low, high = allowed(f.count, scope, low, high)
    elif f.size and f.item is not None:
        low, high = items_within(f, scope, MAX_LIST)
    item = st.booleans() if f.item is None else number(f.item, f.minimum, f.maximum)
    if f.item is None and (f.size or f.count == "rest"):
        least, most = allowed(f.size, scope, 0, MAX_LIST // 8 + 1) if f.size else (0, MAX_LIST // 8 + 1)
        return st.integers(least, most).flatmap(lambda n: st.lists(item, min_size=8 * n, max_size=8 * n))
    return st.lists(item, min_size=low, max_size=high)


def message_fields(protocol: Protocol, message: Message) -> st.SearchStrategy[dict[str, Any]]:
    frame = protocol.layout(message).value_elements
    partial = protocol.framing.partial_values(message.direction)  # None too: sent in a layout without it
    frame_values = st.fixed_dictionaries(
        {
            e.name: st.fixed_dictionaries({b.name: bit_values(b) for b in e.bits})
            if e.bits
            else st.none() | st.integers(int(e.minimum), int(e.maximum))
            if e.name in partial
            else st.integers(int(e.minimum), int(e.maximum))
            for e in frame
            if e.type is not None
        }
        | refused_code(protocol, message)
    )
    error = protocol.error_reply
    if error is not None and error.status and message.direction == Direction.RESPONSE:
        # told by the status (`error_bits`): the error reply has one of them set, every other reply none
        element = next(e for e in frame if e.name == error.status)
        bits, refusing = error.bits, message.error_reply
        frame_values = frame_values.map(
            lambda values: {**values, element.name: status_told(element, values[element.name], bits, refusing)}
        )
    drawn = st.tuples(frame_values, fields_values(message.fields, 8)).map(lambda pair: {**pair[0], **pair[1]})
    optional = protocol.framing.layouts[message.direction].optional
    return drawn.flatmap(lambda fields: optional_values(fields, optional)) if optional else drawn


def status_told(element: Any, value: Any, bits: int, error_reply: bool) -> Any:
    """A status drawn, its error `bits` cleared for a reply; for the error reply, the lowest set where none is."""
    wire = sum((int(value[b.name]) & b.mask) << b.low for b in element.bits) if element.bits else int(value)
    if not error_reply:
        wire &= ~bits
    elif not wire & bits:
        wire |= bits & -bits
    return {b.name: wire >> b.low & b.mask for b in element.bits} if element.bits else wire


def optional_values(fields: dict[str, Any], optional: tuple[Any, ...]) -> st.SearchStrategy[dict[str, Any]]:
    """The bytes of optional frame elements (`present_if`), as hex or None: sent as a value flag element says, or
    at random where the flag is a constant (encode sets its bit)."""
    values: dict[str, st.SearchStrategy[Any]] = {}
    for e in optional:
        sent = st.binary(min_size=e.size, max_size=e.size).map(lambda b: b.hex(" "))
        flag, mask = e.present_if
        if flag in fields:
            values[e.name] = sent if fields[flag] & mask else st.none()
        else:
            values[e.name] = st.one_of(st.none(), sent)
    return st.fixed_dictionaries(values).map(lambda extra: {**fields, **extra})


def refused_code(protocol: Protocol, message: Message) -> dict[str, st.SearchStrategy[int]]:
    """An error reply also carries the code of the request it refuses (any code without the error flag; under an
    error header any code of the command element)."""
    error = protocol.error_reply
    if not message.error_reply or error is None:
        return {}
    element = next(e for e in protocol.layout(message).elements if e.name == error.element)
    return {error.element: st.integers(0, error.flag - 1 if error.flag else int(element.maximum))}
