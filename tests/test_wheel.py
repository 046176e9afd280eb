"""The wheel, installed into fresh virtual environments outside the repository, used as a new user would.

The environments are made without pip and get their dependencies from this one (a folder of links to exactly the
packages the distribution declares, on a .pth line), so nothing is downloaded and nothing else is importable: the
repository's sources, tests and generated/ are not on their path.
"""

from __future__ import annotations

import contextlib
import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
import tty
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
TINYLAMP = ROOT / "examples" / "tinylamp" / "tinylamp.yaml"
DIM = "aa 02 04 01 32 c8 00 ab"  # set_brightness lamp 1 to 50 % over 200 ms (the spec's example)
IGNORE = shutil.ignore_patterns(
    ".venv", ".git", "build", "dist", "*.egg-info", "__pycache__", ".*_cache", ".hypothesis"
)


def _link_packages(names: list[str], folder: Path) -> Path:
    """A folder holding links to these importable top-level packages (and modules) of this environment."""
    folder.mkdir()
    for name in names:
        spec = importlib.util.find_spec(name)
        assert spec is not None and spec.origin is not None, name
        source = Path(spec.origin).parent if spec.submodule_search_locations else Path(spec.origin)
        (folder / source.name).symlink_to(source)
    return folder


def _venv(where: Path, deps: Path) -> Path:
    """A fresh environment (no pip, no system packages) whose only extra path is `deps`; returns its python."""
    subprocess.run([sys._base_executable, "-m", "venv", "--without-pip", str(where)], check=True)  # type: ignore[attr-defined]
    python = where / "bin" / "python"
    purelib = subprocess.run(
        [str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    Path(purelib, "deps.pth").write_text(f"{deps}\n", encoding="utf-8")
    return python


def _install(python: Path, wheel: Path) -> None:
    pip = [sys.executable, "-m", "pip", "--python", str(python), "install", "--no-deps", "--no-index", "-q"]
    subprocess.run([*pip, str(wheel)], check=True)


@pytest.fixture(scope="module")
def wheels(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The serialspec and serialspec-runtime wheels, built from a copy of the working tree."""
    tmp = tmp_path_factory.mktemp("wheels")
    source = tmp / "source"
    shutil.copytree(ROOT, source, ignore=IGNORE)
    dist = tmp / "dist"
    build = [sys.executable, "-m", "pip", "wheel", "--no-build-isolation", "--no-deps", "-q", "-w", str(dist)]
    subprocess.run([*build, str(source)], check=True)
    subprocess.run([sys.executable, str(source / "packaging" / "runtime" / "build.py"), str(dist)], check=True)
    return {
        "serialspec": next(dist.glob("serialspec-*.whl")),
        "runtime": next(dist.glob("serialspec_runtime-*.whl")),
    }


class User:
    """A folder of one's own, with the wheel installed in a fresh environment."""

    def __init__(self, home: Path, python: Path) -> None:
        self.home = home
        self.python = python
        self.bin = python.parent

    def run(self, *args: str, stdin: str | None = None, check: bool = True) -> subprocess.CompletedProcess[str]:
        env = {k: v for k, v in os.environ.items() if k not in {"PYTHONPATH", "VIRTUAL_ENV"}}
        env["PATH"] = f"{self.bin}{os.pathsep}{env.get('PATH', '')}"
        result = subprocess.run(args, cwd=self.home, env=env, capture_output=True, text=True, input=stdin)
        if check:
            assert result.returncode == 0, f"{args}: {result.stderr}"
        return result

    def serialspec(self, *args: str, stdin: str | None = None, check: bool = True) -> subprocess.CompletedProcess[str]:
        return self.run(str(self.bin / "serialspec"), *args, stdin=stdin, check=check)

    def python_code(self, code: str) -> str:
        return self.run(str(self.python), "-c", code).stdout


@pytest.fixture(scope="module")
def user(wheels: dict[str, Path], tmp_path_factory: pytest.TempPathFactory) -> User:
    tmp = tmp_path_factory.mktemp("user")
    deps = _link_packages(
        ["yaml", "jinja2", "markupsafe", "construct", "serial", "shtab", "rich", "markdown_it", "mdurl", "pygments"],
        tmp / "deps",
    )
    python = _venv(tmp / "venv", deps)
    _install(python, wheels["serialspec"])
    home = tmp / "home"
    home.mkdir()
    shutil.copy(TINYLAMP, home / "tinylamp.yaml")
    return User(home, python)


def test_version(user: User) -> None:
    from serialspec import __version__

    assert user.serialspec("--version").stdout.strip() == f"serialspec {__version__}"


def test_decode_and_encode_with_a_spec_never_generated(user: User) -> None:
    assert not (user.home / "generated").exists()
    decoded = json.loads(user.serialspec("decode", "tinylamp.yaml", DIM, "--json").stdout)
    assert decoded["fields"] == {"lamp_id": 1, "brightness": 50, "fade": 200}
    assert user.serialspec("encode", "tinylamp.yaml", "--json", json.dumps(decoded)).stdout.strip() == DIM
    piped = user.serialspec("decode", "tinylamp.yaml", "-", "--units", stdin=f"{DIM}\n")
    assert "50 %" in piped.stdout and "200 ms" in piped.stdout


def test_generate_with_out_then_import_without_the_generator(user: User) -> None:
    user.serialspec("generate", "tinylamp.yaml", "--out", "lamps")
    assert (user.home / "lamps" / "tinylamp" / "__init__.py").is_file()
    assert (user.home / "lamps" / "docs" / "tinylamp.md").is_file()
    assert user.serialspec("check", "tinylamp.yaml", "--out", "lamps").returncode == 0
    loaded = user.python_code(
        "import sys; sys.path.insert(0, 'lamps'); import tinylamp, tinylamp.client, tinylamp.simulator\n"
        "m = tinylamp.decode(bytes.fromhex('" + DIM.replace(" ", "") + "'))\n"
        "print(m.brightness, sorted(n for n in ('jinja2', 'yaml', 'construct') if n in sys.modules))"
    )
    assert loaded.split() == ["50", "[]"]


def test_an_edited_spec_takes_effect_without_regenerating(user: User) -> None:
    spec = user.home / "edited.yaml"
    spec.write_text(TINYLAMP.read_text(encoding="utf-8"), encoding="utf-8")
    user.serialspec("generate", "edited.yaml", "--out", "edited")
    too_bright = json.dumps({"command": "set_brightness", "fields": {"lamp_id": 1, "brightness": 110, "fade": 0}})
    refused = user.serialspec("encode", "edited.yaml", "--json", too_bright, check=False)
    assert refused.returncode == 1 and "brightness = 110 is outside its range 0..100" in refused.stderr
    spec.write_text(spec.read_text(encoding="utf-8").replace("range: [0, 100]", "range: [0, 200]"), encoding="utf-8")
    assert user.serialspec("encode", "edited.yaml", "--json", too_bright).stdout.strip().startswith("aa 02 04 01 6e")
    stale = user.serialspec("check", "edited.yaml", "--out", "edited", check=False)
    assert stale.returncode == 1 and "edited/tinylamp/messages.py: stale" in stale.stderr


def test_a_renamed_protocol_leaves_no_orphans(user: User) -> None:
    spec = user.home / "renamed.yaml"
    spec.write_text(TINYLAMP.read_text(encoding="utf-8"), encoding="utf-8")
    user.serialspec("generate", "renamed.yaml", "--out", "renamed")
    assert (user.home / "renamed" / "c" / "tinylamp" / "test" / "vectors.h").is_file()
    (user.home / "renamed" / "notes.txt").write_text("mine\n", encoding="utf-8")
    spec.write_text(spec.read_text(encoding="utf-8").replace("protocol: tinylamp", "protocol: bigger_lamp"))
    orphaned = user.serialspec("check", "renamed.yaml", "--out", "renamed", check=False)
    assert orphaned.returncode == 1 and "renamed/tinylamp/codec.py: orphaned" in orphaned.stderr
    user.serialspec("generate", "renamed.yaml", "--out", "renamed")
    assert not (user.home / "renamed" / "tinylamp").exists()
    assert not (user.home / "renamed" / "c" / "tinylamp").exists()  # its C, the test/ folder included
    assert (user.home / "renamed" / "bigger_lamp" / "codec.py").is_file()
    assert (user.home / "renamed" / "notes.txt").is_file()  # not generated: left alone
    assert user.serialspec("check", "renamed.yaml", "--out", "renamed").returncode == 0


def test_a_project_table_in_pyproject_sets_specs_and_output(user: User) -> None:
    project = user.home / "robot"
    (project / "protocols").mkdir(parents=True)
    shutil.copy(TINYLAMP, project / "protocols" / "tinylamp.yaml")
    (project / "pyproject.toml").write_text(
        '[project]\nname = "robot"\n\n[tool.serialspec]\nspecs = ["protocols/*.yaml"]\nout = "src"\n', encoding="utf-8"
    )
    robot = User(project / "protocols", user.python)  # run from a sub-folder: the project is found upwards
    robot.serialspec("generate")
    assert (project / "src" / "tinylamp" / "codec.py").is_file() and (
        project / "src" / "docs" / "tinylamp.md"
    ).is_file()
    assert (project / "src" / "c" / "tinylamp" / "tinylamp.h").is_file()  # the C target, beside the package
    assert robot.serialspec("check").stdout.startswith("19 generated files match")
    (project / "src" / "tinylamp" / "codec.py").write_text("edited\n", encoding="utf-8")
    stale = robot.serialspec("check", check=False)
    assert stale.returncode == 1 and "src/tinylamp/codec.py: stale" in stale.stderr


def test_a_shipped_protocol_decodes_by_name(user: User) -> None:
    result = user.serialspec("decode", "feetech_sms", "ff ff 01 02 01 fb", "--direction", "request", "--json")
    assert json.loads(result.stdout)["command"] == "ping"
    missing = user.serialspec("decode", "no_such_protocol", "00", check=False)
    assert (
        missing.returncode == 1
        and "no such spec file, nor a protocol package no_such_protocol/ in this folder, the project's output folder "
        "or installed"
        in missing.stderr
    )


@contextlib.contextmanager
def serving(user: User, *arguments: str) -> Iterator[str]:
    """`serialspec sim ARGUMENTS` of the installed wheel, yielding the port it prints, stopped after the block."""
    process = subprocess.Popen(
        [str(user.bin / "serialspec"), "sim", *arguments],
        cwd=user.home,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert process.stdout is not None
        yield process.stdout.readline().strip()
    finally:
        process.send_signal(signal.SIGTERM)
        assert process.wait(5) == 0


@pytest.fixture
def sim(user: User) -> Iterator[tuple[str, Path]]:
    tap = user.home / "session.capture"
    with serving(user, "tinylamp.yaml", "--id", "1", "--tap", str(tap)) as port:
        yield port, tap


def test_sim_with_a_client_and_its_tap_replays(user: User, sim: tuple[str, Path]) -> None:
    port, tap = sim
    user.serialspec("generate", "tinylamp.yaml", "--out", "lamps")
    printed = user.python_code(
        "import sys; sys.path.insert(0, 'lamps')\n"
        "from tinylamp.client import TinylampClient\n"
        f"with TinylampClient({port!r}) as lamps:\n"
        "    print(lamps.ping(1), lamps.ping(2))\n"
        "    lamps.set_brightness(1, 80, 0)\n"
        "    print(lamps.read_brightness(1))\n"
    )
    assert printed.split() == ["True", "False", "80"]
    replayed = user.serialspec("decode", "tinylamp.yaml", "--file", str(tap), "--json")
    seen = [(o["direction"], o["command"]) for o in map(json.loads, replayed.stdout.splitlines())]
    assert seen == [
        ("request", "ping"),
        ("response", "ping"),
        ("request", "ping"),
        ("request", "set_brightness"),
        ("response", "set_brightness"),
        ("request", "read_brightness"),
        ("response", "read_brightness"),
    ]


def test_watch_export_and_the_dissector_from_the_wheel(user: User, sim: tuple[str, Path]) -> None:
    port, tap = sim
    user.serialspec("generate", "tinylamp.yaml", "--out", "lamps2")
    user.python_code(
        "import sys; sys.path.insert(0, 'lamps2')\n"
        "from tinylamp.client import TinylampClient\n"
        f"with TinylampClient({port!r}) as lamps:\n"
        "    lamps.set_brightness(1, 80, 0)\n"
    )
    # not on a terminal: watch prints its table once, when it stops
    table = user.serialspec("watch", "tinylamp.yaml", "--tap", str(tap), "--duration", "1").stdout
    assert any("set_brightness" in line and "80 %" in line for line in table.splitlines()), table
    user.serialspec("generate", "tinylamp.yaml", "--target", "wireshark", "--out", "dissectors")
    assert sorted(p.name for p in (user.home / "dissectors").rglob("*") if p.is_file()) == ["tinylamp.lua"]
    user.serialspec("export", str(tap), "--pcap", "session.pcap")
    assert (user.home / "session.pcap").read_bytes()[20:24] == (147).to_bytes(4, "little")  # DLT_USER0
    shipped = user.python_code(
        "import importlib.resources; print((importlib.resources.files('feetech_sms') / 'feetech_sms.lua').is_file())"
    )
    assert shipped.strip() == "True"
    tshark = shutil.which("tshark")
    if tshark is not None:
        lua = f"lua_script:{user.home / 'dissectors' / 'tinylamp' / 'tinylamp.lua'}"
        shown = user.run(tshark, "-X", lua, "-r", "session.pcap", "-T", "fields", "-e", "tinylamp.command").stdout
        assert "set_brightness" in shown.split()


def test_sim_refuses_an_id_outside_the_spec(user: User) -> None:
    refused = user.serialspec("sim", "tinylamp.yaml", "--id", "300", check=False)
    assert refused.returncode == 1 and "--id 300 is outside the spec's id range 0..254" in refused.stderr


def test_a_capture_saved_by_monitor_replays_through_decode(user: User) -> None:
    controller, device = os.openpty()
    tty.setraw(device)
    tty.setraw(controller)
    try:
        monitor = subprocess.Popen(
            [str(user.bin / "serialspec"), "monitor", "tinylamp.yaml", "--port", os.ttyname(device)]
            + ["--save", "monitor.capture", "--count", "2"],
            cwd=user.home,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert monitor.stderr is not None
        assert "Ctrl-C to stop" in monitor.stderr.readline()  # the port is open
        os.write(controller, bytes.fromhex(DIM.replace(" ", "") + "bb010101be"))
        out, err = monitor.communicate(timeout=10)
    finally:
        os.close(controller)
        os.close(device)
    assert monitor.returncode == 0, err
    assert [line.split()[1:3] for line in out.splitlines()] == [["request", "set_brightness"], ["response", "ping"]]
    replayed = user.serialspec("decode", "tinylamp.yaml", "--file", "monitor.capture")
    assert "tinylamp request set_brightness" in replayed.stdout and "tinylamp response ping" in replayed.stdout


def test_the_tools_work_from_the_wheel(user: User) -> None:
    """scan and replay against a shipped protocol's sim, completion, and the license in the wheel's metadata."""
    tap = user.home / "scan.capture"
    with serving(user, "feetech_sms", "--id", "3", "--quiet", "--tap", str(tap)) as port:
        found = user.serialspec("scan", "feetech_sms", "--port", port, "--ids", "1-4", "--json")
        replayed = user.serialspec("replay", str(tap), "--port", port, "--speed", "0")
    assert [json.loads(line) for line in found.stdout.splitlines()] == [
        {"id": 3, "baudrate": 1000000, "model": "sts3215"}
    ]
    assert replayed.stderr.startswith("serialspec replay: 5 request chunk(s), 32 byte(s) sent to ")
    assert "_shtab_serialspec" in user.serialspec("completion", "bash").stdout
    metadata = user.python_code(
        "from importlib.metadata import distribution; d = distribution('serialspec'); "
        "print(d.metadata['License-Expression']); print(any(f.name == 'LICENSE' for f in d.files))"
    )
    assert metadata.split() == ["MIT", "True"]


def test_generated_code_runs_on_the_runtime_alone(
    wheels: dict[str, Path], user: User, tmp_path_factory: pytest.TempPathFactory
) -> None:
    tmp = tmp_path_factory.mktemp("robot")
    python = _venv(tmp / "venv", _link_packages(["serial"], tmp / "deps"))
    _install(python, wheels["runtime"])
    user.serialspec("generate", "tinylamp.yaml", "--out", "lamps")
    robot = User(user.home, python)
    printed = robot.python_code(
        "import sys; sys.path.insert(0, 'lamps')\n"
        "import tinylamp, tinylamp.aio, tinylamp.client, tinylamp.simulator\n"
        "frame = tinylamp.encode(tinylamp.SetBrightnessRequest(lamp_id=1, brightness=50, fade=200))\n"
        "print(frame.hex(' '), 'serialspec.lang' in sys.modules)\n"
        "try:\n    import yaml\nexcept ImportError:\n    print('no yaml')\n"
    )
    assert printed.splitlines() == [f"{DIM} False", "no yaml"]


def _distribution_packages(name: str, metadata_into: Path) -> list[str]:
    """The top-level packages and modules of a distribution and of everything it requires (markers for no extra);
    their metadata (entry points: mkdocs finds its themes by them) linked into `metadata_into`."""
    from importlib import metadata

    from packaging.requirements import Requirement

    found: set[str] = set()
    seen: set[str] = set()
    todo = [name]
    while todo:
        wanted = todo.pop()
        if wanted.lower() in seen:
            continue
        seen.add(wanted.lower())
        try:
            dist = metadata.distribution(wanted)
        except metadata.PackageNotFoundError:
            continue
        for file in dist.files or []:
            top = file.parts[0]
            if top.endswith(".dist-info"):
                if not (metadata_into / top).exists():
                    (metadata_into / top).symlink_to(Path(str(dist.locate_file(top))))
            elif len(file.parts) > 1 and not top.endswith(".data") and top not in ("..", "__pycache__"):
                found.add(top)
            elif len(file.parts) == 1 and top.endswith(".py"):
                found.add(top.removesuffix(".py"))
        for text in dist.requires or []:
            requirement = Requirement(text)
            if requirement.marker is None or requirement.marker.evaluate({"extra": ""}):
                todo.append(requirement.name)
    # a folder of shared libraries (`numpy.libs`) is no module, but it is kept: the packages beside it load from it
    return sorted(n for n in found if not n.isidentifier() or importlib.util.find_spec(n) is not None)


def _chromium() -> str | None:
    return shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")


def test_a_docs_site_of_ones_own_spec_with_the_docs_extra(
    wheels: dict[str, Path], user: User, tmp_path_factory: pytest.TempPathFactory
) -> None:
    """`serialspec docs` from the wheel with mkdocs beside it (serialspec[docs]): the reference of one's own spec
    and of a shipped protocol, the spec linked, and a search that works when the site is opened from disk."""
    tmp = tmp_path_factory.mktemp("writer")
    (tmp / "metadata").mkdir()
    packages = _distribution_packages("mkdocs", tmp / "metadata")
    deps = _link_packages(sorted({"yaml", "jinja2", "markupsafe", "construct", "serial", *packages}), tmp / "deps")
    for info in (tmp / "metadata").iterdir():
        (deps / info.name).symlink_to(info.resolve())
    writer = User(user.home, _venv(tmp / "venv", deps))
    _install(writer.python, wheels["serialspec"])
    built = writer.serialspec("docs", "tinylamp.yaml", "vesc", "--out", "site", "--title", "My devices").stdout
    assert built.splitlines() == [
        "serialspec docs: 2 protocol(s) in site: open site/index.html",
        "(search works from disk too; to serve the site instead: python -m http.server -d site)",
    ]
    site = user.home / "site"
    index = (site / "index.html").read_text(encoding="utf-8")
    assert "My devices" in index and 'href="protocols/tinylamp.html"' in index and 'href="specs/vesc.yaml"' in index
    page = (site / "protocols" / "tinylamp.html").read_text(encoding="utf-8")
    assert 'href="../specs/tinylamp.yaml"' in page and "set_brightness" in page
    assert (site / "specs" / "tinylamp.yaml").read_text(encoding="utf-8") == (user.home / "tinylamp.yaml").read_text()
    assert "set_brightness" in (site / "search" / "search_index.js").read_text(encoding="utf-8")
    browser = _chromium()
    if browser is None:
        pytest.skip("no Chromium to open the site from disk (apt-get install chromium)")
    dom = subprocess.run(
        [
            browser,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--disable-background-networking",
            "--virtual-time-budget=5000",
            "--dump-dom",
            (site / "search.html").as_uri() + "?q=brightness+fade",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    ).stdout
    results = dom.split('id="mkdocs-search-results"')[1]
    assert '<a href="./protocols/tinylamp.html#set_brightness-0x02">set_brightness (0x02)</a>' in results, results[
        :2000
    ]


def test_docs_without_mkdocs_says_how_to_install_it(user: User) -> None:
    result = user.serialspec("docs", "tinylamp.yaml", "--out", "site", check=False)
    assert (result.returncode, result.stdout) == (1, "")
    assert (
        result.stderr
        == "serialspec docs: the docs site needs mkdocs, an optional extra: pip install 'serialspec[docs]'\n"
    )


def test_the_readme_tools_run_as_printed_from_the_wheel(
    wheels: dict[str, Path], user: User, tmp_path_factory: pytest.TempPathFactory
) -> None:
    """Each command of the README's Tools section that needs no bus, run as printed from the wheel with both extras
    (serialspec[docs,plot]) in a folder outside the repository that holds the files it names: the same output."""
    import re
    import shlex

    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme[readme.index("## Tools") :]
    section = section[: section.index("\n## ", 1)]
    commands: list[tuple[str, list[str]]] = []
    for block in re.findall(r"```console\n(.*?)```", section, flags=re.S):
        for line in block.splitlines():
            if line.startswith("$ "):
                commands.append((line[2:], []))
            elif commands:
                commands[-1][1].append(line)
    commands += [
        (line, []) for block in re.findall(r"```sh\n(.*?)```", section, flags=re.S) for line in block.splitlines()
    ]
    tmp = tmp_path_factory.mktemp("tools")
    (tmp / "metadata").mkdir()
    packages = {
        *_distribution_packages("mkdocs", tmp / "metadata"),
        *_distribution_packages("matplotlib", tmp / "metadata"),
    }
    deps = tmp / "deps"
    deps.mkdir()
    site = Path(importlib.util.find_spec("serial").origin).parent.parent  # type: ignore[arg-type,union-attr]
    for name in sorted({"yaml", "jinja2", "markupsafe", "construct", "serial", "shtab", "rich", *packages}):
        source = next((p for p in (site / name, site / f"{name}.py") if p.exists()), None)
        if source is not None:
            (deps / source.name).symlink_to(source)
    for info in (tmp / "metadata").iterdir():
        (deps / info.name).symlink_to(info.resolve())
    home = tmp / "home"
    home.mkdir()
    tools = User(home, _venv(tmp / "venv", deps))
    _install(tools.python, wheels["serialspec"])
    ran = []
    for command, printed in commands:
        words = shlex.split(command)
        if words[0] != ".venv/bin/serialspec" or words[1] in ("scan", "replay", "watch", "completion"):
            continue  # on a bus (tests/test_tools.py, test_watch.py, and above from the wheel), or an install step
        for word in words[2:]:
            # the captures and spec of one's own that the command names; never specs/: the wheel ships those
            if word.startswith("examples/") and (ROOT / word).is_file() and not (home / word).exists():
                (home / word).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy(ROOT / word, home / word)
        result = tools.serialspec(*words[1:])
        assert "Traceback" not in result.stderr, result.stderr
        if printed:
            assert (result.stdout + result.stderr).splitlines() == printed, command
        ran.append(words[1])
    assert sorted(ran) == ["docs", "export", "generate", "plot"]
    assert (home / "build" / "angle.png").read_bytes().startswith(b"\x89PNG")
    assert (home / "build" / "wireshark" / "fashionstar_uart" / "fashionstar_uart.lua").is_file()
