"""Benewake TFmini data frames (tests/specs/tfmini.yaml), written from the user docs alone and checked against
Adafruit's TFmini driver (adafruit-circuitpython-tfmini, which takes a pyserial port): it reads the frames we encode
and the ones `serialspec sim` streams, and our decoder reads frames built by the driver's own unpacking rules. The
configuration commands (a second layout, the command byte after the parameters) are added below, each command naming
its layout (`layout:`)."""

from __future__ import annotations

import struct
from pathlib import Path
from types import ModuleType

import pytest
import serial
from conftest import generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from sim_process import serve

adafruit_tfmini = pytest.importorskip("adafruit_tfmini")

SPEC = Path(__file__).parent / "specs" / "tfmini.yaml"


@pytest.fixture(scope="module")
def tf(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("tfmini"), "tfmini")


def driver_frame(distance: int, strength: int, mode: int, spare: int) -> bytes:
    """A frame the driver accepts: 59, then "<BHHBBB" (59, distance, strength, mode, spare, checksum), the checksum
    the sum of the 8 bytes before it."""
    body = b"\x59" + struct.pack("<BHHBB", 0x59, distance, strength, mode, spare)
    return body + bytes([sum(body) & 0xFF])


class FakeUart:
    """What the driver reads from: the bytes given, as a pyserial-like port."""

    def __init__(self, data: bytes) -> None:
        self.data, self.baudrate = data, 0

    def reset_input_buffer(self) -> None:
        pass

    def read(self, n: int) -> bytes:
        out, self.data = self.data[:n], self.data[n:]
        return out


@settings(max_examples=200, deadline=None)
@given(
    distance=st.integers(0, 0xFFFF),
    strength=st.integers(0, 0xFFFF),
    mode=st.sampled_from([2, 7]),
    spare=st.integers(0, 255),
)
def test_frames_match_the_driver(tf: ModuleType, distance: int, strength: int, mode: int, spare: int) -> None:
    golden = driver_frame(distance, strength, mode, spare)
    message = tf.MeasurementResponse(distance=distance, strength=strength, mode=mode, spare=spare)
    assert tf.encode(message) == golden
    assert tf.decode(golden, tf.Direction.RESPONSE) == message
    sensor = adafruit_tfmini.TFmini(FakeUart(tf.encode(message)), timeout=0.5)
    assert sensor.distance == distance
    assert sensor._strength == strength and sensor._mode == mode


def test_the_driver_reads_the_sim() -> None:
    with serve(str(SPEC)) as path, serial.Serial(path, 115200, timeout=1) as port:
        sensor = adafruit_tfmini.TFmini(port, timeout=5)
        assert sensor.distance == 123
        assert sensor.strength == 800
        assert sensor.mode == adafruit_tfmini.MODE_SHORT


def test_the_generated_client_reads_the_sim_stream(tf: ModuleType) -> None:
    import importlib

    client_module = importlib.import_module("tfmini.client")
    with serve(str(SPEC)) as path, client_module.TfminiClient(path) as sensor:
        report = next(iter(sensor.reports(timeout=5)))
        assert (report.distance, report.strength, report.mode) == (123, 800, 2)


CONFIG = """
framing:
  layouts:
    data:
      elements:
        header: {role: header, value: "59 59"}
        content: {role: content}
        checksum: {role: checksum, type: u8, algorithm: sum, covers: [header, content]}
    config:
      elements:
        header: {role: header, value: {request: "42 57 02 00", response: "42 57 02 01"}}
        content: {role: content}
        command: {role: command, type: u8}
"""
CONFIG_COMMANDS = """
  config_mode:
    code: 0x02
    request: {fields: {parameter: {type: u16, const: 0}, enter: {type: u8, range: [0, 1]}}}
    response: {fields: {parameter: {type: u16, const: 0}, enter: {type: u8, range: [0, 1]}}}
  set_mode:
    code: 0x11
    request: {fields: {parameter: {type: u16, const: 0}, mode: {type: u8, enum: mode}}}
    response: {fields: {parameter: {type: u16, const: 0}, mode: {type: u8, enum: mode}}}
"""


def full_spec(tmp_path: Path) -> Path:
    """The TFmini spec with its configuration commands: a second layout, with a command byte after the content."""
    text = SPEC.read_text("utf-8")
    start, end = text.index("framing:"), text.index("enums:")
    text = text[:start] + CONFIG.lstrip() + text[end:]
    text = text.replace("commands:\n", "commands:" + CONFIG_COMMANDS, 1)
    spec = tmp_path / "tfmini.yaml"
    spec.write_text(text, "utf-8")
    return spec


