"""Replies of other commands: a request answered by another command's response (`answered_by`) under frames matched
by command, refusals (`refused_by`: the client raises DeviceError naming them, the simulator sends them for a refused
request) and replies carrying the code of the request they answer (`request_code`)."""

from __future__ import annotations

import os
import threading
import tty
from collections.abc import Iterator
from types import ModuleType

import pytest
from serialspec.backends import emitters
from serialspec.backends.python.memory import imported
from serialspec.lang import SpecErrors
from serialspec.lang.loader import load_text
from serialspec.lang.resolve import resolve
from serialspec.runtime.errors import DeviceError

SPEC = """
protocol: acks
title: Acknowledged settings
byte_order: little
serial: {baudrate: 115200}
framing:
  elements:
    header: {role: header, value: B5 62}
    code: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: sum, covers: [code, content]}
matching:
  by: [command]
commands:
  set_rate:
    code: 0x10
    request:
      fields:
        rate: {type: u16, range: [1, 1000]}
      answered_by: {command: ack, refused_by: [nak]}
  set_mode:
    code: 0x11
    request:
      fields:
        mode: {type: u8, range: [0, 3]}
      answered_by: {command: ack, refused_by: [nak]}
  ack:
    code: 0x05
    response:
      request_code: acked
      fields:
        acked: u8
  nak:
    code: 0x06
    response:
      request_code: refused
      fields:
        refused: u8
device:
  state: {rate: 1}
"""


def frame(code: int, content: bytes) -> bytes:
    body = bytes([code, len(content)]) + content
    return b"\xb5\x62" + body + bytes([sum(body) & 0xFF])


@pytest.fixture(scope="module")
def acks() -> Iterator[ModuleType]:
    protocol = resolve(load_text(SPEC, "acks.yaml"))
    files = {
        path: text for emitter in emitters() if not emitter.folder for path, text in emitter.files(protocol).items()
    }
    modules = {path.partition("/")[2]: text for path, text in files.items() if path.startswith("acks/")}
    with imported("acks", modules) as package:
        yield package


def test_the_client_gets_another_commands_reply_from_the_simulator(acks: ModuleType) -> None:
    """ACK (code 05) answers set_rate (10) although replies are matched by command; it carries 10, which the
    simulator fills in; a request outside its range gets the NAK, carrying the code of the request it refuses."""
    import acks.client as client_module
    import acks.simulator as simulator_module

    simulator = simulator_module.AcksSimulator(ids=[0])
    path = simulator.start()
    try:
        with client_module.AcksClient(path, timeout=1.0) as client:
            assert client.set_rate(5) is True
            assert client.set_mode(2) is True
            # out of range (the client refuses it, so it goes raw): refused by a NAK of set_rate's code
            client.bus._port.write(frame(0x10, bytes([0, 0])))
            reply = client.bus.receive(1.0)
            assert reply == acks.messages.NakResponse(refused=0x10)
    finally:
        simulator.close()


def peer(controller: int, replies: list[bytes]) -> threading.Thread:
    """A device that reads one request, then writes `replies`."""

    def run() -> None:
        os.read(controller, 64)
        os.write(controller, b"".join(replies))

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread


def test_a_refusal_raises_by_name_and_another_requests_ack_is_not_taken(acks: ModuleType) -> None:
    import acks.client as client_module

    controller, device = os.openpty()
    tty.setraw(device)
    try:
        with client_module.AcksClient(os.ttyname(device), timeout=1.0) as client:
            seen: list[object] = []
            client.subscribe(seen.append)
            # an ACK of set_mode (11) first: not set_rate's, then set_rate's NAK
            thread = peer(controller, [frame(0x05, bytes([0x11])), frame(0x06, bytes([0x10]))])
            with pytest.raises(DeviceError, match="^set_rate: the device refuses it: nak$"):
                client.set_rate(5)
            thread.join()
            assert seen == [acks.messages.AckResponse(acked=0x11)]
            # the NAK of another request is not this one's refusal: its ACK is taken
            thread = peer(controller, [frame(0x06, bytes([0x11])), frame(0x05, bytes([0x10]))])
            assert client.set_rate(5) is True
            thread.join()
    finally:
        os.close(controller)
        os.close(device)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            ("refused_by: [nak]}", "refused_by: [nack]}"),
            "acks.yaml:21:48: commands.set_rate.request.answered_by.refused_by[0]: 'nack' is not a command with a "
            "response",
        ),
        (
            ("refused_by: [nak]}", "refused_by: [ack]}"),
            "acks.yaml:21:48: commands.set_rate.request.answered_by.refused_by[0]: 'ack' is the reply that answers it",
        ),
        (("request_code: acked", "request_code: ackd"), "no integer field 'ackd' in this response (it has: acked)"),
    ],
)
def test_mistakes_are_named(change: tuple[str, str], message: str) -> None:
    with pytest.raises(SpecErrors) as caught:
        resolve(load_text(SPEC.replace(*change, 1), "acks.yaml"))
    assert message in str(caught.value)
