"""u-blox UBX against pyubx2 (PyPI): frames pyubx2 builds (`UBXMessage(...).serialize()`) decode to pyubx2's values and
re-encode byte for byte, and pyubx2 parses the frames we encode to our values (hypothesis); the spec's examples are
pyubx2's frames; pyubx2's UBXReader reads `serialspec sim specs/ubx.yaml` over a real pty (the NAV-PVT stream, its
polls answered, CFG-RATE sets acknowledged or refused, CFG-VALSET/VALGET); our generated client against the sim.

pyubx2 names fields in u-blox's camelCase and flattens bit fields into the message; ours are snake_case, bit fields
grouped under their byte, and hold raw wire values where pyubx2 applies the scale (lat in degrees, pDOP as 1.23).
"""

from __future__ import annotations

import os
import re
import threading
import tty
from typing import Any

import pytest
import serial
from conftest import examples
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.lang import load_protocol
from serialspec.lang.model import Scalar
from serialspec.runtime.errors import DeviceError
from serialspec_protocols import ubx
from serialspec_protocols.ubx.client import UbxClient
from sim_process import ROOT, serve

pytest.importorskip("pyubx2")
from pyubx2 import GET, POLL, SET, UBXMessage, UBXReader  # noqa: E402

SPEC = load_protocol(str(ROOT / "specs" / "ubx.yaml"))
# pyubx2's names that are not ours in snake case
RENAMED = {"iTOW": "itow", "min": "minute", "clsID": "code_high", "msgID": "code_low"}


def snake(name: str) -> str:
    return RENAMED.get(name) or re.sub(r"([a-z0-9])([A-Z])", r"\1_\2", name).lower()


def model_fields(message: Any) -> tuple[Any, ...]:
    command = next(c for c in SPEC.commands if c.name == message.COMMAND)
    return next(m for m in command.messages() if m.direction.value == message.DIRECTION.value).fields


def flat(message: Any) -> dict[str, Any]:
    """Our message as pyubx2 shows it: bit fields flattened, group and list items numbered (name_01, ...), scaled
    values scaled (pyubx2 scales them), constant fields given, ACK codes split in class and id, items as bytes."""
    fields = model_fields(message)
    scaled = {f.name: f.scale for f in fields if isinstance(f, Scalar) and f.scale is not None}
    values: dict[str, Any] = {f.name: f.const for f in fields if isinstance(f, Scalar) and f.const is not None}
    for name, value in message.to_fields().items():
        if isinstance(value, dict):
            values.update(value)
        elif isinstance(value, list | tuple):
            for i, item in enumerate(value, 1):
                values.update(
                    {f"{k}_{i:02d}": v for k, v in item.items()}
                    if isinstance(item, dict)
                    else {f"{name}_{i:02d}": item}
                )
        elif name in ("acked", "refused"):  # ACK-ACK/NAK: the class and id, one u16 here
            values.update(code_high=value >> 8, code_low=value & 0xFF)
        else:
            values[name] = value * scaled[name] if name in scaled else value
    return values


def peer_values(parsed: Any) -> dict[str, Any]:
    return {snake(k): v for k, v in vars(parsed).items() if not k.startswith("_")}


def assert_same(ours: Any, parsed: Any) -> None:
    """Every value pyubx2 parsed is ours (approximately where scaled); the reserved bits it hides are zero.
    Configuration items, which pyubx2 names by their keys (CFG_RATE_MEAS=100), are our `cfg_data` bytes whole."""
    mine, peer = flat(ours), peer_values(parsed)
    if "cfg_data" in mine:
        del mine["cfg_data"]
        assert ours.cfg_data == parsed.payload[4:]
        peer = {k: v for k, v in peer.items() if not k.startswith("cfg_")}
    assert set(peer) <= set(mine), f"pyubx2 fields we lack: {set(peer) - set(mine)}"
    for name, value in peer.items():
        expected = mine[name]
        if isinstance(value, bytes):  # pyubx2 keeps the NUL padding of strings
            assert value.rstrip(b"\x00").decode("ascii") == expected, name
        else:
            assert value == pytest.approx(expected, rel=1e-9, abs=1e-9), name
    assert all(mine[n] == 0 for n in set(mine) - set(peer) if n.startswith("reserved")), mine


