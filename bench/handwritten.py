"""Hand-written `struct` codecs for the benchmarked frames: the baseline the generated codec is measured against.

Written the way a competent engineer writes them for one device: precompiled struct.Struct for the whole frame
where it has a fixed size, every check the generated codec makes (header, length byte, checksum, command code,
sub-command, counts, the range of a frame's id, the ranges it checks before encoding, True and False refused as
numbers), and a small slotted dataclass as the result. Enum and flag bytes become enum members as in the generated
messages. Nothing here is generated or imported from the
generated packages: these are the frames as a person would code them from the documents.
"""

from __future__ import annotations

import binascii
import struct
from dataclasses import dataclass
from enum import IntEnum, IntFlag
from typing import NamedTuple

# --- Fashion Star: header 12 4C (request) / 05 1C (response), cmd, length, content, sum mod 256 -----------------

FS_REQUEST_HEADER = b"\x12\x4c"
FS_RESPONSE_HEADER = b"\x05\x1c"
FS_ROTATE = 8
FS_READ_ANGLE = 10


@dataclass(slots=True)
class FsRotate:
    servo_id: int
    angle: int  # 0.1°
    interval: int  # ms
    power: int = 0  # mW


@dataclass(slots=True)
class FsReadAngleReply:
    servo_id: int
    angle: int  # 0.1°


_FS_ROTATE_FRAME = struct.Struct("<2sBBBhHHB")  # header, cmd, length, servo_id, angle, interval, power, checksum
_FS_ROTATE_BODY = struct.Struct("<2sBBBhHH")
_FS_READ_ANGLE_FRAME = struct.Struct("<2sBBBhB")  # header, cmd, length, servo_id, angle, checksum
_FS_READ_ANGLE_BODY = struct.Struct("<2sBBBh")


def fs_decode_rotate(frame: bytes) -> FsRotate:
    if len(frame) != _FS_ROTATE_FRAME.size:
        raise ValueError(f"rotate frame is {len(frame)} bytes, expected {_FS_ROTATE_FRAME.size}")
    header, code, length, servo_id, angle, interval, power, checksum = _FS_ROTATE_FRAME.unpack(frame)
    if header != FS_REQUEST_HEADER:
        raise ValueError(f"bad header {header.hex(' ')}")
    if code != FS_ROTATE:
        raise ValueError(f"command {code} is not ROTATE")
    if length != 7:
        raise ValueError(f"length byte {length}, expected 7")
    if sum(frame[:-1]) & 0xFF != checksum:
        raise ValueError("bad checksum")
    return FsRotate(servo_id, angle, interval, power)


def fs_encode_rotate(message: FsRotate) -> bytes:
    if not 0 <= message.servo_id <= 254 or message.servo_id.__class__ is bool:
        raise ValueError(f"servo_id {message.servo_id} outside 0..254")
    if not -32768 <= message.angle <= 32767 or message.angle.__class__ is bool:
        raise ValueError(f"angle {message.angle} outside -32768..32767")
    if not 0 <= message.interval <= 65535 or message.interval.__class__ is bool:
        raise ValueError(f"interval {message.interval} outside 0..65535")
    if not 0 <= message.power <= 65535 or message.power.__class__ is bool:
        raise ValueError(f"power {message.power} outside 0..65535")
    body = _FS_ROTATE_BODY.pack(
        FS_REQUEST_HEADER, FS_ROTATE, 7, message.servo_id, message.angle, message.interval, message.power
    )
    return body + bytes((sum(body) & 0xFF,))


def fs_decode_read_angle_reply(frame: bytes) -> FsReadAngleReply:
    if len(frame) != _FS_READ_ANGLE_FRAME.size:
        raise ValueError(f"read-angle reply is {len(frame)} bytes, expected {_FS_READ_ANGLE_FRAME.size}")
    header, code, length, servo_id, angle, checksum = _FS_READ_ANGLE_FRAME.unpack(frame)
    if header != FS_RESPONSE_HEADER:
        raise ValueError(f"bad header {header.hex(' ')}")
    if code != FS_READ_ANGLE:
        raise ValueError(f"command {code} is not READ_ANGLE")
    if length != 3:
        raise ValueError(f"length byte {length}, expected 3")
    if sum(frame[:-1]) & 0xFF != checksum:
        raise ValueError("bad checksum")
    return FsReadAngleReply(servo_id, angle)


