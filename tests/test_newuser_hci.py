"""Bluetooth HCI over UART, H4 (tests/specs/hci_h4.yaml), written from the user docs alone and checked against bumble:
the commands its HCI classes serialise decode to their values and re-encode byte for byte, its HCI_Packet parser
reads the events and ACL packets we encode and we read its, its Host drives the generated simulator over a
pseudo-terminal, as does the generated client. The packet type byte is each layout's header (01 command, 04 event,
02 ACL, each command naming its layout); Command Complete's return parameters are picked by the opcode after
num_packets, a u16 selector at offset 1.

Bugs this found, fixed: the Python decoder read a selector of more than one byte as its first byte (`unknown
sub-command 0x03` for HCI_Reset's 0x0C03); a request `answered_by` a sub-command's response that also `answers` it
(both sides saying the same) got no reply at all: the client's method sent and returned None, the simulator stayed
silent."""

from __future__ import annotations

import asyncio
import importlib
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples, generate_and_import, simulated
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import DecodeError

hci = pytest.importorskip("bumble.hci")

SPEC = Path(__file__).parent / "specs" / "hci_h4.yaml"
U16 = st.integers(0, 0xFFFF)


@pytest.fixture(scope="module")
def h4(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("hci"), "hci_h4")


@settings(max_examples=examples(10), deadline=None)
@given(enable=st.integers(0, 1), duplicates=st.integers(0, 1))
def test_the_peers_commands_are_our_requests(h4: ModuleType, enable: int, duplicates: int) -> None:
    for command, ours in (
        (hci.HCI_Reset_Command(), h4.ResetRequest()),
        (hci.HCI_Read_BD_ADDR_Command(), h4.ReadBdAddrRequest()),
        (hci.HCI_Read_Local_Version_Information_Command(), h4.ReadLocalVersionRequest()),
        (
            hci.HCI_LE_Set_Scan_Enable_Command(le_scan_enable=enable, filter_duplicates=duplicates),
            h4.LeSetScanEnableRequest(enable, duplicates),
        ),
    ):
        frame = bytes(command)
        assert h4.decode(frame, h4.Direction.REQUEST) == ours
        assert h4.encode(ours) == frame


@settings(max_examples=examples(20), deadline=None)
@given(version=st.integers(0, 13), sub=U16, company=U16, lmp=U16, packets=st.integers(0, 255))
def test_command_complete_both_ways(
    h4: ModuleType, version: int, sub: int, company: int, lmp: int, packets: int
) -> None:
    ours = h4.CommandCompleteReadLocalVersionResponse(packets, 0, version, sub, version, company, lmp)
    event = hci.HCI_Packet.from_bytes(h4.encode(ours))
    assert isinstance(event, hci.HCI_Command_Complete_Event)
    assert (event.num_hci_command_packets, event.command_opcode) == (packets, 0x1001)
    got = event.return_parameters
    assert (got.status, got.hci_version, got.hci_subversion) == (0, version, sub)
    assert (got.lmp_version, got.company_identifier, got.lmp_subversion) == (version, company, lmp)
    theirs = hci.HCI_Command_Complete_Event(
        num_hci_command_packets=packets, command_opcode=hci.HCI_RESET_COMMAND, return_parameters=bytes([0])
    )
    assert h4.decode(bytes(theirs), h4.Direction.RESPONSE) == h4.CommandCompleteResetResponse(packets, 0)


@settings(max_examples=examples(20), deadline=None)
@given(
    handle=st.integers(0, 0x0EFF),
    boundary=st.integers(0, 3),
    data=st.binary(max_size=40),
    reason=st.sampled_from([0x05, 0x13, 0x16]),
)
def test_acl_data_and_a_disconnection_both_ways(
    h4: ModuleType, handle: int, boundary: int, data: bytes, reason: int
) -> None:
    acl = hci.HCI_AclDataPacket(
        connection_handle=handle, pb_flag=boundary, bc_flag=0, data_total_length=len(data), data=data
    )
    message = h4.decode(bytes(acl), h4.Direction.RESPONSE)
    assert (message.handle.connection, message.handle.boundary, message.data) == (handle, boundary, data)
    assert h4.encode(message) == bytes(acl)
    theirs = hci.HCI_Packet.from_bytes(h4.encode(h4.AclDataRequest(h4.HandleBits(handle, boundary), data)))
    assert (theirs.connection_handle, theirs.pb_flag, theirs.data) == (handle, boundary, data)
    event = hci.HCI_Disconnection_Complete_Event(status=0, connection_handle=handle, reason=reason)
    ours = h4.DisconnectionCompleteResponse(0, handle, reason)
    assert h4.decode(bytes(event), h4.Direction.RESPONSE) == ours and h4.encode(ours) == bytes(event)


def test_packets_in_a_stream_and_an_unknown_opcode(h4: ModuleType) -> None:
    frames = [
        bytes.fromhex("04 0e 04 01 03 0c 00"),
        bytes.fromhex("02 01 20 03 00 61 62 63"),
        bytes.fromhex("04 0e 0a 01 09 10 00 66 55 44 33 22 11"),
        bytes.fromhex("04 05 04 00 01 00 13"),
    ]
    stream = b"".join(frames)
    parser = h4.StreamParser(h4.Direction.RESPONSE)
    got = [m for i in range(0, len(stream), 3) for m in parser.feed(stream[i : i + 3])]
    assert [h4.encode(m) for m in got] == frames
    with pytest.raises(DecodeError, match="unknown sub-command 0xc04"):  # was 0x04: the selector's first byte
        h4.decode(bytes.fromhex("04 0e 04 01 04 0c 00"), h4.Direction.RESPONSE)


@pytest.fixture
def sim(h4: ModuleType) -> Iterator[str]:
    with simulated("hci_h4") as path:
        yield path


def test_the_peer_drives_the_sim(sim: str) -> None:
    from bumble.host import Host
    from bumble.transport import open_transport

    async def session() -> tuple[object, object]:
        async with await open_transport(f"serial:{sim}") as transport:
            host = Host(transport.source, transport.sink)
            await host.send_command(hci.HCI_Reset_Command())  # the host takes nothing else before the reset
            host.ready = True
            address = await host.send_command(hci.HCI_Read_BD_ADDR_Command())
            version = await host.send_command(hci.HCI_Read_Local_Version_Information_Command())
            return address.return_parameters, version.return_parameters

    address, version = asyncio.run(asyncio.wait_for(session(), 20))
    assert str(address.bd_addr).startswith("11:22:33:44:55:66")
    assert (version.hci_version, version.company_identifier, version.lmp_subversion) == (13, 0x05F1, 0x5678)


def test_the_generated_client_drives_the_sim(h4: ModuleType, sim: str) -> None:
    client_module = importlib.import_module("hci_h4.client")
    with client_module.HciH4Client(sim, timeout=3) as client:
        # was None, the request sent and nothing awaited (answered_by beside the reply's `answers`)
        assert client.reset() == h4.CommandCompleteResetResponse(1, 0)
        assert client.read_bd_addr().bd_addr == bytes.fromhex("66 55 44 33 22 11")
        assert client.read_local_version().company_identifier == 0x05F1
