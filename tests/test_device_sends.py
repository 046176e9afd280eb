"""`device.sends`: a device that talks on its own (a heartbeat every period, telemetry after a command, a report
when a value changes) while it answers requests; the client's reports() iterator, on_<report>() subscriptions
and the asyncio client's async iterator, with request/reply matching still right among the unsolicited frames.

No shipped spec documents a device that sends periodically (the RRC board's reports come at no documented rate):
a small test spec stands in. Timing is counted over a simulated clock, never measured.
"""

from __future__ import annotations

import asyncio
import importlib
import threading
from collections.abc import Iterator
from types import ModuleType
from typing import Any

import pytest
import yaml
from serialspec.backends import emitters
from serialspec.backends.python.memory import imported
from serialspec.lang import SpecErrors
from serialspec.lang.loader import load_text
from serialspec.lang.resolve import resolve

SPEC: dict[str, Any] = {
    "protocol": "beacon",
    "title": "Beacon",
    "description": "A test device that sends a heartbeat, telemetry after ARM and a report when its level changes.",
    "byte_order": "little",
    "serial": {"baudrate": 115200},
    "framing": {
        "elements": {
            "header": {"role": "header", "value": "AA 55"},
            "id": {"role": "address", "type": "u8", "range": [0, 253], "broadcast": 254},
            "code": {"role": "command", "type": "u8"},
            "length": {"role": "length", "type": "u8"},
            "content": {"role": "content"},
            "checksum": {"role": "checksum", "type": "u8", "algorithm": "sum", "covers": ["id", "content"]},
        }
    },
    "matching": {"by": ["id", "command"]},
    "tables": {
        "regs": {
            "key": "address",
            "entries": {
                "raw": {"key": 0, "type": "u16", "default": 0},
                "offset": {"key": 2, "type": "i16", "default": 0, "memory": "eeprom"},
                "shown": {"key": 4, "type": "i32", "access": "r", "default": 0},
            },
        }
    },
    "commands": {
        "heartbeat": {"code": 1, "title": "Heartbeat", "response": {"unsolicited": True, "fields": {"armed": "u8"}}},
        "telemetry": {
            "code": 2,
            "title": "Telemetry",
            "response": {"unsolicited": True, "fields": {"level": "u16", "double": "u16"}},
        },
        "changed": {"code": 6, "title": "Level changed", "response": {"unsolicited": True, "fields": {"level": "u16"}}},
        "arm": {"code": 3, "title": "Arm", "request": {"fields": {"on": "u8"}}, "response": {"fields": {"on": "u8"}}},
        "set_level": {
            "code": 4,
            "title": "Set the level",
            "request": {"fields": {"level": "u16"}},
            "response": {"fields": {"level": "u16"}},
        },
        "read_level": {"code": 5, "title": "Read the level", "request": {}, "response": {"fields": {"level": "u16"}}},
    },
    "device": {
        "memory": "regs",
        "derived": {"shown": "raw + offset"},
        "locks": [{"memory": "eeprom", "while": "armed"}],
        "state": {"armed": 0, "level": 7},
        "sends": {
            "heartbeat": {"every": 20, "values": {"armed": "armed"}},
            "telemetry": {"after": ["arm"], "while": "armed", "values": {"level": "level", "double": "level * 2"}},
            "changed": {"changes": ["level"], "values": {"level": "level"}},
        },
        "commands": {
            "arm": {"stores": {"on": "armed"}, "echoes": ["on"]},
            "set_level": {"stores": {"level": "level"}, "reports": {"level": "level"}},
            "read_level": {"reports": {"level": "level"}},
        },
    },
}


def files(spec: dict[str, Any]) -> dict[str, str]:
    protocol = resolve(load_text(yaml.safe_dump(spec, sort_keys=False), "beacon.yaml"))
    found: dict[str, str] = {}
    for emitter in emitters():
        emitted = emitter.files(protocol)
        found |= {f"{emitter.folder}/{p}" if emitter.folder else p: t for p, t in emitted.items()}
        if emitter.verify is not None:
            assert list(emitter.verify(protocol, emitted)) == []
    return {path.split("/", 1)[1]: text for path, text in found.items() if path.startswith("beacon/")}


