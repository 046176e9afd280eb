"""Slamtec RPLIDAR A1/A2 (tests/specs/slamtec_rplidar.yaml), written from the user docs alone and checked against
rplidar-roboticia (module `rplidar`): the requests its RPLidar writes (A5 and the command; A5, the command, the size,
the payload and their XOR) decode and re-encode byte for byte, its get_info() and get_health() read our replies (the
descriptor A5 5A, size, send mode and data type, then the data, one frame here), and its scan (start() reading our
GET_HEALTH reply and SCAN descriptor, iter_measures() our five-byte measurements) reads the values we encoded.

Four layouts chosen by command: plain and payload requests, each with the descriptor-and-data response; the SCAN
descriptor alone (send mode 1, its size a plain value); the headerless measurements. Layouts chosen by command whose
frame values differ (the descriptor's `size` and `stream`, none in a measurement) gave every message the first
layout's values: decoding a measurement raised TypeError, encoding one a zip() error (a bug, fixed). The peer reads
GET_HEALTH's error_code high byte first; the protocol document's struct (and our spec) has it little-endian like
every other value. The stream parser cannot know that measurements follow a SCAN descriptor (a strict xfail)."""

from __future__ import annotations

import logging
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st

peer = pytest.importorskip("rplidar")

SPEC = Path(__file__).parent / "specs" / "slamtec_rplidar.yaml"


@pytest.fixture(scope="module")
def rp(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("rplidar"), "slamtec_rplidar")


class FakePort:
    """What the driver writes; each write releases the next of `replies` to be read."""

    def __init__(self, *replies: bytes) -> None:
        self.written = b""
        self.replies = list(replies)
        self.waiting = b""

    def write(self, data: bytes) -> None:
        self.written += data
        self.waiting += self.replies.pop(0) if self.replies else b""

    def read(self, size: int = 1) -> bytes:
        data, self.waiting = self.waiting[:size], self.waiting[size:]
        return data

    def inWaiting(self) -> int:  # noqa: N802 (pyserial's old name, which the peer calls)
        return len(self.waiting)

    def setDTR(self, value: bool) -> None:  # noqa: N802
        pass

    def flushInput(self) -> None:  # noqa: N802
        pass


def lidar(*replies: bytes) -> peer.RPLidar:
    sensor = peer.RPLidar.__new__(peer.RPLidar)  # no port opened
    sensor._serial = FakePort(*replies)
    sensor.logger = logging.getLogger("rplidar-peer")
    sensor._motor_speed, sensor.motor_running = peer.DEFAULT_MOTOR_PWM, False
    sensor.scanning, sensor.express_trame, sensor.express_data = [False, 0, "normal"], 32, False
    return sensor


@pytest.mark.parametrize(
    ("send", "name", "fields"),
    [
        (lambda s: s._send_cmd(peer.GET_INFO_BYTE), "GetInfoRequest", {}),
        (lambda s: s._send_cmd(peer.GET_HEALTH_BYTE), "GetHealthRequest", {}),
        (lambda s: s._send_cmd(peer.STOP_BYTE), "StopRequest", {}),
        (lambda s: s._send_cmd(peer.RESET_BYTE), "ResetRequest", {}),
        (lambda s: s._set_pwm(660), "SetMotorPwmRequest", {"pwm": 660}),
        (lambda s: s._send_payload_cmd(b"\x82", b"\x00" * 5), "ExpressScanRequest", {"reserved": b"\x00" * 4}),
    ],
)
def test_the_drivers_requests(rp: ModuleType, send: object, name: str, fields: dict[str, object]) -> None:
    sensor = lidar()
    send(sensor)  # type: ignore[operator]
    golden = sensor._serial.written
    message = getattr(rp, name)(**fields)
    assert rp.encode(message) == golden
    assert rp.decode(golden, rp.Direction.REQUEST) == message


@settings(max_examples=examples(15), deadline=None)
@given(
    model=st.integers(0, 255),
    firmware=st.tuples(st.integers(0, 255), st.integers(0, 255)),
    hardware=st.integers(0, 255),
    serial=st.binary(min_size=16, max_size=16),
)
def test_the_driver_reads_our_info(
    rp: ModuleType, model: int, firmware: tuple[int, int], hardware: int, serial: bytes
) -> None:
    reply = rp.encode(
        rp.InfoResponse(
            model=model, firmware_minor=firmware[1], firmware_major=firmware[0], hardware=hardware, serial_number=serial
        )
    )
    assert reply[:7] == bytes.fromhex("A5 5A 14 00 00 00 04")  # 20 bytes, a single response, data type 4
    info = lidar(reply).get_info()
    assert info == {"model": model, "firmware": firmware, "hardware": hardware, "serialnumber": serial.hex().upper()}


