"""Family 1: decode and encode of one frame, to and from its typed message, against three peers.

Frames come from the specs' `examples:`. For each: the generated codec (`package.decode(frame, direction)`,
`package.encode(message)`), hand-written `struct` code doing the same checks (bench/handwritten.py), construct's
interpreted structs from `generated/<protocol>/structs.py` (frame struct, then content struct; encode builds the
content then the frame), and pymavlink's MAVLink 2 `common` dialect (`MAVLink.decode`, `message.pack`).
"""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from serialspec.lang import load_protocol
from serialspec.lang.model import Protocol
from serialspec.runtime.message import Direction, Message, Record, field_names

from bench import handwritten as hw
from bench.timing import Operation, Table, compare, times, us, verdict

ROOT = Path(__file__).resolve().parent.parent
HANDWRITTEN_TARGET = 1.0  # generated time ≤ hand-written time
CONSTRUCT_TARGET = 10.0  # generated ≥ 10 × faster than construct
MINIMAL_TARGET = 1.0  # generated decode time ≤ a minimal hand-written struct decoder's


@dataclass(frozen=True)
class Case:
    protocol: str
    example: str  # name in the spec's `examples:`
    label: str
    decode: Callable[[bytes], Any]  # hand-written
    encode: Callable[[Any], bytes]  # hand-written
    construct: bool = True  # whether the generated structs.py can parse and build the whole frame
    minimal: Callable[[bytes], Any] | None = None  # a minimal hand-written decoder (handwritten.py), where there is one


CASES = [
    Case(
        "fashionstar_uart",
        "rotate_request",
        "FS ROTATE request",
        hw.fs_decode_rotate,
        hw.fs_encode_rotate,
        minimal=hw.fs_minimal_rotate,
    ),
    Case(
        "fashionstar_uart",
        "read_angle_response",
        "FS READ_ANGLE response",
        hw.fs_decode_read_angle_reply,
        hw.fs_encode_read_angle_reply,
        minimal=hw.fs_minimal_read_angle_reply,
    ),
    Case(
        "hiwonder_rrc",
        "t_bus_position_report",
        "RRC bus_servo read_position report",
        hw.rrc_decode_position_report,
        hw.rrc_encode_position_report,
    ),
    Case(
        "hiwonder_rrc",
        "ex07_motor_speeds",
        "RRC motor set_speeds (2 motors)",
        hw.rrc_decode_set_speeds,
        hw.rrc_encode_set_speeds,
    ),
    Case(
        "feetech_sms",
        "read_present_position_reply",
        "SMS READ reply (2 bytes)",
        hw.sms_decode_reply,
        hw.sms_encode_reply,
        minimal=hw.sms_minimal_reply,
    ),
    Case("feetech_sms", "write_goal", "SMS WRITE request (6 data bytes)", hw.sms_decode_write, hw.sms_encode_write),
    Case(
        "dynamixel_p2",
        "read_present_position_reply",
        "DXL status reply, 4 data bytes",
        hw.dxl_decode_status,
        hw.dxl_encode_status,
        construct=False,
    ),
    Case(
        "modbus_rtu",
        "read_holding_registers_response",
        "Modbus read holding registers reply (3 registers)",
        hw.mb_decode_registers_reply,
        hw.mb_encode_registers_reply,
        construct=False,
    ),
    Case(
        "vesc",
        "set_duty_half",
        "VESC COMM_SET_DUTY request",
        hw.vesc_decode_set_duty,
        hw.vesc_encode_set_duty,
        construct=False,
    ),
]


def as_tuple(value: Any) -> Any:
    """A generated message or a hand-written dataclass as nested tuples of its field values, to compare the two."""
    if isinstance(value, Record):
        return tuple(as_tuple(getattr(value, name)) for name in field_names(value))
    if dataclasses.is_dataclass(value):
        return tuple(as_tuple(getattr(value, f.name)) for f in dataclasses.fields(value))
    if isinstance(value, list | tuple):
        return type(value)(as_tuple(item) for item in value)
    return value


@cache
def protocol(name: str) -> Protocol:
    path = ROOT / "specs" / f"{name}.yaml"
    return load_protocol(str(path), f"specs/{name}.yaml")


