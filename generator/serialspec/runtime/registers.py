"""Register maps: named registers at byte addresses, packed into and out of the runs of bytes a device reads and writes.

A protocol whose READ and WRITE carry raw bytes "from address N on" (FEETECH's control table) gets a generated
`RegisterMap` per table; clients use it to read and write registers by name, the virtual device to keep its
memory, and both refuse a bad name, a read-only register or an out-of-range value before a byte is sent.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, replace

from serialspec.runtime.errors import DecodeError, EncodeError, out_of_range


@dataclass(frozen=True, slots=True)
class Register:
    """One register: its address, wire type (a struct format character), range and access."""

    name: str
    address: int
    format: str  # struct character of the wire type, e.g. "H"
    minimum: float
    maximum: float
    access: str = "rw"  # "r" (read-only) or "rw"
    sign_bit: int | None = None  # sign-magnitude: the bit holding the sign

    @property
    def size(self) -> int:
        return struct.calcsize(self.format)

    @property
    def end(self) -> int:
        return self.address + self.size


class RegisterMap:
    """The registers of one table, by name and by address, with the table's byte order."""

    def __init__(self, table: str, registers: Iterable[Register], byte_order: str) -> None:
        self.table = table
        self.registers = tuple(sorted(registers, key=lambda r: r.address))
        self.by_name = {r.name: r for r in self.registers}
        self.by_address = {r.address: r for r in self.registers}
        self._endian = ">" if byte_order == "big" else "<"
        self._structs = {r.name: struct.Struct(self._endian + r.format) for r in self.registers}
        self._readers: dict[str, tuple[int, int, Callable[[bytes], int]]] = {}

    def __getitem__(self, name: str) -> Register:
        register = self.by_name.get(name)
        if register is None:
            raise EncodeError(f"{self.table}: unknown register {name!r}")
        return register

    def __contains__(self, name: object) -> bool:
        return name in self.by_name

    def span(self, names: Iterable[str]) -> tuple[int, int]:
        """The first address and the byte count of one read that covers every named register."""
        if isinstance(names, tuple) and len(names) == 1:  # one register: the usual read
            register = self[names[0]]
            return register.address, self._structs[register.name].size
        chosen = [self[name] for name in names]
        if not chosen:
            raise EncodeError(f"{self.table}: name at least one register")
        start = min(r.address for r in chosen)
        return start, max(r.end for r in chosen) - start

    # --- values <-> bytes -----------------------------------------------------------------------------------------

    def to_wire(self, register: Register, value: int, checked: bool = True) -> bytes:
        """One value as the register's bytes, refused (naming the register and its range) when it does not fit.

        `checked` False: only the type's bounds apply (a device reporting its memory, whose model's range may be
        wider than the table's)."""
        if isinstance(value, bool) or not isinstance(value, int):
            raise EncodeError(f"{register.name} must be an integer, got {value!r}")
        if checked and not register.minimum <= value <= register.maximum:
            raise out_of_range(self.table, register.name, value, register.minimum, register.maximum)
        if register.sign_bit is not None and value < 0:
            value = -value | 1 << register.sign_bit
        return self._structs[register.name].pack(value)

    def from_wire(self, register: Register, data: bytes, offset: int = 0) -> int:
        (value,) = self._structs[register.name].unpack_from(data, offset)
        if register.sign_bit is not None and value >> register.sign_bit & 1:
            return -int(value & ((1 << register.sign_bit) - 1))
        return int(value)

    def size(self, register: Register) -> int:
        """The register's size in bytes (without working it out from its format again)."""
        return self._structs[register.name].size

    def value(self, register: Register, data: bytes) -> int:
        """The register's value from the bytes read for it alone; fewer bytes than it holds is a DecodeError."""
        if len(data) < self._structs[register.name].size:
            raise DecodeError(f"{register.name}: {len(data)} bytes read, {self._structs[register.name].size} needed")
        return self.from_wire(register, data)

    def reader(self, name: str) -> tuple[int, int, Callable[[bytes], int]]:
        """Reading one register by name, worked out once: its address, its size, and `value` from the bytes read
        for it alone (a DecodeError when fewer bytes came). An unknown name is an EncodeError."""
        found = self._readers.get(name)
        if found is None:
            register = self[name]
            layout = self._structs[name]
            found = self._readers[name] = (register.address, layout.size, _value(name, layout, register.sign_bit))
        return found

    def unpack(self, start: int, data: bytes) -> dict[str, int]:
        """Bytes read from address `start` on, by register name; bytes that belong to no whole register by address."""
        values: dict[str, int] = {}
        address, offset, end = start, 0, len(data)
        by_address, structs = self.by_address, self._structs
        while offset < end:
            register = by_address.get(address)
            size = structs[register.name].size if register is not None else 0
            if register is None or offset + size > end:
                values[f"{address:#04x}"] = data[offset]
                address, offset = address + 1, offset + 1
                continue
            values[register.name] = self.from_wire(register, data, offset)
            address, offset = address + size, offset + size
        return values

    def pack(self, values: Mapping[str, int], *, writable: bool = True) -> tuple[int, bytes]:
        """Named values as one run of bytes and its first address; the registers must follow each other."""
        chosen = sorted((self[name] for name in values), key=lambda r: r.address)
        if not chosen:
            raise EncodeError(f"{self.table}: name at least one register to write")
        data = bytearray()
        for before, register in zip([None, *chosen], chosen, strict=False):
            if writable and register.access == "r":
                raise EncodeError(f"{register.name} is read-only")
            if before is not None and before.end != register.address:
                raise EncodeError(
                    f"{before.name} ({before.address:#04x}) and {register.name} ({register.address:#04x}) are not "
                    f"adjacent registers: one write takes one run of registers, so write them separately"
                )
            data += self.to_wire(register, values[register.name])
        return chosen[0].address, bytes(data)

    def for_model(self, model: str, ranges: Mapping[str, tuple[float, float]]) -> RegisterMap:
        """The same registers with one device model's ranges where they differ (spec: device.models)."""
        registers = [
            replace(r, minimum=ranges[r.name][0], maximum=ranges[r.name][1]) if r.name in ranges else r
            for r in self.registers
        ]
        endian = "big" if self._endian == ">" else "little"
        return RegisterMap(f"{self.table} ({model})", registers, endian)

    def split(self, start: int, data: bytes) -> dict[str, int]:
        """Bytes written from address `start` on as register values; refused unless they cover whole registers."""
        values = self.unpack(start, data)
        stray = [name for name in values if name not in self.by_name]
        if stray:
            raise EncodeError(f"{self.table}: bytes at {', '.join(stray)} are not whole registers")
        return values


