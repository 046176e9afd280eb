"""Errors raised by generated code; each message is one line meant for a person."""

from __future__ import annotations


class SerialspecError(Exception):
    """Base of every error the runtime and generated code raise on purpose."""


class DecodeError(SerialspecError, ValueError):
    """Bytes that are not a valid frame or content: the message says why."""


class ChecksumError(DecodeError):
    """A frame whose checksum does not match its bytes."""


class EncodeError(SerialspecError, ValueError):
    """A message that cannot be encoded: unknown or missing field, wrong type."""


class RangeError(EncodeError):
    """A field value outside its allowed range, refused before any byte is written."""


def out_of_range(where: str, field: str, value: object, low: float, high: float) -> RangeError:
    return RangeError(f"{where}: {field} = {value!r} is outside its range {_number(low)}..{_number(high)}")


def content_size_error(where: str, got: int, low: int, high: int | None) -> DecodeError:
    if high == low:
        expected = f"{low}"
    elif high is None:
        expected = f"at least {low}"
    else:
        expected = f"{low}..{high}"
    return DecodeError(f"{where}: content is {got} bytes, expected {expected}")


def _number(value: float) -> str:
    return str(int(value)) if float(value).is_integer() else str(value)
