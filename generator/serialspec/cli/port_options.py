"""The serial line options of the verbs that open a port themselves (scan, replay): the spec's settings, overridable."""

from __future__ import annotations

import argparse
from types import ModuleType
from typing import Any

PARITIES = {"none": "N", "even": "E", "odd": "O"}


def add_arguments(parser: argparse.ArgumentParser, *, baudrate: bool = True) -> None:
    if baudrate:
        parser.add_argument("--baudrate", type=int, metavar="N", help="default: the spec's")
    parser.add_argument("--parity", choices=tuple(PARITIES), help="default: the spec's")
    parser.add_argument("--stopbits", type=float, choices=(1, 1.5, 2), help="default: the spec's")


def open_port(
    args: argparse.Namespace, package: ModuleType | None, baudrate: int | None = None, timeout: float = 0.1
) -> Any:
    """The port of `args.port` with the spec's settings (when there is a spec), as the options change them; a port
    that refuses a setting is a PortError naming it (the pseudo-terminals of some kernels refuse even parity)."""
    from serialspec.runtime.transport import _open_port

    settings = package.SERIAL if package is not None else None
    options: dict[str, Any] = {"timeout": timeout, "write_timeout": 5}
    if settings is not None:
        options.update(
            baudrate=settings.baudrate,
            bytesize=settings.bytesize,
            parity=PARITIES.get(settings.parity, "N"),
            stopbits=settings.stopbits,
        )
    rate = baudrate or getattr(args, "baudrate", None)
    if rate:
        options["baudrate"] = rate
    if args.parity:
        options["parity"] = PARITIES[args.parity]
    if args.stopbits:
        options["stopbits"] = args.stopbits
    return _open_port(args.port, options)