def pad(text: bytes, size: int) -> bytes:
    return text.ljust(size, b"\x00")


MON_VER = (
    pad(b"ROM SPG 5.10 (7b202e)", 30) + pad(b"000A0000", 10) + pad(b"FWVER=SPG 5.10", 30) + pad(b"MOD=NEO-M10S", 30)
)
PVT = dict(
    iTOW=489618000, year=2026, month=11, day=27, hour=16, min=0, second=0, validDate=1, validTime=1,
    fullyResolved=1, tAcc=25, nano=-12345, fixType=3, gnssFixOk=1, carrSoln=2, psmState=1, confirmedAvai=1,
    confirmedDate=1, confirmedTime=1, numSV=14, lon=8.5455939, lat=47.3977418, height=545123, hMSL=497000, hAcc=1200,
    vAcc=1800, velN=-100, velE=250, velD=3, gSpeed=269, headMot=111.80123, sAcc=150, headAcc=12.5, pDOP=1.23,
    lastCorrectionAge=2, headVeh=-45.5, magDec=2.5, magAcc=0.3,
)  # fmt: skip
STATUS = dict(
    iTOW=1000, gpsFix=2, gpsFixOk=1, towSet=1, diffCorr=1, mapMatching=2, psmState=3, spoofDetState=2, carrSoln=1,
    ttff=28000, msss=123456,
)  # fmt: skip
PEER_FRAMES = {
    "nav_pvt": (UBXMessage("NAV", "NAV-PVT", GET, **PVT), "response"),
    "nav_pvt_poll": (UBXMessage("NAV", "NAV-PVT", POLL), "request"),
    "nav_status": (
        UBXMessage("NAV", "NAV-STATUS", GET, **STATUS),
        "response",
    ),  # fmt: skip
    "nav_status_poll": (UBXMessage("NAV", "NAV-STATUS", POLL), "request"),
    "mon_ver_poll": (UBXMessage("MON", "MON-VER", POLL), "request"),
    "mon_ver": (UBXMessage("MON", "MON-VER", GET, payload=MON_VER), "response"),
    "cfg_rate_poll": (UBXMessage("CFG", "CFG-RATE", POLL), "request"),
    "cfg_rate": (UBXMessage("CFG", "CFG-RATE", GET, measRate=1000, navRate=1, timeRef=1), "response"),
    "set_rate": (UBXMessage("CFG", "CFG-RATE", SET, measRate=100, navRate=3, timeRef=4), "request"),
    "ack_ack": (UBXMessage("ACK", "ACK-ACK", GET, clsID=0x06, msgID=0x8A), "response"),
    "ack_nak": (UBXMessage("ACK", "ACK-NAK", GET, clsID=0x06, msgID=0x08), "response"),
    "cfg_valset": (UBXMessage.config_set(3, 1, [("CFG_RATE_MEAS", 100), ("CFG_UART1_BAUDRATE", 115200)]), "request"),
    "cfg_valget": (UBXMessage.config_poll(2, 0, ["CFG_RATE_MEAS", "CFG_UART1_BAUDRATE"]), "request"),
}


@pytest.mark.parametrize("name", sorted(PEER_FRAMES))
def test_peer_frames_decode_to_its_values_and_re_encode(name: str) -> None:
    built, direction = PEER_FRAMES[name]
    frame = built.serialize()
    message = ubx.decode(frame, direction)
    assert ubx.encode(message) == frame
    parsed = UBXReader.parse(frame, msgmode=built.msgmode)
    assert_same(message, parsed)


