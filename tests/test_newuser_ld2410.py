"""Hi-Link HLK-LD2410 presence radar (tests/specs/hlk_ld2410.yaml), written from the user docs alone and checked against
`aio-ld2410` on PyPI (its construct structs for frames, commands, replies and reports): the commands it builds decode
as our requests and re-encode byte for byte, it parses the ACKs and reports we encode, and the generated client talks
to the generated simulator. Commands and ACKs (FD FC FB FA, a u16 command word, an ACK's word | 0x0100) and reports
(F4 F3 F2 F1, a u8 data type, AA ... 55 00) are two layouts chosen by command. `reply_code` on the command layout's
command element was applied to the reports too: `encode` of a basic report said `type = 258 does not fit 1 byte(s)`
and decoding the datasheet's report said `unknown command 0x02`; the reference said the report's type byte was the
ACK's code. A bug, fixed: where layouts are chosen by command, only the layouts whose command element gives
`reply_code` compute it. Engineering reports carry N + 1 energies per gate after N (N is 8 on the LD2410): a count
was a number or a field, so the spec fixed it at 9 (a strict xfail); the spec now counts them `max_moving_gate + 1`
(counts by expression, lang/counts.py), N staying in the message, and the Python, the C and the peer agree."""

from __future__ import annotations

import importlib
import json
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from conftest import examples, generate_and_import, simulated, spec_error
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import DecodeError, EncodeError

protocol = pytest.importorskip("aio_ld2410.protocol")

SPEC = Path(__file__).parent / "specs" / "hlk_ld2410.yaml"
Code = protocol.CommandCode
# aio-ld2410's test trace: the datasheet's engineering report with the light sensor's value and the OUT pin (60 01)
TRACE = bytes.fromhex(
    "f4 f3 f2 f1 23 00 01 aa 03 1e 00 3c 00 00 39 00 00 08 08 3c 22 05 03 03 04 03 06 05 00 00 39 10"
    "13 06 06 08 04 60 01 55 00 f8 f7 f6 f5"
)


@pytest.fixture(scope="module")
def ld(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("ld2410"), "hlk_ld2410")


def peer_command(code: Any, data: Any = None) -> bytes:
    return bytes(protocol.CommandFrame.build({"data": protocol.Command.build({"code": code, "data": data})}))


@pytest.mark.parametrize(
    ("code", "data", "name", "fields"),
    [
        (Code.CONFIG_ENABLE, {}, "EnableConfigurationRequest", {}),
        (Code.CONFIG_DISABLE, None, "EndConfigurationRequest", {}),
        (Code.PARAMETERS_READ, None, "ReadParametersRequest", {}),
        (Code.ENGINEERING_ENABLE, None, "EnableEngineeringModeRequest", {}),
        (Code.FIRMWARE_VERSION, None, "ReadFirmwareVersionRequest", {}),
        (Code.MODULE_RESTART, None, "RestartRequest", {}),
        (Code.BAUD_RATE_SET, {"index": "RATE_115200"}, "SetBaudRateRequest", {"index": 5}),
        (
            Code.PARAMETERS_WRITE,
            {"moving_max_distance_gate": 6, "static_max_distance_gate": 4, "presence_timeout": 30},
            "SetMaxGatesAndDurationRequest",
            {"max_moving_gate": 6, "max_stationary_gate": 4, "unmanned_duration": 30},
        ),
        (
            Code.GATE_SENSITIVITY_SET,
            {"distance_gate": 0xFFFF, "moving_threshold": 40, "static_threshold": 30},
            "SetSensitivityRequest",
            {"gate": 0xFFFF, "moving_sensitivity": 40, "stationary_sensitivity": 30},
        ),
    ],
)
def test_the_peers_commands_are_our_requests(
    ld: ModuleType, code: Any, data: Any, name: str, fields: dict[str, int]
) -> None:
    golden = peer_command(code, data)
    message = ld.decode(golden, ld.Direction.REQUEST)
    assert type(message).__name__ == name
    assert {k: int(v) for k, v in message.to_fields().items() if k in fields} == fields
    assert ld.encode(message) == golden


def peer_reply(frame: bytes) -> Any:
    return protocol.Reply.parse(protocol.CommandFrame.parse(frame).data)


def test_the_peer_parses_our_acks(ld: ModuleType) -> None:
    ack = peer_reply(ld.encode(ld.EnableConfigurationResponse(status=0, protocol_version=1, buffer_size=64)))
    assert (int(ack.code), int(ack.status)) == (Code.CONFIG_ENABLE, 0)
    assert (ack.data.protocol_version, ack.data.buffer_size) == (1, 64)
    ack = peer_reply(ld.encode(ld.ReadFirmwareVersionResponse(0, 0x0100, 0x0107, 0x22091516)))
    assert (ack.data.major, ack.data.minor, ack.data.revision) == (1, 7, 0x22091516)
    moving, stationary = [50, 50, 40, 30, 20, 15, 15, 15, 15], [0, 0, 40, 40, 30, 30, 20, 20, 20]
    ack = peer_reply(ld.encode(ld.ReadParametersResponse(0, 8, 8, 6, moving, stationary, 5)))
    assert int(ack.code) == Code.PARAMETERS_READ
    assert (ack.data.max_distance_gate, ack.data.moving_max_distance_gate, ack.data.static_max_distance_gate) == (
        8,
        8,
        6,
    )
    assert (list(ack.data.moving_threshold), list(ack.data.static_threshold)) == (moving, stationary)
    assert ack.data.presence_timeout == 5
    failed = peer_reply(ld.encode(ld.RestartResponse(status=ld.Status.FAILURE)))
    assert (int(failed.code), int(failed.status), failed.data) == (Code.MODULE_RESTART, 1, None)