@pytest.mark.parametrize("status", [0, 1, 2])
def test_the_driver_reads_our_health(rp: ModuleType, status: int) -> None:
    reply = rp.encode(rp.HealthResponse(status=status, error_code=0x0102))
    assert reply == bytes([0xA5, 0x5A, 3, 0, 0, 0, 6, status, 0x02, 0x01])  # error_code little-endian, as documented
    got, error_code = lidar(reply).get_health()
    assert got == ["Good", "Warning", "Error"][status]
    assert error_code == 0x0201  # the peer reads it high byte first


def measurement(rp: ModuleType, start: bool, quality: int, angle_q6: int, distance_q2: int) -> object:
    return rp.MeasurementResponse(
        flags=rp.FlagsBits(quality=quality, not_start=int(not start), start=int(start)),
        angle=rp.AngleBits(angle_q6=angle_q6),
        distance_q2=distance_q2,
    )


@settings(max_examples=examples(20), deadline=None)
@given(
    points=st.lists(st.tuples(st.integers(0, 63), st.integers(0, 32767), st.integers(0, 65535)), min_size=1, max_size=4)
)
def test_the_driver_scans_our_measurements(rp: ModuleType, points: list[tuple[int, int, int]]) -> None:
    """start() reads our GET_HEALTH reply and SCAN descriptor, iter_measures() our measurements; each decodes and
    re-encodes alone (a headerless layout beside layouts with other frame values: the bug)."""
    nodes = [measurement(rp, i == 0, *point) for i, point in enumerate(points)]
    frames = [rp.encode(node) for node in nodes]
    descriptor = rp.encode(rp.ScanDescriptorResponse(size=5))
    assert descriptor == bytes.fromhex("A5 5A 05 00 00 40 81")
    health = rp.encode(rp.HealthResponse(status=0, error_code=0))
    measures = lidar(b"", health, descriptor + b"".join(frames)).iter_measures()  # PWM, GET_HEALTH, SCAN
    for i, (quality, angle_q6, distance_q2) in enumerate(points):
        assert next(measures) == (i == 0, quality, angle_q6 / 64, distance_q2 / 4)
        assert rp.decode(frames[i], rp.Direction.RESPONSE) == nodes[i]


@pytest.mark.xfail(
    strict=True,
    reason="language gap: RPLIDAR's SCAN answers one descriptor (A5 5A 05 00 00 40 81: send mode 1, each packet "
    "5 bytes) and then a stream of headerless 5-byte packets that only the descriptor before them announces; the "
    "language has no way to say that packets of a headerless layout follow a given reply, so the stream parser takes "
    "the earliest-ending candidate: 5A 05 00 00 40 inside the descriptor reads as a measurement",
)
def test_the_stream_parser_reads_a_scan(rp: ModuleType) -> None:
    nodes = [measurement(rp, i == 0, 15, 64 * i, 1000 + i) for i in range(3)]
    stream = bytes.fromhex("A5 5A 05 00 00 40 81") + b"".join(rp.encode(node) for node in nodes)
    parser = rp.StreamParser(rp.Direction.RESPONSE)
    assert parser.feed(stream) == [rp.ScanDescriptorResponse(size=5), *nodes]


def test_json_may_leave_out_a_value_whose_bit_fields_are_all_fixed(rp: ModuleType) -> None:
    """The descriptor's send mode and size bits are constants: the message class fills them in, and so does JSON
    (`serialspec encode --json`), as it once did not ("missing field 'mode'"); a bit field given is still checked."""
    message = rp.HealthResponse.from_fields({"status": 1, "error_code": 5})
    assert message == rp.HealthResponse(status=1, error_code=5)
    assert rp.ModeBits.from_fields({"size_top": 0}) == rp.ModeBits()
    with pytest.raises(ValueError, match=r"mode.send_mode = 1 is outside its range 0\.\.0"):
        rp.encode(rp.HealthResponse.from_fields({"mode": {"send_mode": 1}, "status": 1, "error_code": 5}))
