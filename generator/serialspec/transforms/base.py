"""What every frame transform is: the base class of the registry (see __init__.py) and the plain data it speaks.

A transform rewrites the bytes of one span of frame elements between their plain form and the wire. It is a value,
a frozen dataclass of its parameters (`Replace(pairs=...)`), made from a spec's `transparency:` by `from_spec`. Its
class owns all that the transform means to every part of serialspec:

- the language: its `method:` name, the keys it owns (`keys`, plain data that lang/grammar.py turns into the grammar,
  the JSON Schema and docs/language.md), their validation (`from_spec`, `check_layout`);
- the runtime: `runtime(span)`, the object the frame engine (runtime/framing.py Layout) calls: `encode(plain)`,
  `decode(wire)` (DecodeError for bytes that are not the transform of any bytes) and `plain_prefix` (how the stream
  parser reads a length inside the span before the frame is complete), and optionally `span_end` (where the span
  ends on the wire, for a transform that can tell: the stream parser then drops a candidate whose trailer is not
  right there, instead of waiting for the next trailer); the runtime class lives in the
  transform's module, which imports nothing of the generator (the runtime wheel ships this package);
- the Python backend: `runtime_name` and `python_arguments(span)`, how generated code builds the runtime object;
- the markdown backend: `describe()` and `worked(plain)`;
- the C backend: `c_code(prefix)`, its C99 (CTransform: a function that rewrites the span either way, and the C of
  `span_end` where the runtime has one); `c_refusal()`, why the C target cannot generate it yet ("" where it can);
- the Wireshark backend: `lua()`, the data the dissector's Lua engine reads;
- tests: `samples`, one framing per documented option, which tests/test_transforms.py runs through every output.

The rule every transform keeps (lang/passes/framing.py checks it): a length or checksum inside the span sees the
plain bytes (before the transform); one outside it sees the bytes on the wire.

A new transform is one module of this package with one subclass that sets `name`: it is found by `transforms()`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from serialspec.checksums.base import ChecksumProblem
from serialspec.runtime.values import dataclass, field

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from typing import Any, ClassVar, Literal, Protocol
else:
    Protocol = object  # SpanTransform is a typing.Protocol to type checkers, at run time only a name

__all__ = ["DEFAULT", "CTransform", "Key", "Report", "Sample", "SpanTransform", "Transform", "TransformProblem"]

Report = Callable[[tuple[str, ...], str], None]  # a problem with the spec: keys below `transparency`, message
DEFAULT = "replace"  # the method of a `transparency:` that names none


class TransformProblem(ChecksumProblem):
    """A `transparency:` the transform cannot be made from: keys below it, and a one-line reason."""


@dataclass(frozen=True)
class Key:
    """A key of `transparency:` that a transform owns: its shape, as lang/grammar.py's shapes take it."""

    name: str
    kind: Literal["bool", "int", "hex", "hex_map"]  # hex_map: hex bytes -> hex bytes
    description: str
    default: Any = None
    example: Any = None  # shown in the language reference where no spec uses the key
    minimum: int | None = None
    maximum: int | None = None


@dataclass(frozen=True)
class Sample:
    """One documented option of a transform, as a spec writes it: the whole `framing:` of a small protocol."""

    label: str
    framing: Mapping[str, Any] = field(default_factory=dict)
    plain: bytes = b""  # the span's plain bytes of a frame, for the worked example in the language reference


class SpanTransform(Protocol):
    """What the frame engine calls: the runtime object of a transform over the elements `span` (inclusive)."""

    @property
    def span(self) -> tuple[int, int]: ...

    def encode(self, data: bytes) -> bytes: ...

    def decode(self, data: bytes) -> bytes: ...

    def plain_prefix(self, buffer: bytes, start: int, end: int, count: int) -> tuple[bytes, int] | None:
        """The first `count` plain bytes of the wire bytes buffer[start:end] and the wire bytes they took (the
        plain bytes may be fewer where the wire ends before them: a transform that can tell where its span ends);
        None while more wire bytes are needed; DecodeError where no transformed bytes start there."""
        ...


