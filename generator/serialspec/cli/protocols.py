"""The protocol the decode/encode/sim/monitor verbs work with: never code older than its spec.

Given a spec file, the protocol's importable package is used only if it was generated from exactly that spec text
(the copy of the spec every generated package ships says so); otherwise the package is generated from the spec in
memory. So an edited spec takes effect at once, without regenerating. Given a protocol name, the installed package
is used with the spec it ships.
"""

from __future__ import annotations

import os
import sys
from types import ModuleType

from serialspec.cli.shipped import SHIPPED_NAMESPACE, SHIPPED_SPEC, import_name
from serialspec.runtime import import_module
from serialspec.runtime.errors import SerialspecError

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing
if TYPE_CHECKING:
    from serialspec.lang.model import Protocol

SPEC_HELP = (
    "a spec file (built from it in memory, never stale), or a generated protocol package's name (in the current "
    "folder or installed)"
)
#: Modules the verbs use, imported with a package generated in memory (a package on disk imports each one when a
#: verb asks for it: `submodule`); structs (construct) and client are left out: the CLI needs neither.
_MODULES = ("messages", "codec", "registers", "simulator")


def open_spec(spec: str) -> tuple[Protocol, ModuleType]:
    """The resolved spec and its package; errors are one line for the user."""
    from pathlib import Path

    from serialspec.lang.limits import read_spec

    path = Path(spec)
    if path.suffix in (".yaml", ".yml") or path.is_file() or "/" in spec:
        try:
            data = read_spec(spec)
        except OSError:
            raise SerialspecError(f"no such spec: {spec}") from None
        key = (str(path.resolve()), spec, data)
        if key not in _BUILT:  # the same spec text again in this process (in-process callers, tests)
            protocol = resolved(spec, os.path.relpath(spec), data)
            package = generated_from_this(protocol, data.decode("utf-8", "surrogateescape"))
            _BUILT[key] = protocol, package or package_in_memory(protocol)
        return _BUILT[key]
    return installed(spec)


_BUILT: dict[tuple[str, str, bytes], tuple[Protocol, ModuleType]] = {}


def open_binary_spec(spec: str, verb: str) -> tuple[Protocol, ModuleType]:
    """`open_spec` for the verbs that address devices by id (`scan`): a text protocol is refused in one line."""
    protocol, package = open_spec(spec)
    if protocol.text is not None:
        raise SerialspecError(
            f"{spec} is a text protocol (`framing: {{kind: text}}`): its sentences carry no device id to "
            f"`serialspec {verb}` for (`monitor` and `watch` show what its devices send)"
        )
    return protocol, package


def resolved(path: str, display: str, data: bytes) -> Protocol:
    """`load_protocol(path, display)` for a spec whose text is `data`: from the cache when it holds the model resolved
    from exactly that text and name by exactly this spec language (the commands that only read a spec, `decode`
    above all, then import neither PyYAML nor the resolver); resolved, and stored, otherwise."""
    import pickle

    from serialspec import cache

    wanted = cache.key(cache.language(), display, data)
    name = f"model/{cache.key(display).hex()[:16]}.{sys.implementation.cache_tag}"
    payload = cache.load(name, wanted)
    if payload is not None:
        try:
            protocol = pickle.loads(payload)
        except Exception:  # an entry that does not load (damaged, from classes since changed): rebuilt below
            protocol = None
        from serialspec.lang.model import Protocol

        if isinstance(protocol, Protocol):
            return protocol
    from serialspec.lang import load_protocol

    protocol = load_protocol(path, display)
    if not sys.dont_write_bytecode:
        cache.store(name, wanted, pickle.dumps(protocol, pickle.HIGHEST_PROTOCOL), keep=KEEP_MODELS)
    return protocol


#: How many resolved models the cache keeps (the ones written last); tens of kB each.
KEEP_MODELS = 64


def submodule(package: ModuleType, name: str) -> ModuleType | None:
    """A module of a generated package (`simulator`, `registers`), imported when first asked for; None if the
    package has none (a spec without `device:` has no simulator)."""
    found = getattr(package, name, None)
    if found is not None or getattr(package, "__file__", None) is None:  # generated in memory: imported with it
        return found
    return _import_if_any(f"{package.__name__}.{name}")


def _import_if_any(name: str, *, parent_missing: bool = False) -> ModuleType | None:
    """The module `name` imported, or None where there is no such module (or, `parent_missing`, no such package
    above it): what importlib.util.find_spec tells before an import, without importing importlib.util (and
    contextlib with it) on the way of `serialspec decode PACKAGE`. An import error inside the module is raised."""
    try:
        return import_module(name)
    except ModuleNotFoundError as exc:
        if exc.name == name or (parent_missing and exc.name and name.startswith(f"{exc.name}.")):
            return None
        raise


def installed(name: str) -> tuple[Protocol, ModuleType]:
    """A generated package by protocol name, with the spec it ships as package data: a package NAME/ in the current
    folder first, then the installed serialspec_protocols.NAME, then an installed top-level NAME."""
    package, shipped, data = installed_package(name)
    return resolved(shipped, f"{name}/{SHIPPED_SPEC}", data), package