def test_the_peer_names_the_items_we_carry_as_bytes() -> None:
    """CFG-VALSET/VALGET items are one bytes field here; pyubx2's configuration database reads ours back."""
    items = (0x30210001).to_bytes(4, "little") + (250).to_bytes(2, "little")  # CFG-RATE-MEAS, u16: 250 ms
    layers = ubx.messages.LayersBits(ram=1, bbr=1, flash=0)
    valset = ubx.CfgValsetRequest(version=0, layers=layers, transaction=ubx.messages.TransactionBits(action=0),
                                  reserved0=0, cfg_data=items)  # fmt: skip
    parsed = UBXReader.parse(ubx.encode(valset), msgmode=SET)
    assert (parsed.identity, parsed.CFG_RATE_MEAS, parsed.ram, parsed.bbr) == ("CFG-VALSET", 250, 1, 1)
    reply = ubx.CfgValgetResponse(layer=ubx.Layer.FLASH, position=0, cfg_data=items)
    parsed = UBXReader.parse(ubx.encode(reply))
    assert (parsed.identity, parsed.version, parsed.layer, parsed.CFG_RATE_MEAS) == ("CFG-VALGET", 1, 2, 250)
    valget = ubx.CfgValgetRequest(layer=ubx.Layer.RAM, position=0, keys=(0x30210001, 0x40520001))
    assert ubx.encode(valget) == UBXMessage.config_poll(0, 0, [0x30210001, 0x40520001]).serialize()


def test_the_spec_examples_are_the_frames_pyubx2_builds() -> None:
    """Every example of the spec, decoded by pyubx2 (in the direction the example gives), has the example's values."""
    assert len(SPEC.examples) >= 10
    for example in SPEC.examples:
        frame = bytes.fromhex(example.printed)
        request = example.direction.value == "request"
        # pyubx2 reads requests as polls (an empty payload, CFG-VALGET's key list) or sets
        mode = (POLL if len(frame) == 8 or frame[2:4] == b"\x06\x8b" else SET) if request else GET
        parsed = UBXReader.parse(frame, msgmode=mode)
        message = ubx.decode(frame, example.direction.value)
        assert example.command == message.COMMAND
        assert_same(message, parsed)


bits = st.integers(0, 1)
u8, u16, u32 = st.integers(0, 0xFF), st.integers(0, 0xFFFF), st.integers(0, 0xFFFFFFFF)
i32 = st.integers(-(2**31), 2**31 - 1)


@st.composite
def navigation_solutions(draw: st.DrawFn) -> Any:
    m = ubx.messages
    return ubx.NavPvtResponse(
        itow=draw(u32), year=draw(u16), month=draw(st.integers(1, 12)), day=draw(st.integers(1, 31)),
        hour=draw(st.integers(0, 23)), minute=draw(st.integers(0, 59)), second=draw(st.integers(0, 60)),
        valid=m.ValidBits(valid_date=draw(bits), valid_time=draw(bits), fully_resolved=draw(bits),
                          valid_mag=draw(bits)),
        t_acc=draw(u32), nano=draw(st.integers(-(10**9), 10**9)), fix_type=draw(st.sampled_from(ubx.FixType)),
        flags=m.FlagsBits(gnss_fix_ok=draw(bits), diff_soln=draw(bits), psm_state=draw(st.integers(0, 7)),
                                        head_veh_valid=draw(bits), carr_soln=draw(st.integers(0, 2))),
        flags2=m.Flags2Bits(reserved=0, confirmed_avai=draw(bits), confirmed_date=draw(bits),
                                          confirmed_time=draw(bits)),
        num_sv=draw(u8), lon=draw(i32), lat=draw(i32), height=draw(i32), h_msl=draw(i32), h_acc=draw(u32),
        v_acc=draw(u32), vel_n=draw(i32), vel_e=draw(i32), vel_d=draw(i32), g_speed=draw(i32), head_mot=draw(i32),
        s_acc=draw(u32), head_acc=draw(u32), p_dop=draw(u16),
        flags3=m.Flags3Bits(invalid_llh=draw(bits), last_correction_age=draw(st.integers(0, 15)), reserved1=0,
                            auth_time=draw(bits), nma_fix_status=draw(bits)),
        reserved0=0, head_veh=draw(i32), mag_dec=draw(st.integers(-(2**15), 2**15 - 1)), mag_acc=draw(u16),
    )  # fmt: skip


@settings(max_examples=examples(100))
@given(navigation_solutions())
def test_peer_parses_every_navigation_solution_we_encode(message: Any) -> None:
    frame = ubx.encode(message)
    assert len(frame) == 6 + 92 + 2
    parsed = UBXReader.parse(frame)
    assert parsed.identity == "NAV-PVT"
    assert_same(message, parsed)
    assert ubx.decode(frame, "response") == message


