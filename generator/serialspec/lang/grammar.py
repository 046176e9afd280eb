"""The spec language's shape, declared once as data.

The same declaration checks a loaded spec's structure (unknown keys, wrong kinds of value, missing keys) and is
exported as the JSON Schema that editors use to complete and check spec files. Meaning (types that exist,
references that resolve, sizes that add up) is checked later, in resolve.py.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable, Iterator
from dataclasses import field
from typing import Any, assert_never

from serialspec import checksums, transforms
from serialspec.checksums.base import Key
from serialspec.checksums.crc import KANGAROO_CRC14
from serialspec.encodings import bit_run, low_bits, seven_bit, varint
from serialspec.lang.frozen import mutable
from serialspec.lang.limits import MAX_TEXT
from serialspec.lang.loader import CONTROL, Path
from serialspec.transforms.base import Key as TransformKey

SCALAR_TYPES = ("u8", "i8", "u16", "i16", "u32", "i32", "f32")
# what a field (not a frame element, enum, flag set or table entry) can be besides those
FIELD_SCALAR_TYPES = ("u8", "i8", "u16", "i16", "u24", "i24", "u32", "i32", "u64", "i64", "f32", "f64")
BIT_ORDERS = ("lsb_first", "msb_first")


class Shape:
    description = ""

    def check(self, value: Any, path: Path) -> Iterator[tuple[Path, str]]:
        raise NotImplementedError

    def json_schema(self) -> dict[str, Any]:
        raise NotImplementedError


@mutable
class Str(Shape):
    description: str = ""
    choices: tuple[str, ...] = ()
    default: Any = None  # the value a spec gets when it leaves the key out (for the reference and the schema)
    example: Any = None  # shown in the reference where no spec uses the key

    def check(self, value: Any, path: Path) -> Iterator[tuple[Path, str]]:
        if not isinstance(value, str):
            yield path, f"expected text, got {_kind(value)}"
        elif len(value) > MAX_TEXT:
            yield path, f"text of {len(value):,} characters (at most {MAX_TEXT:,})"
        elif bad := CONTROL.search(value):
            yield path, f"control character U+{ord(bad.group()):04X} in text (not allowed in a spec)"
        elif self.choices and value not in self.choices:
            yield path, f"unknown value {value!r} (expected one of {', '.join(self.choices)})"

    def json_schema(self) -> dict[str, Any]:
        schema: dict[str, Any] = {"type": "string", "description": self.description}
        if self.choices:
            schema["enum"] = list(self.choices)
        return _with_default(schema, self.default, self.example)


@mutable
class Int(Shape):
    description: str = ""
    default: Any = None  # the value a spec gets when it leaves the key out (for the reference and the schema)
    example: Any = None  # shown in the reference where no spec uses the key
    minimum: int | None = None
    maximum: int | None = None

    def check(self, value: Any, path: Path) -> Iterator[tuple[Path, str]]:
        if not isinstance(value, int) or isinstance(value, bool):
            yield path, f"expected an integer, got {_kind(value)}"
        elif (self.minimum is not None and value < self.minimum) or (self.maximum is not None and value > self.maximum):
            yield path, f"{value} is outside {_bounds(self.minimum, self.maximum)}"

    def json_schema(self) -> dict[str, Any]:
        schema: dict[str, Any] = {"type": "integer", "description": self.description}
        if self.minimum is not None:
            schema["minimum"] = self.minimum
        if self.maximum is not None:
            schema["maximum"] = self.maximum
        return _with_default(schema, self.default, self.example)


@mutable
class Num(Shape):
    """A finite number (NaN and infinities are never a protocol fact)."""

    description: str = ""
    default: Any = None  # the value a spec gets when it leaves the key out (for the reference and the schema)
    example: Any = None  # shown in the reference where no spec uses the key
    choices: tuple[float, ...] = ()

    def check(self, value: Any, path: Path) -> Iterator[tuple[Path, str]]:
        if not isinstance(value, int | float) or isinstance(value, bool):
            yield path, f"expected a number, got {_kind(value)}"
        elif not math.isfinite(value):
            yield path, f"expected a finite number, got {value}"
        elif self.choices and value not in self.choices:
            yield path, f"unknown value {value} (expected one of {', '.join(f'{c:g}' for c in self.choices)})"

    def json_schema(self) -> dict[str, Any]:
        schema: dict[str, Any] = {"type": "number", "description": self.description}
        if self.choices:
            schema["enum"] = list(self.choices)
        return _with_default(schema, self.default, self.example)


def _bounds(minimum: int | None, maximum: int | None) -> str:
    if minimum is not None and maximum is not None:
        return f"{minimum}..{maximum}"
    return f"the minimum {minimum}" if minimum is not None else f"the maximum {maximum}"


@mutable
class Bool(Shape):
    description: str = ""
    default: Any = None  # the value a spec gets when it leaves the key out (for the reference and the schema)
    example: Any = None  # shown in the reference where no spec uses the key

    def check(self, value: Any, path: Path) -> Iterator[tuple[Path, str]]:
        if not isinstance(value, bool):
            yield path, f"expected true or false, got {_kind(value)}"

    def json_schema(self) -> dict[str, Any]:
        return _with_default({"type": "boolean", "description": self.description}, self.default, self.example)


def _with_default(schema: dict[str, Any], default: Any, example: Any = None) -> dict[str, Any]:
    if default is not None:
        schema["default"] = default
    if example is not None:
        schema["examples"] = [example]
    return schema


def value_description(shape: Shape, parent: str) -> str:
    """A shape's own description, or its parent's for a part that needs none of its own (a map's value, a list's
    item, an option of a OneOf: `Document id -> what it is.` describes the values of `sources:`)."""
    return shape.description or parent


@mutable
class Any_(Shape):
    description: str = ""

    def check(self, value: Any, path: Path) -> Iterator[tuple[Path, str]]:
        return iter(())

    def json_schema(self) -> dict[str, Any]:
        return {"description": self.description}


@mutable
class ListOf(Shape):
    item: Shape
    description: str = ""
    length: int | None = None
    example: Any = None  # shown in the reference where no spec uses the key

    def check(self, value: Any, path: Path) -> Iterator[tuple[Path, str]]:
        if not isinstance(value, list):
            yield path, f"expected a list, got {_kind(value)}"
            return
        if self.length is not None and len(value) != self.length:
            yield path, f"expected a list of {self.length} items, got {len(value)}"
        for index, item in enumerate(value):
            yield from self.item.check(item, (*path, index))

    def json_schema(self) -> dict[str, Any]:
        schema: dict[str, Any] = {
            "type": "array",
            "items": _described(self.item, self.description),
            "description": self.description,
        }
        if self.length is not None:
            schema["minItems"] = schema["maxItems"] = self.length
        return _with_default(schema, None, self.example)


@mutable
class MapOf(Shape):
    """A mapping from names (or numbers) chosen by the spec author to values of one shape."""

    value: Shape
    description: str = ""
    int_keys: bool = False
    example: Any = None  # shown in the reference where no spec uses the key

    def check(self, value: Any, path: Path) -> Iterator[tuple[Path, str]]:
        if not isinstance(value, dict):
            yield path, f"expected a mapping, got {_kind(value)}"
            return
        for key, item in value.items():
            if self.int_keys != isinstance(key, int):
                yield (*path, key), "expected a number as key" if self.int_keys else "expected a name as key"
                continue
            yield from self.value.check(item, (*path, key))

    def json_schema(self) -> dict[str, Any]:
        return {
            "type": "object",
            "additionalProperties": _described(self.value, self.description),
            "description": self.description,
        }


def _mapping_keys(shape: Shape) -> Iterable[str]:
    """The keys of the mapping a key's value is (a Ref's target's; each mapping a OneOf takes), else none."""
    if isinstance(shape, Ref):
        shape = shape.target()
    if isinstance(shape, OneOf):
        return [key for option in shape.options for key in _mapping_keys(option)]
    return shape.keys if isinstance(shape, Obj) else ()


def _did_you_mean(key: object, keys: Iterable[str]) -> str:
    """ "did you mean 'range'? " for a key one or two letters from one of `keys` (`rnage`), else ""."""
    if not isinstance(key, str):
        return ""
    import difflib  # noqa: PLC0415 (only for a spec with a mistake)

    close = difflib.get_close_matches(key, list(keys), n=1, cutoff=0.75)
    return f"did you mean {close[0]!r}? " if close else ""


@mutable
class Obj(Shape):
    keys: dict[str, Shape]
    required: tuple[str, ...] = ()
    description: str = ""
    # more examples for the language reference, beyond the shipped specs': (label, YAML under the parent key, a
    # line that works it through) for each documented variant (the transforms' samples)
    variants: tuple[tuple[str, dict[str, Any], str], ...] = ()
    # what the line saying a required key is missing adds, by key (what a newcomer writes in its place)
    missing_hints: dict[str, str] = field(default_factory=dict)

    def check(self, value: Any, path: Path) -> Iterator[tuple[Path, str]]:
        if not isinstance(value, dict):
            yield path, f"expected a mapping with keys {', '.join(self.keys)}, got {_kind(value)}"
            return
        missing = [key for key in self.required if key not in value]
        home, strays = self._strays(value, missing)
        if strays:  # one mistake, one line: the entries of a mapping written one level too high
            said = f"missing key {home!r}: " if home in missing else ""
            yield path, f"{said}{', '.join(map(str, strays))} belong one level lower, under `{home}:`"
        for key in missing:
            if key != home or not strays:
                hint = f" ({self.missing_hints[key]})" if key in self.missing_hints else ""
                yield path, f"missing key {key!r}{hint}"
        for key, item in value.items():
            shape = self.keys.get(key) if isinstance(key, str) else None
            if shape is None and key in strays:
                continue
            if shape is None:
                # no key of the language holds a space or punctuation: such a "key" is most likely the rest of a
                # text cut at a comma in a flow mapping (`{description: a value, or 0}`)
                cut = isinstance(key, str) and not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", key)
                hint = "; a comma inside `{...}` ends a value: quote text that holds one" if cut else ""
                close = _did_you_mean(key, self.keys)
                lower = "" if close or cut else self._lower_homes(key)
                yield (
                    (*path, key),
                    f"unknown key {key!r} ({close}{lower}expected one of " + (f"{', '.join(self.keys)}{hint})"),
                )
            else:
                yield from shape.check(item, (*path, key))

    def _lower_homes(self, key: Any) -> str:
        """ "a key of `response:`, one level lower; " for a key of the mapping one of this mapping's keys holds
        (a command's `answers`, a key of its request or response), else ""."""
        if not isinstance(key, str):
            return ""
        homes = [name for name, shape in self.keys.items() if key in _mapping_keys(shape)]
        if not homes:
            return ""
        return f"a key of {' or '.join(f'`{name}:`' for name in homes)}, one level lower; "

    def _strays(self, value: dict[Any, Any], missing: list[str]) -> tuple[str, list[Any]]:
        """(the key, the unknown keys of `value`) when those are all entries of the one mapping key they fit, absent
        here, as written one level too high (a layout's elements without `elements:`, a request's fields without
        `fields:`); else ("", []). A missing required mapping is tried first, then any absent one: the one whose
        entries they all are, if exactly one."""
        strays = [key for key in value if not (isinstance(key, str) and key in self.keys)]
        if not strays or not all(isinstance(key, str) and self._entry_like(key, value[key]) for key in strays):
            return "", []
        absent = [key for key, shape in self.keys.items() if key not in value and isinstance(shape, MapOf)]
        for candidates in ([key for key in missing if key in absent], absent):
            homes = [key for key in candidates if self._holds(key, value, strays)]
            if len(homes) == 1:
                return homes[0], strays
            if homes:
                return "", []
        return "", []

    def _entry_like(self, key: str, item: Any) -> bool:
        """A stray key that may be an entry put one level too high, not a misspelling of one of this mapping's own
        keys (`descripton: Lamp`): not close to any of them, and holding a mapping or a name (`u8`, a shared
        field's), not free text."""
        if _did_you_mean(key, self.keys):
            return False
        return isinstance(item, dict) or (
            isinstance(item, str) and re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", item) is not None
        )

    def _holds(self, key: str, value: dict[Any, Any], strays: list[Any]) -> bool:
        """Every stray key's value is an entry the mapping `key` takes."""
        mapping = self.keys[key]
        assert isinstance(mapping, MapOf)
        return not mapping.int_keys and all(not list(mapping.value.check(value[k], ())) for k in strays)

    def json_schema(self) -> dict[str, Any]:
        return {
            "type": "object",
            "description": self.description,
            "properties": {key: shape.json_schema() for key, shape in self.keys.items()},
            "required": list(self.required),
            "additionalProperties": False,
        }


@mutable
class Ref(Shape):
    """A shape defined later, or by itself (group fields are fields): checked as it, a $ref in the JSON Schema."""

    name: str
    target: Callable[[], Shape]
    description: str = ""

    def check(self, value: Any, path: Path) -> Iterator[tuple[Path, str]]:
        yield from self.target().check(value, path)

    def json_schema(self) -> dict[str, Any]:
        return {"$ref": f"#/$defs/{self.name}", "description": self.description}


