"""The `serialspec` command: one module per verb, each with `add_arguments(parser)` and `run(args) -> int`."""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from serialspec import __version__
from serialspec.lang.errors import SpecErrors
from serialspec.runtime.errors import SerialspecError

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
}


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="serialspec", description=__doc__.split(":")[0] if __doc__ else None)
    parser.add_argument("--version", action="version", version=f"serialspec {__version__}")
    verbs = parser.add_subparsers(dest="verb", required=True, metavar="VERB")
    given = list(sys.argv[1:] if argv is None else argv)
    chosen = next((word for word in given if not word.startswith("-")), None)  # options before it: --help, --version
    subparsers = {}
    for name, text in VERBS.items():
        sub = subparsers[name] = verbs.add_parser(name, help=text, description=text)
        if name == chosen:
            module = importlib.import_module(f"{__name__}.{name}")
            module.add_arguments(sub)
            sub.set_defaults(run=module.run, verb=name)
    args, extra = parser.parse_known_args(argv)
    if extra:
        # Options between a verb's positional arguments (`decode SPEC --direction response HEX`): argparse only
        # intermixes them without subparsers, so the verb's own parser reads its arguments again.
        args = subparsers[args.verb].parse_intermixed_args(given[given.index(args.verb) + 1 :])
    try:
        code: int = args.run(args)
    except SpecErrors as exc:
        print(exc, file=sys.stderr)
        return 1
    except SerialspecError as exc:
        print(f"serialspec {args.verb}: {exc}", file=sys.stderr)
        return 1
    except BrokenPipeError:
        return 0
    return code


if __name__ == "__main__":
    sys.exit(main())
