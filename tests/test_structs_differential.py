"""The construct structs and the fast codec accept the same contents (issue 25, item 4).

The structs are the reference the codec is tested against, so they must refuse what it refuses: a field derived by a
`value:` expression (Modbus byte_count = 2 * count, write_coils, read_write_registers) that does not hold what the
expression gives. For every message with such a field, hypothesis takes random valid messages, changes their content
(a byte changed, one cut off, one added), wraps it in a frame whose checksum holds, and asks both: the codec decodes
the frame exactly when the content struct parses the whole content.
"""

from __future__ import annotations

from typing import Any

import pytest
from conftest import ALL, Generated, by_protocol, examples
from construct import ConstructError, Struct, Terminated
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.lang.model import Message, Scalar
from serialspec.runtime.errors import DecodeError
from strategies import message_fields
from test_codec import frame_content, message_type

DERIVED = by_protocol(
    [(g, m) for g in ALL for m in g.protocol.messages() if any(isinstance(f, Scalar) and f.value for f in m.fields)]
)


def rewrapped(g: Generated, spec: Message, frame: bytes, content: bytes) -> bytes:
    """The frame with another content, its lengths and checksums made to hold (by the frame struct)."""
    frame_struct = getattr(g.structs, f"{spec.direction.name}_FRAME")
    parsed = frame_struct.parse(frame)
    if g.protocol.framing.classic:
        fields = {k: v for k, v in parsed.body.value.items() if not k.startswith("_")}
        return bytes(frame_struct.build({"body": {"value": {**fields, "content": content}}}))
    return bytes(frame_struct.build({**parsed, "content": content}))


def test_the_issue_s_messages_are_covered() -> None:
    names = {m.command for _, m in (p.values for p in DERIVED)}
    assert {"write_coils", "write_registers", "read_write_registers"} <= names


@pytest.mark.parametrize(("g", "spec"), DERIVED)
def test_codec_and_structs_accept_the_same_changed_contents(g: Generated, spec: Message) -> None:
    cls = message_type(g, spec)
    whole = Struct("content" / g.structs.CONTENTS[(spec.key, spec.direction.value)], Terminated)

    @settings(max_examples=examples(60), deadline=None, suppress_health_check=list(HealthCheck))
    @given(message_fields(g.protocol, spec), st.data())
    def run(fields: dict[str, Any], data: st.DataObject) -> None:
        frame = g.package.encode(cls.from_fields(fields))
        content = frame_content(g, frame, spec.direction.value)
        kind = data.draw(st.integers(0, 2))
        if kind == 0 and content:
            at = data.draw(st.integers(0, len(content) - 1))
            content = content[:at] + bytes([content[at] ^ data.draw(st.integers(1, 255))]) + content[at + 1 :]
        elif kind == 1 and content:
            content = content[:-1]
        else:
            content += bytes([data.draw(st.integers(0, 255))])
        changed = rewrapped(g, spec, frame, content)
        try:
            g.package.decode(changed, spec.direction.value, cls)
            codec = True
        except DecodeError:
            codec = False
        try:
            whole.parse(content)
            structs = True
        except ConstructError:
            structs = False
        assert codec == structs, (changed.hex(" "), codec, structs)

    run()
