"""`<protocol>/aio.py`: the asyncio client, made from the blocking client the package already has.

The asyncio client is the blocking client with its waits awaited, so it is derived from the generated `client.py`
rather than written a second time: every method that moves bytes (a call of the bus's `request`, `request_each`,
`send`, `receive`, of the client base's `_maybe`, `_ask`, `_carry`, `_answers`, `_read_key`, or of such a method of
the client) becomes `async def` and its calls of them `await`; a loop over `bus.messages()` becomes `async for`.
Everything else — names, arguments, docstrings, the checks made before a byte is written, the errors — is the
blocking client's text, so the two cannot drift apart. The module-level tables (BINDING, a table's entries, what a
sync command carries) are imported from `client.py`, not repeated. The edits are made on the source text at the
positions `ast` gives, so comments and layout stay as the client template wrote them.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass

from serialspec.backends.python.render import one_line, render
from serialspec.lang.model import Protocol

# What moves bytes, called on the bus or on the client base (`self.` or, in a group class, `self._client.`).
BUS_IO = frozenset({"request", "request_each", "send", "receive"})
CLIENT_IO = frozenset({"_maybe", "_ask", "_carry", "_answers", "_read_key", "_from_new_address"})
RENAMED = {"Bus": "AsyncBus", "ClientBase": "AsyncClientBase", "Iterator": "AsyncIterator"}
LINE = 120  # ruff's line length: a longer import is wrapped as ruff's isort wraps it


@dataclass(frozen=True)
class Edit:
    """Replace the UTF-8 bytes [start, end) of a 1-based line with `text` (start == end: an insertion)."""

    line: int
    start: int
    end: int
    text: str


def aio_module(protocol: Protocol, client: str) -> str:
    """The text of `<protocol>/aio.py` from the text of the package's generated `client.py`."""
    tree = ast.parse(client)
    classes = [node for node in tree.body if isinstance(node, ast.ClassDef)]
    renamed = {**RENAMED, **{c.name: f"Async{c.name}" for c in classes}}
    edits: list[Edit] = []
    for cls in classes:
        edits += _class_edits(cls, renamed)
    lines = client.splitlines(keepends=True)
    text = _apply(lines, edits)
    # names defined at module level (BINDING, tables) come from client.py
    shared = sorted(
        target.id
        for node in tree.body
        if isinstance(node, (ast.Assign, ast.AnnAssign))
        for target in (node.targets if isinstance(node, ast.Assign) else [node.target])
        if isinstance(target, ast.Name) and target.id != "__all__"
    )
    bodies = ["".join(text[c.lineno - 1 : c.end_lineno]) for c in classes]
    used = {n.id for body in bodies for n in ast.walk(ast.parse(body)) if isinstance(n, ast.Name)}
    imports = _imports(tree, client, protocol.name, shared, used)
    header = lines[0].rstrip("\n")
    return render(
        "aio.py.j2",
        header=header,
        title=one_line(protocol.title),
        client=next(renamed[c.name] for c in classes if _is_client(c)),
        sync_client=next(c.name for c in classes if _is_client(c)),
        package=protocol.name,
        imports=imports,
        exported=[renamed[c.name] for c in classes],
        bodies=bodies,
    )


def _is_client(cls: ast.ClassDef) -> bool:
    return any(isinstance(base, ast.Name) and base.id == "ClientBase" for base in cls.bases)


def _owner(node: ast.expr) -> bool:
    """`self` or `self._client` (a group class reaching its client)."""
    if isinstance(node, ast.Name):
        return node.id == "self"
    return isinstance(node, ast.Attribute) and node.attr == "_client" and _owner(node.value)


def _calls_io(call: ast.Call, methods: set[str]) -> bool:
    func = call.func
    if not isinstance(func, ast.Attribute):
        return False
    target = func.value
    if func.attr in BUS_IO and isinstance(target, ast.Attribute) and target.attr == "bus" and _owner(target.value):
        return True
    return (func.attr in CLIENT_IO or func.attr in methods) and _owner(target)


def _messages_loop(node: ast.AST) -> bool:
    """`for ... in <owner>.bus.messages(...)`: the device's own reports."""
    if not isinstance(node, ast.For) or not isinstance(node.iter, ast.Call):
        return False
    func = node.iter.func
    return isinstance(func, ast.Attribute) and func.attr == "messages"


def _class_edits(cls: ast.ClassDef, renamed: dict[str, str]) -> list[Edit]:
    functions = [f for f in cls.body if isinstance(f, ast.FunctionDef)]
    # every method that moves bytes, directly or through another one: found until nothing changes (the group
    # classes reach the client's methods only through the bus, so a class's own methods are enough)
    waiting: set[str] = set()
    while True:
        found = {
            f.name
            for f in functions
            if any((isinstance(n, ast.Call) and _calls_io(n, waiting)) or _messages_loop(n) for n in ast.walk(f))
        }
        if found == waiting:
            break
        waiting = found
    edits: list[Edit] = []
    for node in ast.walk(cls):
        if isinstance(node, ast.Name) and node.id in renamed and node.id != "Iterator":
            edits.append(Edit(node.lineno, node.col_offset, node.end_col_offset or 0, renamed[node.id]))
    edits.append(_rename_class(cls, renamed[cls.name]))
    for f in functions:
        if f.name == "__enter__":
            edits.append(Edit(f.lineno, f.col_offset, f.col_offset + len("def __enter__"), "async def __aenter__"))
        elif f.name in waiting:
            edits.append(Edit(f.lineno, f.col_offset, f.col_offset, "async "))
            edits += _awaits(f, waiting)
    return edits


