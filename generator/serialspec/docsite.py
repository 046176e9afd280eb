"""A documentation site of markdown pages, built with mkdocs in strict mode: `serialspec docs` (a user's own specs)
and `make docs` (the repository's pages, tools/docsite.py) share its look and its search.

mkdocs is the optional extra `serialspec[docs]`, imported only here and run as `python -m mkdocs`. Pages are staged
in a temporary folder with the files they link to, the mkdocs configuration is written beside them, and the site is
built into the folder given. The site works from the file system (plain `.html` links); its search does too: mkdocs'
own search reads its index with a request and a web worker, which browsers refuse for `file://` pages, so the index
is also written as a script and searched in the page (`search/main.js` replaced).
"""

from __future__ import annotations

import importlib.util
import json
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from serialspec.runtime.errors import SerialspecError

MISSING = "the docs site needs mkdocs, an optional extra: pip install 'serialspec[docs]'"

# Readable without any JavaScript from the network: tables scroll sideways instead of squeezing their columns, and
# CJK text breaks between words, never between every character.
CSS = """\
.wy-nav-content { max-width: 1200px; }
table { display: block; overflow-x: auto; width: fit-content; max-width: 100%; }
td, th { word-break: keep-all; overflow-wrap: normal; vertical-align: top; }
td code { white-space: nowrap; }
.wy-table-responsive table td, .wy-table-responsive table th { white-space: normal; }
"""

# The site's search without a request or a worker: the index is a script beside this one, loaded by a <script> tag
# (which file:// pages may do), and searched here: every word of the query in a section's title or text, title
# matches first. The results page and its markup are the theme's (search.html, #mkdocs-search-results).
SEARCH_JS = r"""// serialspec: search that works from disk (file://) as well as served; see serialspec/docsite.py.
(function () {
  function joinUrl(base, path) {
    return base.substring(base.length - 1) === "/" ? base + path : base + "/" + path;
  }
  function escapeHtml(value) {
    return value.replace(/&/g, "&amp;").replace(/"/g, "&quot;").replace(/</g, "&lt;").replace(/>/g, "&gt;");
  }
  function term() {
    var match = /[?&]q=([^&]*)/.exec(window.location.search);
    return match ? decodeURIComponent(match[1].replace(/\+/g, "%20")) : "";
  }
  function summary(text, word) {
    var at = Math.max(0, text.toLowerCase().indexOf(word) - 60);
    return (at > 0 ? "…" : "") + text.substring(at, at + 200) + (text.length > at + 200 ? "…" : "");
  }
  function search(query) {
    var words = query.toLowerCase().split(/\s+/).filter(function (w) { return w.length > 0; });
    var found = [];
    if (!words.length) { return found; }
    window.serialspecSearchIndex.docs.forEach(function (doc) {
      var title = doc.title.toLowerCase(), text = doc.text.toLowerCase(), score = 0;
      for (var i = 0; i < words.length; i++) {
        var inTitle = title.indexOf(words[i]) >= 0, inText = text.indexOf(words[i]) >= 0;
        if (!inTitle && !inText) { return; }
        score += (inTitle ? 10 : 0) + (inText ? 1 : 0);
      }
      found.push({score: score, doc: doc});
    });
    found.sort(function (a, b) { return b.score - a.score; });
    return found.slice(0, 50).map(function (f) { return f.doc; }).map(function (doc) {
      return {location: doc.location, title: doc.title, summary: summary(doc.text, words[0])};
    });
  }
  function show(results) {
    var box = document.getElementById("mkdocs-search-results");
    if (!box) { return; }
    box.innerHTML = "";
    results.forEach(function (r) {
      box.insertAdjacentHTML("beforeend", '<article><h3><a href="' + joinUrl(base_url, r.location) + '">' +
        escapeHtml(r.title) + "</a></h3><p>" + escapeHtml(r.summary) + "</p></article>");
    });
    if (!results.length) {
      var none = box.getAttribute("data-no-results-text") || "No results found";
      box.insertAdjacentHTML("beforeend", "<p>" + none + "</p>");
    }
  }
  function start() {
    var input = document.getElementById("mkdocs-search-query");
    if (!input) { return; }
    var run = function () { show(input.value.length > 1 ? search(input.value) : []); };
    input.addEventListener("keyup", run);
    if (term()) { input.value = term(); run(); }
  }
  var script = document.createElement("script");
  script.src = joinUrl(base_url, "search/search_index.js");
  script.onload = start;
  document.head.appendChild(script);
})();
"""


def mkdocs_available() -> bool:
    return importlib.util.find_spec("mkdocs") is not None


def build(
    pages: Mapping[str, str],
    nav: Sequence[Mapping[str, Any]],
    site: Path,
    *,
    name: str,
    files: Mapping[str, Path] | None = None,
) -> None:
    """Build the site into `site` (emptied first): `pages` maps each page's site path (`protocols/vesc.md`) to its
    markdown, `files` a site path to a file the pages link to, `nav` is mkdocs' navigation. A broken link or
    anchor fails the build (strict): SerialspecError with mkdocs' warnings."""
    if not mkdocs_available():
        raise SerialspecError(MISSING)
    with tempfile.TemporaryDirectory(prefix="serialspec-docs-") as folder:
        stage = Path(folder) / "docs"
        for target, text in pages.items():
            (stage / target).parent.mkdir(parents=True, exist_ok=True)
            (stage / target).write_text(text, encoding="utf-8")
        for target, source in (files or {}).items():
            (stage / target).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(source, stage / target)
        (stage / "extra.css").write_text(CSS, encoding="utf-8")
        config_file = Path(folder) / "mkdocs.yml"
        # JSON is YAML: no YAML writer needed
        config_file.write_text(json.dumps(config(name, nav, stage, site), indent=2), encoding="utf-8")
        # not --quiet: mkdocs counts the warnings strict mode fails on only where it prints them
        result = subprocess.run(
            [sys.executable, "-m", "mkdocs", "build", "-f", str(config_file)], capture_output=True, text=True
        )
    if result.returncode != 0:
        problems = [line for line in result.stderr.splitlines() if not line.startswith("INFO")]
        raise SerialspecError("mkdocs failed:\n" + "\n".join(problems or result.stderr.splitlines()[-5:]))
    searchable_from_disk(site)


def config(name: str, nav: Sequence[Mapping[str, Any]], stage: Path, site: Path) -> dict[str, object]:
    return {
        "site_name": name,
        "docs_dir": str(stage),
        "site_dir": str(site),
        "strict": True,
        "use_directory_urls": False,  # the site works from the file system too
        "theme": {"name": "readthedocs", "highlightjs": False, "navigation_depth": 2},
        "extra_css": ["extra.css"],
        "markdown_extensions": ["tables", "attr_list", {"toc": {"permalink": True}}],
        "validation": {"links": {"not_found": "warn", "anchors": "warn", "unrecognized_links": "warn"}},
        "nav": list(nav),
    }


def searchable_from_disk(site: Path) -> None:
    """The search index as a script, and the search that reads it (see SEARCH_JS)."""
    search = site / "search"
    index = json.loads((search / "search_index.json").read_text(encoding="utf-8"))
    text = json.dumps(index, ensure_ascii=False).replace("</", "<\\/")
    (search / "search_index.js").write_text(f"window.serialspecSearchIndex = {text};\n", encoding="utf-8")
    (search / "main.js").write_text(SEARCH_JS, encoding="utf-8")