@dataclass(frozen=True)
class CTransform:
    """A transform as C99, its names prefixed with the protocol's prefix (backends/c/engine.py calls them).

    `rewrite` names `static int NAME(int to_wire, const uint8_t *src, size_t n, uint8_t *dst, const uint8_t *cmp,
    size_t cap, size_t *out)`: the n bytes at src rewritten to the wire (to_wire) or back, into dst, never past cap,
    their count in *out; 1 on success, 0 for bytes that are no transform of any bytes or that do not fit. With cmp
    (the engine's re-encoding check after a decode): 1 when the wire form of src is cmp[0..cap), or 1 at once (and
    *out = cap) for a transform whose decoding checks the form itself. `code` is its C (with any helpers).
    `span_end` (or ""): `static long NAME(const uint8_t *b, size_t start, size_t avail)`, where the span that starts
    at b[start] ends on the wire (the runtime's span_end), -2 while the bytes end inside it; `span_code` its C.
    `plain_prefix` (or ""): `static long NAME(const uint8_t *b, size_t start, size_t avail, size_t count, size_t
    from, uint8_t *dst)`, the runtime's plain_prefix: the wire bytes from b[start] that give the span's first `count`
    plain bytes, -2 while more are needed, -1 where none do (the span ends first, bytes of no form); the plain bytes
    from index `from` on go to dst. With it, a length inside the span that counts its plain bytes generates in C;
    `prefix_code` its C."""

    rewrite: str
    code: str
    span_end: str = ""
    span_code: str = ""
    plain_prefix: str = ""
    prefix_code: str = ""


_REGISTERED: dict[str, type[Transform]] = {}


class Transform:
    """A frame transform with its parameters. Subclasses are frozen dataclasses that set the class variables."""

    name: ClassVar[str]  # the `method:` value
    summary: ClassVar[str]  # what it does, for the grammar's description of `method`
    runtime_name: ClassVar[str]  # the runtime class's name (generated code imports it by this name)
    keys: ClassVar[tuple[Key, ...]] = ()
    samples: ClassVar[tuple[Sample, ...]] = ()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if "name" in cls.__dict__:
            _REGISTERED[cls.name] = cls

    # -- the language ------------------------------------------------------------------------------------------

    @classmethod
    def from_spec(cls, raw: Mapping[str, Any], report: Report) -> Transform:
        raise NotImplementedError

    def check_layout(self, roles: list[str], constants: list[bytes], first: int, last: int) -> str:
        """Why a layout (its elements' roles and constant bytes) cannot carry the transform over elements
        first..last, or ""."""
        return ""

    # -- the runtime -------------------------------------------------------------------------------------------

    def with_digits(self, offsets: tuple[int, ...]) -> Transform | str:
        """This transform sending the plain bytes at `offsets` (from the span's start, before the content) as one
        hex digit each (`type: u4` elements, 0..15), or why it cannot ("" never)."""
        return f"a u4 element is one hex digit: its span's method must be hex_ascii, not {self.name}"

    def runtime(self, span: tuple[int, int]) -> SpanTransform:
        raise NotImplementedError

    # -- the Python backend ------------------------------------------------------------------------------------

    def python_arguments(self, span: tuple[int, int]) -> list[str]:
        """The arguments of `<runtime_name>(...)` in generated code, as expressions."""
        raise NotImplementedError

    # -- the markdown backend ----------------------------------------------------------------------------------

    def describe(self) -> str:
        """What it does, completing "From `first` to `last`, ...: encode applies it"."""
        raise NotImplementedError

    def worked(self, plain: bytes) -> str:
        """A worked example: the plain bytes and what goes on the wire."""
        wire = self.runtime((0, 0)).encode(plain)
        return f"the span's bytes {_hex(plain)} are sent as {_hex(wire)}"

    @classmethod
    def worked_sample(cls, sample: Sample) -> str:
        """The worked example of a sample, as the language reference shows it."""
        made = cls.from_spec(sample.framing["transparency"], lambda keys, message: None)
        return f"For example, {made.worked(sample.plain)}."

    # -- other backends ----------------------------------------------------------------------------------------

    def c_refusal(self) -> str:
        """Why the C target cannot generate frames with this transform yet ("" when it can)."""
        return "" if self.c_code("p") is not None else f"frames with `method: {self.name}`"

    def c_code(self, prefix: str) -> CTransform | None:
        """The transform as C99 with the protocol's `prefix` (CTransform); None where the C target has none."""
        return None

    def lua(self) -> dict[str, Any] | None:
        """The data the Wireshark dissector's engine reads (its `method` and parameters); None: not supported."""
        return None


def _hex(data: bytes) -> str:
    return data.hex(" ").upper() if data else "(no bytes)"
