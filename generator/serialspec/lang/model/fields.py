"""Field kinds and types: scalars, arrays, lists, packed integers, text, bytes, groups, table values; enums and
flags; the parameter tables."""

from __future__ import annotations

import re
from typing import Literal

from serialspec.encodings.low_bits import LowBits
from serialspec.lang.expression import Expr, show
from serialspec.lang.frozen import frozen

_UNIT_STEP = re.compile(r"^\s*[0-9]+(\.[0-9]+)?\s*")


def engineering_unit(unit: str, scale: float | None) -> str:
    """The unit of wire value x scale: a wire unit of `0.1°` with scale 0.1 is `°`, `6.5 mA` with 6.5 is `mA`."""
    return _UNIT_STEP.sub("", unit) if scale is not None else unit


@frozen
class ScalarType:
    name: str
    size: int
    struct_char: str
    signed: bool
    is_float: bool
    minimum: float
    maximum: float


SCALARS: dict[str, ScalarType] = {
    "u8": ScalarType("u8", 1, "B", False, False, 0, 0xFF),
    "i8": ScalarType("i8", 1, "b", True, False, -0x80, 0x7F),
    "u16": ScalarType("u16", 2, "H", False, False, 0, 0xFFFF),
    "i16": ScalarType("i16", 2, "h", True, False, -0x8000, 0x7FFF),
    # 3-byte integers (fields only, as the 64-bit types: not frame elements, enums, flags or tables) are read as 3
    # bytes ("3s") and converted, since struct has no format for them
    "u24": ScalarType("u24", 3, "3s", False, False, 0, 0xFFFFFF),
    "i24": ScalarType("i24", 3, "3s", True, False, -0x800000, 0x7FFFFF),
    "u32": ScalarType("u32", 4, "I", False, False, 0, 0xFFFFFFFF),
    "i32": ScalarType("i32", 4, "i", True, False, -0x80000000, 0x7FFFFFFF),
    "u64": ScalarType("u64", 8, "Q", False, False, 0, 0xFFFFFFFFFFFFFFFF),
    "i64": ScalarType("i64", 8, "q", True, False, -0x8000000000000000, 0x7FFFFFFFFFFFFFFF),
    "f32": ScalarType("f32", 4, "f", True, True, -3.4028234663852886e38, 3.4028234663852886e38),
    "f64": ScalarType("f64", 8, "d", True, True, -1.7976931348623157e308, 1.7976931348623157e308),
}


@frozen
class EnumValue:
    name: str
    value: int
    text: str


@frozen
class EnumDef:
    name: str
    class_name: str
    type: ScalarType
    description: str
    values: tuple[EnumValue, ...]


@frozen
class FlagBit:
    name: str
    bit: int
    text: str


@frozen
class FlagsDef:
    name: str
    class_name: str
    type: ScalarType
    description: str
    bits: tuple[FlagBit, ...]


@frozen
class BitField:
    name: str
    high: int
    low: int
    enum: EnumDef | None
    description: str
    const: int | None = None  # the bits always hold this value: decode refuses another, encode writes it
    default: int | None = None  # the value a bits class is built with when none is given

    @property
    def mask(self) -> int:
        return (1 << (self.high - self.low + 1)) - 1

    @property
    def preset(self) -> int | None:
        """The value the bits class fills in when none is given: the constant, else the default."""
        return self.const if self.const is not None else self.default


def fixed_bits(bits: tuple[BitField, ...]) -> tuple[int, int]:
    """(mask, value) of the constant bit fields of an integer: a value must hold `value` under `mask`."""
    mask = value = 0
    for bit in bits:
        if bit.const is not None:
            mask |= bit.mask << bit.low
            value |= bit.const << bit.low
    return mask, value


