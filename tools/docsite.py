"""Build the documentation site (`make docs`): the README, the tutorial, the language reference and every
protocol's reference, with mkdocs in strict mode (a warning, such as a broken link, fails the build).

The pages stay where they are in the repository, readable on any git host; this script stages them under
build/docs/ with their links rewritten to the site's layout, copies the files they link to (specs, examples), writes
the mkdocs configuration and builds into site/ (or the folder given).

    python tools/docsite.py [SITE_DIR]
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
STAGE = ROOT / "build" / "docs"
LINK = re.compile(r"(\]\()([^)#:\s]+)((?:#[^)\s]*)?\))")

# Readable without any JavaScript from the network: tables scroll sideways instead of squeezing their columns, and
# CJK text breaks between words, never between every character.
CSS = """\
.wy-nav-content { max-width: 1200px; }
table { display: block; overflow-x: auto; width: fit-content; max-width: 100%; }
td, th { word-break: keep-all; overflow-wrap: normal; vertical-align: top; }
td code { white-space: nowrap; }
.wy-table-responsive table td, .wy-table-responsive table th { white-space: normal; }
"""


# Search reads its index with a web worker, which a browser refuses to a page opened from disk: there its results
# page would say "Searching..." forever, so it says how to serve the site instead.
SEARCH_FROM_DISK = """\
if (location.protocol === "file:") {
  document.addEventListener("DOMContentLoaded", function () {
    var results = document.getElementById("mkdocs-search-results");
    if (results) {
      results.innerHTML = "<p>Search needs the site served over HTTP: a browser does not let a page opened from "
        + "disk read the search index. Serve it with <code>python3 -m http.server -d site</code> and open "
        + "<a href='http://localhost:8000/'>http://localhost:8000/</a>; every other page works from disk.</p>";
    }
  });
}
"""


def pages() -> dict[str, str]:
    """Repository path -> site path of every page."""
    found = {"README.md": "index.md", "docs/tutorial.md": "tutorial.md", "docs/language.md": "language.md"}
    for doc in sorted((ROOT / "generated" / "docs").glob("*.md")):
        found[f"generated/docs/{doc.name}"] = f"protocols/{doc.name}"
    return found


def stage() -> dict[str, str]:
    mapping = pages()
    shutil.rmtree(STAGE, ignore_errors=True)
    for source, target in mapping.items():
        text = (ROOT / source).read_text(encoding="utf-8")
        here = Path(source).parent

        def relink(match: re.Match[str], here: Path = here, target: str = target) -> str:
            linked = os.path.normpath(here / match.group(2))
            if not (ROOT / linked).exists():
                return match.group(0)  # mkdocs reports it (strict: the build fails)
            site_path = mapping.get(linked, linked)
            if linked not in mapping:
                (STAGE / linked).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy(ROOT / linked, STAGE / linked)
            relative = os.path.relpath(site_path, Path(target).parent)
            return f"{match.group(1)}{relative}{match.group(3)}"

        (STAGE / target).parent.mkdir(parents=True, exist_ok=True)
        (STAGE / target).write_text(LINK.sub(relink, text), encoding="utf-8")
    (STAGE / "extra.css").write_text(CSS, encoding="utf-8")
    (STAGE / "search-from-disk.js").write_text(SEARCH_FROM_DISK, encoding="utf-8")
    return mapping


def config(mapping: dict[str, str], site: Path) -> dict[str, object]:
    protocols = [{Path(p).stem: p} for p in mapping.values() if p.startswith("protocols/")]
    return {
        "site_name": "serialspec",
        "docs_dir": str(STAGE),
        "site_dir": str(site),
        "strict": True,
        "use_directory_urls": False,  # the site works from the file system too
        "theme": {"name": "readthedocs", "highlightjs": False, "navigation_depth": 2},
        "extra_css": ["extra.css"],
        "extra_javascript": ["search-from-disk.js"],
        "markdown_extensions": ["tables", "attr_list", {"toc": {"permalink": True}}],
        "validation": {"links": {"not_found": "warn", "anchors": "warn", "unrecognized_links": "warn"}},
        "nav": [
            {"Home": "index.md"},
            {"Tutorial": "tutorial.md"},
            {"Language reference": "language.md"},
            {"Protocols": protocols},
        ],
    }


def build(site: Path) -> int:
    mapping = stage()
    config_file = STAGE.parent / "mkdocs.yml"
    # JSON is YAML: no YAML writer needed
    config_file.write_text(json.dumps(config(mapping, site), indent=2), encoding="utf-8")
    # not --quiet: mkdocs counts the warnings strict mode fails on only where it prints them
    code = subprocess.run([sys.executable, "-m", "mkdocs", "build", "-f", str(config_file)]).returncode
    if code == 0:
        shown = os.path.relpath(site) if site.is_relative_to(Path.cwd()) else str(site)
        print(f"open {shown}/index.html; for search, serve it: python3 -m http.server -d {shown}", file=sys.stderr)
    return code


if __name__ == "__main__":
    sys.exit(build(Path(sys.argv[1]).resolve() if len(sys.argv) > 1 else ROOT / "site"))
