"""serialspec sim: serve virtual devices generated from a spec on a pseudo-terminal."""

from __future__ import annotations

import argparse
import importlib
import signal
import sys
from types import FrameType

from serialspec.cli.protocols import open_spec
from serialspec.runtime.errors import SerialspecError

HELP = "serve virtual devices on a pseudo-terminal; prints the device path first, answers until stopped"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help="the protocol spec (YAML)")
    parser.add_argument(
        "--id",
        dest="ids",
        type=int,
        action="append",
        metavar="N",
        help="a device id on the bus (repeat for several; default: the spec's `device.ids`, else 0)",
    )
    parser.add_argument(
        "--size",
        dest="sizes",
        action="append",
        metavar="SPACE=N",
        help="number of items of a data space (repeat for several; Modbus: coils=20000)",
    )
    parser.add_argument("--quiet", action="store_true", help="do not log requests on stderr")


def run(args: argparse.Namespace) -> int:
    protocol, _ = open_spec(args.spec)
    try:
        module = importlib.import_module(f"{protocol.name}.simulator")
    except ImportError:
        raise SerialspecError(f"{args.spec} has no `device:` section, so no simulator is generated") from None
    sizes: dict[str, int] = {}
    for text in args.sizes or ():
        name, _, count = text.partition("=")
        if not count.isdigit() or int(count) < 1:
            raise SerialspecError(f"--size {text}: expected SPACE=N with N a positive number")
        sizes[name] = int(count)
    options: dict[str, object] = {"sizes": sizes} if sizes else {}
    try:
        simulator = module.SIMULATOR(args.ids, **options) if args.ids else module.SIMULATOR(**options)
    except (TypeError, ValueError) as exc:  # sizes for a device without data spaces, or an unknown space
        raise SerialspecError(f"{args.spec}: {exc}") from None
    controller, path = simulator.open_pty()

    def stop(signum: int, frame: FrameType | None) -> None:
        simulator.stop()

    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    print(path, flush=True)
    ids = ", ".join(str(i) for i in simulator.devices)
    print(f"serialspec sim: {protocol.name} device(s) {ids} on {path}; Ctrl-C to stop", file=sys.stderr, flush=True)
    simulator.serve(controller)
    return 0
