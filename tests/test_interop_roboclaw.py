"""Basicmicro RoboClaw packet serial (specs/roboclaw.yaml) against basicmicro 2.0.10 from PyPI, unchanged.

The peer's packing code writes the golden frames (its controller on a stand-in port that records what is written and
plays back what it reads): our codec encodes the same bytes for its writes and reads, and the peer accepts our
replies (their CRC covers the request's address and command, which the reply does not carry); every example frame
of the spec is one the peer writes, or reads as the values the spec records. Then the peer's `Basicmicro` class
drives `serialspec sim specs/roboclaw.yaml` over a pseudo-terminal, and so does our client.
"""

from __future__ import annotations

import contextlib
import io
import json
from collections.abc import Iterator
from typing import Any

import pytest
from conftest import ROOT
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec import cli
from serialspec.lang import load_protocol
from serialspec.runtime.errors import DecodeError
from serialspec.runtime.transport import Bus
from serialspec_protocols import roboclaw as rc
from serialspec_protocols.roboclaw import client as rc_client

basicmicro = pytest.importorskip("basicmicro")

SIM = ("roboclaw.yaml", 0x80, 0x81)  # the `port` fixture (conftest.py): `serialspec sim` on a pseudo-terminal
SPEC = str(ROOT / "specs" / "roboclaw.yaml")


class Recorder:
    """A stand-in serial port: records what the peer writes, plays back `replies` to its reads."""

    is_open = True

    def __init__(self, replies: bytes = b"") -> None:
        self.written = bytearray()
        self.replies = bytearray(replies)

    def write(self, data: bytes) -> int:
        self.written += bytes(data)
        return len(data)

    def read(self, size: int = 1) -> bytes:
        data = bytes(self.replies[:size])
        del self.replies[:size]
        return data

    def flushInput(self) -> None:  # noqa: N802 (pyserial's old name, which the peer calls)
        pass

    def close(self) -> None:
        pass


def peer(replies: bytes = b"") -> Any:
    """The peer's controller on a Recorder (one try per call: a wrong reply is not sent again)."""
    controller = basicmicro.Basicmicro("/dev/null", 38400, retries=1)
    controller._port = Recorder(replies)
    controller._connected = True
    return controller


def written(call: Any, *args: Any, replies: bytes = b"\xff") -> bytes:
    controller = peer(replies)
    result = getattr(controller, call)(*args)
    assert result, f"{call}{args} failed: {result}"
    return bytes(controller._port.written)


ADDRESSES = st.integers(0x80, 0x87)
I16 = st.integers(-32767, 32767)
I32 = st.integers(-(2**31), 2**31 - 1)
U32 = st.integers(0, 2**32 - 1)


@settings(max_examples=60, deadline=None)
@given(ADDRESSES, I16, I16, I32, I32, st.integers(0, 2**31 - 1))
def test_peer_writes_encode_byte_for_byte(address: int, d1: int, d2: int, s1: int, s2: int, accel: int) -> None:
    assert written("DutyM1", address, d1) == rc.encode(rc.DutyM1Request(address=address, duty=d1))
    assert written("DutyM2", address, d2) == rc.encode(rc.DutyM2Request(address=address, duty=d2))
    assert written("SpeedM1", address, s1) == rc.encode(rc.SpeedM1Request(address=address, speed=s1))
    assert written("SpeedM2", address, s2) == rc.encode(rc.SpeedM2Request(address=address, speed=s2))
    frame = written("DutyAccelM1", address, accel, d1)
    assert frame == rc.encode(rc.DutyAccelM1Request(address=address, duty=d1, accel=accel))
    assert rc.decode(frame, "request") == rc.DutyAccelM1Request(address=address, duty=d1, accel=accel)
    assert written("ResetEncoders", address) == rc.encode(rc.ResetEncodersRequest(address=address))


@settings(max_examples=40, deadline=None)
@given(ADDRESSES, st.integers(0, 2**16 - 1), st.integers(0, 2**16 - 1), st.integers(0, 2**16 - 1), U32)
def test_peer_pid_write_and_read(address: int, p: int, i: int, d: int, qpps: int) -> None:
    """SetM1VelocityPID sends D, P, I, QPPS (16.16 fixed point gains); ReadM1VelocityPID reads P, I, D, QPPS."""
    scale = 65536.0
    frame = written("SetM1VelocityPID", address, p / scale, i / scale, d / scale, qpps)
    assert rc.decode(frame, "request") == rc.SetVelocityPidM1Request(address=address, d=d, p=p, i=i, qpps=qpps)
    request = rc.ReadVelocityPidM1Request(address=address)
    reply = rc.encode(rc.ReadVelocityPidM1Response(p=p, i=i, d=d, qpps=qpps), request)
    controller = peer(reply)
    assert controller.ReadM1VelocityPID(address) == (True, p / scale, i / scale, d / scale, qpps)
    assert bytes(controller._port.written) == rc.encode(request)  # address and command only: no CRC


