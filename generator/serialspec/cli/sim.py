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
from serialspec.spec.model import Protocol, Scalar

HELP = "serve virtual devices on a pseudo-terminal; prints the device path first, answers until stopped"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help="the protocol spec (YAML)")
    parser.add_argument(
        "--id",
        dest="ids",
        type=int,
        action="append",
        metavar="N",
        help="a device id on the bus (repeat for several; default 0)",
    )
    parser.add_argument("--quiet", action="store_true", help="do not log requests on stderr")


def run(args: argparse.Namespace) -> int:
    protocol, _ = open_spec(args.spec)
    try:
        module = importlib.import_module(f"{protocol.name}.simulator")
    except ImportError:
        raise SerialspecError(f"{args.spec} has no `device:` section, so no simulator is generated") from None
    ids = args.ids or [0]
    low, high = id_range(protocol)
    for device_id in ids:
        if not low <= device_id <= high or (protocol.device and device_id == protocol.device.broadcast):
            raise SerialspecError(f"--id {device_id} is outside {protocol.name}'s device ids {low}..{high}")
    simulator = module.SIMULATOR(ids)
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


def id_range(protocol: Protocol) -> tuple[int, int]:
    """The ids a device may have: the range of the field that carries the address (the spec's device.address)."""
    name = protocol.device.address if protocol.device else ""
    candidates: list[Any] = [e for layout in protocol.framing.layouts.values() for e in layout.value_elements]
    candidates += [f for m in protocol.messages() for f in m.fields if isinstance(f, Scalar)]
    found = next((c for c in candidates if c.name == name), None)
    return (int(found.minimum), int(found.maximum)) if found is not None else (0, 255)
