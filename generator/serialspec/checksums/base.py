"""What every checksum algorithm is: the base class of the registry (see __init__.py) and the plain data it speaks.

An algorithm is a value, a frozen dataclass of its parameters (`Sum(width=8, invert=True)`), made from a spec's
checksum element by `from_spec`. Its class owns all that the algorithm means to every part of serialspec:

- the language: its `algorithm:` name, the element keys it owns (`keys`, as plain data that lang/grammar.py turns
  into the grammar, the JSON Schema and docs/language.md), their validation (`from_spec`);
- the runtime: `function()`, the checksum of bytes, and `function_code()`, how generated code makes the same
  function (the runtime function lives in the algorithm's module, which imports nothing of the generator: the
  runtime wheel ships this package);
- the Python backend: module-level set-up and statements for straight-line codecs (`python_setup`, `python_call`,
  `python_lines`), and optional fast paths (`byte_total`, `frame_test`, `summed`, `byte_table`: None where the
  algorithm has none);
- the C backend: `c_code(prefix)`, the algorithm as an incremental C99 function (NoCode where it has none yet);
- the markdown backend: `describe()`, `parameters()` and `worked(covered)` for the checksum section;
- the Wireshark backend: `lua_function()` and `lua_parameters()`, the dissector's Lua code of the algorithm;
- tests: `samples`, one per documented option, which tests/test_matrix.py runs through every output.

A new algorithm is one module of this package with one subclass that sets `name`: it is found by `algorithms()`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from serialspec.runtime.values import dataclass, field

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any, ClassVar, Literal

Import = tuple[str, str]  # generated code's `from <module> import <name>` (the name may be `x as _y`)
Report = Callable[[tuple[str, ...], str], None]  # a problem with the spec: keys below the element, message


class NoCode(Exception):
    """The algorithm (with these parameters) has no code for a backend yet: one line naming what (the C target
    refuses the spec with it)."""


class ChecksumProblem(Exception):
    """A checksum element the algorithm cannot be made from: keys below the element, and a one-line reason."""

    def __init__(self, keys: tuple[str, ...], message: str) -> None:
        super().__init__(message)
        self.keys = keys
        self.message = message


@dataclass(frozen=True)
class Key:
    """A key of the checksum element that an algorithm owns: its shape, as lang/grammar.py's shapes take it."""

    name: str
    kind: Literal["bool", "int", "str", "object"]
    description: str
    default: Any = None
    example: Any = None  # shown in the language reference where no spec uses the key
    minimum: int | None = None
    maximum: int | None = None
    keys: tuple[Key, ...] = ()  # an object's keys
    required: tuple[str, ...] = ()  # an object's required keys


@dataclass(frozen=True)
class Sample:
    """One documented option of an algorithm, as a spec writes it: the element's type and the algorithm's keys."""

    label: str
    type: str
    keys: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class TableSteps:
    """A checksum that python_lines computes by `target = table[target ^ byte]` over the covered bytes: the table's
    name in the generated module, its entries, the value before the first byte, and the statements after the last
    (into `target`)."""

    table: str
    entries: tuple[int, ...]
    start: int
    finish: tuple[str, ...] = ()


@dataclass(frozen=True)
class CCode:
    """A checksum as C99: a public, incremental function `acc = name(acc, data, n)` (a firmware author checksums a
    frame in pieces with it; the generated frame engine calls the same code), its start value and its final step."""

    name: str  # the public function's name, prefixed
    ctype: str  # the accumulator's C type
    definition: str  # the function's C text (a comment saying what it computes first)
    prototype: str
    start: str  # C expression of the accumulator's start value
    finish: str  # C expression of the checksum from the accumulator (a str.format template with {a}); it may call
    # `<prefix>__reflect(value, width)`, the low `width` bits of value in reverse order, which the C backend defines
    reflects: bool = False  # finish calls <prefix>__reflect (the backend writes it only then)


def c_finish(sign: str, whole: int) -> str:
    """The C finish (a str.format template with {a}) of an accumulator inverted ("~"), negated ("-") or kept (""),
    within the bits of `whole` (the width's mask, ANDed with a `mask:`)."""
    if not sign and whole == 0xFFFFFFFF:
        return "(uint32_t)({a})"
    return f"({sign}(uint32_t)({{a}}) & 0x{whole:x}u)"


def c_uint(width: int) -> str:
    """The narrowest C unsigned type of at least `width` bits (up to 32)."""
    return "uint8_t" if width <= 8 else "uint16_t" if width <= 16 else "uint32_t"


