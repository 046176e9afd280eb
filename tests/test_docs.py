"""The README's and the tutorial's commands run as printed and print what the pages say they print."""

from __future__ import annotations

import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
TUTORIAL = ROOT / "docs" / "tutorial.md"
TINYLAMP = ROOT / "examples" / "tinylamp" / "tinylamp.yaml"
PRINTED_PORT = "/dev/pts/5"
# run until stopped: their sessions are checked below, in test_readme.py and test_watch.py (watch, in tmux)
SERVERS = ("sim", "monitor", "watch")
ON_A_BUS = ("scan", "replay")  # need the README session's port: tests/test_tools.py runs them against a sim


def blocks(page: Path, language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", page.read_text(encoding="utf-8"), flags=re.S)


def commands(page: Path) -> list[tuple[str, list[str]]]:
    """Every `$ command` of the page's console blocks with the lines printed after it."""
    found: list[tuple[str, list[str]]] = []
    for block in blocks(page, "console"):
        current: list[tuple[str, list[str]]] = []
        for line in block.splitlines():
            if line.startswith("$ "):
                current.append((line[2:], []))
            elif current:
                current[-1][1].append(line)
        found += current
    return found


def run(command: str, cwd: Path) -> list[str]:
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}")
    result = subprocess.run(shlex.split(command), cwd=cwd, env=env, capture_output=True, text=True)
    assert "Traceback" not in result.stderr, result.stderr
    return (result.stdout + result.stderr).splitlines()


def check_page(page: Path, cwd: Path) -> int:
    ran = 0
    for command, printed in commands(page):
        program = shlex.split(command)
        if program[1] in SERVERS + ON_A_BUS:
            continue
        assert run(command, cwd) == printed, command
        ran += 1
    return ran


def test_the_readme_commands_print_what_the_readme_shows() -> None:
    assert check_page(ROOT / "README.md", ROOT) >= 4
    for command, _ in commands(ROOT / "README.md"):
        assert command.startswith(".venv/bin/serialspec "), "README commands work right after `make generate`"


def test_the_readme_command_example_and_its_mistake_give_what_the_readme_shows(tmp_path: Path) -> None:
    """The README's new command, added at the end of `commands:`, generates; with `power: int17` it gives the
    README's one-line error, at the line and column the README prints."""
    command = blocks(ROOT / "README.md", "yaml")[0]
    assert command.startswith("commands:\n")
    shutil.copytree(ROOT / "specs", tmp_path / "specs")
    spec = tmp_path / "specs" / "fashionstar_uart.yaml"
    text = spec.read_text(encoding="utf-8")
    spec.write_text(text.replace("\nexamples:\n", "\n" + command.removeprefix("commands:\n") + "examples:\n"))
    run(f"serialspec generate {spec} --out {tmp_path / 'out'}", tmp_path)
    assert "class ReadAnglePowerResponse(" in (tmp_path / "out" / "fashionstar_uart" / "messages.py").read_text()
    spec.write_text(
        spec.read_text(encoding="utf-8").replace(
            "power: {type: u16, unit: mW, description: Power now.}", "power: int17"
        )
    )
    printed = [block for block in blocks(ROOT / "README.md", "console") if "int17" in block]
    assert run("serialspec check specs/fashionstar_uart.yaml", tmp_path) == printed[0].splitlines()


def test_every_yaml_block_of_the_tutorial_is_part_of_its_spec() -> None:
    spec = TINYLAMP.read_text(encoding="utf-8")
    text_spec = (ROOT / "specs" / "nmea0183.yaml").read_text(encoding="utf-8")  # the text-protocol section's
    answering = (ROOT / "examples" / "textlamp" / "textlamp.yaml").read_text(encoding="utf-8")
    grbl = (ROOT / "examples" / "grbl" / "grbl.yaml").read_text(encoding="utf-8")  # a message's own text layout
    lss = (ROOT / "tests" / "specs" / "lynxmotion_lss.yaml").read_text(encoding="utf-8")  # an address, glued values
    yaml_blocks = blocks(TUTORIAL, "yaml")
    assert len(yaml_blocks) >= 6
    for block in yaml_blocks:
        assert any(block in text for text in (spec, text_spec, answering, grbl, lss)), block[:60]


