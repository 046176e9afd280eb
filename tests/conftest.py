"""Shared fixtures: every spec under specs/ with its generated package, so each test runs for every protocol."""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from serialspec.spec import load_protocol
from serialspec.spec.model import Example, Protocol

ROOT = Path(__file__).resolve().parent.parent
SPECS = sorted((ROOT / "specs").glob("*.yaml"))


@dataclass(frozen=True)
class Generated:
    protocol: Protocol
    package: ModuleType
    structs: ModuleType


def load(spec: Path) -> Generated:
    protocol = load_protocol(str(spec), str(spec.relative_to(ROOT)))
    package = importlib.import_module(protocol.name)
    structs = importlib.import_module(f"{protocol.name}.structs")
    return Generated(protocol, package, structs)


ALL = [load(spec) for spec in SPECS]


def by_protocol(items: list[tuple[Generated, object]]) -> list[object]:
    return [pytest.param(g, item, id=f"{g.protocol.name}:{getattr(item, 'name', item)}") for g, item in items]


@pytest.fixture(params=ALL, ids=[g.protocol.name for g in ALL])
def generated(request: pytest.FixtureRequest) -> Generated:
    return request.param  # type: ignore[no-any-return]


def example_class(g: Generated, example: Example) -> Any:
    """The message class an example records: the reply layout to expect where replies share a code."""
    for cls in g.package.MESSAGE_TYPES:
        if (example.command, example.subcommand, example.direction) == (cls.COMMAND, cls.SUBCOMMAND, cls.DIRECTION):
            return cls
    raise AssertionError(f"no message class for example {example.name}")
