"""A protocol's C files, from the modules that write them: the one module of the C target that imports the others
(emit.py the shared parts, files.py the header, source and JSON, readme.py, vectors.py, text.py for a text protocol),
none of which imports it."""

from __future__ import annotations

import re

from serialspec.backends import Unsupported
from serialspec.backends.c import length_byte, text
from serialspec.backends.c.emit import Ctx, refuse_unsupported
from serialspec.backends.c.files import header, json_header, json_source, source
from serialspec.backends.c.optional import expanded
from serialspec.backends.c.readme import readme
from serialspec.backends.c.vectors import check_vectors, vectors_header
from serialspec.backends.common.frames import refuse_code_forms, refuse_partial_values
from serialspec.lang.model import Protocol

# The names a header defines: its macros, and the constants of its enums (`enum { P_MODE_SLOW = 0, P_MODE_FAST }`)
_MACRO = re.compile(r"^#define (\w+)", re.MULTILINE)
_ENUM = re.compile(r"\benum\s*\w*\s*\{([^}]*)\}")
_COMMENT = re.compile(r"/\*.*?\*/", re.DOTALL)
_CONSTANT = re.compile(r"\s*(\w+)")


def files(protocol: Protocol) -> dict[str, str]:
    made = _files(protocol)
    for name, body in made.items():
        if name.endswith(".h"):
            refuse_clashing_names(body)
    return made


def refuse_clashing_names(header_text: str) -> None:
    """Spec names make C names (enum `role`'s value `host` is P_ROLE_HOST, command `move`'s request P_MOVE_REQUEST):
    two alike, one of them perhaps the target's own (P_ROLE_HOST, P_E_RANGE, a capacity's P_..._MAX), would not
    compile. The target refuses such a spec naming the C name; renaming one of the spec's names fixes it."""
    names = _MACRO.findall(header_text)
    for body in _ENUM.findall(_COMMENT.sub("", header_text)):
        names += [found[1] for item in body.split(",") if (found := _CONSTANT.match(item))]
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise Unsupported(f"two spec names make the one C name {name}: rename one of them")
        seen.add(name)


def _files(protocol: Protocol) -> dict[str, str]:
    if protocol.text is not None:  # a text protocol: backends/c/text.py
        return text.files(protocol, protocol.text)
    refuse_unsupported(protocol)
    refuse_code_forms(protocol, length_byte.applies(protocol))  # (emit.py: length_byte imports it)
    refuse_partial_values(protocol)

    spec = protocol
    protocol, variants = expanded(spec)  # optional elements: each layout's plain variants in its place
    ctx = Ctx(protocol, protocol.name, protocol.name.upper(), original=spec if protocol is not spec else None)
    ctx.variants = variants
    for layouts in protocol.framing.alternatives.values():  # the checksums first: the header declares them
        for layout in layouts:
            for e in layout.elements:
                if e.checksum is not None:
                    ctx.check_index(e.checksum)

    p = protocol.name
    h = header(ctx)
    c = source(ctx)
    return {
        f"{p}/{p}.h": h,
        f"{p}/{p}.c": c,
        f"{p}/{p}_json.h": json_header(ctx),
        f"{p}/{p}_json.c": json_source(ctx),
        f"{p}/README.md": readme(ctx),
        f"{p}/test/vectors.h": vectors_header(ctx),
        f"{p}/test/check_vectors.c": check_vectors(ctx),
    }
