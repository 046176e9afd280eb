"""Load YAML safely into plain Python values while remembering where each value came from.

PyYAML's safe loader forgets positions and silently keeps the last of duplicate keys; both matter for people
reading error messages, so we compose the node graph ourselves and convert it. Composition runs in libyaml
(`CSafeLoader`, about ten times faster, with the same line and column in every node's marks) when PyYAML was built
with it, in pure Python otherwise; a YAML syntax error is reported by the pure-Python loader either way, so the
message does not depend on how PyYAML was built.
"""

from __future__ import annotations

import re
from dataclasses import field
from typing import Any

import yaml

from serialspec.collection import without_cycle_collection
from serialspec.lang.errors import SpecError, SpecErrors
from serialspec.lang.frozen import mutable
from serialspec.lang.limits import MAX_SPEC_BYTES, read_spec

Path = tuple[str | int, ...]


@mutable
class Located:
    """A loaded document plus the (line, column) of every value, by path from the root."""

    file: str
    data: Any
    marks: dict[Path, tuple[int, int]] = field(default_factory=dict)
    key_marks: dict[Path, tuple[int, int]] = field(default_factory=dict)
    # `load_text(..., keep_going=True)`: the loader's mistakes in a document it could still read (a key dropped, a
    # value left out), which `resolve` reports beside its own (but none at or around their paths)
    problems: list[SpecError] = field(default_factory=list)

    def where(self, path: Path) -> tuple[int, int]:
        """The position of the value at path, or of its nearest located ancestor."""
        while path not in self.marks and path:
            path = path[:-1]
        return self.marks.get(path, (1, 1))

    def error(self, path: Path, message: str) -> SpecError:
        line, column = self.where(path)
        return SpecError(self.file, line, column, dotted(path), message)


def dotted(path: Path) -> str:
    text = ".".join(f"[{p}]" if isinstance(p, int) else p for p in path).replace(".[", "[")
    return "".join(c if c.isprintable() else f"\\x{ord(c):02x}" for c in text)  # error lines stay one plain line


# Builds scalars only (the YAML 1.1 rules of the safe loader); mappings and lists are walked by _convert.
_CONSTRUCTOR = yaml.SafeLoader("")
_COMPOSER: type[yaml.SafeLoader] = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_STR = "tag:yaml.org,2002:str"
_MERGE = "tag:yaml.org,2002:merge"
_ScalarNode = yaml.ScalarNode
# The safe loader's constructor of each scalar tag, called directly: construct_object's bookkeeping (recursion
# guard, a cache of every node built) is for mappings and lists, which _convert walks itself.
_SCALARS: dict[str, Any] = {
    f"tag:yaml.org,2002:{kind}": yaml.SafeLoader.yaml_constructors[f"tag:yaml.org,2002:{kind}"]
    for kind in ("null", "bool", "int", "float", "binary", "timestamp")
}


def _position(node: yaml.Node) -> tuple[int, int]:
    return node.start_mark.line + 1, node.start_mark.column + 1


# Limits that keep a hostile file from taking the generator down: how deep values nest, and how many values the
# aliases of a file may expand to (beyond the values it holds: a "billion laughs" file expands to 10^9).
MAX_DEPTH = 64
EXPANSION_FACTOR = 4
EXPANSION_SLACK = 10_000
_PLAIN_TAGS = frozenset({"tag:yaml.org,2002:map", "tag:yaml.org,2002:seq"})
# Control characters (C0 but tab, newline, carriage return; DEL; C1) have no place in a spec's text, nor have the
# bidirectional embeddings, overrides and isolates, which make generated code read other than it runs (compilers
# refuse them unpaired in a comment: gcc's -Wbidi-chars).
CONTROL = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]")


def load_file(path: str, display_name: str | None = None, *, keep_going: bool = False) -> Located:
    file = display_name or path
    try:
        raw = read_spec(path)
    except IsADirectoryError:
        raise SpecErrors([SpecError(file, 1, 1, "", "is a folder, not a spec file")]) from None
    except OSError as exc:
        raise SpecErrors([SpecError(file, 1, 1, "", f"cannot read the spec: {exc.strerror or exc}")]) from None
    return load_text(decode_text(raw, file), file, keep_going=keep_going)


