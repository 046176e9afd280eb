"""serialspec sim: serve virtual devices generated from a spec on a pseudo-terminal."""

from __future__ import annotations

import argparse
import importlib
import signal
import sys
from types import FrameType
from typing import Any

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
    parser.add_argument(
        "--model",
        dest="models",
        action="append",
        metavar="NAME|ID=NAME",
        help="the device model (a name from the spec's `device.models`) of every device, or of one id (repeat)",
    )
    parser.add_argument(
        "--echo",
        action="store_true",
        help="echo every byte received before answering, like a one-wire half-duplex adapter (clients: echo=True)",
    )
    parser.add_argument("--quiet", action="store_true", help="do not log requests on stderr")


def model_choice(given: list[str] | None) -> str | dict[int, str] | None:
    """--model NAME (every device) or --model ID=NAME (one device), as the simulator's `model` argument."""
    if not given:
        return None
    per_id: dict[int, str] = {}
    every: str | None = None
    for item in given:
        key, sep, name = item.partition("=")
        if not sep:
            every = item
        elif key.strip().isdigit():
            per_id[int(key)] = name.strip()
        else:
            raise SerialspecError(f"--model {item}: expected NAME or ID=NAME (e.g. 3=sts3215)")
    if every is not None and per_id:
        raise SerialspecError("--model: give either one NAME for every device or ID=NAME for each, not both")
    return per_id or every


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
    options: dict[str, Any] = {"model": model_choice(args.models)}
    if sizes:
        options["sizes"] = sizes
    try:
        simulator = module.SIMULATOR(args.ids, **options) if args.ids else module.SIMULATOR(**options)
    except TypeError:  # a simulator without data spaces takes no sizes
        raise SerialspecError(f"--size: {protocol.name} devices keep no data spaces") from None
    except ValueError as exc:  # an unknown model or data space, or a model for an id not on the bus
        raise SerialspecError(f"--model/--size: {exc}") from None
    simulator.echo = args.echo
    controller, path = simulator.open_pty()

    def stop(signum: int, frame: FrameType | None) -> None:
        simulator.stop()

    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    print(path, flush=True)
    ids = ", ".join(f"{i} ({d.model.name})" if d.model else str(i) for i, d in simulator.devices.items())
    print(f"serialspec sim: {protocol.name} device(s) {ids} on {path}; Ctrl-C to stop", file=sys.stderr, flush=True)
    simulator.serve(controller)
    return 0
