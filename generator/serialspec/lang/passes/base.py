"""What every pass shares: the context earlier passes fill in, and the helpers that report problems.

A pass has one job. It reads the loaded document and what earlier passes resolved (the `Context`), records what it
resolves there, and returns its problems; `serialspec.lang.resolve` runs the passes in order.
"""

from __future__ import annotations

import builtins
import keyword
import math
import re
import sys
from dataclasses import field
from typing import Any, Literal

from serialspec.encodings.low_bits import LowBits
from serialspec.lang import grammar
from serialspec.lang.errors import SpecError, listed, type_hint
from serialspec.lang.frozen import mutable
from serialspec.lang.loader import Located, Path, dotted
from serialspec.lang.model import (
    SCALARS,
    Command,
    Device,
    EnumDef,
    Erratum,
    ErrorReply,
    Example,
    FlagsDef,
    Framing,
    ScalarType,
    Serial,
    Table,
    TextFrame,
)

NAME = re.compile(r"^[a-z][a-z0-9_]*$")
LABEL = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")

# --- reserved names: every name generated code uses itself, so that no spec name can shadow one -----------------

# Attribute and parameter names the generated classes and methods use themselves.
RESERVED_NAMES = frozenset({"to_fields", "from_fields", "self", "cls"})
# A field is also a parameter of a client method, whose body has these locals and calls these builtins (a parameter
# of the same name would shadow them); `id`, a usual address field, is a builtin generated code never calls.
RESERVED_FIELD_NAMES = (
    RESERVED_NAMES
    | {"request", "reply", "replies"}
    | {
        "any",
        "bool",
        "bytearray",
        "bytes",
        "classmethod",
        "dict",
        "float",
        "frozenset",
        "getattr",
        "hasattr",
        "int",
        "isinstance",
        "iter",
        "len",
        "list",
        "next",
        "object",
        "str",
        "sum",
        "super",
        "tuple",
    }
)
# Names the generated modules (messages, codec, client, simulator, registers, __init__) import or define next to
# the classes a spec names, and Python's capitalised builtins: a generated class of the same name would shadow one.
GENERATED_CLASS_NAMES = frozenset(
    {
        "Any",
        "AsyncBus",
        "AsyncClientBase",
        "AsyncIterator",
        "Binding",
        "Bus",
        "Callable",
        "ChecksumError",
        "ClassVar",
        "ClientBase",
        "CommandSpec",
        "CorruptReply",
        "DecodeError",
        "DeviceError",
        "EchoMismatch",
        "DeviceSpec",
        "Direction",
        "EncodeError",
        "EntrySpec",
        "FrameFormat",
        "IntEnum",
        "IntFlag",
        "Iterable",
        "Iterator",
        "KindSpec",
        "Literal",
        "Mapping",
        "Message",
        "PortError",
        "RangeError",
        "Register",
        "RegisterMap",
        "Self",
        "SerialSettings",
        "SerialspecError",
        "Simulator",
        "StreamParser",
        "Timeout",
        "TransportError",
    }
    | {name for name in dir(builtins) if name[:1].isupper()}
)
# Module-level constants of the generated package.
GENERATED_CONSTANTS = frozenset(
    {
        "BAUDRATE",
        "BINDING",
        "CONTENTS",
        "DEVICE",
        "MATCH_BY",
        "MESSAGE_TYPES",
        "PROTOCOL",
        "REQUEST_FORMAT",
        "REQUEST_FRAME",
        "RESPONSE_FORMAT",
        "RESPONSE_FRAME",
        "SERIAL",
        "SIMULATOR",
        "SPEC",
    }
)
# A protocol's name is its package's: it must not shadow a module the generated code (or anything) imports.
RESERVED_PACKAGES = frozenset(sys.stdlib_module_names) | {
    "construct",
    "docs",  # generated/docs holds the markdown references
    "jinja2",
    "serial",
    "serialspec",
    "yaml",
}


def enum_span(enum: EnumDef, low: float, high: float) -> tuple[float, float]:
    """The range of a value an enum names when the spec gives none: its declared values' span (within the type)."""
    values = [v.value for v in enum.values]
    return (max(low, min(values)), min(high, max(values))) if values else (low, high)


def camel(*parts: str) -> str:
    return "".join(word.capitalize() for part in parts for word in part.split("_") if word)