def installed_package(name: str) -> tuple[ModuleType, str, bytes]:
    """`installed`'s package, the path of the spec it ships and that spec's text, without the spec's model (what
    `decode` needs when the package can answer alone)."""
    here = os.getcwd()
    sys.path.insert(0, here)
    try:
        local = not name.isidentifier() or os.path.isfile(os.path.join(name, "__init__.py"))
        # as _import_name chooses: the folder's own package, else the shipped one, else NAME as it is
        package = None if local else _import_if_any(f"{SHIPPED_NAMESPACE}.{name}", parent_missing=True)
        package = package or import_module(name)
    except ImportError:
        package = None
    finally:
        sys.path.remove(here)
    package = package or _in_project(name)
    if package is None:
        raise SerialspecError(
            f"no such spec file, nor a protocol package {name}/ in this folder, the project's output folder or "
            f"installed: give the spec file ({name}.yaml), or run from the folder that holds the generated {name}/"
        )
    folder = getattr(package, "__path__", None)
    shipped = os.path.join(next(iter(folder)), SHIPPED_SPEC) if folder else None
    data = None
    if shipped is not None and getattr(package, "PROTOCOL", None) == name:
        try:
            with open(shipped, "rb") as stream:
                data = stream.read()
        except OSError:
            data = None
    if data is None or shipped is None:
        raise SerialspecError(f"{name} is not a package generated by serialspec (it ships no {SHIPPED_SPEC})")
    return package, shipped, data


def _in_project(name: str) -> ModuleType | None:
    """The package NAME as `serialspec generate` writes it into the project's output folder (`[tool.serialspec]
    out`, under its namespace) when the working directory is in a project; None where it is not there."""
    if not name.isidentifier():
        return None
    from serialspec.cli.project import project

    try:
        where = project(None)
    except SerialspecError:
        return None
    folder = str(where.out)
    if not os.path.isfile(os.path.join(folder, where.package_folder(name), "__init__.py")):
        return None
    sys.path.insert(0, folder)
    try:
        return import_module(f"{where.namespace}.{name}" if where.namespace else name)
    except ImportError:
        return None
    finally:
        sys.path.remove(folder)


def generated_from_this(protocol: Protocol, spec_text: str) -> ModuleType | None:
    """The importable generated package of this protocol, if it was generated from exactly this spec text (the copy
    of the spec it ships says so); else None, and the caller builds the package from the spec instead."""
    import importlib.util
    from pathlib import Path

    name = import_name(protocol.name)
    try:
        found = importlib.util.find_spec(name)
    except (ImportError, ValueError):
        return None
    if found is None or not found.submodule_search_locations:
        return None
    shipped = Path(next(iter(found.submodule_search_locations))) / SHIPPED_SPEC
    try:
        generated_from = shipped.read_text(encoding="utf-8").partition("\n")[2]  # after the generated header
    except OSError:
        return None
    if generated_from != spec_text:
        return None
    return import_module(name)


def package_in_memory(protocol: Protocol) -> ModuleType:
    """The protocol's package generated from the resolved spec and imported from memory (nothing on disk)."""
    from serialspec.backends.python.memory import imported
    from serialspec.backends.python.package import emit_package
    from serialspec.backends.python.text import text_package

    files = emit_package(protocol) if protocol.text is None else text_package(protocol, protocol.text)
    with imported(protocol.name, files, protocol.spec_path) as package:
        for module in _MODULES:
            if f"{module}.py" in files:
                import_module(f"{protocol.name}.{module}")
    return package


def message_type(package: ModuleType, command: str, subcommand: str | None, direction: str) -> type:
    for cls in package.MESSAGE_TYPES:
        if (cls.COMMAND, cls.SUBCOMMAND, cls.DIRECTION.value) == (command, subcommand, direction):
            return cls  # type: ignore[no-any-return]
    what = f"{command}.{subcommand}" if subcommand else command
    import difflib  # only for a name that is not there

    names = sorted(
        {
            f"{c.COMMAND}.{c.SUBCOMMAND}" if c.SUBCOMMAND else c.COMMAND
            for c in package.MESSAGE_TYPES
            if c.DIRECTION.value == direction
        }
    )
    close = difflib.get_close_matches(what, names, n=3)
    other = "response" if direction == "request" else "request"
    elsewhere = any(
        (c.COMMAND, c.SUBCOMMAND, c.DIRECTION.value) == (command, subcommand, other) for c in package.MESSAGE_TYPES
    )
    hint = (
        f" (it is a {other}: give the direction {other})"
        if elsewhere
        else f" (did you mean {' or '.join(close)}?)"
        if close
        else f" (it has no {direction}s)"
        if not names
        else f" (it has {', '.join(names)})"
        if len(names) <= 12
        else ""
    )
    raise SerialspecError(f"{getattr(package, 'PROTOCOL', package.__name__)} has no {direction} {what!r}{hint}")
