"""Trinamic TMC2209 UART (tests/specs/tmc2209.yaml), written from the user docs alone and checked against
pytmcstepper: the requests its TmcComUartBase builds are our golden frames (decoded to its values, re-encoded byte
for byte), it reads the replies we build, it drives `serialspec sim --echo` over a pseudo-terminal (read_int,
write_reg, write_reg_check and its Tmc2209 driver), as does the generated client, and our stream parser reads a noisy
stream of its frames.

pytmcstepper's package imports its GPIO layer, which on a machine that is no Raspberry Pi imports `Mock.GPIO` (the
`Mock.GPIO` distribution pins two dozen packages, rich 13 among them, against our constraints): a stand-in module with
the constants it reads is put in its place, and no test here touches a pin."""

from __future__ import annotations

import importlib
import importlib.util
import sys
import types
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from conftest import generate_and_import
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.runtime.errors import DecodeError, EncodeError, Timeout
from sim_process import serve

if importlib.util.find_spec("Mock") is None:  # before tmc_driver imports it (see the module docstring)
    _gpio = types.ModuleType("Mock.GPIO")
    _gpio.__dict__.update(BCM=11, BOARD=10, IN=1, OUT=0, HIGH=1, LOW=0, PUD_OFF=20, PUD_UP=22, PUD_DOWN=21, RISING=31)
    for _name in ("setwarnings", "setmode", "cleanup", "setup", "output", "input"):
        setattr(_gpio, _name, lambda *args, **kwargs: 0)
    _mock = types.ModuleType("Mock")
    _mock.GPIO = _gpio  # type: ignore[attr-defined]
    sys.modules.setdefault("Mock", _mock)
    sys.modules.setdefault("Mock.GPIO", _gpio)

tmc_driver = pytest.importorskip("tmc_driver")
from tmc_driver.com._tmc_com import compute_crc8_atm  # noqa: E402
from tmc_driver.com._tmc_com_uart import TmcComUart  # noqa: E402
from tmc_driver.com._tmc_com_uart_base import TmcComUartBase  # noqa: E402
from tmc_driver.tmc_logger import Loglevel, TmcLogger  # noqa: E402

SPEC = Path(__file__).parent / "specs" / "tmc2209.yaml"
# register address -> (read command, write command or None) of the spec
REGISTERS = {
    0x00: ("read_gconf", "write_gconf"),
    0x01: ("read_gstat", "write_gstat"),
    0x02: ("read_ifcnt", None),
    0x06: ("read_ioin", None),
    0x10: ("read_ihold_irun", "write_ihold_irun"),
    0x11: ("read_tpowerdown", "write_tpowerdown"),
    0x12: ("read_tstep", None),
    0x13: ("read_tpwmthrs", "write_tpwmthrs"),
    0x14: ("read_tcoolthrs", "write_tcoolthrs"),
    0x22: ("read_vactual", "write_vactual"),
    0x40: ("read_sgthrs", "write_sgthrs"),
    0x41: ("read_sg_result", None),
    0x42: ("read_coolconf", "write_coolconf"),
    0x6A: ("read_mscnt", None),
    0x6C: ("read_chopconf", "write_chopconf"),
    0x6F: ("read_drv_status", None),
    0x70: ("read_pwmconf", "write_pwmconf"),
}
WRITABLE = sorted(a for a, (_, write) in REGISTERS.items() if write)
LOG = TmcLogger(Loglevel.ERROR, "tmc2209-test")