def example_frame(protocol_name: str, example: str) -> tuple[bytes, Direction]:
    found = next(e for e in protocol(protocol_name).examples if e.name == example)
    return found.frame, Direction(found.direction.value)


def _plain(container: Any) -> dict[str, Any]:
    """A construct container as the plain values a caller would build from (private keys dropped)."""
    return {
        key: [_plain(item) if isinstance(item, dict) else item for item in value] if isinstance(value, list) else value
        for key, value in container.items()
        if not key.startswith("_")
    }


@dataclass(frozen=True)
class ConstructCodec:
    """construct's parse and build of one frame: the frame struct around the command's content struct."""

    frame_struct: Any
    content_struct: Any
    frame_values: dict[str, Any]  # frame-level values beside the content (command code, id, error)
    content_values: dict[str, Any]

    def decode(self, frame: bytes) -> Any:
        parsed = self.frame_struct.parse(frame)
        return self.content_struct.parse(parsed.body.value.content)

    def encode(self) -> bytes:
        content = self.content_struct.build(self.content_values)
        return bytes(self.frame_struct.build({"body": {"value": {**self.frame_values, "content": content}}}))


def construct_codec(protocol_name: str, frame: bytes, direction: Direction, message: Message) -> ConstructCodec:
    structs = importlib.import_module(f"serialspec_protocols.{protocol_name}.structs")
    spec = next(m for m in protocol(protocol_name).messages() if m.class_name == type(message).__name__)
    frame_struct = getattr(structs, f"{direction.name}_FRAME")
    content_struct = structs.CONTENTS[(spec.key, direction.value)]
    value = frame_struct.parse(frame).body.value
    frame_values = {k: v for k, v in _plain(value).items() if k not in ("header", "length", "content")}
    content_values = _plain(content_struct.parse(value.content))
    return ConstructCodec(frame_struct, content_struct, frame_values, content_values)


def mavlink_peers() -> dict[str, tuple[int, Operation, Operation]]:
    """pymavlink: message name -> (frame size, decode operation, encode operation)."""
    from pymavlink.dialects.v20 import common as mavlink

    link = mavlink.MAVLink(None, srcSystem=1, srcComponent=1)
    messages = {
        "HEARTBEAT": mavlink.MAVLink_heartbeat_message(2, 3, 81, 0, 4, 3),
        "ATTITUDE": mavlink.MAVLink_attitude_message(1000, 0.1, -0.2, 0.3, 0.01, 0.02, 0.03),
    }
    peers = {}
    for name, message in messages.items():
        frame = bytearray(message.pack(link))
        decoded = link.decode(frame)
        assert decoded.get_type() == name, decoded
        peers[name] = (len(frame), (link.decode, (frame,)), (message.pack, (link,)))
    return peers


