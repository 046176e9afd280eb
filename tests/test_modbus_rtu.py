"""Modbus RTU: frames built by the peer (pymodbus) against ours, exception replies, broadcast, back-to-back frames
split by layout and CRC, and the virtual server's data model and exceptions."""

from __future__ import annotations

import random
from typing import Any

import pytest
from serialspec.runtime.errors import ChecksumError, DecodeError, RangeError
from serialspec_protocols import modbus_rtu as mb
from serialspec_protocols.modbus_rtu.simulator import ModbusRtuSimulator

pymodbus_pdu = pytest.importorskip("pymodbus.pdu")
from pymodbus.framer import FramerRTU  # noqa: E402
from pymodbus.pdu import DecodePDU, bit_message, register_message  # noqa: E402

CLIENT_FRAMER = FramerRTU(DecodePDU(is_server=False))


def peer_frame(pdu: Any) -> bytes:
    """A frame as pymodbus builds it (address, PDU, CRC)."""
    return bytes(CLIENT_FRAMER.buildFrame(pdu))


# (our message, pymodbus's PDU for the same frame)
PAIRS: list[tuple[Any, Any]] = [
    (
        mb.ReadCoilsRequest(unit=17, address=0x13, count=19),
        bit_message.ReadCoilsRequest(address=0x13, count=19, dev_id=17),
    ),
    (
        mb.ReadDiscreteInputsRequest(unit=1, address=0xC4, count=22),
        bit_message.ReadDiscreteInputsRequest(address=0xC4, count=22, dev_id=1),
    ),
    (
        mb.ReadHoldingRegistersRequest(unit=1, address=0, count=10),
        register_message.ReadHoldingRegistersRequest(address=0, count=10, dev_id=1),
    ),
    (
        mb.ReadInputRegistersRequest(unit=247, address=8, count=125),
        register_message.ReadInputRegistersRequest(address=8, count=125, dev_id=247),
    ),
    (
        mb.WriteCoilRequest(unit=1, address=0xAC, value=mb.CoilState.ON),
        bit_message.WriteSingleCoilRequest(address=0xAC, bits=[True], dev_id=1),
    ),
    (
        mb.WriteRegisterRequest(unit=0, address=1, value=3),
        register_message.WriteSingleRegisterRequest(address=1, registers=[3], dev_id=0),
    ),
    (
        mb.WriteCoilsRequest(
            unit=1, address=0x13, values=(True, False, True, True, False, False, True, True, True, False)
        ),
        bit_message.WriteMultipleCoilsRequest(
            address=0x13, bits=[True, False, True, True, False, False, True, True, True, False], dev_id=1
        ),
    ),
    (
        mb.WriteRegistersRequest(unit=1, address=1, values=(10, 258)),
        register_message.WriteMultipleRegistersRequest(address=1, registers=[10, 258], dev_id=1),
    ),
    (
        mb.MaskWriteRegisterRequest(unit=1, address=4, and_mask=0xF2, or_mask=0x25),
        register_message.MaskWriteRegisterRequest(address=4, and_mask=0xF2, or_mask=0x25, dev_id=1),
    ),
    (
        mb.ReadWriteRegistersRequest(unit=1, read_address=3, read_count=6, write_address=14, values=(0xFF, 0xFF, 0xFF)),
        register_message.ReadWriteMultipleRegistersRequest(
            read_address=3, read_count=6, write_address=14, write_registers=[0xFF, 0xFF, 0xFF], dev_id=1
        ),
    ),
    (
        mb.ReadHoldingRegistersResponse(unit=1, registers=(555, 0, 100)),
        register_message.ReadHoldingRegistersResponse(registers=[555, 0, 100], dev_id=1),
    ),
    (
        mb.ReadCoilsResponse(unit=1, coils=(True, False, True) + (False,) * 5 + (True,) + (False,) * 7),
        bit_message.ReadCoilsResponse(bits=[True, False, True] + [False] * 5 + [True] + [False] * 7, dev_id=1),
    ),
    (
        mb.WriteRegistersResponse(unit=1, address=1, count=2),
        register_message.WriteMultipleRegistersResponse(address=1, count=2, dev_id=1),
    ),
    (
        mb.ExceptionResponse(unit=1, function=3, exception_code=mb.ExceptionCode.ILLEGAL_DATA_ADDRESS),
        register_message.ExceptionResponse(0x03, 2, device_id=1),
    ),
]


