"""Device models: a spec lists models with their model number and factory values; the simulator serves one.

An arm driver checks every servo's model number and firmware version at connect and then reads all six at once
(SYNC READ); here the vendor's SDK (scservo_sdk) does exactly that against `serialspec sim`.
"""

from __future__ import annotations

import dataclasses
import importlib
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from serialspec.lang import SpecErrors, load_protocol
from serialspec.runtime.device import ModelSpec, Simulator
from serialspec_protocols.feetech_sms import MODELS
from serialspec_protocols.feetech_sms.client import FeetechSmsClient
from serialspec_protocols.feetech_sms.codec import StreamParser, encode
from serialspec_protocols.feetech_sms.messages import Direction, ResetRequest, WriteRequest
from serialspec_protocols.feetech_sms.registers import CONTROL_TABLE
from serialspec_protocols.feetech_sms.simulator import DEVICE, FeetechSmsSimulator
from sim_process import ROOT, serve

scservo_sdk = pytest.importorskip("scservo_sdk")
sms_sts = importlib.import_module("scservo_sdk.sms_sts")
SUCCESS = scservo_sdk.COMM_SUCCESS
ARM = (1, 2, 3, 4, 5, 6)


@pytest.fixture(scope="module")
def arm_port() -> Iterator[str]:
    with serve("feetech_sms.yaml", *ARM) as path:
        yield path


@pytest.fixture
def sdk(arm_port: str) -> Iterator[Any]:
    handler = scservo_sdk.PortHandler(arm_port)
    assert handler.openPort()
    yield sms_sts.sms_sts(handler)
    handler.closePort()


def test_an_arm_driver_connects_to_six_virtual_sts3215(sdk: Any) -> None:
    """Ping, model number, firmware version of each servo, then one SYNC READ of all six positions."""
    for servo in ARM:
        _, result, error = sdk.ping(servo)
        assert (result, error) == (SUCCESS, 0)
        model, result, error = sdk.read2ByteTxRx(servo, sms_sts.SMS_STS_MODEL_L)
        assert (model, result, error) == (777, SUCCESS, 0)  # the STS3215's model number
        assert MODELS[model] == "sts3215"  # the generated package names the models by number
        major, result, _ = sdk.read1ByteTxRx(servo, CONTROL_TABLE["firmware_major"].address)
        minor, _, _ = sdk.read1ByteTxRx(servo, CONTROL_TABLE["firmware_minor"].address)
        assert (major, minor, result) == (3, 10, SUCCESS)
        assert sdk.read1ByteTxRx(servo, sms_sts.SMS_STS_BAUD_RATE)[0] == sms_sts.SMS_STS_1M
        assert sdk.read2ByteTxRx(servo, sms_sts.SMS_STS_MAX_ANGLE_LIMIT_L)[0] == 4095
        assert sdk.read1ByteTxRx(servo, sms_sts.SMS_STS_CW_DEAD)[0] == 2
    for servo, goal in zip(ARM, (100, 600, 1100, 1600, 2100, 2600), strict=True):
        assert sdk.SyncWritePosEx(servo, goal, 0, 0)
    assert sdk.groupSyncWrite.txPacket() == SUCCESS
    sdk.groupSyncWrite.clearParam()
    reader = scservo_sdk.GroupSyncRead(sdk, sms_sts.SMS_STS_PRESENT_POSITION_L, 2)
    for servo in ARM:
        assert reader.addParam(servo)
    assert reader.txRxPacket() == SUCCESS
    positions = {s: reader.getData(s, sms_sts.SMS_STS_PRESENT_POSITION_L, 2) for s in ARM}
    assert positions == dict(zip(ARM, (100, 600, 1100, 1600, 2100, 2600), strict=True))
    assert sdk.ReadPos(4) == (1600, SUCCESS, 0)


def test_our_client_reads_the_same_model_number(arm_port: str) -> None:
    with FeetechSmsClient(arm_port, timeout=1.0) as servos:
        assert servos.read(6, "model_number") == 777
        assert servos.read_many(6, "firmware_major", "firmware_minor") == {"firmware_major": 3, "firmware_minor": 10}


