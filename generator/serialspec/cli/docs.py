"""serialspec docs: a documentation site of one's own specs (each protocol's reference and its spec), with the look
and the search of serialspec's own site; mkdocs is the optional extra `serialspec[docs]`."""

from __future__ import annotations

import argparse
import os
from dataclasses import replace
from pathlib import Path
from typing import Any

from serialspec.cli.protocols import SPEC_HELP, open_spec
from serialspec.cli.shipped import SHIPPED_SPEC, shipped_spec
from serialspec.lang.model import Protocol
from serialspec.runtime.errors import SerialspecError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("specs", nargs="+", metavar="SPEC", help=SPEC_HELP)
    parser.add_argument("--out", required=True, metavar="DIR", help="the folder to build the site in (emptied first)")
    parser.add_argument("--title", default="Protocols", help="the site's name (default: Protocols)")


def run(args: argparse.Namespace) -> int:
    from serialspec import docsite
    from serialspec.backends.markdown.docs import emit_docs

    if not docsite.mkdocs_available():
        raise SerialspecError(docsite.MISSING)
    protocols: dict[str, Protocol] = {}
    files: dict[str, Path] = {}
    for spec in args.specs:
        protocol, _ = open_spec(spec)
        if not Path(spec).is_file():  # by name: the reference's commands (`serialspec scan vesc`) name it so too,
            protocol = replace(protocol, spec_path=spec)  # not as the path of its package's copy (vesc/spec.yaml)
        if protocol.name in protocols:
            raise SerialspecError(f"{spec}: protocol {protocol.name} is given twice")
        protocols[protocol.name] = protocol
        files[f"specs/{protocol.name}.yaml"] = _spec_file(spec, protocol.name)
    pages = {"index.md": index(args.title, list(protocols.values()))}
    for name, protocol in protocols.items():
        # the reference links its spec as generated/docs/ sees it; on the site the spec sits in specs/
        text = emit_docs(protocol).replace(f"](../../{protocol.spec_path})", f"](../specs/{name}.yaml)")
        pages[f"protocols/{name}.md"] = text
    nav: list[dict[str, Any]] = [
        {"Home": "index.md"},
        {"Protocols": [{name: f"protocols/{name}.md"} for name in protocols]},
    ]
    out = Path(args.out).resolve()
    try:  # a folder that cannot be written is said in one line here, not by mkdocs' traceback
        out.mkdir(parents=True, exist_ok=True)
        probe = out / f".serialspec-{os.getpid()}"
        probe.touch()
        probe.unlink()
    except OSError as exc:
        raise SerialspecError(f"cannot write the site to {args.out}: {exc.strerror or exc}") from None
    docsite.build(pages, nav, out, name=args.title, files=files)
    print(f"serialspec docs: {len(protocols)} protocol(s) in {args.out}: open {Path(args.out) / 'index.html'}")
    print("(search works from disk too; to serve the site instead: python -m http.server -d " + f"{args.out})")
    return 0


def _spec_file(spec: str, name: str) -> Path:
    """The spec's file: the one given, or the copy an installed protocol package ships (found without importing a
    shipped protocol by its old, deprecated top-level name)."""
    if Path(spec).is_file():
        return Path(spec)
    shipped = shipped_spec(spec)
    if shipped is None:  # open_spec found the package: it ships its spec
        raise SerialspecError(f"{spec}: the package of protocol {name} ships no {SHIPPED_SPEC}")
    return shipped


def index(title: str, protocols: list[Protocol]) -> str:
    """The home page: every protocol with its title and the first sentence of its description."""
    rows = "\n".join(
        f"| [{p.name}](protocols/{p.name}.md) | {_cell(p.title)} | {_cell(_first_sentence(p.description))} "
        f"| [{p.name}.yaml](specs/{p.name}.yaml) |"
        for p in protocols
    )
    return (
        f"# {title}\n\n"
        "Each protocol's reference: its frames, commands and fields with units and ranges, every example frame broken "
        "down, errata. Made from the specs by `serialspec docs`.\n\n"
        f"| protocol | device | what it is | spec |\n| --- | --- | --- | --- |\n{rows}\n"
    )


def _first_sentence(text: str) -> str:
    text = " ".join(text.split())
    end = text.find(". ")
    return text if end < 0 else text[: end + 1]


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("<", "&lt;")
