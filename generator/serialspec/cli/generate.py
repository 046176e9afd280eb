"""serialspec generate: write each spec's package and reference, and the JSON Schema; remove orphaned files."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from serialspec.backends import target_names
from serialspec.cli.project import expected_files, orphans, project
from serialspec.lang.errors import shown
from serialspec.runtime.errors import SerialspecError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("specs", nargs="*", metavar="SPEC", help="spec files (default: the project's specs)")
    parser.add_argument("--out", metavar="DIR", help="output folder (default: the project's, else generated/)")
    parser.add_argument(
        "--target",
        dest="targets",
        action="append",
        choices=target_names(),
        help="only this output (repeatable; default: all of them): python (packages), markdown (references), "
        "wireshark (DIR/<protocol>/<protocol>.lua, a Lua dissector), c (DIR/<protocol>/ given --out, else "
        "generated/c/<protocol>/: C99 for firmware and hosts)",
    )
    parser.add_argument(
        "--root",
        type=Path,
        metavar="DIR",
        help="project root (default: the nearest folder with a [tool.serialspec] table or specs/)",
    )


def run(args: argparse.Namespace) -> int:
    proj = project(args.root, args.specs, args.out)
    notes: list[str] = []  # targets that leave a spec out, and why
    files, errors = expected_files(proj, args.targets or (), bare=args.out is not None, notes=notes)
    if proj.chosen and errors and all(path == proj.schema for path in files):
        # every spec named has mistakes: nothing is written (not even the schema, into a generated/ of its own)
        for line in shown(errors):
            print(line, file=sys.stderr)
        return 1
    written = 0
    for path, text in files.items():
        try:
            if not path.exists() or path.read_text(encoding="utf-8") != text:
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_text(text, encoding="utf-8")
                written += 1
        except OSError as exc:
            raise SerialspecError(f"cannot write {path}: {exc.strerror or exc}") from None
    # Only the whole set of targets says which files nothing generates any more.
    removed = [] if args.targets else orphans(proj, files, {e.file for e in errors})
    for path in removed:
        path.unlink()
        print(f"removed {proj.display(path)} (no spec generates it any more)", file=sys.stderr)
    for folder in {p.parent for p in removed}:
        import shutil  # only where an orphaned package leaves its bytecode behind

        shutil.rmtree(folder / "__pycache__", ignore_errors=True)
        while folder != proj.out and folder.is_dir() and not any(folder.iterdir()):  # test/, then <protocol>/
            folder.rmdir()
            folder = folder.parent
    files_generated = f"{len(files)} file{'' if len(files) == 1 else 's'} generated"
    print(f"{files_generated} in {proj.display(proj.out)}, {written} changed, {len(removed)} removed")
    for line in notes:
        print(line, file=sys.stderr)
    for line in shown(errors):
        print(line, file=sys.stderr)
    return 1 if errors else 0
