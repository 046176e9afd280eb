"""iRobot Create 2 / Roomba Open Interface (tests/specs/create2_oi.yaml), written from the user docs alone and checked
against pycreate2: the bytes its Create2 methods write (modes, drive, LEDs, songs, the digit display, sensor
requests) decode to its arguments and re-encode byte for byte; its SensorPacketDecoder reads our 80-byte packet 100
to the values we encoded; its serial interface asks the simulator for packets and decodes the replies, and our client
does too. The OI has no framing at all: requests are an opcode and data, sensor replies a packet's bytes alone,
sized by the request (replies without a code, each request `answered_by` its packet, packet 100 `default: true`).

pycreate2's erratum, for the record: its WHEEL_OVERCURRENT masks (main brush 0x02, right wheel 0x04, left 0x08)
are not the OI's (bit 1 reserved, main brush bit 2, right wheel bit 3, left wheel bit 4); the spec follows the OI."""

from __future__ import annotations

import contextlib
import importlib
import io
import struct
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from conftest import generate_afresh, simulated

pycreate2 = pytest.importorskip("pycreate2")
from pycreate2.create2api import Create2  # noqa: E402
from pycreate2.createSerial import SerialCommandInterface  # noqa: E402
from pycreate2.packets import SensorPacketDecoder  # noqa: E402

SPEC = Path(__file__).parent / "specs" / "create2_oi.yaml"


