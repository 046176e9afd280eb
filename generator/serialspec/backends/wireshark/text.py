"""A Wireshark dissector for a text protocol (`framing: {kind: text}`): the text model as a Lua table, read by
text_dissector.lua.j2, which splits each sentence into its talker, text code and named fields (each as the text
sent) and verifies the checksum after the marker with the algorithm's own Lua code."""

from __future__ import annotations

from typing import Any

from serialspec.backends import Unsupported
from serialspec.backends.common.render import render
from serialspec.backends.common.text import collapse
from serialspec.backends.common.text_frames import WIRESHARK_TAKES, refuse_text_frames
from serialspec.backends.wireshark.dissector import lua
from serialspec.lang.model import Protocol, TextField, TextFrame, TextLayout, TextMessage, TextRepeat


def _field(f: TextField) -> dict[str, Any]:
    # `rest`: the rest of the line, separators included (the message's last field); `address`: the framing's,
    # every message's first field, its digits right after the start (LSS's servo id); `label`: in a message's own
    # text with labels, the label its value follows
    return {"name": f.name, "title": f.name, "rest": f.rest or None, "address": f.address or None, "label": f.label}


def _layout(m: TextMessage, layout: TextLayout, ids: dict[TextLayout, int]) -> dict[str, Any]:
    """A message's own text (`text:`) as runtime/text.py reads it: its start and ending, separator, labels (`named`,
    or glued to their values), a repeat's `list`, what follows the code (`after`), and its labels, the longest first
    (a glued value is found by the longest label its text starts with)."""
    labels = [item.label for item in m.fields if not (isinstance(item, TextField) and item.address)]
    after = m.read_after_code  # nothing where the value labelled with the code follows it (LSS's `D1800`)
    return {
        "id": ids.setdefault(layout, len(ids) + 1),
        "start": layout.start,
        "ending": layout.end,
        "separator": layout.separator,
        "named": layout.named,
        "glued": layout.glued,
        "list": layout.list,
        "after": after,
        "labels": sorted(labels, key=len, reverse=True),
        "labelled": {label: True for label in labels},
    }


def emit_text_dissector(protocol: Protocol, text: TextFrame) -> str:
    refuse_text_frames(text, WIRESHARK_TAKES)
    messages: dict[str, dict[str, Any]] = {}
    alone: list[TextMessage] = []  # the messages found by their own code, the longest code first
    enclosed: dict[TextLayout, dict[str, Any]] = {}  # the own texts with a start, each once, in message order
    layout_ids: dict[TextLayout, int] = {}
    for m in text.messages:
        fields = [
            {
                "name": item.name,
                "count": item.count,
                "max": item.max_count,
                "label": item.label,
                "fields": [_field(f) for f in item.fields],
            }
            if isinstance(item, TextRepeat)
            else _field(item)
            for item in m.fields
        ]
        entry: dict[str, Any] = {
            "command": m.key,
            "code": m.code,
            "direction": m.direction.value,
            "title": m.title or m.key,  # the item of each sentence names it (the command where untitled)
            "fields": fields,
            "bare": m.values_only or None,  # read only right after its request (the last one before it in the capture)
        }
        if m.layout is not None:  # its own text: inside its start and end, or found by its code (without a start)
            entry["layout"] = _layout(m, m.layout, layout_ids)
            if m.layout.start:
                enclosed.setdefault(m.layout, entry["layout"])
            else:
                alone.append(m)
        messages.setdefault(m.code, {})[m.direction.value] = entry
    for by_direction in messages.values():
        if len(by_direction) == 1:  # the code says the direction (runtime/text.py TextFraming.sentence)
            by_direction["only"] = next(iter(by_direction))
    checksums: list[tuple[str, str]] = []
    checksum = None
    if text.checksum is not None:
        code = text.checksum.lua_function()
        if code is None:
            raise Unsupported(f"the text checksum {text.checksum.name} (no Lua code)")
        checksum = {"algorithm": text.checksum.name} | text.checksum.lua_parameters()
        checksums = [(lua(text.checksum.name, 0), code)]
    data = {
        "name": protocol.name,
        "title": protocol.title,
        # the framing's own text as bytes (a line ending may hold bytes above 0x7F: Nextion's FF FF FF); each
        # direction's own where it has one (nil: the requests')
        "start": text.start.encode("latin-1"),
        "response_start": text.response_start.encode("latin-1") or None,
        "separator": text.separator,
        "marker": text.marker,
        "ending": text.end.encode("latin-1"),
        "response_ending": text.response_end.encode("latin-1") or None,
        "decimal": text.checksum_format == "decimal",
        "checksummed": {d: True for d in text.checksum_directions},
        "separated": {d: True for d in text.checksum_separated},
        "digits": text.digits,
        "talker": text.talker,
        "address": text.address is not None,
        "required": text.required,
        "checksum": checksum,
        "messages": messages,
        "layouts": list(enclosed.values()),
        "alone": [{"code": m.code, "direction": m.direction.value} for m in sorted(alone, key=lambda m: -len(m.code))],
    }
    return render(
        "serialspec.backends.wireshark",
        "text_dissector.lua.j2",
        protocol=protocol,
        title=collapse(protocol.title),  # Lua comment lines: one line each
        spec=collapse(protocol.spec_path),
        data=lua(data, 0),
        checksums=checksums,
    )