def run() -> Table:
    mavlink = mavlink_peers()
    peer_size, peer_decode, peer_encode = mavlink["HEARTBEAT"]
    rows = []
    worst_handwritten = 0.0
    for case in CASES:
        package = importlib.import_module(f"serialspec_protocols.{case.protocol}")
        frame, direction = example_frame(case.protocol, case.example)
        message = package.decode(frame, direction)
        mine = case.decode(frame)
        # the three codecs must agree before their speed means anything
        assert as_tuple(mine) == as_tuple(message), (case.label, mine, message)
        assert package.encode(message) == frame and case.encode(mine) == frame, case.label
        peer = construct_codec(case.protocol, frame, direction, message) if case.construct else None
        assert peer is None or peer.encode() == frame, case.label
        operations: dict[str, tuple[Operation, Operation, Operation | None, Operation]] = {
            "decode": (
                (package.decode, (frame, direction)),
                (case.decode, (frame,)),
                (peer.decode, (frame,)) if peer else None,
                peer_decode,
            ),
            "encode": (
                (package.encode, (message,)),
                (case.encode, (mine,)),
                (peer.encode, ()) if peer else None,
                peer_encode,
            ),
        }
        for op, (generated, handwritten, construct, mavlink_op) in operations.items():
            competitors = {"generated": generated, "handwritten": handwritten, "mavlink": mavlink_op}
            if construct is not None:
                competitors["construct"] = construct
            if op == "decode" and case.minimal is not None:
                competitors["minimal"] = (case.minimal, (frame,))
            timed = compare(competitors)
            gen = timed["generated"].best_ns
            over_hand = gen / timed["handwritten"].best_ns
            over_construct = timed["construct"].best_ns / gen if construct is not None else None
            worst_handwritten = max(worst_handwritten, over_hand)
            rows.append(
                [
                    f"{case.label} ({len(frame)} B)",
                    op,
                    us(gen),
                    us(timed["handwritten"].best_ns),
                    times(over_hand),
                    verdict(over_hand <= HANDWRITTEN_TARGET),
                    us(timed["minimal"].best_ns) if "minimal" in timed else "—",
                    times(gen / timed["minimal"].best_ns) if "minimal" in timed else "—",
                    verdict(gen <= timed["minimal"].best_ns * MINIMAL_TARGET) if "minimal" in timed else "—",
                    us(timed["construct"].best_ns) if over_construct is not None else "—",
                    times(over_construct) if over_construct is not None else "—",
                    verdict(over_construct >= CONSTRUCT_TARGET) if over_construct is not None else "—",
                    us(timed["mavlink"].best_ns),
                    times(timed["mavlink"].best_ns / gen),
                ]
            )
    attitude_size, attitude_decode, attitude_encode = mavlink["ATTITUDE"]
    attitude = compare({"decode": attitude_decode, "encode": attitude_encode})
    return Table(
        title="Codec: one frame to and from its typed message (µs per frame, best of 7 rounds)",
        header=[
            "frame",
            "op",
            "generated µs",
            "hand-written µs",
            f"gen ÷ hand (≤ {HANDWRITTEN_TARGET}×)",
            "",
            "minimal µs",
            f"gen ÷ minimal (≤ {MINIMAL_TARGET}×)",
            "",
            "construct µs",
            f"construct ÷ gen (≥ {CONSTRUCT_TARGET:.0f}×)",
            "",
            f"pymavlink HEARTBEAT ({peer_size} B) µs",
            "pymavlink ÷ gen",
        ],
        rows=rows,
        notes=[
            "generated: `package.decode(frame, direction)` / `package.encode(message)`: header, length, checksum, "
            "command dispatch, field unpack, range checks on encode, a frozen message built from the tuple of its "
            "values.",
            "hand-written: bench/handwritten.py, one function per frame with a precompiled struct.Struct for the "
            "whole frame where its size is fixed, the same checks, a slotted dataclass, enum/flag members.",
            "minimal: the least a person writes for one frame (bench/handwritten.py `*_minimal_*`): one struct "
            "unpack, the checksum and command code checked, a NamedTuple; no length, header or range checks, no enum "
            "members (decode only, fixed-size classic frames).",
            "construct: the generated `structs.py` (frame struct with RawCopy + Checksum, then the command's content "
            "struct); decode yields construct Containers (no typed message), encode builds content then frame. "
            "DYNAMIXEL, Modbus and VESC: — (their structs.py describes the content, not the stuffed, header-less or "
            "two-layout frame).",
            "DYNAMIXEL 2.0, Modbus RTU and VESC frames are not of the classic shape (stuffing, u16 length over a span, "
            "CRC-16, no header, two layouts): the generator writes straight-line frame code for them from the "
            "framing description (backends/python/frames/); the CRC-16s are the runtime's crc_function "
            "(two bytes per step from a 65,536-entry table; CRC-16/XMODEM is binascii.crc_hqx). Hand-written: one "
            "function each, a table-driven CRC-16 loop a byte at a time (VESC: binascii.crc_hqx).",
            f"pymavlink {mavlink_version()} `common` (MAVLink 2): `MAVLink.decode(frame)` and `message.pack(mav)`; its "
            "CRC runs in the compiled `fastcrc` extension when installed (it is here). ATTITUDE "
            f"({attitude_size} B): decode {us(attitude['decode'].best_ns)} µs, encode "
            f"{us(attitude['encode'].best_ns)} µs.",
            f"Worst generated ÷ hand-written ratio: {times(worst_handwritten)}.",
        ],
    )


def mavlink_version() -> str:
    from importlib.metadata import version

    return version("pymavlink")