def test_sim_model_option_serves_another_model_on_every_id() -> None:
    with (
        serve("feetech_sms.yaml", 1, 2, options=("--model", "sm8512bl")) as path,
        FeetechSmsClient(path, timeout=1.0) as servos,
    ):
        assert [servos.read(i, "model_number") for i in (1, 2)] == [11272, 11272]


def test_sim_model_option_per_id() -> None:
    options = ("--model", "2=sm8512bl", "--model", "3=sts3250")
    with serve("feetech_sms.yaml", 1, 2, 3, options=options) as path, FeetechSmsClient(path, timeout=1.0) as servos:
        assert [servos.read(i, "model_number") for i in (1, 2, 3)] == [777, 11272, 2825]


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--model", "xl330"], "unknown model 'xl330' (expected one of: sts3215, sts3250, sm8512bl)"),
        (["--model", "9=sts3215"], "a model is given for id 9, which is not on the bus"),
        (["--model", "x=y=z"], "expected NAME or ID=NAME"),
    ],
)
def test_sim_refuses_a_bad_model_in_one_line(options: list[str], message: str) -> None:
    args = [sys.executable, "-m", "serialspec", "sim", str(ROOT / "specs" / "feetech_sms.yaml"), "--id", "1"]
    result = subprocess.run([*args, *options], capture_output=True, text=True, timeout=30)
    assert result.returncode != 0
    assert message in result.stderr
    assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1


def test_a_spec_without_models_says_so() -> None:
    args = [sys.executable, "-m", "serialspec", "sim", str(ROOT / "specs" / "fashionstar_uart.yaml"), "--model", "x"]
    result = subprocess.run(args, capture_output=True, text=True, timeout=30)
    assert result.returncode != 0
    assert result.stderr.strip() == "serialspec sim: --model: unknown model 'x': the spec lists no device models"


def test_reset_goes_back_to_the_models_factory_values() -> None:
    simulator = FeetechSmsSimulator([1], model="sts3250")
    device = simulator.devices[1]
    device.set("cw_dead_band", 7)
    device.set("model_number", 1)  # as if corrupted: RESET restores the model's own values
    assert device.model is not None and device.model.name == "sts3250"
    simulator.handle(_request("reset", 1))
    assert (device.get("cw_dead_band"), device.get("model_number"), device.id) == (2, 2825, 1)


def test_a_models_range_replaces_the_tables_range() -> None:
    narrow = ModelSpec("narrow", 9, {"model_number": 9}, {"torque_limit": (0, 500)})
    spec = dataclasses.replace(DEVICE, models=(narrow, *DEVICE.models))
    simulator = Simulator(spec, [1], encode=encode, parser=lambda: StreamParser(Direction.REQUEST))
    wide = Simulator(spec, [1], encode=encode, parser=lambda: StreamParser(Direction.REQUEST), model="sts3215")
    for sim, accepted in ((simulator, False), (wide, True)):
        sim.handle(_request("write", 1, address=CONTROL_TABLE["torque_limit"].address, data=bytes([0x58, 0x02])))
        assert (sim.devices[1].get("torque_limit") == 600) is accepted  # 600 > 500: the narrow model refuses


def test_a_servo_whose_id_is_changed_answers_at_its_new_id() -> None:
    with serve("feetech_sms.yaml", 1, 2) as path, FeetechSmsClient(path, timeout=0.3) as servos:
        servos.write(1, lock=0)
        servos.write(1, id=9)
        assert not servos.ping(1)
        assert servos.ping(9)
        assert servos.read(9, "model_number") == 777  # the same servo, its model kept


def _request(command: str, servo: int, **fields: Any) -> Any:
    cls = {"reset": ResetRequest, "write": WriteRequest}[command]
    return cls(id=servo, **fields)


