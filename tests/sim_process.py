"""A real `serialspec sim` subprocess serving virtual devices on a pseudo-terminal, for the device tests."""

from __future__ import annotations

import signal
import subprocess
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


@contextmanager
def serve(spec: str, *ids: int, options: Sequence[str] = ()) -> Iterator[str]:
    """Start `serialspec sim SPEC --id N... OPTIONS`, yield the device path it prints first, stop it with SIGTERM."""
    args = [sys.executable, "-m", "serialspec", "sim", str(ROOT / "specs" / spec), "--quiet", *options]
    for device_id in ids:
        args += ["--id", str(device_id)]
    process = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert process.stdout is not None
        path = process.stdout.readline().strip()
        assert path.startswith("/dev/"), (
            f"sim printed {path!r}; stderr: {process.stderr.read() if process.stderr else ''}"
        )
        yield path
    finally:
        process.send_signal(signal.SIGTERM)
        try:
            # it stops within 0.2 s here, also beside busy loops; 15 s leaves room for a CI machine that runs the
            # suite's other processes on the same 2 cores (5 s was once not enough there)
            code = process.wait(15)
        except subprocess.TimeoutExpired:
            process.kill()  # say what it was doing rather than leave it behind
            _, err = process.communicate(timeout=5)
            raise AssertionError(f"sim still running 15 s after SIGTERM; stderr: {err}") from None
        assert code == 0, f"sim exited with {code}"
