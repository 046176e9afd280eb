"""A text protocol's device and client over a real pseudo-terminal: `serialspec sim specs/nmea0183.yaml` streams
GGA and RMC fixes on its own, pynmea2 parses every sentence it sends, and the generated Client iterates over them
and calls subscribed callbacks. Also decode/encode on the command line for text sentences. No timed assertions:
sentences are counted, with generous bounds on how long to wait for them."""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import pynmea2
import pytest
from serialspec_protocols import nmea0183
from serialspec_protocols.nmea0183 import simulator

SPEC = "specs/nmea0183.yaml"
CLI = [sys.executable, "-m", "serialspec"]


def test_the_cli_sim_streams_fixes_that_pynmea2_parses_and_the_client_iterates_over() -> None:
    sim = subprocess.Popen([*CLI, "sim", SPEC], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert sim.stdout is not None
        path = sim.stdout.readline().strip()
        assert path.startswith("/dev/"), sim.stderr.read() if sim.stderr else ""
        seen: list[object] = []
        with nmea0183.Client(path) as client:
            client.on(seen.append, nmea0183.GgaResponse)
            messages = []
            for message in client.messages(timeout=10):
                messages.append(message)
                # the client may open the port after the first burst began: count both kinds, not just RMCs
                ggas_so_far = sum(isinstance(m, nmea0183.GgaResponse) for m in messages)
                rmcs_so_far = sum(isinstance(m, nmea0183.RmcResponse) for m in messages)
                if ggas_so_far >= 2 and rmcs_so_far >= 2:
                    break
    finally:
        sim.terminate()
        sim.wait(10)
    ggas = [m for m in messages if isinstance(m, nmea0183.GgaResponse)]
    assert len(ggas) >= 2 and seen == ggas  # the callback saw the GGAs only, all of them
    for message in messages:
        parsed = pynmea2.parse(nmea0183.encode(message).decode("ascii").strip())
        assert parsed.sentence_type == message.CODE
        assert parsed.latitude == pytest.approx(message.latitude.value, abs=1e-6)
    # the receiver moves: each fix is further north than the last
    latitudes = [m.latitude.value for m in ggas]
    assert latitudes == sorted(latitudes) and len(set(latitudes)) == len(latitudes)
    # and each fix is a second after the one before
    seconds = [m.utc.hour * 3600 + m.utc.minute * 60 + m.utc.second for m in ggas]
    assert [b - a for a, b in zip(seconds, seconds[1:], strict=False)] == [1] * (len(seconds) - 1)


def test_the_simulator_at_a_faster_rate_sends_sentences_pynmea2_parses() -> None:
    device = fast_device()
    path = device.start()
    try:
        with nmea0183.Client(path) as client:
            got = []
            for message in client.messages(timeout=10):
                got.append(message)
                if len(got) >= 40:
                    break
    finally:
        device.close()
    assert len(got) >= 40
    fixes = {}
    for message in got:
        text = nmea0183.encode(message).decode("ascii").strip()
        parsed = pynmea2.parse(text)  # raises on a sentence pynmea2 does not take (a bad checksum included)
        assert parsed.talker == "GP"
        fixes.setdefault(parsed.sentence_type, []).append(parsed.latitude)
    assert set(fixes) == {"GGA", "RMC"}
    # the RMC right after a GGA is of the same fix: the same position
    pairs = [(a, b) for a, b in zip(got, got[1:], strict=False) if isinstance(a, nmea0183.GgaResponse)]
    assert pairs and all(isinstance(b, nmea0183.RmcResponse) and a.latitude == b.latitude for a, b in pairs)


def test_decode_and_encode_take_a_sentence_as_typed_or_as_hex() -> None:
    sentence = "$GPRMC,225446,A,4916.45,N,12311.12,W,000.5,054.7,191194,020.3,E*68"
    for given in (sentence, sentence + "\\r\\n", (sentence + "\r\n").encode().hex(" ")):
        out = subprocess.run([*CLI, "decode", SPEC, given, "--json"], capture_output=True, text=True, check=True)
        result = json.loads(out.stdout)
        assert (result["command"], result["direction"], result["talker"]) == ("rmc", "response", "GP")
        assert result["fields"]["latitude"] == "4916.45" and result["fields"]["mode"] == ""
        back = subprocess.run([*CLI, "encode", SPEC, "--json", out.stdout], capture_output=True, text=True, check=True)
        assert back.stdout.strip() == sentence
    bad = subprocess.run([*CLI, "decode", SPEC, sentence[:-2] + "00"], capture_output=True, text=True)
    assert bad.returncode == 1 and len(bad.stderr.strip().splitlines()) == 1 and "checksum" in bad.stderr
    refused = subprocess.run(
        [*CLI, "encode", SPEC, "--json", '{"command": "gga", "fields": {"satellites": "123"}}'],
        capture_output=True,
        text=True,
    )
    assert refused.returncode != 0 and "satellites" in refused.stderr and "Traceback" not in refused.stderr


def fast_device() -> simulator.Simulator:
    fast = dataclasses.replace(
        simulator.DEVICE, sends=tuple(dataclasses.replace(s, every=0.02) for s in simulator.DEVICE.sends)
    )
    return simulator.Simulator(fast, (0,), encode=nmea0183.CODEC.encode, parser=lambda: nmea0183.StreamParser())


def test_monitor_shows_the_sentences_a_text_device_sends() -> None:
    device = fast_device()
    path = device.start()
    try:
        out = subprocess.run(
            [*CLI, "monitor", SPEC, "--port", path, "--count", "6"], capture_output=True, text=True, timeout=60
        )
    finally:
        device.close()
    lines = out.stdout.splitlines()
    assert out.returncode == 0 and len(lines) == 6, out.stderr
    for line in lines:
        sentence = line.rsplit(" ", 1)[1]
        parsed = pynmea2.parse(sentence)
        fields = json.loads(line.split(" ", 3)[3].rsplit(" ", 1)[0])
        assert fields["latitude"] == parsed.lat and f"response {parsed.sentence_type.lower()} " in line


def test_a_text_device_section_with_mistakes_gets_one_line_each(tmp_path: Path) -> None:
    spec = Path(SPEC).read_text(encoding="utf-8")
    spec = spec.replace("step: fix\n", "step: fixx\n").replace("altitude: altitude}", "altitude: nope, bogus: fix}")
    spec = spec.replace("reply: {talker: GP,", "reply: {talker: XX, colour: 1,")
    spec = spec.replace("    rmc:\n      every: 1000\n", "    rmc:\n      after: [gga]\n")
    bad = tmp_path / "nmea.yaml"
    bad.write_text(spec, encoding="utf-8")
    out = subprocess.run([*CLI, "check", str(bad)], capture_output=True, text=True)
    errors = out.stderr.strip().splitlines()
    assert out.returncode != 0 and "Traceback" not in out.stderr
    expected = [
        "device.reply.talker: talker 'XX' is not one of GP, GN, GL, GA, BD",
        "device.reply.colour: no sentence has a field 'colour'",
        "device.sends.gga.step: unknown state variable 'fixx'",
        "device.sends.gga.values.altitude: unknown name 'nope' (not a state variable)",
        "device.sends.gga.values.bogus: gga has no field 'bogus'",
        "device.sends.rmc: says not when: give `every`",
        "device.sends.rmc.after: `after` is not available in a text protocol's device yet",
    ]
    assert [e.split(": ", 1)[1] for e in errors] == expected, errors
    assert all(e.startswith(f"{bad}:") for e in errors)
