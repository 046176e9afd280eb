"""serialspec decode."""

from __future__ import annotations

import argparse

HELP = "decode"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    pass


def run(args: argparse.Namespace) -> int:
    return 0
