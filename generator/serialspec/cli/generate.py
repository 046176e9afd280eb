"""serialspec generate: regenerate generated/ (packages and docs) and the JSON Schema from specs/."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from serialspec.cli.project import expected_files, find_root
from serialspec.runtime.errors import SerialspecError

HELP = "regenerate generated/ and specs/serialspec.schema.json from specs/*.yaml"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--root", type=Path, help="project root (default: the nearest folder holding specs/)")


def run(args: argparse.Namespace) -> int:
    root = args.root or find_root()
    files, errors = expected_files(root)
    written = 0
    for path, text in files.items():
        try:
            if not path.exists() or path.read_text(encoding="utf-8") != text:
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_text(text, encoding="utf-8")
                written += 1
        except OSError as exc:
            raise SerialspecError(f"cannot write {path}: {exc.strerror or exc}") from None
    print(f"{len(files)} files generated, {written} changed")
    for error in errors:
        print(error, file=sys.stderr)
    return 1 if errors else 0