@frozen
class BitPlace:
    """A field's place in a bit run (encodings/bit_run.py: `type: u12` and the fields packed with it): the run is
    read as one big-endian integer of `size` bytes, the field `shift` bits above its lowest bit."""

    run: str  # the name of the run's first field
    bits: int
    shift: int
    size: int
    earlier: tuple[tuple[str, int, int], ...] = ()  # the last field's: (name, bits, shift) of the fields before it

    @property
    def first(self) -> bool:
        return self.shift + self.bits == self.size * 8

    @property
    def last(self) -> bool:
        return self.shift == 0

    @property
    def mask(self) -> int:
        return (1 << self.bits) - 1


@frozen
class Common:
    """What every field kind carries."""

    name: str
    description: str
    description_cn: str
    inferred: str


@frozen
class Counted:
    """A count or size worked out from earlier integer fields that stay in the message (`count: n + 1`): decode reads
    that many items or bytes (refusing a negative value), encode refuses a list of another length
    (serialspec/lang/counts.py)."""

    expr: Expr
    low: int  # the least and greatest values it takes for any wire values of its fields
    high: int

    def __str__(self) -> str:
        return show(self.expr)


Count = int | str | Counted  # a number, "rest", the name of a count field (derived), or an expression


@frozen
class Scalar(Common):
    type: ScalarType
    endian: Literal["<", ">"]
    unit: str
    scale: float | None
    minimum: float
    maximum: float
    const: int | None
    default: float | None
    enum: EnumDef | None
    flags: FlagsDef | None
    bits: tuple[BitField, ...]
    bits_class: str
    sign_magnitude: bool
    # Derived fields are computed on encode and checked on decode, never given by the user:
    # ("count", group) is the number of items of a group; ("size", group, field) the size of bytes in each item.
    derived: tuple[str, ...] = ()
    # A response field reporting success: any value but this one is a device error (the client raises DeviceError).
    status_ok: int | None = None
    # Derived by an expression over the other fields (`byte_count = 2 * count`): computed on encode, checked on decode.
    value: Expr | None = None
    offset: float | None = None  # engineering value = wire value × scale + offset
    value_at: tuple[int, int] = (1, 1)  # line and column of `value:` in the spec, for a target's refusal of it
    low_bits: LowBits | None = None  # `encoding: seven_bit` or `nibbles`: a few bits a byte (encodings/low_bits.py)
    bit_place: BitPlace | None = None  # a member of a bit run (serialspec/encodings/bit_run.py)

    @property
    def odd_width(self) -> bool:
        """A 3-byte integer: read as 3 bytes and converted, since struct has no format for it."""
        return self.type.size == 3 and self.bit_place is None

    @property
    def hidden(self) -> bool:
        """Not a member of the message: constant or derived."""
        return self.const is not None or bool(self.derived) or self.value is not None

    @property
    def wire_signed(self) -> bool:
        """Its wire word read as a signed integer: a signed type's, but a few bits a byte (low_bits), whose word is
        unsigned and its value signed by its own bits."""
        return self.type.signed and self.low_bits is None


@frozen
class Varint(Common):
    """An integer in as many bytes as its value needs (`encoding: varint`, serialspec/encodings/varint.py): `bits`
    value bits a byte, the bit above them set on every byte but the last; `type` gives the range and what C stores
    it in, `sign` how a signed value is sent ("": unsigned, zigzag, low_bit)."""

    type: ScalarType
    bits: int
    sign: Literal["", "zigzag", "low_bit"]
    high_first: bool
    unit: str
    minimum: int
    maximum: int
    default: int | None
    most_bytes: int  # the most bytes a value of the range takes (decoding refuses more)


@frozen
class Array(Common):
    item: ScalarType
    endian: Literal["<", ">"]
    count: int
    unit: str
    minimum: float
    maximum: float


