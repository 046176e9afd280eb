"""serialspec sim: serve virtual devices generated from a spec on a pseudo-terminal."""

from __future__ import annotations

import argparse
import json
import signal
import sys
from types import FrameType, ModuleType
from typing import Any

from serialspec.cli import capture
from serialspec.cli.protocols import SPEC_HELP, open_spec, submodule
from serialspec.lang.model import FrameElement, Protocol, Scalar
from serialspec.runtime.errors import SerialspecError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help=SPEC_HELP)
    parser.add_argument(
        "--id",
        dest="ids",
        type=int,
        action="append",
        metavar="N",
        help="a device id on the bus (repeat for several; default: the spec's `device.ids`, else 0); checked "
        "against the spec's id range",
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
    parser.add_argument(
        "--baudrate",
        type=int,
        metavar="N",
        help="answer only while the client has set the line to N baud, like devices set to that rate (they hear "
        "noise at any other: `serialspec scan --all-baudrates` finds them at N alone); default: at any rate",
    )
    parser.add_argument("--quiet", action="store_true", help="do not log requests and replies on stderr")
    parser.add_argument("--tap", metavar="FILE", help="record both directions of the session to a capture file")


def id_range(protocol: Protocol) -> tuple[int, int, int | None]:
    """The ids a device may have (from its id entry's range, else its address field's) and the broadcast id."""
    assert protocol.device is not None
    device = protocol.device
    low, high = 0, 255
    elements = (e for layout in protocol.framing.layouts.values() for e in layout.elements if e.name == device.address)
    fields = (f for m in protocol.messages() for f in m.fields if f.name == device.address)
    address = next(elements, None) or next(fields, None)  # a frame element (Modbus, FEETECH) or a content field
    if isinstance(address, FrameElement | Scalar):
        low, high = int(address.minimum), int(address.maximum)
    entry = next((e for e in device.memory.entries if e.name == device.id_entry), None) if device.memory else None
    if entry is not None:
        low, high = max(low, int(entry.minimum)), min(high, int(entry.maximum))
    return low, high, device.broadcast


def served(protocol: Protocol, devices: dict[int, Any]) -> str:
    """What the simulator serves, in words: `id 1 (sts3215), 2 (sts3215)`; each further kind of device with its ids
    (`pwm_servo servo_id 1, 2, 3, 4`); `(one device: the protocol has no address)` for a protocol without one."""
    device = protocol.device
    assert device is not None
    if not device.address:
        return "(one device: the protocol has no address)"
    shown = ", ".join(f"{i} ({d.model.name})" if d.model else str(i) for i, d in devices.items())
    groups = [f"{device.address} {shown}"]
    groups += [f"{k.name} {k.address} {', '.join(map(str, k.ids))}" for k in device.kinds]
    return "; ".join(groups)


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
    protocol, package = open_spec(args.spec)
    module = submodule(package, "simulator")
    if module is None or (protocol.text is None and protocol.device is None):
        raise SerialspecError(
            f"{args.spec} has no `device:` section, so no simulator is generated: add one (`device: {{}}` answers each"
            " request with its response, every value 0 or its `default`; the tutorial's step 4 describes a device)"
        )
    simulator = _text_device(args, module) if protocol.text is not None else _bus(args, protocol, module)
    simulator.echo = args.echo
    if args.baudrate is not None and args.baudrate <= 0:
        raise SerialspecError(f"--baudrate {args.baudrate}: give a positive number of bits per second")
    simulator.baudrate = args.baudrate
    tap = None
    if args.tap:
        try:
            tap = open(args.tap, "w", encoding="utf-8")  # noqa: SIM115 (closed below)
        except OSError as exc:
            raise SerialspecError(f"cannot write {args.tap}: {exc.strerror}") from None
    if tap is not None:
        # every byte that crosses the pseudo-terminal, as it does: replies and the device's own reports alike
        simulator.tap = capture.Writer(tap, protocol.name).write
    if not args.quiet:
        feed = simulator.feed

        def logged(data: bytes) -> list[tuple[float, bytes]]:
            before = len(simulator.log)
            replies: list[tuple[float, bytes]] = feed(data)
            for request in simulator.log[before:]:
                print(f"request  {_text(request)}", file=sys.stderr, flush=True)
            for _, frame in replies:
                print(f"response {_shown(protocol, frame)}", file=sys.stderr, flush=True)
            return replies

        simulator.feed = logged
    controller, path = simulator.open_pty()

    def stop(signum: int, frame: FrameType | None) -> None:
        simulator.stop()

    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    print(path, flush=True)
    shown = "device" if protocol.text is not None else served(protocol, simulator.devices)
    rate = f" at {args.baudrate} baud" if args.baudrate else ""
    print(f"serialspec sim: {protocol.name} {shown} on {path}{rate}; Ctrl-C to stop", file=sys.stderr, flush=True)
    try:
        simulator.serve(controller)
    finally:
        if tap is not None:
            tap.close()
    return 0


def _text_device(args: argparse.Namespace, module: ModuleType) -> Any:
    """A text protocol's device: one on the line, so no ids, models or data spaces to choose."""
    given = [
        option for option, value in (("--id", args.ids), ("--model", args.models), ("--size", args.sizes)) if value
    ]
    if given:
        raise SerialspecError(f"a text protocol's simulator is one device: {', '.join(given)} do(es) not apply")
    return module.SIMULATOR()


def _bus(args: argparse.Namespace, protocol: Protocol, module: ModuleType) -> Any:
    """The devices on a binary protocol's bus, as --id, --model and --size choose."""
    assert protocol.device is not None
    if args.ids and not protocol.device.address:
        raise SerialspecError(f"--id: {protocol.name} frames carry no device address, so the bus has one device")
    ids = args.ids or list(protocol.device.ids)
    low, high, broadcast = id_range(protocol)
    for device_id in ids:
        if not low <= device_id <= high or device_id == broadcast:
            also = f" ({broadcast} is the broadcast id)" if device_id == broadcast else ""
            if not args.ids:  # the spec's default ids (0 where `device.ids` names none), not an --id typed
                raise SerialspecError(
                    f"no --id given, and the spec's default id {device_id} (`device.ids`: 0 when not given) is "
                    f"outside its id range "
                    f"{low}..{high}{also}: give --id N, or `ids: [N]` under `device:`"
                )
            raise SerialspecError(f"--id {device_id} is outside the spec's id range {low}..{high}{also}")
    sizes: dict[str, int] = {}
    for text in args.sizes or ():
        name, _, count = text.partition("=")
        if not count.isdigit() or int(count) < 1:
            raise SerialspecError(f"--size {text}: expected SPACE=N with N a positive number")
        sizes[name] = int(count)
    options: dict[str, Any] = {"model": model_choice(args.models)}
    if sizes:
        if not protocol.device.spaces:
            raise SerialspecError(f"--size: {protocol.name} devices keep no data spaces")
        options["sizes"] = sizes
    try:
        return module.SIMULATOR(ids, **options)
    except ValueError as exc:  # an unknown model or data space, or a model for an id not on the bus
        option = "--size" if "data space" in str(exc) else "--model"
        raise SerialspecError(f"{option}: {exc}") from None


def _shown(protocol: Protocol, frame: bytes) -> str:
    """A frame sent, for the log: a text sentence as its line, binary bytes as hex."""
    if protocol.text is not None:
        return frame.decode("ascii", "replace").rstrip("\r\n")
    return f"[{frame.hex(' ')}]"


def _text(message: object) -> str:
    what = message.COMMAND + (f".{message.SUBCOMMAND}" if message.SUBCOMMAND else "")  # type: ignore[attr-defined]
    values = message.to_fields()  # type: ignore[attr-defined]
    return f"{what} {json.dumps(values, ensure_ascii=False, default=_plain)}"


def _plain(value: object) -> object:
    """A text message's value JSON has no type for: a letter (an Enum) as its letter, a decimal, time or date as
    its text."""
    from enum import Enum

    return value.value if isinstance(value, Enum) else str(value)
