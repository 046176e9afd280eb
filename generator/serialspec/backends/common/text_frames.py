"""What of a text protocol (`framing: {kind: text}`) the C and Wireshark targets cannot generate yet: one list, so the
two say the same one line (backends.Unsupported) for the same spec."""

from __future__ import annotations

from collections.abc import Collection

from serialspec.backends import Unsupported
from serialspec.lang.model import TextField, TextFrame, TextLayout

# what of the list each target generates
C_TAKES = frozenset({"lines", "decimal", "separated", "values_only", "high_end"})
WIRESHARK_TAKES = frozenset(
    {
        "lines",
        "decimal",
        "separated",
        "values_only",
        "high_end",
        "end_by_direction",
        "start_by_direction",
        "one_way",
        "rest",
        "address",
        "own_code",
    }
)


def refuse_text_frames(text: TextFrame, takes: Collection[str] = ()) -> None:
    """Unsupported naming the first text feature of the list the target does not generate; `takes`: the features of
    it the target does ("lines": frames without a start character, "decimal": a checksum written in decimal,
    "separated": a separator before the checksum, "values_only": replies of values alone, "high_end": a line ending
    with bytes above 0x7F, "end_by_direction" and "start_by_direction": a line ending or start of its own for each
    direction, "one_way": a checksum in one direction only, "rest": a text field to the end of the line,
    "address": an address before the text code, "own_code": a message under a code of its own, found by it, its
    fields after it as the framing's are; own layouts of any other kind stay refused)."""
    if not text.start and "lines" not in takes:
        raise Unsupported("text frames without a start character (every line a frame)")
    if any(c > "\x7f" for c in text.end) and "high_end" not in takes:
        raise Unsupported("a line ending with bytes above 0x7F (`end`)")
    if any(isinstance(f, TextField) and f.rest for m in text.messages for f in m.fields) and "rest" not in takes:
        raise Unsupported("a text field to the end of the line (`size: rest`)")
    if text.response_end and "end_by_direction" not in takes:
        raise Unsupported("a line ending of its own for each direction (`end: {request: ..., response: ...}`)")
    if any(m.code != (text.request(m.key) or m).code for m in text.messages) and "own_code" not in takes:
        raise Unsupported("a reply under a code of its own (`text: {code: ...}`)")
    if any(m.layout is not None and not ("own_code" in takes and found_by_code(m.layout)) for m in text.messages):
        raise Unsupported("a message's own text layout (`text:`)")
    # (a target that reads each line alone: a line of values names no message)
    if any(m.values_only for m in text.messages) and "values_only" not in takes:
        raise Unsupported("a reply of values alone (`values_only`), read only with the request it answers")
    if text.checksum is not None and text.checksum_format == "decimal" and "decimal" not in takes:
        raise Unsupported("a text checksum written in decimal (`format: decimal`)")
    if text.checksum is not None and text.checksum_directions != ("request", "response") and "one_way" not in takes:
        raise Unsupported("a text checksum in one direction only (`checksum.directions`)")
    if text.checksum is not None and text.checksum_separated and "separated" not in takes:
        raise Unsupported("a separator before the text checksum (`checksum.separated`)")
    if text.response_start and "start_by_direction" not in takes:
        raise Unsupported("a start of its own for each direction (`start: {request: ..., response: ...}`)")
    if text.address is not None and "address" not in takes:
        raise Unsupported("an address before the text code (`framing.address`)")


def found_by_code(layout: TextLayout) -> bool:
    """A message's own text that is only its code (maybe holding the separator), then `after_code` and its fields
    separated (and an ending of its own): found by its code alone, without labels or lists (an ELM327's `41 0C`)."""
    return not layout.start and not layout.labelled and not layout.list