@mutable
class Context:
    """The document being resolved and everything resolved from it so far."""

    doc: Located
    structural: set[Path] = field(default_factory=set)  # paths the structural check found malformed
    # Names of definitions (fields, enums, tables, commands, ...) that failed to resolve, their problem reported:
    # a reference to one is not reported again.
    broken: set[str] = field(default_factory=set)
    reported: set[Path] = field(default_factory=set)  # where every problem so far was reported
    class_names: dict[str, tuple[Path, object]] = field(default_factory=dict)
    endian: Literal["<", ">"] = "<"
    shared_fields: dict[str, Any] = field(default_factory=dict)
    name: str = ""
    client_class: str = ""
    simulator_class: str = ""
    serial: Serial | None = None
    matching: tuple[str, ...] = ()
    matching_description: str = ""
    enums: dict[str, EnumDef] = field(default_factory=dict)
    flags: dict[str, FlagsDef] = field(default_factory=dict)
    tables: dict[str, Table] = field(default_factory=dict)
    framing: Framing | None = None
    commands: list[Command] = field(default_factory=list)
    errata: tuple[Erratum, ...] = ()
    examples: tuple[Example, ...] = ()
    device: Device | None = None
    error_reply: ErrorReply | None = None
    text: TextFrame | None = None  # framing kind text

    @property
    def data(self) -> Any:
        return self.doc.data

    def malformed_near(self, path: Path) -> bool:
        """The structural check reported a value at, inside or around path, or in a shared field (used anywhere)."""
        return any(
            bad[: len(path)] == path or path[: len(bad)] == bad or bad[:1] == ("fields",) for bad in self.structural
        )


# The mappings whose keys name definitions other parts of a spec refer to.
DEFINITIONS = frozenset({"fields", "enums", "flags", "tables", "commands", "subcommands", "examples", "errata"})


class Bad(Exception):
    """A value could not be resolved; its problem is already recorded."""


