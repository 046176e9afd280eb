"""The README's client session runs as printed, against a real `serialspec sim` process."""

from __future__ import annotations

import contextlib
import io
import re

import pytest
from serialspec.runtime.errors import RangeError
from sim_process import ROOT, serve

PRINTED_PORT = "/dev/pts/5"


def session_block() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    return next(b for b in blocks if "FeetechSmsClient" in b and PRINTED_PORT in b)


def test_the_readme_session_runs_as_printed() -> None:
    code = session_block()
    output = io.StringIO()
    refused = pytest.raises(RangeError, match=r"torque_limit = 1001 is outside its range 0\.\.1000")
    with serve("feetech_sms.yaml", 1, 2) as port, contextlib.redirect_stdout(output), refused:
        exec(compile(code.replace(PRINTED_PORT, port), "README.md", "exec"), {})
    lines = output.getvalue().splitlines()
    assert lines[0] == "True False"
    assert lines[1] == "1000"
    assert lines[2] == "777"
    assert 0 <= int(lines[3]) < 2048
    assert lines[4] == "{1: {'goal_position': 100}, 2: {'goal_position': 300}}"


def test_the_readme_stream_parser_snippet_runs_against_a_simulated_servo() -> None:
    """The StreamParser snippet, as printed but for its port, reads a reply from a `serialspec sim` process."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    code = next(b for b in re.findall(r"```python\n(.*?)```", text, flags=re.S) if "StreamParser" in b)
    output = io.StringIO()
    with serve("fashionstar_uart.yaml", 0) as port, contextlib.redirect_stdout(output):
        exec(compile(code.replace('"/dev/ttyUSB0"', repr(port)), "README.md", "exec"), {})
    assert output.getvalue().strip().lstrip("-").isdigit()


def test_the_readme_names_the_errors_decode_and_encode_raise() -> None:
    """Found by a new user (tests/test_newuser_ibus.py): the README showed decode and encode but not what they raise
    on a bad frame or a bad message, nor where to import it from."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    imports = re.search(r"`(from serialspec\.runtime\.errors import [A-Za-z, ]+)`", text)
    assert imports, "the README does not say where the errors come from"
    names: dict[str, object] = {}
    exec(imports.group(1), names)
    from serialspec_protocols import fashionstar_uart as fs

    frame = bytearray(fs.encode(fs.RotateRequest(servo_id=2, angle=900, interval=500)))
    frame[-1] ^= 1
    with pytest.raises(names["ChecksumError"]):  # type: ignore[call-overload]
        fs.decode(bytes(frame))
    with pytest.raises(names["RangeError"]):  # type: ignore[call-overload]
        fs.encode(fs.RotateRequest(servo_id=2, angle=900, interval=500, power=-1))


def test_the_readme_crc_table_recipe_gives_the_catalogue_parameters() -> None:
    """Found by a new user (tests/test_newuser_ld06.py): the LDROBOT datasheet prints a CRC-8 table and a loop, the
    `crc:` key wants catalogue parameters and a check value, and the docs did not say how to get one from the other.
    The README's recipe, run on the table lds2d ships, gives what tests/specs/ld06.yaml says."""
    import yaml

    crc_module = pytest.importorskip("lds2d.crc")
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    recipe = re.search(r"```python\n(table = CRC_TABLE.*?)```", text, re.S)
    assert recipe, "the README has no CRC table recipe"
    names: dict[str, object] = {"CRC_TABLE": crc_module.CRC_TABLE}
    exec(compile(recipe.group(1), "README.md", "exec"), names)
    spec = yaml.safe_load((ROOT / "tests" / "specs" / "ld06.yaml").read_text(encoding="utf-8"))
    crc = spec["framing"]["elements"]["crc"]["crc"]
    assert (names["poly"], names["check"]) == (crc["poly"], crc["check"]) == (0x4D, 0xC3)
