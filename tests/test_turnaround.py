"""`framing.turnaround`: after a request no device answers (a broadcast), the client waits that long before it
writes again, so that every device has carried it out (Modbus serial line §2.4.1's turnaround delay). The waits are
checked as lower bounds on the times the client wrote at, which a busy machine can only lengthen."""

from __future__ import annotations

import asyncio
import time
from pathlib import Path
from typing import Any

import pytest
import serial
from serialspec.lang import load_protocol
from serialspec.lang.errors import SpecErrors
from serialspec.runtime.settings import SerialSettings
from serialspec_protocols import modbus_ascii, modbus_rtu
from serialspec_protocols.modbus_rtu.aio import AsyncModbusRtuClient
from serialspec_protocols.modbus_rtu.client import ModbusRtuClient

SPECS = Path(__file__).resolve().parent.parent / "specs"


class WriteTimes(serial.serial_for_url("loop://", do_not_open=True).__class__):  # type: ignore[misc]
    """pyserial's loop:// port (what is written comes back to be read), noting when each write was made."""

    def __init__(self) -> None:
        super().__init__("loop://", timeout=0.05)
        self.written: list[float] = []

    def write(self, data: Any) -> int | None:
        self.written.append(time.monotonic())
        written: int | None = super().write(data)
        return written


def test_modbus_specs_say_their_turnaround() -> None:
    assert modbus_rtu.SERIAL.turnaround == 0.1
    assert modbus_ascii.SERIAL.turnaround == 0.1
    assert SerialSettings(9600, turnaround=0.2).replace(baudrate=19200) == SerialSettings(19200, turnaround=0.2)


def test_a_broadcast_is_followed_by_the_turnaround() -> None:
    port = WriteTimes()
    with ModbusRtuClient(port) as client:
        assert client.write_register(0, 30, 4321) is None  # broadcast: no reply is due
        assert client.write_register(0, 31, 1) is None
    first, second = port.written
    assert second - first >= modbus_rtu.SERIAL.turnaround


def test_a_request_that_is_answered_is_not_followed_by_the_turnaround() -> None:
    """A unicast request waits for its reply (here loop:// hands the request back, which is no reply), then only
    the 3.5-character gap."""
    port = WriteTimes()
    with ModbusRtuClient(port, timeout=0.01) as client:
        for _ in range(2):
            with pytest.raises(Exception, match="reply to read_holding_registers from unit=1"):
                client.read_holding_registers(1, 0, 1)
        assert client.bus._quiet_until == 0.0


def test_the_asyncio_client_waits_the_turnaround_too() -> None:
    port = WriteTimes()

    async def main() -> None:
        async with AsyncModbusRtuClient(port) as client:
            assert await client.write_register(0, 30, 4321) is None
            assert await client.write_register(0, 31, 1) is None

    asyncio.run(main())
    first, second = port.written
    assert second - first >= modbus_rtu.SERIAL.turnaround


@pytest.mark.parametrize(
    ("key", "value", "said"),
    [
        ("turnaround", -0.1, "framing.turnaround: expected a time of 0 or more, got -0.1"),
        ("gap", -3.5, "framing.gap: expected a time of 0 or more, got -3.5"),
        ("turnaround", "soon", "framing.turnaround: expected a number, got"),
    ],
)
def test_a_negative_or_missing_time_is_one_line(tmp_path: Path, key: str, value: object, said: str) -> None:
    text = (SPECS / "modbus_rtu.yaml").read_text("utf-8").replace("  turnaround: 0.1\n", f"  {key}: {value}\n", 1)
    if key == "gap":
        text = text.replace("  gap: 3.5\n", "", 1)
    path = tmp_path / "modbus_rtu.yaml"
    path.write_text(text, "utf-8")
    with pytest.raises(SpecErrors) as caught:
        load_protocol(path)
    lines = str(caught.value).splitlines()
    assert any(said in line and "modbus_rtu.yaml:" in line for line in lines), lines