def _rename_class(cls: ast.ClassDef, name: str) -> Edit:
    start = cls.col_offset + len("class ")
    return Edit(cls.lineno, start, start + len(cls.name.encode()), name)


def _awaits(f: ast.FunctionDef, waiting: set[str]) -> list[Edit]:
    parents = {child: parent for parent in ast.walk(f) for child in ast.iter_child_nodes(parent)}
    edits: list[Edit] = []
    for node in ast.walk(f):
        if _messages_loop(node):
            assert isinstance(node, ast.For)
            edits.append(Edit(node.lineno, node.col_offset, node.col_offset, "async "))
            # the generator's annotation: Iterator[...] becomes AsyncIterator[...]
            returns = f.returns
            if isinstance(returns, ast.Subscript) and isinstance(returns.value, ast.Name):
                name = returns.value
                edits.append(Edit(name.lineno, name.col_offset, name.end_col_offset or 0, "AsyncIterator"))
        if not (isinstance(node, ast.Call) and _calls_io(node, waiting)):
            continue
        inside = parents.get(node)
        while inside is not None and inside is not f:
            assert not isinstance(inside, (ast.Lambda, ast.FunctionDef)), f"{f.name}: I/O inside a nested function"
            inside = parents.get(inside)
        # `await` binds less tightly than an attribute, a subscript or a call: `(await x()).data`
        parent = parents.get(node)
        if isinstance(parent, (ast.Attribute, ast.Subscript)) or (isinstance(parent, ast.Call) and parent.func is node):
            edits.append(Edit(node.lineno, node.col_offset, node.col_offset, "(await "))
            edits.append(Edit(node.end_lineno or 0, node.end_col_offset or 0, node.end_col_offset or 0, ")"))
        else:
            edits.append(Edit(node.lineno, node.col_offset, node.col_offset, "await "))
    return edits


def _apply(lines: list[str], edits: list[Edit]) -> list[str]:
    """The lines with the edits made (positions are UTF-8 byte offsets, as `ast` gives them)."""
    data = [line.encode() for line in lines]
    for edit in sorted(edits, key=lambda e: (e.line, e.start, e.end), reverse=True):
        line = data[edit.line - 1]
        data[edit.line - 1] = line[: edit.start] + edit.text.encode() + line[edit.end :]
    return [line.decode() for line in data]


def _imports(tree: ast.Module, source: str, package: str, shared: list[str], used: set[str]) -> list[str]:
    """The client's import block, each statement cut to the names the async classes use, in ruff's isort form:
    `serialspec.runtime.aio` first among the runtime's modules and `<package>.client` first among the package's
    modules. Sections (runs of statements without a blank line) stay apart; one left empty goes."""
    sections: list[list[str]] = []
    previous_end = 0
    added: set[str] = set()
    for node in tree.body:
        if not isinstance(node, (ast.Import, ast.ImportFrom)):
            continue
        if not sections or node.lineno > previous_end + 1:
            sections.append([])
        previous_end = node.end_lineno or node.lineno
        section = sections[-1]
        module = node.module if isinstance(node, ast.ImportFrom) else None
        if isinstance(node, ast.Import) or not module or module == "__future__":
            section.append(ast.get_source_segment(source, node) or "")
            continue
        for prefix, first, names in (
            ("serialspec.runtime.", "serialspec.runtime.aio", ["AsyncBus", "AsyncClientBase"]),
            (f"{package}.", f"{package}.client", [name for name in shared if name in used]),
        ):
            if module.startswith(prefix) and first not in added:
                added.add(first)
                if names:
                    section.append(_from(first, names))
        names = [RENAMED.get(a.name, a.name) if module == "collections.abc" else a.name for a in node.names]
        kept = [n for n, a in zip(names, node.names, strict=True) if (a.asname or n) in used]
        if module == "collections.abc":
            kept.sort()  # Iterator became AsyncIterator
        if kept:
            section.append(_from(module, kept, node.names))
    return ["\n".join(section) for section in sections if section]


def _from(module: str, names: list[str], aliases: list[ast.alias] | None = None) -> str:
    asnames = {a.name: a.asname for a in aliases or [] if a.asname}
    shown = [f"{n} as {asnames[n]}" if n in asnames else n for n in names]
    line = f"from {module} import {', '.join(shown)}"
    if len(line) <= LINE:
        return line
    return f"from {module} import (\n" + "".join(f"    {n},\n" for n in shown) + ")"