energies = st.lists(st.integers(0, 100), min_size=9, max_size=9)


@settings(max_examples=examples(25), deadline=None)
@given(
    state=st.integers(0, 3),
    distances=st.lists(st.integers(0, 0xFFFF), min_size=3, max_size=3),
    moving=energies,
    stationary=energies,
    light=st.integers(0, 255),
    engineering=st.booleans(),
)
def test_the_peer_parses_our_reports(
    ld: ModuleType,
    state: int,
    distances: list[int],
    moving: list[int],
    stationary: list[int],
    light: int,
    engineering: bool,
) -> None:
    basic = dict(
        target_state=state,
        moving_distance=distances[0],
        moving_energy=moving[0],
        stationary_distance=distances[1],
        stationary_energy=stationary[0],
        detection_distance=distances[2],
    )
    if engineering:
        message = ld.EngineeringReportResponse(
            **basic,
            max_moving_gate=8,
            max_stationary_gate=8,
            moving_energies=moving,
            stationary_energies=stationary,
            light=light,
            out_pin=1,
        )
    else:
        message = ld.BasicReportResponse(**basic)
    frame = ld.encode(message)
    report = protocol.Report.parse(protocol.ReportFrame.parse(frame).data)
    assert int(report.type) == (1 if engineering else 2)
    peer = report.data.basic
    assert (int(peer.target_status), peer.moving_distance, peer.static_distance) == (state, *distances[:2])
    assert (peer.moving_energy, peer.static_energy, peer.detection_distance) == (moving[0], stationary[0], distances[2])
    if engineering:
        assert list(report.data.engineering.moving_gate_energy) == moving
        assert list(report.data.engineering.static_gate_energy) == stationary
        assert (report.data.engineering.photosensitive_value, int(report.data.engineering.out_pin_status)) == (light, 1)
    assert ld.decode(frame, ld.Direction.RESPONSE) == message


def test_the_peers_own_engineering_TRACE(ld: ModuleType) -> None:
    """aio-ld2410's test TRACE: the datasheet's report with the light sensor's value and the OUT pin (60 01) where the
    datasheet prints retained bytes."""
    message = ld.decode(TRACE, ld.Direction.RESPONSE)
    assert (message.target_state, message.moving_distance, message.light, message.out_pin) == (3, 30, 0x60, 1)
    assert ld.encode(message) == TRACE


def test_a_layout_without_reply_code_keeps_its_codes(ld: ModuleType) -> None:
    """The bug: the reports' type byte got the ACKs' `code | 0x0100`."""
    report = ld.BasicReportResponse(2, 81, 0, 0, 59, 0)
    frame = bytes.fromhex("F4 F3 F2 F1 0D 00 02 AA 02 51 00 00 00 00 3B 00 00 55 00 F8 F7 F6 F5")
    assert ld.encode(report) == frame
    assert ld.decode(frame, ld.Direction.RESPONSE) == report
    ack = ld.encode(ld.EndConfigurationResponse(status=0))
    assert ack == bytes.fromhex("FD FC FB FA 04 00 FE 01 00 00 04 03 02 01")
    parser = ld.StreamParser(ld.Direction.RESPONSE)
    found = parser.feed(frame[3:] + frame + ack + frame[:9])
    assert [type(m).__name__ for m in found] == ["BasicReportResponse", "EndConfigurationResponse"]


def test_the_reference_gives_each_layout_its_own_codes(tmp_path: Path) -> None:
    from serialspec.cli import main as serialspec_main

    assert serialspec_main(["generate", str(SPEC), "--out", str(tmp_path), "--target", "markdown"]) == 0
    page = (tmp_path / "docs" / "hlk_ld2410.md").read_text("utf-8")
    assert "| word | u16 | the code of the request it answers, as `code \\| 0x0100`." in page
    assert "| type | u8 | The data type" in page


@pytest.fixture
def sim_path(ld: ModuleType) -> Iterator[str]:
    with simulated("hlk_ld2410") as path:
        yield path


