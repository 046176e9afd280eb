"""The `serialspec` command's argparse parser: built for the chosen verb alone (see serialspec.cli)."""

from __future__ import annotations

import argparse
import functools
import gettext
import importlib
import os
from collections.abc import Iterable, Sequence

from serialspec import __version__

DESCRIPTION = (
    "serial protocols as YAML specs: generate codecs, typed clients, virtual devices and references from them; "
    "decode, encode, simulate and watch frames"
)
# Each verb (its module, serialspec.cli.<verb>, is imported only to run it: `generate` loads no serial-port code)
# and its one-line help.
VERBS = {
    "generate": "generate DIR/<protocol>/ and DIR/docs/<protocol>.md from specs "
    "(default: the project's, see [tool.serialspec])",
    "check": "check the specs and that the generated files match them (exit 1 naming each stale or orphaned file)",
    "decode": "decode frames given as hex ('12 4c 08', '0x12 0x4c', '124c08', '12:4c:08'), one frame per argument "
    "('-': one per line from stdin), or a capture with --file",
    "encode": "encode a JSON object ({command, subcommand, direction, fields}) as a frame; prints hex",
    "sim": "serve virtual devices on a pseudo-terminal; prints the device path first, answers until stopped",
    "monitor": "print every frame seen on a port (device path or pyserial URL), one line each with a timestamp",
    "docs": "build a documentation site (mkdocs) of specs: each protocol's reference and its spec, searchable",
    "plot": "plot fields over time in their units, one panel each, from a capture or live from a port (PNG, SVG)",
    "ports": "list the serial ports: device path, description, VID:PID and serial number",
    "scan": "find the devices on a bus: each id (and baud rate) answering the spec's presence request, with its model",
    "replay": "send the frames of one direction of a capture to a port, with their timing",
    "completion": "print the shell completion script for bash, zsh or fish",
    "watch": "a live full-screen view of a port: one row per device and command, last values in units, rates, errors",
    "export": "write captures (monitor --save, sim --tap) as one pcap file for Wireshark (generate --target wireshark)",
}


class _Formatter(argparse.HelpFormatter):
    """argparse's help layout, sized without importing shutil (and with it lzma and bz2) on every start: the width
    as shutil.get_terminal_size() gives it (COLUMNS, else the terminal's, else 80), less 2 as argparse does."""

    def __init__(self, prog: str) -> None:
        try:
            columns = int(os.environ.get("COLUMNS", "")) or os.get_terminal_size().columns
        except (ValueError, OSError):
            columns = 80
        super().__init__(prog, width=max(columns, 10) - 2)


def _translate_once() -> None:
    """argparse looks each of its texts ('usage: ', 'options', ...) up in gettext's catalogues every time it uses one,
    a search of the locale's folders each time (some 45 while the parser is built, a third of the command's start):
    the catalogue of gettext's domain is looked up once (what gettext.gettext does for each text), and each text in
    it once. The translations are the same (the locale does not change while the command runs)."""
    if not hasattr(argparse._, "cache_info"):  # type: ignore[attr-defined]
        domain = gettext.textdomain()
        folder = gettext.bindtextdomain(domain)
        if not os.path.isdir(folder):
            # no catalogues at all (as in many Python installs): each text is its own translation, told without
            # importing locale, as gettext's search of the folder would
            argparse._ = functools.cache(str)  # type: ignore[attr-defined]
            return
        catalogue = gettext.translation(domain, folder, fallback=True)
        argparse._ = functools.cache(catalogue.gettext)  # type: ignore[attr-defined]


class _Unbuilt:
    """Stands for the parser of a verb that is not given (`serialspec --help`, or no verb, or an unknown one): the
    command's help and errors name the verbs and their one-line help, and never parse with a verb's parser, so it
    is not built (building all of them would cost a third of `serialspec --help`)."""

    def __init__(self, **_: object) -> None:
        pass


def build_parser(chosen: Iterable[str]) -> tuple[argparse.ArgumentParser, dict[str, argparse.ArgumentParser]]:
    """The command's parser, with the arguments of the `chosen` verbs only (each verb's module is imported for its
    arguments), and each verb's own parser: of every verb, or where the chosen verbs are all known, of those alone (a
    verb's parser costs as much to build as a verb's imports; `serialspec --help` lists them all)."""
    _translate_once()
    only = bool(chosen) and all(name in VERBS for name in chosen)
    parser = argparse.ArgumentParser(prog="serialspec", description=DESCRIPTION, formatter_class=_Formatter)
    parser.add_argument("--version", action="version", version=f"serialspec {__version__}")
    # argparse's parsers for the chosen verbs, where they are known; else none is parsed with (see _Unbuilt)
    parser_class: type[argparse.ArgumentParser] = argparse.ArgumentParser if only else _Unbuilt  # type: ignore[assignment]
    verbs = parser.add_subparsers(dest="verb", required=True, metavar="VERB", parser_class=parser_class)
    subparsers = {}
    for name, text in VERBS.items():
        if only and name not in chosen:
            continue
        sub = subparsers[name] = verbs.add_parser(name, help=text, description=text, formatter_class=_Formatter)
        if name in chosen:
            module = importlib.import_module(f"serialspec.cli.{name}")
            module.add_arguments(sub)
            sub.set_defaults(run=module.run, verb=name)
    return parser, subparsers


def parse(given: Sequence[str]) -> argparse.Namespace:
    """The command line `given` (without the program name) parsed: the chosen verb's arguments, its `run` and `verb`."""
    chosen = next((word for word in given if not word.startswith("-")), None)  # options before it: --help, --version
    parser, subparsers = build_parser(() if chosen is None else (chosen,))
    args, extra = parser.parse_known_args(given)
    if extra:
        # Options between a verb's positional arguments (`decode SPEC --direction response HEX`): argparse only
        # intermixes them without subparsers, so the verb's own parser reads its arguments again.
        args = subparsers[args.verb].parse_intermixed_args(given[given.index(args.verb) + 1 :])
    return args