@mutable
class OneOf(Shape):
    """Either a short form (e.g. a bare type name) or a long form; picked by the kind of value given."""

    options: tuple[Shape, ...] = field(default_factory=tuple)
    description: str = ""
    example: Any = None  # shown in the reference where no spec uses the key

    def check(self, value: Any, path: Path) -> Iterator[tuple[Path, str]]:
        for option in self.options:
            problems = list(option.check(value, path))
            if not problems:
                return
            if _accepts_kind(option, value):
                yield from problems
                return
        wanted = " or ".join(dict.fromkeys(_WANTED.get(type(option), "something else") for option in self.options))
        yield path, f"expected {wanted}, got {_kind(value)}: {self.description}"

    def json_schema(self) -> dict[str, Any]:
        options = [_described(option, self.description) for option in self.options]
        return {"anyOf": options, "description": self.description}


@mutable
class IntOrText(OneOf):
    """An integer, or text where the spec's framing is text (a command's code): the checks of the passes say which."""

    def check(self, value: Any, path: Path) -> Iterator[tuple[Path, str]]:
        if not isinstance(value, str):
            yield from Int().check(value, path)


def _described(shape: Shape, parent: str) -> dict[str, Any]:
    return _fill(shape.json_schema(), parent)


def _fill(schema: dict[str, Any], parent: str) -> dict[str, Any]:
    """Give every part without a description of its own (an option, a list's items) its parent's."""
    if not schema.get("description"):
        schema["description"] = parent
    for part in ("items", "additionalProperties"):
        if isinstance(schema.get(part), dict):
            _fill(schema[part], schema["description"])
    for option in schema.get("anyOf", []):
        _fill(option, schema["description"])
    return schema


def _accepts_kind(shape: Shape, value: Any) -> bool:
    kinds: dict[type[Shape], type | tuple[type, ...]] = {
        Str: str,
        Int: int,
        Num: (int, float),
        Bool: bool,
        ListOf: list,
        MapOf: dict,
        Obj: dict,
    }
    expected = kinds.get(type(shape))
    return expected is not None and isinstance(value, expected)


_WANTED: dict[type[Shape], str] = {
    Str: "text",
    Int: "an integer",
    Num: "a number",
    Bool: "true or false",
    ListOf: "a list",
    MapOf: "a mapping",
    Obj: "a mapping",
}


# A number with an exponent that YAML 1.1 (PyYAML) reads as text: one without a point or without the exponent's sign
_EXPONENT_AS_TEXT = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)[eE][-+]?\d+")


def _kind(value: Any) -> str:
    if value is None:
        return "nothing"
    if isinstance(value, str) and _EXPONENT_AS_TEXT.fullmatch(value):
        mantissa, _, exponent = value.lower().partition("e")
        mantissa += "" if "." in mantissa else ".0"
        written = f"{mantissa}e{exponent if exponent[0] in '+-' else '+' + exponent}"
        return f"text ({value!r}: YAML takes an exponent only after a point and with its sign: write {written})"
    if isinstance(value, float):
        return f"a number ({value!r})"  # where an integer was wanted, 1.0 shows why it is not one
    return {
        bool: "true/false",
        int: "a number",
        float: "a number",
        str: "text",
        list: "a list",
        dict: "a mapping",
    }.get(type(value), type(value).__name__)


# --- the language -------------------------------------------------------------------------------------------------

TEXT = Str("Free text (English); shown in docs and docstrings, never executed.")
TITLE = Str("A one-line title (free text), shown in the reference and as the docstring's first line.")
TITLE_CN = Str("The title as printed in the (Chinese) document.")
SOURCE = Str("Where the fact comes from: a document id from `sources:` and its section (free text).")
SCALAR_TYPE = Str("Wire type of the value.", choices=SCALAR_TYPES, default="u8")
RANGE = ListOf(Num(), "Inclusive [min, max] of the value in wire units; checked before encoding.", length=2)
HEX_BYTES = Str("Bytes as hex: '12 4c 08', '0x12 0x4c', '124c08' or '12:4c:08'.")


def bit_fields(description: str) -> MapOf:
    """Sub-fields of an integer by bit position: a field's or a frame element's `bits`."""
    where = "A bit number, or [high, low] for several bits."
    return MapOf(
        OneOf(
            (
                Int(where),
                ListOf(Int(), where, length=2),
                Obj(
                    {
                        "bits": OneOf((Int(), ListOf(Int(), length=2)), where),
                        "enum": Str("Name of an entry in `enums:`."),
                        "const": Int(
                            "The bits always hold this value (a sync nibble): decode refuses a value with other bits "
                            "there (a frame element's: the stream parser sees no frame), the bits class fills it in "
                            "and encode writes it (refusing another). Bit fields filled in are defaults of the bits "
                            "class from the last one with none on.",
                            example=5,
                        ),
                        "default": Int(
                            "The value the bits class fills in when none is given (reserved bits sent as 0). A value "
                            "whose every bit field has a `const` or `default` (a frame element's: a sync byte) needs "
                            "no argument: message classes and client methods default it to the bits class's preset "
                            "(`SYNC_BITS_PRESET`); later parameters without a default stay positional and are "
                            "refused (TypeError) when left out. JSON (`serialspec encode --json`, `from_fields`) "
                            "may likewise leave out such a value, or any bit field with a `const` or `default`.",
                            example=0,
                        ),
                        "description": TEXT,
                    },
                    required=("bits",),
                    description="One sub-field in full: its bit (or bits), the enum its value belongs to, if any, "
                    "and a constant or default value.",
                ),
            ),
            "One sub-field: its bit number or [high, low] bits (short form, `failsafe: 3`, `error: [6, 0]`), or a "
            "mapping with `bits` and optionally the enum its value belongs to.",
        ),
        description,
    )


_FIELD_LONG: dict[str, Shape] = {
    "type": Str(
        "Wire type: u8, i8, u16, i16, u24, i24, u32, i32, u64, i64, f32, f64, bytes, string, cstring "
        f"(NUL-terminated text), array, group, table_value, table_block; {bit_run.DOC}. In text frames: decimal, "
        "integer, angle (ddmm.mmmm degrees and minutes), char, text, time (hhmmss.ss), date (ddmmyy), repeat (a group "
        "of `fields` repeated `count` times, or up to `max_count` times at the end); an empty field is None."
    ),
    "use": Str("Name of an entry in `fields:` (top level) to copy; keys given here override it."),
    "label": Str(
        "Text frames, in a message whose `text` has `named`: the label the field's value follows (GRBL's `MPos` in "
        "`MPos:1.000,2.000,3.000`). Labelled fields are found by their label in any order; a label absent from a "
        "frame leaves its field None (a repeat: empty) and encode leaves out the fields that are None. A field "
        "labelled with the message's own code is written right after the code (GRBL's sub-state: `code: Hold` and "
        "`sub_state: {label: Hold, type: integer}` read `<Hold:0|…>`; `<Hold|…>` leaves it None).",
        example="MPos",
    ),
    "description": TEXT,
    "description_cn": Str("Description as printed in the (Chinese) document."),
    "unit": Str("Unit of one wire step, e.g. mV, ms, 0.1°."),
    "scale": Num(
        "Engineering value = wire value × scale (e.g. 0.1 for 0.1° steps); a number field's (an array refuses it: its "
        "items are shown as sent, with the `unit` of one step)."
    ),
    "offset": Num(
        "Added after `scale`: engineering value = wire value × scale + offset (CRSF GPS altitude: wire metres "
        "+ 1000, so offset -1000). `range` stays in wire units.",
        example=-1000,
    ),
    "range": RANGE,
    "const": Int(
        "The field always has this value (sub-command selectors, fixed addresses). As the first field of messages "
        "that share a code (or frames without one), it picks the message (RTCM 3's message number: see "
        "commands.NAME).",
        example=1,
    ),
    "default": OneOf(
        (Num(), Str()),
        "Value used when a message is built without this field: a number; for bytes of a fixed size, their hex "
        "(`reserved: {type: bytes, size: 3, default: 00 00 00}`).",
    ),
    "enum": Str("Name of an entry in `enums:`; values decode to that enum."),
    "flags": Str("Name of an entry in `flags:`; the value is a set of bit flags."),
    "bits": bit_fields("Sub-fields packed into this integer, by bit position (unlisted bits must be zero)."),
    "encoding": Str(
        "How the integer is stored: plain two's complement, sign_magnitude (top bit the sign, the rest the size), or "
        f"{low_bits.SEVEN_BIT.doc}; {low_bits.NIBBLES.doc}; {low_bits.SIGNED_DOC}; {seven_bit.TEXT_DOC}; or "
        f"{varint.DOC}.",
        choices=("plain", "sign_magnitude", low_bits.SEVEN_BIT.name, low_bits.NIBBLES.name, varint.NAME),
        default="plain",
        example="sign_magnitude",
    ),
    "varint": Obj(
        {
            "bits": Int(
                "Value bits a byte; the bit above them marks more bytes.", default=7, minimum=1, maximum=7, example=6
            ),
            "order": Str("Which group comes first.", choices=varint.ORDERS, default="low_first", example="high_first"),
            "sign": Str(
                "How a signed value is sent (a signed type needs one).", choices=varint.SIGNS, example="zigzag"
            ),
        },
        description=varint.KEY_DOC,
    ),
    "endian": Str("Override of the protocol's byte order for this field.", choices=("little", "big"), example="big"),
    "size": OneOf(
        (Int(), Str()),
        "bytes, string: a number (a field or a content of a fixed size holds at most 2147483647 bytes, 2^31 - 1), "
        "`rest` (up to the end of the content; a frame that has no length element, trailer "
        "or transform cannot end that way: a stream parser could not tell where, so it is refused) or the name of "
        "an earlier integer field, "
        "which becomes derived (encode writes the length, decode checks it; messages and JSON leave it out; in a "
        "group's items, every item's bytes must then have one length: DYNAMIXEL SYNC WRITE), or an expression over "
        "earlier integer fields, which stay in the message (`length - 2`: see `count`); array: the earlier "
        "field holding the array's size in bytes (Modbus byte_count). In text frames, a `text` field's `size: "
        "rest` is the rest of the line, separators included (a message's last field: Marlin's `Error:checksum "
        "mismatch, Last Line: 122` as one text).",
    ),
    "count": OneOf(
        (Int(), Str()),
        "array/group: a number, `rest`, the name of an earlier count field (which becomes derived: encode writes the "
        "number of items, messages leave it out), or an expression of earlier integer fields (`max_moving_gate + 1`, "
        "`2 * n`; the grammar of `value:`), which stay in the message: decode reads that many items and refuses a "
        "negative count, encode refuses a list of another length.",
        example="max_moving_gate + 1",
    ),
    "of": Str(
        "array: the item type: a scalar type; `bit` (bools packed 8 to a byte, lowest bit first); or `uN`/`iN` for "
        "integers of N bits (1..64) packed with no gaps, e.g. u11 (CRSF/SBUS RC channels: 16 × 11 bits), with a "
        "fixed `count`; see `bit_order`.",
        example="u11",
    ),
    "bit_order": Str(
        "array of uN/iN items: `lsb_first`, the first item in the lowest bits of the first byte, each item's lowest "
        "bit first (CRSF, SBUS); `msb_first`, the first item in the highest bits, highest bit first. Default: "
        "lsb_first in a little-endian field, msb_first in a big-endian one (so `of: u24` is 3-byte integers).",
        choices=BIT_ORDERS,
        example="lsb_first",
    ),
    "pad": Str(
        "string of a fixed size: the byte (hex) that fills it after shorter text, e.g. '00' (NUL-padded); decoding "
        "drops the trailing pad bytes, encoding refuses text longer than the size. Without it the text must fill "
        "the size.",
        example="00",
    ),
    "count_from": Str(
        "array of a response: the request field (request.<field>) saying how many items are meant, when the array "
        "holds more (Modbus coils padded to a multiple of 8): clients keep that many."
    ),
    "value": Str(
        "An integer field derived from the others by an expression, computed on encode and checked on decode: "
        "`2 * count`, `ceil(len(coils) / 8)` (names of fields, len() of a list, group or bytes (not of text, "
        "whose characters are not its bytes), ceil(a / b), min, max, + - * / % & | << >>). "
        "At most 500 characters and 50 levels deep; every value it can take for any values of its fields' types "
        "(intermediate ones too) within 512 bits, and some value within the field's range (a constant one must fit "
        "it). A frame whose fields make it divide by 0 or shift by a negative count is refused when decoded, in "
        "every output (the codec's DecodeError, the construct structs' error, the C decoder's E_CONTENT; the "
        "simulator answers nothing and logs one line), and such values are refused on encode. `/` and `%` round "
        "down (Python's // and %), in every output. Messages leave the field out; JSON (from_fields, `serialspec "
        "encode`) and the construct structs may give it only as the computed value (any other is refused in one "
        "line naming both), and a frame holding a value outside the field's `range` is refused on decode, as "
        "encode refuses it. The C target computes in int64_t: it refuses an expression that can exceed it."
    ),
    "fields": Ref("fields", lambda: FIELDS, "group: the fields of each item (a mapping, like request/response)."),
    "table": Str("table_value/table_block, or bytes holding registers: name of an entry in `tables:`."),
    "key": Str("table_value: the earlier field holding the table key (e.g. data_id)."),
    "start": Str("bytes holding registers: the field (or request.<field>) with the first register's key."),
    "size_from": Str(
        "bytes of a response, size `rest`: the request field giving its size (request.<field>), or the bytes that "
        "field plus (or minus) a number gives (`request.count + 1`: STM32's Read Memory sends the number of bytes "
        "minus one; not for a run of registers). Where the frame "
        "carries no length (a raw read: the Pololu Tic's Get Variable answers `length` bytes alone), the stream "
        "parser sizes the reply awaited by that field of its request (the client's), and decode and encode with the "
        "request refuse a reply of another size (the simulator then answers nothing and logs why; the C target "
        "refuses such a spec, not yet)."
    ),
    "select": MapOf(Any_(), "table_block: entry attributes an entry must have to be in the block, e.g. {access: rw}."),
    "expect_size": Int("table_block: the block's size in bytes, asserted by the generator."),
    "inferred": TEXT,
    "precision": Int(
        "text decimal, angle, time: fraction digits written for a value that does not carry its own (a float; a "
        "decoded value keeps the digits it was sent with); a decimal without one writes a float in its shortest "
        "form (2.5, never rounded to 2).",
        minimum=0,
        maximum=18,
        example=4,
    ),
    "width": Int(
        "text integer, decimal: digits before the point, zero-padded; angle: digits of the degrees (2 for a "
        "latitude, 3 for a longitude).",
        minimum=1,
        maximum=20,
        example=3,
    ),
    "base": Num(
        "text integer: the digits' base, 10 or 16 (hex digits: an ELM327's `41 0C 1A F8`, `a: {type: integer, base: "
        "16, width: 2}`). Hex digits decode in either case and encode in upper case (`case: lower`: lower), after a "
        "`-` for a negative value; `width` counts digits, zero-padded.",
        default=10,
        example=16,
        choices=(10, 16),
    ),
    "case": Str(
        "text integer with `base: 16`: the case of the hex digits written (decode reads either).",
        default="upper",
        example="lower",
        choices=("upper", "lower"),
    ),
    "letters": MapOf(
        Str(), "text char: label -> the letter that stands for it; decoded letters become members of a generated Enum."
    ),
    "max_count": Int("text repeat at the end of a message: at most this many groups.", minimum=1, example=4),
    "status": Obj(
        {"ok": Int("The value that means success; any other value is a device error.")},
        required=("ok",),
        description=(
            "A response field that says whether the device could do it (RRC `success`): the client raises "
            "DeviceError unless it holds `ok`, and returns the other fields."
        ),
    ),
}
FIELD = OneOf(
    (
        Str("A wire type or the name of an entry in `fields:`"),
        Obj(
            _FIELD_LONG,
            description="A field in full: its type, and its unit, range, enum... where it has them.",
            variants=(
                (
                    "A count or size given by an expression (HLK LD2410's engineering report: N + 1 energies after N; "
                    "a payload of `length - 2` bytes)",
                    {
                        "max_moving_gate": {"type": "u8", "description": "N, the farthest moving gate reported."},
                        "moving_energies": {"type": "array", "of": "u8", "count": "max_moving_gate + 1"},
                        "length": "u8",
                        "payload": {"type": "bytes", "size": "length - 2"},
                    },
                    "An array's or group's `count`, a bytes or string field's `size`, may be an expression of the "
                    "`value:` grammar over earlier integer fields of the same content (plain ones: not constant, "
                    "derived, scaled, flags or bit fields; no `len()`). Unlike a count given by a field's name, "
                    "which becomes derived (encode writes the list's length, messages leave it out), the fields an "
                    "expression names stay in the message as ordinary fields: here `max_moving_gate` is a member, and "
                    "decode reads `max_moving_gate + 1` energies. A frame whose count works out negative is refused "
                    "in one line (`moving_energies has max_moving_gate + 1 = -1 items: a count cannot be negative`), "
                    "as one whose count asks for more bytes than it holds. Encode refuses a list, group, bytes or "
                    "text of another length before writing a byte, naming the field and the count expected "
                    "(`moving_energies needs max_moving_gate + 1 = 9 items, got 8`): one rule, also for `n + 1`, "
                    "encode never derives the fields. The expression's values for any wire values of its fields "
                    "keep the expression limits and cannot all be negative; one that may divide by 0 or shift by a "
                    "field is refused. A frame with no length element, trailer or stuffing is sized by a count "
                    "`k * field + m` (k >= 1, m >= 0) of fixed-size items; another expression there is refused in one "
                    "line. The C computes it in int64_t (docs/c.md); the Wireshark dissector refuses a count with bit "
                    "operators (`& | << >> ~`: Lua 5.2 has none) in one line.",
                ),
                varint.VARIANT,
                low_bits.VARIANT,
            ),
        ),
    ),
    "A field: a wire type or the name of a shared field (short form), or a mapping (long form).",
)
FIELDS: Shape = MapOf(
    FIELD,
    "Fields in wire order: name -> type or mapping. A name is any lower-case identifier the protocol uses (`type`, "
    "`id`, `data`, and Python keywords: `class`, `from`, `in`) except the few names generated code uses itself "
    "(`self`, `request`, `reply`, `to_fields`, builtins a client method calls such as `len`), which are refused, "
    "one line naming them. A field named after a Python keyword keeps its name in the spec's references, JSON "
    "(`decode --json`, `to_fields`/`from_fields`), the reference, Wireshark and C (where a C or C++ keyword also "
    "gets a trailing underscore); in generated Python, its attribute, client argument and construct struct field "
    "take a trailing underscore (`message.class_`), so `class_` itself is not a field name.",
)