def decode_text(raw: bytes, file: str) -> str:
    """A spec file's bytes as text: within the size limit, UTF-8 (a byte order mark is allowed), and no NUL bytes
    (binary files)."""
    if len(raw) > MAX_SPEC_BYTES:
        message = f"the file is larger than {MAX_SPEC_BYTES:,} bytes, the most a spec may have"
        raise SpecErrors([SpecError(file, 1, 1, "", message)])
    if b"\x00" in raw:
        line, column = _line_column(raw, raw.index(b"\x00"))
        raise SpecErrors([SpecError(file, line, column, "", "a binary file (NUL bytes), not YAML text")])
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line, column = _line_column(raw, exc.start)
        byte = raw[exc.start]
        message = f"not UTF-8 text: byte {byte:#04x} cannot be decoded (save the spec as UTF-8)"
        raise SpecErrors([SpecError(file, line, column, "", message)]) from None


def _line_column(raw: bytes | str, offset: int) -> tuple[int, int]:
    before = raw[:offset]
    newline = b"\n" if isinstance(before, bytes) else "\n"
    return before.count(newline) + 1, offset - (before.rfind(newline) + 1) + 1  # type: ignore[arg-type]


@without_cycle_collection
def load_text(text: str, file: str, *, keep_going: bool = False) -> Located:
    """The document with the position of every value; raises SpecErrors for a mistake in it, unless `keep_going` and
    the document is still a mapping: its mistakes are then `problems`, for `resolve` to report with its own."""
    located = Located(file, None)
    try:
        try:
            root = yaml.compose(text, Loader=_COMPOSER)
        except (yaml.YAMLError, RecursionError):
            # libyaml refused the file (or is not there, and the pure-Python composer ran out of stack): the error
            # as the pure-Python loader words it. That composer recurses once per level, so the depth is measured
            # from the parse events first, iteratively: the same message, path included, whatever PyYAML build or
            # recursion limit a machine has.
            _refuse_deep_nesting(text, file)
            root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, column = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        problem = exc.problem or exc.context or "invalid YAML"
        raise SpecErrors([SpecError(file, line, column, "", f"YAML syntax error: {problem}")]) from None
    except yaml.reader.ReaderError as exc:
        line, column = _line_column(text, exc.position)
        problem = f"character U+{exc.character:04X} is not allowed in YAML"
        raise SpecErrors([SpecError(file, line, column, "", problem)]) from None
    except RecursionError:
        message = f"values nested too deeply (more than {MAX_DEPTH} levels)"
        raise SpecErrors([SpecError(file, 1, 1, "", message)]) from None
    if root is None:
        raise SpecErrors([SpecError(file, 1, 1, "", "empty spec (expected a mapping with protocol, framing, ...)")])
    errors: list[SpecError] = []
    located.data = _Converter(located, errors, root).convert(root, ())
    if errors and not (keep_going and isinstance(located.data, dict)):
        raise SpecErrors(errors)
    located.problems = errors
    return located


def _refuse_deep_nesting(text: str, file: str) -> None:
    """The first value nested deeper than MAX_DEPTH, refused as _Converter would (its position, path[:3])."""
    # One entry per open collection: a list's next index, or a mapping's next key (None while a key is due).
    open_: list[list[Any]] = []
    path: list[str | int] = []
    for event in yaml.parse(text, Loader=yaml.SafeLoader):
        if isinstance(event, yaml.CollectionEndEvent):
            open_.pop()
            if path:
                path.pop()
            continue
        if not isinstance(event, yaml.NodeEvent):
            continue
        element: str | int | None = None
        if open_:
            parent = open_[-1]
            if parent[0] == "seq":
                element = parent[1]
                parent[1] += 1
            elif parent[1] is None:  # a key: names the value that follows
                parent[1] = _scalar_value(event) if isinstance(event, yaml.ScalarEvent) else "?"
                if not isinstance(event, yaml.CollectionStartEvent):
                    continue
                element = "?"
            else:
                element, parent[1] = parent[1], None
        inner = path if element is None else [*path, element]
        if len(inner) > MAX_DEPTH:
            mark = event.start_mark  # the pure-Python parser marks every event
            line, column = (mark.line + 1, mark.column + 1) if mark else (1, 1)
            message = f"values nested too deeply (more than {MAX_DEPTH} levels)"
            raise SpecErrors([SpecError(file, line, column, dotted(tuple(inner[:3])), message)])
        if not isinstance(event, yaml.CollectionStartEvent):
            continue
        path = inner
        open_.append(["seq", 0] if isinstance(event, yaml.SequenceStartEvent) else ["map", None])