def test_the_tutorial_commands_and_client_session_run_as_printed(tmp_path: Path) -> None:
    shutil.copy(TINYLAMP, tmp_path / "tinylamp.yaml")
    assert check_page(TUTORIAL, tmp_path) >= 5
    sim = next(c for c, _ in commands(TUTORIAL) if shlex.split(c)[1] == "sim")
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}")
    process = subprocess.Popen(
        shlex.split(sim), cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        assert process.stdout is not None
        port = process.stdout.readline().strip()
        session = next(b for b in blocks(TUTORIAL, "python") if PRINTED_PORT in b)
        result = subprocess.run(
            [sys.executable, "-c", session.replace(PRINTED_PORT, port)], cwd=tmp_path, capture_output=True, text=True
        )
    finally:
        process.send_signal(signal.SIGTERM)
        process.wait(5)
    assert result.stdout.splitlines() == ["True False", "80"]
    assert "RangeError: set_brightness request: brightness = 300 is outside its range 0..100" in result.stderr
    replay = run(f"serialspec decode tinylamp.yaml --file {tmp_path / 'session.capture'}", tmp_path)
    assert sum("tinylamp response" in line for line in replay) == 3
    # the spec's editor line names the schema the tutorial's `generate --out .` wrote beside it, as step 1 says
    schema = re.search(r"\$schema=(\S+)", (tmp_path / "tinylamp.yaml").read_text(encoding="utf-8"))
    assert schema is not None and f"$schema={schema[1]}`" in TUTORIAL.read_text(encoding="utf-8")
    assert (tmp_path / schema[1]).is_file()


@pytest.mark.parametrize("page", ["README.md", "docs/tutorial.md"])
def test_the_pages_link_only_to_files_that_exist(page: str) -> None:
    path = ROOT / page
    for target in re.findall(r"\]\(([^)#:]+)(?:#[^)]*)?\)", path.read_text(encoding="utf-8")):
        assert (path.parent / target).exists(), target


def test_the_documentation_site_builds_strictly(tmp_path: Path) -> None:
    # mkdocs in strict mode: a broken link or anchor fails the build (tools/docsite.py; `make docs`)
    result = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "docsite.py"), str(tmp_path / "site")], capture_output=True, text=True
    )
    assert result.returncode == 0, result.stderr
    built = {p.relative_to(tmp_path / "site").as_posix() for p in (tmp_path / "site").rglob("*.html")}
    assert {"index.html", "tutorial.html", "language.html", "protocols/feetech_sms.html"} <= built
    index = (tmp_path / "site" / "index.html").read_text(encoding="utf-8")
    assert 'href="protocols/feetech_sms.html"' in index and 'href="tutorial.html"' in index
    # serialspec's site builder (serialspec/docsite.py, as `serialspec docs`): its search works from disk too
    assert "serialspecSearchIndex" in (tmp_path / "site" / "search" / "search_index.js").read_text(encoding="utf-8")
    assert "serialspec: search that works from disk" in (tmp_path / "site" / "search" / "main.js").read_text()
    assert (tmp_path / "site" / "docs" / "plot-example.png").is_file()  # the README's picture


@pytest.mark.parametrize("spec", sorted((ROOT / "specs").glob("*.yaml")), ids=lambda p: p.stem)
def test_example_breakdowns_show_values_as_people_write_them(spec: Path) -> None:
    """A bit-field status in an example's breakdown reads `alert=0, number=0`, coils `[1; 0; 1]`: never Python's repr,
    and a protocol without errata says so under its Errata heading."""
    from serialspec.backends.markdown.docs import emit_docs
    from serialspec.lang import load_protocol

    docs = emit_docs(load_protocol(str(spec), spec.name))
    assert not re.findall(r"\{'|\['|<[A-Z]\w+\.|\[(?:True|False);", docs)
    errata = docs.split("\n## Errata\n")[1]
    assert errata.strip() and ("### " in errata or "None recorded" in errata)


