"""bench/c_stack.py's worst-case stack: a function's frame plus its deepest callee's along gcc's call graph, a call
through a pointer as the deepest static function, a cycle refused (no bound)."""

from __future__ import annotations

import sys

from conftest import ROOT

sys.path.append(str(ROOT))  # bench/ is a folder of the project, not an installed package
from bench.c_stack import _graph, _worst  # noqa: E402

CALL_GRAPH = r"""graph: { title: "p.c"
node: { title: "p.c:p_decode" label: "p_decode\np.c:10:5\n40 bytes (static)" }
node: { title: "p.c:p__scan" label: "p__scan.constprop\np.c:20:13\n100 bytes (static)" }
node: { title: "p.c:p__small" label: "p__small\np.c:30:13\n8 bytes (static)" }
node: { title: "p.c:p__enc_a" label: "p__enc_a\np.c:40:12\n300 bytes (static)" }
node: { title: "memcpy" label: "__builtin_memcpy\n<built-in>" shape : ellipse }
edge: { sourcename: "p.c:p_decode" targetname: "p.c:p__scan" label: "p.c:11:5" }
edge: { sourcename: "p.c:p_decode" targetname: "p.c:p__small" label: "p.c:12:5" }
edge: { sourcename: "p.c:p__scan" targetname: "memcpy" }
node: { title: "p.c:p_encode" label: "p_encode\np.c:50:5\n16 bytes (static)" }
node: { title: "__indirect_call" label: "Indirect Call Placeholder" shape : ellipse }
edge: { sourcename: "p.c:p_encode" targetname: "__indirect_call" label: "p.c:51:5" }
node: { title: "p.c:p_loop" label: "p_loop\np.c:60:5\n4 bytes (static)" }
edge: { sourcename: "p.c:p_loop" targetname: "p.c:p_loop" label: "p.c:61:5" }
}
"""


def test_the_worst_case_is_the_frame_and_the_deepest_call_chain() -> None:
    frames, calls, names = _graph(CALL_GRAPH)
    assert names["p_decode"] == "p.c:p_decode" and names["p__scan"] == "p.c:p__scan"  # .constprop dropped
    assert _worst(names["p_decode"], frames, calls) == 40 + 100  # the deeper of its two callees
    assert _worst(names["p_encode"], frames, calls) == 16 + 300  # through a pointer: the deepest static function
    assert _worst(names["p_loop"], frames, calls) == -1  # recursion: no bound
