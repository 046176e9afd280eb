"""serialspec plot: a session recorded by `serialspec sim --tap` (and live from a port) drawn as PNG and SVG, values in
the spec's units, one panel per field; one-line errors, and a one-line hint when matplotlib is missing."""

from __future__ import annotations

import os
import subprocess
import sys
import tty
from pathlib import Path

import pytest
from serialspec.cli import capture
from serialspec.cli.plot import collect
from serialspec.cli.protocols import open_spec
from sim_process import ROOT, serve

FS = str(ROOT / "specs" / "fashionstar_uart.yaml")
pytestmark = pytest.mark.slow  # matplotlib takes a second or two to import in every process


def serialspec(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "serialspec", *args], capture_output=True, text=True, env=env, timeout=120
    )


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two Fashion Star servos turned (to 90.0° and -45.0°) and read while they move, recorded by the sim's tap."""
    from serialspec_protocols.fashionstar_uart.client import FashionstarUartClient

    tap = tmp_path_factory.mktemp("plot") / "session.capture"
    with (
        serve("fashionstar_uart.yaml", 0, 1, options=["--tap", str(tap)]) as path,
        FashionstarUartClient(path, timeout=1.0) as servos,
    ):
        servos.rotate(0, 900, 300)
        servos.rotate(1, -450, 300)
        while servos.read_angle(0) != 900 or servos.read_angle(1) != -450:
            pass  # until both have arrived
    return tap


def test_a_capture_is_drawn_as_png_and_svg_with_units_per_panel(session: Path, tmp_path: Path) -> None:
    result = serialspec(
        "plot", str(session), "--field", "read_angle.angle", "--field", "angle", "--out", str(tmp_path / "a.png")
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("serialspec plot: ") and result.stdout.endswith(
        f"2 fields in {tmp_path / 'a.png'}\n"
    )
    assert (tmp_path / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    result = serialspec("plot", str(session), "--field", "angle", "--id", "1", "--out", str(tmp_path / "a.svg"))
    assert result.returncode == 0, result.stderr
    svg = (tmp_path / "a.svg").read_text(encoding="utf-8")
    # matplotlib writes text as glyph paths, and each string as a comment beside them
    for text in ("angle (°)", "read_angle response, servo_id 1", "rotate request, servo_id 1", "time (s)"):
        assert f"<!-- {text} -->" in svg, text
    assert "servo_id 0" not in svg  # --id 1 only


def test_values_are_in_the_specs_units(session: Path) -> None:
    protocol, package = open_spec(FS)
    with session.open(encoding="utf-8") as lines:
        chunks = [chunk for _, chunk in capture.read(lines)]
    (panel,) = collect(protocol, package, chunks, ["read_angle.angle"], set())
    assert panel.unit == "°"
    zero, one = panel.lines["read_angle response, servo_id 0"], panel.lines["read_angle response, servo_id 1"]
    assert zero.values[-1] == 90.0 and one.values[-1] == -45.0  # the wire's 900 and -450, times the scale 0.1
    assert zero.times == sorted(zero.times) and zero.times[0] >= 0
    assert len(set(zero.values)) > 2  # read on its way, not only at the end


def test_registers_read_through_a_table_are_fields_of_their_reply(tmp_path: Path) -> None:
    from serialspec_protocols.feetech_sms.client import FeetechSmsClient

    tap = tmp_path / "sms.capture"
    with serve("feetech_sms.yaml", 1, options=["--tap", str(tap)]) as path, FeetechSmsClient(path, timeout=1.0) as sms:
        sms.read_many(1, "present_voltage", "present_temperature")
        sms.read(1, "present_voltage")
    protocol, package = open_spec("feetech_sms")
    with tap.open(encoding="utf-8") as lines:
        chunks = [chunk for _, chunk in capture.read(lines)]
    voltage, temperature = collect(protocol, package, chunks, ["present_voltage", "present_temperature"], set())
    assert (voltage.unit, voltage.lines["reply response, id 1"].values) == ("V", [7.4, 7.4])
    assert temperature.lines["reply response, id 1"].values == [30]
    # the capture names its protocol: no --spec needed
    result = serialspec("plot", str(tap), "--field", "present_voltage", "--out", str(tmp_path / "v.svg"))
    assert result.returncode == 0 and "<!-- present_voltage (V) -->" in (tmp_path / "v.svg").read_text()


def test_live_from_a_port_for_a_duration(tmp_path: Path) -> None:
    controller, device = os.openpty()
    tty.setraw(device)
    tty.setraw(controller)
    try:
        process = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "serialspec",
                "plot",
                "--spec",
                FS,
                "--port",
                os.ttyname(device),
                "--duration",
                "2",
                "--field",
                "angle",
                "--out",
                str(tmp_path / "live.svg"),
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert process.stderr is not None
        assert "recording" in process.stderr.readline()
        # read_angle replies of servo 3: 10.0°, then 20.0° (wire values 100 and 200, checksums as the spec says)
        os.write(controller, bytes.fromhex("05 1c 0a 03 03 64 00 95 05 1c 0a 03 03 c8 00 f9"))
        out, err = process.communicate(timeout=60)
    finally:
        os.close(controller)
        os.close(device)
    assert process.returncode == 0, err
    assert out == f"serialspec plot: 2 values of 1 field in {tmp_path / 'live.svg'}\n"
    assert "<!-- read_angle response, servo_id 3 -->" in (tmp_path / "live.svg").read_text(encoding="utf-8")


def test_mistakes_are_one_line_each(session: Path, tmp_path: Path) -> None:
    cases = {
        ("--field", "nothing", "--out", str(tmp_path / "x.png")): "serialspec plot: no frame has a number named "
        "'nothing' (numbers seen: angle, data_id, interval, power, servo_id)",
        ("--field", "angle", "--out", str(tmp_path / "x.gif")): f"serialspec plot: --out {tmp_path / 'x.gif'}: "
        "give a .png or .svg file",
        ("--field", "angle", "--out", "/proc/x.png"): "serialspec plot: cannot write /proc/x.png",
    }
    for args, line in cases.items():
        result = serialspec("plot", str(session), *args)
        assert result.returncode == 1 and result.stderr.startswith(line) and result.stderr.count("\n") == 1, result


def test_without_matplotlib_it_says_how_to_install_it(session: Path, tmp_path: Path) -> None:
    (tmp_path / "matplotlib.py").write_text("raise ImportError(\"No module named 'matplotlib'\")\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), *sys.path]))
    result = serialspec("plot", str(session), "--field", "angle", "--out", str(tmp_path / "x.png"), env=env)
    assert (result.returncode, result.stdout) == (1, "")
    assert (
        result.stderr
        == "serialspec plot: plotting needs matplotlib, an optional extra: pip install 'serialspec[plot]'\n"
    )