def test_model_mistakes_are_spec_errors(tmp_path: Path) -> None:
    text = (ROOT / "specs" / "feetech_sms.yaml").read_text(encoding="utf-8")
    text = text.replace("      number: 2825\n", "      number: 777\n")
    text = text.replace(
        "        cw_dead_band: 2\n        ccw_dead_band: 2\n    sm8512bl:", "        cw_dead_band: 99\n    sm8512bl:"
    )
    text = text.replace("  default_model: sts3215", "  default_model: sts9999")
    text = text.replace("        firmware_minor: 10\n\n", "        firmware_minor: 10\n        nothing: 1\n\n", 1)
    spec = tmp_path / "feetech_sms.yaml"
    spec.write_text(text, encoding="utf-8")
    with pytest.raises(SpecErrors) as failure:
        load_protocol(str(spec), "feetech_sms.yaml")
    lines = str(failure.value).splitlines()
    assert any("model number 777 is already used by 'sts3215'" in line for line in lines), lines
    assert any("cw_dead_band = 99 is outside its range 0..32" in line for line in lines), lines
    assert any("unknown model 'sts9999'" in line for line in lines), lines
    assert all(line.startswith("feetech_sms.yaml:") for line in lines), lines


def test_behaviour_mistakes_are_spec_errors(tmp_path: Path) -> None:
    text = (ROOT / "specs" / "fashionstar_uart.yaml").read_text(encoding="utf-8")
    text = text.replace("stop_on_control_mode: {stops: [angle]}", "stop_on_control_mode: {stops: [angel]}")
    text = text.replace("begin_async: {every_device: true, sets: {holding: 1}}", "begin_async: {cancel_when: {x: 1}}")
    text = text.replace("        commands: [rotate, move_by_interval,", "        commands: [rotat, move_by_interval,")
    text = text.replace("counts: {turns: {state: angle, per: 3600}}}", "counts: {turn: {state: angle, per: 3600}}}")
    spec = tmp_path / "fashionstar_uart.yaml"
    spec.write_text(text, encoding="utf-8")
    with pytest.raises(SpecErrors) as failure:
        load_protocol(str(spec), "fashionstar_uart.yaml")
    lines = str(failure.value).splitlines()
    for expected in (
        "stops: unknown state variable 'angel'",
        "cancel_when: `cancel_when` needs `releases`",
        "cancel_when.x: begin_async has no request field 'x'",
        "carries.commands: unknown command 'rotat'",
        "counts.turn: read_mturn_angle has no response field 'turn'",
    ):
        assert any(expected in line for line in lines), (expected, lines)
    assert all(line.startswith("fashionstar_uart.yaml:") for line in lines), lines


def test_moving_reads_1_on_the_way_and_0_on_arrival() -> None:
    now = [0.0]
    simulator = FeetechSmsSimulator([1], clock=lambda: now[0])
    goal = CONTROL_TABLE["goal_position"].address
    simulator.handle(WriteRequest(id=1, address=goal, data=bytes([0x00, 0x08, 0xF4, 0x01])))  # 2048 in 500 ms
    device = simulator.devices[1]
    now[0] = 0.25
    assert (device.get("moving"), device.get("present_position")) == (1, 1024)
    now[0] = 0.5
    assert (device.get("moving"), device.get("present_position")) == (0, 2048)


def test_a_models_entries_reach_the_docs_and_the_simulator(tmp_path: Path) -> None:
    """Per-model ranges and units (DYNAMIXEL's XL330 counts current in 1 mA, the XM430 in 2.69 mA) end to end."""
    from serialspec.backends.markdown.docs import emit_docs
    from serialspec.backends.python.simulator import simulator_module

    text = (ROOT / "specs" / "feetech_sms.yaml").read_text(encoding="utf-8")
    text = text.replace(
        "    sm8512bl:\n      number: 11272\n",
        "    sm8512bl:\n      number: 11272\n      entries:\n"
        "        protection_current: {range: [0, 300], unit: 10 mA, scale: 10, description: Its own current steps.}\n",
    )
    spec = tmp_path / "feetech_sms.yaml"
    spec.write_text(text, encoding="utf-8")
    protocol = load_protocol(str(spec), "feetech_sms.yaml")
    docs = emit_docs(protocol)
    assert "| protection_current |  | 0..300 | 10 mA | Its own current steps. |" in docs
    assert "'protection_current': (0, 300)," in simulator_module(protocol)
    bad = text.replace("range: [0, 300]", "range: [0, 70000]")
    spec.write_text(bad, encoding="utf-8")
    with pytest.raises(SpecErrors, match=r"range \[0, 70000\] does not fit u16"):
        load_protocol(str(spec), "feetech_sms.yaml")
