"""The rewrites that make the statements the Python backend writes fast (backends/python/ir.py): each takes
statements and gives statements, and none reads generated source.

- content decoders: fold_last_size_check (one comparison on the way of an intact frame), fuse_unpack (an unpack
  that is the message, a lone byte read by indexing);
- encoders: deferred_item_checks (a list's range loop only when struct.pack fails), read_fields_once (each field
  read more than once read into a local first; field_read writes the reads it fills).
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import replace

from serialspec.backends.python.ir import (
    Advance,
    Block,
    Code,
    If,
    ItemsCheck,
    LeftOver,
    Loop,
    Needs,
    Raise,
    ReturnNew,
    Statement,
    Try,
    Unpack,
    reads_cursor,
    single_line,
    walk,
)


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
    if not single_line(read):
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
        case Try():
            body, handler = tuple(_indexed(s) for s in statement.body), tuple(_indexed(s) for s in statement.handler)
            return replace(statement, body=body, handler=handler)
        case _:
            return statement


def deferred_item_checks(body: Block) -> Block:
    """An encoder's statements with each deferrable items check (ItemsCheck) run only when the pack of its list
    fails: the list's numbers span their type's whole range, so struct.pack refuses exactly what the loop would, but
    True and False (which it takes as numbers: looked for first, the cheaper loop). The full loop then finds the item
    at fault and raises what it raised before; a failure it does not explain (a float) goes on as struct's error. A
    check whose list is packed inside a block, or after one, keeps its loop where it was."""
    for index, check in enumerate(body):
        if not (isinstance(check, ItemsCheck) and check.deferrable):
            continue
        rest = body[:index] + body[index + 1 :]
        packs = next((s for s in walk(rest[index:]) if isinstance(s, Code) and check.items in s.lists), None)
        at = next((i for i, s in enumerate(rest) if i >= index and s is packs), None)
        if at is None or not all(single_line(s) for s in rest[index:at]):
            return deferred_item_checks([*body[:index], replace(check, deferrable=False), *body[index + 1 :]])
        refused = "struct.pack takes True and False as numbers: refused below"
        bools = If(f"{check.item}.__class__ is bool", (Raise("TypeError"),), comment=refused)
        block = Try(
            (Loop(f"for {check.item} in {check.items}", (bools,), variable=check.item), rest[at]),
            "(TypeError, struct.error)",
            (replace(check, deferrable=False, chained=True), Raise("")),
            comment="the item at fault, looked for only when the pack fails",
        )
        return deferred_item_checks([*rest[:at], block, *rest[at + 1 :]])
    return body


# A field read in an encoder's text is a hole, `⟨var.name⟩`, until read_fields_once fills it: with `var.name`, or
# with a local `var_name` that reads it once up front. The marks are characters no Python the backend writes holds
# (names are identifiers; spec text reaches code only through repr() of ASCII keys and names).
_OPEN, _CLOSE = "\u27e8", "\u27e9"
_HOLE = re.compile(f"{_OPEN}[^{_CLOSE}]*{_CLOSE}")


def field_read(var: str, name: str) -> str:
    """The expression of a read of field `name` of the record in `var` (see read_fields_once)."""
    return f"{_OPEN}{var}.{name}{_CLOSE}"


def attribute_reads(text: str) -> str:
    """A text with every field read a plain attribute read (code outside an encoder's statements)."""
    return text.replace(_OPEN, "").replace(_CLOSE, "")


def read_fields_once(body: Block, names: list[str]) -> Block:
    """An encoder's statements with each field of the message `m` that they read more than once read once, into a
    local `m_<field>` first (of `names`, in their order), and likewise each field of a `for` loop's item
    (`item_<field>`, in the order first read): a range check and the pack read a field two or three times, and a
    local costs less than an attribute (a record's fields are read through a descriptor, ~15 ns each). Every other
    read is the attribute."""
    return [_filled(s, {}) for s in _loops_read_once(_read_once(body, "m", names))]


def _read_once(body: Block, var: str, names: list[str] | None) -> Block:
    reads = Counter(name for s in body for text in _texts(s) for v, name in _holes(text) if v == var)
    again = [name for name in (names if names is not None else reads) if reads[name] > 1]
    if not again:
        return body
    local = {field_read(var, name): f"{var}_{name}" for name in again}
    return [*(Code(f"{var}_{name} = {var}.{name}") for name in again), *(_filled(s, local) for s in body)]


def _loops_read_once(body: Block) -> Block:
    out: Block = []
    for statement in body:
        if isinstance(statement, Loop) and statement.variable:
            inner = _read_once(list(statement.body), statement.variable, None)
            statement = replace(statement, body=tuple(_loops_read_once(inner)))
        elif isinstance(statement, If | Loop):
            statement = replace(statement, body=tuple(_loops_read_once(list(statement.body))))
        elif isinstance(statement, Try):
            body_, handler = _loops_read_once(list(statement.body)), _loops_read_once(list(statement.handler))
            statement = replace(statement, body=tuple(body_), handler=tuple(handler))
        out.append(statement)
    return out


def _holes(text: str) -> list[tuple[str, str]]:
    """The field reads (var, name) in a text, in order."""
    found = []
    for piece in text.split(_OPEN)[1:]:
        var, _, name = piece.partition(_CLOSE)[0].partition(".")
        found.append((var, name))
    return found


def _texts(statement: Statement) -> list[str]:
    """A statement's texts in source order, its body's included."""
    match statement:
        case Code() | Raise():
            return [statement.text if isinstance(statement, Code) else statement.error]
        case If():
            return [statement.condition, *(t for s in statement.body for t in _texts(s))]
        case Loop():
            return [statement.header, *(t for s in statement.body for t in _texts(s))]
        case ItemsCheck():
            return [statement.items, statement.error]
        case Try():
            return [t for s in (*statement.body, *statement.handler) for t in _texts(s)]
        case _:
            return []  # content decoders' statements: no field reads


def _filled(statement: Statement, local: dict[str, str]) -> Statement:
    """A statement with the holes in `local` filled with their locals, and any others with the attribute read."""

    def fill(text: str) -> str:
        if _OPEN not in text:
            return text
        if not local:  # the last pass: every hole left is an attribute read
            return text.replace(_OPEN, "").replace(_CLOSE, "")
        return _HOLE.sub(lambda hole: local.get(hole[0], hole[0]), text)  # one pass, whatever the holes

    match statement:
        case Code():
            return replace(statement, text=fill(statement.text))
        case Raise():
            return replace(statement, error=fill(statement.error))
        case If():
            return replace(statement, condition=fill(statement.condition), body=_filled_all(statement.body, local))
        case Loop():
            return replace(statement, header=fill(statement.header), body=_filled_all(statement.body, local))
        case ItemsCheck():
            return replace(statement, items=fill(statement.items), error=fill(statement.error))
        case Try():
            body, handler = _filled_all(statement.body, local), _filled_all(statement.handler, local)
            return replace(statement, body=body, handler=handler)
        case _:
            return statement


def _filled_all(statements: tuple[Statement, ...], local: dict[str, str]) -> tuple[Statement, ...]:
    return tuple(_filled(s, local) for s in statements)


def content_unpacked(body: Block) -> tuple[str, str] | None:
    """(class, struct) where a decoder's statements past its size check are one struct's unpack of the content as
    the message, as it is: `return _new(Cls, _S.unpack_from(buf, o))`; None for others."""
    fused = fuse_unpack(body)
    last = fused[0] if len(fused) == 1 else None
    if isinstance(last, ReturnNew) and last.unpacked is not None and last.unpacked.at == "o":
        return last.cls, last.unpacked.struct
    return None