@given(st.integers(25, 0xFFFF), st.integers(1, 127), st.sampled_from(ubx.TimeReference))
def test_peer_builds_rate_settings_we_decode(meas_rate: int, nav_rate: int, time_ref: int) -> None:
    frame = UBXMessage("CFG", "CFG-RATE", SET, measRate=meas_rate, navRate=nav_rate, timeRef=int(time_ref)).serialize()
    assert ubx.decode(frame, "request") == ubx.SetRateRequest(meas_rate=meas_rate, nav_rate=nav_rate, time_ref=time_ref)


def read_until(reader: UBXReader, identity: str, seen: list[Any], limit: int = 20) -> Any:
    """The next message of that identity, collecting what comes before it (NAV-PVT arrives unasked)."""
    for _ in range(limit):
        _, parsed = reader.read()
        assert parsed is not None, f"no {identity}: the stream went quiet"
        seen.append(parsed)
        if parsed.identity == identity:
            return parsed
    raise AssertionError(f"no {identity} among {[p.identity for p in seen]}")


def test_pyubx2_reads_the_sim_stream_and_gets_replies_to_its_polls_and_sets() -> None:
    with serve("ubx.yaml") as path, serial.Serial(path, 38400, timeout=5) as port:
        reader = UBXReader(port, protfilter=2)  # UBX only; pyubx2 checks every checksum
        seen: list[Any] = []
        fixes = [read_until(reader, "NAV-PVT", seen) for _ in range(3)]
        assert [f.iTOW - fixes[0].iTOW for f in fixes] == [0, 1000, 2000]  # one a second, each 1 s on
        assert fixes[0].lat < fixes[1].lat < fixes[2].lat and fixes[0].fixType == 3 and fixes[0].gnssFixOk == 1
        port.write(UBXMessage("MON", "MON-VER", POLL).serialize())
        version = read_until(reader, "MON-VER", seen)
        assert version.swVersion.rstrip(b"\x00") == b"ROM SPG 5.10 (7b202e)"
        assert version.extension_04.rstrip(b"\x00") == b"GPS;GLO;GAL;BDS"  # pyubx2 numbers the repeated items
        port.write(UBXMessage("CFG", "CFG-RATE", SET, measRate=200, navRate=2, timeRef=0).serialize())
        ack = read_until(reader, "ACK-ACK", seen)
        assert (ack.clsID, ack.msgID) == (0x06, 0x08)
        port.write(UBXMessage("CFG", "CFG-RATE", SET, measRate=10, navRate=1, timeRef=0).serialize())  # under 25 ms
        nak = read_until(reader, "ACK-NAK", seen)
        assert (nak.clsID, nak.msgID) == (0x06, 0x08)
        port.write(UBXMessage("CFG", "CFG-RATE", POLL).serialize())
        rate = read_until(reader, "CFG-RATE", seen)
        assert (rate.measRate, rate.navRate, rate.timeRef) == (200, 2, 0)  # the set stored, the refused one not
        port.write(UBXMessage.config_set(1, 0, [("CFG_RATE_MEAS", 100)]).serialize())
        ack = read_until(reader, "ACK-ACK", seen)
        assert (ack.clsID, ack.msgID) == (0x06, 0x8A)
        port.write(UBXMessage.config_poll(0, 0, ["CFG_RATE_MEAS"]).serialize())
        assert read_until(reader, "CFG-VALGET", seen).CFG_RATE_MEAS == 1000
        ack = read_until(reader, "ACK-ACK", seen)
        assert (ack.clsID, ack.msgID) == (0x06, 0x8B)
        port.write(UBXMessage("NAV", "NAV-STATUS", POLL).serialize())
        status = read_until(reader, "NAV-STATUS", seen)
        assert (status.gpsFix, status.gpsFixOk, status.towSet) == (3, 1, 1)
    for parsed in seen:  # every frame pyubx2 read is one we decode to its values
        assert_same(ubx.decode(parsed.serialize(), "response"), parsed)