def fs_encode_read_angle_reply(message: FsReadAngleReply) -> bytes:
    if not 0 <= message.servo_id <= 254 or message.servo_id.__class__ is bool:
        raise ValueError(f"servo_id {message.servo_id} outside 0..254")
    if not -32768 <= message.angle <= 32767 or message.angle.__class__ is bool:
        raise ValueError(f"angle {message.angle} outside -32768..32767")
    body = _FS_READ_ANGLE_BODY.pack(FS_RESPONSE_HEADER, FS_READ_ANGLE, 3, message.servo_id, message.angle)
    return body + bytes((sum(body) & 0xFF,))


class FsReplyStream:
    """A straightforward hand-written stream parser for READ_ANGLE replies: find the header, check the command code,
    length byte and checksum, unpack; after a mismatch, look again one byte after that header."""

    def __init__(self) -> None:
        self.pending = b""

    def feed(self, data: bytes) -> list[FsReadAngleReply]:
        buffer = self.pending + data if self.pending else data
        end = len(buffer)
        size = _FS_READ_ANGLE_FRAME.size
        found = []
        start = 0
        while True:
            position = buffer.find(FS_RESPONSE_HEADER, start)
            if position < 0:
                self.pending = buffer[max(start, end - 1) :]  # the last byte may begin a header
                return found
            if end - position < size:
                self.pending = buffer[position:]
                return found
            _, code, length, servo_id, angle, checksum = _FS_READ_ANGLE_FRAME.unpack_from(buffer, position)
            if code != FS_READ_ANGLE or length != 3 or sum(buffer[position : position + size - 1]) & 0xFF != checksum:
                start = position + 1
                continue
            found.append(FsReadAngleReply(servo_id, angle))
            start = position + size


# --- Hiwonder RRC: AA 55, function, length, data, CRC-8/MAXIM over function..data ---------------------------------

RRC_HEADER = b"\xaa\x55"
RRC_MOTOR = 3
RRC_BUS_SERVO = 5
RRC_SET_SPEEDS = 1
RRC_READ_POSITION = 5
FLOAT32_MAX = 3.4028234663852886e38


def _crc8_maxim_table() -> tuple[int, ...]:
    table = []
    for byte in range(256):
        crc = byte
        for _ in range(8):
            crc = (crc >> 1) ^ 0x8C if crc & 1 else crc >> 1
        table.append(crc)
    return tuple(table)


_CRC8_MAXIM = _crc8_maxim_table()


def crc8_maxim(data: bytes) -> int:
    crc = 0
    for byte in data:
        crc = _CRC8_MAXIM[crc ^ byte]
    return crc


class RrcReadResult(IntEnum):
    OK = 0
    FAILED = -1


@dataclass(slots=True)
class RrcPositionReport:
    servo_id: int
    success: RrcReadResult | int
    position: int


@dataclass(slots=True)
class RrcMotorSpeed:
    motor_id: int
    speed: float  # r/s


@dataclass(slots=True)
class RrcSetSpeeds:
    motors: tuple[RrcMotorSpeed, ...]


_RRC_REPORT_FRAME = struct.Struct("<2sBBBBbhB")  # header, function, length, servo_id, sub, success, position, crc
_RRC_REPORT_BODY = struct.Struct("<2sBBBBbh")
_RRC_SPEEDS_HEAD = struct.Struct("<2sBBBB")  # header, function, length, sub, count
_RRC_MOTOR_ITEM = struct.Struct("<Bf")
_RRC_READ_RESULTS = {member.value: member for member in RrcReadResult}


