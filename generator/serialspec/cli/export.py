"""serialspec export: captures (`monitor --save`, `sim --tap`) as a pcap file that Wireshark and tshark read.

Several captures (of several buses, or protocols) are merged by time. Each chunk of a capture becomes one packet
with its timestamp, link type DLT_USER0 (147), the bytes after a pseudo-header: one byte of direction (0 request,
1 response, 2 unknown), one byte of length and the protocol's name. The dissector that `serialspec generate SPEC
--target wireshark` writes decodes them (several frames a packet, frames cut between packets joined again).
"""

from __future__ import annotations

import argparse
import datetime
import struct
import sys
from pathlib import Path
from typing import BinaryIO

from serialspec.cli import capture
from serialspec.runtime.errors import SerialspecError

DLT_USER0 = 147
DIRECTION_CODES = {"request": 0, "response": 1, None: 2}
HEADER = "# serialspec capture:"
EPOCH = datetime.datetime(1970, 1, 1, tzinfo=datetime.UTC)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "captures",
        nargs="+",
        metavar="CAPTURE",
        help="capture files (monitor --save, sim --tap; - reads stdin); several are merged by time",
    )
    parser.add_argument("--pcap", required=True, metavar="FILE", help="the pcap file to write (- for stdout)")
    parser.add_argument(
        "--protocol",
        metavar="NAME",
        help="the protocol of a capture whose first line names none (# serialspec capture: NAME)",
    )


def run(args: argparse.Namespace) -> int:
    packets: list[tuple[bytes, capture.Chunk]] = []
    for path in args.captures:
        name, chunks = _read(path, args.protocol)
        packets += [(name, chunk) for chunk in chunks]
    if all(chunk.when for _, chunk in packets):  # merged by time (a stable sort: one capture keeps its order)
        packets.sort(key=lambda packet: _timestamp(packet[1].when))
    out = sys.stdout.buffer if args.pcap == "-" else _create(args.pcap)
    with out:
        write(out, packets)
    if args.pcap != "-":
        print(f"{len(packets)} packet(s) written to {args.pcap}", file=sys.stderr)
    return 0


def _read(path: str, protocol: str | None) -> tuple[bytes, list[capture.Chunk]]:
    """A capture's protocol name (from its first line, else `protocol`) and chunks."""
    stream = sys.stdin if path == "-" else capture.open_text(path)
    with stream:
        lines = stream.readlines()
    name = next((line[len(HEADER) :].strip() for line in lines if line.startswith(HEADER)), None) or protocol
    if not name:
        raise SerialspecError(f"{path} names no protocol (no '{HEADER} NAME' line): give --protocol NAME")
    if len(name.encode("utf-8")) > 255:
        raise SerialspecError(f"{path}: protocol name {name!r} is longer than 255 bytes")
    try:
        chunks = [chunk for _, chunk in capture.read(lines)]
    except ValueError as exc:
        raise SerialspecError(f"{path}: {exc}") from None
    return name.encode("utf-8"), chunks


def write(out: BinaryIO, packets: list[tuple[bytes, capture.Chunk]]) -> None:
    """A pcap file (microsecond timestamps, DLT_USER0) of the chunks, each after its protocol's pseudo-header."""
    out.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, DLT_USER0))
    for name, chunk in packets:
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


def _create(path: str) -> BinaryIO:
    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        return open(path, "wb")
    except OSError as exc:
        raise SerialspecError(f"cannot write {path}: {exc.strerror}") from None
