"""`<protocol>/aio.py`: the asyncio client, rendered from the same context and the same class template
(templates/_client_classes.j2) as the blocking client, with `aio` set: every method that moves bytes becomes a
coroutine awaiting the AsyncBus, `reports()` an async iterator, `Foo` `AsyncFoo`. The module-level tables (BINDING,
a table's entries, what a sync command carries) are imported from `client.py`, not repeated."""

from __future__ import annotations

from serialspec.backends.python.client import client_context
from serialspec.backends.python.render import render
from serialspec.lang.model import Protocol
from serialspec.lang.names import python_view


def aio_module(protocol: Protocol) -> str:
    context = client_context(python_view(protocol))
    # the names the classes use, with the blocking client's Iterator awaited
    abc_imports = sorted("AsyncIterator" if name == "Iterator" else name for name in context.pop("abc_imports"))
    return render("aio.py.j2", **context, abc_imports=abc_imports, aio=True)