class ModelRegisters:
    """Which model's ranges a client checks writes against: `model` None (the table's own ranges), one model name
    for every device, or device address -> model name (a bus of mixed models; other addresses get the table's
    ranges, and a broadcast write must suit every model named and the table)."""

    def __init__(
        self,
        model: str | Mapping[int, str] | None,
        table: RegisterMap,
        models: Mapping[str, RegisterMap],
        broadcast: int | None,
    ) -> None:
        chosen = [] if model is None else [model] if isinstance(model, str) else list(model.values())
        for name in chosen:
            if name not in models:
                raise ValueError(f"model {name!r} is not one of the spec's models ({', '.join(models)})")
        self.table = table
        self.one = models[model] if isinstance(model, str) else None
        self.by_address = {a: models[n] for a, n in model.items()} if isinstance(model, Mapping) else {}
        self.broadcast = broadcast

    def maps(self, address: int) -> list[RegisterMap]:
        if self.one is not None:
            return [self.one]
        if address == self.broadcast and self.by_address:
            return [self.table, *{id(m): m for m in self.by_address.values()}.values()]
        return [self.by_address.get(address, self.table)]

    def pack(self, address: int, values: Mapping[str, int]) -> tuple[int, bytes]:
        """`RegisterMap.pack` with the ranges of the model at `address` (of every model, for a broadcast)."""
        first, *others = self.maps(address)
        packed = first.pack(values)
        for other in others:
            other.pack(values)
        return packed


def _value(name: str, layout: struct.Struct, sign_bit: int | None) -> Callable[[bytes], int]:
    """RegisterMap.value of one register as one call (what `from_wire` does, worked out for that register)."""
    unpack, size = layout.unpack_from, layout.size
    magnitude = (1 << sign_bit) - 1 if sign_bit is not None else -1
    integral = layout.format[-1] in "bBhHiIlLqQ"  # unpacked as an int already

    def value(data: bytes) -> int:
        if len(data) < size:
            raise DecodeError(f"{name}: {len(data)} bytes read, {size} needed")
        number: int = unpack(data)[0]
        if not integral:
            number = int(number)  # as from_wire does
        if sign_bit is not None and number >> sign_bit & 1:  # sign-magnitude: the sign bit set is negative
            return -(number & magnitude)
        return number

    return value
