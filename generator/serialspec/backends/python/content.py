"""Python source fragments computed from the model, which the package templates lay out.

The decisions live here (how each field kind is read, written, range-checked and turned into JSON); the templates
only place the fragments into modules. Every fragment is built from names the resolver has checked to be
identifiers, and every piece of spec text reaches generated code through repr(), so no spec text can inject code.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from typing import assert_never

from serialspec.backends.common.frames import optional_elements
from serialspec.backends.common.numbers import number
from serialspec.backends.python.dispatch import decoder_name, encoder_name
from serialspec.backends.python.frames.encode import message_frame
from serialspec.backends.python.frames.layouts import StraightLayouts, straight_direction
from serialspec.backends.python.ir import (
    Advance,
    Block,
    Calls,
    Code,
    ContentSize,
    Expect,
    If,
    ItemsCheck,
    LeftOver,
    Loop,
    Needs,
    Pack,
    PackItems,
    Raise,
    ReturnNew,
    Simple,
    TakeRest,
    Try,
    Unpack,
    helpers_of,
    lines_of,
    packed_lists,
    values_tuple,
)
from serialspec.backends.python.kinds import (
    fixed_runs,
    is_fixed_run_member,
    kind,
    one_order,
    run_endian,
    struct_format,
    struct_tokens,
    takes_the_rest,
)
from serialspec.backends.python.optimize import (
    attribute_reads,
    deferred_item_checks,
    field_read,
    fold_last_size_check,
    read_fields_once,
)
from serialspec.backends.python.render import one_line
from serialspec.encodings import bit_run
from serialspec.lang import counts, expression
from serialspec.lang.model import (
    Array,
    Bytes,
    Counted,
    Direction,
    FrameElement,
    Group,
    List,
    Message,
    Packed,
    Protocol,
    Scalar,
    TableBlock,
    TableValue,
    Text,
    Varint,
    fixed_size,
)
from serialspec.lang.model import Field as SpecField
from serialspec.lang.names import spec_key

Lines = list[str]
_MOST_RUNS = 256  # the most items of a list read by a struct made for each count (see unpack_runs)
_STRUCT_NAMES = {
    "B": "U8",
    "b": "I8",
    "H": "U16",
    "h": "I16",
    "I": "U32",
    "i": "I32",
    "f": "F32",
    "Q": "U64",
    "q": "I64",
    "d": "F64",
}


def fixed_lengths(fields: list[SpecField]) -> dict[str, int]:
    """What `len()` of each field of a known length is: a fixed array's or packed array's count, fixed bytes' size."""
    found: dict[str, int] = {}
    for f in fields:
        match f:
            case Array(count=count) | Packed(count=count) | Bytes(size=int() as count):
                found[f.name] = count
    return found


def varint_form(f: Varint) -> str:
    """The runtime's description of a varint field (packing.py read_varint, write_varint)."""
    return repr((f.bits, f.high_first, f.sign, f.most_bytes))


def bound(f: Scalar, value: float) -> str:
    """A range bound as the literal a comparison with the field's values is quickest with: a float field's bounds
    as floats where they are exactly that (a float compared with float32's maximum written as a 39-digit integer
    takes a slow path in CPython), others as numbers."""
    if f.type.is_float and float(value) == value:
        return repr(float(value))
    return number(value)


def preset_name(bits_class: str) -> str:
    """The module-level instance of a bits class with every bit field at its constant or default (SyncBits:
    SYNC_BITS_PRESET), a parameter's default (a call there would be built once anyway, and linters frown on it)."""
    return re.sub(r"(?<!^)(?=[A-Z])", "_", bits_class).upper() + "_PRESET"


def field_default(f: SpecField) -> str:
    """A field's default as Python source ("" for none): a plain number's `default`, or its bits class built with
    every bit field's constant or default where each has one."""
    if isinstance(f, Bytes):
        return repr(f.default) if f.default is not None else ""
    if isinstance(f, Varint):
        return str(f.default) if f.default is not None else ""
    if not isinstance(f, Scalar):
        return ""
    if f.bits:
        return preset_name(f.bits_class) if all(b.preset is not None for b in f.bits) else ""
    return number(f.default) if f.default is not None and not f.enum else ""


def members_name(class_name: str) -> str:
    """The codec's module-level value -> member map of an enum or flag class."""
    return f"_MEMBERS_{class_name}"


def element_scalar(element: FrameElement) -> Scalar:
    """A frame-level value element (SMS id, error, a sync byte with bit fields) as the scalar field messages carry,
    its bit fields and flags included: the codec, the client and the sims see one field."""
    assert element.type is not None
    return Scalar(
        element.name,
        element.description,
        "",
        "",
        element.type,
        element.endian,
        "",
        None,
        element.minimum,
        element.maximum,
        None,
        None,
        None,
        element.flags,
        element.bits,
        element.bits_class,
        False,
    )


def annotation(f: SpecField) -> str:
    return kind(f).annotation(f)


def doc_line(f: SpecField) -> str:
    parts = [f.description or f.name]
    if isinstance(f, Scalar | Array | List) and f.unit:
        parts.append(f"[{f.unit}]")
    if isinstance(f, Scalar) and not f.bits and (f.minimum, f.maximum) != (f.type.minimum, f.type.maximum):
        parts.append(f"range {number(f.minimum)}..{number(f.maximum)}")
    if f.inferred:
        parts.append("(layout inferred, not documented)")
    return one_line(" ".join(parts))


@dataclass
class Attribute:
    """One field of a generated class: its name, annotation, default (Python source, or "" for none) and doc line."""

    name: str
    annotation: str
    doc: str
    default: str = ""
    # the default shown in the class body too (a trailing run of defaults); False for one only __new__ has: a
    # frame value made of preset bit fields before fields without a default, and those fields' REQUIRED
    in_class: bool = True

    @property
    def stored(self) -> str:
        """The value the constructor stores: a list given for a sequence field as a tuple (so the message equals the
        one `decode` gives for its frame); anything else as given, for encode to check and name (a string or a
        record is no list of items, and iterating it would hide that)."""
        if self.annotation.startswith("tuple["):
            return f"tuple({self.name}) if isinstance({self.name}, list) else {self.name}"
        return self.name


@dataclass
class ClassCode:
    """A generated value class: its name, docstring, fields, to_fields and from_fields bodies."""

    name: str
    doc: str
    base: str
    attributes: list[Attribute]
    class_vars: Lines = field(default_factory=list)
    to_fields: Lines = field(default_factory=list)
    from_fields: Lines = field(default_factory=list)
    given_checks: Lines = field(default_factory=list)  # from_fields' checks of the computed values given (`m`)
    helpers: frozenset[str] = frozenset()  # the runtime.fields helpers from_fields calls (as _<name>)
    default_name: str = ""  # a bits class whose bit fields all have a constant or default: its instance of them

    def read_from(self, values: list[Calls]) -> None:
        """from_fields' arguments: each field's value from data, with the helpers they call."""
        self.from_fields = [f"{value}," for value in values]
        self.helpers = frozenset().union(*(helpers_of(value) for value in values))


