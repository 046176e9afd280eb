"""A text protocol's device and client over a real pseudo-terminal: `serialspec sim specs/nmea0183.yaml` streams
GGA and RMC fixes on its own, pynmea2 parses every sentence it sends, and the generated Client iterates over them
and calls subscribed callbacks. Also decode/encode on the command line for text sentences. No timed assertions:
sentences are counted, with generous bounds on how long to wait for them."""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
import subprocess
import sys
import tty
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
    # the callback saw the GGAs only, all of them (as read: a read may bring more than the loop took)
    assert len(ggas) >= 2 and seen[: len(ggas)] == ggas and all(isinstance(m, nmea0183.GgaResponse) for m in seen)
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
            # the device streams before the port opens: a first sentence caught halfway is a BAD line, filtered out
            [*CLI, "monitor", SPEC, "--port", path, "--count", "6", "--command", "gga", "--command", "rmc"],
            capture_output=True,
            text=True,
            timeout=60,
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


def test_sim_tap_records_the_sentences_sent_and_decode_file_reads_them_back(tmp_path: Path) -> None:
    tap = tmp_path / "fixes.capture"
    sim = subprocess.Popen(
        [*CLI, "sim", SPEC, "--tap", str(tap), "--quiet"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        assert sim.stdout is not None
        path = sim.stdout.readline().strip()
        assert path.startswith("/dev/"), sim.stderr.read() if sim.stderr else ""
        with nmea0183.Client(path) as client:
            received = []
            for message in client.messages(timeout=10):
                received.append(message)
                if len(received) >= 3:
                    break
    finally:
        sim.terminate()
        sim.wait(10)
    out = subprocess.run([*CLI, "decode", SPEC, "--file", str(tap), "--json"], capture_output=True, text=True)
    assert out.returncode == 0 and out.stderr == "", out.stderr
    decoded = [json.loads(line) for line in out.stdout.splitlines()]
    assert len(decoded) >= len(received) and all(d["direction"] == "response" and d["time"] for d in decoded)
    sent = [d["text"] for d in decoded]
    for message in received:  # every sentence the client got is in the recording, as it was sent
        assert nmea0183.encode(message).decode("ascii").strip() in sent
    assert all(pynmea2.parse(text).sentence_type in ("GGA", "RMC") for text in sent)
    readable = subprocess.run([*CLI, "decode", SPEC, "--file", str(tap)], capture_output=True, text=True, check=True)
    assert readable.stdout.count("nmea0183 response gga") == sum(d["command"] == "gga" for d in decoded)


def test_decode_file_of_a_text_capture_reports_garbage_and_a_cut_sentence_on_their_lines(tmp_path: Path) -> None:
    good = b"$GPRMC,225446,A,4916.45,N,12311.12,W,000.5,054.7,191194,020.3,E*68\r\n"
    capture = tmp_path / "noisy.capture"
    capture.write_text(
        "# serialspec capture: nmea0183\n" + f"{b'xx'.hex(' ')}\n{good.hex(' ')}\n{good[:20].hex(' ')}\n",
        encoding="utf-8",
    )
    out = subprocess.run([*CLI, "decode", SPEC, "--file", str(capture), "--json"], capture_output=True, text=True)
    assert out.returncode == 1 and "Traceback" not in out.stderr
    assert [json.loads(line)["command"] for line in out.stdout.splitlines()] == ["rmc"]
    errors = out.stderr.strip().splitlines()
    assert len(errors) == 2 and "line 2" in errors[0] and "'xx'" in errors[0], errors
    assert "ends inside a sentence" in errors[1] and "$GPRMC,225446" in errors[1], errors


GGA = b"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n"
RMC = b"$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A\r\n"


def test_plot_draws_a_text_capture_s_numbers_in_their_units(tmp_path: Path) -> None:
    capture = tmp_path / "fixes.capture"
    lines = ["# serialspec capture: nmea0183"]
    for second, sentence in enumerate((GGA, RMC, GGA, RMC)):
        lines.append(f"2026-11-27T12:00:0{second}.000000+00:00 response {sentence.hex(' ')}")
    capture.write_text("\n".join(lines) + "\n", encoding="utf-8")
    out = tmp_path / "fixes.svg"
    fields = ["--field", "latitude", "--field", "gga.altitude", "--field", "speed"]
    done = subprocess.run(
        [*CLI, "plot", str(capture), "--spec", SPEC, *fields, "--out", str(out)], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    assert "8 values of 3 fields" in done.stdout  # latitude from 2 GGA + 2 RMC, altitude 2, speed 2
    svg = out.read_text(encoding="utf-8")
    assert "altitude (m)" in svg and "speed (kn)" in svg and "latitude (°)" in svg
    refused = subprocess.run(
        [*CLI, "plot", str(capture), "--spec", SPEC, "--field", "utc", "--out", str(out)],
        capture_output=True,
        text=True,
    )
    assert refused.returncode != 0 and "numbers seen: altitude" in refused.stderr and "Traceback" not in refused.stderr


def test_replay_sends_a_text_capture_that_monitor_reads_back(tmp_path: Path) -> None:
    capture = tmp_path / "fixes.capture"
    capture.write_text(f"{GGA.hex(' ')}\n{RMC.hex(' ')}\n", encoding="utf-8")  # unknown direction: the spec splits
    controller, device = os.openpty()
    tty.setraw(controller)
    tty.setraw(device)
    try:
        path = os.ttyname(device)
        done = subprocess.run(
            [*CLI, "replay", str(capture), "--port", path, "--spec", SPEC, "--direction", "response", "--speed", "0"],
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert done.returncode == 0, done.stderr
        received = b""
        while len(received) < len(GGA + RMC):
            received += os.read(controller, 4096)
    finally:
        os.close(controller)
        os.close(device)
    assert received == GGA + RMC


@pytest.mark.skipif(shutil.which("tmux") is None, reason="tmux is not installed (make generate installs it)")
def test_watch_shows_a_text_device_s_sentences_with_units() -> None:
    from test_watch import pane, row

    device = fast_device()
    path = device.start()
    try:
        with pane("nmea") as screen:
            screen.start([*CLI, "watch", SPEC, "--port", path])
            # a row's values wrap onto the lines below it in a 160-column pane
            text = screen.wait_for(lambda s: "altitude=545.4 m" in s and "speed=22.0 kn" in s)
    finally:
        device.close()
    assert row(text, "gga", "utc=") and row(text, "rmc", "utc="), text
    assert "altitude=545.4 m" in text and "speed=22.0 kn" in text and "course=45.0°" in text, text
    assert "0 bad" in text and "Traceback" not in text
