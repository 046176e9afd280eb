"""The small hand-written runtime that generated packages import: errors, framing, hex input (and the checksum
functions from serialspec/checksums/, which the runtime wheel ships too)."""