OPTIONAL_WHEN = Obj(
    {
        "parameter": Str("A table entry: `entry` or `table.entry` (e.g. response_switch)."),
        "equals": Int("The device answers while the parameter has this value."),
        "not_equals": Int("The device answers while the parameter has any other value.", example=0),
        "at_least": Int("The device answers while the parameter is at least this (status_return_level ≥ 1)."),
        "at_most": Int("The device answers while the parameter is at most this.", example=1),
    },
    required=("parameter",),
    description="The reply is sent only while a device parameter compares true (give one comparison).",
)

TEXT_LAYOUT = Obj(
    {
        "start": Str(
            "What the message's text starts with, right after the framing's own start (GRBL's status report: `<`); "
            "not a letter, digit or character of a text code: frames are told apart by it. Without one the message "
            "is found by its code at the start of the frame (after the talker), the longest code that fits: the "
            "code, then `after_code`, then the fields (Roboteq's `A=12:13` answering `?A`: `text: {separator: "
            '"=", list: ":"}`).',
            example="<",
        ),
        "code": Str(
            "The code this message's frames carry where it is not its command's `code`: a reply under a code of its "
            'own (an ELM327 answers `010C` with `41 0C 1A F8`: `response: {text: {code: "41 0C"}}`; an AT modem '
            'answers `AT+CSQ` with `+CSQ: 20,99`: `text: {code: "+CSQ:", after_code: " "}`). It may hold '
            "the message's separator (several words); the message is found by it, the longest code that fits, and "
            "clients and the simulator pair it with its request as usual.",
            example="41 0C",
        ),
        "end": Str("What the message's text ends with, before the framing's own checksum and end (`>`).", example=">"),
        "separator": Str(
            "One character between the code and the fields, and between fields (`|`); default the framing's. "
            'Empty with labels glued to their values (`named: ""`): nothing between them.',
            example="|",
        ),
        "after_code": Str(
            "What comes between the code and the first field, in place of `separator` (at most one character): "
            'empty glues the first value to the code (Lynxmotion LSS\'s `D1800`: `text: {after_code: ""}`; '
            "G-code's line number `N123` before the line). A frame of the code alone carries no fields. A code "
            "glued to its value may begin another code only where that value is a number and the other code goes "
            "on with no digit or sign (LSS's `Q` beside `QD`): the longest code that fits is read.",
            example="",
        ),
        "named": Str(
            "One character between a field's `label` and its value (`:`): every field has a label and is found "
            'by it, in any order. Empty (`named: ""`) glues each label to its value, in a message found by its '
            "code (no `start`): G-code's `G1 X10.5 Y-3` (`code: G1`, `x: {label: X, type: decimal}`); with "
            '`separator: ""` too, the values are numbers, each ending where a label begins (Lynxmotion LSS\'s '
            "`D1800T1500`: `position: {label: D}` labelled with the code, right after it, then `time: {label: "
            "T}`). No label may begin another.",
            example=":",
        ),
        "list": Str(
            "One character between a repeat's values (`,`: `MPos:1.000,2.000,3.000`); needed with `named`, else "
            "a repeat's values are separated as fields are.",
            example=",",
        ),
    },
    description="Text frames: the message's own text inside the frame, in place of the framing's separator (GRBL's "
    "status report `<Idle|MPos:1.000,2.000,3.000|FS:0,0>` beside plain `ok` and `error:20` lines); the stream parser, "
    "checksum and line end stay the framing's. Every target takes it, labels too (the C: a `has_<field>` flag per "
    "labelled field, a repeat's too).",
)

MESSAGE = Obj(
    {
        "description": Str(TEXT.description, example="Sent once the move has finished."),
        "fields": FIELDS,
        "text": TEXT_LAYOUT,
        "optional": TEXT,
        "unsolicited": Bool(
            "Sent by the device on its own, not as an answer to its own command's request. It may still answer another "
            "request, one that names it in `answered_by` or that it names in `answers` (a sensor's measurement, "
            "streamed in active mode and sent when read in passive mode: PMS5003 `read: {request: {answered_by: "
            "{command: data}}}`): the client's method for that request waits for it and returns it.",
            default=False,
        ),
        "values_only": Bool(
            "Text frames, a response: the reply is its values alone, without its code (ODrive's ASCII protocol "
            "answers `f 0` with `1.2340 0.5000`: `feedback: {code: f, request: {fields: {motor: integer}}, "
            "response: {values_only: true, fields: {position: decimal, velocity: decimal}}}`; SCPI instruments "
            "answer `MEAS:VOLT?` with `+1.234E+00`). It is read "
            "as the reply to the request before it: `decode` refuses it without that request (`--request`), the "
            "stream parser takes it while the request awaits its reply (the client's, or the request just read in a "
            "stream of both directions), and the simulator answers with it. The C decoder reads it as the reply "
            "awaited; the Wireshark dissector as the reply to the request right before it in the capture.",
            default=False,
            example=True,
        ),
        "answers": Str(
            "For a response: the request (command or command.subcommand) it answers, if another. Replies that "
            "share the code of that request's own reply, told apart by their size (none `default`), answer it "
            "beside it: the client returns whichever comes (see `code`).",
            example="device_ping",
        ),
        "error_reply": Bool(
            "For a response: the reply a device sends instead of any request's own when it cannot carry it out, "
            "under the request's code plus the command element's `error_flag` (Modbus exception replies), or "
            "under the header's `error_value` (MSP's `$M!`), or with the status element's `error_bits` set (SHDLC's "
            "state byte). Its message carries the code of the refused request "
            "in a value named after the command element; clients raise DeviceError for it."
        ),
        "optional_when": OPTIONAL_WHEN,
        "after": Str("For a response: the request field (in ms) after which the device answers, e.g. a move's time."),
        "request_code": Str(
            "For a response that answers other commands' requests (`answered_by`): its integer field holding the "
            "command code of the request it answers (u-blox ACK: the acknowledged class and id). The client "
            "matches it, the simulator fills it in.",
            example="acked",
        ),
        "answered_by": Obj(
            {
                "command": Str("The command whose response answers this request (one reply layout for many)."),
                "command_in": Str(
                    "Instead of `command`: the request's integer field holding the code of the command whose "
                    "response answers it (Blue Robotics Ping's general_request: `requested_id`; a request for any "
                    "message). The client's method returns that command's reply, and refuses a code no command with "
                    "a response has before a byte is written; the simulator acts on it as on that command's request "
                    "sent with no content (`decode` and the stream parser read the reply by its own code).",
                    example="requested_id",
                ),
                "refused_by": ListOf(
                    Str(),
                    "Commands whose responses refuse this request instead (u-blox ACK-NAK): the client waits for "
                    "the `command`'s reply or one of these, and raises DeviceError naming the refusal. Where "
                    "layouts are chosen by command and replies carry no code, a refusal may travel in a layout of its "
                    "own that starts with another header: decode (given the request), the stream parser and the C "
                    "read a frame starting with it as the refusal (Bosch BNO055: a read answered by `BB length "
                    "data`, `refused_by: [write]`, whose reply is `EE status`).",
                    example=["nak"],
                ),
                "then": Str(
                    "Text frames: the command whose response ends the answer, after the reply (an AT command's "
                    "final `OK` after its `+NAME:` line; GRBL's `ok` after a `$` setting's line). The client's method "
                    "returns the reply once this response has come too, so the next request does not take it for its "
                    "own answer; a `refused_by` response in place of either raises DeviceError, and where the device "
                    "ends the answer without a reply the method says so (DeviceError). The simulator sends it after "
                    "each reply that is not a refusal.",
                    example="ok",
                ),
                "many": Bool(
                    "Text frames, with `then`: the reply comes any number of times, a line each, before the `then` "
                    "response (an AT module's `+CWLAP:` line per access point, then `OK`). The client's method "
                    "returns the tuple of them, in order (empty when the device ends the answer at once).",
                    default=False,
                    example=True,
                ),
                "optional_when": OPTIONAL_WHEN,
            },
            description="For a request: answered by another command's response (FEETECH's one status packet; in text "
            "frames GRBL's `ok`, with `refused_by: [error]`), named by `command`, or by the code a request field "
            "holds (`command_in`).",
        ),
        "default": Bool(
            "Among replies that share a code (or that all have none), the one a frame is decoded as when the "
            "request it answers is unknown; the others are chosen by the request they answer. Without one, such "
            "replies are told apart by their content size (see `code`). Code-less replies of "
            "different sizes in one layout with no length element, terminator or transform are sized by the reply "
            "awaited: a stream parser takes them only while it awaits one (`expect`, as the client does).",
            default=False,
            example=True,
        ),
        "source": SOURCE,
    },
    description="One direction of a command: its content fields and how it is sent.",
)

