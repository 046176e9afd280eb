"""Load YAML safely into plain Python values while remembering where each value came from.

PyYAML's safe loader forgets positions and silently keeps the last of duplicate keys; both matter for people
reading error messages, so we compose the node graph ourselves and convert it. Composition runs in libyaml
(`CSafeLoader`, about ten times faster, with the same line and column in every node's marks) when PyYAML was built
with it, in pure Python otherwise; a YAML syntax error is reported by the pure-Python loader either way, so the
message does not depend on how PyYAML was built.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import yaml

from serialspec.collection import without_cycle_collection
from serialspec.spec.errors import SpecError, SpecErrors

Path = tuple[str | int, ...]


@dataclass
class Located:
    """A loaded document plus the (line, column) of every value, by path from the root."""

    file: str
    data: Any
    marks: dict[Path, tuple[int, int]] = field(default_factory=dict)
    key_marks: dict[Path, tuple[int, int]] = field(default_factory=dict)

    def where(self, path: Path) -> tuple[int, int]:
        """The position of the value at path, or of its nearest located ancestor."""
        while path not in self.marks and path:
            path = path[:-1]
        return self.marks.get(path, (1, 1))

    def error(self, path: Path, message: str) -> SpecError:
        line, column = self.where(path)
        return SpecError(self.file, line, column, dotted(path), message)


def dotted(path: Path) -> str:
    return ".".join(f"[{p}]" if isinstance(p, int) else p for p in path).replace(".[", "[")


# Builds scalars only (the YAML 1.1 rules of the safe loader); mappings and lists are walked by _convert.
_CONSTRUCTOR = yaml.SafeLoader("")
_COMPOSER: type[yaml.SafeLoader] = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_STR = "tag:yaml.org,2002:str"
# The safe loader's constructor of each scalar tag, called directly: construct_object's bookkeeping (recursion
# guard, a cache of every node built) is for mappings and lists, which _convert walks itself.
_SCALARS: dict[str, Any] = {
    f"tag:yaml.org,2002:{kind}": yaml.SafeLoader.yaml_constructors[f"tag:yaml.org,2002:{kind}"]
    for kind in ("null", "bool", "int", "float", "binary", "timestamp")
}


def _position(node: yaml.Node) -> tuple[int, int]:
    return node.start_mark.line + 1, node.start_mark.column + 1


def load_file(path: str, display_name: str | None = None) -> Located:
    with open(path, encoding="utf-8") as stream:
        text = stream.read()
    return load_text(text, display_name or path)


@without_cycle_collection
def load_text(text: str, file: str) -> Located:
    located = Located(file, None)
    try:
        try:
            root = yaml.compose(text, Loader=_COMPOSER)
        except yaml.YAMLError:
            root = yaml.compose(text, Loader=yaml.SafeLoader)  # the error, as the pure-Python loader words it
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, column = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        problem = exc.problem or exc.context or "invalid YAML"
        raise SpecErrors([SpecError(file, line, column, "", f"YAML syntax error: {problem}")]) from None
    if root is None:
        raise SpecErrors([SpecError(file, 1, 1, "", "empty spec (expected a mapping with protocol, framing, ...)")])
    errors: list[SpecError] = []
    located.data = _convert(root, (), located, errors)
    if errors:
        raise SpecErrors(errors)
    return located


def _convert(node: yaml.Node, path: Path, located: Located, errors: list[SpecError]) -> Any:
    located.marks[path] = _position(node)
    if isinstance(node, yaml.MappingNode):
        result: dict[Any, Any] = {}
        for key_node, value_node in node.value:
            key = _scalar(key_node) if isinstance(key_node, yaml.ScalarNode) else None
            if not isinstance(key, str | int) or isinstance(key, bool):
                line, column = _position(key_node)
                errors.append(SpecError(located.file, line, column, dotted(path), "keys must be names or numbers"))
                continue
            if key in result:
                line, column = _position(key_node)
                errors.append(SpecError(located.file, line, column, dotted((*path, key)), f"duplicate key {key!r}"))
                continue
            located.key_marks[(*path, key)] = _position(key_node)
            result[key] = _convert(value_node, (*path, key), located, errors)
        return result
    if isinstance(node, yaml.SequenceNode):
        return [_convert(item, (*path, index), located, errors) for index, item in enumerate(node.value)]
    if isinstance(node, yaml.ScalarNode):
        try:
            return _scalar(node)
        except yaml.constructor.ConstructorError as exc:
            line, column = _position(node)
            errors.append(SpecError(located.file, line, column, dotted(path), str(exc.problem)))
            return None
    line, column = _position(node)
    errors.append(SpecError(located.file, line, column, dotted(path), "YAML aliases and tags are not supported"))
    return None


def _scalar(node: yaml.ScalarNode) -> Any:
    """A scalar's value by the safe loader's rules (YAML 1.1: yes is true, 0x10 is 16, ...)."""
    if node.tag == _STR:  # most scalars: the text itself
        return node.value
    construct = _SCALARS.get(node.tag)
    if construct is None:
        return _CONSTRUCTOR.construct_object(node)  # an unknown tag: the safe loader's own error
    return construct(_CONSTRUCTOR, node)
