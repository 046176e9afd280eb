"""Strict encode of the field kinds beyond numbers: bit lists (Modbus coils), lists whose count varies, text and
NUL-terminated text. Each wrong value is refused with one line naming the field, from data (the CLI, as a process),
in messages built in Python, and in clients before a byte is written."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import ALL, ROOT
from serialspec.runtime.errors import DecodeError, EncodeError
from test_captures import pty_pair
from test_strict_encode import nothing_written

MODBUS = next(g for g in ALL if g.protocol.name == "modbus_rtu")
VESC = next(g for g in ALL if g.protocol.name == "vesc")
CLI = [str(Path(sys.executable).parent / "serialspec")]

COILS = {"unit": 1, "address": 0}
FW = {"major": 1, "minor": 2, "uuid": "00" * 12, "pairing_done": 0, "test_version": 0, "hw_type": 0}
FW |= {"custom_config_count": 0, "phase_filters": 0, "qml_hw": 0, "qml_app": 0, "nrf_flags": 0, "hw_crc": 0}
FW |= {"hw_name": "hw", "fw_name": "fw"}

# (generated package, command, direction, fields, words the one line holds)
CASES: list[tuple[Any, str, str, dict[str, Any], str]] = [
    (MODBUS, "write_coils", "request", {**COILS, "values": "abc"}, "values must be a list, got 'abc'"),
    (
        MODBUS,
        "write_coils",
        "request",
        {**COILS, "values": [1, 2]},
        "values[1] must be a bit (true/false or 0/1), got 2",
    ),
    (MODBUS, "write_coils", "request", {**COILS, "values": [True, 1.0]}, "values[1] must be a bit"),
    (MODBUS, "write_coils", "request", {**COILS, "values": [None]}, "values[0] must be a bit"),
    (MODBUS, "write_coils", "request", {**COILS, "values": [True] * 1969}, "count = 1969 is outside its range 1..1968"),
    (MODBUS, "write_registers", "request", {**COILS, "values": "ab"}, "values must be a list, got 'ab'"),
    (MODBUS, "write_registers", "request", {**COILS, "values": [1, True]}, "values[1] must be an integer, got True"),
    (MODBUS, "write_registers", "request", {**COILS, "values": [1, 70000]}, "values[1] = 70000 is outside its range"),
    (MODBUS, "write_registers", "request", {**COILS, "values": [0] * 124}, "count = 124 is outside its range 1..123"),
    (MODBUS, "read_coils", "response", {"unit": 1, "coils": [True] * 2001}, "coils has 2001 items, at most 2000"),
    (MODBUS, "read_coils", "response", {"unit": 1, "coils": "xyz"}, "coils must be a list, got 'xyz'"),
    (VESC, "print", "response", {"text": 5}, "text must be text, got 5"),
    (VESC, "print", "response", {"text": ["a"]}, "text must be text, got ['a']"),
    (VESC, "print", "response", {"text": "\ud800"}, "text is not UTF-8 text"),
    (VESC, "fw_version", "response", {**FW, "hw_name": "a\0b"}, "hw_name holds a NUL"),
    (VESC, "fw_version", "response", {**FW, "fw_name": None}, "fw_name must be text, got None"),
]
IDS = [f"{c[1]}-{c[4][:24]}" for c in CASES]


def message_class(g: Any, command: str, direction: str) -> Any:
    return next(c for c in g.package.MESSAGE_TYPES if (c.COMMAND, c.DIRECTION.value) == (command, direction))


@pytest.mark.parametrize(("g", "command", "direction", "fields", "words"), CASES, ids=IDS)
def test_from_data(g: Any, command: str, direction: str, fields: dict[str, Any], words: str) -> None:
    with pytest.raises(EncodeError) as failure:
        g.package.encode(message_class(g, command, direction).from_fields(fields))
    assert words in str(failure.value) and "\n" not in str(failure.value)


@pytest.mark.parametrize(("g", "command", "direction", "fields", "words"), CASES, ids=IDS)
def test_built_in_python(g: Any, command: str, direction: str, fields: dict[str, Any], words: str) -> None:
    """The same values given to the message class directly (bytes for hex text, tuples for lists)."""
    cls = message_class(g, command, direction)
    values = {k: bytes.fromhex(v) if k == "uuid" else tuple(v) if isinstance(v, list) else v for k, v in fields.items()}
    values = {k: v for k, v in values.items() if k in cls.__match_args__}
    with pytest.raises(EncodeError) as failure:
        g.package.encode(cls(**values))
    text = str(failure.value)
    field = words.split("[")[0].split(" ")[0]
    assert (field in text or "count" in text) and "\n" not in text, text


def test_the_good_values_still_encode() -> None:
    cls = message_class(MODBUS, "write_coils", "request")
    frame = MODBUS.package.encode(cls.from_fields({**COILS, "values": [True, 0, 1, False]}))
    assert frame.hex()[:16] == "010f000000040105"
    response = message_class(MODBUS, "read_coils", "response")
    assert MODBUS.package.encode(response.from_fields({"unit": 1, "coils": [True] * 2000}))
    fw = message_class(VESC, "fw_version", "response")
    assert VESC.package.encode(fw.from_fields({**FW, "hw_name": "naïve"}))


def test_the_cli_as_a_process() -> None:
    """One case per kind through `serialspec encode` run as a process: exit 1, one line on stderr, nothing out."""
    chosen = [CASES[1], CASES[6], CASES[9], CASES[11], CASES[14]]
    runs = []
    for g, command, direction, fields, words in chosen:
        obj = json.dumps({"command": command, "direction": direction, "fields": fields})
        spec = str(ROOT / g.protocol.spec_path)
        argv = [*CLI, "encode", spec, "--json", obj]
        runs.append((subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True), words))
    for process, words in runs:
        out, err = process.communicate(timeout=60)
        assert (process.returncode, out) == (1, ""), err
        assert len(err.splitlines()) == 1 and words in err and "Traceback" not in err, err


@pytest.fixture
def line() -> Iterator[tuple[int, str]]:
    with pty_pair() as pair:
        yield pair


@pytest.mark.parametrize(
    ("method", "values", "words"),
    [
        ("write_coils", "1010", "values must be a list of bits"),
        ("write_coils", (1, 2), "values[1] must be a bit"),
        ("write_registers", (1, True), "values[1] must be a number in 0..65535, got True"),
        ("write_registers", (0,) * 124, "count = 124 is outside"),
    ],
)
def test_client_refuses_before_writing(line: tuple[int, str], method: str, values: Any, words: str) -> None:
    from serialspec_protocols.modbus_rtu.client import ModbusRtuClient

    controller, path = line
    with ModbusRtuClient(path, timeout=0.05) as client, pytest.raises(EncodeError) as failure:
        getattr(client, method)(1, 0, values)
    assert words in str(failure.value) and "\n" not in str(failure.value)
    assert nothing_written(controller)


# --- decode: frame-level values outside their declared range ----------------------------------------------------

RANGED = [
    (g, e, element)
    for g in ALL
    for e in g.protocol.examples
    for element in g.protocol.framing.layouts[e.direction].value_elements
    if element.type is not None and (element.minimum, element.maximum) != (element.type.minimum, element.type.maximum)
]
# one example per protocol and direction is enough: the check is per frame layout
RANGED = list({(g.protocol.name, e.direction, el.name): (g, e, el) for g, e, el in RANGED}.values())


def out_of_range_frame(g: Any, example: Any, element: Any) -> tuple[bytes, int]:
    """The example's frame with `element` just past its range, every length and checksum still right."""
    bad = int(element.maximum) + 1
    if bad == element.broadcast:
        bad += 1
    if bad > element.type.maximum:
        bad = int(element.minimum) - 1
    layout = g.protocol.framing.layouts[example.direction]
    if not g.protocol.framing.classic:  # the frame engine wraps the same content with the bad value
        frames = getattr(g.package.codec, f"_{example.direction.name}_FRAMES")
        parts = frames.unwrap(example.frame)
        values = tuple(bad if v.name == element.name else parts.values[i] for i, v in enumerate(layout.value_elements))
        return frames.wrap(parts.content, parts.code, values), bad
    assert g.protocol.name == "feetech_sms", "a classic codec with ranged values: give its checksum here"
    frame = bytearray(example.frame)
    frame[layout.offsets[element.name]] = bad
    frame[-1] = ~sum(frame[2:-1]) & 0xFF  # FEETECH: the complement of the sum after the header
    return bytes(frame), bad


