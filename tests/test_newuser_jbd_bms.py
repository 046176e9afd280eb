"""JBD (Jiabaida / Xiaoxiang) smart BMS over its UART (tests/specs/jbd_bms.yaml), written from the user docs alone and
checked against `bmstools` on PyPI (its JBD class): the commands it writes decode as our requests and re-encode byte for
byte, and it reads the basic information, cell voltages and device name from the generated simulator, and switches the
MOSFETs there (password, factory mode, write, exit). Commands carry A5 (read) or 5A (write) and the register where
replies carry the register and a status byte: two layouts chosen by command that are one in replies, and a checksum
(0x10000 - sum) that covers the register in commands but not in replies (`covers` by direction). The V13 document's
reply with three stray bytes is an erratum of the spec."""

from __future__ import annotations

import importlib
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest
import serial
from conftest import examples, generate_and_import, simulated, spec_error
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import ChecksumError

jbd = pytest.importorskip("bmstools.jbd")

SPEC = Path(__file__).parent / "specs" / "jbd_bms.yaml"


@pytest.fixture(scope="module")
def bms(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("jbd"), "jbd_bms")


def peer() -> object:
    return jbd.JBD(serial.Serial())  # the port is opened by the peer, when it talks


@pytest.mark.parametrize(
    ("frame", "name", "fields"),
    [
        (lambda p: p.readCmd(0x03), "BasicInfoRequest", {}),
        (lambda p: p.readCmd(0x04), "CellVoltagesRequest", {}),
        (lambda p: p.readCmd(0x05), "HardwareVersionRequest", {}),
        (lambda p: p.writeCmd(0x00, [0x56, 0x78]), "EnterFactoryRequest", {}),
        (lambda p: p.writeCmd(0x01, [0x28, 0x28]), "ExitFactoryRequest", {"save": 0x2828}),
        (lambda p: p.writeCmd(0x06, [6, *b"J1B2D4"]), "UsePasswordRequest", {}),
        (lambda p: p.writeCmd(0xE1, [0, 2]), "MosControlRequest", {}),
    ],
)
def test_the_peers_commands_are_our_requests(bms: ModuleType, frame: object, name: str, fields: dict[str, int]) -> None:
    golden = frame(peer())  # type: ignore[operator]
    message = bms.decode(golden, bms.Direction.REQUEST)
    assert type(message).__name__ == name
    assert {k: v for k, v in message.to_fields().items() if k in fields} == fields
    assert bms.encode(message) == golden


@settings(max_examples=examples(25), deadline=None)
@given(voltages=st.lists(st.integers(0, 0xFFFF), max_size=32), status=st.sampled_from([0, 0x80]))
def test_replies_follow_the_peers_checksum(bms: ModuleType, voltages: list[int], status: int) -> None:
    """The reply checksum is 0x10000 minus the sum from the status byte to the data's end (not the register)."""
    message = bms.CellVoltagesResponse(status=status, voltages=voltages)
    frame = bms.encode(message)
    assert frame[:3] == bytes([0xDD, 0x04, status]) and frame[-1] == 0x77
    assert int.from_bytes(frame[-3:-1], "big") == jbd.JBD.chksum(frame[2:-3]) & 0xFFFF
    assert bms.decode(frame, bms.Direction.RESPONSE) == message
    with pytest.raises(ChecksumError):
        bms.decode(frame[:-2] + bytes([frame[-2] ^ 1]) + frame[-1:], bms.Direction.RESPONSE)


@pytest.fixture
def sim_path(bms: ModuleType) -> Iterator[str]:
    with simulated("jbd_bms") as path:
        yield path


def test_the_peer_reads_and_drives_the_sim(sim_path: str) -> None:
    port = serial.Serial()
    port.port, port.baudrate = sim_path, 9600
    driver = jbd.JBD(port, timeout=2)
    basic = driver.readBasicInfo()
    assert (basic["pack_mv"], basic["cap_pct"], basic["cell_cnt"], basic["ntc_cnt"]) == (58880, 72, 15, 2)
    assert (basic["year"], basic["month"], basic["day"]) == (2016, 3, 24)
    assert (basic["ntc0"], basic["ntc1"]) == (20.3, 21.5)
    assert (basic["chg_fet_en"], basic["dsg_fet_en"]) == (True, True)
    cells = driver.readCellInfo()
    assert (len(cells), cells["cell0_mv"], cells["cell14_mv"]) == (15, 3942, 3901)
    assert driver.readDeviceInfo() == {"device_name": "JBD-SP15S020"}
    driver.chgDsgEnable(chgEnable=False, dsgEnable=True)  # password, factory mode, the write, exit: each answered
    basic = driver.readBasicInfo()
    assert (basic["chg_fet_en"], basic["dsg_fet_en"]) == (False, True)


def test_the_generated_client_reads_the_sim(bms: ModuleType, sim_path: str) -> None:
    client_module = importlib.import_module("jbd_bms.client")
    with client_module.JbdBmsClient(sim_path, timeout=2) as client:
        info = client.basic_info()
        assert (info.total_voltage, info.rsoc, list(info.temperatures)) == (5888, 72, [2934, 2946])
        assert info.production_date.year == 16
        assert client.hardware_version() == "JBD-SP15S020"


def test_the_c_measures_the_password_by_its_bytes(tmp_path: Path) -> None:
    """`size: {value: len(password)}` of bytes: the C said `m->password_count` (no such member: `password_len`) and
    did not compile."""
    import json

    from test_c_backend import GCC, spec_driver

    if GCC is None:
        pytest.skip("no C compiler")
    driver = spec_driver(SPEC, "jbd_bms", tmp_path)
    try:
        frame = peer().writeCmd(0x06, [6, *b"J1B2D4"]).hex()  # type: ignore[attr-defined]
        said = driver.ask(f"dec request {frame}")[0]
        assert said.startswith("ok ") and json.loads(said[3:])["fields"]["password"] == "4a 31 42 32 44 34"
    finally:
        driver.close()


def test_len_of_text_in_a_value_is_one_line(tmp_path: Path) -> None:
    """Python's len() of text counts characters, the frame its UTF-8 bytes: `value: len(name)` with a text sized by it
    encoded `µm` as 2 followed by 3 bytes, a frame that did not decode. Refused now, naming the form that works."""
    text = SPEC.read_text("utf-8").replace(
        "        name: {type: string, size: rest}",
        '        size: {type: u8, value: "len(name)"}\n        name: {type: string, size: size}',
    )
    assert spec_error(text, tmp_path).endswith(
        "commands.hardware_version.response.fields.size.value: len(name): name is text, whose characters are not its "
        "bytes; size it by a field (`size: size`), which encode then writes"
    )