SUBCOMMAND = Obj(
    {
        "code": Int("Selector value."),
        "title": TITLE,
        "title_cn": TITLE_CN,
        "description": TEXT,
        "request": MESSAGE,
        "response": MESSAGE,
        "source": SOURCE,
    },
    required=("code",),
    description="A sub-command: its selector value and the fields of its request and response.",
)

COMMAND = Obj(
    {
        "code": IntOrText(
            (Int(), Str()),
            "Value of the frame's command field; omit for the one response of a protocol whose replies carry no "
            "command field. In text frames: the text code after the talker (NMEA's sentence id, GGA; GRBL's `$H`): "
            "letters, digits and `$!?~#%&+-./:;=@^_`, none of the framing's own characters. The requests of several "
            "commands may share a code when no content size fits two of them: each is its own message, "
            "decoded by its size (u-blox: an empty payload polls, a full one sets), or when each content begins "
            "with a constant field of one width, no two equal: each is picked by that value before its size "
            "(below, RTCM 3's message number). Told apart by size, they need a length element (the size is read "
            "before the message is known); picked by a constant, they need none where each has a size its own "
            "bytes tell (fixed fields, a count before what it counts, a NUL-terminated text last: iRobot's sensor "
            "queries `8E 16`, `8E 17`; Kondo ICS and MIDI below). Frames without a command element share the same "
            "way. Replies that share a code are told apart the same way where none of them is marked `default: "
            "true` (below, SPS30's measured values: 40, 20 or 0 bytes; Kondo ICS's replies by their command bits); "
            "with one, they are chosen by the request they answer.",
        ),
        "title": TITLE,
        "title_cn": TITLE_CN,
        "description": TEXT,
        "request": MESSAGE,
        "response": MESSAGE,
        "broadcast": TEXT,
        "checksum_seed": Int(
            "The byte taken in after the covered bytes by a checksum with `seed: per_command` (MAVLink's "
            "CRC_EXTRA of the message id); every command needs one when the frame has such a checksum.",
            example=50,
            minimum=0,
            maximum=255,
        ),
        "layout": OneOf(
            (Str(), MapOf(Str(), "direction -> layout name")),
            "With `framing.layouts`: the layout this command's frames travel in, a layout name or a mapping "
            "direction -> layout name (RoboClaw: reads send only address and command, and get data and a CRC; "
            "writes send data and a CRC, and get one 0xFF byte). Once a command names one, layouts are chosen by "
            "command, not by header: a command that names none travels in the first layout, a request frame is "
            "read in the layout of its code (a code sent in another layout is refused), and replies that carry no "
            "code are read in the layout of the request they answer: `decode` and `encode` refuse such a reply in "
            "one line without it (`--request HEX`), the stream parser takes none while no request is pending, and "
            "the client and the simulator give it. A layout may be constant bytes alone (RoboClaw's 0xFF "
            "acknowledgement: `ack: {role: header, value: FF, directions: [response]}`). Layouts chosen by command "
            "may differ in having a command element: a command without `code` travels in a layout without one, its "
            "frames told apart by their header (TFmini: data frames `59 59` with no command byte, `measurement: "
            "{layout: data}`, beside configuration frames `42 57 02 00`, parameters, the command byte last, "
            "`set_mode: {code: 0x11, layout: config}`); a command element after a content of one size per code, "
            "with no length, is found by trying each code's size. They may also carry different frame values (an "
            "`address`, `status` or `value` one layout has and another has not: RPLIDAR's response descriptor beside "
            "its headerless measurements): each message carries its own layout's (in the C, its struct holds its own "
            "layout's values). The C decoder takes such a spec where each frame "
            "says how to read it (replies through `p_decode_reply` with their request); the Wireshark dissector "
            "reads a reply with the last request before it in the capture, and marks one whose request is not in "
            "the capture (expert note `Request not in capture`).",
            example="read",
        ),
        "probe": Bool(
            "The command asks whether a device is there (PING): its client method returns True when the device "
            "answers and False when none does, whatever the reply holds. Every other command with a reply raises "
            "Timeout when none comes.",
            default=False,
            example=True,
        ),
        "source": SOURCE,
        "selector": Obj(
            {
                "type": Str("Wire type of the selector.", choices=SCALAR_TYPES, default="u8"),
                "name": Str("The selector's field name, as messages show it."),
                "offset": MapOf(Int(), "Byte offset of the selector in the content, by direction."),
            },
            required=("offset",),
            description="Where the sub-command selector sits in the content, by direction.",
        ),
        "subcommands": MapOf(SUBCOMMAND, "Sub-commands the selector picks: name -> sub-command."),
    },
    description="A command: its code, and the fields of its request and response.",
    variants=(
        (
            "Messages picked by their leading constant (RTCM 3: frames without a command element, each payload "
            "beginning with its 12-bit message number)",
            {
                "station": {
                    "request": {
                        "unsolicited": True,
                        "fields": {
                            "message_number": {"type": "u12", "const": 1005},
                            "station_id": "u12",
                            "height": "u16",
                        },
                    }
                },
                "descriptor": {
                    "request": {
                        "unsolicited": True,
                        "fields": {
                            "message_number": {"type": "u12", "const": 1033},
                            "station_id": "u12",
                            "antenna_size": "u8",
                            "antenna": {"type": "string", "size": "antenna_size"},
                        },
                    }
                },
            },
            "Where the requests that share a code (or all those of a frame without a command element) each begin "
            "with a constant integer field of one width (a bit field, `u12` here, or a whole-byte one), no two "
            "constants equal, decode, the stream parser, the C decoder and the Wireshark dissector read that many "
            "leading bits of the content and pick the message whose constant they hold, before its size: a "
            "`descriptor` of 5 bytes (antenna `A`) is a descriptor, though a `station` is 5 bytes too. A value no "
            "message has is refused in one line (`unknown message_number 1004`). Where some message has no such "
            "field, or widths or values clash, the messages are told apart by their content size alone, which no "
            "two may share. The reference says of each message that it is chosen by its constant. In a frame "
            "without a length element, each message picked so is sized by its own bytes (iRobot's Open Interface: "
            "`8E 16` asks for the voltage, `8E 17` the current, both `code: 0x8E` with `packet_id: {type: u8, "
            "const: 22}` or `23`; see the next example for messages of different sizes). Replies that share a code, "
            "none of them `default: true`, are picked the same way.",
        ),
        (
            "A value in the low bits of the command byte (MIDI's status byte, Firmata, Kondo ICS): no command "
            "element, each message beginning with its command bits",
            {
                "note_on": {
                    "request": {
                        "fields": {
                            "status": {"type": "u4", "const": 0x9},
                            "channel": "u4",
                            "key": {"type": "u8", "range": [0, 127]},
                            "velocity": {"type": "u8", "range": [0, 127]},
                        }
                    }
                },
                "pitch_bend": {
                    "request": {
                        "fields": {
                            "status": {"type": "u4", "const": 0xE},
                            "channel": "u4",
                            "bend": {"type": "u16", "encoding": "seven_bit"},
                        }
                    }
                },
                "timing_clock": {"request": {"fields": {"status": {"type": "u8", "const": 0xF8}}}},
            },
            "With `framing: {elements: {content: {role: content}}}` (no header, no command element, no length), the "
            "command byte's high bits are each message's leading constant bit field and its low bits the next "
            "field: `93 3C 64` is note_on on channel 3, `E3 00 40` pitch_bend 8192 on channel 3, `F8` "
            "timing_clock. Constants of different widths pick as a prefix code, each read as every value of the "
            "widest it begins (`0x9` of 4 bits is 0x90..0x9F beside `0xF8` of 8 bits): none may begin another "
            "(a `u4` 0xF beside `0xF8` would: they are then told apart by size, which needs a length element or a "
            "trailer), "
            "and the code is at most 256 values. Each "
            "message is sized by its own bytes (fixed fields, a count before what it counts, a NUL-terminated "
            "text last), so the frame needs no length; a stream parser finds each message's start by its "
            "constant. Replies are picked the same way (Kondo ICS: the servo answers `05 3A 4C`, command bits 0 "
            "and id 5, to the request `85 3A 4C`, command bits 4), with no `default: true`. The command element's "
            "`bits` cannot say this: a code and a field in one element.",
        ),
        (
            "Replies told apart by their size (Sensirion SPS30: Read Measured Values, 0x03, answers 40 bytes of "
            "floats, or 20 bytes of integers after Start Measurement asked for them, or nothing when no new values "
            "are there)",
            {
                "read_measured_values": {
                    "code": 0x03,
                    "request": {"fields": {}},
                    "response": {"fields": {"values": {"type": "array", "of": "f32", "count": 10}}},
                },
                "measured_values_u16": {
                    "code": 0x03,
                    "response": {
                        "answers": "read_measured_values",
                        "fields": {"values": {"type": "array", "of": "u16", "count": 10}},
                    },
                },
                "no_new_values": {"code": 0x03, "response": {"answers": "read_measured_values", "fields": {}}},
            },
            "Replies that share a code (and layout), none of them marked `default: true`, are each their own "
            "message, told apart by their content size like requests (a leading constant picks them likewise): "
            "decode without the request, the stream parser however the bytes are split, the C decoder and parser "
            "and the Wireshark dissector read a 20-byte reply under 0x03 as `measured_values_u16`. The frame needs "
            "a length element, a trailer (VISCA's inquiry replies, `90 50 ... FF`) or a transform, and no content "
            "size may fit two of them: a tie is refused in one line naming both "
            "(`code 0x03 in response frames is already used by 'read_measured_values', and a content of 40 bytes "
            "fits both`). A reply whose `answers` names a request answers it beside that request's own: the "
            "client's method returns whichever comes, whole (`ReadMeasuredValuesResponse | "
            "MeasuredValuesU16Response | NoNewValuesResponse`); the simulator answers with the request's own "
            "reply.",
        ),
    ),
)

ENUM = Obj(
    {
        "type": Str("Wire type of fields holding the enum.", choices=SCALAR_TYPES, default="u8"),
        "description": TEXT,
        "values": MapOf(
            OneOf(
                (
                    Int(),
                    Obj(
                        {
                            "value": Int("The wire value."),
                            "text": Str("What the value means (free text)."),
                            "text_cn": Str("The meaning as printed in the (Chinese) document.", example="释放"),
                        },
                        required=("value",),
                    ),
                ),
                "The wire value, or {value, text}.",
            ),
            "Label -> wire value.",
        ),
    },
    required=("values",),
    description="Names for the values of a field; decoded values become members of a generated IntEnum.",
)

FLAGS = Obj(
    {
        "type": Str("Wire type of fields holding the flags.", choices=SCALAR_TYPES, default="u8", example="u16"),
        "description": TEXT,
        "bits": MapOf(
            OneOf(
                (
                    Int(),
                    Obj(
                        {"bit": Int("Bit number (0 is the least significant)."), "text": TEXT},
                        required=("bit",),
                    ),
                ),
                "A bit number, or {bit, text}.",
            ),
            "Flag name -> bit number.",
        ),
    },
    required=("bits",),
    description="Names for the bits of a field; decoded values become a generated IntFlag.",
)

TABLE_ENTRY = Obj(
    {
        "key": Int("data_id or register address."),
        "type": Str("Wire type of the value.", choices=SCALAR_TYPES),
        "name_cn": Str("The name as printed in the (Chinese) document."),
        "description": TEXT,
        "unit": Str("Unit of one wire step, e.g. mV, 0.1°."),
        "scale": Num("Engineering value = wire value × scale."),
        "range": RANGE,
        "default": OneOf((Num(), Str()), "The value after a reset: a number, or text when the document gives none."),
        "access": Str(
            "r (read-only), rw (readable and writable), or w1c (readable; a write clears the bits written as 1 and "
            "leaves the others: status flags a datasheet marks R+WC or W1C, as the TMC2209's GSTAT).",
            choices=("r", "rw", "w1c"),
            default="rw",
        ),
        "memory": Str("Where the device keeps it: eeprom (kept over power-off) or sram.", choices=("eeprom", "sram")),
        "enum": Str("Name of an entry in `enums:`."),
        "flags": Str("Name of an entry in `flags:`."),
        "encoding": Str(
            "How the integer is stored (see a field's `encoding`).",
            choices=("plain", "sign_magnitude"),
            default="plain",
        ),
        "sign_bit": Int("sign_magnitude: the bit holding the sign when it is not the top bit (FEETECH load: 10)."),
        "reserved": Bool("A slot the document reserves: no name of its own.", default=False),
        "source": SOURCE,
    },
    required=("key", "type"),
    description="One parameter or register of the table.",
)

TABLE = Obj(
    {
        "title": TITLE,
        "key": Str("What the key is called on the wire (data_id, address)."),
        "description": TEXT,
        "source": SOURCE,
        "entries": MapOf(TABLE_ENTRY, "The table's entries: name -> entry."),
    },
    required=("key", "entries"),
    description="Parameters or registers addressed by a key (a data_id, a register address).",
)


