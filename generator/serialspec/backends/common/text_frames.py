"""What of a text protocol (`framing: {kind: text}`) a target cannot generate yet: one list, so the targets say the
same one line (backends.Unsupported) for the same spec."""

from __future__ import annotations

from collections.abc import Collection

from serialspec.backends import Unsupported
from serialspec.lang.model import TextField, TextFrame

# what of the list each target generates: the C and the Wireshark dissector all of it
C_TAKES = frozenset(
    {"lines", "decimal", "separated", "values_only", "high_end", "ends", "codes", "layouts", "rest", "one_way"}
    | {"starts", "address", "labels"}
)
WIRESHARK_TAKES = C_TAKES


def refuse_text_frames(text: TextFrame, takes: Collection[str] = ()) -> None:
    """Unsupported naming the first text feature of the list the target does not generate; `takes`: the features of
    it the target does ("lines": frames without a start character, "decimal": a checksum written in decimal,
    "separated": a separator before the checksum, "values_only": replies of values alone, "high_end": a line ending
    with bytes above 0x7F, "ends": a line ending of its own for each direction, "codes": a reply under a code of its
    own, "layouts": messages in their own text (found by their code alone, or inside a start and an ending),
    "labels": messages in their own text with labels, "rest": a text field to the end of the line, "one_way": a
    checksum in one direction only, "starts": a start of its own for each direction, "address": an address before
    the code)."""
    if not text.start and "lines" not in takes:
        raise Unsupported("text frames without a start character (every line a frame)")
    if any(c > "\x7f" for c in text.end) and "high_end" not in takes:
        raise Unsupported("a line ending with bytes above 0x7F (`end`)")
    if any(isinstance(f, TextField) and f.rest for m in text.messages for f in m.fields) and "rest" not in takes:
        raise Unsupported("a text field to the end of the line (`size: rest`)")
    if text.response_end and "ends" not in takes:
        raise Unsupported("a line ending of its own for each direction (`end: {request: ..., response: ...}`)")
    if any(m.code != (text.request(m.key) or m).code for m in text.messages) and "codes" not in takes:
        raise Unsupported("a reply under a code of its own (`text: {code: ...}`)")
    if any(m.layout is not None for m in text.messages) and "layouts" not in takes:
        raise Unsupported("a message's own text layout (`text:`)")
    if any(m.layout is not None and m.layout.labelled for m in text.messages) and "labels" not in takes:
        raise Unsupported("a message's own text with labels (`text: {named: ...}`)")
    # (a target that reads each line alone: a line of values names no message)
    if any(m.values_only for m in text.messages) and "values_only" not in takes:
        raise Unsupported("a reply of values alone (`values_only`), read only with the request it answers")
    if text.checksum is not None and text.checksum_format == "decimal" and "decimal" not in takes:
        raise Unsupported("a text checksum written in decimal (`format: decimal`)")
    if text.checksum is not None and text.checksum_directions != ("request", "response") and "one_way" not in takes:
        raise Unsupported("a text checksum in one direction only (`checksum.directions`)")
    if text.checksum is not None and text.checksum_separated and "separated" not in takes:
        raise Unsupported("a separator before the text checksum (`checksum.separated`)")
    if text.response_start and "starts" not in takes:
        raise Unsupported("a start of its own for each direction (`start: {request: ..., response: ...}`)")
    if text.address is not None and "address" not in takes:
        raise Unsupported("an address before the text code (`framing.address`)")