@pytest.fixture(scope="module")
def oi(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_afresh(SPEC, tmp_path_factory, "create2_oi")


class Recorder:
    """pycreate2's SerialCommandInterface.write, recording the bytes instead of sending them."""

    def __init__(self) -> None:
        self.frames: list[bytes] = []

    def write(self, opcode: int, data: tuple[int, ...] | None = None) -> None:
        message = (opcode, *(data or ()))
        self.frames.append(struct.pack("B" * len(message), *message))


class QuietCreate2(Create2):  # type: ignore[misc]
    """Create2 without its port and its goodbye (stop motors, LEDs off, sleeps) when collected."""

    def __del__(self) -> None:
        pass


def recorded(call: Any) -> list[bytes]:
    bot = QuietCreate2.__new__(QuietCreate2)
    bot.SCI, bot.sleep_timer, bot.song_list = Recorder(), 0, {}
    call(bot)
    return list(bot.SCI.frames)


@pytest.mark.parametrize(
    ("call", "name", "fields"),
    [
        (lambda bot: bot.start(), "StartRequest", {}),
        (lambda bot: bot.drive_direct(200, -100), "DriveDirectRequest", {"right_velocity": 200, "left_velocity": -100}),
        (lambda bot: bot.drive_direct(900, -900), "DriveDirectRequest", {"right_velocity": 500, "left_velocity": -500}),
        (lambda bot: bot.drive_pwm(-255, 17), "DrivePwmRequest", {"right_pwm": -255, "left_pwm": 17}),
        (lambda bot: bot.drive_stop(), "DriveDirectRequest", {"right_velocity": 0, "left_velocity": 0}),
        (
            lambda bot: bot.led(0x0F, 128, 255),
            "LedsRequest",
            {"led_bits": 0x0F, "power_color": 128, "power_intensity": 255},
        ),
        (lambda bot: bot.digit_led_ascii("abc"), "DigitLedsAsciiRequest", {"digits": "ABC "}),
    ],
)
def test_what_pycreate2_writes_decodes_and_re_encodes(
    oi: ModuleType, call: Any, name: str, fields: dict[str, Any]
) -> None:
    (frame,) = recorded(call)
    message = oi.decode(frame, oi.Direction.REQUEST)
    assert message == getattr(oi, name)(**fields)
    assert oi.encode(message) == frame


def test_songs_and_sensor_requests(oi: ModuleType) -> None:
    """safe() clears the song memory (a song and a play for each of songs 0..3) after the mode byte; a song of two
    notes is a group counted by its length byte; get_sensors asks for packet 100."""
    frames = recorded(lambda bot: (bot.safe(), bot.createSong(1, [60, 32, 62, 16]), bot.playSong(1)))
    messages = [oi.decode(frame, oi.Direction.REQUEST) for frame in frames]
    assert messages[0] == oi.SafeRequest()
    assert messages[1] == oi.SongRequest(song_number=0, notes=(oi.NotesItem(note=70, duration=0),))
    assert messages[2] == oi.PlayRequest(song_number=0)
    song = oi.SongRequest(song_number=1, notes=(oi.NotesItem(note=60, duration=32), oi.NotesItem(note=62, duration=16)))
    assert messages[-2:] == [song, oi.PlayRequest(song_number=1)]
    assert [oi.encode(m) for m in messages] == frames
    assert oi.encode(oi.SensorsAllRequest()) == bytes([142, 100])


def test_the_stream_parser_reads_sensor_requests(oi: ModuleType) -> None:
    """A code whose requests are sub-commands (142, then the packet id), with no length element: the parser dropped
    them as garbage (no size rule for a code with sub-commands), so the simulator never answered a sensor query."""
    stream = bytes([142, 22, 145, 0, 200, 255, 156, 142, 100, 128])
    for size in (1, 2, len(stream)):
        parser = oi.StreamParser(oi.Direction.REQUEST)
        got = [m for i in range(0, len(stream), size) for m in parser.feed(stream[i : i + size])]
        assert got == [
            oi.SensorsVoltageRequest(),
            oi.DriveDirectRequest(right_velocity=200, left_velocity=-100),
            oi.SensorsAllRequest(),
            oi.StartRequest(),
        ], size
        assert parser.garbage == 0


def test_the_peer_decodes_our_sensor_packet(oi: ModuleType) -> None:
    values = {name: 0 for name in oi.AllPacketResponse.__match_args__}
    values |= {
        "bumps": oi.Bumps.BUMP_LEFT | oi.Bumps.WHEEL_DROP_RIGHT,
        "wall": 1,
        "buttons": oi.Buttons.DOCK | oi.Buttons.CLOCK,
        "distance": -123,
        "angle": 45,
        "charging_state": oi.ChargingState.TRICKLE_CHARGING,
        "voltage": 14823,
        "current": -1200,
        "temperature": -5,
        "battery_charge": 2100,
        "battery_capacity": 2696,
        "cliff_right_signal": 4000,
        "charging_sources": oi.ChargingSources.HOME_BASE,
        "oi_mode": oi.OiMode.SAFE,
        "requested_right_velocity": -500,
        "left_encoder_counts": 65000,
        "light_bumper": oi.LightBumper.RIGHT,
        "light_bump_right_signal": 3000,
        "side_brush_motor_current": -7,
        "stasis": oi.Stasis.DISABLED,
        "unused_2": bytes(3),
    }
    frame = oi.encode(oi.AllPacketResponse(**values))
    assert len(frame) == 80
    peer = SensorPacketDecoder(frame)
    assert peer.bumps_wheeldrops == (False, True, True, False)  # bits 0..3 (pycreate2 calls bit 0 bump_left)
    assert (peer.wall, peer.distance, peer.angle, peer.charger_state) == (True, -123, 45, 3)
    assert (peer.voltage, peer.current, peer.temperature) == (14823, -1200, -5)
    assert (peer.battery_charge, peer.battery_capacity, peer.cliff_right_signal) == (2100, 2696, 4000)
    assert peer.buttons.dock and peer.buttons.clock and not peer.buttons.clean
    assert peer.charger_available == (False, True) and peer.open_interface_mode == 2
    assert (peer.velocity_right, peer.encoder_counts_left) == (-500, 65000)
    assert peer.light_bumper.right and peer.light_bumper_right == 3000
    assert peer.side_brush_current == -7 and peer.statis.disabled
    assert oi.decode(frame, oi.Direction.RESPONSE) == oi.AllPacketResponse(**values)


def test_the_peer_and_our_client_read_the_simulated_robot(oi: ModuleType) -> None:
    with simulated("create2_oi") as path:
        interface = SerialCommandInterface()
        with contextlib.redirect_stdout(io.StringIO()):  # it prints a banner on open
            interface.open(path, timeout=2)
        try:
            interface.write(128)
            interface.write(142, (100,))
            sensors = SensorPacketDecoder(interface.read(80))
            interface.write(142, (22,))
            (voltage,) = struct.unpack(">H", interface.read(2))
        finally:
            interface.close()
        assert (sensors.voltage, sensors.open_interface_mode, sensors.temperature) == (14800, 1, 25)
        assert (sensors.battery_charge, sensors.battery_capacity, voltage) == (2500, 2696, 14800)
        client_module = importlib.import_module("create2_oi.client")
        client_class = next(v for k, v in vars(client_module).items() if k.endswith("Client") and k != "ClientBase")
        with client_class(path, timeout=2.0) as client:
            client.start()
            assert client.sensors.voltage() == 14800
            assert client.sensors.oi_mode() == oi.OiMode.PASSIVE
            assert client.sensors.all().battery_capacity == 2696