@pytest.fixture(scope="module")
def beacon() -> Iterator[ModuleType]:
    with imported("beacon", files(SPEC), "the sends test") as package:
        for module in ("simulator", "client", "aio", "messages"):
            __import__(f"beacon.{module}")
        yield package


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_periodic_messages_counted_over_a_simulated_clock(beacon: ModuleType) -> None:
    clock = Clock()
    sim = beacon.simulator.BeaconSimulator(ids=[1, 2], clock=clock)
    decode = beacon.codec.StreamParser(beacon.messages.Direction.RESPONSE)
    sent: list[Any] = []
    for _ in range(200):  # one simulated second in 5 ms steps
        sent += [m for _, frame in sim.due() for m in decode.feed(frame)]
        clock.now += 0.005
    beats = [m for m in sent if isinstance(m, beacon.messages.HeartbeatResponse)]
    assert len(beats) == 2 * 50  # every 20 ms from each of the two devices
    assert {m.id for m in beats} == {1, 2} and {m.armed for m in beats} == {0}
    assert [m for m in sent if not isinstance(m, beacon.messages.HeartbeatResponse)] == []  # nothing changed
    clock.now += 10  # a jump of many periods: one heartbeat each, then every period again
    assert len(sim.due()) == 2 and sim.due() == []
    clock.now += 0.02
    assert len(sim.due()) == 2


def test_after_a_command_while_a_state_and_on_a_change(beacon: ModuleType) -> None:
    m = beacon.messages
    clock = Clock()
    sim = beacon.simulator.BeaconSimulator(ids=[1], clock=clock)
    sim.due()  # the first heartbeat
    decode = beacon.codec.StreamParser(m.Direction.RESPONSE)

    def replies(request: Any) -> list[Any]:
        return [x for _, frame in sim.feed(beacon.codec.encode(request)) for x in decode.feed(frame)]

    assert replies(m.SetLevelRequest(id=1, level=5)) == [m.SetLevelResponse(id=1, level=5)]
    assert [type(x) for _, f in sim.due() for x in decode.feed(f)] == [m.ChangedResponse]  # level changed
    assert sim.due() == []  # once per change
    # telemetry after ARM, while armed: not after disarming
    assert replies(m.ArmRequest(id=1, on=1)) == [
        m.ArmResponse(id=1, on=1),
        m.TelemetryResponse(id=1, level=5, double=10),
    ]
    assert replies(m.ArmRequest(id=1, on=0)) == [m.ArmResponse(id=1, on=0)]
    assert replies(m.ReadLevelRequest(id=1)) == [m.ReadLevelResponse(id=1, level=5)]


def test_client_matches_replies_among_unsolicited_frames_on_a_pty(beacon: ModuleType) -> None:
    sim = beacon.simulator.BeaconSimulator(ids=[1])
    path = sim.start()
    try:
        with beacon.client.BeaconClient(path, timeout=2.0) as client:
            beats: list[Any] = []
            enough = threading.Event()

            def on_beat(message: Any) -> None:
                beats.append(message)
                if len(beats) >= 5:
                    enough.set()

            unsubscribe = client.on_heartbeat(on_beat)
            for level in range(300):  # heartbeats every 20 ms meanwhile: each reply is still the right one
                assert client.set_level(1, level) == level  # the level the device reports back
                assert client.read_level(1) == level
            assert client.arm(1, 1) is True  # telemetry follows the reply
            reports = client.reports(timeout=2.0)
            telemetry = next(r for r in reports if isinstance(r, beacon.messages.TelemetryResponse))
            assert (telemetry.level, telemetry.double) == (299, 598)
            while not enough.is_set():
                next(reports)  # reading the bus runs the callbacks
            unsubscribe()
            assert all(isinstance(b, beacon.messages.HeartbeatResponse) and b.id == 1 for b in beats)
            seen = {type(next(reports)) for _ in range(5)}
            assert beacon.messages.HeartbeatResponse in seen
    finally:
        sim.close()


def test_async_client_iterates_over_reports(beacon: ModuleType) -> None:
    sim = beacon.simulator.BeaconSimulator(ids=[3])
    path = sim.start()

    async def run() -> list[Any]:
        async with beacon.aio.AsyncBeaconClient(path, timeout=2.0) as client:
            assert await client.set_level(3, 41) == 41  # the level the device reports back
            found = []
            async for message in client.reports():
                found.append(message)
                if len(found) == 3:
                    break
            assert await client.read_level(3) == 41
            return found

    try:
        found = asyncio.run(run())
    finally:
        sim.close()
    assert {type(m) for m in found} <= {beacon.messages.HeartbeatResponse, beacon.messages.ChangedResponse}
    assert beacon.messages.HeartbeatResponse in {type(m) for m in found}