def span(description: str) -> OneOf:
    """A span of frame elements: [first, last] (inclusive), or a mapping direction -> [first, last]."""
    return OneOf(
        (
            ListOf(Str(), "[first, last] frame element names", length=2),
            MapOf(ListOf(Str(), "[first, last] frame element names", length=2), "direction -> [first, last]"),
        ),
        f"{description} [first, last] frame element names, or a mapping direction -> [first, last].",
    )


def checksum_keys() -> dict[str, Shape]:
    """The checksum element's keys that the algorithms own (serialspec/checksums/): `algorithm`, whose choices are
    the registered algorithms, and each algorithm's own keys."""
    found = checksums.algorithms()
    described = "; ".join(f"`{name}`, {algorithm.summary}" for name, algorithm in found.items())
    keys: dict[str, Shape] = {"algorithm": Str(f"checksum: what it computes: {described}.", choices=tuple(found))}
    for algorithm in found.values():
        keys |= {key.name: _shape(key) for key in algorithm.keys}
    return keys


def _shape(key: Key | TransformKey) -> Shape:
    """The shape of a checksum algorithm's or a transform's key, as its registry gives it (plain data)."""
    match key.kind:
        case "bool":
            return Bool(key.description, default=key.default, example=key.example)
        case "int":
            return Int(
                key.description, default=key.default, example=key.example, minimum=key.minimum, maximum=key.maximum
            )
        case "str" | "hex":
            return Str(key.description, default=key.default, example=key.example)
        case "hex_map":
            return MapOf(HEX_BYTES, key.description)
        case "object":
            assert isinstance(key, Key)
            keys = {k.name: _shape(k) for k in key.keys}
            return Obj(keys, required=key.required, description=key.description)
        case _:
            assert_never(key.kind)


FRAME_ELEMENT = Obj(
    {
        "role": Str(
            "What the element is: constant bytes (header first, trailer last, constant anywhere, e.g. a reserved "
            "byte), a frame-level value (address, command, status, or a plain `value` every message carries: a "
            "sequence number, a flags byte), the length, the content, a checksum, or `optional` bytes that are "
            "sent only when `present_if` holds (MAVLink v2's signature after the CRC). A frame value in some "
            "alternative layouts only (the Pololu form's device number) is None in messages of the others (see "
            "`framing.layouts`).",
            choices=(
                "header",
                "trailer",
                "constant",
                "command",
                "length",
                "content",
                "checksum",
                "address",
                "status",
                "value",
                "optional",
            ),
        ),
        "type": Str(
            "Wire type of a value, length or checksum (default u8); u24 for a checksum only (RTCM 3's CRC-24Q); u4 "
            "for an address, command, status or value sent as ONE hex digit inside a hex_ascii span, before the "
            "content (Victron VE.Direct HEX: `:`, the command as one digit, then bytes as pairs: `command: {role: "
            "command, type: u4}`); a checksum takes it in as a byte 0..15.",
            choices=(*SCALAR_TYPES, "u24", "u4"),
        ),
        "endian": Str(
            "Byte order of a multi-byte element (default little, whatever the protocol's byte_order).",
            choices=("little", "big"),
            default="little",
            example="big",
        ),
        "value": OneOf(
            (Str(), MapOf(Str(), "direction -> hex bytes")),
            "Constant bytes as hex, or a mapping direction -> hex bytes. On a header, trailer or constant: its "
            "bytes. On any other element: in the directions given, the element is these constant bytes instead "
            "(DYNAMIXEL status packets carry 55 where requests carry the instruction).",
        ),
        "directions": ListOf(
            Str(choices=("request", "response")), "The directions whose frames have it (default both)."
        ),
        "error_flag": Int(
            "command: a bit a device sets in the code of a reply that refuses the request (Modbus: 0x80); such a "
            "reply has the layout of the command whose response is the `error_reply`."
        ),
        "error_bits": Int(
            "status: bits whose being set in a reply's status make it an error reply (SHDLC: 0x7F, the execution "
            "error code of the state byte); such a reply carries the refused request's code in the command element, "
            "its status as it is, and its content is that of the command whose response is the `error_reply`; a "
            "reply whose status has none of them is the command's own. Encode refuses an error reply without one "
            "of them set and any other reply with one; clients raise DeviceError naming the status.",
            example=0x7F,
        ),
        "error_value": Str(
            "header: the bytes a response starts with instead of its `value` when it refuses the request (MSP: "
            "`24 4d 21`, `$M!` where replies carry `$M>`); such a reply has the response's layout, its command "
            "element carries the refused request's code and its content is that of the command whose response is "
            "the `error_reply`.",
            example="24 4d 21",
        ),
        "reply_code": Str(
            "command: the code response frames carry, as an expression of the request's `code` (HerkuleX: "
            "`code | 0x40`, so STAT 0x07 is answered under 0x47). Every command's reply then has that code, computed "
            "when the spec is read: encode writes it, decode (without `--direction` too) and the stream parser read "
            "a reply by it, the simulator answers with it and clients match replies as usual (by command). With "
            "alternative layouts, every layout's command element gives the same one, unless layouts are chosen by "
            "command (`layout:`): then only the commands whose replies travel in a layout that gives it have a reply "
            "code (HLK-LD2410: ACKs under `code | 0x0100` in the command layout, beside reports whose type byte is "
            "their own code in a report layout without it). Where requests and replies have command elements of "
            "their own (`directions:`), it goes on either, and `code` is the request's, which may be wider than "
            'the reply\'s (a u16 request code, a u8 reply code: `reply_code: "code & 0xFF"`); without it, a code '
            "that does not fit the replies' command element is refused in one line.",
            example="code | 0x40",
        ),
        "code": Str(
            "command: the code this layout's frames carry, as an expression of the command's `code`, where one "
            "protocol sends the same commands in two frame forms (the Pololu Maestro's Pololu protocol: `AA`, a "
            "device number, then the command with bit 7 cleared, `code & 0x7F`; its compact protocol sends the "
            "code itself). Computed when the spec is read: no two commands may carry the same code in the layout, "
            "encode writes it, decode and the stream parser read the command by it.",
            example="code & 0x7F",
        ),
        "counts": span(
            "length: the span of elements it counts (within a transparency span their plain bytes, over more than "
            "it the bytes as sent); default the content only. It may start at the length itself (LX-16A: "
            "`counts: [length, checksum]`, N parameters + 3), which counts its own bytes too, or at an element of "
            "fixed size before it, outside a transparency span (Benewake TFmini Plus: `counts: [head, checksum]`, "
            "the whole frame from its header), which counts those too.",
        ),
        "adds": Int("length: added to the counted size (SMS: 2 = instruction + checksum); may be negative.", default=0),
        "extended": Obj(
            {
                "when": Int(
                    "The value of the one-byte length that says the wider length follows (Xsens MT: 0xFF; MQTT-SN: "
                    "0x01). It must lie at an end of the short form's range (or outside it): the short form holds "
                    "every other value of the range that fits a byte.",
                    minimum=0,
                    maximum=255,
                    example=255,
                ),
                "type": Str(
                    "The wider length's type, sent after `when` most significant byte first.",
                    choices=("u16",),
                    example="u16",
                ),
            },
            required=("when", "type"),
            description=(
                "length: a u8 length that says a larger size in a wider length after it (Xsens MT: `LEN` 0xFF, then "
                "the size as a big-endian u16; MQTT-SN: 0x01, then the message's length as a u16). Encode sends "
                "the one-byte form when the value fits it (and its `range`), else `when` and the wider value; "
                "decode, the stream parser, the C and the Wireshark dissector read either, a long form holding a "
                "small value too (MQTT-SN allows it). `range` bounds the value in both forms; a length that counts "
                "itself counts the bytes of the form sent (1, or 3). Not inside a transparency span, nor in a "
                "layout with optional elements."
            ),
        ),
        "description": TEXT,
        "range": ListOf(
            Num(),
            "Inclusive [min, max] of the value in wire units; checked before encoding. An address, status or value "
            "outside it, or a length outside it (CRSF: [2, 62]; RTCM 3: [0, 1023], its 6 reserved bits above a "
            "10-bit length read as one u16 kept 0), makes a candidate no frame: decode refuses it in one line, the "
            "stream parser looks past it at once (not waiting for the bytes the length claims), the C and the "
            "Wireshark dissector likewise; encode refuses a frame whose length would be outside it.",
            length=2,
        ),
        "broadcast": Int("address: the broadcast value."),
        "sequence": Bool(
            "value: a sequence number the client fills in: 0 in its first request, one more in each request after "
            "it, back to 0 past the element's largest value. A reply repeats it; name it in `matching.by` to match "
            "replies by it.",
            default=False,
            example=True,
        ),
        "ok": ListOf(
            Int(),
            "status: the values that mean the device carried out the request (default: 0, or with `bits` every bit "
            "field 0): clients raise DeviceError for a reply whose status holds any other, naming it (Trinamic TMCL: "
            "`ok: [100, 101]`, done and stored in EEPROM; below 100 an error). Not with `bits`.",
            example=[100, 101],
        ),
        "flags": Str("status (address, value): name of an entry in `flags:`."),
        "bits": bit_fields(
            "status, address or value: bit fields packed into the element (DYNAMIXEL: alert bit 7, error number "
            "6..0); refused on any other element, whose value no message carries."
        ),
        "covers": span(
            "checksum: the span of elements covered. Within a transparency span (all of it, or part) it sees the "
            "bytes before the transform, over more than it or outside it the bytes as sent. Checksums strictly "
            "inside the span (itself too) are left out of it (HerkuleX: `checksum1` in the header covers [size, "
            "data]); one at an end is covered, so a checksum can be computed from another that comes before it "
            "(HerkuleX `checksum2: {algorithm: xor, invert: true, mask: 0xFE, covers: [checksum1, checksum1]}`).",
        ),
        "seed": Str(
            "checksum: `per_command`, one byte that each command gives in `checksum_seed` is taken in after the "
            "covered bytes (MAVLink's CRC_EXTRA); the command element must lie in the covered span, after "
            "elements of fixed size only. A frame whose code no command has gets no seed.",
            choices=("per_command",),
            example="per_command",
        ),
        "from_request": ListOf(
            Str(),
            "checksum (of a response): elements of the request this reply answers whose bytes the checksum takes "
            "in first, in this order, before the span it covers (RoboClaw: the reply CRC starts with the "
            "request's address and command, which the reply does not carry). Decoding such a reply needs its "
            "request: `decode` without one refuses it in one line (give `--request HEX`), the stream parser reads "
            "such replies only while a request is pending (the client and the simulator have it); the Wireshark "
            "dissector verifies it with the last request before it in the capture, and says when that is missing.",
            example=["address", "command"],
        ),
        "encoding": Str(
            "checksum: `seven_bit`, its value sent 7 bits a byte, bit 7 of each clear, in the element's byte order "
            "(Dimension Engineering's Kangaroo: a CRC-14 as two 7-bit bytes, low first, `type: u16, encoding: "
            "seven_bit` with `crc: {width: 14, ...}`); the element keeps the value's low 7 bits a byte (a CRC's "
            "width must be those: 14 for a u16), and a frame with bit 7 set in one of its bytes fails the checksum.",
            choices=("plain", seven_bit.NAME),
            default="plain",
            example=seven_bit.NAME,
        ),
        "size": Int("optional: its size in bytes.", example=13),
        "present_if": Str(
            "optional: when the element is in the frame, as `<element> & <mask>`: it is there when any bit of "
            "`mask` is set in that earlier element of fixed position before the content (a constant, value, address "
            "or status). Messages carry the element's bytes as an attribute of its name (None: not sent) and "
            "`--json` as hex. A constant flag element keeps its other bits: encode sets the mask's bits when the "
            "message has the bytes and clears them when it has None; a value flag element is the message's own "
            "value, and a message whose value and bytes disagree is refused before a byte is written. It lies "
            "outside every length's and checksum's span and outside the transparency span (MAVLink v2: "
            '`signature: {role: optional, size: 13, present_if: "incompat_flags & 0x01"}` after the CRC; a '
            "receiver that knows the secret key checks it). In C, every message struct of the direction has "
            "`bool has_<name>` and `uint8_t <name>[size]`, and the C refuses a disagreeing value flag with "
            "`P_E_RANGE`.",
            example="incompat_flags & 0x01",
        ),
        "truncate": Str(
            "content: `trailing_zeros`, encode drops the content's trailing zero bytes (keeping at least one) and "
            "the length says the size sent; decode pads a shorter content with zero bytes to its command's size "
            "(MAVLink v2 payload truncation). Every command's content must have one size.",
            choices=("trailing_zeros",),
            example="trailing_zeros",
        ),
        **checksum_keys(),
    },
    required=("role",),
    description="One element of the frame, in wire order.",
    variants=(
        (
            "A CRC over the low 7 bits of each byte, sent 7 bits a byte (Dimension Engineering's Kangaroo: address "
            "128..135, command, length, data, then a CRC-14 as two 7-bit bytes, low first)",
            {
                "crc": {
                    "role": "checksum",
                    "type": "u16",
                    "encoding": "seven_bit",
                    "algorithm": "crc",
                    "crc": KANGAROO_CRC14,
                    "covers": ["address", "content"],
                }
            },
            "`80 20 02 31 00 22 44` (start channel '1') checks: the CRC of the low 7 bits of 80 20 02 31 00 is 0x2222, "
            "sent as 22 44. A library's reflected polynomial (Kangaroo's 0x22F0) is `poly` reflected over the width "
            "(0x03D1); the check value is of '123456789', whose bytes are 7-bit already.",
        ),
        (
            "A one-byte length with a long form (Xsens MT: `FA FF MID LEN DATA CHECKSUM`, LEN 0..254 the data's size, "
            "LEN FF then the size as a big-endian u16 for 255..2048 bytes)",
            {
                "len": {
                    "role": "length",
                    "type": "u8",
                    "extended": {"when": 0xFF, "type": "u16"},
                    "range": [0, 2048],
                }
            },
            "GoToConfig is `FA FF 30 00 D1`; an MTData2 (0x36) of 255 data bytes is `FA FF 36 FF 00 FF` then the data "
            "and its checksum: LEN FF is the marker, so 255 bytes already take the long form, and the checksum, a "
            "`sum` with `negate: true` over [bid, data], covers the long form's three bytes. MQTT-SN's length counts "
            "the whole message, itself too, 0x01 then a u16 from 256 bytes on: `length: {role: length, type: u8, "
            "extended: {when: 0x01, type: u16}, counts: [length, content], range: [2, 65535]}` (the one-byte form "
            "2..255, the long one 3 bytes of the count). Encode picks the one-byte form whenever the value fits it; "
            "a long form holding a small value is read as well.",
        ),
        (
            "Error replies told by their status (SHDLC's state byte: an execution error code in bits 6..0, the "
            "device's error flag in bit 7)",
            {
                "state": {
                    "role": "status",
                    "type": "u8",
                    "directions": ["response"],
                    "error_bits": 0x7F,
                    "bits": {"error": {"bits": 7}, "code": {"bits": [6, 0], "enum": "execution_error"}},
                }
            },
            "With a command `refused: {response: {error_reply: true, fields: {}}}` (no `code`), `7E 00 D1 43 00 EB "
            "7E` decodes as `refused` with `command` = 0xD1 (the refused request, Read Version) and `state.code` = "
            "0x43, its length 0 where Read Version's reply carries 7 bytes; `state` = 0x80 (bit 7 alone) is a normal "
            "reply. The status must come before the content and the frame needs a command element; one of "
            "`error_flag`, `error_value` and `error_bits` per protocol.",
        ),
    ),
)

