"""Building messages from plain data (JSON objects), with errors that name the field at fault."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from serialspec.runtime.errors import EncodeError
from serialspec.runtime.hexbytes import parse_hex


def check_keys(data: Mapping[str, Any], known: Iterable[str], optional: Iterable[str], where: str) -> None:
    """Refuse unknown keys; `optional` keys (derived values such as counts) may be given and are ignored."""
    allowed = set(known) | set(optional)
    for key in data:
        if key not in allowed:
            raise EncodeError(f"{where}: unknown field {key!r} (expected {', '.join(known) or 'no fields'})")


def get(data: Mapping[str, Any], name: str, where: str) -> Any:
    try:
        return data[name]
    except KeyError:
        raise EncodeError(f"{where}: missing field {name!r}") from None


def mapping(value: Any, name: str, where: str) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise EncodeError(f"{where}: {name} must be an object, got {value!r}")
    return value


def as_bytes(value: Any, name: str, where: str) -> bytes:
    if isinstance(value, bytes | bytearray):
        return bytes(value)
    if isinstance(value, str):
        if not value.strip():
            return b""
        try:
            return parse_hex(value)
        except ValueError as exc:
            raise EncodeError(f"{where}: {name}: {exc}") from None
    if isinstance(value, list) and all(isinstance(v, int) and 0 <= v <= 255 for v in value):
        return bytes(value)
    raise EncodeError(f"{where}: {name} must be hex text or a list of byte values, got {value!r}")
