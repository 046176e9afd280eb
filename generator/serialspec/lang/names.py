"""Field names that are Python keywords: a field may be called what the protocol calls it (`class`, `from`,
`in`), and generated Python names its attribute (and client argument) after it with a trailing underscore
(`class_`). Everything else — the spec's references, `to_fields`/`from_fields` and JSON (`decode --json`), the
reference docs, Wireshark, C — keeps the spec's name; `python_view` gives the Python target a model with the
attribute names. (Keywords are never names of commands, tables, enums or frame elements, so a string equal to one
in the model names a field.)"""

from __future__ import annotations

import dataclasses
import keyword
from enum import Enum
from typing import Any, TypeVar

from serialspec.lang.model import Field, Group, Message, Protocol
from serialspec.runtime import values
from serialspec.runtime.message import spec_name as spec_name  # the inverse of python_name, for the runtime too
from serialspec.runtime.values import is_value

T = TypeVar("T")


def mangled(name: str) -> bool:
    """Whether a field of this name gets another name in generated Python."""
    return keyword.iskeyword(name)


def python_name(name: str) -> str:
    """The attribute (and argument) name of a field in generated Python: `class` -> `class_`."""
    return name + "_" if mangled(name) else name


def spec_key(name: str) -> str:
    """The field's spec name as a Python string literal (generated `to_fields`/`from_fields` keys, error messages)."""
    return repr(spec_name(name))


def _fields(fields: tuple[Field, ...]) -> set[str]:
    found = {f.name for f in fields}
    for f in fields:
        if isinstance(f, Group):
            found |= _fields(f.fields)
    return found


def python_view(protocol: Protocol) -> Protocol:
    """The model as the Python target names things: every field name that generated Python cannot use (and every
    reference to it) renamed by python_name. The protocol itself where no field needs it (the usual case)."""
    messages: tuple[Message, ...] = protocol.messages()
    renames = {name: python_name(name) for name in _fields(tuple(f for m in messages for f in m.fields))}
    renames = {old: new for old, new in renames.items() if old != new}
    if not renames:
        return protocol
    return _rewrite(protocol, renames, {})


# free text of the model's classes, never a reference (a unit may be `in`)
_FREE_TEXT = frozenset(
    {"description", "description_cn", "title", "title_cn", "unit", "source", "inferred", "optional", "broadcast"}
    | {"printed", "completed", "text", "text_cn", "notes", "correct", "matching_description"}
)


def _rewrite(value: T, renames: dict[str, str], seen: dict[int, Any]) -> T:
    """`value` with every string that names a renamed field replaced, in dataclasses, tuples, lists and dicts."""
    if isinstance(value, Enum):
        return value
    if isinstance(value, str):
        return renames.get(value, value)  # type: ignore[return-value]
    known = seen.get(id(value))
    if known is not None:
        return known  # type: ignore[no-any-return]
    result: Any = value
    if isinstance(value, tuple):
        items = tuple(_rewrite(item, renames, seen) for item in value)
        result = items if any(a is not b for a, b in zip(items, value, strict=True)) else value
    elif isinstance(value, list):
        result = [_rewrite(item, renames, seen) for item in value]
    elif isinstance(value, dict):
        result = {_rewrite(k, renames, seen): _rewrite(v, renames, seen) for k, v in value.items()}
    elif (is_value(value) or dataclasses.is_dataclass(value)) and not isinstance(value, type):
        kind: Any = values if is_value(value) else dataclasses  # the runtime's value classes, or dataclasses
        changes = {}
        for f in kind.fields(value):
            if f.name in _FREE_TEXT:
                continue
            old = getattr(value, f.name)
            new = _rewrite(old, renames, seen)
            if new is not old:
                changes[f.name] = new
        result = kind.replace(value, **changes) if changes else value
    seen[id(value)] = result
    return result  # type: ignore[no-any-return]
