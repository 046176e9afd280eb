"""Trinamic TMCL (tests/specs/tmcl.yaml), written from the user docs alone and checked against pytrinamic: the
datagrams its TMCLRequest builds are our requests (decoded to its values, re-encoded byte for byte), its TMCLReply
reads our replies and we read its, and its SerialTmclInterface drives the generated simulator over a pseudo-terminal,
as does the generated client.

Bugs this found, each fixed generally: a status element whose success is 100, not 0 (`ok: [100, 101]`; the client
raised DeviceError for every successful reply); a data space read into a single response field (the simulator sent
`[value]` where a number was due, and so no reply at all); a data space of signed words (`type: i32`: only unsigned
items existed, so -51200 written came back as 4294916096, outside the reply's i32); and the client's Get Axis
Parameter returned the reply address, taking the reply's `value` for an echo of the request's unused `value`."""

from __future__ import annotations

import importlib
import os
import struct
import threading
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import, simulated, spec_error
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import DeviceError

pytrinamic = pytest.importorskip("pytrinamic")
from pytrinamic.connections.serial_tmcl_interface import SerialTmclInterface  # noqa: E402
from pytrinamic.tmcl import TMCLCommand, TMCLReply, TMCLRequest  # noqa: E402

SPEC = Path(__file__).parent / "specs" / "tmcl.yaml"
I32 = st.integers(-(2**31), 2**31 - 1)
U8 = st.integers(0, 255)


@pytest.fixture(scope="module")
def tmcl(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("tmcl"), "tmcl")


# (pytrinamic's command, our request class, the names our request gives its type, motor and value)
COMMANDS = [
    (TMCLCommand.ROR, "RorRequest", ("type", "motor", "velocity")),
    (TMCLCommand.ROL, "RolRequest", ("type", "motor", "velocity")),
    (TMCLCommand.MST, "MstRequest", ("type", "motor", "value")),
    (TMCLCommand.SAP, "SapRequest", ("type", "motor", "value")),
    (TMCLCommand.GAP, "GapRequest", ("type", "motor", "value")),
    (TMCLCommand.SGP, "SgpRequest", ("type", "bank", "value")),
    (TMCLCommand.GGP, "GgpRequest", ("type", "bank", "value")),
]


@settings(max_examples=examples(20), deadline=None)
@given(which=st.sampled_from(COMMANDS), address=U8, kind=U8, motor=U8, value=I32)
def test_the_peers_requests_are_ours(
    tmcl: ModuleType, which: tuple[int, str, tuple[str, str, str]], address: int, kind: int, motor: int, value: int
) -> None:
    command, name, (type_name, motor_name, value_name) = which
    frame = TMCLRequest(address, command, kind, motor, value).to_buffer()  # value & 0xFFFFFFFF, as it sends it
    message = tmcl.decode(frame, tmcl.Direction.REQUEST)
    assert type(message).__name__ == name
    assert (message.module_address, getattr(message, type_name), getattr(message, motor_name)) == (address, kind, motor)
    assert getattr(message, value_name) == value  # signed: the peer sends a u32 of the same bits
    assert tmcl.encode(message) == frame


@pytest.mark.parametrize("move", [0, 1, 2])
def test_a_move_and_the_version_requests(tmcl: ModuleType, move: int) -> None:
    frame = TMCLRequest(1, TMCLCommand.MVP, move, 0, -9000).to_buffer()
    message = tmcl.decode(frame, tmcl.Direction.REQUEST)
    assert (message.type, message.position) == (tmcl.MoveType(move), -9000)
    assert tmcl.encode(message) == frame
    # Get Firmware Version: type 0 (an ASCII reply) and type 1 (binary) are two messages under 136, picked by type
    ascii_request = tmcl.decode(TMCLRequest(1, TMCLCommand.GET_FIRMWARE_VERSION, 0, 0, 0).to_buffer())
    binary_request = tmcl.decode(TMCLRequest(1, TMCLCommand.GET_FIRMWARE_VERSION, 1, 0, 0).to_buffer())
    assert isinstance(ascii_request, tmcl.GetVersionStringRequest)
    assert isinstance(binary_request, tmcl.GetFirmwareVersionRequest)


@settings(max_examples=examples(20), deadline=None)
@given(host=U8, address=U8, status=st.sampled_from([1, 2, 3, 4, 5, 6, 9, 100, 101]), value=I32)
def test_replies_both_ways(tmcl: ModuleType, host: int, address: int, status: int, value: int) -> None:
    ours = tmcl.encode(tmcl.GapResponse(reply_address=host, module_address=address, status=status, value=value))
    peer = TMCLReply.from_buffer(ours)
    assert peer.is_checksum_correct()
    assert (peer.reply_address, peer.module_address, peer.status, peer.command) == (host, address, status, 6)
    assert struct.unpack(">i", struct.pack(">I", peer.value))[0] == value
    theirs = TMCLReply(host, address, status, TMCLCommand.GAP, value).to_buffer()
    assert theirs == ours
    assert tmcl.decode(theirs, tmcl.Direction.RESPONSE) == tmcl.GapResponse(host, address, status, value)