def rrc_decode_position_report(frame: bytes) -> RrcPositionReport:
    if len(frame) != _RRC_REPORT_FRAME.size:
        raise ValueError(f"position report is {len(frame)} bytes, expected {_RRC_REPORT_FRAME.size}")
    header, function, length, servo_id, sub, success, position, crc = _RRC_REPORT_FRAME.unpack(frame)
    if header != RRC_HEADER:
        raise ValueError(f"bad header {header.hex(' ')}")
    if function != RRC_BUS_SERVO:
        raise ValueError(f"function {function} is not BUS_SERVO")
    if length != 5:
        raise ValueError(f"length byte {length}, expected 5")
    if crc8_maxim(frame[2:-1]) != crc:
        raise ValueError("bad CRC")
    if sub != RRC_READ_POSITION:
        raise ValueError(f"sub-command {sub} is not READ_POSITION")
    return RrcPositionReport(servo_id, _RRC_READ_RESULTS.get(success, success), position)


def rrc_encode_position_report(message: RrcPositionReport) -> bytes:
    if not 0 <= message.servo_id <= 255 or message.servo_id.__class__ is bool:
        raise ValueError(f"servo_id {message.servo_id} outside 0..255")
    if not -1 <= message.success <= 0 or message.success.__class__ is bool:
        raise ValueError(f"success {message.success} outside -1..0")
    if not -32768 <= message.position <= 32767 or message.position.__class__ is bool:
        raise ValueError(f"position {message.position} outside -32768..32767")
    body = _RRC_REPORT_BODY.pack(
        RRC_HEADER, RRC_BUS_SERVO, 5, message.servo_id, RRC_READ_POSITION, message.success, message.position
    )
    return body + bytes((crc8_maxim(body[2:]),))


def rrc_decode_set_speeds(frame: bytes) -> RrcSetSpeeds:
    size = len(frame)
    if size < _RRC_SPEEDS_HEAD.size + 1:
        raise ValueError(f"set-speeds frame of {size} bytes is too short")
    header, function, length, sub, count = _RRC_SPEEDS_HEAD.unpack_from(frame)
    if header != RRC_HEADER:
        raise ValueError(f"bad header {header.hex(' ')}")
    if function != RRC_MOTOR:
        raise ValueError(f"function {function} is not MOTOR")
    if length != size - 5:
        raise ValueError(f"length byte {length}, but the frame holds {size - 5}")
    if crc8_maxim(frame[2:-1]) != frame[-1]:
        raise ValueError("bad CRC")
    if sub != RRC_SET_SPEEDS:
        raise ValueError(f"sub-command {sub} is not SET_SPEEDS")
    if length != 2 + _RRC_MOTOR_ITEM.size * count:
        raise ValueError(f"{length} content bytes do not hold {count} motors")
    items = _RRC_MOTOR_ITEM.iter_unpack(frame[_RRC_SPEEDS_HEAD.size : -1])
    return RrcSetSpeeds(tuple(RrcMotorSpeed(motor_id, speed) for motor_id, speed in items))


def rrc_encode_set_speeds(message: RrcSetSpeeds) -> bytes:
    count = len(message.motors)
    if count > 50:  # 2 + 5 * count content bytes must fit the length byte
        raise ValueError(f"{count} motors do not fit one frame")
    parts = []
    for motor in message.motors:
        if not 0 <= motor.motor_id <= 255 or motor.motor_id.__class__ is bool:
            raise ValueError(f"motor_id {motor.motor_id} outside 0..255")
        if not -FLOAT32_MAX <= motor.speed <= FLOAT32_MAX:
            raise ValueError(f"speed {motor.speed} is not a finite float32")
        parts.append(_RRC_MOTOR_ITEM.pack(motor.motor_id, motor.speed))
    body = _RRC_SPEEDS_HEAD.pack(RRC_HEADER, RRC_MOTOR, 2 + 5 * count, RRC_SET_SPEEDS, count) + b"".join(parts)
    return body + bytes((crc8_maxim(body[2:]),))


# --- FEETECH SMS: FF FF, id, length (params + 2), instruction|error, params, ~sum(id..params) ----------------------

