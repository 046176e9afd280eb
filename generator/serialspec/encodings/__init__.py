"""Integer encodings beyond plain two's complement (a field's `encoding:`), one module each owning its grammar text,
validation, runtime and the code of every backend: `low_bits` (an integer a few bits a byte: `seven_bit`, Pololu
Maestro, MIDI; `nibbles`, Sony VISCA); `seven_bit` (text of 14-bit characters); `varint`
(as many bytes as the value needs: LEB128/protobuf, zigzag, Kangaroo, MIDI's variable-length quantities); `bit_run`
(bit fields of any width, `u12`, `i38`, packed highest bit first into runs of whole bytes: RTCM 3). The package
imports nothing of the generator; the runtime wheel ships it (generated structs import its construct adapters).
`sign_magnitude` predates it and is still spread over the passes and backends (a candidate to move here)."""
