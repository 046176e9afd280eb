"""The C target (generated/c/): flash and RAM on Cortex-M0+, and parse throughput on this host against a hand-written
FEETECH parser (bench/c/feetech_handwritten.c) and the Python stream parser.

Flash: `arm-none-eabi-gcc -mcpu=cortex-m0plus -mthumb -Os -ffunction-sections -fdata-sections -Wl,--gc-sections`
(newlib-nano), a main() reaching what the build enables (bench/c/size_main.c); text + data of that program minus an
empty main's. Skipped (noted) where arm-none-eabi-gcc is not installed (`apt-get install gcc-arm-none-eabi`).
Throughput: gcc -O2 on this host, bench/c/throughput.c feeding one stream to the parser 20 times.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

from serialspec.lang import load_protocol
from serialspec.lang.model import Direction

from bench.timing import Table

ROOT = Path(__file__).resolve().parent.parent
HERE = Path(__file__).resolve().parent / "c"
GENERATED = ROOT / "generated" / "c"
ARM = ["-mcpu=cortex-m0plus", "-mthumb", "-Os", "-ffunction-sections", "-fdata-sections", "-std=c99"]
LINK = ["-Wl,--gc-sections", "--specs=nano.specs", "--specs=nosys.specs"]
TARGET = 1.2  # the flash target: generated host parser+decode ÷ the hand-written one
PROTOCOLS = sorted(p.name for p in GENERATED.iterdir() if p.is_dir()) if GENERATED.is_dir() else []


def _flash(folder: Path, sources: list[str], defines: list[str]) -> int:
    exe = folder / "size.elf"
    command = ["arm-none-eabi-gcc", *ARM, *defines, *sources, str(HERE / "size_main.c"), *LINK, "-o", str(exe)]
    subprocess.run(command, check=True, capture_output=True)
    out = subprocess.run(["arm-none-eabi-size", str(exe)], check=True, capture_output=True, text=True).stdout
    text, data = out.splitlines()[1].split()[:2]
    return int(text) + int(data)


def _ram(folder: Path, name: str) -> tuple[int, int]:
    """sizeof(parser_t) and sizeof(msg_t) on the target."""
    source = folder / "sizes.c"
    source.write_text(
        f'#include "{name}.h"\nconst unsigned long sizes_[2] = {{sizeof({name}_parser_t), sizeof({name}_msg_t)}};\n'
    )
    obj = folder / "sizes.o"
    subprocess.run(
        ["arm-none-eabi-gcc", *ARM, "-I", str(GENERATED / name), "-c", str(source), "-o", str(obj)], check=True
    )
    raw = folder / "sizes.bin"
    subprocess.run(["arm-none-eabi-objcopy", "-O", "binary", "-j", ".rodata.sizes_", str(obj), str(raw)], check=True)
    data = raw.read_bytes()
    return int.from_bytes(data[0:4], "little"), int.from_bytes(data[4:8], "little")


def sizes() -> Table:
    rows: list[list[str]] = []
    notes = [
        "Flash: text + data on Cortex-M0+ (`-Os`, `--gc-sections`, newlib-nano) of a program whose main() reaches "
        "what the build enables, minus an empty main's; bitwise CRCs (no tables). RAM: sizeof on the target.",
        "encode: `P_ENABLE_DECODE=0 P_ENABLE_PARSER=0`; parser+decode: `P_ENABLE_ENCODE=0`; all: the default. "
        "host: `P_ROLE=P_ROLE_HOST` (requests out, responses in), the parser and decoder of responses alone "
        "(`P_ENABLE_ENCODE=0`) and with the encoders of requests; device: `P_ROLE=P_ROLE_DEVICE` (requests in, "
        "responses out), everything it keeps. small: the host's parser and decoder built smallest "
        "(`P_PARSER_SMALL=1 P_PARSER_WHOLE_FRAMES=0`, frames of the length-byte shape: FEETECH, FashionStar, "
        "Hiwonder).",
        "Reproduce: `.venv/bin/python -m bench.run c`.",
    ]
    if shutil.which("arm-none-eabi-gcc") is None:
        notes.insert(0, "arm-none-eabi-gcc is not installed here: no sizes (apt-get install gcc-arm-none-eabi).")
        return Table("C target: flash and RAM on Cortex-M0+", ["protocol"], [], notes)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        base = _flash(folder, [], [])
        for name in PROTOCOLS:
            up = name.upper()
            src = [str(GENERATED / name / f"{name}.c")]
            common = ["-I", str(GENERATED / name), f"-DPROTO={name}", f"-DPROTO_UPPER={up}", "-include", f"{name}.h"]
            encode = _flash(folder, src, [*common, f"-D{up}_ENABLE_DECODE=0", f"-D{up}_ENABLE_PARSER=0"]) - base
            parse = _flash(folder, src, [*common, f"-D{up}_ENABLE_ENCODE=0"]) - base
            both = _flash(folder, src, common) - base
            host, device = f"-D{up}_ROLE={up}_ROLE_HOST", f"-D{up}_ROLE={up}_ROLE_DEVICE"
            host_parse = _flash(folder, src, [*common, host, f"-D{up}_ENABLE_ENCODE=0"]) - base
            host_all = _flash(folder, src, [*common, host]) - base
            device_all = _flash(folder, src, [*common, device]) - base
            small = ""  # the smallest parser (P_PARSER_SMALL, no whole-frame path), where the protocol has the switch
            if f"#define {up}_PARSER_SMALL " in (GENERATED / name / f"{name}.h").read_text(encoding="utf-8"):
                minimal = [f"-D{up}_ENABLE_ENCODE=0", f"-D{up}_PARSER_SMALL=1", f"-D{up}_PARSER_WHOLE_FRAMES=0"]
                small = str(_flash(folder, src, [*common, host, *minimal]) - base)
            parser_ram, msg_ram = _ram(folder, name)
            sizes_ = [encode, parse, both, host_parse, small, host_all, device_all, parser_ram, msg_ram]
            rows.append([name, *map(str, sizes_), "", ""])
        hand = _flash(folder, [str(HERE / "feetech_handwritten.c")], ["-DHANDWRITTEN"]) - base
        checked = _flash(folder, [str(HERE / "feetech_checked.c")], ["-DCHECKED"]) - base
        feetech = next((r for r in rows if r[0] == "feetech_sms"), None)
        if feetech is not None:  # like with like: a host's parser and decoder of responses, both sides
            host, least = int(feetech[4]), int(feetech[5])
            feetech[-2:] = [f"{host / hand:.2f} (small: {least / hand:.2f})", f"≤ {TARGET:.2f}"]
            rows.append(["feetech, hand-written host parser (bench/c)", "", "", "", str(hand), str(hand), *[""] * 6])
            rows.append(
                [
                    "feetech, hand-written with the spec's checks (bench/c)",
                    *["", "", "", str(checked), str(checked)],
                    *["", "", "", "", f"{host / checked:.2f} (small: {least / checked:.2f})", ""],
                ]
            )
            notes.append(
                f"FEETECH built for a host (responses parsed and decoded): {host / hand:.2f}× the "
                f"hand-written host parser's flash with the default parser, {least / hand:.2f}× with the smallest "
                f"(`P_PARSER_SMALL=1 P_PARSER_WHOLE_FRAMES=0`: {least} B; target ≤ {TARGET}×; "
                f"both directions: {int(feetech[2]) / hand:.2f}×)."
                " The hand-written one (feetech_handwritten.c) frames and checks packets only: no id range, and after"
                " a bad checksum it drops the bytes it held (no resynchronisation inside a candidate); it copies the"
                f" packet with newlib's memcpy (142 B). Against a hand-written parser with the spec's checks"
                f" (feetech_checked.c: the id's range, the length byte, the sum, the reply's fields, no byte lost on a"
                f" failed candidate by shifting its buffer, the counters; {checked} B): {host / checked:.2f}×. That"
                " one still differs from the Python parser where a frame starts inside a candidate waiting for its"
                " bytes (the generated parser finds it when it ends, as Python does; the shift finds it only after the"
                " candidate fails)."
            )
    header = [
        "protocol",
        "encode (B)",
        "parser+decode (B)",
        "all (B)",
        "host parser+decode (B)",
        "host parser+decode, small (B)",
        "host all (B)",
        "device all (B)",
        "parser_t (B)",
        "msg_t (B)",
        "host parser+decode ÷ hand-written",
        "target",
    ]
    return Table("C target: flash and RAM on Cortex-M0+", header, rows, notes)


#: function groups by the name a symbol has after the protocol's prefix (`p_` or `p__`); the first that matches
GROUPS = (
    ("encoders", ("encode", "enc_", "wrap", "put", "l_", "layouts")),
    ("decoders", ("decode", "dec_", "unwrap", "get", "copy", "utf8", "same")),
    ("stream parser", ("parser", "scan", "front", "size", "probe", "frame", "drop", "push", "move", "rule")),
    ("names", ("kind_name", "result_name", "names.")),
)


def _group(symbol: str, prefix: str) -> str:
    name = symbol.removeprefix(prefix).lstrip("_")
    for group, starts in GROUPS:
        if name.startswith(starts):
            return group
    return "checksums and the rest"  # the public checksum functions, their tables, other helpers


def _groups(name: str, compiler: list[str], nm: str, folder: Path) -> list[int]:
    """Bytes per function group of <name>.c compiled alone at -Os (every function and table, nothing linked: a
    static helper the compiler inlines counts in its callers)."""
    obj = folder / f"{name}.o"
    subprocess.run([*compiler, "-c", str(GENERATED / name / f"{name}.c"), "-o", str(obj)], check=True)
    listing = subprocess.run([nm, "-S", "--size-sort", "--radix=d", str(obj)], check=True, capture_output=True)
    sizes = dict.fromkeys([g for g, _ in GROUPS] + ["checksums and the rest"], 0)
    for line in listing.stdout.decode().splitlines():
        _, size, _, symbol = line.split()
        sizes[_group(symbol, name)] += int(size)
    return list(sizes.values())


def groups() -> Table:
    """Flash per function group at -Os: the host's gcc and, where installed, arm-none-eabi-gcc for Cortex-M0+."""
    targets = [("host gcc -Os", ["gcc", "-std=c99", "-Os", "-ffunction-sections", "-fdata-sections"], "nm")]
    notes = [
        "Each protocol's `<p>.c` compiled alone with every switch on (`-Os -ffunction-sections -fdata-sections`), its "
        "symbols' sizes from `nm -S` summed by the name after the protocol's prefix (bench/c_target.py GROUPS): a "
        "static helper the compiler inlines counts in its callers, a table in what reads it (the layout tables in "
        "encoders: the frame engine encodes from them). Nothing is linked: a firmware's flash is the c-size table's.",
        "Reproduce: `make bench-c` (or `.venv/bin/python -m bench.run c-groups`).",
    ]
    if shutil.which("arm-none-eabi-gcc") is None:
        notes.insert(0, "arm-none-eabi-gcc is not installed here: host figures only.")
    else:
        targets.append(("Cortex-M0+ -Os", ["arm-none-eabi-gcc", *ARM], "arm-none-eabi-nm"))
    rows: list[list[str]] = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in PROTOCOLS:
            for target, compiler, nm in targets:
                sizes = _groups(name, compiler, nm, Path(tmp))
                rows.append([name, target, *map(str, sizes), str(sum(sizes))])
    header = ["protocol", "target", *(f"{g} (B)" for g, _ in GROUPS), "checksums and the rest (B)", "total (B)"]
    return Table("C target: flash per function group", header, rows, notes)