FRAME_ELEMENTS = MapOf(FRAME_ELEMENT, "The frame's elements in wire order: name -> element.")


def transform_keys() -> dict[str, Shape]:
    """The `transparency:` keys that the transforms own (serialspec/transforms/): `method`, whose choices are the
    registered transforms, and each transform's own keys."""
    found = transforms.transforms()
    described = "; ".join(f"`{name}`, {transform.summary}" for name, transform in found.items())
    keys: dict[str, Shape] = {
        "method": Str(
            f"How the span is rewritten: {described}.",
            choices=tuple(found),
            default=transforms.DEFAULT,
            example=max(found, key=lambda name: name != transforms.DEFAULT),
        )
    }
    for transform in found.values():
        keys |= {key.name: _shape(key) for key in transform.keys}
    return keys


TRANSPARENCY = Obj(
    {
        "span": span("The elements whose bytes are rewritten."),
        **transform_keys(),
        "description": TEXT,
    },
    required=("span",),
    variants=tuple(
        (f"`method: {name}`, {sample.label}", dict(sample.framing), transform.worked_sample(sample))
        for name, transform in transforms.transforms().items()
        for sample in transform.samples
    ),
    description=(
        "A transform of the bytes of a span (byte stuffing, escaping, COBS), applied by encode and removed by "
        "decode and the stream parser. A length or checksum over elements within the span (all of it, or part) "
        "counts and covers their plain bytes, before the transform; one over more than the span, or outside it, the "
        "bytes as sent. A length or checksum that lies inside the span is transformed with it."
    ),
)

FRAMING = Obj(
    {
        "elements": FRAME_ELEMENTS,
        "layouts": MapOf(
            Obj(
                {
                    "description": Str(TEXT.description, example="Payloads of up to 255 bytes."),
                    "elements": FRAME_ELEMENTS,
                },
                required=("elements",),
                description="One alternative layout: its elements in wire order.",
            ),
            "Alternative layouts (instead of `elements`), told apart by their headers; encode uses the first "
            "whose command element holds the code and whose length can count the frame (VESC: 02 + u8 length, 03 "
            "+ u16 length; MSP v1 `$M<`, u8 size, u8 command, XOR, beside v2 `$X<`, u16 command, u16 size, "
            "CRC-8/DVB-S2: a code above 255 is sent in v2, any other in v1; a code must fit one layout; the C "
            "encoder likewise sends a code in the first layout whose command element holds it). They all have a "
            "command element or none, unless each command names its layout (`layout:`). One layout may have no "
            "header if it starts with its command element: it takes every frame that starts with no other "
            "layout's header, and no code it sends may start as a header does (checked when the spec is read), so"
            " a frame is told by its first bytes alone. Layouts that are the same in one direction are one layout"
            " there. The Pololu Maestro's two forms of the same commands: `compact: {elements: {command: {role: "
            "command}, content: {role: content}}}` (84 02 70 2E) and `pololu: {elements: {start: {role: header, "
            'value: AA}, command: {role: command, code: "code & 0x7F"}, content: {role: content}}}` (AA 04 02 70 '
            "2E): both decode to Set Target, a frame starting AA is the Pololu form (no command code is AA). "
            "Layouts told apart by their header may carry different frame values (address, status, value "
            "elements; one name is one role, type and range wherever it is): every message of the direction "
            "carries each of them, None in a frame whose layout has no such element, and is sent in the layout "
            "carrying exactly the values it gives (the Pololu form's `device: {role: address, type: u8, range: "
            "[0, 127]}` after AA: `device=12` sends AA 0C 04 02 70 2E, `device=None` the compact 84 02 70 2E; "
            "the client takes None for the device number; the simulator answers a frame without it as its first "
            "device, in a form without it where replies carry it too; the C target refuses such a spec, its "
            "structs' integers holding no None).",
        ),
        "transparency": TRANSPARENCY,
        "gap": Num("Silence between frames, in character times (Modbus RTU: 3.5).", example=3.5),
        "turnaround": Num(
            "Seconds the client waits after a request no device answers (one sent to the address element's "
            "`broadcast` value) before it writes again, so that every device has carried it out (Modbus serial line "
            "§2.4.1's turnaround delay, typically 100 to 200 ms). 0: no wait beyond `gap`.",
            example=0.1,
        ),
        "description": TEXT,
        "kind": Str(
            "binary: frames of bytes described by `elements` or `layouts`; text: line-oriented text frames "
            "(`start`, `separator`, `checksum`, `end`, `talker`), each message chosen by its command's text `code`; "
            "a command's request and its response share the code, unless its `text` gives another (decode takes "
            "the direction; the simulator reads requests, the client answers; a text device answers as its "
            "`device.commands` entry says: `stores`, `sets`, `reports`, `echoes`).",
            choices=("binary", "text"),
            default="binary",
            example="text",
        ),
        "start": OneOf(
            (
                Str(),
                Obj(
                    {
                        "request": Str("The requests' start (`#`).", example="#"),
                        "response": Str("The responses' start (`*`).", example="*"),
                    },
                    required=("request", "response"),
                ),
            ),
            "text: the character that starts every frame; without one, each line is a frame (`V=12.1` then the "
            "line ending) and the stream parser resynchronises at the next line ending. A mapping gives each "
            'direction its own (Lynxmotion LSS: `start: {request: "#", response: "*"}`, `#5QD` asked and '
            "`*5QD1800` answered): a frame's start then says its direction.",
            example="$",
        ),
        "separator": Str("text: the character between fields.", example=","),
        "end": OneOf(
            (
                Str(),
                Obj(
                    {
                        "request": Str("The requests' line ending (`\\r`).", example="\r"),
                        "response": Str("The responses' line ending (`\\r\\r>`).", example="\r\r>"),
                    },
                    required=("request", "response"),
                ),
            ),
            "text: the line ending that closes every frame. A mapping gives each direction its own (an ELM327 "
            'OBD-II adapter: `end: {request: "\\r", response: "\\r\\r>"}`, its reply ended by CR, a blank line '
            "and its `>` prompt): the stream parser of one direction waits for that direction's, and one reading "
            "both takes the longest that ends a frame.",
            example="\r\n",
        ),
        "checksum": Obj(
            {
                "algorithm": Str(
                    "What it computes over the characters: `xor`, the XOR of their bytes (NMEA 0183); `sum`, their "
                    "sum modulo 256 (as a checksum element's).",
                    choices=("sum", "xor"),
                ),
                "invert": Bool("sum: bitwise NOT of the sum.", default=False, example=True),
                "marker": Str("The character before the checksum's digits.", default="*"),
                "format": Str(
                    "How the checksum is written: hex2, two upper-case hex digits (an 8-bit checksum, NMEA 0183); "
                    "decimal, its value in decimal digits without leading zeros, 0 to 255 (G-code's line checksum, "
                    "Marlin and RepRap firmware: `N1 G28*18`; ODrive's ASCII protocol).",
                    choices=("hex2", "decimal"),
                    default="hex2",
                    example="decimal",
                ),
                "required": Bool(
                    "Frames without a checksum are refused (false: accepted unchecked, as NMEA 0183 allows for "
                    "some sentences; a message decoded without one is encoded again without one, and the simulator "
                    "answers a request sent without one without one, as the ODrive does).",
                    default=True,
                    example=False,
                ),
                "separated": ListOf(
                    Str(choices=("request", "response")),
                    "The directions whose frames write the separator between the last field and the marker, "
                    "covered by the checksum (ODrive's documented request `r vbus_voltage *93`; its replies, "
                    "`12.5*48`, do not: `separated: [request]`); decode also takes such a frame without it.",
                    example=["request"],
                ),
                "directions": ListOf(
                    Str(choices=("request", "response")),
                    "The directions whose frames carry it (default both): G-code's numbered lines carry one, the "
                    "firmware's `ok` and `Resend: 124` none (`directions: [request]`); a frame of the other "
                    "direction is text to its end, the marker too.",
                    example=["request"],
                ),
            },
            required=("algorithm",),
            description=(
                "text: the checksum over the characters between `start` and `marker`, written after `marker` as "
                "hex digits (or decimal ones: `format`), before the line ending."
            ),
        ),
        "talker": Obj(
            {
                "size": Int("Characters of the talker at the start of the address field.", minimum=1),
                "values": ListOf(Str(), "The talkers encode accepts (every one when left out).", example=["GP"]),
                "description": TEXT,
            },
            required=("size",),
            description=(
                "text: a frame-level value at the start of the first field, before the text code (NMEA's talker "
                "id: GP in $GPGGA); every message carries it as `talker`."
            ),
        ),
        "address": Str(
            "text: a shared integer field (its name in `fields:`) that every message carries first, its digits "
            "written right after the start and before the talker and code, with nothing between (Lynxmotion LSS's "
            "servo id: `address: id` reads `#5D1800` as id 5, code D, 1800). Messages, JSON and client methods have "
            "it as a field; the simulator answers with the request's.",
            example="id",
        ),
        "max_length": Int(
            "text: the longest frame in characters, start to checksum (NMEA 0183: 82 with the line ending): the "
            "stream parser drops a line that grows longer.",
            minimum=1,
            example=82,
        ),
    },
    description=(
        "The frame every command travels in: `elements` (one layout) or `layouts` (alternatives), or with "
        "`kind: text` a line of text fields."
    ),
    variants=(
        (
            "Text frames whose replies are not written as their requests (an ELM327 OBD-II adapter: `010C` and CR "
            "asked, `41 0C 1A F8 ` answered, then CR, a blank line and its `>` prompt)",
            {
                "framing": {"kind": "text", "separator": " ", "end": {"request": "\r", "response": "\r\r>"}},
                "commands": {
                    "engine_rpm": {
                        "code": "010C",
                        "request": {"fields": {}},
                        "response": {
                            "text": {"code": "41 0C", "end": " "},
                            "fields": {
                                "a": {"type": "integer", "base": 16, "width": 2, "range": [0, 255]},
                                "b": {"type": "integer", "base": 16, "width": 2, "range": [0, 255]},
                            },
                        },
                    }
                },
            },
            "Three keys of text frames, each usable alone. `end` as a mapping gives each direction its own line "
            "ending: encode, the client and the simulator write a frame's own, decode takes it off, the stream "
            "parser of one direction waits for that direction's and one of both directions (a monitor's) takes "
            "the longest that ends a frame (a request's CR is not taken while the CR CR `>` of a reply may still "
            "come). A response's `text: {code: ...}` is the code its frames carry instead of its command's, here "
            'two words (mode + 0x40, then the PID), and `end: " "` the space after its last byte; the reply is '
            "found by that code (the longest that fits), and the client, the simulator and the stream parser pair "
            'it with its request as usual. An AT modem\'s `+CSQ: 20,99` answering `AT+CSQ` is `code: "+CSQ:"` '
            'with `after_code: " "` (the framing\'s `separator: ","` between its values). `base: 16` writes an '
            "integer field as hex digits (`1A F8`: a = 26, b = 248, the engine at (256 a + b) / 4 = 1726 rpm), "
            "zero-padded to `width` digits, "
            "in upper case (`case: lower` for lower case), a negative value after `-`; decode reads either case. "
            "The C target writes and reads hex integers (up to 15 digits, as decimal ones up to 18).",
        ),
    ),
)

