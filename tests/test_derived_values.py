"""Derived values and spec expressions computed alike everywhere (issues 21 and 25).

1. A value encode computes (a `value:` expression, a count, a size) that the caller gives anyway is refused in one
   line unless it is the computed one: the messages' from_fields (the codec's and the CLI's way in), the construct
   structs' build. The C structs have no member for it: C computes it (docs/c.md).
2. A computed value outside its declared range (Modbus write_coils count 0, range 1..1968) is refused on decode as
   encode refuses it: codec, stream parser, construct structs and C decoder.
3. The C target computes exactly what Python computes for any expression: floor division and modulo, ceil, shifts
   by any count; an expression some intermediate value of which can exceed int64_t is refused for C at its
   file:line:column. Hypothesis draws the fields and the frames; the compiled C driver must agree with Python.
"""

from __future__ import annotations

import contextlib
import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from conftest import ALL, ROOT, Generated, by_protocol, examples
from construct import ConstructError
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.backends import Unsupported
from serialspec.backends.c.build import files as c_files
from serialspec.backends.python.memory import imported
from serialspec.backends.python.package import emit_package
from serialspec.checksums.crc import crc_function
from serialspec.lang import expression
from serialspec.lang.loader import load_text
from serialspec.lang.model import Direction, Message, Scalar
from serialspec.lang.resolve import resolve
from serialspec.runtime.errors import DecodeError, EncodeError
from strategies import message_fields
from test_c_backend import FLAGS, GCC, Driver, c_decode
from test_codec import message_type

MODBUS = next(g for g in ALL if g.protocol.name == "modbus_rtu")
CRC = crc_function(16, 0x8005, 0xFFFF, True, True, 0x0)


def modbus_frame(body: bytes) -> bytes:
    return body + CRC(body).to_bytes(2, "little")


# --- 1. a computed value given by the caller -------------------------------------------------------------------------


def test_a_count_that_contradicts_the_values_is_refused_naming_both() -> None:
    cls = MODBUS.package.WriteRegistersRequest
    with pytest.raises(EncodeError) as refused:
        cls.from_fields({"unit": 1, "address": 1, "values": [1, 2], "count": 7})
    assert str(refused.value) == "write_registers request: count is given as 7, but it is computed: 2 (leave it out)"
    with pytest.raises(EncodeError, match="byte_count is given as 5, but it is computed: 4"):
        cls.from_fields({"unit": 1, "address": 1, "values": [1, 2], "byte_count": 5})
    with pytest.raises(EncodeError, match="count must be an integer"):
        cls.from_fields({"unit": 1, "address": 1, "values": [1, 2], "count": "2"})
    given = cls.from_fields({"unit": 1, "address": 1, "values": [1, 2], "count": 2, "byte_count": 4})
    assert MODBUS.package.encode(given) == MODBUS.package.encode(cls(1, 1, (1, 2)))


def test_the_cli_encode_refuses_a_contradicting_count_in_one_line() -> None:
    fields = {"unit": 1, "address": 1, "values": [1, 2], "count": 7}
    run = subprocess.run(
        [sys.executable, "-m", "serialspec", "encode", str(ROOT / "specs" / "modbus_rtu.yaml"), "--json"]
        + [json.dumps({"command": "write_registers", "fields": fields})],
        capture_output=True,
        text=True,
    )
    assert run.returncode != 0 and run.stdout == ""
    assert run.stderr.strip().splitlines() == [
        "serialspec encode: write_registers request: count is given as 7, but it is computed: 2 (leave it out)"
    ]


def test_the_construct_struct_refuses_a_contradicting_count_and_takes_the_computed_one() -> None:
    content = MODBUS.structs.WriteRegistersRequestContent
    with pytest.raises(ConstructError, match="given as 7, but it is computed: 2"):
        content.build({"address": 1, "values": [1, 2], "count": 7})
    assert content.build({"address": 1, "values": [1, 2], "count": 2}) == content.build(
        {"address": 1, "values": [1, 2]}
    )


COMPUTED = by_protocol(
    [
        (g, m)
        for g in ALL
        for m in g.protocol.messages()
        if any(isinstance(f, Scalar) and (f.value is not None or f.derived) for f in m.fields)
    ]
)


