"""Where a project's specs and generated files live, and what generating them produces."""

from __future__ import annotations

import json
from pathlib import Path

from serialspec.emit import emitters
from serialspec.spec import SpecError, SpecErrors, load_protocol
from serialspec.spec.grammar import json_schema

SCHEMA_NAME = "serialspec.schema.json"


def find_root(start: Path | None = None) -> Path:
    """The nearest folder holding specs/ (the project root), from the working directory up."""
    here = (start or Path.cwd()).resolve()
    for folder in (here, *here.parents):
        if (folder / "specs").is_dir():
            return folder
    return here


def expected_files(root: Path) -> tuple[dict[Path, str], list[SpecError]]:
    """Every generated file, by path, from the valid specs under root; and every mistake in the others."""
    files: dict[Path, str] = {
        root / "specs" / SCHEMA_NAME: json.dumps(json_schema(), indent=2, ensure_ascii=False) + "\n"
    }
    errors = []
    for spec in sorted((root / "specs").glob("*.yaml")):
        try:
            protocol = load_protocol(str(spec), str(spec.relative_to(root)))
        except SpecErrors as exc:
            errors.extend(exc.errors)
            continue
        for emitter in emitters():
            emitted = emitter.files(protocol)
            for name, text in emitted.items():
                files[root / "generated" / name] = text
            if emitter.verify is not None:
                errors.extend(emitter.verify(protocol, emitted))
    return files, errors