def test_a_damaged_datagram_is_refused(tmcl: ModuleType) -> None:
    from serialspec.runtime.errors import ChecksumError

    frame = TMCLReply(2, 1, 100, TMCLCommand.GGP, 7).to_buffer()
    with pytest.raises(ChecksumError):
        tmcl.decode(frame[:-1] + bytes([frame[-1] ^ 0x10]), tmcl.Direction.RESPONSE)
    parser = tmcl.StreamParser(tmcl.Direction.RESPONSE)
    assert parser.feed(frame[:4]) + parser.feed(frame[4:]) == [tmcl.GgpResponse(2, 1, 100, 7)]


@pytest.mark.xfail(
    strict=True,
    reason="gap: a reply layout told only by the request it answers (no header, no command element: TMCL's "
    "Get Firmware Version type 0, the reply address and 8 characters) beside replies that carry their code: the "
    "stream parser reads it whether or not that request awaits it, so any 9 bytes are one",
)
def test_a_version_string_is_read_only_while_awaited(tmcl: ModuleType) -> None:
    frame = TMCLReply(2, 1, 100, TMCLCommand.GGP, 7).to_buffer()
    parser = tmcl.StreamParser(tmcl.Direction.RESPONSE)
    replies = [parser.feed(bytes([b])) for b in frame[:5] + frame]
    assert [m for got in replies for m in got] == [tmcl.GgpResponse(2, 1, 100, 7)]


def test_the_version_string_reply_is_read_with_its_request(tmcl: ModuleType) -> None:
    request = tmcl.GetVersionStringRequest(module_address=1)
    reply = tmcl.decode(bytes.fromhex("02 31 31 34 30 56 31 33 30"), tmcl.Direction.RESPONSE, request=request)
    assert reply == tmcl.GetVersionStringResponse(reply_address=2, text="1140V130")
    assert TMCLReply.from_buffer(tmcl.encode(reply, request=request)).version_string() == "1140V130"


@pytest.fixture
def sim(tmcl: ModuleType) -> Iterator[str]:
    with simulated("tmcl") as path:
        yield path


def test_the_peer_drives_the_sim(sim: str) -> None:
    with SerialTmclInterface(sim, timeout_s=5) as bus:
        bus.set_axis_parameter(4, 0, -51200)  # maximum speed, a negative value to see the sign kept
        assert bus.get_axis_parameter(4, 0, signed=True) == -51200  # 4294916096 once: the space held u32 words
        assert bus.get_axis_parameter(5, 0) == 0
        bus.set_global_parameter(65, 0, 7)
        assert bus.get_global_parameter(65, 0) == 7
        assert bus.move_to(0, 9000) == 0  # the reply's value; its checksum and status 100 checked by the peer
        assert bus.get_version_string() == "1140V130"
        assert bus.send(TMCLCommand.GET_FIRMWARE_VERSION, 1, 0, 0).value == 0x04740130


def test_the_generated_client_drives_the_sim(tmcl: ModuleType, sim: str) -> None:
    client_module = importlib.import_module("tmcl.client")
    with client_module.TmclClient(sim, timeout=3) as client:
        client.sap(1, 4, 0, -51200)  # the reply's value is checked as an echo of the request's (`echoes`)
        # was the reply address (2): the reply's `value` taken for an echo of the request's unused `value`; and
        # before that a DeviceError for status 100
        assert client.gap(1, 4, 0) == -51200
        assert client.get_version_string(1) == "1140V130"
        assert client.get_firmware_version(1) == 0x04740130


def test_a_status_below_100_is_a_device_error(tmcl: ModuleType) -> None:
    client_module = importlib.import_module("tmcl.client")
    controller, device = os.openpty()
    os.set_blocking(controller, True)

    def module() -> None:  # answers two requests: an invalid value (4), then stored in EEPROM (101)
        for status in (4, 101):
            request = b""
            while len(request) < 9:
                request += os.read(controller, 9 - len(request))
            os.write(controller, TMCLReply(2, 1, status, request[1], 5).to_buffer())

    thread = threading.Thread(target=module, daemon=True)
    thread.start()
    try:
        with client_module.TmclClient(os.ttyname(device), timeout=3) as client:
            with pytest.raises(DeviceError, match="status = 0x04"):
                client.ggp(1, 65, 0)
            assert client.ggp(1, 65, 0) == 5  # 101 is success too
    finally:
        thread.join(5)
        os.close(controller)
        os.close(device)


def test_ok_is_refused_where_it_means_nothing(tmp_path: Path) -> None:
    text = SPEC.read_text("utf-8")
    moved = text.replace("          ok: [100, 101]\n", "").replace(
        "        command:\n          role: command\n          type: u8\n",
        "        command:\n          role: command\n          type: u8\n          ok: [1]\n",
    )
    assert spec_error(moved, tmp_path).endswith("`ok` belongs to a status element")
    too_wide = text.replace("ok: [100, 101]", "ok: [100, 300]")
    assert spec_error(too_wide, tmp_path).endswith("ok value 300 does not fit u8")
    with_bits = text.replace("ok: [100, 101]", "ok: [100]\n          bits: {code: [7, 0]}")
    assert spec_error(with_bits, tmp_path).endswith("`ok` compares the status as one number: give it without `bits`")
    counted = text.replace(
        "gap: {reads: {value: {space: axis_parameters, start: type}}}",
        "gap: {reads: {value: {space: axis_parameters, start: type, count: motor}}}",
    )
    assert spec_error(counted, tmp_path).endswith("value is one number, not an array: a run read into it is one item")