@frozen
class List(Common):
    """A list of numbers or bits whose count varies: from a count field, from a byte-size field, or the rest.

    `item` None means bits packed 8 to a byte, the first in the lowest bit, the last byte padded with zeros
    (Modbus coils). The count comes from `count` (a number, `rest`, or a field) or, when that is "", from the
    byte size in the field named by `size`.
    """

    item: ScalarType | None
    endian: Literal["<", ">"]
    count: Count
    size: str
    unit: str
    minimum: float
    maximum: float
    count_from: str = ""  # a response's: the request field saying how many items are meant (the rest is padding)

    @property
    def bits(self) -> bool:
        return self.item is None

    def byte_size(self, count: int) -> int:
        return -(-count // 8) if self.item is None else count * self.item.size


@frozen
class Packed(Common):
    """A fixed number of integers of `bits` bits each, packed with no gaps (CRSF RC channels: 16 × 11 bits).

    `lsb_first`: the first item starts at the lowest bit of the first byte, each item's lowest bit first (CRSF,
    SBUS; a little-endian u24 array is the same); else the first item starts at the highest bit, its highest bit
    first (a big-endian u24 array is the same). The last byte is padded with zero bits.
    """

    bits: int
    signed: bool
    count: int
    lsb_first: bool
    unit: str
    minimum: float
    maximum: float

    @property
    def byte_size(self) -> int:
        return -(-self.bits * self.count // 8)


@frozen
class Text(Common):
    """Text: NUL-terminated (`size` None; the NUL is not part of the value), or sized like bytes.

    `pad`: a fixed-size text shorter than its size is sent followed by this byte (NUL-padded names), and read
    without the trailing pad bytes; None: the text must fill its size exactly."""

    size: Count | None  # a number, "rest", a field name, an expression, or None for NUL-terminated
    pad: int | None = None
    seven_bit: bool = False  # `encoding: seven_bit`: 14-bit characters, two 7-bit bytes each (encodings/seven_bit.py)

    @property
    def terminated(self) -> bool:
        return self.size is None


@frozen
class Bytes(Common):
    size: Count  # a number, "rest", the name of a field holding it, or an expression
    table: Table | None = None  # when the bytes are a run of registers of this table
    start: str = ""  # the field holding the first register's key: a field of this content, or of the request
    start_in_request: bool = False  # `start: request.<field>`: the field is the request's (the resolver checked it)
    size_from: str = ""  # a response's `rest` bytes: the request field giving their number (`request.<field>`)
    size_from_adds: int = 0  # ... plus this many (`request.count + 1`: STM32 Read Memory's count minus one)
    default: bytes | None = None  # bytes of a fixed size: the value a message built without them has


@frozen
class Group(Common):
    class_name: str
    count: Count  # a number, "rest", the name of a count field, or an expression
    fields: tuple[Field, ...]
    item_size: int | None  # None when an item holds bytes sized by another field


@frozen
class TableValue(Common):
    table: Table
    key: str


@frozen
class TableBlock(Common):
    table: Table
    class_name: str
    entries: tuple[TableEntry, ...]
    endian: Literal["<", ">"]
    struct_name: str = ""  # the construct struct of the block


Field = Scalar | Varint | Array | Packed | List | Text | Bytes | Group | TableValue | TableBlock


@frozen
class TableEntry:
    name: str
    key: int
    type: ScalarType
    name_cn: str
    description: str
    unit: str
    scale: float | None
    minimum: float
    maximum: float
    default: float | str | None
    access: str
    memory: str
    enum: EnumDef | None
    flags: FlagsDef | None
    sign_magnitude: bool
    reserved: bool
    source: str
    sign_bit: int | None = None  # sign_magnitude: the sign's bit (the top bit unless the spec says otherwise)


@frozen
class Table:
    name: str
    title: str
    key_name: str
    description: str
    source: str
    entries: tuple[TableEntry, ...]
    # generated names: the register map (or the table's constant), the switch of its values by key, the name alias
    constant: str = ""
    value_constant: str = ""
    names_class: str = ""

    def entry(self, key: int) -> TableEntry | None:
        for entry in self.entries:
            if entry.key == key:
                return entry
        return None
