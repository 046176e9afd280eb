"""The stream parser's calls beside p_parser_feed that every C parser has (the general one in files.py, the
length-byte one, the text one): p_parser_frame, and p_parser_expect where the Python parser has expect()."""

from __future__ import annotations


def frame_function(p: str) -> str:
    """p_parser_frame: the raw bytes of the last frame delivered (each parser keeps `frame` and `frame_len`)."""
    return f"""
const uint8_t *{p}_parser_frame(const {p}_parser_t *parser, size_t *len)
{{
    if (len != NULL) {{
        *len = parser->frame_len;
    }}
    return parser->frame;
}}
"""


def expect_function(p: str, P: str, classic: bool) -> str:
    """p_parser_expect. Python's StreamParser (classic frames: one layout a code) ignores expect(); its
    FrameStreamParser decodes what it takes as the expected reply, deciding every candidate again on the next
    feed: a candidate found corrupt as another reply is judged again (its verdict cleared, the scan run at the next
    byte)."""
    if classic:
        return f"""
void {p}_parser_expect({p}_parser_t *parser, {p}_kind_t reply)
{{
    (void)parser;
    (void)reply;
}}
"""
    return f"""
void {p}_parser_expect({p}_parser_t *parser, {p}_kind_t reply)
{{
    size_t i;
    parser->expect = reply;
    for (i = 0u; i < parser->n; i++) {{
        if (parser->verdict[i] == {P}__V_CORRUPT) {{ /* corrupt as another reply: judged again */
            parser->verdict[i] = 0u;
        }}
    }}
    parser->wake = 0u;
}}
"""


def event_type(p: str, P: str) -> str:
    """p_event_t, what p_parser_push says a byte did (c-target.md's NONE, MESSAGE, FRAME_UNKNOWN)."""
    return f"""/* What one byte did ({p}_parser_push): nothing complete; a message (in *out, its bytes
 * {p}_parser_frame's); or a frame whose checksum is good but whose command (or sub-command) the spec does not have,
 * so a router can still forward it ({p}_parser_frame gives its bytes; *out holds no message). The parser counts
 * that frame as the Python parser counts it (see docs/c.md) and in `unknown`. */
typedef enum {{ {P}_EVENT_NONE = 0, {P}_EVENT_MESSAGE, {P}_EVENT_FRAME_UNKNOWN }} {p}_event_t;
"""


def push_prototype(p: str) -> str:
    return f"""/* One byte in (an interrupt handler's call): what it completed. The same parser as {p}_parser_feed's,
 * one byte at a time (the two can be mixed on one parser); a frame of an unknown command is an event here only. */
{p}_event_t {p}_parser_push({p}_parser_t *parser, uint8_t byte, {p}_msg_t *out);
"""


def push_function(p: str, P: str, frame: str | None) -> str:
    """p_parser_push over the parser's own push (`{p}__push`: 1 a message, 2 a frame of an unknown command, else 0).
    `frame`: the statements that point parser->frame at that frame, kept with P_PARSER_UNKNOWN_FRAMES (None: the
    parser's push has done it)."""
    role = f"""#if {P}_ROLE != {P}_ROLE_BOTH
    if (!{P}__DECODES(parser->dir)) {{ /* the other side's direction, left out of this build */
        return {P}_EVENT_NONE;
    }}
#endif
"""
    unknown = f"\n        return {P}_EVENT_FRAME_UNKNOWN;"
    if frame:  # the copy's switch: without it, no event
        unknown = f"\n#if {P}_PARSER_UNKNOWN_FRAMES\n        {frame}{unknown}\n#endif"
    return f"""
{p}_event_t {p}_parser_push({p}_parser_t *parser, uint8_t byte, {p}_msg_t *out)
{{
{role}    switch ({p}__push(parser, byte, out)) {{
    case 1:
        return {P}_EVENT_MESSAGE;
    case 2:{unknown}
    default:
        return {P}_EVENT_NONE;
    }}
}}
"""
