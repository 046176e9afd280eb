"""The shipped protocol packages live under one namespace (serialspec_protocols.<protocol>); their old top-level
names still import, for one release, as aliases that warn; a user's project can put its own packages in a namespace
the same way ([tool.serialspec] namespace / old_names)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from conftest import PACKAGES, ROOT, SHIPPED

TINYLAMP = ROOT / "examples" / "tinylamp" / "tinylamp.yaml"
PATH = os.pathsep.join([str(ROOT / "generator"), str(ROOT / "generated")])


def python(code: str, *options: str, cwd: Path = ROOT) -> subprocess.CompletedProcess[str]:
    """A fresh interpreter (nothing imported yet) with the repository's sources on its path."""
    env = {**os.environ, "PYTHONPATH": PATH}
    return subprocess.run([sys.executable, *options, "-c", code], capture_output=True, text=True, cwd=cwd, env=env)


def test_every_shipped_protocol_is_in_the_namespace_and_the_old_ones_have_their_old_names() -> None:
    shipped = sorted(p.name for p in PACKAGES.iterdir() if (p / "__init__.py").is_file())
    assert shipped == sorted(p.stem for p in (ROOT / "specs").glob("*.yaml"))
    assert not (PACKAGES / "__init__.py").exists()  # a namespace package: other distributions may add protocols
    old = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["serialspec"]["old_names"]
    assert set(old) < set(shipped)
    for name in shipped:
        alias = ROOT / "generated" / name / "__init__.py"
        assert alias.is_file() == (name in old), name  # protocols new in the namespace get no alias
        if name in old:
            assert f'moved(__name__, "{SHIPPED}.{name}")' in alias.read_text(encoding="utf-8")
            assert sorted(p.name for p in alias.parent.iterdir() if p.name != "__pycache__") == ["__init__.py"]


@pytest.mark.parametrize("statement", ["import vesc", "from vesc import encode", "import vesc.codec"])
def test_an_old_name_warns_with_the_new_one(statement: str) -> None:
    result = python(statement, "-W", "error::DeprecationWarning")
    assert result.returncode == 1
    assert "DeprecationWarning: `vesc` is now `serialspec_protocols.vesc`: import that instead" in result.stderr


def test_an_old_name_gives_the_very_same_modules_and_classes() -> None:
    code = """
import warnings
warnings.simplefilter("ignore", DeprecationWarning)
import serialspec_protocols.feetech_sms as new
import serialspec_protocols.feetech_sms.client
import feetech_sms
import feetech_sms.codec
from feetech_sms.client import FeetechSmsClient
from feetech_sms.messages import PingRequest
assert feetech_sms is new and feetech_sms.codec is new.codec
assert FeetechSmsClient is new.client.FeetechSmsClient and PingRequest is new.PingRequest
assert isinstance(feetech_sms.decode(new.encode(PingRequest(id=1)), new.Direction.REQUEST), new.PingRequest)
print("same")
"""
    result = python(code)
    assert result.returncode == 0 and result.stdout == "same\n", result.stderr


def test_the_new_names_import_without_a_warning() -> None:
    result = python(f"import {SHIPPED}.vesc.client, {SHIPPED}.vesc.simulator", "-W", "error")
    assert result.returncode == 0, result.stderr


def test_the_cli_finds_a_shipped_protocol_by_its_name_without_a_warning(tmp_path: Path) -> None:
    env = {**os.environ, "PYTHONPATH": PATH}
    result = subprocess.run(
        [
            sys.executable,
            "-W",
            "error::DeprecationWarning",
            "-m",
            "serialspec",
            "decode",
            "vesc",
            "02 01 00 00 00 03",
            "--direction",
            "request",
        ],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
    )
    assert result.returncode == 0, result.stderr
    assert "fw_version" in result.stdout


def test_a_users_project_puts_its_packages_in_its_own_namespace(tmp_path: Path) -> None:
    (tmp_path / "specs").mkdir()
    shutil.copy(TINYLAMP, tmp_path / "specs")
    (tmp_path / "pyproject.toml").write_text(
        '[tool.serialspec]\nnamespace = "acme.devices"\nold_names = true\n', encoding="utf-8"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT / "generator")}
    generate = [sys.executable, "-m", "serialspec", "generate"]
    result = subprocess.run(generate, capture_output=True, text=True, cwd=tmp_path, env=env)
    assert result.returncode == 0, result.stderr
    package = tmp_path / "generated" / "acme" / "devices" / "tinylamp"
    assert (package / "codec.py").is_file() and (package / "spec.yaml").is_file()
    reference = (tmp_path / "generated" / "docs" / "tinylamp.md").read_text(encoding="utf-8")  # stays where it was
    assert "Python package: `acme.devices.tinylamp`" in reference  # names the package where it went
    code = "import acme.devices.tinylamp as t; import tinylamp; assert tinylamp is t; print(t.PROTOCOL)"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "generator"), str(tmp_path / "generated")])}
    imported = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, env=env)
    assert imported.returncode == 0 and imported.stdout == "tinylamp\n", imported.stderr
    check = subprocess.run([*generate[:-1], "check"], capture_output=True, text=True, cwd=tmp_path, env=env)
    assert check.returncode == 0, check.stderr


def test_a_namespace_that_is_no_package_name_is_refused_in_one_line(tmp_path: Path) -> None:
    (tmp_path / "specs").mkdir()
    shutil.copy(TINYLAMP, tmp_path / "specs")
    (tmp_path / "pyproject.toml").write_text('[tool.serialspec]\nnamespace = "acme-devices"\n', encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": str(ROOT / "generator")}
    result = subprocess.run(
        [sys.executable, "-m", "serialspec", "generate"], capture_output=True, text=True, cwd=tmp_path, env=env
    )
    assert result.returncode != 0
    assert (
        result.stderr.strip()
        .splitlines()[-1]
        .endswith("[tool.serialspec] namespace must be a dotted Python package name, not 'acme-devices'")
    )
