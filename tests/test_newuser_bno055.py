"""Bosch BNO055 over its UART (tests/specs/bno055.yaml), written from the datasheet by a new user: layouts chosen by
command whose replies carry no code (a read is answered by BB length data, a write by EE status), and a read refused
by the EE status reply, in that reply's own layout (`refused_by: [write]`). The codec, the stream parser, the client
on a real pseudo-terminal and the C decoder and parser read the refusal as the write's status reply; a frame of a
layout no request uses is no request (it was a traceback once)."""

from __future__ import annotations

import importlib
import json
import os
import threading
import tty
from pathlib import Path
from types import ModuleType

import pytest
from conftest import generate_and_import
from serialspec.runtime.errors import DecodeError, DeviceError

SPEC = Path(__file__).parent / "specs" / "bno055.yaml"
READ = bytes.fromhex("aa 01 08 02")  # read 2 bytes from register 0x08


@pytest.fixture(scope="module")
def bno(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("bno055"), "bno055")


def test_a_refusal_in_its_own_layout_is_the_reply_to_a_read(bno: ModuleType) -> None:
    read = bno.decode(READ, bno.Direction.REQUEST)
    assert read == bno.ReadRequest(register=8, length=2)
    refused = bno.decode(bytes.fromhex("ee 07"), bno.Direction.RESPONSE, request=read)
    assert refused == bno.WriteResponse(status=bno.Status.BUS_OVER_RUN_ERROR)
    assert bno.decode(bytes.fromhex("bb 02 01 02"), bno.Direction.RESPONSE, request=read) == bno.ReadResponse(
        data=b"\x01\x02"
    )
    with pytest.raises(DecodeError, match="^start is cc, expected bb$"):  # neither: the reply's own reason
        bno.decode(bytes.fromhex("cc 07"), bno.Direction.RESPONSE, request=read)


def test_a_frame_of_a_reply_layout_is_no_request(bno: ModuleType) -> None:
    """The status layout carries nothing in requests: `EE 07` as a request said `TypeError: unsupported format
    string passed to NoneType.__format__` (a codeless request layout no command uses, read as one)."""
    with pytest.raises(DecodeError, match="^frame starts ee 07, expected aa$"):
        bno.decode(bytes.fromhex("ee 07"), bno.Direction.REQUEST)


@pytest.mark.parametrize("cut", [1, 2, 3, 7])
def test_the_stream_parser_reads_the_refusal_however_split(bno: ModuleType, cut: int) -> None:
    read = bno.decode(READ, bno.Direction.REQUEST)
    stream = bytes.fromhex("ee 02 bb 02 01 02")
    parser = bno.StreamParser(bno.Direction.RESPONSE)
    parser.expect(bno.ReadResponse, read)
    found = [m for i in range(0, len(stream), cut) for m in parser.feed(stream[i : i + cut])]
    assert found == [bno.WriteResponse(status=bno.Status.READ_FAIL), bno.ReadResponse(data=b"\x01\x02")]
    assert (parser.garbage, parser.errors) == (0, 0)


def peer(controller: int, reply: bytes) -> threading.Thread:
    """A BNO055 that reads one request, then writes `reply`."""

    def run() -> None:
        os.read(controller, 64)
        os.write(controller, reply)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread


def test_the_client_raises_the_refusal_by_name(bno: ModuleType) -> None:
    client_module = importlib.import_module("bno055.client")
    controller, device = os.openpty()
    tty.setraw(device)
    try:
        with client_module.Bno055Client(os.ttyname(device), timeout=1.0) as client:
            thread = peer(controller, bytes.fromhex("ee 07"))
            with pytest.raises(DeviceError, match="^read: the device refuses it: write$") as refused:
                client.read(8, 2)
            thread.join()
            assert refused.value.reply == bno.WriteResponse(status=bno.Status.BUS_OVER_RUN_ERROR)
            thread = peer(controller, bytes.fromhex("bb 02 01 02"))
            assert client.read(8, 2) == b"\x01\x02"
            thread.join()
    finally:
        os.close(controller)
        os.close(device)


def test_the_c_reads_the_refusal(tmp_path: Path) -> None:
    from test_c_backend import GCC, Driver

    if GCC is None:
        pytest.skip("no C compiler")
    from serialspec.cli import main as serialspec_main

    assert serialspec_main(["generate", str(SPEC), "--out", str(tmp_path), "--target", "c"]) == 0
    driver = Driver("bno055", tmp_path / "bno055", tmp_path)
    try:
        assert driver.ask(f"req request {READ.hex()}") == ["ok"]
        said = driver.ask("dec response ee07")[0]
        assert said.startswith("ok ") and json.loads(said[3:])["command"] == "write"
        assert json.loads(said[3:])["fields"] == {"status": 7}
        said = driver.ask("dec response bb020102")[0]
        assert said.startswith("ok ") and json.loads(said[3:])["command"] == "read"
        lines = driver.ask("stream response 1,2,3 ee02bb020102 read_response")
        messages = [json.loads(line[4:]) for line in lines if line.startswith("msg ")]
        assert [(m["command"], m["fields"]) for m in messages] == [
            ("write", {"status": 2}),
            ("read", {"data": "01 02"}),
        ]
        assert lines[-1] == "end 2 0 0 0"
    finally:
        driver.close()
