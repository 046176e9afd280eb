"""VESC: pyvesc (PyPI) encodes setters we decode and decodes our frames, in both length forms; back-to-back packets
under noise; the virtual controller's replies, motor model and command timeout (on an injected clock)."""

from __future__ import annotations

import random
from typing import Any

import pytest
from serialspec.runtime.errors import ChecksumError, DecodeError
from serialspec_protocols import vesc
from serialspec_protocols.vesc.client import VescClient
from serialspec_protocols.vesc.simulator import VescSimulator

pyvesc = pytest.importorskip("pyvesc")  # needs pythoncrc (its PyCRC module)
from pyvesc.messages import setters  # noqa: E402
from pyvesc.packet.codec import frame as peer_frame  # noqa: E402
from pyvesc.packet.codec import unframe as peer_unframe  # noqa: E402


@pytest.mark.parametrize(
    ("theirs", "ours"),
    [
        (setters.SetDutyCycle(50000), vesc.SetDutyRequest(duty=50000)),
        (setters.SetDutyCycle(-100000), vesc.SetDutyRequest(duty=-100000)),
        (setters.SetRPM(-1000), vesc.SetRpmRequest(rpm=-1000)),
        (setters.SetCurrent(12500), vesc.SetCurrentRequest(current=12500)),
        (setters.SetCurrentBrake(3000), vesc.SetCurrentBrakeRequest(current=3000)),
        (setters.SetPosition(90.5), vesc.SetPosRequest(position=90_500_000)),  # pyvesc scales by 1e6 itself
    ],
    ids=lambda x: type(x).__name__,
)
def test_we_decode_what_pyvesc_encodes_and_it_decodes_ours(theirs: Any, ours: Any) -> None:
    frame = pyvesc.encode(theirs)
    assert vesc.decode(frame, "request") == ours
    assert vesc.encode(ours) == frame
    decoded, consumed = pyvesc.decode(vesc.encode(ours))
    assert consumed == len(frame) and type(decoded) is type(theirs)


def test_get_values_request_is_pyvescs() -> None:
    assert vesc.encode(vesc.GetValuesRequest()) == pyvesc.encode_request(pyvesc.GetValues)


def test_long_packets_use_the_two_byte_length_both_ways() -> None:
    payload = bytes(range(256)) + bytes(44)
    ours = vesc.ForwardCanRequest(can_id=7, payload=payload)
    theirs = peer_frame(bytes([34, 7]) + payload)
    assert theirs[:3] == bytes([0x03, 0x01, 0x2E])  # 03, then 302 big-endian
    assert vesc.encode(ours) == theirs
    assert vesc.decode(theirs, "request") == ours
    text = "x" * 300
    printed = vesc.encode(vesc.PrintResponse(text=text))
    payload_back, consumed = peer_unframe(printed)
    assert payload_back == bytes([21]) + text.encode() and consumed == len(printed)
    short = vesc.encode(vesc.PrintResponse(text="hello"))
    assert short[0] == 0x02 and peer_unframe(short)[0] == b"\x15hello"


def test_get_values_reply_round_trips_and_pyvesc_unframes_it() -> None:
    reply = vesc.GetValuesResponse(
        temp_fet=312,
        temp_motor=280,
        avg_motor_current=-1234,
        avg_input_current=567,
        avg_id=1,
        avg_iq=-2,
        duty_now=-250,
        rpm=-12000,
        v_in=481,
        amp_hours=1,
        amp_hours_charged=2,
        watt_hours=3,
        watt_hours_charged=4,
        tachometer=-5,
        tachometer_abs=5,
        fault=vesc.FaultCode.OVER_TEMP_FET,
        pid_pos=180_000_000,
        controller_id=3,
        temp_mos1=300,
        temp_mos2=301,
        temp_mos3=302,
        avg_vd=-10,
        avg_vq=11,
        status=vesc.ValuesStatus.TIMEOUT,
    )
    frame = vesc.encode(reply)
    assert vesc.decode(frame, "response") == reply
    payload, consumed = peer_unframe(frame)
    assert consumed == len(frame) and payload[0] == 4 and len(payload) == 74