@pytest.mark.parametrize(("g", "example", "element"), RANGED, ids=[f"{g.protocol.name}-{e.name}" for g, e, _ in RANGED])
def test_decode_refuses_a_frame_value_out_of_range(g: Any, example: Any, element: Any) -> None:
    """decode says why in one line; the stream parser, which sees no frame there, agrees."""
    frame, bad = out_of_range_frame(g, example, element)
    with pytest.raises(DecodeError) as failure:
        g.package.decode(frame, example.direction.value)
    text = str(failure.value)
    assert f"{element.name} = {bad} is outside its range {int(element.minimum)}..{int(element.maximum)}" in text
    assert "\n" not in text
    assert g.package.StreamParser(example.direction.value).feed(frame) == []
    assert g.package.decode(example.frame, example.direction.value)  # the example itself still decodes


def test_decode_at_the_cli_as_a_process() -> None:
    g, example, element = next(r for r in RANGED if r[0].protocol.name == "feetech_sms")
    frame, bad = out_of_range_frame(g, example, element)
    spec = str(ROOT / g.protocol.spec_path)
    argv = [*CLI, "decode", spec, "--direction", example.direction.value, frame.hex(" ")]
    result = subprocess.run(argv, capture_output=True, text=True, timeout=60)
    assert (result.returncode, result.stdout) == (1, ""), result.stderr
    assert f"id = {bad} is outside its range 0..253 (or 254)" in result.stderr
    assert len(result.stderr.splitlines()) == 1