@pytest.mark.parametrize(("ours", "theirs"), PAIRS, ids=[type(p[0]).__name__ for p in PAIRS])
def test_frames_are_the_ones_pymodbus_builds(ours: Any, theirs: Any) -> None:
    frame = peer_frame(theirs)
    assert mb.encode(ours) == frame
    assert mb.decode(frame, ours.DIRECTION) == ours


def test_the_specifications_frame_and_its_crc() -> None:
    frame = bytes.fromhex("01 03 00 00 00 0A C5 CD")
    assert mb.decode(frame, "request") == mb.ReadHoldingRegistersRequest(unit=1, address=0, count=10)
    with pytest.raises(ChecksumError):
        mb.decode(bytes.fromhex("01 03 00 00 00 0A CD C5"), "request")  # the CRC high byte first: wrong


def test_an_exception_reply_decodes_as_such() -> None:
    reply = mb.decode(bytes.fromhex("01 81 02 C1 91"), "response")
    assert reply == mb.ExceptionResponse(unit=1, function=1, exception_code=mb.ExceptionCode.ILLEGAL_DATA_ADDRESS)
    assert reply.to_fields() == {"unit": 1, "function": 1, "exception_code": 2}


def test_derived_values_are_checked_on_decode_and_limits_on_encode() -> None:
    frame = bytearray(mb.encode(mb.WriteRegistersRequest(unit=1, address=1, values=(10, 258))))
    frame[6] = 5  # byte_count 5 where 2 × count is 4; the CRC is made to fit
    crc = CRC(bytes(frame[:-2]))
    frame[-2:] = crc.to_bytes(2, "little")
    with pytest.raises(DecodeError, match="byte_count"):
        mb.decode(bytes(frame), "request")
    with pytest.raises(RangeError, match="count = 126 is outside its range 1..125"):
        mb.encode(mb.ReadHoldingRegistersRequest(unit=1, address=0, count=126))
    with pytest.raises(RangeError, match="count = 124"):
        mb.encode(mb.WriteRegistersRequest(unit=1, address=0, values=(0,) * 124))
    with pytest.raises(RangeError, match="unit = 248"):
        mb.encode(mb.ReadCoilsRequest(unit=248, address=0, count=1))


def CRC(data: bytes) -> int:  # noqa: N802 - the checksum the spec names, computed independently of the codec
    crc = 0xFFFF
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return crc


def sample_responses() -> list[bytes]:
    return [peer_frame(theirs) for ours, theirs in PAIRS if ours.DIRECTION == mb.Direction.RESPONSE]


def sample_requests() -> list[bytes]:
    return [peer_frame(theirs) for ours, theirs in PAIRS if ours.DIRECTION == mb.Direction.REQUEST]


@pytest.mark.parametrize("direction", ["request", "response"])
def test_back_to_back_frames_are_split_by_layout_and_crc(direction: str) -> None:
    """No gap, no header, no length: the parser must find where each frame ends from its function and byte count."""
    pool = sample_requests() if direction == "request" else sample_responses()
    rng = random.Random(12)
    frames = [rng.choice(pool) for _ in range(300)]
    stream = b"".join(frames)
    parser = mb.StreamParser(direction)
    found: list[Any] = []
    position = 0
    while position < len(stream):  # random read sizes, as a serial port delivers them
        size = rng.randint(1, 40)
        found += parser.feed(stream[position : position + size])
        position += size
    assert [mb.encode(m) for m in found] == frames
    assert parser.errors == 0 and parser.garbage == 0  # a frame cut by a read is no error, no garbage


