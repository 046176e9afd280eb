"""BYTE_VALUES for generated codecs, and the checksum functions under the names packages generated before the
checksum registry import: each algorithm's runtime function now lives in its module of serialspec/checksums/
(shipped in the runtime wheel too), where generated code imports it from."""

from __future__ import annotations

from serialspec.runtime import import_module

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any

# Each byte value as a one-byte bytes object: appending a 1-byte checksum is an index, not a bytes((x,)) call.
BYTE_VALUES: tuple[bytes, ...] = tuple(bytes((value,)) for value in range(256))

_MOVED = {
    "crc_function": "crc",
    "crc_hqx": "crc",
    "crc_in_one_call": "crc",
    "crc_table": "crc",
    "sum_function": "sum",
    "xor_function": "xor",
}


def __getattr__(name: str) -> Any:
    # imported when first asked for: a codec that imports BYTE_VALUES does not pay for every algorithm's module
    if name in _MOVED:
        return getattr(import_module(f"serialspec.checksums.{_MOVED[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
