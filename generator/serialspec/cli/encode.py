"""serialspec encode."""

from __future__ import annotations

import argparse

HELP = "encode"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    pass


def run(args: argparse.Namespace) -> int:
    return 0
