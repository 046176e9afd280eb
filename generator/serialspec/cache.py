"""Where generation keeps what it can always rebuild: compiled templates and compiled generated modules.

Both are caches in the sense of Python's own `.pyc` files: an entry is used only when its key matches what it would be
rebuilt from (the exact source text, the Python and library versions, the settings), anything else about it (absent,
stale, truncated, corrupt, unreadable, unwritable) means "rebuild", never an error and never stale output.

The folder is the package's own `__pycache__/serialspec/` when it can be written (a checkout, a user's install), else
the user's cache folder (`$XDG_CACHE_HOME/serialspec`, by default `~/.cache/serialspec`: a read-only install), or
below `sys.pycache_prefix` when Python is told to keep its bytecode there (PYTHONPYCACHEPREFIX). Nothing is written
when Python is told not to write bytecode (PYTHONDONTWRITEBYTECODE, -B); what is there is still read.
`SERIALSPEC_CACHE_DIR` names another folder; set to an empty string, it turns the caches off.
"""

from __future__ import annotations

import contextlib
import importlib.util
import marshal
import os
import sys
from functools import cache
from pathlib import Path
from types import CodeType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from hashlib import sha256 as _sha256
else:  # CPython's own SHA-256: hashlib's digests, without the OpenSSL library that importing hashlib loads
    try:
        from _sha2 import sha256 as _sha256  # Python 3.12+
    except ImportError:
        try:
            from _sha256 import sha256 as _sha256  # Python 3.11
        except ImportError:
            from hashlib import sha256 as _sha256

_PACKAGE = Path(__file__).resolve().parent
_MAGIC = b"serialspec cache 1\n"
# How many entries a folder of the cache keeps (the ones written last), so that it does not grow without bound.
KEEP_CODE = 256  # compiled generated modules: three a spec, 1..150 kB each
MAX_FOLDER_BYTES = 256 * 1024 * 1024  # and at most this much (a 5,000-command spec's outputs take ~50 MB)


@cache
def folder() -> Path | None:
    """The cache folder (created where it may be), or None when there is none to read from."""
    setting = os.environ.get("SERIALSPEC_CACHE_DIR")
    if setting is not None:
        candidates = [Path(setting)] if setting else []
    elif sys.pycache_prefix:
        candidates = [Path(sys.pycache_prefix) / _PACKAGE.relative_to(_PACKAGE.anchor) / "serialspec"]
    else:
        candidates = [_PACKAGE / "__pycache__" / "serialspec", *_user_folder()]
    for candidate in candidates:
        if not sys.dont_write_bytecode:
            with contextlib.suppress(OSError):
                candidate.mkdir(parents=True, exist_ok=True)
        if candidate.is_dir() and (sys.dont_write_bytecode or os.access(candidate, os.W_OK)):
            return candidate
    return None


def _user_folder() -> list[Path]:
    base = os.environ.get("XDG_CACHE_HOME")
    if not base:
        try:
            base = str(Path.home() / ".cache")
        except RuntimeError:  # no home folder to be found
            return []
    return [Path(base) / "serialspec"]


def load(name: str, wanted: bytes) -> bytes | None:
    """The payload of cache entry `name` if it was stored under the key `wanted` and is intact; else None."""
    where = folder()
    if where is None:
        return None
    try:
        data = (where / name).read_bytes()
    except OSError:
        return None
    start = len(_MAGIC)
    if data[:start] != _MAGIC or data[start : start + 32] != wanted:
        return None
    payload = data[start + 64 :]
    if _sha256(payload).digest() != data[start + 32 : start + 64]:
        return None  # damaged: truncated, or changed by something other than this module
    return payload


def store(name: str, stored: bytes, payload: bytes, *, keep: int = 0) -> None:
    """Store a cache entry, atomically (a reader sees the old entry or the new one), if caches may be written; with
    `keep`, the entry's folder then keeps only that many entries, the ones written last (see _prune)."""
    where = folder()
    if where is None or sys.dont_write_bytecode:
        return
    target = where / name
    data = _MAGIC + stored + _sha256(payload).digest() + payload
    temporary = target.with_name(f".{target.name}.{os.getpid()}")
    with contextlib.suppress(OSError):
        target.parent.mkdir(parents=True, exist_ok=True)
        handle = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o666)  # as Python writes .pyc files
        try:
            with open(handle, "wb") as stream:
                stream.write(data)
            os.replace(temporary, target)
        except OSError:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
            raise
        if keep:
            _prune(target.parent, keep)