class PackageCode:
    """Every fragment of one protocol's generated package."""

    def __init__(self, protocol: Protocol) -> None:
        self.protocol = protocol
        self.structs: dict[str, str] = {}  # constant name -> format
        self.stems: dict[
            str, str
        ] = {}  # the name of each struct `struct` made, less its prefix (for names made from it)
        self.helper_classes: list[ClassCode] = []
        self.message_classes: list[ClassCode] = []
        self.decoders: list[tuple[str, str, str, Block]] = []  # name, return type, extra parameters, body
        self.encoders: list[tuple[str, str, Lines]] = []  # name, parameter type, body
        # classes the decoders build through their slots (see `build`): class name -> field names in order
        self.built: dict[str, list[str]] = {}
        self.member_maps: set[str] = set()  # enum and flag classes whose value -> member map the decoders use
        self.unpack_runs: dict[str, tuple[str, int]] = {}  # unpack_runs tables the decoders use: name -> (format, most)
        self.packing: set[str] = set()  # the runtime.packing functions the bodies call (as _<name>)
        self._seen_classes: set[str] = set()
        self._straight: dict[Direction, StraightLayouts | None] = {}
        # the decoders' locals: a prefix and the fields named in it, innermost last: `v_` a message's fields, `i1_` its
        # groups' items', `i2_` theirs (an item's local named as a field before its group would overwrite that
        # field's value); a name is its innermost field's (an item's size may be a field before its group)
        self._scopes: list[tuple[str, frozenset[str]]] = [("v_", frozenset())]
        for message in protocol.messages():
            self.message(message)

    def straight(self, direction: Direction) -> StraightLayouts | None:
        """The direction's frames when straight-line code takes them (frames/), worked out once."""
        if direction not in self._straight:
            self._straight[direction] = (
                None if self.protocol.framing.classic else straight_direction(self.protocol, direction)
            )
        return self._straight[direction]

    # --- structs --------------------------------------------------------------------------------------------------

    def struct(self, base_name: str, fmt: str) -> str:
        """A shared struct.Struct constant for a format, named after its layout (e.g. _S_U8_I16_U16_U16)."""
        for name, existing in self.structs.items():
            if existing == fmt:
                return name
        tokens = []
        for count, char in struct_tokens(fmt):
            token = _STRUCT_NAMES.get(char, char.upper())
            tokens.append(f"{token}X{count}" if count and char != "s" else (f"B{count}" if char == "s" else token))
        layout = "_".join(tokens) if len(tokens) <= 6 else base_name.upper()
        stem = ("BE_" if fmt.startswith(">") else "") + layout
        if "_S_" + stem in self.structs:  # another format got the same name (a long layout named after its message)
            taken = stem
            stem = next(
                f"{taken}_{n}" for n in range(2, len(self.structs) + 3) if f"_S_{taken}_{n}" not in self.structs
            )
        name = "_S_" + stem
        self.structs[name] = fmt
        self.stems[name] = stem
        return name

    # --- classes --------------------------------------------------------------------------------------------------

    def value_fields(self, message: Message) -> list[SpecField]:
        return [f for f in message.fields if not (isinstance(f, Scalar) and f.hidden)]

    def frame_values(self, direction: Direction, message: Message | None = None) -> list[Scalar]:
        """Frame-level values (SMS id, error) every message of a direction carries, as scalar fields; an error reply
        (Modbus exception) also carries the code of the request it refuses, named after the command element. A
        message's are those of its own layout (layouts chosen by command may carry different values)."""
        layout = self.protocol.framing.layouts[direction] if message is None else self.protocol.layout(message)
        elements = list(layout.value_elements)
        error = self.protocol.error_reply
        if message is not None and message.error_reply and error is not None:
            element = next(e for e in layout.elements if e.name == error.element)
            top = error.flag - 1 if error.flag else element.maximum  # an error header: any code of the element
            elements.append(replace(element, minimum=0, maximum=top, flags=None))
        return [element_scalar(element) for element in elements]

    def attributes(
        self, fields: list[SpecField], defaults: bool = True, partial: frozenset[str] = frozenset()
    ) -> list[Attribute]:
        # Defaults only on a trailing run of fields that all have one: classes stay positional. A field with a default
        # before fields without one (a reserved byte, LX-16A's mode write; a value made of bit fields that are all
        # constants or defaults, a sync byte, as its bits class's) has it wherever it is; the fields after it without
        # one get REQUIRED, which __new__ refuses (positional calls keep working).
        given = {f.name: field_default(f) for f in fields} if defaults else {}
        given |= dict.fromkeys(partial, "None")  # a frame value some layout does not carry: None there
        trailing: set[str] = set()
        for f in reversed(fields):
            if not given.get(f.name):
                break
            trailing.add(f.name)
        attributes = []
        after_default = False
        for f in fields:
            default = given.get(f.name, "")
            shown = f"{annotation(f)} | None" if f.name in partial else annotation(f)
            if f.name in trailing:
                attributes.append(Attribute(f.name, shown, doc_line(f), default))
            elif default:
                attributes.append(Attribute(f.name, shown, doc_line(f), default, in_class=False))
                after_default = True
            else:
                attributes.append(Attribute(f.name, shown, doc_line(f), "REQUIRED" if after_default else "", False))
        return attributes

    def helper(self, f: SpecField) -> None:
        """Dataclasses for the nested values of a field: bit fields, group items, table blocks."""
        match f:
            case Scalar() if f.bits and f.bits_class not in self._seen_classes:
                self._seen_classes.add(f.bits_class)
                attributes = []
                # a constant or default bit field is filled in where it and every one after it has one: the class
                # stays positional
                preset = len(f.bits)
                while preset and f.bits[preset - 1].preset is not None:
                    preset -= 1
                for index, bit in enumerate(f.bits):
                    kind = f"{bit.enum.class_name} | int" if bit.enum else "int"
                    where = f"bit {bit.low}" if bit.high == bit.low else f"bits {bit.high}..{bit.low}"
                    if bit.const is not None:
                        where += f", always {bit.const}"
                    default = str(bit.preset) if index >= preset else ""
                    doc = f"{one_line(bit.description or bit.name)} ({where})"
                    attributes.append(Attribute(bit.name, kind, doc, default))
                code = ClassCode(f.bits_class, f"Bit fields of {f.name}.", "", attributes)
                if all(b.preset is not None for b in f.bits):
                    code.default_name = preset_name(f.bits_class)
                code.to_fields = [f"{b.name!r}: int(self.{b.name})," for b in f.bits]
                code.read_from(
                    [self.from_value_expr(b.name, b.enum.class_name if b.enum else None, b.preset) for b in f.bits]
                )
                self.helper_classes.append(code)
            case Group() if f.class_name not in self._seen_classes:
                self._seen_classes.add(f.class_name)
                for inner in f.fields:
                    self.helper(inner)
                inner_fields = [i for i in f.fields if not (isinstance(i, Scalar) and i.hidden)]
                code = ClassCode(f.class_name, f"One item of {f.name}.", "", self.attributes(inner_fields, False))
                code.to_fields = [f"{spec_key(i.name)}: {self.to_json(i, 'self.' + i.name)}," for i in inner_fields]
                code.read_from([self.from_json(i) for i in inner_fields])
                self.helper_classes.append(code)
            case TableBlock() if f.class_name not in self._seen_classes:
                self._seen_classes.add(f.class_name)
                attributes = []
                for e in f.entries:
                    kind = f"{e.enum.class_name} | int" if e.enum else ("float" if e.type.is_float else "int")
                    unit = f" [{e.unit}]" if e.unit else ""
                    doc = one_line(f"{f.table.key_name} {e.key}: {e.description or e.name}{unit}")
                    attributes.append(Attribute(e.name, kind, doc))
                code = ClassCode(
                    f.class_name, one_line(f"{f.description or f.name} ({f.table.title})."), "", attributes
                )
                code.to_fields = [
                    f"{e.name!r}: {'int(self.' + e.name + ')' if e.enum else 'self.' + e.name}," for e in f.entries
                ]
                code.read_from(
                    [
                        self.from_value_expr(e.name, e.enum.class_name if e.enum else None, is_float=e.type.is_float)
                        for e in f.entries
                    ]
                )
                self.helper_classes.append(code)
            case (
                Scalar()
                | Varint()
                | Group()
                | TableBlock()
                | Array()
                | Packed()
                | List()
                | Text()
                | Bytes()
                | TableValue()
            ):
                pass  # no nested values, or their class is made already
            case _:
                assert_never(f)

    def from_value_expr(self, name: str, enum: str | None, preset: int | None = None, is_float: bool = False) -> Calls:
        """A value of a bit field or table block entry, from data: an enum member or an integer (or a number); a bit
        field with a constant or default (`preset`) may be left out, as the bits class leaves it out."""
        get, uses = (
            (f"_get(data, {name!r}, where)", ["_get"]) if preset is None else (f"data.get({name!r}, {preset})", [])
        )
        if enum:
            return Calls(f"_as_enum({enum}, {get}, {name!r}, where)", ["_as_enum", *uses])
        helper = "_number" if is_float else "_integer"
        return Calls(f"{helper}({get}, {name!r}, where)", [helper, *uses])

    def to_json(self, f: SpecField, expr: str) -> str:
        return kind(f).to_json(f, expr)

    def from_json(self, f: SpecField) -> Calls:
        return kind(f).from_json(f)

    def message(self, message: Message) -> None:
        for f in [*self.frame_values(message.direction, message), *message.fields]:
            self.helper(f)
        fields = [*self.frame_values(message.direction, message), *self.value_fields(message)]
        doc = f"{message.command} {message.subcommand or ''} {message.direction.value}".replace("  ", " ")
        # optional frame elements (`present_if`): their bytes, None when not sent, after every other field
        optional = optional_elements(self.protocol, message.direction)
        extras = [
            Attribute(e.name, "bytes | None", one_line(f"{e.description or e.name} ({e.size} bytes, or None)"), "None")
            for e in optional
        ]
        partial = self.protocol.framing.partial_values(message.direction)
        code = ClassCode(message.class_name, doc, "Message", [*self.attributes(fields, partial=partial), *extras])
        code.class_vars = [
            f"PROTOCOL: ClassVar[str] = {self.protocol.name!r}",
            f"COMMAND: ClassVar[str] = {message.command!r}",
            f"SUBCOMMAND: ClassVar[str | None] = {message.subcommand!r}",
            f"DIRECTION: ClassVar[Direction] = Direction.{message.direction.name}",
        ]
        code.to_fields = [
            f"{spec_key(f.name)}: None if self.{f.name} is None else {self.to_json(f, 'self.' + f.name)},"
            if f.name in partial
            else f"{spec_key(f.name)}: {self.to_json(f, 'self.' + f.name)},"
            for f in fields
        ]
        code.to_fields += [f"{e.name!r}: None if self.{e.name} is None else self.{e.name}.hex(' ')," for e in optional]
        code.read_from(
            [
                *(
                    Calls(f"None if data.get({f.name!r}) is None else {self.from_json(f)}", (), self.from_json(f))
                    if f.name in partial
                    else self.from_json(f)
                    for f in fields
                ),
                *(Calls(f"_optional_bytes(data, {e.name!r}, where)", ["_optional_bytes"]) for e in optional),
            ]
        )
        code.given_checks = self.given_checks(message)
        if code.given_checks:
            code.helpers |= {"_check_given"}
        self.message_classes.append(code)
        frame_names = [f.name for f in self.frame_values(message.direction, message)]
        extra = "".join(f", {name}: int" for name in frame_names)
        extra += "".join(f", {e.name}: bytes | None = None" for e in optional)  # (straight-line code: not sent)
        decoder = fold_last_size_check(self.decoder(message, fields))
        self.decoders.append((decoder_name(message), message.class_name, extra, decoder))
        encoder = read_fields_once(deferred_item_checks(self.encoder(message, fields)), [f.name for f in fields])
        encoder_lines = lines_of(encoder)
        self.encoders.append((encoder_name(message), message.class_name, encoder_lines))

    def given_checks(self, message: Message) -> Lines:
        """from_fields: each value encode computes (a count, a size, a `value:` expression, a constant) that the data
        gives anyway must be the one encode writes (runtime.fields.check_given); `m` is the message built."""
        siblings = list(message.fields)
        lines = []
        for f in message.fields:
            if not (isinstance(f, Scalar) and f.hidden):
                continue
            if f.const is not None:
                computed = number(f.const)
            elif f.value is None and f.derived[0] == "size" and self.sibling(siblings, f.derived[1]) is None:
                continue  # the size of bytes in every item of a group: encode refuses items that differ
            else:
                computed = attribute_reads(self.derived_source(f, "m", siblings))
            lines.append(f"_check_given(data, {spec_key(f.name)}, lambda: {computed}, where)")
        return lines

    # --- decoding -------------------------------------------------------------------------------------------------

    def where(self, message: Message) -> str:
        return repr(f"{message.key} {message.direction.value}")

    def decoder(self, message: Message, all_fields: list[SpecField]) -> Block:
        """Body of `_decode_X(buf, o, end, *frame_values)`: content bytes buf[o:end] -> message."""
        body: Block = []
        where = self.where(message)
        low, high = message.min_size, message.max_size
        if message.padded is not None:  # sent without its trailing zero bytes: padded back to its one size
            low = high = message.padded
            pad = (Code(f"buf = bytes(buf[o:end]) + bytes({low} - end + o)"), Code(f"o, end = 0, {low}"))
            body.append(If(f"end - o < {low}", pad, cursor=True, comment="truncate: trailing_zeros"))
        if not (low == 0 and high is None):  # else any size will do
            body.append(ContentSize(low, high, where))
        # Where the layout alone says the fields end at `end` (one fixed size, checked above, or a last field that
        # takes the rest), no check that they do is emitted, and nothing reads the cursor after the last field.
        exact = low == high and all(fixed_size(f) is not None for f in message.fields)
        exact = exact or takes_the_rest(message.fields[-1] if message.fields else None)
        values = self.decode_fields(list(message.fields), message.class_name, body, where, top=not exact)
        if exact and body and isinstance(body[-1], Advance) and body[-1].to in ("", "end"):
            body.pop()
        self.check_values(list(message.fields), body, where)
        frame_fields = all_fields[: len(all_fields) - len(self.value_fields(message))]
        frame_values = [self.after_unpack(f, f.name, body, where) or f.name for f in frame_fields]
        optional = [e.name for e in optional_elements(self.protocol, message.direction)]
        names = [f.name for f in all_fields] + optional
        values = [*values, *optional]
        assert len(names) == len(frame_values) + len(values), (message.class_name, names, frame_values, values)
        self.built[message.class_name] = names
        body.append(ReturnNew(message.class_name, (*frame_values, *values)))
        return body

    def build(self, class_name: str, names: list[str], values: list[str], target: str, body: Block) -> None:
        """The statement that makes an instance of a generated class in `target` from its field values, in field
        order.

        Every decoder builds its messages here or as a ReturnNew (one place, so a change of how messages are made
        reaches all of them): `_new(Class, (values...))` is the runtime's `build`, one C call that stores the tuple
        of values as the record (message.py); decoded values need none of the checks the class's __new__ would not
        make anyway.
        """
        assert len(names) == len(values), (class_name, names, values)
        self.built[class_name] = names
        body.append(Code(f"{target} = _new({class_name}, {values_tuple(values)})"))

    def build_each(self, class_name: str, names: list[str], tuples: str) -> str:
        """The expression of a tuple of instances of a generated class, one built (as `build` does) from each tuple
        of field values, in field order, that the expression `tuples` yields (a struct's iter_unpack)."""
        self.built[class_name] = names
        return f"tuple([_new({class_name}, values) for values in {tuples}])"

    def build_all(self, class_name: str, names: list[str], tuples: str) -> str:
        """The expression of an iterator of instances of a generated class, one built (as `build` does) from each
        tuple of field values, in field order, that the expression `tuples` yields, with no Python call per item."""
        self.built[class_name] = names
        return f"map(_new, repeat({class_name}), {tuples})"

    def enum_value(self, enum: str, raw: str) -> str:
        """The member for a wire value, or the value itself when the spec names none (as enum_or_int does)."""
        self.member_maps.add(enum)
        return f"{members_name(enum)}.get({raw}, {raw})"

    def flags_value(self, flags: str, raw: str, body: Block) -> str:
        """A flags member for a wire value: looked up, made by the flag class only the first time it is seen."""
        self.member_maps.add(flags)
        name = f"{raw}_flags"
        body.append(Code(f"{name} = {members_name(flags)}.get({raw})"))
        body.append(If(f"{name} is None", (Code(f"{name} = {flags}({raw})"),)))
        return name

    def decode_fields(
        self, fields: list[SpecField], base: str, body: Block, where: str, top: bool, known: int | None = None
    ) -> list[str]:
        """Append statements reading fields at cursor `o`; return the expressions of the non-hidden values.

        `known`: bytes known to be left at `o` (None: as many as the leading fixed fields take, which the content's
        size check covers). A run of fixed fields beyond them (after a variable field, in an item of varying size)
        checks the bytes left first: content is decoded in place, and reading past `end` would read the frame's
        next bytes rather than fail."""
        values: list[str] = []
        for item in fixed_runs(fields):
            if isinstance(item, list):
                size = sum(fixed_size(f) or 0 for f in item)
                if known is not None and size > known:
                    reason = f"{item[0].name} needs {size} bytes, {{end - o}} left"
                    body.append(Needs(size, f"DecodeError({where} + f': {reason}')"))
                    known = size
                known = None if known is None else known - size
                values += self.decode_run(item, base, body, where)
            else:
                values.append(self.decode_variable(item, fields, base, body, where))
                known = 0
        if top:
            body.append(LeftOver(where))
        return values

    def check_values(self, fields: list[SpecField], body: Block, where: str) -> None:
        """Every value derived by an expression must hold what the expression gives for the decoded fields."""
        counted = {f.count: f.name for f in fields if isinstance(f, List) and isinstance(f.count, str)}
        # a byte size of a list of numbers: decoding read size // item items and refused a remainder
        sized = {f.size: f for f in fields if isinstance(f, List) and f.size and f.item is not None}
        for f in fields:
            narrow = isinstance(f, Scalar) and (f.minimum, f.maximum) != (f.type.minimum, f.type.maximum)
            if isinstance(f, Scalar) and (f.value is not None or f.derived) and narrow:
                # a computed value out of its declared range (a count of 0 where 1..123 are allowed): encode refuses
                # it, so decode does (the message does not hold it, so nobody could see it was wrong)
                low, high = number(f.minimum), number(f.maximum)
                reason = f"{f.name} is {{{self.local(f)}}}, outside its range {low}..{high}"
                condition = f"not {low} <= {self.local(f)} <= {high}"
                body.append(If(condition, (Raise(f"DecodeError({where} + f': {reason}')"),)))
            if isinstance(f, Scalar) and f.value == expression.Length(counted.get(f.name, "")):
                continue  # the count of the list it counts: decoding read exactly that many
            listed = sized.get(f.name)
            if isinstance(f, Scalar) and listed is not None and listed.item is not None:
                items = expression.Length(listed.name)
                scaled = expression.BinOp("*", expression.Const(listed.item.size), items)
                if f.value in (scaled, items if listed.item.size == 1 else None):
                    continue  # the byte size of the list it sizes: decoding read exactly that many bytes
            if isinstance(f, Scalar) and f.value is not None:
                # a fixed-size field may be read within a run of fixed fields, with no list of its own: its length
                # is known
                known = expression.with_lengths(f.value, fixed_lengths(fields))
                expected = expression.render(known, self.local_named)
                shown = one_line(expression.show(f.value)).replace("{", "{{").replace("}", "}}")
                if expression.fails(f.value):  # a divisor of 0 or a negative shift from the wire: a bad frame
                    reason = f"{f.name}: {shown} has no value here (a division by 0 or a negative shift)"
                    body.append(
                        Try(
                            (Code(f"expected_value = {expected}"),),
                            "(ZeroDivisionError, ValueError)",
                            (Raise(f"DecodeError({where} + f': {reason}') from None"),),
                        )
                    )
                    expected = "expected_value"
                reason = f"{f.name} is {{{self.local(f)}}}, but {shown} = {{{expected}}}"
                body.append(If(f"{self.local(f)} != {expected}", (Raise(f"DecodeError({where} + f': {reason}')"),)))

    def decode_run(self, run: list[SpecField], base: str, body: Block, where: str) -> list[str]:
        endian = run_endian(run)
        fmt = struct_format(endian, run)
        const_name = self.struct(f"{base}_{run[0].name}", fmt)
        size = sum(fixed_size(f) or 0 for f in run)
        simple = all(isinstance(f, Scalar | Bytes) for f in run)
        values: list[str] = []
        if simple:
            read = [f for f in run if not isinstance(f, Scalar) or f.bit_place is None or f.bit_place.first]
            names = [self.local(f) + ("_run" if isinstance(f, Scalar) and f.bit_place else "") for f in read]
            body.append(Unpack(tuple(names), const_name, byte=fmt in ("<B", ">B")))
            for f in run:
                name = self.local(f)
                if isinstance(f, Scalar) and f.bit_place is not None:
                    self.bit_member(f, f"{self.local_named(f.bit_place.run)}_run", body)
                expr = self.after_unpack(f, name, body, where)
                if expr is not None:
                    values.append(expr)
        else:
            body.append(Unpack(("t",), const_name, tuple_target=True))
            position = 0
            for f in run:
                if isinstance(f, Array):
                    values.append(f"t[{position}:{position + f.count}]")
                    position += f.count
                elif isinstance(f, TableBlock):
                    items = []
                    for e in f.entries:
                        item = f"t[{position}]"
                        items.append(self.enum_value(e.enum.class_name, item) if e.enum else item)
                        position += 1
                    self.build(f.class_name, [e.name for e in f.entries], items, self.local(f), body)
                    values.append(self.local(f))
                else:
                    name = self.local(f)
                    if isinstance(f, Scalar) and f.bit_place is not None:
                        if f.bit_place.first:
                            body.append(Code(f"{name}_run = t[{position}]"))
                            position += 1
                        self.bit_member(f, f"{self.local_named(f.bit_place.run)}_run", body)
                    else:
                        body.append(Code(f"{name} = t[{position}]"))
                        position += 1
                    expr = self.after_unpack(f, name, body, where)
                    if expr is not None:
                        values.append(expr)
        body.append(Advance(size))
        return values

    def local(self, f: SpecField) -> str:
        return f"{self._scopes[-1][0]}{f.name}"

    def bit_member(self, f: Scalar, run: str, body: Block) -> None:
        """A member of a bit run from the run's bytes (`run`, read by the struct): the run is one integer, made by
        its first member, and each member its bits (encodings/bit_run.py)."""
        place = f.bit_place
        assert place is not None
        if place.first:
            body.append(Code(f"{run} = int.from_bytes({run}, 'big')"))
        value = bit_run.python_decode(run, place.bits, place.shift, place.size, f.type.signed)
        body.append(Code(f"{self.local(f)} = {value}"))

    def after_unpack(self, f: SpecField, name: str, body: Block, where: str) -> str | None:
        """Checks and conversions after a scalar is unpacked; the value expression, or None if hidden."""
        if isinstance(f, Packed):
            self.packing.add("unpack_ints")
            return f"_unpack_ints({name}, {f.bits}, {f.count}, {f.lsb_first}, {f.signed})"
        if isinstance(f, Text) and isinstance(f.size, int):  # read as bytes by the run's struct
            if f.pad is not None:
                self.packing.add("unpad_text")
                text = f"_unpad_text({name}, {f.pad}, {spec_key(f.name)}, {where})"
            else:
                text = f"{self.text_decoder(f)}({name}, {spec_key(f.name)}, {where})"
            body.append(Code(f"{name} = {text}", checks=True))  # refuses bytes that are not its text
            return name
        if not isinstance(f, Scalar):
            return name
        if f.odd_width:  # read as 3 bytes
            order = "big" if f.endian == ">" else "little"
            body.append(Code(f"{name} = int.from_bytes({name}, {order!r}, signed={f.wire_signed})"))
        if f.const is not None:
            error = f"DecodeError({where} + f': {f.name} is {{{name}:#x}}, expected {f.const:#x}')"
            body.append(Expect(name, f"{f.const}", error))
            return None
        if f.derived or f.value is not None:
            return None
        if f.sign_magnitude:
            top = 1 << (f.type.size * 8 - 1)
            body.append(If(f"{name} & {top:#x}", (Code(f"{name} = -({name} & {top - 1:#x})"),)))
        if (encoding := f.low_bits) is not None:  # a few bits a byte (encodings/low_bits.py)
            size = f.type.size
            marks = encoding.marks(size)
            shown = f"{{{name}:#0{2 + 2 * size}x}}"
            error = f"DecodeError({where} + f': {encoding.flaw} of a byte of {f.name} is set ({shown})')"
            body.append(If(f"{name} & {marks:#x}", (Raise(error),)))
            body.append(Code(f"{name} = {encoding.python_decode(name, size, f.type.signed)}"))
        if f.bits:
            used = 0
            parts = []
            for bit in f.bits:
                used |= bit.mask << bit.low
                raw = f"({name} >> {bit.low}) & {bit.mask:#x}" if bit.low else f"{name} & {bit.mask:#x}"
                if bit.const is not None:
                    error = f"DecodeError({where} + f': {f.name}.{bit.name} is {{{raw}}}, expected {bit.const}')"
                    body.append(If(f"{raw} != {bit.const}", (Raise(error),)))
                if bit.enum:
                    body.append(Code(f"{name}_{bit.name} = {raw}"))
                    parts.append(self.enum_value(bit.enum.class_name, f"{name}_{bit.name}"))
                else:
                    parts.append(raw)
            unused = ((1 << (f.type.size * 8)) - 1) & ~used
            if unused:
                error = f"DecodeError({where} + f': unused bits of {f.name} are set ({{{name}:#04x}})')"
                body.append(If(f"{name} & {unused:#x}", (Raise(error),)))
            self.build(f.bits_class, [b.name for b in f.bits], parts, f"{name}_bits", body)
            return f"{name}_bits"
        if f.enum:
            return self.enum_value(f.enum.class_name, name)
        if f.flags:
            return self.flags_value(f.flags.class_name, name, body)
        return name

    def decode_variable(self, f: SpecField, siblings: list[SpecField], base: str, body: Block, where: str) -> str:
        match f:
            case List():
                return self.decode_list(f, body, where, siblings)
            case Text():
                return self.decode_text(f, body, where)
            case Bytes():
                if f.size == "rest":
                    body.append(TakeRest(self.local(f)))
                    body.append(Advance(to="end"))
                else:
                    size = self.count_value(f, f.size, body, where)
                    body.append(
                        Needs(size, f"DecodeError({where} + f': {f.name} needs {{{size}}} bytes, {{end - o}} left')")
                    )
                    body.append(Code(f"{self.local(f)} = buf[o : o + {size}]", cursor=True))
                    body.append(Advance(size))
                return self.local(f)
            case TableValue():
                table = f"_TABLE_{f.table.name.upper()}"
                key = self.local_named(f.key)
                body.append(Code(f"s = {table}.get({key})"))
                error = f"DecodeError({where} + f': unknown {f.table.key_name} {{{key}}}')"
                body.append(If("s is None", (Raise(error),)))
                reason = f"{f.name} needs {{s.size}} bytes for {f.table.key_name} {{{key}}}"
                body.append(If("end - o < s.size", (Raise(f"DecodeError({where} + f': {reason}')"),), cursor=True))
                body.append(Code(f"({self.local(f)},) = s.unpack_from(buf, o)", cursor=True))
                body.append(Advance("s.size"))
                return self.local(f)
            case Group():
                return self.decode_group(f, body, where)
            case Varint():  # as many bytes as its value needs (encodings/varint.py)
                self.packing.add("read_varint")
                span = f"{varint_form(f)}, {f.minimum}, {f.maximum}"
                read = f"_read_varint(buf, o, end, {span}, {spec_key(f.name)}, {where})"
                body.append(Code(f"{self.local(f)}, stop = {read}", cursor=True))
                body.append(Advance(to="stop"))
                return self.local(f)
            case Scalar() | Array() | Packed() | TableBlock():
                raise AssertionError(f"{f.name}: a field of fixed size is decoded in a run (decode_run)")
            case _:
                assert_never(f)

    def decode_group(self, f: Group, body: Block, where: str) -> str:
        """A group's items: unpacked in a loop where they have one size, else read one by one; their locals in a
        scope of their own (see `_scopes`)."""
        value = self.local(f)
        count = None if f.count == "rest" else self.count_value(f, f.count, body, where)  # (a field of the message)
        self._scopes.append((f"i{len(self._scopes)}_", frozenset(i.name for i in f.fields)))
        try:
            return self.group_items(f, value, count, body, where)
        finally:
            self._scopes.pop()

    def group_items(self, f: Group, value: str, count: str | None, body: Block, where: str) -> str:
        """decode_group's items, `count` the expression of their count (None: the rest of the content)."""
        item_fields = list(f.fields)
        item_names = [i.name for i in item_fields if not (isinstance(i, Scalar) and i.hidden)]
        start_list = Code(f"{value}_list = []")
        body.append(start_list)
        if f.item_size is not None and all(map(is_fixed_run_member, item_fields)) and one_order(item_fields):
            item_fmt = struct_format(run_endian(item_fields), item_fields)  # one struct per item
            item_struct = self.struct(f"{f.class_name}", item_fmt)
            if f.count == "rest":
                reason = f"{{end - o}} bytes do not split into {f.name} items of {f.item_size}"
                split = Raise(f"DecodeError({where} + f': {reason}')")
                body.append(If(f"(end - o) % {f.item_size}", (split,), cursor=True))
                body.append(Code("n = end - o", cursor=True))
            else:
                body.append(Code(f"n = {count} * {f.item_size}"))
                reason = f"content too short for its count ({{{count}}} {f.name})"
                body.append(Needs("n", f"DecodeError({where} + f': {reason}')"))
            item_body: Block = []
            names = []
            for i in item_fields:  # a bit run's bytes read at its first field, each field's bits from them
                if isinstance(i, Scalar) and i.bit_place is not None:
                    run = f"{self.local_named(i.bit_place.run)}_run"
                    names += [run] if i.bit_place.first else []
                    self.bit_member(i, run, item_body)
                else:
                    names.append(self.local(i))
            item_values = [self.after_unpack(i, self.local(i), item_body, where) for i in item_fields]
            values = [v for v in item_values if v is not None]
            items = f"{item_struct}.iter_unpack(buf[o : o + n])"
            if not item_body and values == names:  # the unpacked tuples are the items' values
                body.remove(start_list)
                body.append(Code(f"{value} = {self.build_each(f.class_name, item_names, items)}", cursor=True))
                body.append(Advance("n"))
                return value
            self.build(f.class_name, item_names, values, "item", item_body)
            target = ", ".join(names) + ("," if len(names) == 1 else "")
            item_body.append(Code(f"{value}_list.append(item)"))
            body.append(Loop(f"for {target} in {items}", tuple(item_body), cursor=True))
            body.append(Code(f"{value} = tuple({value}_list)"))
            body.append(Advance("n"))
            return value
        # items of varying size: read them one by one
        if count is None:
            header, cursor = "while o < end", True
        else:
            header, cursor = f"for _ in range({count})", False
        inner: Block = []
        # in `while o < end` one byte is known to be left, in `for _ in range(count)` none
        item_args = self.decode_fields(item_fields, f.class_name, inner, where, False, 1 if f.count == "rest" else 0)
        self.build(f.class_name, item_names, item_args, "item", inner)
        inner.append(Code(f"{value}_list.append(item)"))
        body.append(Loop(header, tuple(inner), cursor=cursor))
        body.append(Code(f"{value} = tuple({value}_list)"))
        return value

    def decode_list(self, f: List, body: Block, where: str, siblings: list[SpecField]) -> str:
        """A list of numbers or bits: its count from a number, a count field, a byte-size field, or the rest."""
        value = self.local(f)
        item = 1 if f.item is None else f.item.size
        if f.size or f.count == "rest":
            body.append(Code(f"nb = {self.local_named(f.size)}") if f.size else Code("nb = end - o", cursor=True))
            if f.item is None:
                body.append(Code("n = nb * 8"))
            else:
                if item > 1:
                    reason = f"{{nb}} bytes do not split into {f.name} items of {item}"
                    body.append(If(f"nb % {item}", (Raise(f"DecodeError({where} + f': {reason}')"),)))
                body.append(Code(f"n = nb // {item}" if item > 1 else "n = nb"))
        else:
            body.append(Code(f"n = {self.count_value(f, f.count, body, where)}"))
            body.append(Code("nb = (n + 7) >> 3" if f.item is None else (f"nb = n * {item}" if item > 1 else "nb = n")))
        body.append(Needs("nb", f"DecodeError({where} + f': {f.name} needs {{nb}} bytes, {{end - o}} left')"))
        most = self.most_items(f, siblings)
        if f.item is None:
            self.packing.add("unpack_bits")
            body.append(Code(f"{value} = _unpack_bits(buf, o, n)", cursor=True))
        elif most is not None and most <= _MOST_RUNS:  # a struct per count, made once
            name = f"_RUNS_{'BE' if f.endian == '>' else 'LE'}_{_STRUCT_NAMES[f.item.struct_char]}"
            known = self.unpack_runs.get(name, ("", 0))[1]
            self.unpack_runs[name] = (f"{f.endian}{f.item.struct_char}", max(most, known))
            body.append(Code(f"{value} = {name}[n](buf, o)", cursor=True))
        else:
            read = f"struct.unpack_from(f'{f.endian}{{n}}{f.item.struct_char}', buf, o)"
            body.append(Code(f"{value} = {read}", cursor=True))
        body.append(Advance("nb"))
        return value

    def most_items(self, f: List, siblings: list[SpecField]) -> int | None:
        """The most items a list of numbers can hold, where a count or byte-size field of the message bounds it: by
        the field's type, not its declared range (a frame may carry any value the type holds)."""
        scalars = {s.name: s for s in siblings if isinstance(s, Scalar) and not s.type.is_float}
        item = 1 if f.item is None else f.item.size
        if f.size and str(f.size) in scalars:
            return int(scalars[str(f.size)].type.maximum) // item
        if isinstance(f.count, str) and f.count in scalars:
            return int(scalars[f.count].type.maximum)
        if isinstance(f.count, Counted):
            return f.count.high
        return None

    def count_value(self, f: SpecField, count: int | str | Counted, body: Block, where: str) -> str:
        """Python source of a decoded count or size: a number, a count field's value, or an expression's, worked out
        into a local and refused when negative (serialspec/lang/counts.py)."""
        if isinstance(count, int):
            return str(count)
        if isinstance(count, str):
            return self.local_named(count)
        local = f"n_{f.name}"
        body.append(Code(f"{local} = {counts.python_value(count, self.local_named)}"))
        if count.low < 0:
            reason = counts.python_reason(f, count, local)
            body.append(If(f"{local} < 0", (Raise(f"DecodeError({where} + f': {reason}')"),)))
        return local

    def check_count(self, f: SpecField, obj: str, data: str, body: Block, where: str) -> None:
        """Encode: a list, group, bytes or text whose count or size an expression gives has that length."""
        count = counts.counted(f)
        if count is None:
            return
        local = f"{obj}_n_{f.name}" if obj != "m" else f"n_{f.name}"
        body.append(Code(f"{local} = {counts.python_value(count, lambda name: field_read(obj, name))}"))
        reason = counts.python_encode_reason(f, count, local, f"len({data})")
        body.append(If(f"len({data}) != {local}", (Raise(f"EncodeError({where} + f': {reason}')"),)))

    def text_decoder(self, f: Text) -> str:
        """The runtime function making a text field's bytes its text (packing.py)."""
        helper = "decode_seven_bit_text" if f.seven_bit else "decode_text"
        self.packing.add(helper)
        return "_" + helper

    def decode_text(self, f: Text, body: Block, where: str) -> str:
        value = self.local(f)
        helper = self.text_decoder(f)
        if f.size is None:
            body.append(Code("stop = buf.find(b'\\0', o, end)", cursor=True))
            body.append(If("stop < 0", (Raise(f"DecodeError({where} + ': {f.name} has no NUL at its end')"),)))
            body.append(Code(f"{value} = {helper}(buf[o:stop], {spec_key(f.name)}, {where})", cursor=True))
            body.append(Advance(to="stop + 1"))
            return value
        if f.size == "rest":
            body.append(Code(f"{value} = {helper}(buf[o:end], {spec_key(f.name)}, {where})", cursor=True))
            body.append(Advance(to="end"))
            return value
        size = self.count_value(f, f.size, body, where)
        body.append(Needs(size, f"DecodeError({where} + f': {f.name} needs {{{size}}} bytes, {{end - o}} left')"))
        body.append(Code(f"{value} = {helper}(buf[o : o + {size}], {spec_key(f.name)}, {where})", cursor=True))
        body.append(Advance(size))
        return value

    def local_named(self, name: str) -> str:
        prefix = next((prefix for prefix, names in reversed(self._scopes) if name in names), self._scopes[0][0])
        return f"{prefix}{name}"

    # --- encoding -------------------------------------------------------------------------------------------------

    def encoder(self, message: Message, all_fields: list[SpecField]) -> Block:
        """Body of `_encode_X(m) -> bytes`: range checks, then the frame's bytes."""
        body: Block = []
        where = self.where(message)
        frame_fields = all_fields[: len(all_fields) - len(self.value_fields(message))]
        layout = self.protocol.layout(message)
        elements = {e.name: e for e in layout.value_elements}
        frame_values = []
        error = self.protocol.error_reply if message.error_reply else None
        for f in frame_fields:
            assert isinstance(f, Scalar)
            if f.bits:
                frame_values.append(self.wire_value(f, "m", [], body, where))
                continue
            if error is not None and f.name == error.element:  # the refused request's code: sent with the flag
                self.check_scalar(f, field_read("m", f.name), body, where)
                continue
            if f.name in self.protocol.framing.partial_values(message.direction):  # None: a layout without it
                checks: Block = []
                self.check_scalar(f, field_read("m", f.name), checks, where, also=elements[f.name].broadcast)
                body.append(If(f"{field_read('m', f.name)} is not None", tuple(checks)))
            else:
                self.check_scalar(f, field_read("m", f.name), body, where, also=elements[f.name].broadcast)
            frame_values.append(Simple(field_read("m", f.name)))
        self.check_error_bits(
            message,
            [f.name for f in frame_fields if f.name != getattr(error, "element", None)],
            frame_values,
            body,
            where,
        )
        self.check_count_from(message, body, where)
        return message_frame(self, message, frame_values, body, where)  # the frame around the content: frames/encode.py

    def check_scalar(self, f: Scalar, expr: str, body: Block, where: str, also: int | None = None) -> None:
        """Range check; `also` is one more value allowed outside the range (an address's broadcast value)."""
        # an integer field refuses True and False too (bool is an int to Python, never to the wire)
        not_bool = "" if f.type.is_float else f" or {expr}.__class__ is bool"
        if f.flags:  # typed as the IntFlag class, which mypy knows is no bool: asked the way it accepts
            not_bool = f" or isinstance({expr}, bool)"
        low, high = bound(f, f.minimum), bound(f, f.maximum)
        if also is not None and also in (f.minimum - 1, f.maximum + 1):  # next to the range: one comparison
            low, high = bound(f, min(also, f.minimum)), bound(f, max(also, f.maximum))
            condition = f"not {low} <= {expr} <= {high}{not_bool}"
        elif also is not None and not f.minimum <= also <= f.maximum:
            condition = f"not ({low} <= {expr} <= {high} or {expr} == {also}){not_bool}"
        else:
            condition = f"not {low} <= {expr} <= {high}{not_bool}"
        broadcast = "" if also is None or f.minimum <= also <= f.maximum else f", {also}"
        error = (
            f"out_of_range({where}, {spec_key(f.name)}, {expr}, {number(f.minimum)}, {number(f.maximum)}{broadcast})"
        )
        body.append(If(condition, (Raise(error),)))

    def check_error_bits(
        self, message: Message, names: list[str], frame_values: list[str], body: Block, where: str
    ) -> None:
        """Where the status's `error_bits` mark the error reply: the error reply has one of them set, every other
        reply none (it would be read back as the error reply)."""
        error = self.protocol.error_reply
        if error is None or not error.status or message.direction != Direction.RESPONSE:
            return
        value = frame_values[names.index(error.status)]
        if message.error_reply:
            condition = f"not ({value}) & {error.bits:#04x}"
            reason = f"an error reply has one of the error bits {error.bits:#04x} set in {error.status}"
        else:
            condition = f"({value}) & {error.bits:#04x}"
            reason = (
                f"{error.status} has error bits {error.bits:#04x} set: only the error reply ({error.command}) has them"
            )
        body.append(If(condition, (Raise(f"EncodeError({where} + {': ' + reason!r})"),)))

    def check_count_from(self, message: Message, body: Block, where: str) -> None:
        """A response list whose count the request gives (`count_from`) holds no more items than the request's
        count field allows (Modbus: at most 2000 coils), so no frame is made that no request could have asked for."""
        for f in message.fields:
            if not (isinstance(f, List) and f.count_from):
                continue
            request = next(
                m
                for m in self.protocol.messages()
                if (m.command, m.subcommand, m.direction.value) == (message.command, message.subcommand, "request")
            )
            count = next(c for c in request.fields if c.name == f.count_from)
            assert isinstance(count, Scalar)
            high = number(count.maximum)
            items = f"len({field_read('m', f.name)})"
            reason = f"{f.name} has {{{items}}} items, at most {high} (the limit of the request field {count.name})"
            body.append(If(f"{items} > {high}", (Raise(f"EncodeError({where} + f': {reason}')"),)))

    def check_items(self, f: Array | List | Packed, expr: str, body: Block, where: str) -> None:
        """Every number of a list within the item's range, and none a bool (True is not 1); the first at fault named.

        A plain loop: any() over a generator costs a frame per call, twice the time for a few items. Where the
        range is the item type's, struct.pack checks it: the loop runs only if the pack fails (deferred_item_checks).
        """
        low, high = number(f.minimum), number(f.maximum)
        kind = f.item if isinstance(f, List) else None
        deferrable = kind is not None and not kind.is_float and (f.minimum, f.maximum) == (kind.minimum, kind.maximum)
        error = f"out_of_range({where}, {spec_key(f.name)}, {expr}, {low}, {high})"
        body.append(ItemsCheck(f"x_{f.name}", expr, low, high, error, deferrable))

    def encode_fields(self, fields: list[SpecField], base: str, obj: str, body: Block, where: str) -> list[str]:
        """Append checks and local values; return expressions of the byte parts in order."""
        parts: list[str] = []
        for item in fixed_runs(fields):
            if isinstance(item, list):
                parts.append(self.encode_run(item, base, obj, fields, body, where))
            else:
                parts.append(self.encode_variable(item, obj, body, where))
        return parts

    def derived_source(self, f: Scalar, obj: str, siblings: list[SpecField]) -> str:
        """Python source of a derived value (by `value:` expression, or a count or size of a list or text)."""
        by_name = {s.name: s for s in siblings}
        if f.value is not None:

            def source(name: str) -> str:
                other = by_name[name]
                if isinstance(other, Scalar) and (other.value is not None or other.derived):
                    return f"({self.derived_source(other, obj, siblings)})"
                return field_read(obj, name)

            return expression.render(f.value, source)
        kind, target = f.derived[0], f.derived[1]
        other = by_name.get(target)
        if kind == "size" and isinstance(other, List):
            count = f"len({field_read(obj, target)})"
            return f"(({count} + 7) >> 3)" if other.item is None else f"{count} * {other.item.size}"
        if kind == "size" and isinstance(other, Text):
            return f"len({field_read(obj, target)}.encode('utf-8'))"
        return f"len({field_read(obj, target)})"

    def wire_value(self, f: Scalar, obj: str, siblings: list[SpecField], body: Block, where: str) -> str:
        if f.const is not None:
            return Simple(number(f.const)) if f.const >= 0 else number(f.const)

        def out_of_range(value: str) -> Raise:
            return Raise(
                f"out_of_range({where}, {spec_key(f.name)}, {value}, {number(f.minimum)}, {number(f.maximum)})"
            )

        if f.value is not None or (f.derived and isinstance(self.sibling(siblings, f.derived[1]), List | Text)):
            value: str = Simple(self.local(f) if obj == "m" else f"{obj}_{f.name}")
            body.append(Code(f"{value} = {self.derived_source(f, obj, siblings)}"))
            condition = f"not {number(f.minimum)} <= {value} <= {number(f.maximum)}"
            body.append(If(condition, (out_of_range(value),)))
            return value
        if f.derived:
            kind, target = f.derived[0], f.derived[1]
            if kind == "count" or any(s.name == target for s in siblings):  # a count, or bytes beside their size
                value = f"len({field_read(obj, target)})"
            else:
                group = next(s for s in siblings if isinstance(s, Group) and any(i.name == target for i in s.fields))
                value = Simple(self.local_named(f.name))
                items = field_read(obj, group.name)
                body.append(Code(f"{value} = len({items}[0].{target}) if {items} else 0"))
                error = f"EncodeError({where} + ': every {target} of {group.name} must have the same length')"
                condition = f"any(len(item.{target}) != {value} for item in {items})"
                body.append(If(condition, (Raise(error),)))
            # a count or size is never negative: its lower bound is checked only where its range sets one
            condition = f"{value} > {number(f.maximum)}"
            if f.minimum > 0:
                condition = f"not {number(f.minimum)} <= {value} <= {number(f.maximum)}"
            body.append(If(condition, (out_of_range(value),)))
            return value
        expr = field_read(obj, f.name)
        if f.bits:
            packed = []
            for bit in f.bits:
                sub = f"{expr}.{bit.name}"
                low, high = (0, bit.mask) if bit.const is None else (bit.const, bit.const)  # a constant: itself
                error = f"out_of_range({where}, {f.name + '.' + bit.name!r}, {sub}, {low}, {high})"
                test = f"not {low} <= {sub} <= {high}" if bit.const is None else f"{sub} != {bit.const}"
                body.append(If(f"{test} or {sub}.__class__ is bool", (Raise(error),)))
                packed.append(f"({sub} << {bit.low})" if bit.low else Simple(sub))
            return packed[0] if len(packed) == 1 else " | ".join(packed)
        self.check_scalar(f, expr, body, where)
        if f.sign_magnitude:
            top = 1 << (f.type.size * 8 - 1)
            return f"(-{expr} | {top:#x} if {expr} < 0 else {expr})"
        if f.low_bits is not None:
            return f.low_bits.python_encode(expr, f.type.size)
        return Simple(expr)

    @staticmethod
    def sibling(siblings: list[SpecField], name: str) -> SpecField | None:
        return next((s for s in siblings if s.name == name), None)

    def encode_run(
        self, run: list[SpecField], base: str, obj: str, siblings: list[SpecField], body: Block, where: str
    ) -> str:
        endian, fmt, args = self.encode_run_format(run, obj, siblings, body, where)
        const_name = self.struct(f"{base}_{run[0].name}", endian + fmt)
        return Pack(const_name, args)

    def encode_run_format(
        self, run: list[SpecField], obj: str, siblings: list[SpecField], body: Block, where: str
    ) -> tuple[str, str, list[str]]:
        """Byte order, struct format (without it) and pack arguments of a run of fixed-size fields; checks to body."""
        args: list[str] = []
        for f in run:
            match f:
                case Scalar() if f.bit_place is not None:
                    place = f.bit_place
                    if place.first:  # the run's bytes from every member's value (encodings/bit_run.py)
                        parts = [
                            (self.wire_value(m, obj, siblings, body, where), at.bits, at.shift, m.type.signed)
                            for m in run
                            if isinstance(m, Scalar) and (at := m.bit_place) is not None and at.run == f.name
                        ]
                        args.append(bit_run.python_encode(parts, place.size))
                case Scalar() if f.odd_width:
                    order = "big" if f.endian == ">" else "little"
                    wire = self.wire_value(f, obj, siblings, body, where)
                    args.append(f"({wire}).to_bytes(3, {order!r}, signed={f.wire_signed})")
                case Scalar():
                    args.append(self.wire_value(f, obj, siblings, body, where))
                case Packed():
                    expr = field_read(obj, f.name)
                    error = f"EncodeError({where} + f': {f.name} needs {f.count} items, got {{len({expr})}}')"
                    body.append(If(f"len({expr}) != {f.count}", (Raise(error),)))
                    self.check_items(f, expr, body, where)
                    self.packing.add("pack_ints")
                    args.append(f"_pack_ints({expr}, {f.bits}, {f.count}, {f.lsb_first})")
                case Text():
                    args.append(self.encode_text(f, obj, body, where))
                case Array():
                    expr = field_read(obj, f.name)
                    error = f"EncodeError({where} + f': {f.name} needs {f.count} items, got {{len({expr})}}')"
                    body.append(If(f"len({expr}) != {f.count}", (Raise(error),)))
                    self.check_items(f, expr, body, where)
                    args.append(f"*{expr}")
                case Bytes():
                    expr = field_read(obj, f.name)
                    error = f"EncodeError({where} + f': {f.name} needs {f.size} bytes, got {{len({expr})}}')"
                    body.append(If(f"len({expr}) != {f.size}", (Raise(error),)))
                    args.append(Simple(expr))
                case TableBlock():
                    for e in f.entries:
                        expr = f"{field_read(obj, f.name)}.{e.name}"
                        name = f.name + "." + e.name
                        error = f"out_of_range({where}, {name!r}, {expr}, {number(e.minimum)}, {number(e.maximum)})"
                        body.append(If(f"not {number(e.minimum)} <= {expr} <= {number(e.maximum)}", (Raise(error),)))
                        args.append(Simple(expr))
                case List() | Group() | TableValue() | Varint():
                    raise AssertionError(f"{f.name}: a field of varying size is encoded alone (encode_variable)")
                case _:
                    assert_never(f)
        return run_endian(run), struct_format("", run), args

    def encode_text(self, f: Text, obj: str, body: Block, where: str) -> str:
        """The bytes of a text field: fixed-size text padded or checked to fill its size."""
        expr = field_read(obj, f.name)
        if isinstance(f.size, int) and f.pad is not None:
            self.packing.add("pad_text")
            return f"_pad_text({expr}, {f.size}, {f.pad}, {spec_key(f.name)}, {where})"
        if f.seven_bit:
            self.packing.add("encode_seven_bit_text")
            data = f"_encode_seven_bit_text({expr}, {spec_key(f.name)}, {where})"
        else:
            self.packing.add("encode_text")
            data = f"_encode_text({expr}, {spec_key(f.name)}, {where}, {f.size is None})"
        if isinstance(f.size, Counted):
            local = self.local(f) if obj == "m" else f"{obj}_{f.name}"
            body.append(Code(f"{local} = {data}"))
            self.check_count(f, obj, local, body, where)
            return local
        if isinstance(f.size, int):
            local = self.local(f) if obj == "m" else f"{obj}_{f.name}"
            body.append(Code(f"{local} = {data}"))
            what = f"{f.size // 2} characters ({f.size} bytes)" if f.seven_bit else f"{f.size} bytes of UTF-8"
            reason = f"{f.name} needs {what}, got {{len({local})}}"
            body.append(If(f"len({local}) != {f.size}", (Raise(f"EncodeError({where} + f': {reason}')"),)))
            return local
        return data

    def encode_variable(self, f: SpecField, obj: str, body: Block, where: str) -> str:
        expr = field_read(obj, f.name)
        count = f.count if isinstance(f, List | Group) else None
        count_error = f"EncodeError({where} + f': {f.name} needs {count} items, got {{len({expr})}}')"
        match f:
            case List():
                if isinstance(f.count, int):
                    body.append(If(f"len({expr}) != {f.count}", (Raise(count_error),)))
                self.check_count(f, obj, expr, body, where)
                if f.item is None:
                    self.packing.add("pack_bits")
                    return f"_pack_bits({expr}, {spec_key(f.name)}, {where})"
                self.check_items(f, expr, body, where)
                return PackItems(f.endian, f.item.struct_char, expr)
            case Text():
                return self.encode_text(f, obj, body, where)
            case Bytes():  # bytes as they are (bytes(b) looks up b.__bytes__ first), anything else made bytes
                body.append(Code(f"{self.local(f)} = {expr} if {expr}.__class__ is bytes else bytes({expr})"))
                self.check_count(f, obj, self.local(f), body, where)
                return self.local(f)
            case TableValue():
                table = f"_TABLE_{f.table.name.upper()}"
                key = field_read(obj, f.key)
                body.append(Code(f"s = {table}.get({key})"))
                body.append(
                    If("s is None", (Raise(f"EncodeError({where} + f': unknown {f.table.key_name} {{{key}}}')"),))
                )
                body.append(Code(f"low, high = _TABLE_{f.table.name.upper()}_RANGES[{key}]"))
                body.append(
                    If(
                        f"not low <= {expr} <= high",
                        (Raise(f"out_of_range({where}, {spec_key(f.name)}, {expr}, low, high)"),),
                    )
                )
                return f"s.pack({expr})"
            case Group():
                return self.encode_group(f, obj, body, where, expr, count_error)
            case Varint():
                self.packing.add("write_varint")
                form = varint_form(f)
                return f"_write_varint({expr}, {form}, {f.minimum}, {f.maximum}, {spec_key(f.name)}, {where})"
            case Scalar() | Array() | Packed() | TableBlock():
                raise AssertionError(f"{f.name}: a field of fixed size is encoded in a run (encode_run_format)")
            case _:
                assert_never(f)

    def encode_group(self, f: Group, obj: str, body: Block, where: str, expr: str, count_error: str) -> str:
        """A group's items, checked and packed in a loop."""
        if isinstance(f.count, int):
            body.append(If(f"len({expr}) != {f.count}", (Raise(count_error),)))
        self.check_count(f, obj, expr, body, where)
        # the items are checked and packed in a loop here, not by a function called per item
        item = "item" if obj == "m" else f"{obj}_item"
        item_body: Block = []
        parts = self.encode_fields(list(f.fields), f.class_name, item, item_body, where)
        packed = f"b''.join(({', '.join(parts)},))" if len(parts) > 1 else parts[0]
        # (a group in an item: its list named by its depth, apart from a group of its name further out)
        joined = f"parts_{f.name}" if obj == "m" else f"parts{obj.count('item')}_{f.name}"
        body.append(Code(f"{joined} = []"))
        item_body.append(Code(f"{joined}.append({packed})", lists=packed_lists(parts)))
        body.append(Loop(f"for {item} in {expr}", tuple(item_body), variable=item))
        return f"b''.join({joined})"
