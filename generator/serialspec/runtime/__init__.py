"""The small hand-written runtime that generated packages import: checksums, errors, framing, hex input."""
