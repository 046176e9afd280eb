"""How the bus moves bytes: the descriptor path for pyserial's own POSIX ports (waiting in poll, or in select where
poll cannot wait on terminals), pyserial's calls for everything else; each sees the same frames."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import pytest
from serialspec.runtime.errors import Timeout
from serialspec.runtime.transport import Bus, FdLink, Link
from serialspec_protocols.fashionstar_uart import ReadAngleRequest, ReadAngleResponse
from serialspec_protocols.fashionstar_uart.client import BINDING
from serialspec_protocols.fashionstar_uart.simulator import FashionstarUartSimulator


@pytest.fixture
def path() -> Iterator[str]:
    simulator = FashionstarUartSimulator(ids=[1, 2])
    yield simulator.start()
    simulator.close()


def waiting_in_select(bus: Bus) -> Bus:
    assert isinstance(bus._link, FdLink)
    bus._link._poll = None  # what macOS gets
    return bus


def pyserial_calls(bus: Bus) -> Bus:
    bus._link = Link(bus._port)
    return bus


LINKS = {"poll": lambda bus: bus, "select": waiting_in_select, "pyserial": pyserial_calls}


@pytest.mark.parametrize("how", LINKS.values(), ids=LINKS.keys())
def test_every_link_answers_and_times_out(path: str, how: Callable[[Bus], Bus]) -> None:
    with Bus(path, BINDING, timeout=0.05) as bus:
        how(bus)
        for servo_id in (1, 2, 1):
            assert bus.request(ReadAngleRequest(servo_id=servo_id), ReadAngleResponse).servo_id == servo_id
        with pytest.raises(Timeout, match="servo_id=9"):
            bus.request(ReadAngleRequest(servo_id=9), ReadAngleResponse)
        assert bus.request(ReadAngleRequest(servo_id=2), ReadAngleResponse).servo_id == 2


def test_a_device_path_takes_the_descriptor_and_a_url_pyserial(path: str) -> None:
    with Bus(path, BINDING) as bus:
        assert type(bus._link) is FdLink
    with Bus("loop://", BINDING) as bus:
        assert type(bus._link) is Link