# Keys more than one algorithm owns: how the result is finished (`finish` below), after the bytes are taken in.
INVERT = Key("invert", "bool", "sum, xor: the result bitwise inverted (one's complement).", default=False)
MASK = Key(
    "mask",
    "int",
    "sum, xor: ANDed with the result, after `invert` or `negate` (HerkuleX: 0xFE clears bit 0).",
    example=0xFE,
    minimum=1,
)


def finish(value: int, width: int, invert: bool, negate: bool, mask: int | None) -> int:
    """A result inverted (one's complement) or negated (two's complement) within `width` bits, then masked."""
    if invert:
        value = ~value
    elif negate:
        value = -value
    return value & ((1 << width) - 1) & (mask if mask is not None else -1)


def finish_problem(raw: Mapping[str, Any], width: int) -> ChecksumProblem | None:
    """Why `invert`, `negate` and `mask` of a checksum element of `width` bits do not go together, or None."""
    if raw.get("invert") and raw.get("negate"):
        return ChecksumProblem(("negate",), "give `invert` (one's complement) or `negate` (two's complement), not both")
    mask = raw.get("mask")
    if mask is not None and not 0 < mask < 1 << width:
        return ChecksumProblem(("mask",), f"mask {mask:#x} does not fit the checksum's {width} bits")
    return None


_REGISTERED: dict[str, type[Algorithm]] = {}


