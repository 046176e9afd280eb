"""Build the serialspec-runtime wheel: `python packaging/runtime/build.py [DIR]` (default dist/).

The runtime's files are staged in a temporary folder first, so building leaves nothing behind in the source tree.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent


def build(out: Path) -> Path:
    """The path of the wheel built into `out`."""
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        stage = Path(tmp)
        project = stage / "packaging" / "runtime"
        project.mkdir(parents=True)
        shutil.copy(HERE / "pyproject.toml", project)
        source = ROOT / "generator" / "serialspec"
        target = stage / "generator" / "serialspec"
        for package in ("runtime", "checksums", "transforms", "encodings"):  # each one's runtime code
            shutil.copytree(source / package, target / package, ignore=shutil.ignore_patterns("__pycache__"))
        for name in ("__init__.py", "py.typed"):
            shutil.copy(source / name, target / name)
        command = [sys.executable, "-m", "pip", "wheel", "--no-build-isolation", "--no-deps", "-q", "-w", str(out)]
        subprocess.run([*command, str(project)], check=True)
    return max(out.glob("serialspec_runtime-*.whl"), key=lambda p: p.stat().st_mtime)


if __name__ == "__main__":
    print(build(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "dist"))