SMS_HEADER = b"\xff\xff"
SMS_WRITE = 3


class SmsError(IntFlag):
    NONE = 0
    VOLTAGE = 1 << 0
    ANGLE_SENSOR = 1 << 1
    OVERHEAT = 1 << 2
    OVERCURRENT = 1 << 3
    OVERLOAD = 1 << 5


@dataclass(slots=True)
class SmsReply:
    servo_id: int
    error: SmsError
    data: bytes


@dataclass(slots=True)
class SmsWrite:
    servo_id: int
    address: int
    data: bytes


_SMS_HEAD = struct.Struct("<2sBBB")  # header, id, length, error (reply) or instruction (request)
_SMS_WRITE_HEAD = struct.Struct("<2sBBBB")  # header, id, length, instruction, address


def sms_decode_reply(frame: bytes) -> SmsReply:
    size = len(frame)
    if size < _SMS_HEAD.size + 1:
        raise ValueError(f"reply of {size} bytes is too short")
    header, servo_id, length, error = _SMS_HEAD.unpack_from(frame)
    if header != SMS_HEADER:
        raise ValueError(f"bad header {header.hex(' ')}")
    if servo_id > 254:
        raise ValueError(f"id {servo_id} outside 0..254")
    if length != size - 4:
        raise ValueError(f"length byte {length}, but the frame holds {size - 4}")
    if ~sum(frame[2:-1]) & 0xFF != frame[-1]:
        raise ValueError("bad checksum")
    return SmsReply(servo_id, SmsError(error), frame[_SMS_HEAD.size : -1])


class SmsReplyStream:
    """A straightforward hand-written stream parser for FEETECH replies (any number of data bytes): find the header,
    check the id and length byte, wait for the whole frame, check the checksum, unpack; after a mismatch, look again
    one byte after that header."""

    def __init__(self) -> None:
        self.pending = b""

    def feed(self, data: bytes) -> list[SmsReply]:
        buffer = self.pending + data if self.pending else data
        end = len(buffer)
        found = []
        start = 0
        while True:
            position = buffer.find(SMS_HEADER, start)
            if position < 0:
                self.pending = buffer[max(start, end - 1) :]  # the last byte may begin a header
                return found
            if end - position < 6:  # header, id, length, error, checksum
                self.pending = buffer[position:]
                return found
            servo_id = buffer[position + 2]
            length = buffer[position + 3]
            if servo_id > 254 or length < 2:
                start = position + 1
                continue
            stop = position + 4 + length
            if stop > end:
                self.pending = buffer[position:]
                return found
            if ~sum(buffer[position + 2 : stop - 1]) & 0xFF != buffer[stop - 1]:
                start = position + 1
                continue
            found.append(SmsReply(servo_id, SmsError(buffer[position + 4]), buffer[position + 5 : stop - 1]))
            start = stop


def sms_encode_reply(message: SmsReply) -> bytes:
    if not 0 <= message.servo_id <= 254 or message.servo_id.__class__ is bool:
        raise ValueError(f"id {message.servo_id} outside 0..254")
    if not 0 <= message.error <= 255 or message.error.__class__ is bool:
        raise ValueError(f"error {message.error} outside 0..255")
    if len(message.data) > 253:
        raise ValueError(f"{len(message.data)} data bytes do not fit one frame")
    body = _SMS_HEAD.pack(SMS_HEADER, message.servo_id, len(message.data) + 2, message.error) + message.data
    return body + bytes((~sum(body[2:]) & 0xFF,))


def sms_decode_write(frame: bytes) -> SmsWrite:
    size = len(frame)
    if size < _SMS_WRITE_HEAD.size + 1:
        raise ValueError(f"write frame of {size} bytes is too short")
    header, servo_id, length, instruction, address = _SMS_WRITE_HEAD.unpack_from(frame)
    if header != SMS_HEADER:
        raise ValueError(f"bad header {header.hex(' ')}")
    if servo_id > 254:
        raise ValueError(f"id {servo_id} outside 0..254")
    if length != size - 4:
        raise ValueError(f"length byte {length}, but the frame holds {size - 4}")
    if ~sum(frame[2:-1]) & 0xFF != frame[-1]:
        raise ValueError("bad checksum")
    if instruction != SMS_WRITE:
        raise ValueError(f"instruction {instruction} is not WRITE")
    return SmsWrite(servo_id, address, frame[_SMS_WRITE_HEAD.size : -1])