class Algorithm:
    """A checksum algorithm with its parameters. Subclasses are frozen dataclasses that set the class variables."""

    name: ClassVar[str]  # the `algorithm:` value
    registered: ClassVar[bool] = True  # False: not an `algorithm:` of its own (seed.Seeded wraps one)
    summary: ClassVar[str]  # what it computes, for the grammar's description of `algorithm`
    keys: ClassVar[tuple[Key, ...]] = ()
    samples: ClassVar[tuple[Sample, ...]] = ()
    width: int  # bits of the checksum value

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if "name" in cls.__dict__ and cls.__dict__.get("registered", True):
            _REGISTERED[cls.name] = cls

    # -- the language ------------------------------------------------------------------------------------------

    @classmethod
    def from_spec(cls, raw: Mapping[str, Any], size: int, type_name: str, report: Report, bits: int = 0) -> Algorithm:
        """The algorithm of a checksum element `raw` (its keys as the grammar checked them) of `size` bytes of
        type `type_name`; `bits`, the bits of its value where they are not 8 a byte (`encoding: seven_bit`: 7 a
        byte, which the element keeps of the value computed: an algorithm of a width, a CRC, checks it). Raises
        ChecksumProblem where it cannot be made; `report` takes problems that do not stop it (keys below the
        element, message)."""
        raise NotImplementedError

    # -- the runtime -------------------------------------------------------------------------------------------

    def function(self) -> Callable[[bytes], int]:
        """The checksum of the covered bytes, as the element holds it (an unsigned value of `width` bits)."""
        raise NotImplementedError

    def function_code(self) -> tuple[Import, str]:
        """How generated code makes `function()`: the import, and the call that returns it."""
        raise NotImplementedError

    def function_imports(self) -> list[Import]:
        """Every import function_code's call needs (its own, and a wrapped algorithm's)."""
        return [self.function_code()[0]]

    def title(self) -> str:
        """A catalogue name for comments and docs (CRC-16/MODBUS), or ""."""
        return ""

    # -- the Python backend: straight-line codecs --------------------------------------------------------------

    def python_setup(self, name: str) -> tuple[list[Import], list[str]]:
        """Imports and module-level definitions that python_lines relies on, for the checksum named `name` in the
        generated module (they define `name`, its runtime function, or names made from it, where they need one).
        python_call relies on at most these and `name`: codecs that use it define the runtime function as `name`
        (the frame engine's elements call it too)."""
        module_import, call = self.function_code()
        comment = f"  # {self.title()}" if self.title() else ""
        return [module_import], [f"{name}: Callable[[bytes], int] = {call}{comment}"]

    def python_call(self, name: str) -> str:
        """The checksum of the bytes `{}` as one expression (a str.format template), an operand of any operator
        (parenthesised where it is not an atom or a call)."""
        return name + "({})"

    def python_calls_function(self) -> bool:
        """Whether python_call calls the codec's function of the checksum (which the codec then defines), not an
        expression of its own."""
        return True

    def python_expression(self, name: str, covered: str) -> str | None:
        """The checksum of the bytes `covered` as the one expression python_lines assigns; None where python_lines
        takes more than one statement."""
        return self.python_call(name).format(covered)

    def python_lines(self, name: str, covered: str, target: str) -> list[str]:
        """Statements that compute the checksum of the bytes `covered` (an expression) into the variable `target`."""
        expression = self.python_expression(name, covered)
        assert expression is not None  # an algorithm that takes statements writes them itself
        return [f"{target} = {expression}"]

    # -- the Python backend: optional fast paths (None where the algorithm has none) ---------------------------

    def byte_total(self, total: str) -> str | None:
        """The checksum as an expression of `total`, the sum of the covered bytes (an int expression), where it
        depends on that sum alone: then a codec may sum a whole frame less constant bytes, or sum unpacked
        values, instead of slicing the frame."""
        return None

    def frame_test(self, total: str, skipped: int, check: str) -> str | None:
        """An int expression that is 0 exactly when a one-byte checksum `check` (an expression) is right, from
        `total` less `skipped`: `total` the sum of the frame (an int expression), `skipped` the sum of its bytes
        that are neither covered nor the checksum (constants). Lets a codec test a whole frame by summing it."""
        return None

    def summed(self) -> bool | None:
        """The stream parser's summed-run path (runtime/stream.py FrameFormat.summed) takes 8-bit byte sums:
        whether this one is inverted; None for every other checksum."""
        return None

    def byte_table(self, name: str, target: str) -> TableSteps | None:
        """Where python_lines runs `target = TABLE[target ^ byte]` over the covered bytes from a constant start:
        the steps (a codec may then fold known bytes into the start and unroll short runs); None for others."""
        return None

    # -- the C backend -----------------------------------------------------------------------------------------

    def c_code(self, prefix: str) -> CCode:
        """The checksum as C99, its names prefixed with the protocol's `prefix` (`feetech_sms`: `feetech_sms_sum8`):
        bitwise, no tables, no static data. Raises NoCode, one line naming what, where it has none."""
        raise NoCode(f"algorithm {self.name}")

    # -- the Wireshark backend ---------------------------------------------------------------------------------

    @classmethod
    def lua_function(cls) -> str | None:
        """Lua source of `function(spec, size, data)`: the checksum of the string `data` for a `size`-byte element
        whose parameters (lua_parameters) are the table `spec`; band, bor, bxor, lshift, rshift and width_mask are
        in scope. None where the dissector has no code for it: it shows the value, unverified."""
        return None

    def lua_parameters(self) -> dict[str, Any]:
        """The parameters lua_function reads from `spec`, as the dissector's data holds them."""
        return {}

    # -- the markdown backend ----------------------------------------------------------------------------------

    def describe(self) -> str:
        """What it is, completing "The checksum is the ..., from `a` to `b` inclusive."."""
        raise NotImplementedError

    def parameters(self) -> list[tuple[str, str]]:
        """Its parameters as (name, value) rows for the docs' table ([] for none)."""
        return []

    def worked(self, covered: bytes) -> str:
        """A worked example: how the covered bytes give the checksum, ending in its value."""
        raise NotImplementedError


class Wrapping(Algorithm):
    """An algorithm around another (`inner`, a dataclass field of the subclass): a seed after the covered bytes, a
    value sent 7 bits a byte. Made by the spec language's framing pass, never named by `algorithm:`."""

    registered = False
    inner: Algorithm

    @classmethod
    def from_spec(cls, raw: Mapping[str, Any], size: int, type_name: str, report: Report, bits: int = 0) -> Algorithm:
        raise NotImplementedError  # made by the spec language's framing pass around an algorithm

    def function_imports(self) -> list[Import]:
        return [self.function_code()[0], *self.inner.function_imports()]

    def python_setup(self, name: str) -> tuple[list[Import], list[str]]:
        _, lines = super().python_setup(name)
        return self.function_imports(), lines

    def title(self) -> str:
        return self.inner.title()

    def inner_lua(self) -> dict[str, Any] | None:
        """The inner algorithm and its parameters for the dissector (None where it has no Lua code)."""
        inner = self.inner
        return {"algorithm": inner.name, **inner.lua_parameters()} if inner.lua_function() else None


def hex_value(value: int, width: int) -> str:
    """0x-prefixed, upper-case, as many digits as the width has nibbles (0x0E, 0x340E)."""
    return f"0x{value:0{(width + 3) // 4}X}"


def hex_bytes(data: bytes) -> str:
    return data.hex(" ").upper() if data else "(no bytes)"
