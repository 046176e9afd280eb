"""Line coverage of the generated C (generated/c/<protocol>/) by the tests: `make c-coverage`.

The tests' driver builds (tests/test_c_backend.py `Driver`, gcc) are compiled with `--coverage` when
SERIALSPEC_C_COVERAGE names a folder: one sub-folder per protocol, build (its -D switches) and test process. This
reads them with `gcov --json-format` and reports per protocol the lines of `<p>.c` and `<p>_json.c` run by at least
one build, out of the lines any build compiles (a line left out by a switch in one build counts where another build
compiles it). `--uncovered` lists the lines no test runs, with their text.

    python tools/c_coverage.py build/c-coverage [--uncovered]
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GENERATED = ROOT / "generated" / "c"


def lines(folder: Path) -> dict[str, dict[int, bool]]:
    """Per source file of the generated C: line -> run at least once, over every build in folder."""
    found: dict[str, dict[int, bool]] = {}
    for gcda in sorted(folder.glob("*/*.gcda")):
        run = subprocess.run(
            ["gcov", "--json-format", "--stdout", gcda.name], cwd=gcda.parent, capture_output=True, text=True
        )
        if run.returncode != 0:
            raise SystemExit(f"gcov failed on {gcda}: {run.stderr.strip()}")
        for document in run.stdout.splitlines():
            for entry in json.loads(document)["files"]:
                source = Path(entry["file"])
                if source.parent.parent != GENERATED:
                    continue  # the driver, the system headers
                into = found.setdefault(source.name, {})
                for line in entry["lines"]:
                    into[line["line_number"]] = into.get(line["line_number"], False) or line["count"] > 0
    return found


def main(argv: list[str]) -> int:
    if not argv or argv[0].startswith("-"):
        print(__doc__.strip().splitlines()[-1].strip(), file=sys.stderr)
        return 2
    base, uncovered = Path(argv[0]), "--uncovered" in argv[1:]
    protocols = sorted(p.name for p in base.iterdir() if p.is_dir()) if base.is_dir() else []
    if not protocols:
        print(f"no coverage data in {base}: run `make c-coverage`", file=sys.stderr)
        return 1
    print("| protocol | <p>.c lines run | <p>.c | <p>_json.c lines run | <p>_json.c | both |")
    print("| --- | --- | --- | --- | --- | --- |")
    total_run = total = 0
    report: list[str] = []
    for name in protocols:
        found = lines(base / name)
        cells: list[str] = []
        run_both = all_both = 0
        for source in (f"{name}.c", f"{name}_json.c"):
            got = found.get(source, {})
            run = sum(got.values())
            cells += [f"{run} / {len(got)}", f"{100 * run / len(got):.1f}%" if got else "-"]
            run_both, all_both = run_both + run, all_both + len(got)
            if uncovered:
                text = (GENERATED / name / source).read_text(encoding="utf-8").splitlines()
                report += [f"{source}:{n}: {text[n - 1].strip()}" for n, hit in sorted(got.items()) if not hit]
        total_run, total = total_run + run_both, total + all_both
        print(f"| {name} | {' | '.join(cells)} | {100 * run_both / max(all_both, 1):.1f}% |")
    print(f"| all | | | | | {100 * total_run / max(total, 1):.1f}% ({total_run} / {total}) |")
    if report:
        print("\nLines no test runs:")
        print("\n".join(report))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