@pytest.mark.parametrize(
    ("change", "said"),
    [
        ({"sends": {"nothing": {"every": 5}}}, "device.sends.nothing: unknown command 'nothing'"),
        ({"sends": {"heartbeat": {}}}, "says not when: give `every`, `after` or `changes`"),
        ({"sends": {"heartbeat": {"every": 5, "while": "nope"}}}, "unknown memory entry or state variable 'nope'"),
        ({"sends": {"heartbeat": {"after": ["nope"]}}}, "unknown command 'nope'"),
        ({"sends": {"heartbeat": {"every": 5, "values": {"x": "armed"}}}}, "unknown heartbeat response field 'x'"),
        ({"sends": {"heartbeat": {"every": 5, "values": {"armed": "armed +"}}}}, "heartbeat.values.armed"),
        ({"sends": {"heartbeat": {"every": 0}}}, "0 is outside"),
        ({"sends": {"heartbeat": {"every": "1000 / nope"}}}, "heartbeat.every: unknown name 'nope'"),
        ({"sends": {"heartbeat": {"every": "1000 /"}}}, "device.sends.heartbeat.every:"),
        ({"sends": {"heartbeat": {"every": "0"}}}, "heartbeat.every: a period of 0 ms: it must be at least 1"),
        ({"derived": {"nope": "raw"}}, "device.derived.nope: unknown memory entry 'nope'"),
        ({"derived": {"shown": "raw + nope"}}, "device.derived.shown: unknown name 'nope'"),
        ({"derived": {"shown": "raw", "raw": "offset"}}, "shown reads the derived entry 'raw'"),
        ({"derived": {"shown": "raw +"}}, "device.derived.shown:"),
        ({"locks": [{"memory": "eeprom", "while": "nope"}]}, "device.locks[0].while: unknown memory entry or state"),
        ({"locks": [{"entries": ["nope"], "while": "armed"}]}, "device.locks[0].entries: unknown memory entry 'nope'"),
        ({"locks": [{"memory": "sram", "while": "armed"}]}, "device.locks[0]: locks no memory entry"),
        ({"commands": {"arm": {"moves": {"state": "level", "target": "on", "to": "on - x"}}}}, "unknown name 'x'"),
    ],
)
def test_device_mistakes_in_one_line(change: dict[str, Any], said: str) -> None:
    spec = {**SPEC, "device": {**SPEC["device"], **change}}
    with pytest.raises(SpecErrors) as caught:
        files(spec)
    assert said in str(caught.value)
    assert "Traceback" not in str(caught.value)


def test_a_value_dividing_by_a_written_zero_sends_nothing(caplog: pytest.LogCaptureFixture) -> None:
    sends = {**SPEC["device"]["sends"], "telemetry": {"after": ["arm"], "values": {"double": "100 / level"}}}
    spec = {**SPEC, "device": {**SPEC["device"], "sends": sends}}
    with imported("beacon", files(spec), "the sends test") as package:
        m = importlib.import_module("beacon.messages")
        sim = importlib.import_module("beacon.simulator").BeaconSimulator(ids=[1], clock=Clock())
        codec = importlib.import_module("beacon.codec")
        decode = codec.StreamParser(m.Direction.RESPONSE)
        sim.feed(codec.encode(m.SetLevelRequest(id=1, level=0)))
        sent = [x for _, frame in sim.feed(codec.encode(m.ArmRequest(id=1, on=1))) for x in decode.feed(frame)]
        assert sent == [m.ArmResponse(id=1, on=1)]  # the reply, and no telemetry: 100 / 0 has no value
        assert "no TelemetryResponse sent" in caplog.text
        del package


