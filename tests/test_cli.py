"""The command line contract (design-notes §4), run as a real process."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from conftest import ALL, ROOT, Generated, encode, example_request
from serialspec.cli import main, plain_decode

FS = str(ROOT / "specs" / "fashionstar_uart.yaml")
#: The repository's [tool.serialspec] namespace settings, for a copy of its specs and generated/ elsewhere.
_SETTINGS = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["serialspec"]
PACKAGES_WHERE = f"[tool.serialspec]\nnamespace = {_SETTINGS['namespace']!r}\nold_names = {_SETTINGS['old_names']!r}\n"


def serialspec(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "serialspec", *args], capture_output=True, text=True, cwd=cwd)


def test_decode_rotate_as_json_then_encode_gives_the_same_bytes() -> None:
    frame = "12 4c 08 07 02 84 03 f4 01 00 00 eb"
    decoded = serialspec("decode", FS, frame, "--json")
    assert decoded.returncode == 0, decoded.stderr
    obj = json.loads(decoded.stdout)
    assert obj == {
        "protocol": "fashionstar_uart",
        "direction": "request",
        "command": "rotate",
        "subcommand": None,
        "fields": {"servo_id": 2, "angle": 900, "interval": 500, "power": 0},
        "checksum_ok": True,
        "hex": frame,
    }
    encoded = serialspec("encode", FS, "--json", decoded.stdout)
    assert encoded.stdout.strip() == frame


@pytest.mark.parametrize(
    "form", ["12 4c 01 01 03 63", "0x12 0x4c 0x01 0x01 0x03 0x63", "124c01010363", "12:4c:01:01:03:63"]
)
def test_decode_accepts_the_hex_forms_people_paste(form: str) -> None:
    result = serialspec("decode", FS, form, "--json")
    assert json.loads(result.stdout)["command"] == "ping"


@pytest.mark.parametrize(
    "argv",
    [
        ["decode", "feetech_sms", "ff ff 01 02 01 fb"],
        ["decode", "feetech_sms", "ff ff", "01 02", "--direction", "request", "--json"],
        ["decode", "--json", "feetech_sms", "--direction=response", "ff ff"],
    ],
)
def test_a_plain_decode_command_line_is_read_as_argparse_reads_it(argv: list[str]) -> None:
    """`decode SPEC HEX... [--direction D] [--json]` is read without argparse (start-up time): to the same arguments."""
    from serialspec.cli.arguments import parse

    plain = plain_decode(argv)
    assert plain is not None and vars(plain) == vars(parse(argv))


@pytest.mark.parametrize(
    "argv",
    [
        ["decode", "x", "-"],
        ["decode", "x", "ff", "--dir", "request"],
        ["decode", "x", "ff", "--direction", "up"],
        ["decode", "x", "ff", "--direction"],
        ["decode", "x", "ff", "--units"],
        ["decode", "x", "ff", "--json", "--json"],
        ["decode", "x", "ff", "-h"],
        ["decode", "x"],
        ["encode", "x", "ff"],
    ],
)
def test_any_other_command_line_is_left_to_argparse(argv: list[str]) -> None:
    assert plain_decode(argv) is None


def test_list_and_bit_field_values_are_shown_as_json_writes_them() -> None:
    """decode writes plain values itself (no json import at start-up), and leaves anything else to json."""
    from serialspec.cli.decode import _json

    values = [[], [1, -2, 2**70], {"a": 1, "b": None, "c": True}, ["é", 'q"', "t\tab"], [1.5, float("nan")], {1: [0]}]
    for value in values:
        assert _json(value) == json.dumps(value, ensure_ascii=False)


@pytest.mark.parametrize(
    ("frame", "reason"),
    [
        ("12 4c 08 07 02 84 03 f4 01 00 00 ec", "bad checksum"),
        ("12 4c 14 01 00 73", "unknown command 0x14"),  # 20: between 19 and 22, unused
        ("12 4c 08 03 02 84 03 f2", "content is 3 bytes, expected 7"),
        ("x12 0x4c", "not a hex byte"),
    ],
)
def test_a_frame_that_does_not_decode_exits_non_zero_with_one_line(frame: str, reason: str) -> None:
    result = serialspec("decode", FS, frame, "--json")
    assert result.returncode != 0
    assert reason in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert "Traceback" not in result.stderr


def test_readable_view_and_units() -> None:
    result = serialspec("decode", FS, "05 1c 0a 03 00 86 03 b7", "--units")
    assert "read_angle" in result.stdout and "90.2" in result.stdout


def test_encode_refuses_out_of_range_naming_field_and_range() -> None:
    result = serialspec(
        "encode", FS, "--json", '{"command": "rotate", "fields": {"servo_id": 300, "angle": 0, "interval": 0}}'
    )
    assert result.returncode != 0
    assert "servo_id = 300 is outside its range 0..254" in result.stderr


def test_encode_refuses_a_direction_that_is_neither_request_nor_response() -> None:
    result = serialspec("encode", FS, "--json", '{"command": "rotate", "direction": 5, "fields": {}}')
    assert result.returncode != 0
    assert "`direction` must be 'request' or 'response', got 5" in result.stderr


@pytest.mark.parametrize("g", ALL, ids=[g.protocol.name for g in ALL])
def test_every_example_round_trips_through_the_cli(g: Generated, capsys: pytest.CaptureFixture[str]) -> None:
    # In-process for speed: the subprocess tests above cover the console script itself.
    spec = str(ROOT / g.protocol.spec_path)
    for example in g.protocol.examples:
        request = example_request(g, example)  # a reply read with its request: --request HEX both ways
        asked = [] if request is None else ["--request", encode(g, request).hex(" ")]
        argv = ["decode", spec, example.frame.hex(" "), "--json", "--direction", example.direction.value, *asked]
        assert main(argv) == 0
        decoded = capsys.readouterr().out
        assert main(["encode", spec, "--json", decoded, *asked]) == 0, example.name
        assert capsys.readouterr().out.strip() == example.frame.hex(" "), example.name


def test_check_fails_when_a_generated_file_is_stale(tmp_path: Path) -> None:
    shutil.copytree(ROOT / "specs", tmp_path / "specs")
    shutil.copytree(ROOT / "generated", tmp_path / "generated", ignore=shutil.ignore_patterns("__pycache__"))
    (tmp_path / "pyproject.toml").write_text(PACKAGES_WHERE, encoding="utf-8")
    assert serialspec("check", "--root", str(tmp_path)).returncode == 0
    docs = tmp_path / "generated" / "docs" / "fashionstar_uart.md"
    docs.write_text(docs.read_text(encoding="utf-8") + "edited by hand\n", encoding="utf-8")
    result = serialspec("check", "--root", str(tmp_path))
    assert result.returncode == 1
    assert "generated/docs/fashionstar_uart.md: stale" in result.stderr


def test_a_mistake_in_one_spec_leaves_the_language_reference_alone(tmp_path: Path) -> None:
    """The reference's examples come from every spec: a spec that fails to load must not rewrite it (or make check
    call it stale and send the user to `generate`, which cannot help)."""
    for folder in ("specs", "generated", "docs"):
        shutil.copytree(ROOT / folder, tmp_path / folder, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    reference = (tmp_path / "docs" / "language.md").read_text(encoding="utf-8")
    spec = tmp_path / "specs" / "fashionstar_uart.yaml"
    spec.write_text(spec.read_text(encoding="utf-8").replace("type: u8", "type: int17", 1), encoding="utf-8")
    checked = serialspec("check", "--root", str(tmp_path))
    assert checked.returncode == 1 and "'int17'" in checked.stderr
    assert "language.md" not in checked.stderr and "run `serialspec generate`" not in checked.stderr
    assert serialspec("generate", "--root", str(tmp_path)).returncode == 1
    assert (tmp_path / "docs" / "language.md").read_text(encoding="utf-8") == reference


def test_a_spec_named_on_the_command_line_leaves_the_language_reference_alone(tmp_path: Path) -> None:
    """The reference's examples come from all the project's specs: `check SPEC` and `generate SPEC --out DIR` in a
    project neither call it stale nor rewrite it from the one spec."""
    assert serialspec("check", "specs/fashionstar_uart.yaml").returncode == 0
    reference = (ROOT / "docs" / "language.md").read_text(encoding="utf-8")
    assert serialspec("generate", "specs/fashionstar_uart.yaml", "--out", str(tmp_path)).returncode == 0
    assert (ROOT / "docs" / "language.md").read_text(encoding="utf-8") == reference
    assert (tmp_path / "fashionstar_uart" / "__init__.py").is_file()


def test_decode_picks_the_reply_layout_by_the_request() -> None:
    spec = "specs/dynamixel_p2.yaml"
    status = "FF FF FD 00 01 07 00 55 00 06 04 26 65 5D"  # PING's reply, or a 3-byte READ's: the request decides
    alone = json.loads(serialspec("decode", spec, status, "--direction", "response", "--json").stdout)
    assert alone["command"] == "status" and alone["fields"]["data"] == "06 04 26"
    ping = "FF FF FD 00 01 03 00 01 19 4E"
    answered = serialspec("decode", spec, status, "--direction", "response", "--request", ping, "--json")
    assert json.loads(answered.stdout)["fields"]["model_number"] == 1030


def test_options_may_come_between_the_spec_and_the_frames() -> None:
    """`decode SPEC --direction response --request HEX FRAME`, the order the README names them in."""
    read = "FF FF 01 04 02 38 02 BE"
    result = serialspec(
        "decode", "specs/feetech_sms.yaml", "--direction", "response", "--request", read, "FF FF 01 04 00 18 05 DD"
    )
    assert result.returncode == 0, result.stderr
    assert "register present_position 1304" in result.stdout
    wrong = serialspec("decode", "specs/feetech_sms.yaml", "--direction", "response", "--bogus", "FF FF 01 02 00 FC")
    assert wrong.returncode == 2 and "serialspec decode: error: unrecognized arguments: --bogus" in wrong.stderr


def test_check_names_a_hand_written_file_inside_a_generated_package(tmp_path: Path) -> None:
    shutil.copytree(ROOT / "specs", tmp_path / "specs")
    shutil.copytree(ROOT / "generated", tmp_path / "generated", ignore=shutil.ignore_patterns("__pycache__"))
    (tmp_path / "pyproject.toml").write_text(PACKAGES_WHERE, encoding="utf-8")
    (tmp_path / "generated" / "serialspec_protocols" / "feetech_sms" / "mine.py").write_text(
        "x = 1\n", encoding="utf-8"
    )
    result = serialspec("check", "--root", str(tmp_path))
    assert result.returncode == 1
    assert "generated/serialspec_protocols/feetech_sms/mine.py: not generated from any spec" in result.stderr
    assert serialspec("generate", "--root", str(tmp_path)).returncode == 0
    assert (
        tmp_path / "generated" / "serialspec_protocols" / "feetech_sms" / "mine.py"
    ).exists()  # generate never removes it


def test_a_spec_path_uses_the_generated_package_only_when_it_was_generated_from_that_very_text(tmp_path: Path) -> None:
    from serialspec.cli.protocols import open_spec

    _, package = open_spec(FS)
    assert package.__file__ == str(ROOT / "generated" / "serialspec_protocols" / "fashionstar_uart" / "__init__.py")
    edited = tmp_path / "fashionstar_uart.yaml"
    edited.write_text(Path(FS).read_text(encoding="utf-8").replace("range: [0, 254]", "range: [0, 255]", 1))
    _, live = open_spec(str(edited))
    assert live is not package and "generated in memory" in str(live.__spec__.origin if live.__spec__ else "")
    request = live.RotateRequest(servo_id=255, angle=0, interval=0)  # the edited range, not the generated one
    assert live.encode(request)[:5] == bytes.fromhex("12 4c 08 07 ff")
    with pytest.raises(Exception, match="servo_id = 255 is outside its range 0..254"):
        package.encode(package.RotateRequest(servo_id=255, angle=0, interval=0))


def test_a_package_generated_into_the_current_folder_is_found_by_name(tmp_path: Path) -> None:
    """The installed `serialspec` script (not `python -m`, which puts the folder on the path itself) finds by name a
    package that `import NAME` finds from the current folder."""
    shutil.copy(ROOT / "examples" / "tinylamp" / "tinylamp.yaml", tmp_path)
    script = str(Path(sys.executable).parent / "serialspec")
    generate = subprocess.run([script, "generate", "tinylamp.yaml", "--out", "."], cwd=tmp_path, capture_output=True)
    assert generate.returncode == 0, generate.stderr
    (tmp_path / "tinylamp.yaml").unlink()  # by name only: no spec file to fall back on
    run = [script, "decode", "tinylamp", "aa 01 01 01 ad"]
    decoded = subprocess.run(run, cwd=tmp_path, capture_output=True, text=True)
    assert decoded.returncode == 0 and decoded.stdout.startswith("tinylamp request"), decoded.stderr
    elsewhere = subprocess.run(run, cwd=tmp_path / "docs", capture_output=True, text=True)
    assert elsewhere.returncode == 1 and "run from the folder that holds the generated tinylamp/" in elsewhere.stderr


def test_units_view_reads_flags_as_words_and_json_keeps_the_list() -> None:
    """`--units` prints set flags as names (`overheat, overload`), none set as `none`; `--json` keeps a list."""
    args = ("decode", str(ROOT / "specs" / "feetech_sms.yaml"), "--direction", "response", "--units")
    faults = serialspec(*args, "ff ff 01 02 24 d8").stdout
    assert "  error                overheat, overload\n" in faults
    assert "  error                none\n" in serialspec(*args, "ff ff 01 02 00 fc").stdout
    as_json = json.loads(serialspec(*args, "ff ff 01 02 24 d8", "--json").stdout)
    assert as_json["fields"]["error"] == ["overheat", "overload"]


def test_sim_banner_says_what_is_served_in_words() -> None:
    """No `device(s) 0` for a protocol without an address, and a board's further kinds of device by their ids."""
    from types import SimpleNamespace

    from serialspec.cli.sim import served
    from serialspec.lang import load_protocol

    def banner(name: str, ids: list[int]) -> str:
        protocol = load_protocol(str(ROOT / "specs" / f"{name}.yaml"))
        return served(protocol, {i: SimpleNamespace(model=None) for i in ids})

    assert banner("vesc", [0]) == "(one device: the protocol has no address)"
    assert banner("modbus_rtu", [1, 2]) == "unit 1, 2"
    assert banner("hiwonder_rrc", [1]) == "servo_id 1; pwm_servo servo_id 1, 2, 3, 4; motor motor_id 0, 1, 2, 3"