EXAMPLE = Obj(
    {
        "source": Str("Document and section the frame is printed in."),
        "description": TEXT,
        "direction": Str("The direction the frame travels in.", choices=("request", "response")),
        "printed": Str("The frame exactly as the document prints it."),
        "printed_as": Str(
            "How `printed` (and the frame, where `frame` is not given) is read: hex bytes, or the frame's ASCII "
            "characters for frames sent as text (hex-ASCII spans, Modbus ASCII: `:010300000001FB`), its trailer "
            "(CR LF) left out as documents print it.",
            choices=("hex", "text"),
            default="hex",
            example="text",
        ),
        "printed_span": ListOf(
            Str(),
            "When the document prints only part of the frame (Modbus prints the PDU: function and data), the first "
            "and last frame element it prints; `frame` is then the whole frame.",
            length=2,
        ),
        "frame": HEX_BYTES,
        "erratum": Str("Name of the erratum that explains why `frame` differs from `printed`."),
        "completed": Str(
            "The document prints no complete frame here (a placeholder such as `CRC` for the check byte, or the "
            "values as a table): how `frame` completes it. A printing convention, not an erratum."
        ),
        "command": Str("The command the frame decodes as."),
        "subcommand": Str("Its sub-command, where the command has them."),
        "request": Str("Name of the example whose request this example answers."),
        "fields": MapOf(
            Any_(),
            "The field values the frame carries (raw wire values); a value encode computes (a `const`, a count, a "
            "`value:` expression), which messages leave out, may be recorded too, as the frame holds it.",
        ),
    },
    required=("source", "direction", "printed", "command", "fields"),
    description="A frame as a document prints it, with the fields it carries; the tests decode and encode it.",
    missing_hints={
        "source": "the document and section the frame is printed in, e.g. `source: manual 4.2`; a top-level "
        "`sources:` may name each document",
        "printed": "the frame as the document prints it, e.g. `printed: AA 01 02 01 32 DE`; `frame` only where the "
        "bytes sent differ from it",
        "fields": "the field values the frame carries; `fields: {}` for a message without fields",
    },
)

ERRATUM = Obj(
    {
        "source": Str("Document and section."),
        "printed": Str("What the document says."),
        "correct": Str("What is right, and why."),
        "check": Obj(
            {
                "kind": Str(
                    "The test: the printed frame fails to decode, decodes as given, a checksum's real value, "
                    "CRC parameters that contradict their check value, or prose (no test).",
                    choices=("frame_fails", "frame_decodes_as", "checksum_value", "crc_parameters", "prose"),
                ),
                "frame": HEX_BYTES,
                "direction": Str("The direction of `frame`.", choices=("request", "response")),
                "error": Str("frame_fails: words the one-line decode error contains."),
                "command": Str("frame_decodes_as: the command the frame decodes as."),
                "subcommand": Str("frame_decodes_as: its sub-command."),
                "fields": MapOf(Any_(), "frame_decodes_as: the field values it decodes to."),
                "claimed": Any_("checksum_value: the claimed value; crc_parameters: the claimed parameters."),
                "actual": Int("checksum_value: the value the bytes really give."),
                "examples": ListOf(Str(), "Examples whose frames the check runs over."),
            },
            required=("kind",),
            description="How a test pins the right reading.",
        ),
    },
    required=("source", "printed", "correct", "check"),
    description="A mistake in a document: what it prints, what is right, and the test that pins the right reading.",
)

REPLY_VALUES = (
    "Response field -> value when no behaviour sets it (e.g. result: 1; text for text and bytes fields, bytes as "
    "hex: VESC hw_name: '60'; a list for a list, array or group field: its numbers, or for a group one mapping of "
    "its fields per item, as u-blox MON-VER's extensions: `[{extension: FWVER=SPG 5.10}, {extension: "
    "PROTVER=34.10}]`). A `field.bit_field` key sets one bit field of every response that has the field (each "
    "must have that bit field; its bit fields not named are 0): a field made of bit fields takes its values so, "
    "not as a whole number (SiRF's `mode1.position: 4`)."
)
_REPLY_ITEM_VALUE = OneOf((Num(), Str()), REPLY_VALUES)
REPLY_VALUE = OneOf(
    (
        Num(),
        Str(),
        ListOf(
            OneOf((Num(), Str(), MapOf(OneOf((Num(), Str(), ListOf(_REPLY_ITEM_VALUE)), REPLY_VALUES))), REPLY_VALUES),
            REPLY_VALUES,
        ),
    ),
    REPLY_VALUES,
)

SPACE_ACCESS = Obj(
    {
        "space": Str("The data space (an entry of the device's `spaces:`)."),
        "start": Str("The request field holding the first item's address."),
        "count": Str("reads: the request field holding how many items are read."),
        "value": Str(
            "writes: what is stored, as an expression of the request's fields and `current` (the item's present "
            "value), e.g. Modbus Mask Write `(current & and_mask) | (or_mask & ~and_mask)`; default: the field."
        ),
    },
    required=("space", "start"),
    description="A run of items of a data space, from the address a request field gives.",
)

DEVICE_COMMAND = Obj(
    {
        "description": Str(TEXT.description, example="The servo moves to the goal position over goal_time."),
        "reads": OneOf(
            (
                ListOf(Str(), "Response fields filled from memory: table_value by its key, table_block entries."),
                MapOf(SPACE_ACCESS, "Response field -> the run of a data space it holds (Modbus registers)."),
            ),
            "a list of response fields read from memory, or a mapping response field -> data space run",
        ),
        "writes": OneOf(
            (
                ListOf(Str(), "Request fields stored in memory: table_value by its key, table_block entries."),
                MapOf(SPACE_ACCESS, "Request field -> the run of a data space it is stored in (a value or a list)."),
            ),
            "a list of request fields stored in memory, or a mapping request field -> data space run",
        ),
        "resets": Bool(
            "Memory goes back to its defaults (all but the device's id, unless `keeps` says otherwise).", default=False
        ),
        "keeps": Obj(
            {
                "field": Str("The request field that chooses (DYNAMIXEL FACTORY RESET `option`)."),
                "entries": MapOf(
                    ListOf(Str(), "the memory entries a reset keeps"),
                    "Field value -> the memory entries a reset keeps.",
                    int_keys=True,
                ),
            },
            required=("field", "entries"),
            description="resets: the entries kept, chosen by a request field (0xFF: none, 0x01: id, ...).",
        ),
        "reports": MapOf(
            OneOf((Int(), Str())),
            "Response field -> the state variable or memory entry it reports, or an expression of them where the "
            "units differ (VESC duty_now in 0.001 from a duty in 0.00001: `duty / 100`), or a number (a MediaTek "
            "PMTK001 acknowledging command 220: `{command: 220, flag: 3}`; in a text `char` field a number is "
            "written as its digit, the flag's letter `3`).",
        ),
        "moves": Obj(
            {
                "state": Str("The state variable (or memory entry) that moves."),
                "target": Str("The request field (or memory entry, once written) with the target."),
                "duration": Str("The request field (or memory entry) with the time to reach the target, in ms."),
                "speed": Str("The request field (or memory entry) with the speed, in state units per second."),
                "speed_scale": Num(
                    "State units per second for one unit of `speed` (DYNAMIXEL: 0.229 rev/min x 4096 / 60 = 15.63)."
                ),
                "enabled_by": Str(
                    "A memory entry (or state variable): the move happens only while it is non-zero (torque_enable); "
                    "otherwise the target is only stored."
                ),
                "accel": Str("The request field with the acceleration time (ms) at the start of the move."),
                "decel": Str("The request field with the deceleration time (ms) at the end of the move."),
                "to": Str(
                    "Where the state goes, as an expression of request fields, memory entries and state variables "
                    "(default: the target's value): a goal given in terms of a derived entry (DYNAMIXEL: "
                    "`goal_position - homing_offset`, since the goal is compared with the present position).",
                    example="goal_position - homing_offset",
                ),
            },
            required=("state", "target"),
            description="The device moves a state variable to a target, over a duration or at a speed.",
        ),
        "stops": ListOf(Str(), "State variables whose move in progress stops where it is now."),
        "increments": ListOf(
            Str(),
            "State variables or memory entries the command adds 1 to each time the device carries out a request "
            "that is not refused: a count of the writes taken (the TMC2209's IFCNT: `increments: [ifcnt]`, with "
            "`modulo: {ifcnt: 256}` for a count that wraps past 255); `step` on a message the device sends "
            "(`device.sends`) does the same for each send.",
            example=["ifcnt"],
        ),
        "wraps": MapOf(
            Num(),
            "State variable -> a period: the variable keeps only its remainder, toward zero (an angle within one "
            "turn, 3600 in 0.1°).",
        ),
        "modulo": MapOf(
            Num(),
            "State variable -> a period: the variable keeps its remainder in 0..period-1, also below zero (an "
            "absolute position within one turn: DYNAMIXEL CLEAR, 4096).",
        ),
        "restores": Obj(
            {
                "memory": Str("The memory whose entries go back to their initial values.", choices=("eeprom", "sram")),
                "except": ListOf(Str(), "Entries of that memory left as they are (measured values)."),
            },
            required=("memory",),
            description=(
                "The entries kept in one memory go back to their initial values (the model's, where it gives them) "
                "and stop moving, and writes held for a command that `commits` are dropped: a reboot clears RAM "
                "and keeps EEPROM (DYNAMIXEL REBOOT)."
            ),
        ),
        "refused_while_moving": Str(
            "A state variable (or memory entry): while it moves, the request is refused (`errors.busy`) and "
            "changes nothing (DYNAMIXEL CLEAR works only while the servo is stopped)."
        ),
        "broadcast_ignores": MapOf(
            Num(),
            "Request field -> a value with which a broadcast request is ignored by every device (DYNAMIXEL "
            "FACTORY RESET of everything, option 0xFF, sent to the broadcast id).",
        ),
        "counts": MapOf(
            Obj(
                {"state": Str("The state variable (or memory entry)."), "per": Num("The size of one whole unit.")},
                required=("state", "per"),
                description="The state variable counted and the size of one whole unit of it.",
            ),
            "Response field -> how many whole `per` the state variable holds, toward zero (turns of an angle).",
        ),
        "every_device": Bool(
            "A request without an address reaches every device on the bus (default: the first one only)."
        ),
        "held_while": Str(
            "A state variable: while it is not 0, the device keeps this request instead of carrying it out, until "
            "a command that `releases` the variable."
        ),
        "releases": Str(
            "A state variable: the command sets it to 0 and carries out the requests held while it was set, in "
            "order (or drops them, see `cancel_when`)."
        ),
        "cancel_when": MapOf(
            Num(), "With `releases`: request field -> the value with which the held requests are dropped."
        ),
        "carries": Obj(
            {
                "command": Str("The request field (or `each` item field) holding the code of the command carried."),
                "content": Str("The bytes field holding that command's request content."),
                "commands": ListOf(Str(), "The commands it can carry (default: every command with a code)."),
            },
            required=("command", "content"),
            description=(
                "The request (or each item of its `each` group) carries another command's request content; the "
                "devices act on it as on that request, and answer as they would (a sync command)."
            ),
        ),
        "broadcast_reply": Bool("Answers even when addressed by broadcast (default: silent).", default=False),
        "each": Str("A group field of the request whose items address one device each (by the address field)."),
        "buffered": Bool("The writes are held until a command that `commits` (FEETECH REG WRITE).", default=False),
        "commits": Bool("Carries out the writes held by `buffered` commands (FEETECH ACTION).", default=False),
        "nothing_held": MapOf(
            Num(),
            "commits: response field (or field.bit_field) -> value when no write is held (DYNAMIXEL ACTION without "
            "REG WRITE: error.number 2, instruction error).",
        ),
        "kind": Str("The entry of `kinds:` whose devices the command addresses (default: the devices of --id)."),
        "stores": MapOf(
            Str(),
            "Request field -> the state variable it is stored in (`{origin: asker}`, or the same name: a request "
            "field is stored only where `stores` or `writes` names it).",
        ),
        "echoes": ListOf(
            Str(),
            "Response fields that repeat the request's field of the same name (a write's reply confirming what was "
            "written: Modbus WRITE SINGLE REGISTER). Other response fields never copy the request: they come from "
            "the device (its reads, reports, `reply`, memory and state) or else the field's `default` (else 0); "
            "the fields replies are matched by (`matching.by`), the address and a table value's key echo anyway. "
            "The generated client checks each against what it sent (`EchoMismatch` names the field and both values).",
            example=["address", "value"],
        ),
        "sets": MapOf(Num(), "State variable -> the value the command sets it to."),
        "absent": MapOf(
            Num(),
            "Response field -> value when no device has the addressed id and the bus master answers for it "
            "(RRC: the board reports success -1); without it, silence.",
        ),
    },
    description="What the device does with one command (command or command.subcommand).",
)

MODEL = Obj(
    {
        "number": Int("The model number the device reports (in `model_entry`), e.g. 777 for the FEETECH STS3215."),
        "title": TEXT,
        "description": TEXT,
        "source": TEXT,
        "initial": MapOf(
            Num(),
            "Memory entry or state variable -> the value this model starts with (its factory value), over the "
            "table's default and the device's `initial`.",
        ),
        "entries": MapOf(
            Obj(
                {
                    "range": ListOf(
                        Num(),
                        "This model's inclusive [min, max] in wire units, where it differs from the table's.",
                        length=2,
                        example=[0, 2000],
                    ),
                    "unit": Str("This model's unit of one wire step, where it differs from the table's.", example="mA"),
                    "scale": Num("This model's engineering value per wire step, where it differs.", example=1),
                    "description": Str(TEXT.description, example="XL330: 1 mA steps, up to 1750 mA."),
                },
                description="Where one memory entry of this model differs from the table.",
            ),
            "Memory entry -> where this model's range, unit or scale differs from the table's.",
        ),
    },
    required=("number",),
    description="One device model: its model number, factory values and where its table differs.",
)

