"""Errors raised by generated code; each message is one line meant for a person."""

from __future__ import annotations

from collections.abc import Callable

from serialspec.runtime.message import Direction, Message, is_sequence


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


def out_of_range(
    where: str, field: str, value: object, low: float, high: float, broadcast: int | None = None
) -> EncodeError:
    """The error for a value refused before encoding: outside its range, or not a number at all (True is not 1).

    For a list of values, the first item at fault is named: "values[3] = 70000 is outside its range 0..65535".
    `broadcast` is an address's broadcast value, allowed beside the range, which the line names too.
    """
    if is_sequence(value):
        for index, item in enumerate(value):
            if isinstance(item, bool) or not isinstance(item, int | float) or not low <= item <= high:
                return out_of_range(where, f"{field}[{index}]", item, low, high, broadcast)
    allowed = f"{_number(low)}..{_number(high)}"
    if broadcast is not None:
        allowed += f" (or {broadcast})"  # as decode words it
    if isinstance(value, bool) or not isinstance(value, int | float):
        return EncodeError(f"{where}: {field} must be a number in {allowed}, got {shown(value)}")
    return RangeError(f"{where}: {field} = {shown(value)} is outside its range {allowed}")


def shown(value: object) -> str:
    """A value for an error line: short, one line, and never a 5,000-digit number."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 64:
        return f"a number of about {value.bit_length() * 30103 // 100000 + 1} digits"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


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


# --- talking to devices -----------------------------------------------------------------------------------------


class TransportError(SerialspecError):
    """A transaction with a device failed; the bus stays usable."""


class Timeout(TransportError, TimeoutError):
    """No reply arrived before the deadline; names the command and the device it was sent to."""

    def __init__(self, command: str, device: str, timeout: float) -> None:
        super().__init__(f"no reply to {command} from {device or 'the device'} within {timeout * 1000:.0f} ms")
        self.command = command
        self.device = device
        self.timeout = timeout


class CorruptReply(TransportError):
    """Bytes arrived where a reply was expected, but they are not a valid frame (bad checksum, bad content)."""


class DeviceError(TransportError):
    """The device answered with an error status (e.g. FEETECH error flags); `reply` is the decoded answer."""

    def __init__(self, text: str, reply: object) -> None:
        super().__init__(text)
        self.reply = reply


class EchoMismatch(TransportError):
    """The reply repeats one of the request's fields (a field of the same name) with another value; `reply` is the
    decoded answer."""

    def __init__(self, text: str, reply: object) -> None:
        super().__init__(text)
        self.reply = reply


class PortError(TransportError, OSError):
    """The port could not be opened, read or written."""


def either_direction(decode: Callable[[Direction], Message], ambiguous: str) -> Message:
    """The message a frame decodes to in the one direction it decodes in, where the first bytes do not tell requests
    from responses (a reply whose code only replies have); `ambiguous` is the error when both or neither decode."""
    found: list[Message] = []
    reasons: dict[str, str] = {}
    kinds: set[type[DecodeError]] = set()
    for direction in Direction:
        try:
            found.append(decode(direction))
        except DecodeError as exc:
            reasons[direction.value] = str(exc)
            kinds.add(type(exc))
    if len(found) == 1:
        return found[0]
    if found:
        raise DecodeError(ambiguous)
    if len(set(reasons.values())) == 1:  # one reason, of one kind both ways: ChecksumError stays one
        raise (kinds.pop() if len(kinds) == 1 else DecodeError)(reasons[Direction.REQUEST.value])
    raise DecodeError("neither a request ({request}) nor a response ({response})".format_map(reasons))