def test_corrupt_and_badly_ended_packets_are_refused() -> None:
    frame = bytearray(vesc.encode(vesc.SetRpmRequest(rpm=5000)))
    wrong_end = bytes(frame[:-1]) + b"\x04"
    with pytest.raises(DecodeError, match="end"):
        vesc.decode(wrong_end, "request")
    frame[4] ^= 1
    with pytest.raises(ChecksumError):
        vesc.decode(bytes(frame), "request")


@pytest.mark.parametrize("direction", ["request", "response"])
def test_back_to_back_packets_of_both_forms_under_noise(direction: str) -> None:
    rng = random.Random(5)
    if direction == "request":
        pool = [
            vesc.encode(m)
            for m in (
                vesc.SetDutyRequest(duty=1),
                vesc.GetValuesRequest(),
                vesc.AliveRequest(),
                vesc.ForwardCanRequest(can_id=1, payload=bytes(300)),
                vesc.SetPosRequest(position=-5),
            )
        ]
    else:
        pool = [
            vesc.encode(m)
            for m in (
                vesc.PrintResponse(text="hi"),
                vesc.PrintResponse(text="y" * 280),
                vesc.RotorPositionResponse(position=9),
            )
        ]
    frames = [rng.choice(pool) for _ in range(200)]
    stream = b"".join(bytes(rng.choice(b"\x00\x01\x04\x05\xff") for _ in range(rng.randint(0, 4))) + f for f in frames)
    parser = vesc.StreamParser(direction)
    found: list[Any] = []
    position = 0
    while position < len(stream):
        size = rng.randint(1, 64)
        found += parser.feed(stream[position : position + size])
        position += size
    assert [vesc.encode(m) for m in found] == frames


# --- the virtual controller ----------------------------------------------------------------------------------------


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def ask(sim: VescSimulator, request: Any) -> Any:
    replies = sim.feed(vesc.encode(request))
    return vesc.decode(replies[0][1], "response") if replies else None


def test_the_controller_identifies_itself() -> None:
    reply = ask(VescSimulator(), vesc.FwVersionRequest())
    assert (reply.major, reply.minor, reply.hw_name, reply.hw_type) == (6, 5, "60", vesc.HwType.VESC)
    assert len(reply.uuid) == 12


def test_rpm_follows_the_command_and_the_timeout_releases_the_motor() -> None:
    clock = Clock()
    sim = VescSimulator(clock=clock)
    assert ask(sim, vesc.SetRpmRequest(rpm=10000)) is None  # setpoints get no reply
    clock.now += 0.1  # 50,000 ERPM/s: halfway
    assert ask(sim, vesc.GetValuesRequest()).rpm == 5000
    clock.now += 0.15
    values = ask(sim, vesc.GetValuesRequest())
    assert values.rpm == 10000 and not values.status & vesc.ValuesStatus.TIMEOUT
    ask(sim, vesc.SetDutyRequest(duty=25000))
    assert ask(sim, vesc.GetValuesRequest()).duty_now == 250  # 0.25 in the reply's 0.001 steps
    clock.now += 0.9
    ask(sim, vesc.AliveRequest())  # keeps it going
    clock.now += 0.9
    assert ask(sim, vesc.GetValuesRequest()).rpm == 10000
    clock.now += 0.2  # 1.1 s since ALIVE: released
    values = ask(sim, vesc.GetValuesRequest())
    assert values.rpm == 0 and values.duty_now == 0 and values.status & vesc.ValuesStatus.TIMEOUT
    ask(sim, vesc.SetPosRequest(position=45_000_000))
    values = ask(sim, vesc.GetValuesRequest())
    assert values.pid_pos == 45_000_000 and not values.status & vesc.ValuesStatus.TIMEOUT


def test_our_client_drives_the_virtual_controller_over_a_pty() -> None:
    sim = VescSimulator()
    path = sim.start()
    try:
        with VescClient(path, timeout=2.0) as client:
            assert client.fw_version().hw_name == "60"
            client.set_current(1500)
            client.alive()
            assert client.get_values().fault == vesc.FaultCode.NONE
    finally:
        sim.close()
