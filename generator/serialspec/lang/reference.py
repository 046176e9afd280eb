"""The spec language's reference, generated from the grammar: every key with its meaning, type, default and an
example taken from real specs. A key described in grammar.py is documented here (and in the JSON Schema) at once.
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Sequence
from typing import Any

from serialspec.lang import grammar
from serialspec.lang.frozen import frozen
from serialspec.lang.grammar import Any_, Bool, Int, ListOf, MapOf, Num, Obj, OneOf, Ref, Shape, Str

NAME = "<name>"  # a key the spec author chooses (a command's name, a field's name)


@frozen
class Key:
    path: tuple[str, ...]  # from the spec's top level; NAME where the author chooses the key
    shape: Shape
    description: str
    required: bool


def keys(shape: Shape = grammar.SPEC, path: tuple[str, ...] = ()) -> Iterator[Key]:
    """Every key of the language, depth first, in the grammar's order; a shape used in several places is walked in
    each (its keys are the same; the reference documents them once)."""
    if isinstance(shape, Obj):
        for name, child in shape.keys.items():
            yield Key((*path, name), child, child.description, name in shape.required)
            yield from keys(child, (*path, name))
    elif isinstance(shape, MapOf):
        yield Key((*path, NAME), shape.value, grammar.value_description(shape.value, _scalar_parent(shape)), False)
        yield from keys(shape.value, (*path, NAME))
    elif isinstance(shape, ListOf):
        yield from keys(shape.item, path)
    elif isinstance(shape, OneOf):
        for option in shape.options:
            yield from keys(option, path)


def _scalar_parent(shape: MapOf) -> str:
    """A map of plain values (`Label -> wire value.`) is described by the map; a map of mappings is not."""
    return shape.description if isinstance(shape.value, Str | Int | Num | Bool | Any_ | OneOf) else ""


def undocumented() -> list[str]:
    """Keys of the language that have no description (the test wants none)."""
    return sorted({dotted(k.path) for k in keys() if not k.description.strip()})


def dotted(path: Sequence[str]) -> str:
    return ".".join(path)


def type_text(shape: Shape) -> str:
    if isinstance(shape, Str):
        return "one of " + ", ".join(f"`{c}`" for c in shape.choices) if shape.choices else "text"
    if isinstance(shape, Int):
        return "integer"
    if isinstance(shape, Num):
        return "one of " + ", ".join(f"`{c:g}`" for c in shape.choices) if shape.choices else "number"
    if isinstance(shape, Bool):
        return "true or false"
    if isinstance(shape, ListOf):
        count = f"{shape.length} × " if shape.length else ""
        return f"list of {count}{type_text(shape.item)}"
    if isinstance(shape, MapOf):
        return f"mapping: name → {type_text(shape.value)}"
    if isinstance(shape, Obj):
        return "mapping"
    if isinstance(shape, OneOf):
        return " or ".join(type_text(option) for option in shape.options)
    if isinstance(shape, Ref):
        return f"mapping: name → field (as in `{shape.name}:`)"
    return "any value"


# --- examples from real specs ---------------------------------------------------------------------------------------


def find_example(path: tuple[str, ...], specs: Sequence[Any]) -> Any:
    """The first value at `path` (NAME matching any key) in the specs' data, or None."""
    for data in specs:
        found = _find(data, path)
        if found is not None:
            return found
    return None


def _find(data: Any, path: tuple[str, ...]) -> Any:
    if not path:
        return data
    if not isinstance(data, dict):
        if isinstance(data, list):
            return next((v for item in data if (v := _find(item, path)) is not None), None)
        return None
    head, rest = path[0], path[1:]
    if head == NAME:
        return next((v for value in data.values() if (v := _find(value, rest)) is not None), None)
    return _find(data[head], rest) if head in data else None


def inline(value: Any, limit: int = 70) -> str:
    """A value as a short one-line YAML flow value."""
    text = _flow(value)
    return text if len(text) <= limit else text[: limit - 1].rstrip() + "…"


def _flow(value: Any) -> str:
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_flow(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list):
        return "[" + ", ".join(_flow(v) for v in value) + "]"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        plain = value and not any(c in value for c in ":#{}[],&*!|>'\"%@`") and value.strip() == value
        return value if plain and not value[0].isdigit() else json.dumps(value, ensure_ascii=False)
    return str(value)


# --- the page -------------------------------------------------------------------------------------------------------


def _anchor(path: Sequence[str]) -> str:
    return "key-" + "-".join(p.replace(NAME, "name") for p in path) if path else "key-top"


def _sections(shape: Obj) -> list[tuple[tuple[str, ...], Obj]]:
    """Every distinct mapping shape with the first (shortest) path it appears at, in reading order."""
    seen: dict[int, tuple[str, ...]] = {}
    order: list[tuple[tuple[str, ...], Obj]] = []

    def walk(current: Shape, path: tuple[str, ...]) -> None:
        if isinstance(current, Obj):
            if id(current) in seen:
                return
            seen[id(current)] = path
            order.append((path, current))
            for name, child in current.keys.items():
                walk(child, (*path, name))
        elif isinstance(current, MapOf):
            walk(current.value, (*path, NAME))
        elif isinstance(current, ListOf):
            walk(current.item, path)
        elif isinstance(current, OneOf):
            for option in current.options:
                walk(option, path)

    walk(shape, ())
    return order