def test_an_example_calls_a_constant_a_selector_only_where_it_picks_the_message() -> None:
    """Every constant field was shown as `(selector)`: MH-Z19B's reserved zeros, DYNAMIXEL CLEAR's magic key. A
    sub-command's selector (RRC) and the first field of commands sharing a code (RTCM 3's number) still are."""
    from serialspec.backends.markdown.docs import emit_docs
    from serialspec.lang import load_protocol

    dynamixel = emit_docs(load_protocol(str(ROOT / "specs" / "dynamixel_p2.yaml"), "dynamixel_p2.yaml"))
    assert "| `44 58 4C 22` | key | 0x224c5844 (constant) |" in dynamixel
    rrc = emit_docs(load_protocol(str(ROOT / "specs" / "hiwonder_rrc.yaml"), "hiwonder_rrc.yaml"))
    assert "(selector)" in rrc and "(constant)" not in rrc
    rtcm = emit_docs(load_protocol(str(ROOT / "tests" / "specs" / "rtcm3.yaml"), "rtcm3.yaml"))
    assert "(selector)" in rtcm


def test_a_field_of_whole_bytes_in_a_bit_width_shows_its_bytes_alone(tmp_path: Path) -> None:
    """MH-Z19B's five reserved zeros as one `u40` showed `3..7 (bits 0..39 of 3..7)`; a narrower field still shows
    its bits (found writing the MH-Z19B spec as a new user)."""
    from serialspec.backends.markdown.docs import emit_docs
    from serialspec.lang import load_protocol

    spec = tmp_path / "five.yaml"
    spec.write_text(
        "protocol: five\ntitle: Five\nbyte_order: big\nserial: {baudrate: 9600}\nframing:\n  elements:\n"
        "    start: {role: header, value: FF}\n    command: {role: command, type: u8}\n    data: {role: content}\n"
        "commands:\n  read:\n    code: 0x86\n    request:\n      fields:\n"
        "        reserved: {type: u40, const: 0}\n        high: u4\n        low: u4\n",
        encoding="utf-8",
    )
    docs = emit_docs(load_protocol(str(spec), "five.yaml"))
    assert "| 2..6 | reserved | u40 |" in docs
    assert "| 7 (bits 4..7 of 7) | high | u4 |" in docs or "| 7 (bits 0..3 of 7) | high | u4 |" in docs


@pytest.mark.parametrize("spec", [*sorted((ROOT / "specs").glob("*.yaml")), TINYLAMP], ids=lambda p: p.stem)
def test_a_reference_has_no_empty_code_span_column_or_section(spec: Path, tmp_path: Path) -> None:
    """Empty byte fields rendered as a literal `` (6 places); a spec of one's own got an empty 中文 column, a stray
    `55 AA —` for a header without a description, and an Examples heading over nothing."""
    from serialspec.backends.markdown.docs import emit_docs
    from serialspec.lang import load_protocol

    text = spec.read_text(encoding="utf-8")
    if spec == TINYLAMP:  # the tutorial's spec, without the header's description (as a first spec often is)
        text = text.replace("      description: Frame start; tells requests from responses.\n", "")
        assert "Frame start" not in text
    (tmp_path / spec.name).write_text(text, encoding="utf-8")
    protocol = load_protocol(str(tmp_path / spec.name), spec.name)
    docs = emit_docs(protocol)
    assert not re.findall(r"(?:^|\|)\s*``\s*(?:\||$)", docs, re.M)  # a cell (or line) of an empty code span
    assert not re.findall(r"[0-9A-F]{2} — \|", docs)
    index = docs.split("\n## Command index\n")[1].split("\n## ")[0]
    titles_cn = any(c.title_cn or any(s.title_cn for s in c.subcommands) for c in protocol.commands)
    assert ("中文" in index) == titles_cn
    examples = docs.split("\n## Examples\n")[1].split("\n## ")[0]
    assert ("### " in examples) == bool(protocol.examples or (protocol.text and protocol.text.examples))
    assert "### " in examples or "None recorded" in examples