@settings(max_examples=60, deadline=None)
@given(ADDRESSES, U32, st.integers(0, 255), st.integers(0, 2**16 - 1), U32)
def test_peer_accepts_our_replies(address: int, count: int, status: int, volts: int, error: int) -> None:
    """Each reply's CRC starts with the request's address and command: the peer checks it so."""
    cases = [
        (
            "ReadEncM1",
            rc.ReadEncoderM1Request,
            rc.ReadEncoderM1Response(count=count, status=status),
            (1, count, status),
        ),
        (
            "ReadEncM2",
            rc.ReadEncoderM2Request,
            rc.ReadEncoderM2Response(count=count, status=status),
            (1, count, status),
        ),
        ("ReadSpeedM1", rc.ReadSpeedM1Request, rc.ReadSpeedM1Response(speed=count, direction=status & 1), None),
        ("ReadMainBatteryVoltage", rc.ReadMainBatteryRequest, rc.ReadMainBatteryResponse(voltage=volts), (1, volts)),
        ("ReadLogicBatteryVoltage", rc.ReadLogicBatteryRequest, rc.ReadLogicBatteryResponse(voltage=volts), None),
        ("ReadError", rc.ReadErrorRequest, rc.ReadErrorResponse(status=error), (1, error)),
    ]
    for call, request_class, reply, expected in cases:
        request = request_class(address=address)
        frame = rc.encode(reply, request)
        controller = peer(frame)
        result = getattr(controller, call)(address)
        assert result[0], (call, frame.hex(" "))
        if expected is not None:
            assert tuple(result) == expected
        assert bytes(controller._port.written) == rc.encode(request)
        assert rc.decode(frame, "response", request=request) == reply
        # another controller's address or another command: the CRC no longer holds
        other = request_class(address=0x80 + (address + 1) % 8)
        with pytest.raises(DecodeError, match="bad crc"):
            rc.decode(frame, "response", request=other)


# Each example of the spec as the peer makes or takes it: (example, the peer's call, its arguments, what it returns)
PEER_EXAMPLES = [
    ("duty_m1_half_reverse", "DutyM1", (0x80, -16384), True),
    ("speed_m2", "SpeedM2", (0x81, 1000), True),
    ("set_velocity_pid_m1", "SetM1VelocityPID", (0x80, 1.5, 0.25, 0.0, 44000), True),
    ("reset_encoders", "ResetEncoders", (0x80,), True),
    ("read_main_battery_reply", "ReadMainBatteryVoltage", (0x80,), (1, 120)),
    ("read_encoder_m1_reply", "ReadEncM1", (0x80,), (1, 123456, 2)),
    ("read_version_reply", "ReadVersion", (0x80,), (True, "USB Roboclaw 2x7a v4.1.34\n")),
    ("read_velocity_pid_m1_reply", "ReadM1VelocityPID", (0x80,), (True, 1.5, 0.25, 0.0, 44000)),
]


@pytest.mark.parametrize(("name", "call", "args", "returns"), PEER_EXAMPLES, ids=[e[0] for e in PEER_EXAMPLES])
def test_every_example_is_a_frame_of_the_peer(name: str, call: str, args: tuple[Any, ...], returns: Any) -> None:
    """A request example is what the peer writes for the call; a reply example is read by the peer as the values
    the spec records, after it wrote the example request the reply names; the write acknowledgement is the one
    byte the peer's write waits for."""
    examples = {e.name: e for e in load_protocol(SPEC, "specs/roboclaw.yaml").examples}
    example = examples[name]
    if example.direction.value == "request":
        controller = peer(examples["write_ack"].frame)  # a write waits for the acknowledgement; a read for nothing
        result = getattr(controller, call)(*args)
        assert bytes(controller._port.written) == example.frame
    else:
        controller = peer(example.frame)
        result = getattr(controller, call)(*args)
        assert bytes(controller._port.written) == examples[example.request].frame
    assert result == returns
    # the other examples are the requests these replies name (checked above) and the acknowledgement (used above)
    others = set(examples) - {n for n, *_ in PEER_EXAMPLES}
    assert others == {e.request for e in examples.values() if e.request and e.name != "write_ack"} | {"write_ack"}