def test_the_generated_client_configures_the_sim(ld: ModuleType, sim_path: str) -> None:
    client_module = importlib.import_module("hlk_ld2410.client")
    with client_module.HlkLd2410Client(sim_path, timeout=2) as client:
        report = next(iter(client.reports(timeout=2)))
        assert isinstance(report, ld.BasicReportResponse) and report.stationary_distance == 120
        assert client.enable_configuration().buffer_size == 64
        firmware = client.read_firmware_version()
        assert (firmware.major, firmware.minor) == (0x0107, 0x22091516)
        assert list(client.read_parameters().moving_sensitivity) == [50, 50, 40, 30, 20, 15, 15, 15, 15]
        client.enable_engineering_mode()
        client.end_configuration()
        engineering = next(r for r in client.reports(timeout=2) if isinstance(r, ld.EngineeringReportResponse))
        assert list(engineering.stationary_energies) == [0, 10, 45, 20, 5, 0, 0, 0, 0]


def test_the_c_reads_the_reports_and_acks(ld: ModuleType, tmp_path: Path) -> None:
    from test_c_backend import GCC, spec_driver

    if GCC is None:
        pytest.skip("no C compiler")
    driver = spec_driver(SPEC, "hlk_ld2410", tmp_path)
    try:
        said = driver.ask("dec response f4f3f2f10d0002aa025100000000" + "3b0000" + "5500f8f7f6f5")[0]
        assert said.startswith("ok ") and json.loads(said[3:])["command"] == "basic_report"
        assert json.loads(said[3:])["fields"]["stationary_energy"] == 59
        said = driver.ask("dec response fdfcfbfa0400fe01000004030201")[0]
        assert said.startswith("ok ") and json.loads(said[3:])["command"] == "end_configuration"
        # N + 1 energies after N (`count: max_moving_gate + 1`): 9, then 3 where N = 2; N = 255 asks for more bytes
        said = driver.ask(f"dec response {TRACE.hex()}")[0]
        assert said.startswith("ok ") and json.loads(said[3:])["fields"]["moving_energies"] == [
            60,
            34,
            5,
            3,
            3,
            4,
            3,
            6,
            5,
        ]
        message = ld.decode(TRACE, ld.Direction.RESPONSE)
        fewer = ld.encode(
            type(message).from_fields({**message.to_fields(), "max_moving_gate": 2, "moving_energies": [1, 2, 3]})
        )
        said = driver.ask(f"dec response {fewer.hex()}")[0]
        assert said.startswith("ok ") and json.loads(said[3:])["fields"]["moving_energies"] == [1, 2, 3]
        said = driver.ask(f"rt response {fewer.hex()}")[0]
        assert said == f"ok {fewer.hex()}", said
        said = driver.ask(f"dec response {(TRACE[:17] + bytes([255]) + TRACE[18:]).hex()}")[0]
        assert not said.startswith("ok "), said
    finally:
        driver.close()


def test_a_count_of_a_later_field_is_one_line(tmp_path: Path) -> None:
    """Refused in one line at the count: the device's reply value for the field that failed said a second line once
    (`unknown response field 'moving_energies': no response carries it`)."""
    text = SPEC.read_text("utf-8").replace("count: max_moving_gate + 1", "count: light + 1")
    said = spec_error(text, tmp_path)
    assert "\n" not in said and said.endswith(
        "commands.engineering_report.response.fields.moving_energies.count: a later field 'light' in 'light + 1': a "
        "count or size names earlier integer fields"
    )


def test_a_count_of_one_more_than_a_field(ld: ModuleType) -> None:
    """`count: max_moving_gate + 1`: N stays in the message; decode reads N + 1 energies (the datasheet's report, N
    = 8), encode refuses a list of another length before writing a byte, naming the count expected; construct's
    struct reads the same; the stream parser finds frames of several N."""
    message = ld.decode(TRACE, ld.Direction.RESPONSE)
    assert message.max_moving_gate == 8 and list(message.moving_energies) == [60, 34, 5, 3, 3, 4, 3, 6, 5]
    assert ld.encode(message) == TRACE
    fields = {**message.to_fields(), "max_moving_gate": 2, "moving_energies": [1, 2, 3]}
    fewer = ld.encode(type(message).from_fields(fields))
    assert len(fewer) == len(TRACE) - 6 and ld.decode(fewer, ld.Direction.RESPONSE).moving_energies == (1, 2, 3)
    with pytest.raises(EncodeError, match=r"moving_energies needs max_moving_gate \+ 1 = 3 items, got 4$"):
        ld.encode(type(message).from_fields({**fields, "moving_energies": [1, 2, 3, 4]}))
    with pytest.raises(DecodeError, match="moving_energies needs 256 bytes, 20 left$"):  # N = 255
        ld.decode(TRACE[:17] + b"\xff" + TRACE[18:], ld.Direction.RESPONSE)
    structs = importlib.import_module("hlk_ld2410.structs")
    assert list(structs.EngineeringReportResponseContent.parse(fewer[8:-6]).moving_energies) == [1, 2, 3]
    parser = ld.StreamParser(ld.Direction.RESPONSE)
    assert parser.feed(b"\xf4" + fewer + TRACE + fewer[:5]) == [ld.decode(fewer, ld.Direction.RESPONSE), message]
