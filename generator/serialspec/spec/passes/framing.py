"""The frame around every message: elements, their offsets in each direction, the checksum."""

from __future__ import annotations

from typing import Any

from serialspec.runtime.hexbytes import parse_hex
from serialspec.spec.errors import SpecError
from serialspec.spec.loader import Path
from serialspec.spec.model import (
    Checksum,
    Crc,
    Direction,
    FrameElement,
    FrameLayout,
    Framing,
    ScalarType,
)
from serialspec.spec.passes.base import Pass


class FramingPass(Pass):
    """Resolve `framing:` into a layout per direction."""

    def run(self) -> list[SpecError]:
        self.ctx.framing = self.guard(("framing",), self.framing, self.section("framing"), ("framing",))
        return self.problems

    def framing(self, value: dict[str, Any], path: Path) -> Framing:
        raw = value["elements"]
        elements: list[tuple[dict[str, Any], FrameElement]] = []
        checksum: Checksum | None = None
        headers: dict[Direction, bytes] = {}
        length_adds = 0
        for name, item in raw.items():
            item_path = (*path, "elements", name)
            self.name(name, item_path, "frame element")
            role = item["role"]
            directions = tuple(Direction(d) for d in item.get("directions", ("request", "response")))
            scalar = None
            size: int | None = None
            if role == "header":
                header_value = item.get("value")
                if header_value is None:
                    raise self.fail(item_path, "a header needs `value`: hex bytes, or a mapping by direction")
                for direction in directions:
                    text = header_value if isinstance(header_value, str) else header_value.get(direction.value)
                    if text is None:
                        raise self.fail((*item_path, "value"), f"no header given for {direction.value}")
                    try:
                        headers[direction] = parse_hex(text)
                        if not headers[direction]:
                            raise ValueError("a header needs at least one byte")
                    except ValueError as exc:
                        raise self.fail((*item_path, "value"), str(exc)) from None
                sizes = {len(headers[d]) for d in directions}
                if len(sizes) != 1:
                    raise self.fail((*item_path, "value"), "headers must have the same size in both directions")
                size = sizes.pop()
            elif role != "content":
                scalar = self.scalar_type(item.get("type", "u8"), (*item_path, "type"), allow_float=False)
                size = scalar.size
            if role == "length":
                length_adds = int(item.get("adds", 0))
            low, high = (scalar.minimum, scalar.maximum) if scalar else (0, 0)
            if "range" in item and scalar:
                low, high = self.bounds(scalar, False, item["range"], (*item_path, "range"))
            broadcast = item.get("broadcast")
            if broadcast is not None and scalar is not None and not scalar.minimum <= broadcast <= scalar.maximum:
                self.error((*item_path, "broadcast"), f"broadcast {broadcast} does not fit {scalar.name}")
            element = FrameElement(
                name=name,
                role=role,
                type=scalar,
                size=size,
                directions=directions,
                description=str(item.get("description", "")),
                minimum=low,
                maximum=high,
                broadcast=item.get("broadcast"),
                flags=self.reference("flags", self.flags, item.get("flags"), (*item_path, "flags")),
            )
            elements.append((item, element))
            if role == "checksum":
                assert scalar is not None
                checksum = self.checksum(item, name, scalar, item_path, list(raw))
        if checksum is None:
            raise self.fail((*path, "elements"), "framing needs one element with role checksum")
        layouts = {d: self.layout(d, headers, [e for _, e in elements], checksum, length_adds, path) for d in Direction}
        shared = headers.get(Direction.REQUEST) == headers.get(Direction.RESPONSE)
        return Framing(str(value.get("description", "")), layouts, checksum, shared)

    def checksum(self, item: dict[str, Any], name: str, scalar: ScalarType, path: Path, names: list[str]) -> Checksum:
        covers = item.get("covers")
        if not covers:
            raise self.fail(path, "a checksum needs `covers: [first, last]` (frame element names)")
        unknown = [covered for covered in covers if covered not in names]
        if unknown:
            raise self.fail(
                (*path, "covers"),
                f"unknown frame element {unknown[0]!r} (expected one of {', '.join(names)})",
            )
        algorithm = item.get("algorithm")
        crc = None
        if algorithm == "crc":
            params = item.get("crc")
            if not params:
                raise self.fail(path, "algorithm crc needs `crc:` with width, poly, init, refin, refout, xorout, check")
            crc = Crc(
                str(params.get("name", "")),
                params["width"],
                params["poly"],
                params["init"],
                params["refin"],
                params["refout"],
                params["xorout"],
                params["check"],
            )
            if crc.width != scalar.size * 8:
                raise self.fail((*path, "crc", "width"), f"a {crc.width}-bit CRC does not fill a {scalar.name}")
            for key in ("poly", "init", "xorout", "check"):
                if not 0 <= params[key] < 1 << crc.width:
                    raise self.fail((*path, "crc", key), f"{key} {params[key]} does not fit {crc.width} bits")
            from serialspec.runtime.checksums import crc_function

            computed = crc_function(crc.width, crc.poly, crc.init, crc.refin, crc.refout, crc.xorout)(b"123456789")
            if computed != crc.check:
                self.error(
                    (*path, "crc", "check"),
                    f"these parameters give {computed:#x} for '123456789', not the check value {crc.check:#x}",
                )
        elif algorithm != "sum":
            raise self.fail(path, "a checksum needs `algorithm: sum` or `algorithm: crc`")
        return Checksum(algorithm, bool(item.get("invert", False)), crc, covers[0], covers[1], scalar)

    def layout(
        self,
        direction: Direction,
        headers: dict[Direction, bytes],
        all_elements: list[FrameElement],
        checksum: Checksum,
        length_adds: int,
        path: Path,
    ) -> FrameLayout:
        elements = tuple(e for e in all_elements if direction in e.directions)
        roles = [e.role for e in elements]
        for role in ("header", "length", "content", "checksum"):
            if roles.count(role) != 1:
                raise self.fail((*path, "elements"), f"the {direction.value} frame needs exactly one {role} element")
        if roles.count("command") > 1:
            raise self.fail((*path, "elements"), f"the {direction.value} frame has more than one command element")
        if roles[0] != "header":
            raise self.fail((*path, "elements"), "the frame must start with its header")
        offsets: dict[str, int] = {}
        position = 0
        content_index = roles.index("content")
        for element in elements[:content_index]:
            offsets[element.name] = position
            position += element.size or 0
        offsets[elements[content_index].name] = position
        after = sum(e.size or 0 for e in elements[content_index + 1 :])
        overhead = position + after
        names = [e.name for e in elements]
        if checksum.first not in names or checksum.last not in names:
            raise self.fail(
                (*path, "elements"),
                f"the checksum covers an element missing from the {direction.value} frame",
            )
        last_index = names.index(checksum.last)
        covered_to_end = sum(e.size or 0 for e in elements[last_index + 1 :])
        checksum_element = elements[roles.index("checksum")]
        if roles.index("checksum") != len(roles) - 1:
            raise self.fail((*path, "elements"), "the checksum must be the frame's last element")
        if names.index(checksum.first) > content_index or last_index < content_index:
            raise self.fail((*path, "elements"), "the checksum must cover the content")
        length_index = roles.index("length")
        if length_index > content_index:
            raise self.fail((*path, "elements"), "the length must come before the content")
        return FrameLayout(
            direction=direction,
            header=headers[direction],
            elements=elements,
            offsets=offsets,
            overhead=overhead,
            length_offset=offsets[elements[length_index].name],
            length_adds=length_adds,
            command_offset=offsets[elements[roles.index("command")].name] if "command" in roles else None,
            checksum_offset_from_end=checksum_element.size or 1,
            covered_from=offsets[checksum.first],
            covered_to_end=covered_to_end,
            value_elements=tuple(e for e in elements if e.role in ("address", "status")),
        )
