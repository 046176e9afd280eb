"""The `serialspec` command: one module per verb, each with `add_arguments(parser)` and `run(args) -> int`."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from serialspec import __version__
from serialspec.cli import check, decode, encode, generate, monitor, sim
from serialspec.runtime.errors import SerialspecError
from serialspec.spec.errors import SpecErrors

VERBS = {"generate": generate, "check": check, "decode": decode, "encode": encode, "sim": sim, "monitor": monitor}


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="serialspec", description=__doc__.split(":")[0] if __doc__ else None)
    parser.add_argument("--version", action="version", version=f"serialspec {__version__}")
    verbs = parser.add_subparsers(dest="verb", required=True, metavar="VERB")
    subparsers = {}
    for name, module in VERBS.items():
        sub = subparsers[name] = verbs.add_parser(name, help=module.HELP, description=module.HELP)
        module.add_arguments(sub)
        sub.set_defaults(run=module.run, verb=name)
    args, extra = parser.parse_known_args(argv)
    if extra:
        # Options between a verb's positional arguments (`decode SPEC --direction response HEX`): argparse only
        # intermixes them without subparsers, so the verb's own parser reads its arguments again.
        given = list(sys.argv[1:] if argv is None else argv)
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
