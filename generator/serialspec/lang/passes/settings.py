"""The protocol's own settings: its name, byte order, serial line, shared fields and how replies are matched."""

from __future__ import annotations

from serialspec.lang.errors import SpecError
from serialspec.lang.model import Serial
from serialspec.lang.passes.base import RESERVED_PACKAGES, Pass, camel


class Settings(Pass):
    """Resolve `protocol`, `byte_order`, `fields:` (kept for the commands pass to expand), `serial:`, `matching:`."""

    def run(self) -> list[SpecError]:
        data = self.ctx.data
        name = self.ctx.name = self.name(data.get("protocol", ""), ("protocol",), "protocol")
        if name in RESERVED_PACKAGES:
            self.error(("protocol",), f"protocol {name!r} would shadow the module {name!r} (pick another package name)")
        # the client and simulator classes take the protocol's name: no enum, message or group may take theirs
        self.ctx.client_class = self.client_class_name(camel(name, "client"), ("protocol",))
        self.ctx.simulator_class = self.class_name(camel(name, "simulator"), ("protocol",))
        self.ctx.endian = ">" if data.get("byte_order") == "big" else "<"
        framing = data.get("framing")
        if "byte_order" not in data and not (isinstance(framing, dict) and framing.get("kind") == "text"):
            self.error((), "missing key 'byte_order' (every binary protocol needs one)")
        self.ctx.shared_fields = self.section("fields")
        serial = data.get("serial") or {}
        if isinstance(serial, dict):
            self.ctx.serial = self.guard(("serial",), self.serial, serial)
        matching = self.section("matching")
        by = matching.get("by")
        self.ctx.matching = tuple(name for name in by if isinstance(name, str)) if isinstance(by, list) else ()
        self.ctx.matching_description = str(matching.get("description", ""))
        return self.problems

    def serial(self, serial: dict[str, object]) -> Serial:
        rates = serial.get("baudrates")
        if isinstance(rates, list) and rates:
            if len(set(rates)) != len(rates):
                self.error(("serial", "baudrates"), "a rate is listed twice")
            if serial.get("baudrate") not in rates:
                self.error(("serial", "baudrates"), f"the default rate {serial.get('baudrate')} is not among them")
        return Serial(
            baudrate=int(serial.get("baudrate", 0)),  # type: ignore[call-overload]
            bytesize=int(serial.get("bytesize", 8)),  # type: ignore[call-overload]
            parity=str(serial.get("parity", "none")),
            stopbits=float(serial.get("stopbits", 1)),  # type: ignore[arg-type]
            notes=str(serial.get("notes", "")),
            baudrates=tuple(int(rate) for rate in serial.get("baudrates") or ()),  # type: ignore[attr-defined]
        )
