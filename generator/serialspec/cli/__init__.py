"""The `serialspec` command: one module per verb, each with `add_arguments(parser)` and `run(args) -> int`."""

from __future__ import annotations

import sys
from collections.abc import Iterable, Sequence
from types import SimpleNamespace

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    import argparse


def build_parser(chosen: Iterable[str]) -> tuple[argparse.ArgumentParser, dict[str, argparse.ArgumentParser]]:
    """The command's argparse parser with the arguments of the `chosen` verbs, and each verb's own parser
    (serialspec.cli.arguments)."""
    from serialspec.cli.arguments import build_parser

    return build_parser(chosen)


def plain_decode(given: Sequence[str]) -> SimpleNamespace | None:
    """`decode SPEC HEX... [--direction request|response] [--json]` (in any order after the verb) read without
    argparse: importing argparse (with gettext) and building its parsers costs about a tenth of what the command
    takes to decode a frame (bench/startup.py). The arguments are the ones argparse gives for that command line;
    anything else (help, another option, an abbreviation, `-` for stdin, an option given twice) is None, and argparse
    parses it, telling its errors as always."""
    if len(given) < 3 or given[0] != "decode":
        return None
    positional: list[str] = []
    direction, as_json = None, False
    words = iter(given[1:])
    for word in words:
        if not word.startswith("-"):
            positional.append(word)
        elif word == "--json" and not as_json:
            as_json = True
        elif word.startswith("--direction") and direction is None:
            value = word.partition("=")[2] if word.startswith("--direction=") else next(words, None)
            if word not in ("--direction", f"--direction={value}") or value not in ("request", "response"):
                return None
            direction = value
        else:
            return None
    if len(positional) < 2:
        return None
    from serialspec.cli import decode

    fields = {"file": None, "json": as_json, "direction": direction, "units": False, "request": None}
    return SimpleNamespace(verb="decode", spec=positional[0], hex=positional[1:], **fields, run=decode.run)


def main(argv: Sequence[str] | None = None) -> int:
    given = list(sys.argv[1:] if argv is None else argv)
    args: argparse.Namespace | SimpleNamespace | None = plain_decode(given)
    if args is None:
        from serialspec.cli.arguments import parse

        args = parse(given)
    try:
        code: int = args.run(args)
    except BrokenPipeError:
        return 0
    except Exception as exc:  # the two kinds meant for the user are told in one line each; anything else is a bug
        # (imported here: a command that fails in neither way does not pay for importing them)
        from serialspec.lang.errors import SpecErrors
        from serialspec.runtime.errors import SerialspecError

        if isinstance(exc, SpecErrors):
            print(exc, file=sys.stderr)
            return 1
        if isinstance(exc, SerialspecError):
            print(f"serialspec {args.verb}: {exc}", file=sys.stderr)
            return 1
        raise
    return code


if __name__ == "__main__":
    sys.exit(main())
