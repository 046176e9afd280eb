"""The language's `device.presence` and `serial.baudrates`: resolved into the model, each mistake one line."""

from __future__ import annotations

from pathlib import Path

import pytest
from serialspec.lang import SpecErrors, load_protocol

ROOT = Path(__file__).resolve().parent.parent

BUS = """\
protocol: tinybus
title: Tiny bus
byte_order: little
serial: {baudrate: 9600, baudrates: [9600, 115200]}
framing:
  elements:
    header: {role: header, value: "AA 55"}
    id: {role: address, type: u8, range: [0, 254], broadcast: 254}
    code: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: sum, covers: [id, content]}
tables:
  regs:
    key: address
    entries:
      model_number: {key: 3, type: u16, access: r, default: 7}
commands:
  ping:
    code: 1
    request: {fields: {}}
    response: {fields: {}}
  read:
    code: 2
    request:
      fields:
        address: u8
        length: {type: u8, range: [1, 8]}
    response:
      fields:
        data: {type: bytes, size: rest, table: regs, start: request.address, size_from: request.length}
device:
  memory: regs
  model_entry: model_number
  presence:
    request: ping
    model: {request: read, fields: {address: 3, length: 2}, field: data}
"""


def errors_of(tmp_path: Path, text: str) -> list[str]:
    spec = tmp_path / "tinybus.yaml"
    spec.write_text(text, encoding="utf-8")
    with pytest.raises(SpecErrors) as failure:
        load_protocol(str(spec), "tinybus.yaml")
    return str(failure.value).splitlines()


def test_a_presence_resolves_into_the_model(tmp_path: Path) -> None:
    spec = tmp_path / "tinybus.yaml"
    spec.write_text(BUS, encoding="utf-8")
    protocol = load_protocol(str(spec))
    assert protocol.serial.baudrates == (9600, 115200)
    assert protocol.device is not None
    presence = protocol.device.presence
    assert presence is not None
    assert (presence.request, presence.id_field, presence.ids, presence.broadcast) == ("ping", "id", (0, 253), False)
    assert (presence.model_request, presence.model_fields, presence.model_field) == (
        "read",
        {"address": 3.0, "length": 2.0},
        "data",
    )
    assert presence.model_register is not None and presence.model_register.name == "model_number"


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (("request: ping", "request: pong"), "device.presence.request: unknown command 'pong' (or it has no request)"),
        (
            ("request: ping", "request: ping\n    ids: [0, 300]"),
            "device.presence.ids[1]: id 300 is outside the id range 0..254",
        ),
        (
            ("request: ping", "request: ping\n    ids: [9, 2]"),
            "device.presence.ids: the first id 9 is above the last 2",
        ),
        (
            ("request: ping", "request: ping\n    fields: {angle: 3}"),
            "device.presence.fields.angle: ping has no request field 'angle'",
        ),
        (
            ("request: ping", "request: ping\n    fields: {id: 3}"),
            "device.presence.fields.id: 'id' is the device id: `scan` sets it",
        ),
        (("field: data}", "field: blob}"), "device.presence.model.field: the reply to read has no field 'blob'"),
        (
            ("request: read, fields", "request: reed, fields"),
            "device.presence.model.request: unknown command 'reed' (or it has no request)",
        ),
        (
            ("  model_entry: model_number\n", ""),
            "device.presence.model.field: 'data' holds registers of regs: device.model_entry must name one of them",
        ),
        (
            ("baudrates: [9600, 115200]", "baudrates: [115200]"),
            "serial.baudrates: the default rate 9600 is not among them",
        ),
        (("baudrates: [9600, 115200]", "baudrates: [9600, 9600]"), "serial.baudrates: a rate is listed twice"),
        (("baudrates: [9600, 115200]", "baudrates: [9600, 0]"), "serial.baudrates[1]: 0 is outside the minimum 1"),
    ],
)
def test_each_presence_mistake_is_one_line(tmp_path: Path, change: tuple[str, str], expected: str) -> None:
    assert change[0] in BUS
    text = BUS.replace(change[0], change[1], 1)
    lines = errors_of(tmp_path, text)
    assert len(lines) == 1, lines
    assert lines[0].split(": ", 1)[1] == expected, lines[0]


def test_a_broadcast_presence_needs_a_broadcast_id(tmp_path: Path) -> None:
    text = BUS.replace(", broadcast: 254}", "}").replace("request: ping\n", "request: ping\n    broadcast: true\n", 1)
    assert errors_of(tmp_path, text) == [
        f"tinybus.yaml:{_line(text, 'broadcast: true')}:16: device.presence.broadcast: the device has no broadcast id "
        "(device.broadcast)"
    ]


def _line(text: str, needle: str) -> int:
    return next(number for number, line in enumerate(text.splitlines(), 1) if needle in line)


def test_every_shipped_bus_declares_how_to_find_its_devices() -> None:
    """The shipped specs whose documents give a presence request declare it; the RRC board (one board per port,
    answering no request that is only a presence check), NMEA 0183 (receivers talk on their own) and u-blox UBX (one
    receiver per port, which streams on its own; a MON-VER poll would do, but `scan` is for buses of ids) do not, nor
    does RoboClaw yet (its spec came from the library, whose ReadVersion would serve: not declared before `scan` is
    tried against replies read with their request)."""
    declared = {}
    for spec in sorted((ROOT / "specs").glob("*.yaml")):
        protocol = load_protocol(str(spec))
        presence = protocol.device.presence if protocol.device else None
        declared[protocol.name] = presence.request if presence else None
    assert declared == {
        "dynamixel_p2": "ping",
        "fashionstar_uart": "ping",
        "feetech_sms": "ping",
        "hiwonder_rrc": None,
        "modbus_ascii": "read_holding_registers",
        "modbus_rtu": "read_holding_registers",
        "nmea0183": None,
        "crsf": None,
        "roboclaw": "read_version",
        "mavlink_common": None,
        "ubx": None,
        "vesc": "fw_version",
    }
