"""LewanSoul / Hiwonder LX-16A bus servos (tests/specs/lx16a.yaml), written from the user docs alone and checked by
hand against pylx16a (not a test dependency: its LX16A class read angle, offset, limits, voltages, temperature,
motor mode, torque and LED from `serialspec sim` on a pseudo-terminal, set limits, moved and switched to motor
mode, every value as written). The tests keep what that found: a field with a `default` before fields without one
(SERVO_OR_MOTOR_MODE_WRITE's reserved byte between mode and speed) can be left out of the message class and the
client's method, as the docs say, not only from JSON."""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path
from types import ModuleType

import pytest
from conftest import generate_and_import

SPEC = Path(__file__).parent / "specs" / "lx16a.yaml"


@pytest.fixture(scope="module")
def lx(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("lx16a"), "lx16a")


def test_a_default_before_fields_without_one_may_be_left_out(lx: ModuleType) -> None:
    message = lx.ModeWriteRequest(id=1, mode=1, speed=300)
    assert message == lx.ModeWriteRequest(1, 1, 0, 300)  # positional calls keep working
    assert lx.encode(message) == bytes.fromhex("55 55 01 07 1d 01 00 2c 01 ac")
    with pytest.raises(TypeError, match="missing required argument: 'speed'"):
        lx.ModeWriteRequest(id=1, mode=1)
    client = importlib.import_module("lx16a.client").Lx16aClient
    assert str(inspect.signature(client.mode_write).parameters["reserved"]) == "reserved: 'int' = 0"


def test_the_sim_answers_what_pylx16a_asks_first(lx: ModuleType) -> None:
    """pylx16a's LX16A(1) reads the position first (SERVO_POS_READ, 28): 55 55 01 03 1c df."""
    sim = importlib.import_module("lx16a.simulator").Lx16aSimulator(ids=[1])
    [(_, frame)] = sim.handle(lx.decode(bytes.fromhex("55 55 01 03 1c df"), lx.Direction.REQUEST))
    assert frame == bytes.fromhex("55 55 01 05 1c f4 01 e8")  # position 500 (120 degrees)
