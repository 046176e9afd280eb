"""serialspec export: captures as pcap (DLT_USER0 and serialspec's pseudo-header), read back byte by byte."""

from __future__ import annotations

import struct
import subprocess
import sys
from pathlib import Path

SERIALSPEC = [sys.executable, "-m", "serialspec"]


def packets(pcap: bytes) -> list[tuple[int, int, bytes]]:
    magic, major, minor, _, _, snaplen, link = struct.unpack_from("<IHHiIII", pcap)
    assert (magic, major, minor, snaplen, link) == (0xA1B2C3D4, 2, 4, 65535, 147)
    found, at = [], 24
    while at < len(pcap):
        seconds, micros, size, original = struct.unpack_from("<IIII", pcap, at)
        assert size == original
        found.append((seconds, micros, pcap[at + 16 : at + 16 + size]))
        at += 16 + size
    return found


def test_captures_merge_by_time_with_direction_and_protocol_before_the_bytes(tmp_path: Path) -> None:
    (tmp_path / "a.capture").write_text(
        "# serialspec capture: fashionstar_uart\n"
        "2026-11-25T10:00:00.000001+00:00 request 12 4c 01 01 03 63\n"
        "2026-11-25T10:00:02.999999+00:00 response 05 1c 01 01 03 26\n",
        encoding="utf-8",
    )
    (tmp_path / "b.capture").write_text(
        "# serialspec capture: vesc\n2026-11-25T10:00:01.500000+00:00 - 02 01 04 40 84 03\n", encoding="utf-8"
    )
    done = subprocess.run(
        [*SERIALSPEC, "export", "a.capture", "b.capture", "--pcap", "out/both.pcap"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0 and done.stderr == "3 packet(s) written to out/both.pcap\n", done.stderr
    start = 1795600800  # 2026-11-25T10:00:00Z
    assert packets((tmp_path / "out" / "both.pcap").read_bytes()) == [
        (start, 1, b"\x00\x10fashionstar_uart" + bytes.fromhex("12 4c 01 01 03 63")),
        (start + 1, 500000, b"\x02\x04vesc" + bytes.fromhex("02 01 04 40 84 03")),
        (start + 2, 999999, b"\x01\x10fashionstar_uart" + bytes.fromhex("05 1c 01 01 03 26")),
    ]


def test_a_capture_naming_no_protocol_is_refused_in_one_line(tmp_path: Path) -> None:
    (tmp_path / "frames.txt").write_text("12 4c 01 01 03 63\n", encoding="utf-8")
    done = subprocess.run(
        [*SERIALSPEC, "export", "frames.txt", "--pcap", "x.pcap"], cwd=tmp_path, capture_output=True, text=True
    )
    assert done.returncode == 1
    assert done.stderr == (
        "serialspec export: frames.txt names no protocol (no '# serialspec capture: NAME' line): give --protocol NAME\n"
    )
    given = [*SERIALSPEC, "export", "frames.txt", "--pcap", "x.pcap", "--protocol", "fashionstar_uart"]
    assert subprocess.run(given, cwd=tmp_path, capture_output=True).returncode == 0
    assert packets((tmp_path / "x.pcap").read_bytes()) == [
        (0, 0, b"\x02\x10fashionstar_uart" + bytes.fromhex("12 4c 01 01 03 63"))
    ]
