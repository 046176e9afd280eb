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
