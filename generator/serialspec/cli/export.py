"""serialspec export: a capture (`monitor --save`, `sim --tap`) as a pcap file that Wireshark and tshark read.

Each chunk of the capture becomes one packet with its timestamp, link type DLT_USER0 (147), the bytes after a
pseudo-header: one byte of direction (0 request, 1 response, 2 unknown), one byte of length and the protocol's
name. The dissector `serialspec generate SPEC --target wireshark` writes decodes them (several frames a packet).
"""

from __future__ import annotations

import argparse
import datetime
import struct
import sys
from pathlib import Path
from typing import BinaryIO, TextIO

from serialspec.cli import capture
from serialspec.runtime.errors import SerialspecError

DLT_USER0 = 147
DIRECTION_CODES = {"request": 0, "response": 1, None: 2}
HEADER = "# serialspec capture:"
EPOCH = datetime.datetime(1970, 1, 1, tzinfo=datetime.UTC)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("capture", help="a capture file (monitor --save, sim --tap); - reads stdin")
    parser.add_argument("--pcap", required=True, metavar="FILE", help="the pcap file to write (- for stdout)")
    parser.add_argument(
        "--protocol", metavar="NAME", help="the protocol's name (default: the one the capture's first line names)"
    )


def run(args: argparse.Namespace) -> int:
    stream = sys.stdin if args.capture == "-" else _open(args.capture)
    with stream:
        lines = stream.readlines()
    name = args.protocol or next((line[len(HEADER) :].strip() for line in lines if line.startswith(HEADER)), None)
    if not name:
        raise SerialspecError(f"{args.capture} names no protocol (no '{HEADER} NAME' line): give --protocol NAME")
    encoded = name.encode("utf-8")
    if len(encoded) > 255:
        raise SerialspecError(f"protocol name {name!r} is longer than 255 bytes")
    try:
        chunks = list(capture.read(lines))
    except ValueError as exc:
        raise SerialspecError(f"{args.capture}: {exc}") from None
    out = sys.stdout.buffer if args.pcap == "-" else _create(args.pcap)
    with out:
        write(out, encoded, [chunk for _, chunk in chunks])
    if args.pcap != "-":
        print(f"{len(chunks)} packet(s) written to {args.pcap}", file=sys.stderr)
    return 0


def write(out: BinaryIO, name: bytes, chunks: list[capture.Chunk]) -> None:
    out.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, DLT_USER0))
    for chunk in chunks:
        seconds, micros = _timestamp(chunk.when)
        packet = bytes((DIRECTION_CODES[chunk.direction], len(name))) + name + chunk.data
        out.write(struct.pack("<IIII", seconds, micros, len(packet), len(packet)) + packet)


def _timestamp(when: str) -> tuple[int, int]:
    if not when:
        return 0, 0
    try:
        moment = datetime.datetime.fromisoformat(when)
    except ValueError:
        raise SerialspecError(f"timestamp {when!r} is not ISO 8601") from None
    if moment.tzinfo is None:
        moment = moment.replace(tzinfo=datetime.UTC)
    micros = (moment - EPOCH) // datetime.timedelta(microseconds=1)
    return micros // 1_000_000, micros % 1_000_000


def _open(path: str) -> TextIO:
    try:
        return open(path, encoding="utf-8")
    except OSError as exc:
        raise SerialspecError(f"cannot read {path}: {exc.strerror}") from None


def _create(path: str) -> BinaryIO:
    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        return open(path, "wb")
    except OSError as exc:
        raise SerialspecError(f"cannot write {path}: {exc.strerror}") from None