@pytest.fixture(scope="module")
def tmc(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    return generate_and_import(SPEC, tmp_path_factory.mktemp("tmc2209"), "tmc2209")


class Recorder(TmcComUartBase):  # type: ignore[misc]
    """pytmcstepper's UART code with the port replaced: keeps what it writes, reads back `answer`."""

    def __init__(self, node: int = 0, answer: bytes = b"") -> None:
        super().__init__()
        self.ser = types.SimpleNamespace(is_open=True)
        self.tmc_logger = LOG
        self.driver_address = node
        self.written = b""
        self.answer = answer

    def init(self) -> None:
        pass

    def deinit(self) -> None:
        pass

    def _uart_write(self, data: list[int]) -> int:
        self.written += bytes(data)
        return len(data)

    def _uart_read(self, length: int) -> bytes:
        return self.answer[:length]

    def _uart_flush(self) -> None:
        pass


def peer_read(node: int, register: int) -> bytes:
    peer = Recorder(node)
    peer.read_reg(register)
    return peer.written


def peer_write(node: int, register: int, value: int) -> bytes:
    peer = Recorder(node)
    assert peer.write_reg(register, value)
    return peer.written


def bits_of(tmc: ModuleType, command: str, direction: str, value: int) -> Any:
    """The message field for a register value: its bit fields, or the number itself."""
    cls = getattr(tmc, "".join(p.title() for p in command.split("_")) + direction)
    name = command.split("_", 1)[1]
    bits = getattr(tmc, "".join(p.title() for p in name.split("_")) + "Bits", None)
    if bits is None:
        return cls, name, value
    fields = {b: (value >> low) & ((1 << (high - low + 1)) - 1) for b, low, high in BIT_LAYOUT[name]}
    return cls, name, bits.from_fields(fields)


# the bit fields of the registers that have them, from pytmcstepper's reg/_tmc220x_reg.py and _tmc2209_reg.py
BIT_LAYOUT: dict[str, list[tuple[str, int, int]]] = {}


@pytest.fixture(scope="module", autouse=True)
def _bit_layout(tmc: ModuleType) -> None:
    import yaml

    spec = yaml.safe_load(SPEC.read_text("utf-8"))
    for name, field in spec["fields"].items():
        if "bits" in field:
            layout = []
            for bit_name, bit in field["bits"].items():
                high, low = (bit["bits"], bit["bits"]) if isinstance(bit["bits"], int) else bit["bits"]
                layout.append((bit_name, low, high))
            BIT_LAYOUT[name] = layout


@settings(max_examples=30, deadline=None)
@given(node=st.integers(0, 3), register=st.sampled_from(sorted(REGISTERS)))
def test_the_peers_read_requests_decode_and_re_encode(tmc: ModuleType, node: int, register: int) -> None:
    golden = peer_read(node, register)
    message = tmc.decode(golden, tmc.Direction.REQUEST)
    assert REGISTERS[register][0] == message.COMMAND
    assert (message.node, message.sync.nibble, message.sync.reserved) == (node, 5, 5)  # pytmcstepper sends 0x55
    assert tmc.encode(message) == golden


@settings(max_examples=40, deadline=None)
@given(node=st.integers(0, 3), register=st.sampled_from(WRITABLE), data=st.data())
def test_the_peers_writes_decode_and_re_encode(tmc: ModuleType, node: int, register: int, data: Any) -> None:
    command = REGISTERS[register][1]
    assert command is not None
    cls, name, _ = bits_of(tmc, command, "Request", 0)
    if name == "vactual":
        value = data.draw(st.integers(-(2**23) + 1, 2**23 - 1))
    elif name in BIT_LAYOUT:
        value = sum(data.draw(st.integers(0, (1 << (h - lo + 1)) - 1)) << lo for _, lo, h in BIT_LAYOUT[name])
    else:
        value = data.draw(st.integers(0, {"tpowerdown": 255, "sgthrs": 255}.get(name, 2**20 - 1)))
    golden = peer_write(node, register, value)
    _, _, field = bits_of(tmc, command, "Request", value)
    message = cls(sync=tmc.SyncBits(nibble=5, reserved=5), node=node, **{name: field})
    assert tmc.encode(message) == golden
    assert tmc.decode(golden, tmc.Direction.REQUEST) == message


def test_the_peer_reads_our_replies(tmc: ModuleType) -> None:
    """pytmcstepper's read_int (4 echo bytes, then the 8-byte reply, its CRC checked) takes our replies."""
    cases = [(0x00, 0x000001C0), (0x06, 0x21000300), (0x6C, 0x15000053), (0x6F, 0xC01F0000), (0x22, -1000)]
    for register, value in cases:
        read, _ = REGISTERS[register]
        cls, name, field = bits_of(tmc, read, "Response", value)
        reply = tmc.encode(cls(sync=tmc.SyncBits(nibble=5, reserved=0), **{name: field}))
        peer = Recorder(0, peer_read(0, register) + reply)
        assert peer.read_int(register)[0] == (value if value < 0x80000000 else value - 2**32), reply.hex(" ")


def test_the_spec_crc_is_the_peers(tmc: ModuleType) -> None:
    """CRC-8 poly 0x07, init 0, refin true, refout false: check value 0x04, as compute_crc8_atm gives."""
    assert compute_crc8_atm(list(b"123456789")) == 0x04
    frame = tmc.encode(tmc.ReadIfcntRequest(sync=tmc.SyncBits(nibble=5, reserved=0), node=3))
    assert frame[-1] == compute_crc8_atm(list(frame[:-1]))


def test_the_stream_parser_reads_a_noisy_stream_of_the_peers_frames(tmc: ModuleType) -> None:
    import random

    rng = random.Random(2209)
    frames = [peer_read(n, r) for n in range(4) for r in (0x00, 0x06, 0x6F)]
    frames += [peer_write(n, r, v) for n, r, v in ((0, 0x00, 0x1C0), (1, 0x10, 0x11F10), (3, 0x22, -5), (2, 0x6C, 1))]
    rng.shuffle(frames)
    stream = b""
    for frame in frames:
        stream += bytes(rng.randrange(256) for _ in range(rng.randrange(4))) + frame
    parser = tmc.StreamParser(tmc.Direction.REQUEST)
    seen = []
    at = 0
    while at < len(stream):
        step = rng.randrange(1, 6)
        seen += parser.feed(stream[at : at + step])
        at += step
    assert [tmc.encode(m) for m in seen] == frames


@pytest.fixture(scope="module")
def sim_path() -> Iterator[str]:
    with serve(str(SPEC), 0, 2, options=["--echo"]) as path:
        yield path


@pytest.fixture
def uart(sim_path: str) -> Iterator[TmcComUart]:
    com = TmcComUart(sim_path, 115200)
    com.tmc_logger = LOG
    com.init()
    com.communication_pause = 0.005  # its own is 500 / baud; the echo must be back before the next flush
    yield com
    com.deinit()


def test_the_peer_reads_and_writes_registers_of_the_sim(uart: TmcComUart) -> None:
    assert uart.read_int(0x06)[0] >> 24 == 0x21  # IOIN VERSION
    count = uart.read_int(0x02)[0]  # IFCNT
    assert uart.write_reg(0x13, 12345)
    assert uart.read_int(0x02)[0] == (count + 1) % 256
    assert uart.read_int(0x13)[0] == 12345
    assert uart.write_reg(0x22, -1000)  # VACTUAL: signed, sent sign-extended
    assert uart.read_int(0x22)[0] == -1000


def test_the_peers_tmc2209_driver_runs_against_the_sim(sim_path: str) -> None:
    from tmc_driver import Tmc2209
    from tmc_driver.enable_control import TmcEnableControlToff
    from tmc_driver.motion_control import TmcMotionControlVActual

    driver = Tmc2209(
        TmcEnableControlToff(), TmcMotionControlVActual(), TmcComUart(sim_path, 115200), loglevel=Loglevel.ERROR
    )
    try:
        assert driver.tmc_com is not None
        driver.tmc_com.communication_pause = 0.005
        driver.set_microstepping_resolution(16)
        assert driver.get_microstepping_resolution() == 16
        driver.set_spreadcycle(True)
        assert driver.get_spreadcycle() is True
        assert driver.set_current_rms(600) > 0
        driver.ihold_irun.read()
        assert 0 < driver.ihold_irun.irun <= 31
        driver.set_motor_enabled(False)
        driver.chopconf.read()
        assert driver.chopconf.toff == 0
        driver.ioin.read()
        assert driver.ioin.version == 0x21
        assert driver.tmc_com.write_reg_check(0x70, 0xC10D0025)  # IFCNT read before and after the write
        assert driver.tmc_com.read_int(0x70)[0] & 0xFFFFFFFF == 0xC10D0025  # read_int is signed
    finally:
        driver.deinit()


def test_the_generated_client_against_the_sim(tmc: ModuleType, sim_path: str) -> None:
    client_module = importlib.import_module("tmc2209.client")
    sync = tmc.SyncBits(nibble=5, reserved=0)
    with client_module.Tmc2209Client(sim_path, echo=True) as driver:
        assert driver.read_ioin(sync, 0).version == 0x21
        assert driver.read_ioin(node=0).version == 0x21  # the datasheet's sync byte, 0x05
        driver.write_tpowerdown(sync, 0, 100)
        assert driver.read_tpowerdown(sync, 0) == 100
        chop = driver.read_chopconf(sync, 0)
        driver.write_chopconf(sync, 0, tmc.ChopconfBits.from_fields({**chop.to_fields(), "mres": 4}))
        assert driver.read_chopconf(sync, 0).mres == tmc.Microsteps.MS16
        with pytest.raises(Exception, match="outside its range"):
            driver.write_sgthrs(sync, 0, 256)
        # Found here: replies carry no node address (0xFF), so the Timeout named no device ("from the device")
        with pytest.raises(Timeout, match="^no reply to read_gconf from node=1 within"):
            driver.read_gconf(sync, 1)


def test_client_arguments_of_frame_values_with_bit_fields_are_their_bits_class(tmc: ModuleType) -> None:
    """Found writing this spec: the client annotated a frame value made of bit fields (the sync byte) as `int`,
    while the message takes (and checks for) its bits class."""
    import inspect

    client_module = importlib.import_module("tmc2209.client")
    parameters = inspect.signature(client_module.Tmc2209Client.read_gconf).parameters
    assert parameters["sync"].annotation == "SyncBits"


def test_the_sim_keeps_a_register_of_bit_fields_as_one_integer(tmc: ModuleType) -> None:
    """Found writing this spec: a response field made of bit fields read from a memory entry (a register's integer)
    was no reply at all ("gconf must be an object"), and a written one was kept as a mapping."""
    sim = importlib.import_module("tmc2209.simulator").Tmc2209Simulator(ids=[0])
    sync = tmc.SyncBits(nibble=5, reserved=5)
    [(_, frame)] = sim.handle(tmc.ReadIoinRequest(sync=sync, node=0))
    assert tmc.decode(frame, tmc.Direction.RESPONSE).ioin.version == 0x21
    gconf = tmc.GconfBits.from_fields({**dict.fromkeys(tmc.GconfBits.__match_args__, 0), "pdn_disable": 1})
    assert sim.handle(tmc.WriteGconfRequest(sync=sync, node=0, gconf=gconf)) == []
    [(_, frame)] = sim.handle(tmc.ReadGconfRequest(sync=sync, node=0))
    assert tmc.decode(frame, tmc.Direction.RESPONSE).gconf == gconf
    assert sim.devices[0].get("gconf") == 0x40


def test_a_frame_whose_sync_nibble_is_not_5_is_refused(tmc: ModuleType) -> None:
    """A language gap once: `const: 5` on the sync element's `nibble` bit field. decode and the construct struct
    refuse another nibble, the stream parser sees no frame there, encode refuses one and fills it in if not given."""
    frame = bytes([0x56, 0x00, 0x00])
    frame += bytes([compute_crc8_atm(list(frame))])
    with pytest.raises(DecodeError, match=r"^sync\.nibble is 6, expected 5$"):
        tmc.decode(frame, tmc.Direction.REQUEST)
    structs = importlib.import_module("tmc2209.structs")
    with pytest.raises(DecodeError, match="sync.nibble is 6"):
        structs.REQUEST_FRAME.parse(frame)
    good = bytes.fromhex("55 00 00 cf")
    assert [m.node for m in tmc.StreamParser(tmc.Direction.REQUEST).feed(frame + good)] == [0]
    assert tmc.SyncBits(reserved=5) == tmc.SyncBits(nibble=5, reserved=5)
    with pytest.raises(EncodeError, match="sync.nibble"):
        tmc.encode(tmc.ReadGconfRequest(sync=tmc.SyncBits(nibble=6, reserved=5), node=0))


def test_writing_gstat_clears_the_flags_written_as_1(tmc: ModuleType) -> None:
    """A language gap once (GSTAT is R+WC: no key said so; the spec's device cleared every flag on any write):
    `access: w1c` on the table entry."""
    sim = importlib.import_module("tmc2209.simulator").Tmc2209Simulator(ids=[0])
    sync = tmc.SyncBits(nibble=5, reserved=5)
    zero = tmc.GstatBits(reset=0, drv_err=0, uv_cp=0)
    sim.handle(tmc.WriteGstatRequest(sync=sync, node=0, gstat=zero))
    [(_, frame)] = sim.handle(tmc.ReadGstatRequest(sync=sync, node=0))
    assert tmc.decode(frame, tmc.Direction.RESPONSE).gstat.reset == 1  # set after power-up until a 1 clears it
    sim.handle(tmc.WriteGstatRequest(sync=sync, node=0, gstat=tmc.GstatBits(reset=1, drv_err=0, uv_cp=0)))
    [(_, frame)] = sim.handle(tmc.ReadGstatRequest(sync=sync, node=0))
    assert tmc.decode(frame, tmc.Direction.RESPONSE).gstat.reset == 0


def test_the_c_and_the_dissector_read_tmc2209(tmp_path: Path) -> None:
    """The C (strict flags) decodes every example to its values and encodes it back (its check_vectors program);
    tshark shows a random message of each command as `decode` does, and flags a corrupt CRC."""
    from test_c_backend import GCC, check_vectors
    from test_wireshark import TSHARK, through_tshark

    if GCC is not None:
        assert check_vectors(SPEC, "tmc2209", tmp_path) == "tmc2209: 10 vectors, 0 refused frames, 0 failed\n"
    if TSHARK is not None:
        through_tshark(tmp_path, [SPEC.read_text(encoding="utf-8")], corrupt=True)


def test_ifcnt_counts_the_writes_taken_modulo_256(tmc: ModuleType) -> None:
    """`increments: [ifcnt]` with `modulo: {ifcnt: 256}` on every write (a device key added for this spec): IFCNT counts
    the writes, wraps past 255, and reads do not count."""
    sim = importlib.import_module("tmc2209.simulator").Tmc2209Simulator(ids=[0])
    sync = tmc.SyncBits(nibble=5, reserved=5)

    def ifcnt() -> int:
        [(_, frame)] = sim.handle(tmc.ReadIfcntRequest(sync=sync, node=0))
        return int(tmc.decode(frame, tmc.Direction.RESPONSE).ifcnt)

    assert ifcnt() == 0
    sim.handle(tmc.WriteTpowerdownRequest(sync=sync, node=0, tpowerdown=10))
    sim.handle(tmc.WriteVactualRequest(sync=sync, node=0, vactual=-3))
    assert ifcnt() == 2
    sim.devices[0].set("ifcnt", 255)
    sim.handle(tmc.WriteSgthrsRequest(sync=sync, node=0, sgthrs=1))
    assert ifcnt() == 0
    sim.handle(tmc.WriteSgthrsRequest(sync=sync, node=3, sgthrs=1))  # another node's: not this driver's
    assert ifcnt() == 0


def test_increments_names_a_state_variable_or_memory_entry(tmp_path: Path) -> None:
    from serialspec.lang import SpecErrors, load_protocol

    text = SPEC.read_text("utf-8").replace(
        "write_tpowerdown: {writes: [tpowerdown], increments: [ifcnt]",
        "write_tpowerdown: {writes: [tpowerdown], increments: [ifcn]",
    )
    spec = tmp_path / "tmc2209.yaml"
    spec.write_text(text, "utf-8")
    with pytest.raises(SpecErrors) as caught:
        load_protocol(str(spec), "tmc2209.yaml")
    lines = str(caught.value).splitlines()
    assert len(lines) == 1, lines
    assert "device.commands.write_tpowerdown.increments: unknown state variable 'ifcn'" in lines[0]


def test_serialspec_scan_finds_the_drivers_of_the_sim(sim_path: str, capsys: pytest.CaptureFixture[str]) -> None:
    """`device.presence` reads IOIN with the sync byte's bit fields given as `sync.nibble` and `sync.reserved` (a
    presence request's frame values and bit fields can now be given; before, scan failed when it ran)."""
    from serialspec.cli import main as serialspec_main

    assert serialspec_main(["scan", str(SPEC), "--port", sim_path, "--ids", "0-2", "--timeout", "0.2"]) == 0
    assert capsys.readouterr().out.splitlines() == ["id   0  115200 baud", "id   2  115200 baud"]


def test_the_peers_scan_finds_the_drivers_of_the_sim(sim_path: str) -> None:
    from tmc_driver.reg._tmc2209_reg import Ioin

    com = TmcComUart(sim_path, 115200)
    com.tmc_logger = LOG
    com.init()
    com.ser.timeout = 0.2  # a node that is not there: the peer waits this long for its 12 bytes
    try:
        assert com.scan_for_devices([Ioin], range(3)) == [(0, "TMC220X"), (2, "TMC220X")]
    finally:
        com.deinit()


def test_a_presence_request_missing_a_value_is_one_spec_error(tmp_path: Path) -> None:
    """Found writing this spec: a presence request whose frame carries a value the spec gives no way to fill (the sync
    byte, a plain `role: value` element) passed `check`, and `serialspec scan` failed when it ran; nor could
    `fields` name a frame value or a bit field."""
    from serialspec.lang import SpecErrors, load_protocol

    spec = tmp_path / "tmc2209.yaml"
    spec.write_text(SPEC.read_text("utf-8").replace("    fields: {sync.nibble: 5, sync.reserved: 0}\n", ""), "utf-8")
    with pytest.raises(SpecErrors) as caught:
        load_protocol(str(spec), "tmc2209.yaml")
    lines = str(caught.value).splitlines()
    assert len(lines) == 1, lines
    assert "device.presence.fields: the read_ioin request needs a value for sync: give it here" in lines[0]
    assert "(bit fields as sync.nibble, sync.reserved)" in lines[0]
    spec.write_text(SPEC.read_text("utf-8").replace("sync.reserved: 0}", "sync.reservd: 0}"), "utf-8")
    with pytest.raises(SpecErrors) as caught:
        load_protocol(str(spec), "tmc2209.yaml")
    assert "device.presence.fields.sync.reservd: 'sync' has no bit field 'reservd'" in str(caught.value)


def test_two_requests_without_a_code_and_no_length_is_one_line_that_says_so() -> None:
    """Found trying the register byte as a plain frame value (no command element): the error called the write
    request "a codeless reply"."""
    from serialspec.lang import SpecErrors
    from serialspec.lang.loader import load_text
    from serialspec.lang.resolve import resolve

    text = """
protocol: registers
title: registers
byte_order: big
serial: {baudrate: 115200}
framing:
  elements:
    sync: {role: header, value: "55"}
    register: {role: value, type: u8}
    data: {role: content}
    crc: {role: checksum, type: u8, algorithm: xor, covers: [sync, data]}
commands:
  read: {request: {fields: {}}}
  write: {request: {fields: {value: u32}}}
"""
    with pytest.raises(SpecErrors) as caught:
        resolve(load_text(text, "registers.yaml"))
    lines = str(caught.value).splitlines()
    assert len(lines) == 1, lines
    assert "commands.write: 'read' already sends requests without a code (the request frame has no command" in lines[0]
    assert "reply" not in lines[0]


def test_the_client_sends_the_datasheets_sync_byte_by_itself(tmc: ModuleType) -> None:
    """A language gap once: `default: 0` on the sync element's `reserved` bits beside the constant nibble; a frame
    value whose bit fields all have one needs no argument, and the calls that gave it keep working."""
    assert tmc.encode(tmc.ReadGconfRequest(node=0)) == bytes.fromhex("05 00 00 48")
    sync = tmc.SyncBits(nibble=5, reserved=5)
    assert tmc.ReadGconfRequest(sync, 0) == tmc.ReadGconfRequest(sync=sync, node=0)
    with pytest.raises(TypeError, match="missing required argument: 'node'"):
        tmc.ReadGconfRequest(sync)


def test_a_short_frame_is_not_said_to_be_shorter_than_the_smallest_frame(tmc: ModuleType) -> None:
    """Found decoding a cut reply: "shorter than the smallest response frame (4)", where every TMC2209 reply is 8
    bytes; the 4 are what a frame has besides its content."""
    with pytest.raises(DecodeError) as caught:
        tmc.decode(bytes.fromhex("05 ff"), tmc.Direction.RESPONSE)
    assert str(caught.value) == "frame of 2 bytes is shorter than the 4 bytes a response frame has besides its content"