def _prune(where: Path, keep: int) -> None:
    """Keep the `keep` entries of a folder written last, within MAX_FOLDER_BYTES (the newest one always)."""
    entries = []
    for entry in os.scandir(where):
        with contextlib.suppress(OSError):
            stat = entry.stat()
            entries.append((stat.st_mtime_ns, stat.st_size, entry.path))
    entries.sort(reverse=True)
    total = 0
    for count, (_, size, path) in enumerate(entries):
        total += size
        if count >= keep or (count and total > MAX_FOLDER_BYTES):
            with contextlib.suppress(OSError):
                os.unlink(path)


def key(*parts: str | bytes) -> bytes:
    """A cache key: the hash of everything an entry depends on."""
    digest = _sha256()
    for part in parts:
        data = part if isinstance(part, bytes) else part.encode("utf-8", "surrogatepass")
        digest.update(len(data).to_bytes(8, "little"))
        digest.update(data)
    return digest.digest()


def compiled(source: str, filename: str, entry: str) -> CodeType:
    """`compile(source, filename, "exec")` (as a module's file is compiled: no __future__ flags inherited from here),
    from the cache when it holds exactly that source's code; `entry` names the module in the cache.

    The key covers everything the code object depends on: the source text, the file name it reports, the bytecode's
    version (the interpreter's magic number) and the optimisation level.
    """
    wanted = key(importlib.util.MAGIC_NUMBER, str(sys.flags.optimize), filename, source)
    # One entry per module and file name (a spec generated under two names does not evict itself); a changed
    # source replaces its entry; the entries written last are kept.
    where = _sha256(filename.encode("utf-8", "surrogatepass")).hexdigest()[:12]
    name = f"code/{entry}.{where}.{sys.implementation.cache_tag}"
    payload = load(name, wanted)
    if payload is not None:
        with contextlib.suppress(ValueError, EOFError, TypeError):
            code = marshal.loads(payload)
            if isinstance(code, CodeType):
                return code
    code = compile(source, filename, "exec", dont_inherit=True)
    if not sys.dont_write_bytecode:
        store(name, wanted, marshal.dumps(code), keep=KEEP_CODE)
    return code


@cache
def generator() -> bytes:
    """A hash of everything generation depends on besides the spec: serialspec's own code and templates (every file
    of the package, whatever it is installed as), the jinja2 and PyYAML releases, and the Python release."""
    digest = _sha256(_MAGIC + sys.version.encode())
    for top, folders, names in os.walk(_PACKAGE):
        folders[:] = sorted(f for f in folders if f != "__pycache__")
        for name in sorted(names):
            if name.endswith((".py", ".j2")):
                path = os.path.join(top, name)
                digest.update(key(os.path.relpath(path, _PACKAGE), _contents(path)))
    for library in ("jinja2", "yaml"):  # each one's __init__ names its release
        with contextlib.suppress(ImportError, ValueError):
            found = importlib.util.find_spec(library)
            if found is not None and found.origin is not None:
                digest.update(key(library, _contents(found.origin)))
    return digest.digest()


#: The folders of the package a resolved model depends on (backends/ and cli/ only read models).
MODEL_PARTS = ("lang", "checksums", "runtime")


@cache
def language() -> bytes:
    """A stamp of what a resolved spec model depends on besides the spec: the language's modules and those whose
    objects a model holds (the checksum algorithms, the runtime's Direction), PyYAML's release and Python's. Like a
    .pyc file's, by each file's size and time of change rather than its contents, so that a command that reads a
    cached model (`decode`) stays cheap."""
    digest = _sha256(_MAGIC + sys.version.encode())
    paths = []
    for top, folders, names in (step for part in MODEL_PARTS for step in os.walk(_PACKAGE / part)):
        folders[:] = sorted(f for f in folders if f != "__pycache__")
        paths += [os.path.join(top, name) for name in sorted(names) if name.endswith(".py")]
    with contextlib.suppress(ImportError, ValueError):
        found = importlib.util.find_spec("yaml")
        if found is not None and found.origin is not None:
            paths.append(found.origin)
    for path in paths:
        try:
            stat = os.stat(path)
            digest.update(key(os.path.relpath(path, _PACKAGE), str(stat.st_size), str(stat.st_mtime_ns)))
        except OSError as exc:
            digest.update(key(path, f"unreadable: {exc.errno}"))
    return digest.digest()


def _contents(path: str) -> bytes:
    try:
        with open(path, "rb") as stream:
            return stream.read()
    except OSError as exc:  # hashed as what it is: a file that cannot be read
        return f"unreadable: {exc.errno}".encode()