@pytest.mark.parametrize(("g", "spec"), COMPUTED)
def test_every_computed_value_given_is_refused_unless_it_is_the_computed_one(g: Generated, spec: Message) -> None:
    """For random messages: each computed value, given as what the frame holds, builds the same frame; given as
    anything else, is refused naming the field (codec's from_fields and construct's build alike)."""
    cls = message_type(g, spec)
    content_struct = g.structs.CONTENTS[(spec.key, spec.direction.value)]
    computed = [f for f in spec.fields if isinstance(f, Scalar) and (f.value is not None or f.derived)]

    @settings(max_examples=examples(30), deadline=None, suppress_health_check=list(HealthCheck))
    @given(message_fields(g.protocol, spec), st.integers(1, 1000))
    def run(fields: dict[str, Any], wrong_by: int) -> None:
        try:
            frame = g.package.encode(cls.from_fields(fields))
        except EncodeError:
            return
        parsed = content_struct.parse(content_of(g, frame, spec))
        content_fields = {k: v for k, v in parsed.items() if not k.startswith("_")}
        for f in computed:
            value = parsed[f.name]
            if f.derived and f.derived[0] == "size" and all(s.name != f.derived[1] for s in spec.fields):
                continue  # the size of bytes in each item of a group: not checked by from_fields
            assert g.package.encode(cls.from_fields({**fields, f.name: value})) == frame
            with pytest.raises(EncodeError, match=f"{f.name} is given as {value + wrong_by}, but it is computed"):
                cls.from_fields({**fields, f.name: value + wrong_by})
            with pytest.raises(ConstructError):
                content_struct.build({**content_fields, f.name: value + wrong_by})

    run()


def content_of(g: Generated, frame: bytes, spec: Message) -> bytes:
    from test_codec import frame_content

    return frame_content(g, frame, spec.direction.value)  # type: ignore[no-any-return]


def test_the_typed_client_takes_no_computed_value() -> None:
    """The client's methods have no parameter for a computed value: giving one is Python's TypeError."""
    import inspect

    from serialspec_protocols.modbus_rtu.client import ModbusRtuClient

    method = ModbusRtuClient.write_registers
    assert "count" not in inspect.signature(method).parameters
    assert "byte_count" not in inspect.signature(method).parameters


# --- 2. a computed value outside its declared range on decode ----------------------------------------------------


COUNT_0 = modbus_frame(bytes([1, 0x0F, 0, 0, 0, 0, 0]))  # write_coils, count 0 (range 1..1968), byte_count 0


def test_a_count_of_0_where_its_range_starts_at_1_is_refused_on_decode_everywhere() -> None:
    with pytest.raises(DecodeError, match="count is 0, outside its range 1..1968"):
        MODBUS.package.decode(COUNT_0, "request")
    parser = MODBUS.package.StreamParser("request")
    good = MODBUS.package.encode(MODBUS.package.WriteCoilsRequest(1, 0, (True,)))
    assert [type(m).__name__ for m in parser.feed(COUNT_0 + good)] == ["WriteCoilsRequest"]
    assert [type(m).__name__ for m in parser.feed(COUNT_0)] == []
    with pytest.raises(ConstructError, match="0 is outside its range 1..1968"):
        MODBUS.structs.WriteCoilsRequestContent.parse(COUNT_0[2:-2])
    with pytest.raises(EncodeError, match="count"):  # and encode refuses it, in the codec and the struct alike
        MODBUS.package.encode(MODBUS.package.WriteCoilsRequest(1, 0, ()))
    with pytest.raises(ConstructError, match="0 is outside its range 1..1968"):
        MODBUS.structs.WriteCoilsRequestContent.build({"address": 0, "values": []})


@pytest.mark.skipif(GCC is None, reason="no gcc")
def test_the_c_decoder_refuses_a_count_out_of_its_range_as_python_does() -> None:
    assert c_decode(MODBUS, COUNT_0, Direction.REQUEST) == "E_CONTENT"
    frame = modbus_frame(bytes([1, 0x10, 0, 0, 0, 0, 0]))  # write_registers, count 0 (range 1..123)
    with pytest.raises(DecodeError, match="count is 0, outside its range 1..123"):
        MODBUS.package.decode(frame, "request")
    assert c_decode(MODBUS, frame, Direction.REQUEST) == "E_CONTENT"
    ok = MODBUS.package.encode(MODBUS.package.WriteRegistersRequest(1, 0, (1, 2, 3)))
    assert isinstance(c_decode(MODBUS, ok, Direction.REQUEST), dict)