def test_layouts_that_differ_in_having_a_command_are_one_line_naming_them(tmp_path: Path) -> None:
    """Found writing this spec: the loader said `commands.config_mode.code: its frames have no command field` (or,
    with the layouts the other way round, that `measurement` lacks a code), judging by the first layout alone."""
    from serialspec.lang import SpecErrors, load_protocol

    with pytest.raises(SpecErrors) as caught:
        load_protocol(str(full_spec(tmp_path)), "tfmini.yaml")
    lines = str(caught.value).splitlines()
    assert len(lines) == 1, lines
    assert lines[0].endswith(
        ": framing.layouts: alternative layouts must all have a command element or none (config has one, data has none)"
        ", unless each command names its layout (`layout:`)"
    )


def by_layout(spec: Path) -> Path:
    """The full spec with each command naming its layout (`layout:`): the data frames carry no command byte, the
    configuration frames one after their parameters."""
    text = spec.read_text("utf-8")
    text = text.replace("  measurement:\n", "  measurement:\n    layout: data\n", 1)
    for code in ("0x02", "0x11"):
        text = text.replace(f"    code: {code}\n", f"    code: {code}\n    layout: config\n", 1)
    spec.write_text(text, "utf-8")
    return spec


def test_the_configuration_commands_beside_the_data_frames(tmp_path: Path) -> None:
    """Found writing this spec (issue 21): with `layout:` on each command, the data frames (59 59, no command byte)
    and the configuration frames (42 57 02 00, parameters, the command byte last) share one spec; each frame is told
    apart by its header, read whole by the stream parser however the bytes come, and the driver still reads the data
    frames among configuration echoes."""
    from serialspec.lang import load_protocol

    spec = by_layout(full_spec(tmp_path))
    protocol = load_protocol(str(spec), "tfmini.yaml")
    assert {c.name for c in protocol.commands} >= {"measurement", "config_mode", "set_mode"}
    spec.write_text(spec.read_text("utf-8").replace("protocol: tfmini\n", "protocol: tfmini_full\n"), "utf-8")
    tf = generate_and_import(spec, tmp_path / "out", "tfmini_full")  # not the data frames' package of the fixture
    assert tf.encode(tf.SetModeRequest(mode=tf.Mode.LONG)) == bytes.fromhex("42 57 02 00 00 00 07 11")
    assert tf.encode(tf.ConfigModeResponse(enter=1)) == bytes.fromhex("42 57 02 01 00 00 01 02")
    data = driver_frame(100, 800, 2, 0)
    assert tf.decode(data, tf.Direction.RESPONSE) == tf.MeasurementResponse(distance=100, strength=800, mode=2, spare=0)
    echoes = [tf.SetModeResponse(mode=tf.Mode.SHORT), tf.ConfigModeResponse(enter=0)]
    stream = data + tf.encode(echoes[0]) + data + tf.encode(echoes[1]) + data
    for size in range(1, len(stream) + 1):
        parser, got = tf.StreamParser(tf.Direction.RESPONSE), []
        for at in range(0, len(stream), size):
            got += parser.feed(stream[at : at + size])
        assert [type(m) for m in got] == [
            tf.MeasurementResponse,
            tf.SetModeResponse,
            tf.MeasurementResponse,
            tf.ConfigModeResponse,
            tf.MeasurementResponse,
        ], size


PLUS = """protocol: tfmini_plus
title: Benewake TFmini Plus commands
byte_order: little
serial: {baudrate: 115200}
framing:
  elements:
    head: {role: header, value: 5A}
    len: {role: length, type: u8, counts: [head, checksum], description: The whole frame's length.}
    id: {role: command, type: u8}
    payload: {role: content}
    checksum: {role: checksum, type: u8, algorithm: sum, covers: [head, payload]}
commands:
  version:
    code: 0x01
    request: {}
    response: {fields: {patch: u8, minor: u8, major: u8}}
  frame_rate:
    code: 0x03
    request: {fields: {rate: u16}}
    response: {fields: {rate: u16}}
examples:
  version:
    source: TFmini Plus product manual, obtain firmware version
    direction: request
    printed: 5A 04 01 5F
    command: version
    fields: {}
  rate:
    source: TFmini Plus product manual, frame rate 100 Hz
    direction: request
    printed: 5A 06 03 64 00 C7
    command: frame_rate
    fields: {rate: 100}
"""


def test_a_length_counting_the_whole_frame_from_its_header(tmp_path: Path) -> None:
    """The TFmini Plus's commands give the whole frame's length after the 5A header (`counts: [head, checksum]`): it
    was refused (`the length must come before what it counts`), though a length counting itself was taken."""
    spec = tmp_path / "tfmini_plus.yaml"
    spec.write_text(PLUS, "utf-8")
    plus = generate_and_import(spec, tmp_path / "out", "tfmini_plus")
    assert plus.encode(plus.FrameRateRequest(rate=100)) == bytes.fromhex("5A 06 03 64 00 C7")
    reply = plus.encode(plus.VersionResponse(patch=3, minor=1, major=2))
    assert reply == bytes.fromhex("5A 07 01 03 01 02 68")
    parser = plus.StreamParser(plus.Direction.RESPONSE)
    assert parser.feed(reply[2:] + reply + reply[:3]) == [plus.VersionResponse(patch=3, minor=1, major=2)]
