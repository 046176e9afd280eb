"""Build the documentation site (`make docs`): the README, the tutorial, the language reference and every
protocol's reference, with mkdocs in strict mode (a warning, such as a broken link, fails the build).

The pages stay where they are in the repository, readable on any git host; this script rewrites their links to the
site's layout, collects the files they link to (specs, examples) and builds the site with serialspec's own site
builder (serialspec/docsite.py, which `serialspec docs` uses for a user's specs: the same look and search) into
site/ (or the folder given).

    python tools/docsite.py [SITE_DIR]
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

from serialspec.docsite import build
from serialspec.runtime.errors import SerialspecError

ROOT = Path(__file__).resolve().parent.parent
LINK = re.compile(r"(\]\()([^)#:\s]+)((?:#[^)\s]*)?\))")


def pages() -> dict[str, str]:
    """Repository path -> site path of every page."""
    found = {
        "README.md": "index.md",
        "docs/tutorial.md": "tutorial.md",
        "docs/language.md": "language.md",
        "docs/c.md": "c.md",
        "docs/architecture.md": "architecture.md",
        "docs/performance.md": "performance.md",
        "docs/testing.md": "testing.md",
    }
    for doc in sorted((ROOT / "generated" / "docs").glob("*.md")):
        found[f"generated/docs/{doc.name}"] = f"protocols/{doc.name}"
    return found


def relinked(mapping: dict[str, str]) -> tuple[dict[str, str], dict[str, Path]]:
    """Each page's text with its links rewritten to the site's layout, and the other files they link to."""
    texts: dict[str, str] = {}
    files: dict[str, Path] = {}
    for source, target in mapping.items():
        here = Path(source).parent

        def relink(match: re.Match[str], here: Path = here, target: str = target) -> str:
            linked = os.path.normpath(here / match.group(2))
            if (ROOT / linked).is_dir() and (ROOT / linked / "README.md").is_file():
                linked = os.path.join(linked, "README.md")  # a folder: its README, as GitHub shows it
            if not (ROOT / linked).is_file():
                return match.group(0)  # mkdocs reports it (strict: the build fails), a folder too
            if linked not in mapping:
                files[linked] = ROOT / linked
            relative = os.path.relpath(mapping.get(linked, linked), Path(target).parent)
            return f"{match.group(1)}{relative}{match.group(3)}"

        texts[target] = LINK.sub(relink, (ROOT / source).read_text(encoding="utf-8"))
    return texts, files


def main(site: Path) -> int:
    mapping = pages()
    texts, files = relinked(mapping)
    protocols = [{Path(p).stem: p} for p in mapping.values() if p.startswith("protocols/")]
    nav = [
        {"Home": "index.md"},
        {"Tutorial": "tutorial.md"},
        {"Language reference": "language.md"},
        {"C target": "c.md"},
        {"Protocols": protocols},
        {
            "Working on serialspec": [
                {"Architecture": "architecture.md"},
                {"Performance": "performance.md"},
                {"Testing": "testing.md"},
            ]
        },
    ]
    try:
        build(texts, nav, site, name="serialspec", files=files)
    except SerialspecError as exc:
        print(f"docsite: {exc}", file=sys.stderr)
        return 1
    print(f"docsite: built {site}")
    return 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]).resolve() if len(sys.argv) > 1 else ROOT / "site"))