@pytest.mark.parametrize("direction", ["request", "response"])
def test_noise_between_frames_is_skipped(direction: str) -> None:
    pool = sample_requests() if direction == "request" else sample_responses()
    rng = random.Random(7)
    frames = [rng.choice(pool) for _ in range(200)]
    # Noise that cannot start a frame (addresses 248..255 exist on no bus) and truncated frame starts.
    pieces = []
    for frame in frames:
        pieces.append(bytes(rng.randint(248, 255) for _ in range(rng.randint(0, 5))))
        if rng.random() < 0.3:
            broken = rng.choice(pool)
            pieces.append(broken[: rng.randint(1, len(broken) - 1)] + bytes([0xFF]))
        pieces.append(frame)
    parser = mb.StreamParser(direction)
    found = parser.feed(b"".join(pieces))
    assert [mb.encode(m) for m in found] == frames


def test_a_corrupt_frame_costs_only_itself() -> None:
    good = sample_requests()
    bad = bytearray(good[2])
    bad[3] ^= 0x40
    parser = mb.StreamParser("request")
    found = parser.feed(good[0] + bytes(bad) + good[1])
    assert [mb.encode(m) for m in found] == [good[0], good[1]]
    assert parser.errors >= 1


# --- the virtual server -------------------------------------------------------------------------------------------


def ask(simulator: ModbusRtuSimulator, request: Any) -> Any:
    """Feed a request to the virtual server; its one reply decoded, or None when it stays silent."""
    replies = simulator.feed(mb.encode(request))
    if not replies:
        return None
    assert len(replies) == 1
    return mb.decode(replies[0][1], "response")


def test_the_server_reads_what_was_written() -> None:
    server = ModbusRtuSimulator(ids=[1])
    assert ask(server, mb.WriteRegistersRequest(unit=1, address=100, values=(1, 2, 3))) == mb.WriteRegistersResponse(
        unit=1, address=100, count=3
    )
    assert ask(server, mb.ReadHoldingRegistersRequest(unit=1, address=99, count=5)).registers == (0, 1, 2, 3, 0)
    assert ask(server, mb.WriteRegisterRequest(unit=1, address=9999, value=0xBEEF)).value == 0xBEEF
    assert ask(server, mb.ReadHoldingRegistersRequest(unit=1, address=9999, count=1)).registers == (0xBEEF,)
    coils = (True, False, True, True, False, False, True, True, True, False)
    ask(server, mb.WriteCoilsRequest(unit=1, address=20, values=coils))
    ask(server, mb.WriteCoilRequest(unit=1, address=30, value=mb.CoilState.ON))
    reply = ask(server, mb.ReadCoilsRequest(unit=1, address=20, count=11))
    assert reply.coils[:11] == (*coils, True)
    ask(server, mb.WriteRegisterRequest(unit=1, address=4, value=0x12))
    ask(server, mb.MaskWriteRegisterRequest(unit=1, address=4, and_mask=0xF2, or_mask=0x25))
    assert ask(server, mb.ReadHoldingRegistersRequest(unit=1, address=4, count=1)).registers == (0x17,)  # app §6.16
    both = ask(
        server, mb.ReadWriteRegistersRequest(unit=1, read_address=13, read_count=3, write_address=14, values=(7, 8))
    )
    assert both.registers == (0, 7, 8)  # the write happens before the read


def test_the_server_refuses_with_the_specifications_exceptions() -> None:
    server = ModbusRtuSimulator(ids=[1], sizes={"holding_registers": 100})
    beyond = ask(server, mb.ReadHoldingRegistersRequest(unit=1, address=98, count=3))
    assert beyond == mb.ExceptionResponse(unit=1, function=3, exception_code=mb.ExceptionCode.ILLEGAL_DATA_ADDRESS)
    # a quantity outside its limits: neither our codec nor pymodbus builds it, so it is built here
    too_many = bytes.fromhex("01 03 00 00 00 7E")
    ((when, frame),) = server.feed(too_many + CRC(too_many).to_bytes(2, "little"))
    assert mb.decode(frame, "response") == mb.ExceptionResponse(
        unit=1, function=3, exception_code=mb.ExceptionCode.ILLEGAL_DATA_VALUE
    )
    bad_coil = bytes.fromhex("01 05 00 01 12 34")
    ((when, frame),) = server.feed(bad_coil + CRC(bad_coil).to_bytes(2, "little"))
    assert mb.decode(frame, "response").exception_code == mb.ExceptionCode.ILLEGAL_DATA_VALUE


