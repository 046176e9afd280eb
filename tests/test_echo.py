"""Half-duplex echo: one-wire adapters hear their own transmission. `Bus(..., echo=True)` (and the clients'
`echo=True`) reads back and checks every frame it writes before it looks for the reply; `serialspec sim --echo`
behaves like such an adapter. Both ways round, with the timeouts."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from serialspec.runtime.errors import CorruptReply, DeviceError, PortError, Timeout
from serialspec_protocols import fashionstar_uart as fs
from serialspec_protocols.fashionstar_uart.client import FashionstarUartClient
from serialspec_protocols.feetech_sms.client import FeetechSmsClient
from sim_process import serve


@pytest.fixture(scope="module")
def echoing_feetech() -> Iterator[str]:
    with serve("feetech_sms.yaml", 1, 2, options=("--echo",)) as path:
        yield path


@pytest.fixture(scope="module")
def plain_feetech() -> Iterator[str]:
    with serve("feetech_sms.yaml", 1) as path:
        yield path


def test_an_echo_client_talks_to_an_echoing_bus(echoing_feetech: str) -> None:
    with FeetechSmsClient(echoing_feetech, timeout=1.0, echo=True) as servos:
        assert servos.ping(1)
        assert servos.read(1, "model_number") == 777
        assert servos.write(2, torque_limit=500)
        assert servos.sync_read([1, 2], "torque_limit") == {1: {"torque_limit": 1000}, 2: {"torque_limit": 500}}
        servos.sync_write({1: {"goal_position": 100}})  # broadcast: no reply, but the echo is still checked
        assert servos.read(1, "goal_position") == 100


def test_a_missing_reply_after_the_echo_is_a_timeout(echoing_feetech: str) -> None:
    with FeetechSmsClient(echoing_feetech, timeout=0.5, echo=True) as servos:
        with pytest.raises(Timeout):
            servos.read(7, "model_number")  # the echo comes back, no servo 7 answers
        assert servos.ping(1)  # and the bus is fine afterwards


def test_without_echo_the_client_reads_its_own_request_as_the_reply(echoing_feetech: str) -> None:
    """What users of such adapters hit: FEETECH requests and replies share FF FF, so the echoed READ (instruction
    0x02) parses as a reply from the same id whose error byte 0x02 says "angle sensor fault"."""
    with FeetechSmsClient(echoing_feetech, timeout=0.5) as servos, pytest.raises(DeviceError, match="angle_sensor"):
        servos.read(1, "model_number")


def test_the_echo_is_checked_byte_for_byte(plain_feetech: str) -> None:
    differs = pytest.raises(PortError, match="the echo differs from the bytes written: wrote ff ff 01 04 02 03 02")
    with FeetechSmsClient(plain_feetech, timeout=1.0, echo=True) as servos, differs:
        servos.read(1, "model_number")  # the reply arrives where the echo should be
    no_echo = pytest.raises(PortError, match="no echo of the 8 bytes written within 0.3 s")
    with FeetechSmsClient(plain_feetech, timeout=0.3, echo=True) as servos, no_echo:
        servos.read(9, "model_number")  # nobody answers, nothing echoes


def test_fashion_star_client_with_echo() -> None:
    with (
        serve("fashionstar_uart.yaml", 0, options=("--echo",)) as path,
        FashionstarUartClient(path, timeout=1.0, echo=True) as client,
    ):
        assert client.ping(0)
        client.rotate(0, 300, 0)
        assert client.read_angle(0) == 300
        client.begin_async()  # no reply: the echo alone is read back
        client.end_async(0)
        assert client.monitor(0).voltage == 7400


def test_bus_echo_over_pyserials_loopback() -> None:
    """pyserial's loop:// hands back every byte written: an adapter's echo with no device on the bus."""
    with FashionstarUartClient("loop://", timeout=0.2, echo=True) as client:
        client.set_origin_point(3)  # written, echo checked, nothing else
        with pytest.raises(Timeout):
            client.read_angle(3)
    # without echo=True the echoed request is taken for the start of a broken reply
    with FashionstarUartClient("loop://", timeout=0.2) as client, pytest.raises(CorruptReply, match="incomplete"):
        client.bus.request(fs.ReadAngleRequest(servo_id=3), fs.ReadAngleResponse)