def sms_encode_write(message: SmsWrite) -> bytes:
    if not 0 <= message.servo_id <= 254 or message.servo_id.__class__ is bool:
        raise ValueError(f"id {message.servo_id} outside 0..254")
    if not 0 <= message.address <= 255 or message.address.__class__ is bool:
        raise ValueError(f"address {message.address} outside 0..255")
    if len(message.data) > 252:
        raise ValueError(f"{len(message.data)} data bytes do not fit one frame")
    head = _SMS_WRITE_HEAD.pack(SMS_HEADER, message.servo_id, len(message.data) + 3, SMS_WRITE, message.address)
    body = head + message.data
    return body + bytes((~sum(body[2:]) & 0xFF,))


# --- DYNAMIXEL 2.0: FF FF FD 00, id, length u16 (instruction .. CRC), instruction 0x55, error, params, CRC-16 ------
# (CRC-16/UMTS: poly 0x8005, init 0, MSB first); params are byte-stuffed (FF FF FD -> FF FF FD FD) on the wire.

DXL_HEADER = b"\xff\xff\xfd\x00"
DXL_STATUS = 0x55


def _crc16_msb_table(poly: int) -> tuple[int, ...]:
    table = []
    for byte in range(256):
        crc = byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ poly if crc & 0x8000 else crc << 1) & 0xFFFF
        table.append(crc)
    return tuple(table)


def _crc16_lsb_table(poly: int) -> tuple[int, ...]:
    table = []
    for byte in range(256):
        crc = byte
        for _ in range(8):
            crc = (crc >> 1) ^ poly if crc & 1 else crc >> 1
        table.append(crc)
    return tuple(table)


_CRC16_UMTS = _crc16_msb_table(0x8005)
_CRC16_MODBUS = _crc16_lsb_table(0xA001)


def crc16_umts(data: bytes) -> int:
    crc = 0
    for byte in data:
        crc = ((crc << 8) & 0xFFFF) ^ _CRC16_UMTS[(crc >> 8) ^ byte]
    return crc


def crc16_modbus(data: bytes) -> int:
    crc = 0xFFFF
    for byte in data:
        crc = (crc >> 8) ^ _CRC16_MODBUS[(crc ^ byte) & 0xFF]
    return crc


class DxlErrorNumber(IntEnum):
    NONE = 0
    RESULT_FAIL = 1
    INSTRUCTION_ERROR = 2
    CRC_ERROR = 3
    DATA_RANGE_ERROR = 4
    DATA_LENGTH_ERROR = 5
    DATA_LIMIT_ERROR = 6
    ACCESS_ERROR = 7


_DXL_ERRORS = {member.value: member for member in DxlErrorNumber}


@dataclass(slots=True)
class DxlError:
    alert: int
    number: DxlErrorNumber | int


@dataclass(slots=True)
class DxlStatus:
    servo_id: int
    error: DxlError
    data: bytes


_DXL_HEAD = struct.Struct("<4sBHBB")  # header, id, length, instruction, error


def dxl_decode_status(frame: bytes) -> DxlStatus:
    n = len(frame)
    if n < 11:
        raise ValueError(f"status packet of {n} bytes, at least 11 expected")
    header, servo_id, length, instruction, error = _DXL_HEAD.unpack_from(frame)
    if header != DXL_HEADER:
        raise ValueError(f"bad header {header.hex(' ')}")
    if length != n - 7:
        raise ValueError(f"length field {length}, the packet holds {n - 7}")
    if instruction != DXL_STATUS:
        raise ValueError(f"instruction {instruction:#04x} is not STATUS")
    if crc16_umts(frame[:-2]) != frame[-2] | frame[-1] << 8:
        raise ValueError("bad CRC")
    data = frame[9:-2].replace(b"\xff\xff\xfd\xfd", b"\xff\xff\xfd")
    number = error & 0x7F
    return DxlStatus(servo_id, DxlError(error >> 7, _DXL_ERRORS.get(number, number)), data)


