"""Hypothesis fuzz of the front end: any value anywhere in a spec (or a key removed) gives spec errors or a package,
never an exception of another kind (the hostile corpus pins the messages; this finds what the corpus does not)."""

from __future__ import annotations

import copy
from typing import Any

import pytest
from conftest import examples
from hostile_run import BASES, base
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from serialspec.backends import emit, emitters
from serialspec.lang import SpecErrors
from serialspec.lang.loader import Located, Path
from serialspec.lang.resolve import resolve

VALUES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**70), 2**70),
    st.sampled_from([0, 1, 2, -1, 255, 256, 65536]),
    st.floats(),
    st.sampled_from(["", "x", "rest", "request.x", "u8", "bytes", "group", "array", "table_value", "table_block"]),
    st.lists(st.sampled_from([1, "a", None]), max_size=3),
    st.dictionaries(st.sampled_from(["type", "x", "value", "bits"]), st.sampled_from(["u8", 1, None]), max_size=2),
)


def paths(node: Any, prefix: Path = ()) -> list[Path]:
    found = [prefix] if prefix else []
    if isinstance(node, dict):
        for key, value in node.items():
            found += paths(value, (*prefix, key))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            found += paths(value, (*prefix, index))
    return found


PATHS = {name: paths(base(name).data) for name in BASES}


@st.composite
def mutations(draw: st.DrawFn, name: str) -> list[tuple[Path, Any]]:
    return [
        (draw(st.sampled_from(PATHS[name])), draw(st.one_of(VALUES, st.just(...))))
        for _ in range(draw(st.integers(1, 2)))
    ]


def mutated(name: str, changes: list[tuple[Path, Any]]) -> Located:
    located = base(name)
    data = copy.deepcopy(located.data)
    for path, value in changes:
        node = data
        try:
            for key in path[:-1]:
                node = node[key]
            if value is ...:
                del node[path[-1]]
            else:
                node[path[-1]] = value
        except (KeyError, IndexError, TypeError):
            continue  # an earlier change replaced what this path went through
    return Located(located.file, data, located.marks, located.key_marks)


@pytest.mark.parametrize("name", sorted(BASES))
def test_any_value_anywhere_is_a_spec_error_or_a_package(name: str) -> None:
    @settings(max_examples=examples(60), deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(changes=mutations(name))
    @example(changes=[(("framing", "elements"), {})])  # no elements: was an IndexError
    def check(changes: list[tuple[Path, Any]]) -> None:
        try:
            protocol = resolve(mutated(name, changes))
            for emitter in emitters():
                files = emit(emitter, protocol)  # none from a target that cannot generate the spec yet
                if emitter.verify is not None and files:
                    emitter.verify(protocol, files)
        except SpecErrors as exc:
            assert all(str(e).count("\n") == 0 for e in exc.errors)

    check()
