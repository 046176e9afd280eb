"""serialspec check: fail when a spec has an error or a generated file is stale, missing or unexpected."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from serialspec.cli.project import expected_files, find_root

HELP = "check the specs and that generated/ matches them (exit 1 if not)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--root", type=Path, help="project root (default: the nearest folder holding specs/)")


def run(args: argparse.Namespace) -> int:
    root = args.root or find_root()
    files, errors = expected_files(root)
    problems = [str(error) for error in errors]
    for path, text in files.items():
        if not path.exists():
            problems.append(f"{path.relative_to(root)}: missing")
        elif path.read_text(encoding="utf-8") != text:
            problems.append(f"{path.relative_to(root)}: stale")
    generated = root / "generated"
    for path in sorted(generated.rglob("*")) if generated.is_dir() else []:
        failed_spec = any(part in {e.file for e in errors} for part in path.parts)
        if path.is_file() and "__pycache__" not in path.parts and path not in files and not failed_spec:
            problems.append(f"{path.relative_to(root)}: not generated from any spec")
    for problem in problems:
        print(problem, file=sys.stderr)
    if problems:
        print("run `serialspec generate` to bring generated/ up to date", file=sys.stderr)
        return 1
    print(f"{len(files)} generated files match the specs")
    return 0