# --- 3. C expressions compute what Python computes -------------------------------------------------------------------


def expression_spec(value: str, b_type: str = "i8", check_type: str = "i64") -> str:
    spec = yaml.safe_load(
        (ROOT / "tests" / "adversarial" / "specs" / "derived_divides_by_a_wire_zero.yaml").read_text()
    )
    check = {"type": check_type, "value": value}
    spec["commands"]["set"]["request"]["fields"] = {"a": "i16", "b": b_type, "check": check}
    return yaml.safe_dump(spec, sort_keys=False)


def frame_of(a: int, b: int, check: int, b_type: str, code: int = 1) -> bytes:
    """The frame of command `code` (`set` or EXPRESSIONS' `set<code>`) with these wire values, whatever the check
    (its 8 bytes as two's complement)."""
    content = a.to_bytes(2, "little", signed=True) + b.to_bytes(1, "little", signed=b_type == "i8")
    content += (check % (1 << 64)).to_bytes(8, "little")
    covered = bytes([code, len(content)]) + content  # the checksum covers code to content
    return bytes([0xAA, 0x55, code, len(content)]) + content + bytes([sum(covered) & 0xFF])


EXPRESSIONS = [
    ("a / b", "i8", "i64"),
    ("a % b", "i8", "i64"),
    ("ceil(a / b)", "i8", "i64"),
    ("-a / 7", "i8", "i64"),
    ("(a - 100) % 7", "i8", "i64"),
    ("ceil((a - 5) / -3)", "i8", "i64"),
    ("a >> b", "u8", "i64"),
    ("a >> b", "i8", "i64"),
    ("a << (b % 16)", "u8", "i64"),
    ("(~a & b) | (a % -5)", "i8", "i64"),
    ("min(a, b) / max(b, 1) + ceil(a / 4)", "i8", "i64"),
    # a u64 field: a negative result is no u64 value, whatever its 8 bytes read as in two's complement
    ("a - b", "i8", "u64"),
    # signed fields narrower than 64 bits: C compares their value, not their wire bits
    ("a % b", "i8", "i8"),
    ("b - a / 256", "i8", "i16"),
]


def expressions_spec() -> str:
    """One spec holding every expression of EXPRESSIONS, command `set<i>` (code i) for the i-th (from 1): one C
    build for all of them."""
    spec = yaml.safe_load(expression_spec("a + b"))
    spec["commands"] = {
        f"set{code}": {
            "code": code,
            "request": {"fields": {"a": "i16", "b": b_type, "check": {"type": check_type, "value": value}}},
        }
        for code, (value, b_type, check_type) in enumerate(EXPRESSIONS, 1)
    }
    return yaml.safe_dump(spec, sort_keys=False)


@pytest.fixture(scope="module")
def expressions_c(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Driver, Any]]:
    """EXPRESSIONS' spec in C (its files compiled warning-free under the shipped specs' flags) with the driver, and
    in Python, built once for this module (and process)."""
    if GCC is None:
        pytest.skip("no gcc")
    folder = tmp_path_factory.mktemp("expressions")
    protocol = resolve(load_text(expressions_spec(), "expr.yaml"))
    source = folder / "c"
    source.mkdir()
    for path, text in c_files(protocol).items():
        (source / Path(path).name).write_text(text, encoding="utf-8")
    for name in (f"{protocol.name}.c", f"{protocol.name}_json.c"):  # the helpers compile warning-free too
        strict = [GCC, *FLAGS, "-O2", "-c", str(source / name), "-o", str(folder / "x.o")]
        compiled = subprocess.run(strict, capture_output=True, text=True)
        assert compiled.returncode == 0, compiled.stderr
    run = Driver(protocol.name, source, folder)
    try:
        with imported(protocol.name, emit_package(protocol)) as package:
            yield run, package
    finally:
        run.close()