def _stream(name: str, kind: str) -> tuple[bytes, str]:
    """About 256 kB of one direction's frames: the spec's examples end to end (clean), 10% with a byte changed
    (corrupt), or nothing but the first header byte (adversarial)."""
    protocol = load_protocol(str(ROOT / "specs" / f"{name}.yaml"))
    direction = Direction.REQUEST
    frames = [e.frame for e in protocol.examples if e.direction == direction]
    header = protocol.framing.layouts[direction].header
    out = bytearray()
    i = 0
    while len(out) < 256_000:
        frame = bytearray(frames[i % len(frames)])
        if kind == "corrupt" and i % 10 == 0:
            frame[len(frame) // 2] ^= 0x5A
        out += frame
        i += 1
    if kind == "adversarial":
        out = bytearray(header[:1] * 256_000)
    return bytes(out), direction.value


def _python_rate(name: str, data: bytes, direction: str) -> float:
    import importlib

    package = importlib.import_module(name)
    started = time.perf_counter()
    rounds = 0
    while time.perf_counter() - started < 0.5:
        parser = package.StreamParser(direction)
        for at in range(0, len(data), 4096):
            parser.feed(data[at : at + 4096])
        rounds += 1
    return len(data) * rounds / (time.perf_counter() - started) / 1e6


ROUNDS = 5
PROBE = 65_536  # bytes of each stream the instruction counts run over


def _instructions(command: list[str], data: bytes, folder: Path) -> float | None:
    """Instructions per byte of one parser over the first PROBE bytes of a stream (valgrind --tool=cachegrind: two
    passes minus none, so reading the file cancels out); None where valgrind is not installed."""
    if shutil.which("valgrind") is None:
        return None
    path = folder / "probe.hex"
    path.write_text(data[:PROBE].hex())

    def count(rounds: int) -> int:
        run = ["valgrind", "--tool=cachegrind", "--cache-sim=no", "--cachegrind-out-file=/dev/null"]
        output = subprocess.run(
            [*run, *command[:1], str(path), str(rounds), *command[1:]], capture_output=True, text=True
        )
        found = re.search(r"I\s+refs:\s+([\d,]+)", output.stderr)
        if found is None:
            raise RuntimeError(f"no instruction count from valgrind: {output.stderr[-300:]}")
        return int(found.group(1).replace(",", ""))

    return (count(2) - count(0)) / (2 * len(data[:PROBE]))


def _rate(command: list[str]) -> float:
    """MB/s that bench/c/throughput.c prints for one run."""
    return float(subprocess.run(command, capture_output=True, text=True, check=True).stdout.split()[0])


def throughput() -> Table:
    rows: list[list[str]] = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        builds = {}
        for name in ("feetech_sms", "dynamixel_p2"):
            exe = folder / f"t_{name}"
            command = [
                "gcc",
                "-std=c99",
                "-D_POSIX_C_SOURCE=199309L",
                "-O2",
                "-I",
                str(GENERATED / name),
                f"-DPROTO={name}",
            ]
            command += [f"-DPROTO_UPPER={name.upper()}", "-include", f"{name}.h", str(HERE / "throughput.c")]
            subprocess.run([*command, str(GENERATED / name / f"{name}.c"), "-o", str(exe)], check=True)
            builds[name] = exe
        hand = folder / "t_hand"
        sources = [str(HERE / "throughput.c"), str(HERE / "feetech_handwritten.c")]
        subprocess.run(
            ["gcc", "-std=c99", "-D_POSIX_C_SOURCE=199309L", "-O2", "-DHANDWRITTEN", *sources, "-o", str(hand)],
            check=True,
        )
        for name, exe in builds.items():
            for kind in ("clean", "corrupt", "adversarial"):
                data, direction = _stream(name, kind)
                path = folder / "stream.hex"
                path.write_text(data.hex())
                rates: list[float] = []
                hand_rates: list[float] = []
                for _ in range(ROUNDS):  # alternating, best of each: a busy machine slows some runs, not the best
                    rates.append(_rate([str(exe), str(path), "20", direction]))
                    if name == "feetech_sms":
                        hand_rates.append(_rate([str(hand), str(path), "20"]))
                row = [name, kind, f"{max(rates):.1f}", "", f"{_python_rate(name, data, direction):.1f}"]
                if hand_rates:
                    row[3] = f"{max(hand_rates):.1f}"
                    row.append(f"{max(rates) / max(hand_rates):.2f}")
                else:
                    row.append("")
                ours = _instructions([str(exe), direction], data, folder)
                theirs = _instructions([str(hand)], data, folder) if name == "feetech_sms" else None
                row.append("" if ours is None else f"{ours:.1f}")
                row.append("" if theirs is None else f"{theirs:.1f}")
                row.append("" if ours is None or theirs is None else f"{theirs / ours:.2f}")
                rows.append(row)
    notes = [
        "MB/s of stream parsed: the generated C parser (gcc -O2, p_parser_feed), the hand-written FEETECH state "
        "machine (bench/c/feetech_handwritten.c) and the Python StreamParser (4 kB reads) on the same bytes; the C "
        f"parsers best of {ROUNDS} alternating runs of 20 passes each.",
        "clean: the spec's request examples end to end; corrupt: every 10th frame with a byte changed; adversarial: "
        "the first header byte repeated.",
        f"instr/B: instructions per byte (valgrind cachegrind, the first {PROBE // 1024} kB of the stream, two passes "
        "minus none): the load on a shared machine does not change them; the last column is the speed ratio they give.",
        "The generated parser takes a whole frame at once when it holds no byte and no other header lies inside the "
        "frame (length-byte frames: also when it holds fewer bytes than a header, none beginning one, and a corrupt "
        "whole frame is counted at once; a run of the header's byte in which every candidate is no frame, FEETECH's "
        "adversarial stream, is skipped at once). Otherwise, for length-byte frames (FEETECH: header, id, length byte, "
        "content, sum), it keeps per byte "
        "held whether a candidate starts there, whether its size is known and whether it is corrupt behind one that "
        "waits, and looks back over the bytes held only when a candidate ends with the byte or the one at the front "
        "turns out to be no frame (the adversarial stream: a candidate at every byte, each no frame once its first "
        "bytes come: an id of FF); other framings (DYNAMIXEL) take the general scan, which rescans the bytes held when "
        "a held candidate can be judged or a header comes. Both give the Python parser's results, byte for byte, "
        "however the stream is cut; the hand-written one does not rescan, and loses the frames a stray header hides.",
    ]
    header = [
        "protocol",
        "stream",
        "generated C (MB/s)",
        "hand-written C (MB/s)",
        "Python (MB/s)",
        "generated ÷ hand",
        "generated (instr/B)",
        "hand-written (instr/B)",
        "speed by instr (hand ÷ generated)",
    ]
    return Table("C target: parse throughput on this host", header, rows, notes)