def test_our_client_polls_and_sets_the_sim_among_its_stream() -> None:
    with serve("ubx.yaml") as path, UbxClient(path, timeout=3.0) as client:
        version = client.mon_ver()
        assert (version.sw_version, version.hw_version) == ("ROM SPG 5.10 (7b202e)", "000A0000")
        assert [e.extension for e in version.extensions] == [  # device.reply's list of group items
            "FWVER=SPG 5.10",
            "PROTVER=34.10",
            "MOD=NEO-M10S",
            "GPS;GLO;GAL;BDS",
        ]
        assert client.set_rate(250, 1, ubx.TimeReference.GPS) is True
        assert client.cfg_rate() == ubx.CfgRateResponse(meas_rate=250, nav_rate=1, time_ref=ubx.TimeReference.GPS)
        fix = client.nav_pvt()
        assert fix.fix_type == ubx.FixType.FIX_3D and fix.valid.valid_date == 1
        assert client.cfg_valget(ubx.Layer.RAM, 0, (0x30210001,)) == bytes.fromhex("01 00 21 30 e8 03")
        reports = client.reports(timeout=5.0)
        pvts = [m for m in (next(reports) for _ in range(4)) if isinstance(m, ubx.NavPvtResponse)]
        assert len(pvts) >= 2 and pvts[-1].itow > pvts[0].itow
        with pytest.raises(ValueError, match="meas_rate = 10 is outside its range 25..65535"):
            client.set_rate(10, 1, 0)  # refused before a byte is written


def test_our_client_raises_on_the_ack_nak_pyubx2_builds() -> None:
    """A receiver (here a thread on a pty pair) that refuses CFG-RATE: the client raises DeviceError naming ACK-NAK; an
    ACK-ACK of another message before it is not taken for this one's."""
    controller, device = os.openpty()
    tty.setraw(device)

    def receiver() -> None:
        os.read(controller, 64)
        other = UBXMessage("ACK", "ACK-ACK", GET, clsID=0x06, msgID=0x8A).serialize()
        os.write(controller, other + UBXMessage("ACK", "ACK-NAK", GET, clsID=0x06, msgID=0x08).serialize())

    try:
        with UbxClient(os.ttyname(device), timeout=3.0) as client:
            thread = threading.Thread(target=receiver, daemon=True)
            thread.start()
            with pytest.raises(DeviceError, match="^set_rate: the device refuses it: ack_nak$"):
                client.set_rate(100, 1, ubx.TimeReference.UTC)
            thread.join()
    finally:
        os.close(controller)
        os.close(device)


def test_the_navigation_rate_follows_a_cfg_rate_set() -> None:
    """NAV-PVT comes every meas_rate × nav_rate ms (`every: meas_rate * nav_rate`), counted over a simulated clock:
    once a second by default, four times a second after CFG-RATE sets 250 ms, twice after nav_rate 2."""
    from serialspec_protocols.ubx.simulator import UbxSimulator

    class Clock:
        now = 50.0

        def __call__(self) -> float:
            return self.now

    clock = Clock()
    sim = UbxSimulator(ids=[0], clock=clock)
    parser = ubx.StreamParser(ubx.Direction.RESPONSE)

    def fixes_in_a_second() -> int:
        count = 0
        for _ in range(1000):
            count += sum(isinstance(m, ubx.NavPvtResponse) for _, f in sim.due() for m in parser.feed(f))
            clock.now += 0.001
        return count

    def set_rate(meas_rate: int, nav_rate: int) -> None:
        replies = [
            m for _, f in sim.feed(ubx.encode(ubx.SetRateRequest(meas_rate, nav_rate, 0))) for m in parser.feed(f)
        ]
        assert [type(m) for m in replies] == [ubx.AckAckResponse]

    assert fixes_in_a_second() == 1
    set_rate(250, 1)
    assert 4 <= fixes_in_a_second() <= 5  # the one due at the old rate, then every 250 ms
    assert fixes_in_a_second() == 4
    set_rate(250, 2)
    assert fixes_in_a_second() in (2, 3)
    assert fixes_in_a_second() == 2