def dxl_encode_status(message: DxlStatus) -> bytes:
    if not 0 <= message.servo_id <= 252:
        raise ValueError(f"id {message.servo_id} outside 0..252")
    if not 0 <= message.error.alert <= 1 or not 0 <= message.error.number <= 127:
        raise ValueError(f"error {message.error} out of range")
    params = message.data.replace(b"\xff\xff\xfd", b"\xff\xff\xfd\xfd")
    error = message.error.alert << 7 | message.error.number
    body = _DXL_HEAD.pack(DXL_HEADER, message.servo_id, len(params) + 4, DXL_STATUS, error) + params
    return body + crc16_umts(body).to_bytes(2, "little")


# --- Modbus RTU: unit, function, content, CRC-16/MODBUS (little-endian); no header, no length byte -----------------

MB_READ_HOLDING_REGISTERS = 3


@dataclass(slots=True)
class MbRegisters:
    unit: int
    registers: tuple[int, ...]


def mb_decode_registers_reply(frame: bytes) -> MbRegisters:
    n = len(frame)
    if n < 5:
        raise ValueError(f"reply of {n} bytes, at least 5 expected")
    if frame[1] != MB_READ_HOLDING_REGISTERS:
        raise ValueError(f"function {frame[1]} is not READ_HOLDING_REGISTERS")
    count = frame[2]
    if count != n - 5 or count & 1:
        raise ValueError(f"byte count {count}, the reply holds {n - 5}")
    if crc16_modbus(frame[:-2]) != frame[-2] | frame[-1] << 8:
        raise ValueError("bad CRC")
    return MbRegisters(frame[0], struct.unpack_from(f">{count >> 1}H", frame, 3))


def mb_encode_registers_reply(message: MbRegisters) -> bytes:
    if not 0 <= message.unit <= 247 or message.unit.__class__ is bool:
        raise ValueError(f"unit {message.unit} outside 0..247")
    count = len(message.registers)
    if not 1 <= count <= 125:
        raise ValueError(f"{count} registers, 1..125 allowed")
    for register in message.registers:  # struct.pack checks 0..65535, but takes True and False as numbers
        if register.__class__ is bool:
            raise ValueError(f"register {register} is not a number")
    body = struct.pack(f">BBB{count}H", message.unit, MB_READ_HOLDING_REGISTERS, count * 2, *message.registers)
    return body + crc16_modbus(body).to_bytes(2, "little")


# --- VESC: 02, length u8, payload (command id + fields, big-endian), CRC-16/XMODEM big-endian, 03 ------------------
# (payloads of 256 bytes and more start with 03 and a u16 length; COMM_SET_DUTY never needs them). The CRC is the
# standard library's binascii.crc_hqx, which computes CRC-16/XMODEM in C: what a person writing this would use.

VESC_START = 2
VESC_END = 3
VESC_SET_DUTY = 5


@dataclass(slots=True)
class VescSetDuty:
    duty: int  # 0.00001


_VESC_SET_DUTY_FRAME = struct.Struct(">BBBiHB")  # start, length, command, duty, crc, end
_VESC_SET_DUTY_PAYLOAD = struct.Struct(">Bi")


