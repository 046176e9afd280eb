"""Drive a virtual Fashion Star servo with the generated client: no hardware needed (`make demo`).

Starts `serialspec sim specs/fashionstar_uart.yaml --id 1 --id 2` on a pseudo-terminal, then talks to it.
Everything is in wire units, as in the spec: angles in 0.1°, times in ms, voltages in mV.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

from serialspec_protocols.fashionstar_uart.client import FashionstarUartClient

SPEC = Path(__file__).resolve().parent.parent / "specs" / "fashionstar_uart.yaml"


def main() -> int:
    sim = subprocess.Popen(
        [sys.executable, "-m", "serialspec", "sim", str(SPEC), "--id", "1", "--id", "2"],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert sim.stdout is not None
        port = sim.stdout.readline().strip()
        print(f"virtual servos 1 and 2 on {port}")
        with FashionstarUartClient(port, timeout=0.2) as servo:
            print("ping 1:", servo.ping(1), "| ping 5:", servo.ping(5))
            print("voltage of 1:", servo.read_parameter(1, "voltage"), "mV")
            started = time.perf_counter()
            angle = servo.read_angle(1)
            print(f"angle of 1: {angle} (0.1°), read in {(time.perf_counter() - started) * 1000:.1f} ms")
            servo.rotate(1, 900, 500)  # 90.0° in 500 ms
            for _ in range(6):
                time.sleep(0.1)
                print("  moving:", servo.read_angle(1))
            servo.write_parameter(2, "response_switch", 1)
            print("rotate 2 with the response switch on:", servo.rotate(2, -450, 200))
            print("angle of 2:", servo.read_angle(2))
            print("user block of 2:", servo.read_batch_data(2))
    finally:
        sim.send_signal(signal.SIGTERM)
        sim.wait(5)
    return 0


if __name__ == "__main__":
    sys.exit(main())
