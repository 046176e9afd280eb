"""A text device that answers requests, as a user writes one: a command's request and response share its code
(`#LVL,50` asked, `#LVL,50` answered), `device.commands` says what the device does with each request. Generated and
served with the command line (`serialspec generate`, `serialspec sim` on a real pseudo-terminal), driven by the
generated typed client; decode takes the direction; monitor pairs a request with the answer after it."""

from __future__ import annotations

import importlib
import json
import os
import shutil
import subprocess
import sys
import tty
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import ROOT

CLI = [sys.executable, "-m", "serialspec"]
SPEC = ROOT / "examples" / "textlamp" / "textlamp.yaml"


@pytest.fixture(scope="module")
def lamp(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Path, object]]:
    folder = tmp_path_factory.mktemp("textlamp")
    spec = folder / "textlamp.yaml"
    shutil.copy(SPEC, spec)
    done = subprocess.run([*CLI, "generate", str(spec), "--out", str(folder)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    sys.path.insert(0, str(folder))
    try:
        yield spec, importlib.import_module("textlamp")
    finally:
        sys.path.remove(str(folder))


def test_the_sim_answers_the_typed_client_under_the_request_s_code(lamp: tuple[Path, object]) -> None:
    spec, package = lamp
    sim = subprocess.Popen([*CLI, "sim", str(spec)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert sim.stdout is not None
        path = sim.stdout.readline().strip()
        assert path.startswith("/dev/"), sim.stderr.read() if sim.stderr else ""
        with package.Client(path) as client:  # type: ignore[attr-defined]
            assert client.read_temperature().temperature == pytest.approx(21.5)
            assert client.set_level(40).level == 40
            assert client.read_temperature().temperature == pytest.approx(25.5)  # 21.5 + 40 / 10
            with pytest.raises(ValueError, match="level = 101 is outside its range 0..100"):
                client.set_level(101)  # refused before a byte is written
            assert client.blink() is None  # not answered: nothing to wait for
            assert client.set_level(0).level == 0
    finally:
        sim.terminate()
        sim.wait(10)
    log = sim.stderr.read() if sim.stderr else ""
    assert 'request  set_level {"level": 40}' in log and "response #LVL,40*" in log, log


def test_decode_needs_the_direction_only_for_a_shared_code(lamp: tuple[Path, object]) -> None:
    spec, package = lamp
    asked = subprocess.run([*CLI, "decode", str(spec), "#LVL,50*7F", "--json"], capture_output=True, text=True)
    assert asked.returncode == 1 and "--direction" in asked.stderr and "Traceback" not in asked.stderr
    for direction in ("request", "response"):
        done = subprocess.run(
            [*CLI, "decode", str(spec), "#LVL,50*7F", "--json", "--direction", direction],
            capture_output=True,
            text=True,
        )
        assert done.returncode == 0, done.stderr
        result = json.loads(done.stdout)
        assert (result["command"], result["direction"], result["fields"]) == ("set_level", direction, {"level": "50"})
    assert package.decode("#LVL,50*7F", "request") == package.SetLevelRequest(level=50)  # type: ignore[attr-defined]


def test_monitor_pairs_each_answer_with_the_request_before_it(lamp: tuple[Path, object]) -> None:
    spec, package = lamp
    session = b"".join(
        package.encode(m)  # type: ignore[attr-defined]
        for m in (
            package.SetLevelRequest(level=30),  # type: ignore[attr-defined]
            package.SetLevelResponse(level=30),  # type: ignore[attr-defined]
            package.ReadTemperatureRequest(),  # type: ignore[attr-defined]
            package.ReadTemperatureResponse(temperature=24.5, changes=1),  # type: ignore[attr-defined]
        )
    )
    controller, device = os.openpty()
    tty.setraw(controller)
    tty.setraw(device)
    try:
        monitor = subprocess.Popen(
            [*CLI, "monitor", str(spec), "--port", os.ttyname(device), "--count", "4"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert monitor.stderr is not None
        monitor.stderr.readline()  # "serialspec monitor: ... Ctrl-C to stop": the port is open
        os.write(controller, session)
        out, err = monitor.communicate(timeout=60)
    finally:
        os.close(controller)
        os.close(device)
    kinds = [line.split()[1:3] for line in out.splitlines()]
    assert kinds == [
        ["request", "set_level"],
        ["response", "set_level"],
        ["request", "read_temperature"],
        ["response", "read_temperature"],
    ], out + err