def test_encode_names_the_broadcast_value_beside_the_range() -> None:
    g = next(r[0] for r in RANGED if r[0].protocol.name == "feetech_sms")
    request = g.package.messages.PingRequest(id=255)
    with pytest.raises(EncodeError) as failure:
        g.package.encode(request)
    assert str(failure.value) == "ping request: id = 255 is outside its range 0..253 (or 254)"
    assert g.package.encode(g.package.messages.PingRequest(id=254))  # the broadcast id itself is allowed


# --- clients: a device model's ranges (spec: device.models.<model>.entries.<entry>.range) -------------------------


def drain(controller: int) -> bytes:
    data = b""
    while not nothing_written(controller):
        data += os.read(controller, 4096)
    return data


def test_client_checks_writes_against_the_model(line: tuple[int, str]) -> None:
    """The XL430-W250 has no current control (goal_current 0..0): refused before a byte is written; the table's
    range (the XM430-W350's, the default) takes 1000; a mixed bus names a model per id, a broadcast suits all."""
    from serialspec_protocols.dynamixel_p2.client import DynamixelP2Client

    controller, path = line
    with DynamixelP2Client(path, timeout=0.05, optional_replies=False, model="xl430_w250") as client:
        with pytest.raises(EncodeError) as failure:
            client.write(1, goal_current=1000)
        assert str(failure.value) == "control_table (xl430_w250): goal_current = 1000 is outside its range 0..0"
        with pytest.raises(EncodeError, match=r"max_voltage_limit = 160 is outside its range 60\.\.140"):
            client.sync_write({1: {"max_voltage_limit": 160}, 2: {"max_voltage_limit": 100}})
        assert nothing_written(controller)
        client.write(1, max_voltage_limit=140)
        assert drain(controller)
    with DynamixelP2Client(path, timeout=0.05, optional_replies=False) as client:  # no model: the table's ranges
        client.write(1, goal_current=1000)
        assert drain(controller)
    mixed = {1: "xl430_w250", 2: "xl330_m288"}
    with DynamixelP2Client(path, timeout=0.05, optional_replies=False, model=mixed) as client:
        with pytest.raises(EncodeError, match="xl430_w250"):
            client.write(1, goal_current=5)
        with pytest.raises(EncodeError, match=r"xl330_m288\): goal_current = 1751 is outside its range -1750\.\.1750"):
            client.bulk_write({2: {"goal_current": 1751}})
        with pytest.raises(EncodeError, match="xl430_w250"):
            client.write(254, goal_current=5)  # the broadcast reaches the XL430 too
        assert nothing_written(controller)
        client.write(2, goal_current=1750)
        client.write(3, goal_current=1000)  # a device of no named model: the table's ranges
        assert drain(controller)


def test_client_refuses_an_unknown_model(line: tuple[int, str]) -> None:
    from serialspec_protocols.dynamixel_p2.client import DynamixelP2Client

    with pytest.raises(ValueError, match=r"model 'xl999' is not one of the spec's models \(xm430_w350, "):
        DynamixelP2Client(line[1], model={1: "xl999"})