def test_a_period_from_a_rate_the_client_sets() -> None:
    """`every` as an expression of the device's values (a rate in Hz): worked out for each period, so a new rate
    takes effect from the next message on; a rate of 0 (no period: 1000 / 0) makes the device silent, not broken."""
    commands = {
        **SPEC["commands"],
        "set_rate": {
            "code": 7,
            "title": "Set the heartbeat rate",
            "request": {"fields": {"hz": "u8"}},
            "response": {"fields": {"hz": "u8"}},
        },
    }
    device = {
        **SPEC["device"],
        "state": {**SPEC["device"]["state"], "rate_hz": 50},
        "sends": {"heartbeat": {"every": "1000 / rate_hz", "values": {"armed": "armed"}}},
        "commands": {**SPEC["device"]["commands"], "set_rate": {"stores": {"hz": "rate_hz"}, "echoes": ["hz"]}},
    }
    spec = {**SPEC, "commands": commands, "device": device}
    generated = files(spec)
    protocol = resolve(load_text(yaml.safe_dump(spec, sort_keys=False), "beacon.yaml"))
    docs = next(  # the protocol's reference (the C target writes a README.md too)
        t for e in emitters() for p, t in e.files(protocol).items() if p.endswith(".md") and not p.endswith("README.md")
    )
    assert "every `1000 / rate_hz` ms" in docs
    with imported("beacon", generated, "the sends test") as package:
        m = importlib.import_module("beacon.messages")
        codec = importlib.import_module("beacon.codec")
        clock = Clock()
        sim = importlib.import_module("beacon.simulator").BeaconSimulator(ids=[1], clock=clock)
        decode = codec.StreamParser(m.Direction.RESPONSE)

        def beats_in_a_second() -> int:
            count = 0
            for _ in range(1000):  # one simulated second in 1 ms steps
                count += sum(isinstance(x, m.HeartbeatResponse) for _, f in sim.due() for x in decode.feed(f))
                clock.now += 0.001
            return count

        def set_rate(hz: int) -> None:
            sent = [x for _, frame in sim.feed(codec.encode(m.SetRateRequest(id=1, hz=hz))) for x in decode.feed(frame)]
            assert sent == [m.SetRateResponse(id=1, hz=hz)]

        assert beats_in_a_second() == 50  # every 20 ms
        set_rate(0)
        assert beats_in_a_second() <= 1  # at most the one already due at the old rate, then none: 1000 / 0
        set_rate(200)
        assert 199 <= beats_in_a_second() <= 200  # every 5 ms, from the next 10 ms look on
        del package


LISTED: dict[str, Any] = {
    **SPEC,
    "commands": {
        **SPEC["commands"],
        "info": {
            "code": 8,
            "title": "Device information",
            "request": {},
            "response": {
                "fields": {
                    "flags": {"type": "u8", "bits": {"alarm": {"bits": 0}, "busy": {"bits": 1}}},
                    "temps": {"type": "array", "of": "i8", "count": 3},
                    "n": "u8",
                    "names": {
                        "type": "group",
                        "count": "n",
                        "fields": {"name": {"type": "string", "size": 8, "pad": "00"}},
                    },
                }
            },
        },
        "state_bits": {
            "code": 9,
            "title": "Two bits of another flags",
            "request": {},
            "response": {"fields": {"flags": {"type": "u8", "bits": {"alarm": {"bits": 7}, "ready": {"bits": 0}}}}},
        },
    },
}


def listed(reply: dict[str, Any]) -> dict[str, Any]:
    return {**LISTED, "device": {**SPEC["device"], "reply": reply}}


def test_a_reply_fills_lists_and_groups_from_the_device() -> None:
    """`device.reply` takes a list field's items (numbers) and a group's (a mapping of its fields each); a bit field
    value goes to every response that has the field."""
    reply = {"temps": [21, -4, 30], "names": [{"name": "left"}, {"name": "right"}], "flags.alarm": 1}
    with imported("beacon", files(listed(reply)), "the sends test") as package:
        m = importlib.import_module("beacon.messages")
        codec = importlib.import_module("beacon.codec")
        sim = importlib.import_module("beacon.simulator").BeaconSimulator(ids=[1], clock=Clock())
        decode = codec.StreamParser(m.Direction.RESPONSE)
        (info,) = [x for _, f in sim.feed(codec.encode(m.InfoRequest(id=1))) for x in decode.feed(f)]
        assert list(info.temps) == [21, -4, 30] and [n.name for n in info.names] == ["left", "right"]
        assert (info.flags.alarm, info.flags.busy) == (1, 0)
        (bits,) = [x for _, f in sim.feed(codec.encode(m.StateBitsRequest(id=1))) for x in decode.feed(f)]
        assert (bits.flags.alarm, bits.flags.ready) == (1, 0)
        del package


@pytest.mark.parametrize(
    ("reply", "said"),
    [
        ({"flags.busy": 1}, "device.reply.flags.busy: the state_bits response's flags has no bit field 'busy'"),
        ({"flags.ready": 1}, "device.reply.flags.ready: the info response's flags has no bit field 'ready'"),
        ({"temps": [1, 2]}, "device.reply.temps: the info response's temps: 2 items where it holds 3"),
        ({"temps": [1, 2, 300]}, "temps: item 2 (300) is not a number in -128..127"),
        ({"names": [{"nom": "x"}]}, "names: item 0: no field 'nom'; no value for 'name'"),
        ({"names": ["left"]}, "names: item 0 is not a mapping of its fields (name)"),
        ({"n": [1]}, "the info response's n: a list for a field that is no list, array or group"),
    ],
)
def test_reply_mistakes_in_one_line(reply: dict[str, Any], said: str) -> None:
    with pytest.raises(SpecErrors) as caught:
        files(listed(reply))
    assert said in str(caught.value) and len(str(caught.value).splitlines()) == 1
