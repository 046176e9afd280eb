"""serialspec ports: the serial ports of this machine (pyserial's list_ports), with what identifies each one."""

from __future__ import annotations

import argparse
import json
from typing import Any


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="one JSON object per port")
    parser.add_argument("--all", action="store_true", help="also ports with no device behind them (n/a)")


def ports(everything: bool = False) -> list[dict[str, Any]]:
    """Each port as {device, description, vid_pid, serial_number, manufacturer, location}, sorted by device path."""
    from serial.tools import list_ports

    found = []
    for port in sorted(list_ports.comports(), key=lambda p: p.device):
        if not everything and port.description == "n/a" and port.vid is None:
            continue  # a legacy UART with nothing behind it (Linux lists every /dev/ttyS*)
        found.append(
            {
                "device": port.device,
                "description": port.description,
                "vid_pid": f"{port.vid:04x}:{port.pid:04x}" if port.vid is not None and port.pid is not None else None,
                "serial_number": port.serial_number,
                "manufacturer": port.manufacturer,
                "location": port.location,
            }
        )
    return found


def run(args: argparse.Namespace) -> int:
    found = ports(args.all)
    if args.json:
        for port in found:
            print(json.dumps(port, ensure_ascii=False))
        return 0
    if not found:
        print("no serial ports found" + ("" if args.all else " (--all lists ports with no device behind them too)"))
        return 0
    rows = [(p["device"], p["vid_pid"] or "-", p["serial_number"] or "-", p["description"]) for p in found]
    widths = [max(len(row[i]) for row in [("DEVICE", "VID:PID", "SERIAL", ""), *rows]) for i in range(3)]
    for row in [("DEVICE", "VID:PID", "SERIAL", "DESCRIPTION"), *rows]:
        print("  ".join(text.ljust(widths[i]) for i, text in enumerate(row[:3])) + "  " + row[3])
    return 0
