"""serialspec completion: the shell completion script for bash, zsh or fish (written by shtab from the parser)."""

from __future__ import annotations

import argparse

SHELLS = ("bash", "zsh", "fish")
# Where each shell looks for completion scripts of a user's own, for the help text.
INSTALL = (
    "bash: serialspec completion bash > ~/.local/share/bash-completion/completions/serialspec; "
    "zsh: serialspec completion zsh > ~/.zfunc/_serialspec (with fpath+=~/.zfunc before compinit in ~/.zshrc); "
    "fish: serialspec completion fish > ~/.config/fish/completions/serialspec.fish"
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("shell", choices=SHELLS, help=f"the shell to complete in. {INSTALL}")


def run(args: argparse.Namespace) -> int:
    import shtab

    from serialspec.cli.arguments import VERBS, build_parser

    parser, _ = build_parser(VERBS)
    for action in _actions(parser):
        if action.dest in ("spec", "capture", "file", "save", "tap", "out") or action.dest == "specs":
            action.complete = shtab.FILE  # type: ignore[attr-defined]  # shtab's attribute on an argparse action
        elif action.dest == "port":
            action.complete = shtab.FILE  # type: ignore[attr-defined]  # device paths (/dev/ttyUSB0)
    print(shtab.complete(parser, shell=args.shell), end="")
    return 0


def _actions(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    found: list[argparse.Action] = []
    for action in parser._actions:
        found.append(action)
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                found += _actions(sub)
    return found