PRESENCE = Obj(
    {
        "request": Str(
            "The command (or command.subcommand) a device answers whenever it is there: any reply, an error reply "
            "too, means a device has that id (FEETECH and DYNAMIXEL PING, a Modbus register read)."
        ),
        "fields": MapOf(
            Num(),
            "Request field (or frame value, such as a sync byte) -> its value, besides the id (a read's address and "
            "count); a bit field as `field.bit_field` (TMC2209: `sync.nibble: 5`). Every value of the request that "
            "the spec gives no default, constant or derivation for must be here.",
        ),
        "ids": ListOf(
            Int(),
            "The first and last id `serialspec scan` asks by default (default: the device's id range, without the "
            "broadcast id).",
            length=2,
            example=[1, 247],
        ),
        "broadcast": Bool(
            "Every device answers the request sent to the broadcast id, one after another (DYNAMIXEL broadcast "
            "PING): one request finds them all; `scan` asks the ids one by one only when none answers it.",
            default=False,
        ),
        "model": Obj(
            {
                "request": Str("The command whose reply holds the model (default: the presence request's own)."),
                "fields": MapOf(Num(), "Request field -> its value, besides the id (the model register's address)."),
                "field": Str(
                    "The reply field holding the model: a number (a name from `models` by its `number`), text, or a "
                    "run of registers holding the device's `model_entry`."
                ),
            },
            required=("field",),
            description="Where a device's model is read: a reply field, of the presence reply or of another request.",
        ),
        "description": TEXT,
    },
    required=("request",),
    description=(
        "How to find the devices on a bus (`serialspec scan`): the request each one answers, the ids to ask, and "
        "where its model is."
    ),
)

DEVICE = Obj(
    {
        "description": TEXT,
        "presence": PRESENCE,
        "models": MapOf(
            MODEL,
            "Device models sharing the protocol and table (FEETECH STS3215, SM8512BL; DYNAMIXEL XM430, XL330): "
            "`serialspec sim --model NAME` (or `--model ID=NAME`) picks one; the docs list them.",
        ),
        "default_model": Str("The model the simulator uses when none is named (default: the first of `models`)."),
        "model_entry": Str("The memory entry holding the model number (set from the model's `number`)."),
        "memory": Str("The table the device keeps, initialised from its defaults."),
        "initial": MapOf(Num(), "Memory entry -> value the simulator starts with where the table gives no default."),
        "address": Str("The field holding the device id (default: the frame's address element)."),
        "id_entry": Str("The memory entry or state variable holding the device's id (writing it changes the address)."),
        "broadcast": Int("The address every device obeys (default: the address element's broadcast)."),
        "state": MapOf(Num(), "State variables beyond memory -> initial value (e.g. the present angle)."),
        "reply": MapOf(
            REPLY_VALUE,
            REPLY_VALUES,
        ),
        "status": MapOf(
            Str(),
            "Response field -> the memory entry every response reports in it (a status byte); field.bit_field -> "
            "an entry whose being non-zero sets that bit field (DYNAMIXEL error.alert: hardware_error_status).",
        ),
        "moving": MapOf(
            Obj(
                {
                    "state": Str("The state variable (or memory entry) whose move it reports."),
                    "bit": Int("Only this bit of the entry reports it (the others keep their value)."),
                },
                required=("state",),
                description="The move an entry reports, as the whole entry or as one bit of it.",
            ),
            "Memory entry -> the move it reports: 1 while the state variable moves, 0 once it has arrived (FEETECH "
            "`moving`); with `bit`, one bit of the entry (Fashion Star servo_status bit 0, executing).",
        ),
        "echo_address": Bool(
            "Replies carry the id the request named (RRC: 0xFE for a broadcast read), not the answering device's own.",
            default=False,
        ),
        "commands": MapOf(DEVICE_COMMAND, "Command (or command.subcommand) -> behaviour; others just answer."),
        "ids": ListOf(Int(), "The device ids the simulator serves when none are given (default: 0)."),
        "timeout": Obj(
            {
                "after": Int("Milliseconds without one of the `kept_by` commands after which the device gives up."),
                "kept_by": ListOf(Str(), "The commands that restart the timeout (VESC: every setpoint, and ALIVE)."),
                "sets": MapOf(Num(), "State variable -> its value once the timeout has expired (the motor released)."),
                "description": TEXT,
            },
            required=("after", "kept_by", "sets"),
            description="A command timeout: the device stops unless commands keep coming (VESC, 1 s by default).",
        ),
        "spaces": MapOf(
            Obj(
                {
                    "type": Str(
                        "The item type: `bit`, or an integer type; a signed one keeps negative values (Trinamic "
                        "TMCL's axis parameters: `i32`), a value written wraps to the type's bits as it would on the "
                        "wire.",
                        choices=("bit", "u8", "u16", "u32", "i8", "i16", "i32"),
                    ),
                    "size": Int("Number of items, addressed 0..size-1 (the simulator can be given other sizes)."),
                    "access": Str("r: requests only read it; rw: they read and write it.", choices=("r", "rw")),
                    "description": TEXT,
                },
                required=("type", "size"),
                description="One data space: its item type, its size and whether requests may write it.",
            ),
            "Data spaces the device keeps besides its table: runs of items addressed by number, all zero at "
            "first (Modbus coils, discrete inputs, holding and input registers).",
        ),
        "errors": Obj(
            {
                "out_of_range": MapOf(
                    Num(),
                    "Reply values when a value is outside its entry's range, or a request value outside its "
                    "range or enum (Modbus exception_code: 3; DYNAMIXEL error.number: 4, data range error).",
                ),
                "out_of_space": MapOf(
                    Num(),
                    "Reply values when a write reaches an address no entry has, or a run reaches beyond its data "
                    "space (Modbus exception_code: 2; DYNAMIXEL error.number: 7, access error).",
                ),
                "read_only": MapOf(
                    Num(),
                    "Reply values when a write reaches a read-only entry or data space (DYNAMIXEL error.number: 7).",
                ),
                "busy": MapOf(
                    Num(),
                    "Reply values when a command that is `refused_while_moving` arrives during the move (DYNAMIXEL "
                    "CLEAR: error.number: 1, result fail).",
                ),
                "locked": MapOf(
                    Num(),
                    "Reply values when a write reaches an entry that `locks` locks at the moment (DYNAMIXEL "
                    "error.number: 7, access error: EEPROM written while the torque is on).",
                ),
                "unsupported": MapOf(
                    Num(),
                    "Reply values for a request whose code no command has, recognised when it arrives whole and "
                    "its checksum verifies (Modbus exception_code: 1, illegal function; MSP: `{}`, the `$M!` "
                    "reply, which carries no values); needs the protocol's error reply.",
                ),
            },
            description=(
                "How the device refuses a request, by reason: response field (or field.bit_field) -> value. The "
                "refusal is the protocol's error reply (the response marked `error_reply`, carrying the refused "
                "request's code) when it has one; otherwise the request's own response with these values. A "
                "refused request changes nothing. With an error reply, request values are also checked against "
                "their ranges and enums before the device acts. For a reason not listed the request is still not "
                "carried out, and the reply says nothing of it (with an error reply: no reply)."
            ),
        ),
        "derived": MapOf(
            Str(),
            "Memory entry -> what it reads as: an expression of state variables and other memory entries (DYNAMIXEL "
            "present_position: `position + homing_offset`); every read, reply and report sees that value.",
        ),
        "locks": ListOf(
            Obj(
                {
                    "memory": Str("The memory whose entries are locked.", choices=("eeprom", "sram")),
                    "entries": ListOf(
                        Str(), "Memory entries locked (besides those of `memory`).", example=["id", "baud_rate"]
                    ),
                    "while": Str(
                        "A memory entry (or state variable): the entries are locked while it is non-zero.",
                        example="torque_enable",
                    ),
                    "description": TEXT,
                },
                required=("while",),
                description="Entries a request cannot write while a value is non-zero.",
            ),
            "Access rules that depend on state: a write to a locked entry is refused with `errors.locked` and "
            "changes nothing (DYNAMIXEL: the EEPROM area while torque_enable is 1, access error 7).",
            example=[{"memory": "eeprom", "while": "torque_enable"}],
        ),
        "sends": MapOf(
            Obj(
                {
                    "every": OneOf(
                        (Int(minimum=1), Str()),
                        "Period in ms: the device sends the message this often. A number, or an expression of "
                        "state variables and memory entries (a rate register: `1000 / rate_hz`), worked out again "
                        "for each period: where it has no value (a division by 0) or is not positive, the device "
                        "sends nothing periodically until it has one.",
                    ),
                    "after": ListOf(
                        Str(),
                        "Commands (or command.subcommand) after whose reply the device also sends it.",
                        example=["set_rate"],
                    ),
                    "changes": ListOf(
                        Str(),
                        "State variables or memory entries: the device also sends it when one of them changes.",
                        example=["mode"],
                    ),
                    "while": Str(
                        "A state variable or memory entry: the device sends it only while it is non-zero (default: "
                        "always).",
                        example="streaming",
                    ),
                    "step": Str(
                        "A state variable the device adds 1 to before each time it sends the message (a sequence "
                        "number; a fix counter that `values` expressions move a position along).",
                        example="fix",
                    ),
                    "values": MapOf(
                        OneOf((Int(), Str())),
                        "Field -> an expression of state variables and memory entries it holds, or a number (other "
                        "fields: the device's `reply` values, else 0).",
                        example={"uptime": "ticks / 1000"},
                    ),
                    "description": Str(TEXT.description, example="A heartbeat every second while armed."),
                },
                description="When the device sends one message on its own.",
            ),
            "Unsolicited output: command (or command.subcommand) -> when the device sends that command's response "
            "without a request (a heartbeat every second, a fix at the measurement rate, telemetry after a "
            "command), besides answering requests. Clients offer these messages as an iterator and a subscription.",
        ),
        "kinds": MapOf(
            Obj(
                {
                    "description": TEXT,
                    "address": Str("The request field holding this kind's id."),
                    "ids": ListOf(Int(), "The ids the simulator creates (fixed by the hardware, not by --id)."),
                    "broadcast": Int("The id every device of this kind obeys.", example=255),
                    "state": MapOf(Num(), "State variables of each device of this kind -> initial value."),
                },
                required=("address", "ids"),
                description="One further kind of device: the field with its id, its ids and its state.",
            ),
            "Further kinds of device behind the same port, each with its own ids (a board's PWM servo ports, its "
            "motors); a command names its kind with `kind:`. The devices --id creates are the default kind.",
        ),
    },
    description=(
        "How the device behaves: what the generated simulator does, and the address rule the client uses. In a text "
        "protocol (`framing: {kind: text}`): `description`, `state`, `reply` (values every sentence carries, "
        "`talker` too) and `sends` with `every`, `step`, `while` and `values`."
    ),
)

SPEC = Obj(
    {
        "protocol": Str("Python package name of the generated code."),
        "title": TITLE,
        "description": TEXT,
        "sources": MapOf(Str(), "Document id -> what it is."),
        "byte_order": Str(
            "Byte order of every multi-byte value, unless a field's `endian` says otherwise (required in binary "
            "framing).",
            choices=("little", "big"),
        ),
        "serial": Obj(
            {
                "baudrate": Int("Bits per second.", minimum=1),
                "baudrates": ListOf(
                    Int(minimum=1),
                    "Every rate a device can be set to, the default first (`serialspec scan --all-baudrates` tries "
                    "each).",
                    example=[1000000, 500000, 115200],
                ),
                "bytesize": Int("Data bits per character.", default=8, minimum=5, maximum=8),
                "parity": Str("Parity bit.", choices=("none", "even", "odd"), default="none"),
                "stopbits": Num("Stop bits.", default=1, choices=(1, 1.5, 2)),
                "notes": TEXT,
            },
            required=("baudrate",),
            description="The serial line's settings: what clients, simulators and `monitor` open a port with.",
        ),
        "framing": FRAMING,
        "matching": Obj(
            {
                "by": ListOf(Str(), "What a reply shares with its request: `command` and field names (servo_id)."),
                "description": TEXT,
            },
            description="How a reply is matched to its request.",
        ),
        "fields": FIELDS,
        "enums": MapOf(ENUM, "Value sets: name -> enum; fields refer to them with `enum:`."),
        "flags": MapOf(FLAGS, "Bit sets: name -> flags; fields refer to them with `flags:`."),
        "tables": MapOf(TABLE, "Parameter or register tables: name -> table."),
        "commands": MapOf(COMMAND, "The protocol's commands: name -> command."),
        "examples": MapOf(EXAMPLE, "Frames printed in the documents, each decoded and encoded by the tests."),
        "errata": MapOf(ERRATUM, "Mistakes in the documents, each pinned by a test."),
        "device": DEVICE,
    },
    required=("protocol", "title", "serial", "framing", "commands"),
    description="A serialspec protocol spec.",
)


def json_schema() -> dict[str, Any]:
    schema = SPEC.json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["$defs"] = {"fields": FIELDS.json_schema()}
    schema["title"] = "serialspec protocol spec"
    return schema
