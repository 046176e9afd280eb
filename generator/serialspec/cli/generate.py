"""serialspec generate: write each spec's package and reference, and the JSON Schema; remove orphaned files."""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

from serialspec.cli.project import Project, expected_files, orphans, project, target_files
from serialspec.lang.errors import shown
from serialspec.runtime.errors import SerialspecError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("specs", nargs="*", metavar="SPEC", help="spec files (default: the project's specs)")
    parser.add_argument("--out", metavar="DIR", help="output folder (default: the project's, else generated/)")
    parser.add_argument(
        "--root", type=Path, help="project root (default: the nearest folder with a [tool.serialspec] table or specs/)"
    )
    parser.add_argument(
        "--target",
        metavar="NAME",
        help="only this target's files (c, python, markdown, ...), written to DIR/<protocol>/ (--out DIR; default: "
        "the target's folder of the project's output); default: every target",
    )


def run_target(proj: Project, target: str, out_given: bool) -> int:
    """One target's files, into the output folder as given (no orphans removed: the folder may hold other files)."""
    from serialspec.backends import emitters

    chosen = next((e for e in emitters() if e.name == target), None)
    if chosen is None:
        names = ", ".join(e.name for e in emitters())
        raise SerialspecError(f"no target {target!r}: the targets are {names}")
    if not out_given and chosen.folder:
        proj = replace(proj, out=proj.out / chosen.folder)
    files, errors = target_files(proj, target)
    written = _write(files)
    print(f"{len(files)} {target} files generated in {proj.display(proj.out)}, {written} changed")
    for line in shown(errors):
        print(line, file=sys.stderr)
    return 1 if errors else 0


def _write(files: dict[Path, str]) -> int:
    written = 0
    for path, text in files.items():
        try:
            if not path.exists() or path.read_text(encoding="utf-8") != text:
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_text(text, encoding="utf-8")
                written += 1
        except OSError as exc:
            raise SerialspecError(f"cannot write {path}: {exc.strerror or exc}") from None
    return written


def run(args: argparse.Namespace) -> int:
    proj = project(args.root, args.specs, args.out)
    if args.target:
        return run_target(proj, args.target, bool(args.out))
    files, errors = expected_files(proj)
    if proj.chosen and errors and all(path == proj.schema for path in files):
        # every spec named has mistakes: nothing is written (not even the schema, into a generated/ of its own)
        for line in shown(errors):
            print(line, file=sys.stderr)
        return 1
    written = _write(files)
    removed = orphans(proj, files, {e.file for e in errors})
    for path in removed:
        path.unlink()
        print(f"removed {proj.display(path)} (no spec generates it any more)", file=sys.stderr)
    for folder in {p.parent for p in removed}:
        import shutil  # only where an orphaned package leaves its bytecode behind

        shutil.rmtree(folder / "__pycache__", ignore_errors=True)
        if folder.is_dir() and not any(folder.iterdir()):
            folder.rmdir()
    files_generated = f"{len(files)} file{'' if len(files) == 1 else 's'} generated"
    print(f"{files_generated} in {proj.display(proj.out)}, {written} changed, {len(removed)} removed")
    for line in shown(errors):
        print(line, file=sys.stderr)
    return 1 if errors else 0