@pytest.mark.parametrize(("code", "value", "b_type", "check_type"), [(i, *e) for i, e in enumerate(EXPRESSIONS, 1)])
def test_c_computes_every_expression_as_python_does(
    code: int, value: str, b_type: str, check_type: str, expressions_c: tuple[Driver, Any]
) -> None:
    """Random a (i16) and b: the frame Python encodes (check computed) decodes in C to the same fields and encodes
    back byte for byte; a frame with any check value (or the expression's value as 8 bytes) is accepted by C exactly
    when Python accepts it."""
    run, package = expressions_c
    b_range = (-128, 127) if b_type == "i8" else (0, 255)
    message = getattr(package, f"Set{code}Request")
    agree_all(run, package, expression.parse(value), b_range, b_type, message, code)


def agree_all(
    run: Driver, package: Any, expr: expression.Expr, b_range: tuple[int, int], b_type: str, message: Any, code: int
) -> None:
    """The Python package and the C driver agree on random fields and frames of one command."""

    @settings(max_examples=examples(80), deadline=None, suppress_health_check=list(HealthCheck))
    @given(st.integers(-32768, 32767), st.integers(*b_range), st.integers(-(1 << 63), (1 << 64) - 1), st.integers(0, 2))
    def agree(a: int, b: int, check: int, how: int) -> None:
        try:
            frame: bytes | None = package.encode(message(a=a, b=b))
        except EncodeError:
            frame = None
        if how == 0 and frame is not None:
            (answer,) = run.ask(f"dec request {frame.hex()}")
            assert answer.startswith("ok ") and json.loads(answer[3:])["fields"] == {"a": a, "b": b}, answer
            (answer,) = run.ask(f"rt request {frame.hex()}")
            assert answer == f"ok {frame.hex()}"
            return
        if how == 1:  # the expression's own value, in the check's 8 bytes whatever its sign
            with contextlib.suppress(ZeroDivisionError, ValueError):
                check = expression.evaluate(expr, {"a": a, "b": b})
        frame = frame_of(a, b, check, b_type, code)
        try:
            package.decode(frame, "request")
            python = "ok"
        except DecodeError:
            python = "err"
        (answer,) = run.ask(f"dec request {frame.hex()}")
        assert answer.split(" ")[0] == python, (frame.hex(), answer)

    agree()


def test_an_expression_that_can_exceed_int64_is_refused_for_c_at_its_line() -> None:
    text = expression_spec("a << b", "u8")
    protocol = resolve(load_text(text, "wide.yaml"))
    with pytest.raises(Unsupported) as refused:
        c_files(protocol)
    line = next(i for i, row in enumerate(text.splitlines(), 1) if "a << b" in row)
    message = str(refused.value)
    assert message.startswith(f"wide.yaml:{line}:") and "a << b can exceed 64 bits" in message, message
    assert len(message.splitlines()) == 1
    narrow = resolve(load_text(expression_spec("a << (b % 16)", "u8"), "narrow.yaml"))
    assert c_files(narrow)  # a count below 16 keeps every value within int64_t


# --- 4. other places where outputs could disagree -----------------------------------------------------------------


def test_an_expression_naming_a_field_with_bit_fields_is_a_spec_error() -> None:
    """Its message value is the bit fields (a record), its wire value a number: encode could never compute the
    expression while decode computed it from the number, so the spec is refused where the expression is."""
    from serialspec.lang.errors import SpecErrors

    text = expression_spec("a + 1").replace("a: i16", "a: {type: u8, bits: {lo: {bits: [3, 0]}, hi: {bits: [7, 4]}}}")
    with pytest.raises(SpecErrors) as refused:
        resolve(load_text(text, "bits.yaml"))
    line = next(i for i, row in enumerate(text.splitlines(), 1) if "a + 1" in row)
    assert str(refused.value).startswith(f"bits.yaml:{line}:")
    assert "a has bit fields (bits:): an expression cannot name it" in str(refused.value)


def test_the_c_structs_have_no_member_for_a_computed_value() -> None:
    """C cannot be given a contradicting count: the struct has the list and its `_count`, encode computes the count
    and byte count from it (docs/c.md), as Python's encode does (test_c_backend holds the bytes to Python's)."""
    header = (ROOT / "generated" / "c" / "modbus_rtu" / "modbus_rtu.h").read_text()
    struct = header[: header.index("} modbus_rtu_write_registers_request_t;")]
    struct = struct[struct.rindex("typedef struct {") :]
    members = [line.split(";")[0].split()[-1] for line in struct.splitlines()[1:]]
    assert members == ["unit", "address", "values[MODBUS_RTU_WRITE_REGISTERS_REQUEST_VALUES_MAX]", "values_count"]