def test_field_values_beside_fields_are_named(capsys: pytest.CaptureFixture[str]) -> None:
    """`encode --json '{"command": "rotate", "servo_id": 1, ...}'` said "missing field 'servo_id'" of a field the
    user gave, one level too high (found writing iRobot's Open Interface as a new user)."""
    given = '{"command": "rotate", "servo_id": 1, "angle": 0, "interval": 0, "fields": {}}'
    assert main(["encode", "fashionstar_uart", "--json", given]) == 1
    assert capsys.readouterr().err.strip() == (
        "serialspec encode: --json: unknown keys angle, interval, servo_id (field values go in `fields`)"
    )


def test_plot_given_a_spec_where_its_capture_goes_says_where_the_spec_goes(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """`serialspec plot mhz19b.yaml --field co2 ...`, the spec first as every other verb takes it, said "line 2:
    'protocol' is not a hex byte" (found writing the MH-Z19B spec as a new user); plot takes its spec with --spec."""
    out = str(tmp_path / "co2.png")
    assert main(["plot", "specs/crsf.yaml", "--field", "co2", "--out", out]) == 1
    assert capsys.readouterr().err.strip() == (
        "serialspec plot: specs/crsf.yaml is a spec, not a capture: give the capture (monitor --save, sim --tap) and"
        " the spec with --spec (serialspec plot CAPTURE --spec specs/crsf.yaml --field NAME --out FILE)"
    )


def test_a_mistyped_command_or_a_missing_direction_says_what_to_type(capsys: pytest.CaptureFixture[str]) -> None:
    """`encode --json '{"command": "rotat"}'` said only "has no request 'rotat'", and a shared-header frame "give the
    direction" without naming the option (found following the README from the wheel)."""
    assert main(["encode", "fashionstar_uart", "--json", '{"command": "rotat", "fields": {}}']) == 1
    assert capsys.readouterr().err.strip() == (
        "serialspec encode: fashionstar_uart has no request 'rotat' (did you mean rotate?)"
    )
    # a PING request that reads as a reply too (error 1, no data); a frame only one direction decodes needs none
    assert main(["decode", "feetech_sms", "ff ff 01 02 01 fb"]) == 1
    assert capsys.readouterr().err.strip() == (
        "serialspec decode: ff ff 01 02 01 fb: give the direction: requests and responses share the header "
        "ff ff (--direction request|response)"
    )
    assert main(["decode", "feetech_sms", "ff ff 01 04 00 09 03 ee"]) == 0
    assert capsys.readouterr().out.startswith("feetech_sms response reply")


@pytest.mark.parametrize("out", [".", "src", "build/out"])
def test_a_reference_links_its_spec_from_wherever_it_is_generated(tmp_path: Path, out: str) -> None:
    """The reference linked its spec as `../../SPEC` wherever it was written: from `generate tinylamp.yaml --out .`
    (the tutorial's), `docs/tinylamp.md` pointed one folder above the project."""
    shutil.copy(ROOT / "examples" / "tinylamp" / "tinylamp.yaml", tmp_path / "tinylamp.yaml")
    assert serialspec("generate", "tinylamp.yaml", "--out", out, cwd=tmp_path).returncode == 0
    page = tmp_path / out / "docs" / "tinylamp.md"
    link = re.search(r"spec: \[`tinylamp\.yaml`\]\(([^)]+)\)", page.read_text(encoding="utf-8"))
    assert link is not None
    assert (page.parent / link[1]).resolve() == (tmp_path / "tinylamp.yaml").resolve()
    if out == "src":  # a project whose packages go to src/: `decode NAME` found no package NAME/ in its folder
        (tmp_path / "pyproject.toml").write_text('[tool.serialspec]\nout = "src"\n', encoding="utf-8")
        decoded = serialspec("decode", "tinylamp", "aa 02 04 01 32 c8 00 ab", "--direction", "request", cwd=tmp_path)
        assert decoded.stdout.startswith("tinylamp request set_brightness"), decoded.stderr


def test_check_without_specs_and_generate_of_a_missing_spec_say_so_and_write_nothing(tmp_path: Path) -> None:
    """In a folder without specs, `check` said `generated/serialspec.schema.json: missing` and sent the user to
    generate; `generate nope.yaml` reported the missing file but still made generated/ with the schema in it."""
    result = serialspec("check", cwd=tmp_path)
    assert result.returncode == 1
    assert result.stderr.splitlines() == [
        "serialspec check: no specs to check in .: name spec files, or list them in pyproject.toml's "
        "[tool.serialspec] specs (default: specs/*.yaml)"
    ]
    result = serialspec("generate", "nope.yaml", cwd=tmp_path)
    assert result.returncode == 1
    assert result.stderr.splitlines() == ["nope.yaml:1:1: no such spec file"]
    assert list(tmp_path.iterdir()) == []


def test_check_of_a_spec_of_ones_own_names_the_generate_that_brings_it_up_to_date(tmp_path: Path) -> None:
    """`check lamp.yaml --out .` sent the user to plain `serialspec generate`, which outside a project writes only a
    schema into generated/ and leaves the check failing: the hint repeats the specs and --out it checked."""
    shutil.copy(ROOT / "examples" / "tinylamp" / "tinylamp.yaml", tmp_path / "my lamp.yaml")
    checked = serialspec("check", "my lamp.yaml", "--out", ".", cwd=tmp_path)
    assert checked.returncode == 1
    hint = checked.stderr.splitlines()[-1]
    assert hint == "run `serialspec generate 'my lamp.yaml' --out .` to bring the generated files up to date"
    assert serialspec("generate", "my lamp.yaml", "--out", ".", cwd=tmp_path).returncode == 0
    assert serialspec("check", "my lamp.yaml", "--out", ".", cwd=tmp_path).returncode == 0


def test_check_of_a_spec_with_a_mistake_says_to_fix_it_before_generating(tmp_path: Path) -> None:
    """With a mistake in the spec, the hint sent the user to `generate`, which refuses the spec just the same."""
    text = (ROOT / "examples" / "tinylamp" / "tinylamp.yaml").read_text(encoding="utf-8")
    (tmp_path / "lamp.yaml").write_text(text.replace("protocol: tinylamp", "protocol: tinylamp\nbogus: 1"), "utf-8")
    checked = serialspec("check", "lamp.yaml", "--out", ".", cwd=tmp_path)
    assert checked.returncode == 1
    lines = checked.stderr.splitlines()
    assert lines[0].startswith("lamp.yaml:5:") and "unknown key 'bogus'" in lines[0]
    assert (
        lines[-1]
        == "fix the mistakes above, then run `serialspec generate lamp.yaml --out .` to bring the generated files "
        "up to date"
    )


def test_an_output_folder_outside_the_project_is_shown_as_it_was_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`check ../lamp.yaml --out ../gen` from a folder beside them listed `/abs/path/gen/tinylamp/codec.py: stale`
    (and a spec.yaml there as an installed package's): the paths are shown as the user named the folder."""
    from serialspec.cli.project import project

    (tmp_path / "work").mkdir()
    monkeypatch.chdir(tmp_path / "work")
    proj = project(None, ["../lamp.yaml"], "../gen")
    assert proj.display(proj.out) == "../gen"
    assert proj.display(proj.out / "tinylamp" / "codec.py") == "../gen/tinylamp/codec.py"
    (proj.out / "tinylamp").mkdir(parents=True)
    (proj.out / "tinylamp" / "__init__.py").touch()
    assert proj.display(proj.out / "tinylamp" / "spec.yaml") == "../gen/tinylamp/spec.yaml"


def test_generate_target_c_out_writes_each_protocol_folder_in_dir(tmp_path: Path) -> None:
    """`generate --target c --out DIR` writes DIR/<protocol>/ (as the Python target writes DIR/<protocol>/), not the
    DIR/c/<protocol>/ the project's generated/ holds beside the Python packages."""
    result = serialspec("generate", "specs/feetech_sms.yaml", "--target", "c", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert sorted(p.name for p in (tmp_path / "feetech_sms").iterdir()) == [
        "README.md",
        "feetech_sms.c",
        "feetech_sms.h",
        "feetech_sms_json.c",
        "feetech_sms_json.h",
        "test",
    ]
    assert sorted(p.name for p in (tmp_path / "feetech_sms" / "test").iterdir()) == ["check_vectors.c", "vectors.h"]
    assert not (tmp_path / "c").exists()


def test_a_spec_the_c_target_cannot_generate_is_refused_in_one_line_naming_the_feature(tmp_path: Path) -> None:
    """A feature the C target does not have (here a signed length element) refuses `generate --target c` with one
    line and nothing written; a run of every target writes the others (tinylamp.yaml's own outputs)."""
    text = (ROOT / "examples" / "tinylamp" / "tinylamp.yaml").read_text(encoding="utf-8")
    signed = text.replace("      role: length\n      type: u8", "      role: length\n      type: i8")
    assert signed != text
    (tmp_path / "lamp.yaml").write_text(signed, encoding="utf-8")
    result = serialspec("generate", "lamp.yaml", "--target", "c", "--out", "out", cwd=tmp_path)
    assert result.returncode == 1
    assert result.stderr.splitlines() == [
        "lamp.yaml:1:1: the c target cannot generate this spec: the request frame: element length of type i8"
    ]
    assert not (tmp_path / "out").exists()
    everything = serialspec("generate", "lamp.yaml", "--out", "all", cwd=tmp_path)
    assert everything.returncode == 0, everything.stderr
    assert (tmp_path / "all" / "tinylamp" / "__init__.py").is_file() and not (tmp_path / "all" / "c").exists()
    # ... and says so, rather than leaving the user to wonder where the C went
    assert everything.stderr.splitlines() == [
        "lamp.yaml: no c output: the request frame: element length of type i8 (the other outputs are written)"
    ]


def camera_spec(folder: Path) -> str:
    """A VISCA-like spec: cameras 0x81..0x87, 0x88 (inside the range) every camera; no `device.ids`."""
    spec = folder / "cam.yaml"
    spec.write_text(
        "protocol: cam\ntitle: Cam\nbyte_order: little\nserial: {baudrate: 9600}\nframing:\n  elements:\n"
        "    camera: {role: address, type: u8, range: [0x81, 0x88], broadcast: 0x88}\n"
        "    code: {role: command, type: u8}\n    content: {role: content}\n    end: {role: trailer, value: FF}\n"
        "commands:\n  home: {code: 4, request: {fields: {}}, response: {fields: {}}}\ndevice: {}\n",
        encoding="utf-8",
    )
    return str(spec)


def test_an_address_outside_its_range_names_a_broadcast_inside_it_no_more(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A broadcast value inside the range was named beside it, "129..136 (or 136)" (found writing Sony VISCA)."""
    assert main(["decode", camera_spec(tmp_path), "90 04 ff", "--direction", "request"]) == 1
    assert capsys.readouterr().err.strip() == (
        "serialspec decode: 90 04 ff: camera = 144 is outside its range 129..136"
    )


def test_sim_without_id_names_the_default_id_not_an_id_typed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`serialspec sim visca.yaml` (an address range 0x81..0x88, no `device.ids`) said "--id 0 is outside the spec's
    id range" of an --id nobody typed (found writing Sony VISCA as a new user)."""
    assert main(["sim", camera_spec(tmp_path)]) == 1
    assert capsys.readouterr().err.strip() == (
        "serialspec sim: no --id given, and the spec's default id 0 (`device.ids`: 0 when not given) is outside its "
        "id range 129..136: give --id N, or `ids: [N]` under `device:`"
    )
