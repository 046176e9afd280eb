"""The frame around every message: elements, alternative layouts, lengths over spans, checksums, transparency.

Every layout is described completely by its elements; the classic fields of FrameLayout (offsets from the header,
a one-byte length, one final checksum) are filled in too, and `classic` says whether they describe the whole frame.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, Literal

from serialspec import checksums, transforms
from serialspec.checksums import ChecksumProblem
from serialspec.checksums.seed import Seeded
from serialspec.checksums.seven_bit import SevenBitWire
from serialspec.encodings import seven_bit
from serialspec.lang import expression
from serialspec.lang.errors import SpecError
from serialspec.lang.grammar import FRAME_ELEMENT, Str
from serialspec.lang.loader import Path
from serialspec.lang.model import (
    SCALARS,
    VALUE_ROLES,
    Checksum,
    Direction,
    ExtendedLength,
    FrameElement,
    FrameLayout,
    Framing,
    ScalarType,
    Transparency,
    fixed_bits,
)
from serialspec.lang.passes.fields import FieldResolver
from serialspec.runtime.hexbytes import parse_hex
from serialspec.transforms import TransformProblem

CONSTANT_ROLES = ("header", "trailer", "constant")
_ROLE = FRAME_ELEMENT.keys["role"]
assert isinstance(_ROLE, Str)
ROLES = _ROLE.choices  # the grammar's: a role outside them is reported there, once
_CLASSIC_ROLES = {"header", "address", "command", "status", "value", "length", "content", "checksum"}


class FramingPass(FieldResolver):
    """Resolve `framing:` into the layouts of each direction (a field resolver for the elements' bit fields)."""

    def run(self) -> list[SpecError]:
        self.ctx.framing = self.guard(("framing",), self.framing, self.ctx.data.get("framing") or {}, ("framing",))
        return self.problems

    def framing(self, value: dict[str, Any], path: Path) -> Framing:
        for key in ("start", "separator", "end", "checksum", "talker", "max_length"):
            if key in value:
                self.error((*path, key), f"`{key}` belongs to text frames: add `kind: text`")
        if "layouts" in value and "elements" in value:
            raise self.fail(path, "give either `elements` (one layout) or `layouts` (alternatives), not both")
        if "layouts" in value:
            raw_layouts = {
                name: (item.get("elements") or {}, (*path, "layouts", name, "elements"))
                for name, item in value["layouts"].items()
            }
            if not raw_layouts:
                raise self.fail((*path, "layouts"), "give at least one layout")
        elif "elements" in value:
            raw_layouts = {"": (value["elements"], (*path, "elements"))}
        else:
            raise self.fail(path, "missing key 'elements' (or 'layouts')")
        transparency = value.get("transparency")
        alternatives: dict[Direction, list[FrameLayout]] = {d: [] for d in Direction}
        commands = self.section("commands")
        by_command = "layouts" in value and any(isinstance(c, dict) and "layout" in c for c in commands.values())
        refusing: list[FrameLayout] = []  # the error replies' layouts (`error_value`), after every other
        for layout_name, (raw, elements_path) in raw_layouts.items():
            elements = [
                (name, item, self.frame_element(name, item, (*elements_path, name))) for name, item in raw.items()
            ]
            for direction in Direction:
                request = alternatives[Direction.REQUEST][-1] if direction == Direction.RESPONSE else None
                alternatives[direction].append(
                    self.layout(direction, layout_name, elements, transparency, elements_path, path, request)
                )
            refusing += self.error_layout(raw, alternatives[Direction.RESPONSE][-1], elements_path, by_command)
        alternatives[Direction.RESPONSE] += refusing
        if not by_command:
            alternatives = {d: distinct_layouts(layouts) for d, layouts in alternatives.items()}
        for direction, layouts in alternatives.items():
            if len(layouts) > 1 and not by_command:
                headed = [layout.header for layout in layouts if layout.header]
                bare = [layout for layout in layouts if not layout.header]
                if (
                    len(set(headed)) != len(headed)
                    or len(bare) > 1
                    or any(not layout.elements or layout.elements[0].role != "command" for layout in bare)
                ):
                    raise self.fail(
                        (*path, "layouts"),
                        f"alternative {direction.value} layouts must start with different headers (one layout "
                        "without a header may stand beside them if it starts with its command element: it takes "
                        "the frames no header starts)",
                    )
                alternatives[direction] = self.carried_values(layouts, (*path, "layouts"))
                with_command = [layout.name for layout in layouts if layout.has_command]
                if with_command and len(with_command) != len(layouts):
                    without = [layout.name for layout in layouts if not layout.has_command]
                    raise self.fail(
                        (*path, "layouts"),
                        f"alternative layouts must all have a command element or none ({', '.join(with_command)} "
                        f"{'has' if len(with_command) == 1 else 'have'} one, {', '.join(without)} "
                        f"{'has' if len(without) == 1 else 'have'} none), unless each command names its layout "
                        "(`layout:`)",
                    )
        alternatives = distinct_checksum_functions(alternatives)
        first = {d: layouts[0] for d, layouts in alternatives.items()}
        checksums = first[Direction.REQUEST].checksums or first[Direction.RESPONSE].checksums
        return Framing(
            description=str(value.get("description", "")),
            layouts=first,
            checksum=checksums[0] if checksums else None,
            shared_header=first[Direction.REQUEST].header == first[Direction.RESPONSE].header,
            alternatives={d: tuple(layouts) for d, layouts in alternatives.items()},
            gap=self.seconds_or_characters(value, "gap", path),
            turnaround=self.seconds_or_characters(value, "turnaround", path),
            by_command=by_command,
        )

    def carried_values(self, layouts: list[FrameLayout], path: Path) -> list[FrameLayout]:
        """Alternative layouts told apart by their header may carry different frame values (the Pololu form's
        device number beside the compact form without one): every message of the direction carries each of them
        (`value_elements`, the union in order of first appearance), None where its frame's layout has no such element;
        an element of one name is the same value in every layout that has it."""
        union: dict[str, FrameElement] = {}
        for layout in layouts:
            for element in layout.value_elements:
                seen = union.setdefault(element.name, element)
                if (seen.role, seen.type, seen.minimum, seen.maximum) != (
                    element.role,
                    element.type,
                    element.minimum,
                    element.maximum,
                ):
                    raise self.fail(
                        path,
                        f"frame value {element.name} must be the same role, type and range in every layout that "
                        "carries it",
                    )
        values = tuple(union.values())
        if all(tuple(e.name for e in layout.value_elements) == tuple(union) for layout in layouts):
            return layouts  # the same values in every layout: each keeps its own elements
        return [replace(layout, value_elements=values) for layout in layouts]

    def seconds_or_characters(self, value: dict[str, Any], key: str, path: Path) -> float:
        """`gap` or `turnaround`: a time to wait, never negative (the grammar has checked it is a finite number)."""
        given = float(value.get(key, 0.0))
        if given < 0:
            raise self.fail((*path, key), f"expected a time of 0 or more, got {value[key]}")
        return given

    def error_layout(
        self, raw: dict[str, Any], response: FrameLayout, elements_path: Path, by_command: bool
    ) -> list[FrameLayout]:
        """The layout of replies that refuse their request, where the header has an `error_value`: the response
        layout under that header (MSP: `$M!` for `$M>`)."""
        found = [(name, item) for name, item in raw.items() if isinstance(item, dict) and "error_value" in item]
        if not found:
            return []
        name, item = found[0]
        path: Path = (*elements_path, name, "error_value")
        if item.get("role") != "header":
            raise self.fail(path, "`error_value` goes on the header element")
        if not response.elements or response.elements[0].name != name:
            raise self.fail(path, "the header with an `error_value` must be in the response frame")
        if by_command:
            raise self.fail(path, "an error header needs layouts told apart by their header, not chosen by command")
        if any("error_flag" in other for other in raw.values() if isinstance(other, dict)):
            raise self.fail(path, "give either the command element's `error_flag` or the header's `error_value`")
        try:
            constant = parse_hex(str(item["error_value"]))
        except ValueError as exc:
            raise self.fail(path, str(exc)) from None
        if len(constant) != len(response.header):
            raise self.fail(path, f"the error header has as many bytes as the response header ({len(response.header)})")
        if constant == response.header:
            raise self.fail(path, f"the error header must differ from the response header ({constant.hex(' ')})")
        if not response.has_command:
            raise self.fail(
                path, "an error header needs a command element in the response: it carries the refused code"
            )
        header = replace(response.elements[0], constant=constant)
        return [
            replace(
                response,
                header=constant,
                elements=(header, *response.elements[1:]),
                name=f"{response.name}_error" if response.name else "error",
                classic=False,
                error=True,
            )
        ]

    def frame_element(self, name: str, item: dict[str, Any], path: Path) -> FrameElement:
        """The element as declared (both directions); `layout` makes each direction's copy."""
        self.name(name, path, "frame element")
        role = item["role"]
        directions = tuple(Direction(d) for d in item.get("directions", ("request", "response")))
        endian: Literal["<", ">"] = ">" if item.get("endian") == "big" else "<"
        scalar: ScalarType | None = None
        size: int | None = None
        if role == "optional":
            if "value" in item:
                self.error((*path, "value"), "an optional element is sent by the message, not as constant bytes")
            if "type" in item:
                self.error((*path, "type"), "an optional element is bytes: give its `size`, no type")
            if "size" not in item or "present_if" not in item:
                raise self.fail(path, "an optional element needs `size` and `present_if`")
            size = item["size"]
            if not isinstance(size, int) or not 1 <= size <= 255:
                raise self.fail((*path, "size"), "an optional element's size is 1..255 bytes")
        elif role == "checksum" and item.get("type") == "u24":  # a 3-byte checksum (RTCM 3's CRC-24Q)
            scalar = self.scalar_type("u24", (*path, "type"), allow_float=False, for_field=True)
            size = scalar.size
        elif role not in CONSTANT_ROLES and role != "content":
            if item.get("type") == "u24":
                raise self.fail((*path, "type"), f"u24 is a checksum's type, not a {role}'s")
            digit = item.get("type") == "u4"  # one hex digit of a hex-ASCII span: a byte 0..15 in the plain bytes
            if digit and role in ("checksum", "length"):
                raise self.fail(
                    (*path, "type"), f"u4 is an address's, command's, status's or value's type, not a {role}'s"
                )
            scalar = (
                SCALARS["u8"] if digit else self.scalar_type(item.get("type", "u8"), (*path, "type"), allow_float=False)
            )
            size = scalar.size
        elif "type" in item:
            self.error((*path, "type"), f"a {role} has no type")
        if role in CONSTANT_ROLES and "value" not in item:
            raise self.fail(path, f"a {role} needs `value`: hex bytes, or a mapping by direction")
        low, high = (scalar.minimum, scalar.maximum) if scalar else (0.0, 0.0)
        if item.get("type") == "u4" and scalar:
            low, high = 0.0, 15.0
        wide = self.extended_type(item, role, scalar, path)  # a length's long form (`extended:`): its range's type
        if wide is not None:
            low, high = wide.minimum, wide.maximum
        if "range" in item and scalar:
            low, high = self.bounds(wide or scalar, False, item["range"], (*path, "range"))
            if item.get("type") == "u4" and not 0 <= low <= high <= 15:
                self.error((*path, "range"), f"range [{low:g}, {high:g}] does not fit u4 (0..15)")
        broadcast = item.get("broadcast")
        if broadcast is not None and scalar is not None and not scalar.minimum <= broadcast <= scalar.maximum:
            self.error((*path, "broadcast"), f"broadcast {broadcast} does not fit {scalar.name}")
        for key in ("bits", "flags"):  # only a value the messages carry shows its bits: elsewhere they would be lost
            if key in item and role not in VALUE_ROLES and role in ROLES:
                hint = (
                    " (a value in the command byte's low bits, MIDI style: leave out the command element and begin "
                    "each message with its code as a constant bit field, `kind: {type: u4, const: 0xE}`, then "
                    "`pin: u4`; see 'messages picked by their leading constant')"
                    if key == "bits" and role == "command"
                    else ""
                )
                self.error((*path, key), f"`{key}` belongs to an address, status or value element, not a {role}{hint}")
        bits: tuple[Any, ...] = ()
        bits_class = ""
        if "bits" in item and scalar is not None and role in VALUE_ROLES:
            common = {"name": name, "description": "", "description_cn": "", "inferred": ""}
            resolved = self.scalar(common, {"type": scalar.name, "bits": item["bits"]}, path, endian)
            bits, bits_class = resolved.bits, resolved.bits_class
        checksum = self.checksum(item, name, scalar, endian, path) if role == "checksum" and scalar else None
        ok = tuple(int(v) for v in item.get("ok") or ())
        if ok and "bits" in item:
            self.error((*path, "ok"), "`ok` compares the status as one number: give it without `bits`")
        for value in ok:
            if scalar is not None and not scalar.minimum <= value <= scalar.maximum:
                self.error((*path, "ok"), f"ok value {value} does not fit {scalar.name}")
        for key, allowed in (
            ("adds", "length"),
            ("counts", "length"),
            ("extended", "length"),
            ("covers", "checksum"),
            ("sequence", "value"),
            ("ok", "status"),
            ("truncate", "content"),
            ("from_request", "checksum"),
            ("encoding", "checksum"),
            ("size", "optional"),
            ("present_if", "optional"),
            ("code", "command"),
        ):
            if key in item and role != allowed and role in ROLES:  # an unknown role is one mistake, said once
                article = "an" if allowed[0] in "aeiou" else "a"
                self.error((*path, key), f"`{key}` belongs to {article} {allowed} element")
        return FrameElement(
            name=name,
            role=role,
            type=scalar,
            size=size,
            directions=directions,
            description=str(item.get("description", "")),
            minimum=low,
            maximum=high,
            broadcast=item.get("broadcast"),
            flags=self.reference("flags", self.flags, item.get("flags"), (*path, "flags")),
            sequence=bool(item.get("sequence", False)),
            ok=ok,
            truncate=role == "content" and item.get("truncate") == "trailing_zeros",
            endian=endian,
            bits=bits,
            bits_class=bits_class,
            adds=int(item.get("adds", 0)),
            checksum=checksum,
            code=" ".join(str(item.get("code", "")).split()),
            digit=item.get("type") == "u4",
            extended=self.extended(item["extended"], wide, int(low), int(high), path) if wide is not None else None,
        )

    def extended_type(
        self, item: dict[str, Any], role: str, scalar: ScalarType | None, path: Path
    ) -> ScalarType | None:
        """The wider type of a length's long form (`extended:`), None without one (or on a mistake, said here)."""
        given = item.get("extended")
        if "extended" not in item or role != "length" or scalar is None:
            return None
        if scalar.name != "u8":
            self.error(
                (*path, "type"), f"an extended length is one byte unless it says more: type u8, not {scalar.name}"
            )
            return None
        wide = given.get("type") if isinstance(given, dict) else None  # (a malformed one: the grammar said so)
        return SCALARS[wide] if wide in SCALARS else SCALARS["u16"]

    def extended(self, given: Any, wide: ScalarType, low: int, high: int, path: Path) -> ExtendedLength | None:
        """The long form: its marker, size and the values each form holds (`adds` is the layout's, see layout());
        None for a malformed one (the grammar said what is wrong)."""
        if not isinstance(given, dict) or not isinstance(given.get("when"), int):
            return None
        marker = given["when"]
        short_low, short_high = low, min(high, 255)
        if short_low <= marker <= short_high:
            if marker == short_high:
                short_high -= 1
            elif marker == short_low:
                short_low += 1
            else:
                self.error(
                    (*path, "extended", "when"),
                    f"{marker} lies inside the one-byte form's values {short_low}..{short_high}: the marker must be "
                    "the lowest or highest of them, or outside them (narrow `range`)",
                )
        if short_low > short_high:
            self.error((*path, "range"), "the one-byte form holds no value of the range: drop `extended`")
        return ExtendedLength(marker, wide.size, 0, (short_low, short_high), (low, min(high, int(wide.maximum))))

    def checksum(
        self, item: dict[str, Any], name: str, scalar: ScalarType, endian: Literal["<", ">"], path: Path
    ) -> Checksum:
        if not item.get("covers"):
            raise self.fail(path, "a checksum needs `covers: [first, last]` (frame element names)")
        seven = item.get("encoding") == seven_bit.NAME  # the value sent 7 bits a byte (Kangaroo's CRC-14)
        bits = 7 * scalar.size if seven else 0
        try:
            algorithm = checksums.from_spec(
                item, scalar.size, scalar.name, lambda keys, message: self.error((*path, *keys), message), bits
            )
        except ChecksumProblem as problem:
            raise self.fail((*path, *problem.keys), problem.message) from None
        if seven:
            algorithm = SevenBitWire(algorithm, scalar.size)
        return Checksum(algorithm, "", "", scalar, endian, name)

    def digits(
        self,
        elements: list[FrameElement],
        digits: list[int],
        transparency: Transparency | None,
        t_first: int,
        elements_path: Path,
        framing_path: Path,
    ) -> Transparency:
        """The transparency whose transform sends the `u4` elements (indexes `digits`) as one digit each: they lie in
        its span before the content, after elements of fixed size (their plain offsets are then known)."""
        name = elements[digits[0]].name
        if transparency is None:
            raise self.fail(
                (*elements_path, name, "type"), "u4 is one hex digit: the element must lie in a hex_ascii span"
            )
        content = next((i for i, e in enumerate(elements) if e.role == "content"), len(elements))
        offsets = []
        for index in digits:
            if not t_first <= index < content:
                raise self.fail(
                    (*elements_path, elements[index].name, "type"),
                    "a u4 element (one hex digit) lies in the transparency span, before the content",
                )
            offsets.append(sum(e.size or 0 for e in elements[t_first:index]))
        t_last = next(i for i, e in enumerate(elements) if e.name == transparency.last)
        if any(e.role == "length" for e in elements[t_first : t_last + 1]):
            raise self.fail(
                (*elements_path, name, "type"), "a u4 element (one hex digit) and a length in one span: not supported"
            )
        taken = transparency.transform.with_digits(tuple(offsets))
        if isinstance(taken, str):
            raise self.fail((*framing_path, "transparency"), taken)
        return replace(transparency, transform=taken)

    def seeded(self, checksum: Checksum, elements: list[FrameElement], a: int, b: int, path: Path) -> Checksum:
        """A checksum with `seed: per_command`: its algorithm wrapped with each command's `checksum_seed`, found
        by the command's code at its fixed offset in the covered bytes."""
        found = [i for i in range(a, b + 1) if elements[i].role == "command"]
        if not found:
            raise self.fail(path, "a per-command seed needs the command element inside the covered span")
        before = elements[a : found[0]]
        if any(e.role in ("content", "checksum") or e.size is None for e in before):
            raise self.fail(path, "a per-command seed needs elements of fixed size before the command element")
        command = elements[found[0]]
        assert command.size is not None
        seeds: dict[int, int] = {}
        for name, raw in self.section("commands").items():
            if not isinstance(raw, dict) or not isinstance(raw.get("code"), int):
                continue
            seed = raw.get("checksum_seed")
            if seed is None and not any(p.message.endswith("give `checksum_seed`") for p in self.problems):
                self.error(("commands", name), f"`seed: per_command` on {checksum.name}: give `checksum_seed`")
            elif isinstance(seed, int) and raw["code"] in seeds and seeds[raw["code"]] != seed:
                self.error(("commands", name, "checksum_seed"), f"code {raw['code']} has another seed already")
            elif isinstance(seed, int):
                seeds[raw["code"]] = seed
        offset = sum(e.size or 0 for e in before)
        algorithm = Seeded(
            checksum.algorithm, offset, command.size, command.endian == "<", tuple(sorted(seeds.items()))
        )
        return replace(checksum, algorithm=algorithm)

    def span(
        self, raw: Any, direction: Direction, names: list[str], path: Path, default: tuple[str, str] | None = None
    ) -> tuple[str, str]:
        """A `[first, last]` span, or a mapping direction -> span, checked against this direction's elements."""
        if raw is None:
            if default is None:
                raise self.fail(path, "missing span: give [first, last] frame element names")
            return default
        if isinstance(raw, dict):
            if direction.value not in raw:
                raise self.fail(path, f"no span given for {direction.value}")
            raw, path = raw[direction.value], (*path, direction.value)
        if not isinstance(raw, list) or len(raw) != 2 or not all(isinstance(n, str) for n in raw):
            raise self.fail(path, "expected [first, last]: two frame element names")
        for name in raw:
            if name not in names:
                raise self.fail(
                    path, f"unknown frame element {name!r} in the {direction.value} frame (it has {', '.join(names)})"
                )
        if names.index(raw[0]) > names.index(raw[1]):
            raise self.fail(path, f"{raw[0]!r} comes after {raw[1]!r}")
        return raw[0], raw[1]

    def layout(
        self,
        direction: Direction,
        layout_name: str,
        declared: list[tuple[str, dict[str, Any], FrameElement]],
        transparency_raw: Any,
        elements_path: Path,
        framing_path: Path,
        request: FrameLayout | None = None,
    ) -> FrameLayout:
        elements: list[FrameElement] = []
        raws: dict[str, dict[str, Any]] = {}
        for name, item, element in declared:
            if direction not in element.directions:
                continue
            raws[name] = item
            value = item.get("value")
            text = value if isinstance(value, str) else value.get(direction.value) if isinstance(value, dict) else None
            if text is None and element.role in CONSTANT_ROLES:
                raise self.fail((*elements_path, name, "value"), f"no {element.role} given for {direction.value}")
            if text is not None:
                try:
                    constant = parse_hex(text)
                    if not constant:
                        raise ValueError(f"a {element.role} needs at least one byte")
                except ValueError as exc:
                    raise self.fail((*elements_path, name, "value"), str(exc)) from None
                role = element.role if element.role in CONSTANT_ROLES else "constant"
                element = replace(element, role=role, constant=constant, size=len(constant), type=None)
            elements.append(element)
        names = [e.name for e in elements]
        roles = [e.role for e in elements]
        where = f"the {direction.value} frame" + (f" of layout {layout_name!r}" if layout_name else "")
        if not elements:
            raise self.fail(elements_path, f"{where} has no elements")
        for role in ("content", "command", "length"):
            if roles.count(role) > 1:
                raise self.fail(elements_path, f"{where} has more than one {role} element")
        if "header" in roles[1:]:
            raise self.fail(elements_path, f"a header must be the first element of {where}")
        if "trailer" in roles[:-1]:
            raise self.fail(elements_path, f"a trailer must be the last element of {where}")
        content_index = roles.index("content") if "content" in roles else -1
        # transparency
        transparency = None
        if transparency_raw is not None:
            t_path: Path = (*framing_path, "transparency")
            first, last = self.span(transparency_raw.get("span"), direction, names, (*t_path, "span"))
            try:
                transform = transforms.from_spec(
                    transparency_raw, lambda keys, message: self.error((*t_path, *keys), message)
                )
            except TransformProblem as problem:
                raise self.fail((*t_path, *problem.keys), problem.message) from None
            if not names.index(first) <= content_index <= names.index(last):
                raise self.fail((*t_path, "span"), "the transparency span must hold the content")
            constants = [e.constant for e in elements]
            refused = transform.check_layout(roles, constants, names.index(first), names.index(last))
            if refused:
                raise self.fail(t_path, refused)
            transparency = Transparency(first, last, transform, str(transparency_raw.get("description", "")))
        t_first, t_last = (
            (names.index(transparency.first), names.index(transparency.last)) if transparency else (-1, -1)
        )
        digits = [i for i, e in enumerate(elements) if e.digit]
        if digits:
            transparency = self.digits(elements, digits, transparency, t_first, elements_path, framing_path)

        def overlaps_badly(a: int, b: int) -> bool:
            inside = t_first <= a and b <= t_last
            holds = a <= t_first and t_last <= b
            apart = b < t_first or a > t_last
            return transparency is not None and not (inside or holds or apart)

        # lengths and checksums: their spans
        for index, element in enumerate(elements):
            item = raws[element.name]
            e_path: Path = (*elements_path, element.name)
            if element.role == "length":
                default = (names[content_index], names[content_index]) if content_index >= 0 else None
                counts = self.span(item.get("counts"), direction, names, (*e_path, "counts"), default)
                a, b = names.index(counts[0]), names.index(counts[1])
                before = elements[a:index]  # elements of fixed size before it that it counts too, and itself
                if (
                    a <= index < b
                    and element.type is not None
                    and all(e.size is not None for e in before)
                    and not (transparency and before and t_first <= index)
                ):
                    # a length that counts itself (LX-16A, Hiwonder: N parameters + 3), or from an element before it
                    # (Benewake TFmini Plus: the whole frame, from its header), is one that counts from the next
                    # element and adds the size of those
                    fixed = sum(e.size or 0 for e in before) + element.type.size
                    a, counts = index + 1, (names[index + 1], counts[1])
                    element = replace(element, adds=element.adds + fixed)
                    if element.extended is not None:  # it counts its wider bytes too in the long form
                        grown = element.adds + element.extended.size
                        element = replace(element, extended=replace(element.extended, adds=grown))
                elif element.extended is not None:
                    element = replace(element, extended=replace(element.extended, adds=element.adds))
                if element.extended is not None:
                    self.extended_place(elements, index, content_index, transparency, e_path)
                if index >= a or (transparency and index > t_last):
                    raise self.fail(e_path, "the length must come before what it counts (and before the span's end)")
                within = transparency is not None and t_first <= a and b <= t_last  # it counts plain bytes
                if transparency and t_first <= index and not within:
                    raise self.fail(
                        (*e_path, "counts"), "a length inside the transparency span counts elements inside it"
                    )
                if within and not a <= content_index <= b:
                    raise self.fail(
                        (*e_path, "counts"), "a length of bytes inside the transparency span counts the content"
                    )
                if overlaps_badly(a, b):
                    raise self.fail((*e_path, "counts"), "the counted span must hold the transparency span or miss it")
                elements[index] = replace(element, counts=counts)
            elif element.role == "checksum" and element.checksum is not None:
                covers = self.span(item.get("covers"), direction, names, (*e_path, "covers"))
                a, b = names.index(covers[0]), names.index(covers[1])
                if index in (a, b):
                    raise self.fail((*e_path, "covers"), "a checksum cannot begin or end the span it covers")
                if transparency and t_first <= index <= t_last and not (t_first <= a and b <= t_last):
                    raise self.fail(
                        (*e_path, "covers"),
                        "a checksum inside the transparency span covers elements inside it (their plain bytes)",
                    )
                if overlaps_badly(a, b):
                    raise self.fail((*e_path, "covers"), "the covered span must hold the transparency span or miss it")
                # checksums strictly inside the span (itself too) are left out of it; one at an end is covered
                skips = tuple(names[i] for i in range(a + 1, b) if elements[i].role == "checksum")
                if skips and transparency and not (b < t_first or a > t_last):
                    raise self.fail(
                        (*e_path, "covers"), "a span that leaves out checksums cannot overlap the transparency span"
                    )
                for end in {a, b}:
                    if elements[end].role == "checksum" and end > index:
                        raise self.fail(
                            (*e_path, "covers"), f"a checksum covering {names[end]} must come after it in the frame"
                        )
                checksum = replace(element.checksum, first=covers[0], last=covers[1], skips=skips)
                if item.get("seed") == "per_command":
                    checksum = self.seeded(checksum, elements, a, b, (*e_path, "seed"))
                if item.get("from_request"):
                    names_taken = self.from_request(item["from_request"], direction, request, (*e_path, "from_request"))
                    checksum = replace(checksum, from_request=names_taken)
                elements[index] = replace(element, checksum=checksum)
        checksums = tuple(e.checksum for e in elements if e.checksum is not None)
        for index, element in enumerate(elements):
            if element.role == "optional":
                elements[index] = self.optional(elements, index, raws[element.name], transparency, elements_path)
        if content_index >= 0 and elements[content_index].truncate and "length" not in roles:
            raise self.fail(
                (*elements_path, names[content_index], "truncate"),
                "a truncated content needs a length element: the frame must say how much of it was sent",
            )
        flagged = any("error_flag" in item or "error_bits" in item for item in raws.values())
        return self.classic_fields(direction, layout_name, tuple(elements), transparency, checksums, flagged)

    def extended_place(
        self,
        elements: list[FrameElement],
        index: int,
        content_index: int,
        transparency: Transparency | None,
        path: Path,
    ) -> None:
        """An extended length lies at a fixed offset, before the content and outside any transparency span (its
        marker tells the long form at that offset), in a layout without optional elements."""
        t_first = elements.index(next(e for e in elements if e.name == transparency.first)) if transparency else -1
        if (transparency is not None and index >= t_first) or 0 <= content_index < index:
            raise self.fail(
                (*path, "extended"), "an extended length comes before the content and any transparency span"
            )
        if any(e.role == "optional" for e in elements):
            raise self.fail((*path, "extended"), "an extended length in a layout with optional elements: not supported")

    def optional(
        self,
        elements: list[FrameElement],
        index: int,
        item: dict[str, Any],
        transparency: Transparency | None,
        elements_path: Path,
    ) -> FrameElement:
        """An optional element's `present_if: <element> & <mask>`, checked against this direction's elements: a flag
        element of fixed position before anything variable, the element itself outside every span."""
        element = elements[index]
        path: Path = (*elements_path, element.name, "present_if")
        names = [e.name for e in elements]
        try:
            parsed = expression.parse(str(item["present_if"]))
        except expression.ExpressionError as exc:
            raise self.fail(path, str(exc)) from None
        match parsed:
            case expression.BinOp("&", expression.Name(flag), expression.Const(mask)) if mask > 0:
                pass
            case _:
                raise self.fail(path, "expected `<element> & <mask>`: an earlier element and a positive mask")
        if flag not in names[:index]:
            raise self.fail(path, f"{flag!r} is no element before {element.name!r} in the frame")
        flagged = elements[names.index(flag)]
        if flagged.role not in ("constant", "value", "address", "status") or flagged.present_if[0]:
            raise self.fail(path, f"{flag!r} is a {flagged.role}: the flag is a constant, value, address or status")
        variable = [i for i, e in enumerate(elements) if e.role in ("content", "optional") or e.size is None]
        if transparency is not None:
            variable.append(names.index(transparency.first))
        if variable and names.index(flag) > min(variable):
            raise self.fail(path, f"{flag!r} must come before the content (and before any other optional element)")
        assert flagged.size is not None
        if mask & (mask - 1):
            raise self.fail(path, f"mask {mask:#x} has more than one bit: give the one bit that marks the element")
        if transparency is not None and index <= names.index(transparency.last):
            raise self.fail(path, "an optional element comes after the transparency span")
        if mask >= 1 << (8 * flagged.size):
            raise self.fail(path, f"mask {mask:#x} does not fit {flag!r} ({flagged.size} byte(s))")
        if flagged.role == "constant":
            value = int.from_bytes(flagged.constant, "big" if flagged.endian == ">" else "little")
            if value & mask:
                raise self.fail(
                    path, f"{flag!r} is {flagged.constant.hex(' ')}: its constant has the mask's bits clear"
                )
        for other in elements:
            spans = [other.counts] if other.role == "length" else []
            spans += [(other.checksum.first, other.checksum.last)] if other.checksum is not None else []
            spans += [(transparency.first, transparency.last)] if transparency is not None else []
            for first, last in spans:
                if first and names.index(first) <= index <= names.index(last):
                    raise self.fail(
                        path, f"an optional element lies outside every span ({other.name} takes in {element.name})"
                    )
        return replace(element, present_if=(flag, mask))

    def from_request(
        self, raw: list[str], direction: Direction, request: FrameLayout | None, path: Path
    ) -> tuple[str, ...]:
        """A reply checksum's `from_request`: elements of fixed size of the same layout's request frame."""
        if direction != Direction.RESPONSE or request is None:
            raise self.fail(path, "`from_request` belongs to a checksum of response frames")
        sizes = {e.name: e.size for e in request.elements if e.role != "content"}
        for index, name in enumerate(raw):
            if name not in sizes:
                names = ", ".join(e.name for e in request.elements if e.role != "content") or "none"
                raise self.fail(
                    (*path, index), f"{name!r} is no element of fixed size of the request frame (it has {names})"
                )
        return tuple(raw)

    def classic_fields(
        self,
        direction: Direction,
        layout_name: str,
        elements: tuple[FrameElement, ...],
        transparency: Transparency | None,
        checksums: tuple[Checksum, ...],
        error_flag: bool = False,
    ) -> FrameLayout:
        roles = [e.role for e in elements]
        names = [e.name for e in elements]
        content_index = roles.index("content") if "content" in roles else len(elements)
        length = next((e for e in elements if e.role == "length"), None)
        final = elements[-1] if elements else None  # none: an error said so already
        classic = (
            not layout_name
            and not any(c.from_request for c in checksums)
            and not any(e.truncate for e in elements)  # contents of one size sent shorter: the frame engine's way
            and not error_flag  # error replies carry code | flag: no constant command byte to look frames up by
            and transparency is None
            and set(roles) <= _CLASSIC_ROLES
            and roles.count("header") == 1
            and roles[0] == "header"
            and "content" in roles
            and length is not None
            and length.size == 1
            and length.extended is None
            and length.counts == (names[content_index], names[content_index])
            and roles.index("length") < content_index
            and len(checksums) == 1
            and final is not None
            and final.role == "checksum"
            and (final.size == 1 or final.endian == "<")
            and names.index(checksums[0].first) <= content_index <= names.index(checksums[0].last)
            and all((e.size or 0) <= 1 or e.endian == "<" for e in elements)
            # the classic stream format keys frames by a one-byte code (SBP's u16 message type: the frame engine)
            and all(e.size == 1 for e in elements if e.role == "command")
            # constant bit fields in a value (a sync nibble): the general engine checks them (Element.need)
            and not any(fixed_bits(e.bits)[0] for e in elements)
        )
        offsets: dict[str, int] = {}
        position = 0
        for element in elements[:content_index]:
            offsets[element.name] = position
            position += element.size or 0
        if content_index < len(elements):
            offsets[elements[content_index].name] = position
        overhead = sum(e.size or 0 for e in elements)
        covered_from = covered_to_end = 0
        if checksums and checksums[0].first in offsets:
            covered_from = offsets[checksums[0].first]
            covered_to_end = sum(e.size or 0 for e in elements[names.index(checksums[0].last) + 1 :])
        return FrameLayout(
            direction=direction,
            header=elements[0].constant if roles and roles[0] == "header" else b"",
            elements=elements,
            offsets=offsets,
            overhead=overhead,
            length_offset=offsets.get(length.name, -1) if length else -1,
            length_adds=length.adds if length else 0,
            command_offset=offsets.get(names[roles.index("command")]) if "command" in roles else None,
            checksum_offset_from_end=final.size or 1 if final is not None and final.role == "checksum" else 0,
            covered_from=covered_from,
            covered_to_end=covered_to_end,
            value_elements=tuple(e for e in elements if e.role in VALUE_ROLES),
            name=layout_name,
            transparency=transparency,
            checksums=checksums,
            classic=classic,
        )


def distinct_layouts(layouts: list[FrameLayout]) -> list[FrameLayout]:
    """A direction's layouts, each kept once where alternatives are the same in that direction (the Maestro's
    compact and Pololu forms differ in requests only: their replies are one layout)."""
    kept: list[FrameLayout] = []
    for layout in layouts:
        if not any(_in_direction(k) == _in_direction(layout) and k.transparency == layout.transparency for k in kept):
            kept.append(layout)
    return kept


def _in_direction(layout: FrameLayout) -> tuple[FrameElement, ...]:
    """A layout's elements as its direction sees them: which other directions an element is in does not matter
    (Pixy2: the checksum of responses only, beside one that requests with a checksum have too)."""
    return tuple(replace(e, directions=()) for e in layout.elements)


def distinct_checksum_functions(alternatives: dict[Direction, list[FrameLayout]]) -> dict[Direction, list[FrameLayout]]:
    """The layouts with each checksum's `function` named where alternative layouts hold different algorithms under
    one element name: `<element>_<layout>`, so that each layout's frames are checked with their own algorithm."""
    algorithms: dict[str, set[object]] = {}
    for layouts in alternatives.values():
        for layout in layouts:
            for checksum in layout.checksums:
                algorithms.setdefault(checksum.name, set()).add(checksum.algorithm)
    shared = {name for name, found in algorithms.items() if len(found) > 1}
    if not shared:
        return alternatives

    def named(layout: FrameLayout, checksum: Checksum) -> Checksum:
        return replace(checksum, function=f"{checksum.name}_{layout.name}") if checksum.name in shared else checksum

    return {
        direction: [
            replace(
                layout,
                elements=tuple(
                    replace(e, checksum=named(layout, e.checksum)) if e.checksum is not None else e
                    for e in layout.elements
                ),
                checksums=tuple(named(layout, c) for c in layout.checksums),
            )
            for layout in layouts
        ]
        for direction, layouts in alternatives.items()
    }
