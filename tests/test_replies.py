"""Commands and replies beyond one request and one reply per code: requests that share a code, told apart by their
content size (a poll and a set); a request answered by another command's response (`answered_by`) under frames
matched by command, refusals (`refused_by`: the client raises DeviceError naming them, the simulator sends them for a
refused request) and replies carrying the code of the request they answer (`request_code`)."""

from __future__ import annotations

import contextlib
import importlib
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
from serialspec.runtime.errors import DecodeError, DeviceError

# u-blox-like frames: B5 62, the code, a length byte, the content and a sum
FRAME = """
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
"""
SPEC = (
    """
protocol: acks
title: Acknowledged settings
"""
    + FRAME
    + """commands:
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
)


def frame(code: int, content: bytes) -> bytes:
    body = bytes([code, len(content)]) + content
    return b"\xb5\x62" + body + bytes([sum(body) & 0xFF])


@contextlib.contextmanager
def package(text: str, name: str) -> Iterator[ModuleType]:
    protocol = resolve(load_text(text, f"{name}.yaml"))
    files = {
        path: text for emitter in emitters() if not emitter.folder for path, text in emitter.files(protocol).items()
    }
    modules = {path.partition("/")[2]: text for path, text in files.items() if path.startswith(f"{name}/")}
    with imported(name, modules) as generated:
        yield generated


@pytest.fixture(scope="module")
def acks() -> Iterator[ModuleType]:
    with package(SPEC, "acks") as generated:
        yield generated


POLLS = (
    """
protocol: polls
title: A poll and a set under one code
"""
    + FRAME
    + """commands:
  poll_rate:
    code: 0x08
    request: {fields: {}}
    response:
      fields:
        rate: u16
        nav: u16
  set_rate:
    code: 0x08
    request:
      fields:
        rate: {type: u16, range: [1, 1000]}
        nav: u16
  write_name:
    code: 0x09
    request:
      fields:
        slot: u8
  write_long_name:
    code: 0x09
    request:
      fields:
        slot: u8
        flags: u8
        name: {type: bytes, size: rest}
device:
  state: {rate: 1000, nav: 1}
  commands:
    set_rate: {stores: {rate: rate, nav: nav}}
    poll_rate: {reports: {rate: rate, nav: nav}}
"""
)


def test_requests_that_share_a_code_are_told_apart_by_their_content_size() -> None:
    """Each layout its own class, encoded under the one code, decoded (and parsed) by its size; the client polls
    and sets the simulator."""
    with package(POLLS, "polls") as polls:
        m = polls.messages
        for message in (
            m.PollRateRequest(),
            m.SetRateRequest(rate=5, nav=2),
            m.WriteNameRequest(slot=1),
            m.WriteLongNameRequest(slot=1, flags=2, name=b""),
            m.WriteLongNameRequest(slot=1, flags=2, name=b"abc"),
        ):
            encoded = polls.encode(message)
            assert polls.decode(encoded, "request") == message
            assert polls.StreamParser("request").feed(b"\x00" + encoded + encoded) == [message, message]
        with pytest.raises(DecodeError, match="content of 2 bytes fits none of its layouts"):
            polls.decode(frame(0x08, b"\x01\x02"), "request")
        simulator = importlib.import_module("polls.simulator").PollsSimulator(ids=[0])
        path = simulator.start()
        try:
            with importlib.import_module("polls.client").PollsClient(path, timeout=1.0) as client:
                assert client.poll_rate() == m.PollRateResponse(rate=1000, nav=1)
                client.set_rate(7, 3)
                assert client.poll_rate() == m.PollRateResponse(rate=7, nav=3)
        finally:
            simulator.close()


def test_requests_that_share_a_code_need_sizes_that_differ() -> None:
    text = POLLS.replace("        flags: u8\n", "")
    with pytest.raises(SpecErrors) as caught:
        resolve(load_text(text, "polls.yaml"))
    assert str(caught.value).endswith(
        "commands.write_long_name: code 0x09 in request frames is already used by 'write_name', and a content of 1 "
        "byte fits both (requests that share a code are told apart by their content size: 1 byte and 1 byte or more)"
    )


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
            "acks.yaml:22:48: commands.set_rate.request.answered_by.refused_by[0]: 'nack' is not a command with a "
            "response",
        ),
        (
            ("refused_by: [nak]}", "refused_by: [ack]}"),
            "acks.yaml:22:48: commands.set_rate.request.answered_by.refused_by[0]: 'ack' is the reply that answers it",
        ),
        (("request_code: acked", "request_code: ackd"), "no integer field 'ackd' in this response (it has: acked)"),
    ],
)
def test_mistakes_are_named(change: tuple[str, str], message: str) -> None:
    with pytest.raises(SpecErrors) as caught:
        resolve(load_text(SPEC.replace(*change, 1), "acks.yaml"))
    assert message in str(caught.value)


SEQUENCED = """
protocol: sequenced
title: Frames numbered by the client
byte_order: little
serial: {baudrate: 115200}
framing:
  elements:
    header: {role: header, value: AA 55}
    seq: {role: value, type: u8, range: [0, 2], sequence: true}
    flags: {role: value, type: u8}
    code: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: xor, covers: [seq, content]}
matching:
  by: [seq, command]
commands:
  read:
    code: 1
    request:
      fields:
        index: u8
    response:
      fields:
        value: u16
device:
  state: {value: 0}
  commands:
    read: {reports: {value: value}}
"""


def sequenced_frame(seq: int, flags: int, code: int, content: bytes) -> bytes:
    body = bytes([seq, flags, code, len(content)]) + content
    check = 0
    for byte in body:
        check ^= byte
    return b"\xaa\x55" + body + bytes([check])


def test_a_plain_frame_value_and_a_sequence_the_client_fills_in() -> None:
    """`flags` is a plain value (given, and the simulator's reply repeats it); `seq` counts 0, 1, 2, 0 ... per request
    and a reply is matched by it: one with an old number is not taken."""
    with package(SEQUENCED, "sequenced") as sequenced:
        m = sequenced.messages
        message = m.ReadRequest(seq=2, flags=0x81, index=7)
        assert sequenced.decode(sequenced.encode(message), "request") == message
        simulator = importlib.import_module("sequenced.simulator").SequencedSimulator(ids=[0])
        path = simulator.start()
        try:
            with importlib.import_module("sequenced.client").SequencedClient(path, timeout=1.0) as client:
                assert [client.read(0x81, 1) for _ in range(2)] == [0, 0]
        finally:
            simulator.close()
        controller, device = os.openpty()
        tty.setraw(device)
        try:
            with importlib.import_module("sequenced.client").SequencedClient(os.ttyname(device), timeout=1.0) as client:
                sent = []
                for number in range(4):
                    # a late reply of the request before first (numbered one less), then this one's
                    late = sequenced_frame((number + 2) % 3, 0, 1, (1000 + number).to_bytes(2, "little"))
                    answer = sequenced_frame(number % 3, 0, 1, number.to_bytes(2, "little"))

                    def run(late: bytes = late, answer: bytes = answer) -> None:
                        sent.append(os.read(controller, 64))
                        os.write(controller, late + answer)

                    thread = threading.Thread(target=run, daemon=True)
                    thread.start()
                    assert client.read(5, 9) == number
                    thread.join()
                assert [frame[2] for frame in sent] == [0, 1, 2, 0]  # seq: wraps past its range
                assert {frame[3] for frame in sent} == {5}  # flags as given
        finally:
            os.close(controller)
            os.close(device)