def _scalar_value(event: yaml.ScalarEvent) -> str | int:
    """A mapping key's value as the converter reads it (a name, or a number)."""
    tag = _CONSTRUCTOR.resolve(yaml.ScalarNode, event.value, event.implicit)  # type: ignore[no-untyped-call]
    if tag == _STR:
        return event.value
    try:
        value = _scalar(yaml.ScalarNode(tag, event.value))
    except (yaml.YAMLError, ValueError):
        return event.value
    return value if isinstance(value, int) and not isinstance(value, bool) else event.value


def _count_nodes(root: yaml.Node) -> int:
    """How many distinct nodes the file holds (aliases point at nodes already counted)."""
    seen: set[int] = set()
    stack = [root]
    while stack:
        node = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, yaml.MappingNode):
            stack.extend(n for pair in node.value for n in pair)
        elif isinstance(node, yaml.SequenceNode):
            stack.extend(node.value)
    return len(seen)


class _Expansion(Exception):
    """The aliases expand beyond the budget; its error is recorded."""


class _Converter:
    """Nodes to plain values, within the depth and expansion limits, refusing aliases that contain themselves."""

    def __init__(self, located: Located, errors: list[SpecError], root: yaml.Node) -> None:
        self.located = located
        self.errors = errors
        # Values converted may number EXPANSION_SLACK + EXPANSION_FACTOR * the distinct nodes: the nodes are counted
        # only once the slack is spent (a large file, or aliases), which most files never reach.
        self.budget = EXPANSION_SLACK
        self.root: yaml.Node | None = root
        self.open: set[int] = set()  # the nodes being converted (the current path)

    def fail(self, node: yaml.Node, path: Path, message: str) -> None:
        line, column = _position(node)
        self.errors.append(SpecError(self.located.file, line, column, dotted(path), message))

    def convert(self, node: yaml.Node, path: Path) -> Any:
        try:
            return self._convert(node, path)
        except _Expansion:
            return None

    def _merge(self, node: yaml.Node, path: Path) -> dict[Any, Any]:
        """The keys a YAML merge key (`<<`) brings in: one mapping, or a list of them (the first wins)."""
        sources = node.value if isinstance(node, yaml.SequenceNode) else [node]
        merged: dict[Any, Any] = {}
        for source in sources:
            if not isinstance(source, yaml.MappingNode):
                self.fail(source, path, "`<<` merges a mapping (`<<: *anchor`) or a list of them")
                continue
            value = self._convert(source, path)
            if isinstance(value, dict):
                merged = {**value, **merged}
        return merged

    def _convert(self, node: yaml.Node, path: Path) -> Any:
        located = self.located
        self.budget -= 1
        if self.budget < 0 and self.root is not None:
            self.budget += _count_nodes(self.root) * EXPANSION_FACTOR
            self.root = None
        if self.budget < 0:
            self.fail(node, path, "the YAML aliases expand to too many values (a YAML bomb?)")
            raise _Expansion
        if len(path) > MAX_DEPTH:
            self.fail(node, path[:3], f"values nested too deeply (more than {MAX_DEPTH} levels)")
            return None
        if node.__class__ is _ScalarNode and node.tag == _STR:  # most values: text (a scalar contains no alias)
            mark = node.start_mark
            located.marks[path] = (mark.line + 1, mark.column + 1)
            return node.value
        if id(node) in self.open:
            self.fail(node, path, "a YAML alias refers to a value that contains it")
            return None
        located.marks[path] = _position(node)
        if isinstance(node, yaml.CollectionNode) and node.tag not in _PLAIN_TAGS:
            self.fail(node, path, f"YAML tag {node.tag!r} is not supported")
            return None
        # Text values inside a mapping or list are taken in the loop (most values are): what _convert does for them,
        # without a call each. `shallow`: their paths, one longer than this one, are within the depth limit.
        shallow = len(path) < MAX_DEPTH
        marks = located.marks
        if isinstance(node, yaml.MappingNode):
            self.open.add(id(node))
            result: dict[Any, Any] = {}
            # the keys of `<<: *anchor` (or a list of them) stand where `<<` stands (fields and frame elements are in
            # wire order); a key given here that they hold too overrides its value in their place
            merged: set[Any] = set()
            for key_node, value_node in node.value:
                if key_node.tag == _MERGE:
                    for key, value in self._merge(value_node, path).items():
                        if key not in result:
                            result[key] = value
                            merged.add(key)
                    continue
                if key_node.__class__ is _ScalarNode and key_node.tag == _STR:
                    key = key_node.value  # a name: most keys
                else:
                    key = _scalar(key_node) if isinstance(key_node, yaml.ScalarNode) else None
                    if not isinstance(key, str | int) or isinstance(key, bool):
                        if isinstance(key_node, yaml.ScalarNode) and isinstance(
                            key, bool | None
                        ):  # YAML 1.1 reads on/off/yes/no/null as true/false/nothing
                            shown = "nothing" if key is None else str(key).lower()
                            message = (
                                f"the key {key_node.value} reads as {shown} in YAML: quote it ('{key_node.value}')"
                            )
                        else:
                            message = "keys must be names or numbers"
                        self.fail(key_node, path, message)
                        continue
                inner = (*path, key)
                if key in merged:
                    merged.discard(key)  # given here: it overrides the merged value, in its place
                elif key in result:
                    self.fail(key_node, inner, f"duplicate key {key!r}")
                    continue
                if isinstance(key, str) and not key.isprintable() and (bad := CONTROL.search(key)):
                    self.fail(key_node, inner, f"control character U+{ord(bad.group()):04X} in a key")
                    continue
                mark = key_node.start_mark
                located.key_marks[inner] = (mark.line + 1, mark.column + 1)
                if value_node.__class__ is _ScalarNode and value_node.tag == _STR and shallow and self.budget > 0:
                    self.budget -= 1
                    mark = value_node.start_mark
                    marks[inner] = (mark.line + 1, mark.column + 1)
                    result[key] = value_node.value
                else:
                    result[key] = self._convert(value_node, inner)
            self.open.discard(id(node))
            return result
        if isinstance(node, yaml.SequenceNode):
            self.open.add(id(node))
            items = []
            for index, item in enumerate(node.value):
                if item.__class__ is _ScalarNode and item.tag == _STR and shallow and self.budget > 0:
                    self.budget -= 1
                    mark = item.start_mark
                    marks[(*path, index)] = (mark.line + 1, mark.column + 1)
                    items.append(item.value)
                else:
                    items.append(self._convert(item, (*path, index)))
            self.open.discard(id(node))
            return items
        if isinstance(node, yaml.ScalarNode):
            try:
                value = _scalar(node)
            except yaml.constructor.ConstructorError as exc:
                self.fail(node, path, str(exc.problem))
                return None
            except ValueError:  # an integer of thousands of digits
                self.fail(node, path, f"number too long ({len(node.value)} characters)")
                return None
            return value  # text is checked by the grammar (serialspec.lang.grammar.Str), wherever it came from
        self.fail(node, path, "YAML aliases and tags are not supported")
        return None


def _scalar(node: yaml.ScalarNode) -> Any:
    """A scalar's value by the safe loader's rules (YAML 1.1: yes is true, 0x10 is 16, ...)."""
    if node.tag == _STR:  # most scalars: the text itself
        return node.value
    construct = _SCALARS.get(node.tag)
    if construct is None:
        return _CONSTRUCTOR.construct_object(node)  # an unknown tag: the safe loader's own error
    return construct(_CONSTRUCTOR, node)