def vesc_decode_set_duty(frame: bytes) -> VescSetDuty:
    if len(frame) != _VESC_SET_DUTY_FRAME.size:
        raise ValueError(f"set-duty frame is {len(frame)} bytes, expected {_VESC_SET_DUTY_FRAME.size}")
    start, length, command, duty, crc, end = _VESC_SET_DUTY_FRAME.unpack(frame)
    if start != VESC_START:
        raise ValueError(f"start byte {start:#04x}, expected 02")
    if end != VESC_END:
        raise ValueError(f"end byte {end:#04x}, expected 03")
    if length != 5:
        raise ValueError(f"length byte {length}, expected 5")
    if binascii.crc_hqx(frame[2:7], 0) != crc:
        raise ValueError("bad CRC")
    if command != VESC_SET_DUTY:
        raise ValueError(f"command {command} is not COMM_SET_DUTY")
    return VescSetDuty(duty)


def vesc_encode_set_duty(message: VescSetDuty) -> bytes:
    if not -100000 <= message.duty <= 100000 or message.duty.__class__ is bool:
        raise ValueError(f"duty {message.duty} outside -100000..100000")
    payload = _VESC_SET_DUTY_PAYLOAD.pack(VESC_SET_DUTY, message.duty)
    return b"\x02\x05" + payload + binascii.crc_hqx(payload, 0).to_bytes(2, "big") + b"\x03"


# --- minimal decoders: the least a person writes for one frame (issue 25's second comparison) ------------------------
# One struct unpack of the whole frame, the checksum and the command code checked, a NamedTuple of the fields: no
# length byte, header or range checks, no enum members. What the generated decode is also measured against.


class MinimalReadAngle(NamedTuple):
    servo_id: int
    angle: int


class MinimalRotate(NamedTuple):
    servo_id: int
    angle: int
    interval: int
    power: int


class MinimalSmsReply(NamedTuple):
    servo_id: int
    error: int
    data: bytes


def fs_minimal_read_angle_reply(frame: bytes) -> MinimalReadAngle:
    _, code, _, servo_id, angle, checksum = _FS_READ_ANGLE_FRAME.unpack(frame)
    if code != FS_READ_ANGLE or sum(frame[:-1]) & 0xFF != checksum:
        raise ValueError("not a READ_ANGLE reply")
    return MinimalReadAngle(servo_id, angle)


def fs_minimal_rotate(frame: bytes) -> MinimalRotate:
    _, code, _, servo_id, angle, interval, power, checksum = _FS_ROTATE_FRAME.unpack(frame)
    if code != FS_ROTATE or sum(frame[:-1]) & 0xFF != checksum:
        raise ValueError("not a ROTATE request")
    return MinimalRotate(servo_id, angle, interval, power)


def sms_minimal_reply(frame: bytes) -> MinimalSmsReply:
    if ~sum(frame[2:-1]) & 0xFF != frame[-1]:
        raise ValueError("bad checksum")
    return MinimalSmsReply(frame[2], frame[4], frame[5:-1])


# --- the floor: what no stream parser of Fashion Star replies can do less of (issue 25's noisy-stream context) --------


class _FloorReply(tuple):  # type: ignore[type-arg]
    """The cheapest record there is: a tuple subclass built by tuple.__new__ (as the generated messages are)."""

    __slots__ = ()


_FS_READ_ANGLE_PIECE = struct.Struct("<xxBhx")  # after the header: cmd, length, servo_id, angle, sum (skipped)
_new_floor_reply = tuple.__new__


class FsFloorStream:
    """Not a parser: what every pure-Python parser of this stream does at least, per read: split the bytes at the
    header (one pass in C) and build a record from each piece long enough to hold one (one unpack, one tuple).
    No command, length or checksum check, no resynchronisation inside a piece: it takes garbage for frames. It
    shows how much of a budget per frame the interpreter leaves for the checks."""

    def __init__(self) -> None:
        self.pending = b""

    def feed(self, data: bytes) -> list[_FloorReply]:
        buffer = self.pending + data if self.pending else data
        pieces = buffer.split(FS_RESPONSE_HEADER)
        self.pending = FS_RESPONSE_HEADER + pieces[-1] if len(pieces) > 1 else pieces[-1][-1:]
        unpack = _FS_READ_ANGLE_PIECE.unpack_from
        return [_new_floor_reply(_FloorReply, unpack(piece)) for piece in pieces[1:-1] if len(piece) >= 6]