def test_version_string_ended_by_nul() -> None:
    request = rc.ReadVersionRequest(address=0x80)
    frame = rc.encode(rc.ReadVersionResponse(version="USB Roboclaw 2x7a v4.1.34\n"), request)
    assert frame.endswith(b"\n\x00" + frame[-2:])
    assert peer(frame).ReadVersion(0x80) == (True, "USB Roboclaw 2x7a v4.1.34\n")
    parser = rc.StreamParser("response")
    parser.expect(rc.ReadVersionResponse, request)
    assert [m for byte in frame for m in parser.feed(bytes([byte]))] == [rc.decode(frame, request=request)]


def test_write_acknowledged_by_one_byte() -> None:
    request = rc.DutyM1Request(address=0x82, duty=100)
    assert rc.encode(rc.DutyM1Response(), request) == b"\xff"
    assert rc.decode(b"\xff", request=request) == rc.DutyM1Response()
    with pytest.raises(DecodeError, match="longer than"):
        rc.decode(b"\xff\xff", request=request)


def test_a_reply_without_its_request_is_refused_in_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    frame = "00 78 c8 65"  # 12.0 V, answering 80 18
    with pytest.raises(DecodeError, match="give the request"):
        rc.decode(bytes.fromhex(frame), "response")
    assert cli.main(["decode", SPEC, frame, "--direction", "response"]) == 1
    err = capsys.readouterr().err.strip()
    assert err.endswith("give the request (--request HEX)") and "\n" not in err
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert cli.main(["decode", SPEC, frame, "--request", "80 18", "--json"]) == 0
    decoded = json.loads(out.getvalue())
    assert (decoded["command"], decoded["fields"]) == ("read_main_battery", {"voltage": 120})
    # the stream parser takes no reply while no request is pending: the bytes count as garbage
    parser = rc.StreamParser("response")
    assert parser.feed(bytes.fromhex(frame)) == []


def test_read_requests_carry_no_crc_and_codes_keep_to_their_layout() -> None:
    assert rc.encode(rc.ReadMainBatteryRequest(address=0x80)) == bytes.fromhex("80 18")
    with pytest.raises(DecodeError, match="shorter than the 4 bytes a write frame has besides its content"):
        rc.decode(bytes.fromhex("80 20"), "request")  # duty M1 is a write: it needs data and a CRC
    with pytest.raises(DecodeError, match="longer than the read frame"):
        rc.decode(bytes.fromhex("80 18 88 a1"), "request")  # 80 18 is a read: two bytes, no CRC (not a write's)
    with pytest.raises(DecodeError, match="bad crc"):
        rc.decode(bytes.fromhex("80 20 c0 00 4d ab"), "request")


@pytest.fixture
def controller(port: str) -> Iterator[Any]:
    device = basicmicro.Basicmicro(port, 38400, timeout=0.05, retries=1)
    assert device.Open()
    try:
        yield device
    finally:
        device.close()


def test_peer_drives_the_simulator(controller: Any) -> None:
    assert controller.ReadVersion(0x80) == (True, "USB Roboclaw 2x7a v4.1.34\n")
    assert controller.ReadMainBatteryVoltage(0x80) == (1, 120)
    assert controller.ReadLogicBatteryVoltage(0x81) == (1, 50)
    assert controller.ReadError(0x80) == (1, 0)
    assert controller.SpeedM1(0x80, -1500)
    assert controller.ReadSpeedM1(0x80) == (1, 1500, 1)
    assert controller.ReadSpeedM1(0x81) == (1, 0, 0)  # the other controller keeps its own state
    assert controller.SetM1VelocityPID(0x81, 2.0, 0.5, 0.25, 30000)
    assert controller.ReadM1VelocityPID(0x81) == (True, 2.0, 0.5, 0.25, 30000)
    assert controller.DutyM2(0x80, 12000)
    assert controller.DutyAccelM1(0x80, 500, -3000)
    assert controller.ResetEncoders(0x80)
    assert controller.ReadEncM1(0x80) == (1, 0, 0)


def test_our_client_drives_the_simulator(port: str) -> None:
    with Bus(port, rc_client.BINDING, timeout=1.0) as bus:
        client = rc_client.RoboclawClient(bus)
        assert client.read_version(0x81) == "USB Roboclaw 2x7a v4.1.34\n"
        assert client.read_main_battery(0x80) == 120
        assert client.speed_m2(0x81, 2500) is True
        assert client.read_speed_m2(0x81) == rc.ReadSpeedM2Response(speed=2500, direction=0)
        assert client.set_velocity_pid_m2(0x80, d=1, p=2, i=3, qpps=4000) is True
        assert client.read_velocity_pid_m2(0x80) == rc.ReadVelocityPidM2Response(p=2, i=3, d=1, qpps=4000)
        assert client.duty_m1(0x80, -32767) is True
        assert client.read_error(0x80) == 0
