"""serialspec check: fail when a spec has an error or a generated file is stale, missing or orphaned."""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

from serialspec.cli.project import expected_files, orphans, project, strangers
from serialspec.lang.errors import shown
from serialspec.runtime.errors import SerialspecError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("specs", nargs="*", metavar="SPEC", help="spec files (default: the project's specs)")
    parser.add_argument("--out", metavar="DIR", help="output folder (default: the project's, else generated/)")
    parser.add_argument(
        "--root",
        type=Path,
        metavar="DIR",
        help="project root (default: the nearest folder with a [tool.serialspec] table or specs/)",
    )


def run(args: argparse.Namespace) -> int:
    proj = project(args.root, args.specs, args.out)
    if not proj.specs:
        raise SerialspecError(
            f"no specs to check in {proj.display(proj.root) or '.'}: name spec files, or list them in pyproject.toml's "
            "[tool.serialspec] specs (default: specs/*.yaml)"
        )
    files, errors = expected_files(proj)
    problems: list[str] = []
    for path, text in files.items():
        if not path.exists():
            problems.append(f"{proj.display(path)}: missing")
        elif path.read_text(encoding="utf-8") != text:
            problems.append(f"{proj.display(path)}: stale")
    for path in orphans(proj, files, {e.file for e in errors}):
        problems.append(f"{proj.display(path)}: orphaned (no spec generates it any more)")
    for path in strangers(files):
        problems.append(f"{proj.display(path)}: not generated from any spec (move it out of the generated package)")
    for problem in [*shown(errors), *problems]:
        print(problem, file=sys.stderr)
    if problems:  # a file to regenerate, not only mistakes in specs (which generate refuses until they are fixed)
        first = "fix the mistakes above, then run" if errors else "run"
        print(f"{first} `{generate_command(args)}` to bring the generated files up to date", file=sys.stderr)
    if problems or errors:
        return 1
    print(f"{len(files)} generated {'file matches' if len(files) == 1 else 'files match'} the specs")
    return 0


def generate_command(args: argparse.Namespace) -> str:
    """The `serialspec generate` that writes what this check compared against: its specs, --out and --root."""
    words = ["serialspec", "generate", *args.specs]
    if args.out:
        words += ["--out", args.out]
    if args.root:
        words += ["--root", str(args.root)]
    return shlex.join(words)