def test_an_unsupported_function_is_refused_with_exception_1() -> None:
    """Function 0x2B (read device identification) is in no command: whole and with a good CRC, it is refused."""
    server = ModbusRtuSimulator(ids=[1])
    unknown = bytes.fromhex("01 2B 0E 01 00")
    ((when, frame),) = server.feed(unknown + CRC(unknown).to_bytes(2, "little"))
    assert mb.decode(frame, "response") == mb.ExceptionResponse(
        unit=1, function=0x2B, exception_code=mb.ExceptionCode.ILLEGAL_FUNCTION
    )
    assert server.feed(unknown + bytes(2)) == []  # a bad CRC: silence
    other = bytes.fromhex("07 2B 0E 01 00")
    assert server.feed(other + CRC(other).to_bytes(2, "little")) == []  # another server's


def test_broadcast_writes_reach_every_server_and_get_no_reply() -> None:
    server = ModbusRtuSimulator(ids=[1, 2])
    assert ask(server, mb.WriteRegisterRequest(unit=0, address=5, value=42)) is None
    assert ask(server, mb.ReadHoldingRegistersRequest(unit=1, address=5, count=1)).registers == (42,)
    assert ask(server, mb.ReadHoldingRegistersRequest(unit=2, address=5, count=1)).registers == (42,)
    assert ask(server, mb.ReadHoldingRegistersRequest(unit=3, address=5, count=1)) is None  # nobody at 3


# --- the generated client against the virtual server, over a pseudo-terminal ----------------------------------------


def test_the_client_reads_writes_and_names_exceptions() -> None:
    from serialspec.runtime.errors import DeviceError, Timeout
    from serialspec_protocols.modbus_rtu.client import ModbusRtuClient

    server = ModbusRtuSimulator(ids=[1, 2], sizes={"holding_registers": 200})
    path = server.start()
    try:
        # no parity and 2 stop bits: some kernels' pseudo-terminals refuse the default even parity
        with ModbusRtuClient(path, timeout=1.0, parity="N", stopbits=2) as client:
            assert client.write_registers(1, 10, [7, 8, 9]) == 3
            assert client.read_holding_registers(1, 9, 5) == [0, 7, 8, 9, 0]
            assert client.write_coils(2, 0, [True, False, True]) == 3
            assert client.read_coils(2, 0, 3) == [True, False, True]  # not padded to 8
            assert client.read_discrete_inputs(1, 0, 2) == [False, False]
            assert client.mask_write_register(1, 10, 0xF2, 0x25) is True
            assert client.read_write_registers(1, 10, 2, 100, [1]) == [7, 8]  # (7 & 0xF2) | (0x25 & ~0xF2) = 7
            with pytest.raises(DeviceError, match="read_holding_registers: .* illegal_data_address \\(2\\)"):
                client.read_holding_registers(1, 199, 2)
            with pytest.raises(RangeError, match="count = 126"):
                client.read_holding_registers(1, 0, 126)  # refused before a byte is written
            with pytest.raises(Timeout):
                client.read_holding_registers(3, 0, 1)  # no server 3
            assert client.write_register(0, 5, 99) is None  # broadcast: both servers, no reply
            assert client.read_holding_registers(2, 5, 1) == [99]
    finally:
        server.close()


def test_a_port_that_refuses_even_parity_is_a_port_error_naming_it() -> None:
    """The serial line specification's default is even parity; where a port refuses it, the error says so."""
    from serialspec.runtime.errors import PortError
    from serialspec_protocols.modbus_rtu.client import ModbusRtuClient

    server = ModbusRtuSimulator()
    path = server.start()
    try:
        try:
            client = ModbusRtuClient(path, timeout=1.0)
        except PortError as refused:  # pseudo-terminals of some kernels (gVisor's among them)
            assert "parity = even" in str(refused)
        else:
            with client:
                assert client.read_holding_registers(1, 0, 1) == [0]
    finally:
        server.close()
