"""construct pieces the generated structs need beyond construct's own."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from construct import Adapter, Bytes, Check, Container, ExplicitError, GreedyBytes, Rebuild, evaluate

from serialspec.runtime.packing import pack_ints, unpack_ints


def derived(name: str, compute: Callable[[Any], int]) -> Any:
    """construct's Check, placed after every field, that the field `name` derived by a `value:` expression holds what
    the expression gives for the others (as the codec checks on decode; Modbus byte_count = 2 * count). An expression
    with no value for those fields (a division by 0, a negative shift) does not hold."""

    def holds(context: Any) -> bool:
        try:
            return bool(context[name] == compute(context))
        except (ZeroDivisionError, ValueError):
            return False

    return Check(holds)


def valued(name: str, shown: str, compute: Callable[[Any], int]) -> Callable[[Any], int]:
    """The value a Rebuild of the field `name` computes by its `value:` expression (`shown`), where an expression
    with no value for the fields given (a division by 0, a negative shift) refuses to build in one line."""

    def value(context: Any) -> int:
        try:
            return compute(context)
        except (ZeroDivisionError, ValueError):
            raise ExplicitError(f"{name}: {shown} has no value here (a division by 0 or a negative shift)") from None

    return value


class Rebuilt(Rebuild):  # type: ignore[misc, type-arg, unused-ignore]
    """construct's Rebuild of a value encode computes (a count, a size, a `value:` expression), as the codec treats
    it: a value given for it on build is refused unless it is the computed one (never silently replaced), and a
    value outside the field's declared range (`low`..`high`, narrower than its type's) is refused on build and on
    parse."""

    def __init__(self, subcon: Any, func: Any, low: int | None = None, high: int | None = None) -> None:
        super().__init__(subcon, func)
        self.low, self.high = low, high

    def _parse(self, stream: Any, context: Any, path: Any) -> Any:
        subcon: Any = self.subcon
        value = subcon._parsereport(stream, context, path)
        if self.low is not None and self.high is not None and not self.low <= value <= self.high:
            raise ExplicitError(f"{path}: {value} is outside its range {self.low}..{self.high}")
        return value

    def _build(self, obj: Any, stream: Any, context: Any, path: Any) -> Any:
        computed = evaluate(self.func, context)
        if obj is not None and obj != computed:
            raise ExplicitError(f"{path}: given as {obj}, but it is computed: {computed} (leave it out)")
        if self.low is not None and self.high is not None and not self.low <= computed <= self.high:
            raise ExplicitError(f"{path}: {computed} is outside its range {self.low}..{self.high}")
        subcon: Any = self.subcon
        return subcon._build(computed, stream, context, path)


class SignMagnitude(Adapter):  # type: ignore[misc, type-arg, unused-ignore]
    """An unsigned integer whose top bit is the sign and the rest the magnitude (FEETECH position/speed)."""

    def __init__(self, subcon: Any, bits: int) -> None:
        super().__init__(subcon)
        self.sign = 1 << (bits - 1)

    def _decode(self, obj: int, context: Any, path: Any) -> int:
        return -(obj & (self.sign - 1)) if obj & self.sign else obj

    def _encode(self, obj: int, context: Any, path: Any) -> int:
        return (-obj) | self.sign if obj < 0 else obj


class PackedBits(Adapter):  # type: ignore[misc, type-arg, unused-ignore]
    """Bits packed 8 to a byte, the first in the lowest bit (Modbus coils), as a list of bools; `count` (a number or
    a function of the context) keeps only that many, else every bit of the bytes."""

    def __init__(self, subcon: Any, count: Any = None) -> None:
        super().__init__(subcon)
        self.count = count

    def _decode(self, obj: bytes, context: Any, path: Any) -> list[bool]:
        bits = [bool(obj[i >> 3] >> (i & 7) & 1) for i in range(len(obj) * 8)]
        if self.count is None:
            return bits
        return bits[: self.count(context) if callable(self.count) else self.count]

    def _encode(self, obj: list[bool], context: Any, path: Any) -> bytes:
        out = bytearray(-(-len(obj) // 8))
        for i, value in enumerate(obj):
            if value:
                out[i >> 3] |= 1 << (i & 7)
        return bytes(out)


class PackedInts(Adapter):  # type: ignore[misc, type-arg, unused-ignore]
    """`count` integers of `bits` bits packed with no gaps (runtime.packing.unpack_ints), as a list of ints."""

    def __init__(self, count: int, bits: int, lsb_first: bool, signed: bool) -> None:
        super().__init__(Bytes(-(-bits * count // 8)))
        self.shape = (bits, count, lsb_first)
        self.signed = signed

    def _decode(self, obj: bytes, context: Any, path: Any) -> list[int]:
        bits, count, lsb_first = self.shape
        return list(unpack_ints(obj, bits, count, lsb_first, self.signed))

    def _encode(self, obj: list[int], context: Any, path: Any) -> bytes:
        return pack_ints(obj, *self.shape)


class PaddedUtf8(Adapter):  # type: ignore[misc, type-arg, unused-ignore]
    """Fixed-size bytes holding UTF-8 text followed by pad bytes."""

    def __init__(self, size: int, pad: int) -> None:
        super().__init__(Bytes(size))
        self.size, self.pad = size, pad

    def _decode(self, obj: bytes, context: Any, path: Any) -> str:
        return obj.rstrip(bytes((self.pad,))).decode("utf-8")

    def _encode(self, obj: str, context: Any, path: Any) -> bytes:
        data = obj.encode("utf-8")
        return data + bytes((self.pad,)) * (self.size - len(data))


class Utf8(Adapter):  # type: ignore[misc, type-arg, unused-ignore]
    """Bytes holding UTF-8 text."""

    def _decode(self, obj: bytes, context: Any, path: Any) -> str:
        return obj.decode("utf-8")

    def _encode(self, obj: str, context: Any, path: Any) -> bytes:
        return obj.encode("utf-8")


class TrailingZeros(Adapter):  # type: ignore[misc, type-arg, unused-ignore]
    """A content of `size` bytes sent without its trailing zero bytes, at least one kept (`truncate:
    trailing_zeros`, MAVLink v2): parsed padded back to `size` by `subcon`, built by it and then cut."""

    def __init__(self, subcon: Any, size: int) -> None:
        super().__init__(GreedyBytes)
        self.inner, self.size = subcon, size

    def _decode(self, obj: bytes, context: Any, path: Any) -> Any:
        if len(obj) > self.size:
            raise ExplicitError(f"a content of {len(obj)} bytes is longer than its {self.size}")
        return self.inner.parse(bytes(obj) + bytes(self.size - len(obj)))

    def _encode(self, obj: Any, context: Any, path: Any) -> bytes:
        return bytes(self.inner.build(obj)).rstrip(b"\x00") or b"\x00"


class Framed(Adapter):  # type: ignore[misc, type-arg, unused-ignore]
    """A whole frame of any layout (stuffing, lengths and checksums anywhere), by the runtime's frame engine.

    Parses to a Container of `layout` (its name), `code`, `values` (the address/status elements, None for one its
    layout does not carry), `content` and `extras` (the optional elements sent, by name); builds from the same keys.
    Construct has no byte stuffing, so frames that are not of the classic shape use this.

    Replies read with the request they answer (layouts chosen by command, a checksum over request bytes) parse
    with `layout=` (the layout's name) and `request=` (the request's frame) given: `RESPONSE_FRAME.parse(frame,
    layout="read", request=request_frame)`; without them they are refused as `decode` refuses them.
    """

    def __init__(self, codec: Any, requests: Any = None) -> None:
        super().__init__(GreedyBytes)
        self.codec = codec
        self.requests = requests  # the request frames' codec, where replies are read with their request

    def _asked(self, context: Any) -> dict[str, bytes] | None:
        request = context.get("request") if self.requests is not None else None
        return None if request is None else self.requests.unwrap(bytes(request)).named()

    def _layout(self, name: Any) -> Any:
        return next((layout for layout in self.codec.layouts if layout.name == name), None)

    def _decode(self, obj: bytes, context: Any, path: Any) -> Container:  # type: ignore[type-arg, unused-ignore]
        layout = self._layout(context.get("layout"))
        if layout is not None:
            unwrapped = self.codec.spread(layout.unwrap(bytes(obj), self._asked(context)))
        else:
            unwrapped = self.codec.unwrap(bytes(obj), None, self._asked(context))
        return Container(
            layout=unwrapped.layout.name,
            code=unwrapped.code,
            values=list(unwrapped.values),
            content=unwrapped.content,
            extras=dict(unwrapped.extras),
        )

    def _encode(self, obj: Any, context: Any, path: Any) -> bytes:
        layout = self._layout(obj.get("layout"))
        index = None if layout is None else self.codec.layouts.index(layout)
        content, values, extras = bytes(obj["content"]), tuple(obj["values"]), obj.get("extras")
        return bytes(self.codec.wrap(content, obj["code"], values, index, self._asked(context), extras))
