"""A package's serial settings (`SERIAL`): a frozen value as the dataclass it replaced was, without dataclasses."""

from __future__ import annotations

import dataclasses
import pickle
import subprocess
import sys

import pytest
from serialspec.runtime.settings import SerialSettings


def test_settings_are_a_frozen_value() -> None:
    settings = SerialSettings(baudrate=115200, parity="even")
    assert settings == SerialSettings(115200, 8, "even", 1, 0.0)
    assert settings != SerialSettings(baudrate=9600, parity="even")
    assert hash(settings) == hash(SerialSettings(115200, parity="even"))
    assert repr(settings) == (
        "SerialSettings(baudrate=115200, bytesize=8, parity='even', stopbits=1, gap=0.0, turnaround=0.0)"
    )
    assert pickle.loads(pickle.dumps(settings)) == settings
    with pytest.raises(dataclasses.FrozenInstanceError):
        settings.baudrate = 9600
    with pytest.raises(AttributeError):
        settings.speed = 1


def test_replace_changes_some_settings() -> None:
    settings = SerialSettings(baudrate=115200, gap=3.5)
    assert settings.replace(baudrate=9600) == SerialSettings(baudrate=9600, gap=3.5)
    with pytest.raises(TypeError, match="no field 'speed'"):
        settings.replace(speed=1)


def test_a_generated_package_imports_neither_dataclasses_nor_typing() -> None:
    code = (
        "import sys\n"
        "from serialspec_protocols import feetech_sms\n"
        "assert feetech_sms.decode(bytes.fromhex('ffff010201fb'), 'request') == feetech_sms.PingRequest(id=1)\n"
        "print(sorted(m for m in ('dataclasses', 'inspect', 'typing', 'serialspec.lang') if m in sys.modules))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "[]"
