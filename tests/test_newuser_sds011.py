"""Nova Fitness SDS011 dust sensor (tests/specs/nova_sds011.yaml), written from the user docs alone and checked
against py-sds011 (module `sds011`): the commands its SDS011 class writes decode as our requests and re-encode byte
for byte, and its query() reads our report as the PM values we encoded. The protocol's printed frames are the spec's
examples. Commands (AA B4, the sub-command, ...), their replies (AA C5, the sub-command, ...) and reports (AA C0, no
sub-command) are three layouts chosen by command. A big-endian device id after little-endian PM values in one
message was decoded and encoded little-endian by the Python codec (one struct for the run): a bug, fixed."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import DecodeError

peer = pytest.importorskip("sds011")

SPEC = Path(__file__).parent / "specs" / "nova_sds011.yaml"


@pytest.fixture(scope="module")
def nova(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("sds011"), "nova_sds011")


class FakePort:
    """What the driver writes, and the bytes it reads."""

    def __init__(self, reply: bytes = b"") -> None:
        self.written = b""
        self.reply = reply

    def write(self, data: bytes) -> None:
        self.written += data

    def read(self, size: int = 1) -> bytes:
        data, self.reply = self.reply[:size], self.reply[size:]
        return data


def driver(reply: bytes = b"") -> object:
    sensor = peer.SDS011.__new__(peer.SDS011)  # no port opened
    sensor.ser = FakePort(reply)
    return sensor


@pytest.mark.parametrize(
    ("call", "name", "fields"),
    [
        (lambda s: s.set_report_mode(active=False), "SetReportingModeRequest", {"set": 1, "mode": 1}),
        (lambda s: s.set_report_mode(read=True, active=True), "SetReportingModeRequest", {"set": 0, "mode": 0}),
        (lambda s: s.sleep(), "SetSleepRequest", {"set": 1, "state": 0}),
        (lambda s: s.sleep(sleep=False), "SetSleepRequest", {"set": 1, "state": 1}),
        (lambda s: s.set_work_period(work_time=5), "SetWorkingPeriodRequest", {"set": 1, "period": 5}),
        (lambda s: s.query(), "QueryDataRequest", {}),
    ],
)
def test_the_drivers_commands(nova: ModuleType, call: object, name: str, fields: dict[str, int]) -> None:
    sensor = driver()
    call(sensor)  # type: ignore[operator]
    golden = sensor.ser.written  # type: ignore[attr-defined]
    message = nova.decode(golden, nova.Direction.REQUEST)
    assert type(message).__name__ == name
    assert {k: int(v) for k, v in message.to_fields().items() if k in fields} == fields
    assert message.device_id == 0xFFFF and set(bytes(message.reserved)) == {0}
    assert nova.encode(message) == golden


@settings(max_examples=examples(25), deadline=None)
@given(pm25=st.integers(0, 65535), pm10=st.integers(0, 65535), device_id=st.integers(0, 65535))
def test_the_driver_reads_our_reports(nova: ModuleType, pm25: int, pm10: int, device_id: int) -> None:
    report = nova.encode(nova.ReportResponse(pm25=pm25, pm10=pm10, device_id=device_id))
    assert report[-2] == sum(report[2:8]) & 0xFF  # the sum of the six data bytes, as the driver checks it
    assert driver(report).query() == (pm25 / 10, pm10 / 10)  # type: ignore[attr-defined]
    assert nova.decode(report, nova.Direction.RESPONSE) == nova.ReportResponse(pm25, pm10, device_id)


def test_the_device_id_is_sent_as_printed(nova: ModuleType) -> None:
    """The protocol's report AA C0 D4 04 3A 0A A1 60 1D AB is from sensor A160: the id is big-endian after the
    little-endian PM values (a run of fixed fields in two byte orders: once one struct, all little-endian)."""
    report = bytes.fromhex("AA C0 D4 04 3A 0A A1 60 1D AB")
    assert nova.decode(report, nova.Direction.RESPONSE) == nova.ReportResponse(pm25=1236, pm10=2618, device_id=0xA160)
    assert nova.encode(nova.ReportResponse(pm25=1236, pm10=2618, device_id=0xA160)) == report


def test_replies_need_their_request_only_where_the_layout_says(nova: ModuleType) -> None:
    """A C5 reply carries its sub-command: it decodes alone; a report is told by its header."""
    reply = bytes.fromhex("AA C5 02 01 01 00 A1 60 05 AB")
    message = nova.decode(reply, nova.Direction.RESPONSE)
    assert (type(message).__name__, int(message.set), int(message.mode)) == ("SetReportingModeResponse", 1, 1)
    parser = nova.StreamParser(nova.Direction.RESPONSE)
    report = bytes.fromhex("AA C0 D4 04 3A 0A A1 60 1D AB")
    assert [type(m).__name__ for m in parser.feed(b"\xab\xaa" + report + reply + report[:4])] == [
        "ReportResponse",
        "SetReportingModeResponse",
    ]
    with pytest.raises(DecodeError):
        nova.decode(report[:-2] + bytes([report[-2] ^ 1]) + report[-1:], nova.Direction.RESPONSE)


def test_mixed_byte_orders_in_a_group_item(tmp_path: Path) -> None:
    """The same bug in a group's items (one struct per item, in the protocol's byte order): a big-endian field of a
    little-endian protocol's item."""
    spec = tmp_path / "mixed.yaml"
    spec.write_text(
        "protocol: mixed_orders\ntitle: Mixed\nbyte_order: little\nserial: {baudrate: 9600}\n"
        "framing: {elements: {head: {role: header, value: AA}, code: {role: command, type: u8}, "
        "data: {role: content}}}\n"
        "commands:\n  items:\n    code: 1\n    request:\n      fields:\n        points:\n          type: group\n"
        "          count: 2\n          fields: {x: u16, y: {type: u16, endian: big}}\n"
    )
    mixed = generate_and_import(spec, tmp_path / "out", "mixed_orders")
    frame = bytes.fromhex("AA 01 34 12 12 34 78 56 56 78")
    message = mixed.decode(frame, mixed.Direction.REQUEST)
    assert [(p.x, p.y) for p in message.points] == [(0x1234, 0x1234), (0x5678, 0x5678)]
    assert mixed.encode(message) == frame


def test_the_client_awaits_the_report_a_query_is_answered_by(nova: ModuleType) -> None:
    """The report is sent on its own (`unsolicited`) and `answers: query_data`: the client's query_data() sent the
    query and returned None, never waiting for the report that answers it."""
    import importlib
    import os
    import threading
    import tty

    report = bytes.fromhex("AA C0 D4 04 3A 0A A1 60 1D AB")
    controller, device = os.openpty()
    tty.setraw(device)

    def sensor() -> None:
        os.read(controller, 64)  # the query
        os.write(controller, report)

    try:
        with importlib.import_module("nova_sds011.client").NovaSds011Client(os.ttyname(device), timeout=2) as client:
            thread = threading.Thread(target=sensor, daemon=True)
            thread.start()
            assert client.query_data(bytes(12)) == nova.ReportResponse(pm25=1236, pm10=2618, device_id=0xA160)
            thread.join()
    finally:
        os.close(controller)
        os.close(device)