@pytest.mark.parametrize("spec", sorted((ROOT / "specs").glob("*.yaml")), ids=lambda p: p.stem)
def test_frame_layout_states_the_gap_once(spec: Path) -> None:
    """A protocol with a silence between frames says so once in its frame layout section, not in the spec's
    description and again in the template's sentence."""
    from serialspec.backends.markdown.docs import emit_docs
    from serialspec.lang import load_protocol

    protocol = load_protocol(str(spec), spec.name)
    section = emit_docs(protocol).split("\n## Frame layout\n")[1].split("\n## ")[0]
    assert section.count("character times") == (1 if protocol.framing.gap else 0)


@pytest.mark.parametrize("spec", sorted((ROOT / "specs").glob("*.yaml")), ids=lambda p: p.stem)
def test_a_one_byte_checksum_has_no_byte_order(spec: Path) -> None:
    """A frame table gives a checksum's byte order only where it has two bytes or more (an LRC or a CRC-8 has none)."""
    for line in (ROOT / "generated" / "docs" / f"{spec.stem}.md").read_text(encoding="utf-8").splitlines():
        if line.startswith("| last |") and "| u8 |" in line:
            assert "endian" not in line, line


@pytest.mark.parametrize("spec", sorted((ROOT / "specs").glob("*.yaml")), ids=lambda p: p.stem)
def test_published_reference_cites_only_what_readers_can_find(spec: Path) -> None:
    """No internal note, local file name, issue number or this repository's test files in a published reference:
    sources are named as their publishers name them."""
    from serialspec.backends.markdown.docs import emit_docs
    from serialspec.lang import load_protocol

    docs = emit_docs(load_protocol(str(spec), spec.name))
    assert not re.findall(r"design-notes|protocol-docs/|\.txt\b|\bissue \d|tests/|test_\w+\.py", docs)


def test_the_schema_the_tutorial_spec_names_is_there_from_step_1(tmp_path: Path) -> None:
    """The tutorial's `$schema=serialspec.schema.json` pointed at nothing until `generate` in step 5: step 1 writes it
    with its own command, run here in a folder holding the spec alone."""
    step1 = TUTORIAL.read_text(encoding="utf-8").split("\n## 2.")[0]
    schema = re.search(r"\$schema=(\S+?)`", step1)
    assert schema is not None
    shutil.copy(TINYLAMP, tmp_path / "tinylamp.yaml")
    ran = [(command, printed) for command, printed in commands(TUTORIAL) if f"$ {command}" in step1]
    assert ran
    for command, printed in ran:
        assert run(command, tmp_path) == printed
    assert (tmp_path / schema[1]).is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([schema[1], "tinylamp.yaml"])


def test_every_verb_that_takes_a_spec_says_a_package_name_works_too() -> None:
    """`encode --help` said "the protocol's spec file", though every verb but generate and check takes a generated
    package's name as well."""
    import contextlib
    import io

    from serialspec.cli import main

    for verb in ("decode", "encode", "sim", "monitor"):
        out = io.StringIO()
        with contextlib.redirect_stdout(out), pytest.raises(SystemExit):
            main([verb, "--help"])
        text = " ".join(out.getvalue().split())
        assert "or a generated protocol package's name" in text, verb


def test_the_site_takes_a_link_to_a_folder_as_its_readme(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A link to a folder (GitHub shows its README) made the site's build stop with IsADirectoryError (copied as a
    file); now it links the folder's README, and a folder without one is left to mkdocs' strict check."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("docsite_tool", ROOT / "tools" / "docsite.py")
    assert spec is not None and spec.loader is not None
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    (tmp_path / "examples").mkdir()
    (tmp_path / "examples" / "README.md").write_text("# Examples\n", encoding="utf-8")
    (tmp_path / "specs").mkdir()
    (tmp_path / "README.md").write_text("[the examples](examples/) and [the specs](specs/)\n", encoding="utf-8")
    monkeypatch.setattr(tool, "ROOT", tmp_path)
    texts, files = tool.relinked({"README.md": "index.md"})
    assert texts["index.md"] == "[the examples](examples/README.md) and [the specs](specs/)\n"
    assert files == {"examples/README.md": tmp_path / "examples" / "README.md"}