def _occurrences(
    shape: Shape, path: tuple[str, ...] = (), found: dict[int, list[tuple[str, ...]]] | None = None
) -> dict[int, list[tuple[str, ...]]]:
    """Every path each mapping shape appears at (a shared shape, such as a message, appears at several)."""
    found = {} if found is None else found
    if isinstance(shape, Obj):
        found.setdefault(id(shape), []).append(path)
        for name, child in shape.keys.items():
            _occurrences(child, (*path, name), found)
    elif isinstance(shape, MapOf):
        _occurrences(shape.value, (*path, NAME), found)
    elif isinstance(shape, ListOf):
        _occurrences(shape.item, path, found)
    elif isinstance(shape, OneOf):
        for option in shape.options:
            _occurrences(option, path, found)
    return found


def _example(paths: list[tuple[str, ...]], specs: Sequence[Any]) -> Any:
    """The first value at any of the paths a key appears at, in the specs."""
    return next((v for p in paths if (v := find_example(p, specs)) is not None), None)


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def reference_markdown(specs: Sequence[Any] = ()) -> str:
    """The language reference as markdown; `specs` (loaded spec data) supply the examples."""
    sections = _sections(grammar.SPEC)
    where = {id(shape): path for path, shape in sections}
    described = {k.path: k.description for k in keys()}
    occurrences = _occurrences(grammar.SPEC)
    lines = [
        "<!-- Generated by serialspec from the spec language's grammar; do not edit. -->",
        "# The spec language",
        "",
        "Every key a spec file may hold, generated from the grammar that checks spec files; the same descriptions "
        "are the JSON Schema's (`serialspec.schema.json`, which `serialspec generate` writes beside what it "
        "generates), which YAML editors show as hover help. `NAME` stands for a key you choose (a command's name, "
        "a field's name). Examples come from the shipped specs and the tutorial's `tinylamp.yaml`. New to "
        "serialspec? Start with the [tutorial](tutorial.md).",
        "",
        "The order of keys is meaningful where it is the wire's (fields, frame elements). YAML anchors and merge "
        "keys share definitions: `fields: {data: u32, <<: *telegram}` puts `data` first and the anchored "
        "`telegram` fields after it, where `<<` stands; a key given beside a merge that it holds too overrides the "
        "merged value in the merged key's place (`{<<: *station, message_number: {type: u12, const: 1006}}`).",
        "",
        "Contents: " + ", ".join(_contents(where)),
        "",
    ]
    for path, shape in sections:
        lines += [f'<a id="{_anchor(path)}"></a>', "", f"## {_title(path)}", ""]
        for text in dict.fromkeys(t for t in (described.get(path, ""), shape.description) if t):
            lines += [text, ""]
        lines += ["| key | type | required / default | meaning | example |", "| --- | --- | --- | --- | --- |"]
        for name, child in shape.keys.items():
            meaning = child.description
            target = _mapping_of(child)
            if target is not None and id(target) in where:
                meaning += f" See [{_title(where[id(target)])}](#{_anchor(where[id(target)])})."
            needed = "required" if name in shape.required else _default(child)
            example = _example([(*p, name) for p in occurrences[id(shape)]], specs)
            if example is None:
                example = getattr(child, "example", None)
            shown = f"`{inline(example)}`" if example is not None and target is None else ""
            lines.append(
                f"| `{name}` | {_cell(type_text(child))} | {needed} | {_cell(meaning)} | {_cell(shown) or '—'} |"
            )
        example = _example(occurrences[id(shape)], specs) if path else None
        if example is not None and isinstance(example, dict):
            lines += ["", "For example:", "", "```yaml", *_yaml_lines(path, example), "```"]
        for label, framing, worked in shape.variants:
            lines += ["", f"{label}:", "", "```yaml", *_yaml_lines(path[:-1], framing, 40), "```", "", worked]
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def _contents(where: dict[int, tuple[str, ...]]) -> list[str]:
    """A link to the section of every top-level key that holds mappings."""
    links = []
    for name, child in grammar.SPEC.keys.items():
        target = _mapping_of(child)
        if target is not None and id(target) in where:
            links.append(f"[{name}](#{_anchor(where[id(target)])})")
    return links


def _title(path: Sequence[str]) -> str:
    return ".".join(p.replace(NAME, "NAME") for p in path) if path else "the top level"


def _mapping_of(shape: Shape) -> Obj | None:
    """The mapping shape a key holds (directly, as a map's values or a list's items), for a link to its section."""
    if isinstance(shape, Obj):
        return shape
    if isinstance(shape, MapOf | ListOf):
        return _mapping_of(shape.value if isinstance(shape, MapOf) else shape.item)
    if isinstance(shape, OneOf):
        return next((m for option in shape.options if (m := _mapping_of(option)) is not None), None)
    return None


def _default(shape: Shape) -> str:
    default = getattr(shape, "default", None)
    return f"default `{_flow(default)}`" if default is not None else "optional"


def _yaml_lines(path: Sequence[str], example: dict[str, Any], limit: int = 16) -> list[str]:
    """The example as block YAML under its key (a NAME key shows as the name the spec chose), cut at `limit` lines."""
    import yaml

    name = path[-1] if path else ""
    shown: Any = {name: example} if name and name != NAME else example
    lines = yaml.safe_dump(shown, allow_unicode=True, sort_keys=False, width=100, default_flow_style=False).splitlines()
    return [*lines[:limit], "# ..."] if len(lines) > limit else lines