class Pass:
    """One resolution step: `run()` does its job and returns the problems it found."""

    def __init__(self, ctx: Context) -> None:
        self.ctx = ctx
        self.problems: list[SpecError] = []

    def run(self) -> list[SpecError]:
        raise NotImplementedError

    # --- what earlier passes resolved -----------------------------------------------------------------------------

    @property
    def doc(self) -> Located:
        return self.ctx.doc

    @property
    def endian(self) -> Literal["<", ">"]:
        return self.ctx.endian

    @property
    def enums(self) -> dict[str, EnumDef]:
        return self.ctx.enums

    @property
    def flags(self) -> dict[str, FlagsDef]:
        return self.ctx.flags

    @property
    def tables(self) -> dict[str, Table]:
        return self.ctx.tables

    @property
    def shared_fields(self) -> dict[str, Any]:
        return self.ctx.shared_fields

    def section(self, key: str) -> dict[Any, Any]:
        """A top-level mapping of the spec; empty when missing or malformed (the structural check reports that)."""
        value = self.ctx.data.get(key)
        return value if isinstance(value, dict) else {}

    # --- reporting ------------------------------------------------------------------------------------------------

    def error(self, path: Path, message: str) -> None:
        if any(path[: len(bad)] == bad for bad in self.ctx.structural):
            return  # already reported by the structural check
        self.ctx.reported.add(path)
        self.problems.append(self.doc.error(path, message))

    def fail(self, path: Path, message: str) -> Bad:
        self.error(path, message)
        return Bad()

    def guard(self, path: Path, function: Any, *args: Any) -> Any:
        """Resolve the value at path with function(*args); None if it cannot be (its problem is recorded).

        Only a value the structural check has already reported may fail unexpectedly; anything else is a bug in
        serialspec and is raised, never swallowed.
        """
        try:
            return function(*args)
        except Bad:
            pass
        except (TypeError, AttributeError, ValueError, LookupError, OverflowError):
            if not self.ctx.malformed_near(path):
                raise
        if len(path) >= 2 and path[-2] in DEFINITIONS and isinstance(path[-1], str):
            self.ctx.broken.add(path[-1])
        if path[-1:] in (("request",), ("response",)) and len(path) >= 3:  # a message: its command is broken
            self.ctx.broken.add(str(path[-2]) if path[0] != "commands" or len(path) == 3 else f"{path[1]}.{path[3]}")
        return None

    # --- names and references -------------------------------------------------------------------------------------

    def name(
        self,
        value: str,
        path: Path,
        what: str = "name",
        reserved: frozenset[str] = RESERVED_NAMES,
        keywords: bool = False,
    ) -> str:
        """A name the spec gives; `keywords`: a Python keyword is allowed (a field: generated Python calls it
        `class_`, see lang/names.py), and a keyword with an underscore after it is not (that is its Python name)."""
        if not isinstance(value, str) or not NAME.match(value):
            self.error(
                path,
                f"{what} {value!r} must be a lower-case identifier (a-z, 0-9, _; starting with a letter)",
            )
        elif keywords and value.endswith("_") and keyword.iskeyword(value[:-1]):
            self.error(path, f"{what} {value!r} is the Python name of a field {value[:-1]!r}: call it {value[:-1]!r}")
        elif (keyword.iskeyword(value) and not keywords) or value in reserved:
            self.error(path, f"{what} {value!r} is reserved (a Python keyword or a name generated code uses)")
        return str(value)

    def class_name(self, name: str, path: Path, identity: object = None, scoped: bool = False) -> str:
        """Register a generated class (or constant) name; the same name may be reused only for the same definition.
        `scoped`: a field's class (bit fields, group items) whose name another definition has taken is named after
        its place instead (`ProbeResponse` + `FlagsBits`), so two messages may both have a `flags` field."""
        class_names = self.ctx.class_names
        if name in GENERATED_CLASS_NAMES or name in GENERATED_CONSTANTS:
            self.error(path, f"generated name {name} would shadow the {name} that generated code uses; rename it")
            return name
        if name in class_names:
            other_path, other_identity = class_names[name]
            if other_path != path and (identity is None or identity != other_identity):
                place = [p for p in path[:-1] if isinstance(p, str) and p not in ("commands", "subcommands", "fields")]
                if scoped and place:
                    return self.class_name(camel(*place) + name, path, identity)
                self.error(path, f"generated class name {name} is already used by {dotted(other_path)}")
            return name
        class_names[name] = (path, identity)
        return name

    def client_class_name(self, name: str, path: Path) -> str:
        """Register a class of the generated client, and its asyncio twin `Async<name>` (aio.py) with it."""
        name = self.class_name(name, path)
        self.class_name(f"Async{name}", path)
        return name

    def reference(self, kind: str, registry: dict[str, Any], value: Any, path: Path) -> Any:
        if value is None:
            return None
        if value not in registry:
            if value in self.ctx.broken:
                raise Bad  # defined, but it failed to resolve: its own problem is reported
            known = listed(registry)
            raise self.fail(path, f"unknown {kind} {value!r} (expected one of: {known})")
        return registry[value]

    # --- types and ranges -----------------------------------------------------------------------------------------

    def scalar_type(self, value: Any, path: Path, allow_float: bool = True, for_field: bool = False) -> ScalarType:
        """A wire type by name: one of a field's (`for_field`), or of a frame element, enum, flags or table entry."""
        names = grammar.FIELD_SCALAR_TYPES if for_field else grammar.SCALAR_TYPES
        found = SCALARS.get(value) if isinstance(value, str) and value in names else None
        if found is None or (found.is_float and not allow_float):
            choices = [n for n in names if allow_float or not SCALARS[n].is_float]
            raise self.fail(path, f"unknown type {value!r} ({type_hint(value)}expected one of {', '.join(choices)})")
        return found

    def stored(self, scalar: ScalarType, sign_magnitude: bool, path: Path) -> ScalarType:
        """The wire type of a value: a sign-magnitude value is an unsigned word of its size (the sign is one of its
        bits), whether the spec names the signed or the unsigned type."""
        if not sign_magnitude:
            return scalar
        if scalar.is_float:
            self.error(path, f"encoding sign_magnitude is for integers, not {scalar.name}")
            return scalar
        return SCALARS[f"u{scalar.size * 8}"]

    def bounds(
        self,
        scalar: ScalarType,
        sign_magnitude: bool,
        given: Any,
        path: Path,
        sign_bit: int | None = None,
        low_bits: LowBits | None = None,
    ) -> tuple[float, float]:
        if sign_magnitude:
            limit = (1 << (sign_bit if sign_bit is not None else scalar.size * 8 - 1)) - 1
            low, high = float(-limit), float(limit)
        elif low_bits is not None:
            low, high = (
                float(low_bits.low(scalar.size, scalar.signed)),
                float(low_bits.high(scalar.size, scalar.signed)),
            )
        else:
            low, high = scalar.minimum, scalar.maximum
        if given is None:
            return low, high
        given_low, given_high = given
        if given_low > given_high:
            self.error(path, f"range [{given_low}, {given_high}] is empty")
        fractions = [b for b in given if isinstance(b, float) and math.isfinite(b) and not b.is_integer()]
        if fractions and not scalar.is_float:  # a bound between two values: C and Python would round it apart
            self.error(path, f"range bound {fractions[0]} is no whole number: a {scalar.name} holds whole numbers")
        if given_low < low or given_high > high:
            what = f"{scalar.name} {low_bits.name}" if low_bits is not None else scalar.name
            self.error(path, f"range [{given_low}, {given_high}] does not fit {what} ({low:g}..{high:g})")
        return given_low, given_high
