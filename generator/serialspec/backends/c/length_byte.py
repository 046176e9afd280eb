"""The C stream parser for frames of the length-byte shape (lang's FrameLayout.classic: a header, frame values and a
command code at fixed offsets, a one-byte length before the content, one final checksum, nothing stuffed), straight
line instead of the general scan in files.py.

It gives what serialspec.runtime.stream.StreamParser gives fed one byte at a time (its _scan, _decide and _earliest),
keeping per byte held what that scan needs again: whether a candidate starts there (a header ended with its bytes),
whether its size is known (its first `prefix` bytes came: the command's content bounds, the length byte and the
ranges of its narrowed values gave a plausible size, or it is no frame), or whether it is a corrupt frame behind one
that waits. Only three things change what that scan decides at a byte: a header ends with it, a candidate's prefix
is complete with it, a sized candidate's last byte is it (the parser keeps the nearest such end: `wake`). The scan over
the held bytes runs only then, and stops at the first candidate that waits unless one ends with this byte; the bytes
held (n of them) start at `first` in the buffer and move to its front only when its end is reached (no shift per
byte).
Every other framing takes the general parser.
"""

from __future__ import annotations

from serialspec.backends.c import parser_api
from serialspec.backends.c.emit import Ctx
from serialspec.backends.common.frames import length_limits
from serialspec.lang.model import VALUE_ROLES, Direction, FrameElement, FrameLayout, Protocol

DIRECTIONS = (Direction.REQUEST, Direction.RESPONSE)


def applies(protocol: Protocol) -> bool:
    """Every direction has one layout of the length-byte shape, with a header and its command code (if any) before
    its content: the parser below is exact for it."""
    framing = protocol.framing
    if not framing.classic or not framing.alternatives:
        return False
    for layouts in framing.alternatives.values():
        if len(layouts) != 1 or not layouts[0].header:
            return False
        layout = layouts[0]
        roles = [e.role for e in layout.elements]
        if "command" in roles and roles.index("command") > roles.index("content"):
            return False
        if prefix(layout) >= layout.overhead:  # sized before its last byte (always so: the checksum follows)
            return False
        odd = [e.type for e in layout.value_elements if e.type is not None and _narrowed(e)]
        if any(t.signed or t.is_float or t.size > 4 for t in odd):
            return False  # ranges the size function does not test (compared as unsigned bytes)
    return True


def _narrowed(e: FrameElement) -> bool:
    """A frame value whose declared range is narrower than its type's: a candidate outside it is no frame."""
    return e.type is not None and (e.minimum, e.maximum) != (e.type.minimum, e.type.maximum)


def prefix(layout: FrameLayout) -> int:
    """Bytes the Python parser waits for before it sizes a candidate (stream.py _Candidate.prefix): up to the length
    byte, the command code and every value whose range is narrower than its type's."""
    last = max(layout.length_offset, layout.command_offset or 0)
    offset = 0
    for e in layout.elements:
        if e.role == "content":
            break
        if e.role in VALUE_ROLES and _narrowed(e):
            last = max(last, offset + (e.size or 1) - 1)
        offset += e.size or 0
    return last + 1


def run_byte(layouts: list[FrameLayout]) -> int | None:
    """The byte whose runs the parser skips, or None: every layout's header is that byte repeated, and a candidate whose
    first bytes are all that byte is no frame (a narrowed value of it out of range: the size function's first test),
    with room after its header for a candidate inside the bytes kept. Inside such a run every candidate with a
    whole prefix in the run is no frame, so pushing the run one byte at a time leaves the parser holding its last
    prefix - 1 bytes, the rest garbage."""
    heads = {layout.header for layout in layouts}
    if len(heads) != 1:
        return None
    (head,) = heads
    if len(set(head)) != 1:
        return None
    byte = head[0]
    for layout in layouts:
        if prefix(layout) - 1 < len(head):
            return None
        dead = False
        for e in layout.value_elements:
            if e.type is None or not _narrowed(e) or e.type.signed or e.type.is_float or e.type.size > 4:
                continue
            value = int.from_bytes(bytes([byte]) * e.type.size, "big")
            if (value < e.minimum or value > e.maximum) and value != e.broadcast:
                dead = True
        if not dead:
            return None
    return byte


def _by_direction(protocol: Protocol, P: str, values: dict[Direction, str]) -> str:
    """A C expression of p->dir: the one value when every direction has it."""
    known = [d for d in DIRECTIONS if d in values]
    if len(set(values.values())) == 1:
        return values[known[0]]
    text = values[known[-1]]
    for d in reversed(known[:-1]):
        text = f"({P}__RX(p->dir) == {P}_{d.name} ? {values[d]} : {text})"
    return text


def _value(offset: int, size: int, big: bool) -> str:
    order = range(size) if big else reversed(range(size))
    parts = []
    for shift, i in enumerate(reversed(list(order))):
        parts.append(f"((uint32_t)f[{offset + i}u] << {8 * shift}u)" if shift else f"(uint32_t)f[{offset + i}u]")
    return " | ".join(parts) if size > 1 else parts[0]


def size_function(ctx: Ctx, direction: Direction, layout: FrameLayout) -> str:
    """The size of a plausible frame of this layout from its first prefix bytes, 0 when none starts there (stream.py
    _Candidate.frame_sizes and plausible)."""
    p, P = ctx.p, ctx.P
    need = prefix(layout)
    lines = [
        f"/* The {direction.value} frame's size from its first {need} bytes (the Python parser's candidate: the",
        " * content size bounds of its command, its length byte, the ranges of its values); 0: no frame there. */",
        f"static size_t {p}__size_{direction.value}(const uint8_t *f)",
        "{",
        "    size_t low = 0u, high = 0u;",
        "    int bounded = 0;",
        "    long content;",
    ]
    offset = 0
    code = f"{P}__NO_CODE"
    length = layout.length.name if layout.length is not None else ""
    for e in layout.elements:
        if e.role == "content":
            break
        size = e.size or 0
        value = _value(offset, size, e.endian == ">")
        if e.role == "command":
            code = f"(long)({value})"
        elif e.role in VALUE_ROLES and _narrowed(e):
            test = []
            if int(e.minimum) > 0:
                test.append(f"v < {int(e.minimum)}u")
            if int(e.maximum) < (1 << (8 * size)) - 1:
                test.append(f"v > {int(e.maximum)}u")
            if test:
                cond = " || ".join(test)
                if e.broadcast is not None:
                    cond = f"({cond}) && v != {e.broadcast}u"
                lines.append(f"    {{ uint32_t v = {value}; if ({cond}) {{ return 0u; }} }} /* {e.name} */")
        offset += size
    limits = None if layout.length is None else length_limits(layout.length)
    if limits is not None:  # a length byte outside its range: no frame
        at = f"f[{layout.length_offset}u]"
        refused = f"{at} < {limits[0]}u || {at} > {limits[1]}u" if limits[0] else f"{at} > {limits[1]}u"
        lines.append(f"    if ({refused}) {{ return 0u; }} /* {length}: its range */")
    lines += [
        f"    if (!{p}__bounds({P}_{direction.name}, {code}, &low, &high, &bounded)) {{ return 0u; }}",
        f"    content = (long)f[{layout.length_offset}u] - {layout.length_adds}L; /* {length} */",
        "    if (content < (long)low || (bounded && content > (long)high)) {",
        "        return 0u;",
        "    }",
        f"    return (size_t)content + {layout.overhead}u > {P}_MAX_FRAME ? 0u : (size_t)content + {layout.overhead}u;",
        "}",
        "",
    ]
    return "\n".join(lines)


def parser(ctx: Ctx) -> str:
    """The parser's C (init, the candidate sizes, push, the scan, the whole-frame path, feed) for a protocol that
    `applies`."""
    protocol, p, P = ctx.protocol, ctx.p, ctx.P
    layouts = {d: protocol.framing.alternatives[d][0] for d in DIRECTIONS if d in protocol.framing.alternatives}
    sizes = "\n".join(size_function(ctx, d, layout) for d, layout in layouts.items())
    size_cases = "\n".join(f"    case {P}_{d.name}:\n        return {p}__size_{d.value}(f);" for d in layouts)
    hl = _by_direction(protocol, P, {d: f"{len(layout.header)}u" for d, layout in layouts.items()})
    header = _by_direction(protocol, P, {d: f"{p}__h_{d.value}_0" for d in layouts})
    if len({layout.header for layout in layouts.values()}) == 1:
        header = f"{p}__h_{next(iter(layouts)).value}_0"
    need = _by_direction(protocol, P, {d: f"{prefix(layout)}u" for d, layout in layouts.items()})
    heads = {layout.header for layout in layouts.values()}
    if len(heads) == 1:  # one header: its bytes compared in line, the last one first
        (head,) = heads
        tests = [f"byte == 0x{head[-1]:02x}u"]
        tests += [f"b[end - {len(head) - i}u] == 0x{c:02x}u" for i, c in enumerate(head[:-1])]
        starts = " && ".join([f"n >= {len(head)}u", tests[0], *tests[1:]])
    else:
        starts = f"n >= {hl} && {p}__same(b + end - {hl}, {header}, {hl})"
    keep = max(len(layout.header) for layout in layouts.values()) - 1
    hl_feed = hl.replace("p->dir", "parser->dir")
    skip = ""  # one header: a byte that is none of its bytes ends no header that covers it, so none starts before it
    if len(heads) == 1:
        (head,) = heads
        outside = " && ".join(f"data[i + hl - 1u] != 0x{c:02x}u" for c in sorted(set(head)))
        skip = f"""
        if ({outside}) {{ /* no header covers this byte: the next can start after it */
            i += hl - 1u;
            continue;
        }}"""
    small = small_push(ctx, need, keep)
    tail_copy = (  # (a header of one byte: no tail; a loop to 0 would be -Wtype-limits' "always false")
        f"""    for (i = 0u; i < {keep}u; i++) {{ /* the tail the scan keeps: it could begin a header */
        p->buf[i] = data[size - {keep}u + i];
#if !{P}_PARSER_SMALL
        p->verdict[i] = 0u;
#endif
    }}
"""
        if keep
        else ""
    )
    run_function, run_call = run_skip(ctx, list(layouts.values()), need, hl)
    return f"""#if {P}_ENABLE_PARSER
/* ---- the stream parser (serialspec.runtime.stream.StreamParser fed one byte at a time), for frames of the
 * length-byte shape: per byte held, whether a candidate starts there and what is known of it ---- */

#define {P}__C_NEW 1u     /* a header ends here: a candidate, its size not known yet */
#define {P}__C_SIZED 2u   /* a plausible candidate, waiting for its last byte */
#define {P}__C_CORRUPT 3u /* complete and corrupt, behind a candidate that waits: counted once the scan reaches it */

void {p}_parser_init({p}_parser_t *parser, {p}_direction_t dir)
{{
    memset(parser, 0, sizeof(*parser));
    parser->dir = dir;
}}

{sizes}
static size_t {p}__size({p}_direction_t dir, const uint8_t *f)
{{
    switch (dir) {{
{size_cases}
    default:
        return 0u;
    }}
}}

{take_function(ctx)}
#if !{P}_PARSER_SMALL
/* The Python parser's scan over the bytes held (stream.py _scan, _decide, _earliest), at a byte that can change its
 * outcome: candidates in order; the first that waits holds the bytes from it on; one whose last byte this is gets
 * taken when it decodes (the first such, whether or not one before it waits), else it is corrupt, counted when no
 * candidate before it waits. Past the first waiting candidate it looks only when one ends with this byte. */
static int {p}__scan({p}_parser_t *p, {p}_msg_t *out)
{{
    const size_t first = p->first, end = first + p->n;
    size_t pos, size, hold = (size_t)-1, wake = 0u, cut;
    uint32_t errors = 0u;
    uint8_t *const v = p->verdict;
    const int all = end == p->wake;
    for (pos = first; pos < end; pos++) {{
        if (v[pos] == 0u) {{
            continue;
        }}
        if (v[pos] == {P}__C_CORRUPT) {{
            if (hold == (size_t)-1) {{
                errors++;
                v[pos] = 0u;
            }}
            continue;
        }}
        if (v[pos] == {P}__C_SIZED) {{
            size = {p}__size({P}__RX(p->dir), p->buf + pos);
            if (pos + size <= end) {{
                if ({p}__take({P}__RX(p->dir), p->buf + pos, size, out) == {P}_OK) {{
                    p->errors += errors;
                    p->garbage += (uint32_t)(pos - first);
                    p->frames++;
                    p->frame = p->buf + pos; /* kept there until the next byte is pushed */
                    p->frame_len = size;
                    p->n = 0u;
                    p->first = 0u;
                    p->wake = 0u;
                    return 1;
                }}
                if (hold == (size_t)-1) {{
                    errors++;
                    v[pos] = 0u;
                }} else {{
                    v[pos] = {P}__C_CORRUPT;
                }}
                continue;
            }}
            if (wake == 0u || pos + size < wake) {{
                wake = pos + size;
            }}
        }}
        if (hold == (size_t)-1) {{
            hold = pos;
            if (!all) {{
                break;
            }}
        }}
    }}
    if (all || hold == (size_t)-1) {{
        p->wake = wake;
    }}
    if (hold != (size_t)-1) {{
        cut = hold;
    }} else {{ /* keep a tail that could begin a header */
        cut = end - first > {keep}u ? end - {keep}u : first;
    }}
    p->errors += errors;
    p->garbage += (uint32_t)(cut - first);
    p->n = end - cut;
    p->first = end > cut ? cut : 0u;
    return 0;
}}

/* The bytes held moved to the front of the buffer, once its end is reached (a loop: no library memmove). */
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("no-tree-loop-distribute-patterns")))
#endif
static void {p}__front({p}_parser_t *p)
{{
    size_t i;
    if (p->first == 0u) {{ /* never so (a candidate is judged by its last byte, and none is longer than the buffer) */
        p->first = 1u;
        p->n--;
        p->garbage++;
    }}
    for (i = 0u; i < p->n; i++) {{
        p->buf[i] = p->buf[p->first + i];
        p->verdict[i] = p->verdict[p->first + i];
    }}
    p->wake = p->wake > p->first ? p->wake - p->first : 0u;
    p->first = 0u;
}}

/* One byte in: a header that ends with it starts a candidate, the candidate whose prefix it completes is sized; the
 * scan runs only when a sized candidate ends with it (p->wake) or no candidate is held at the front. */
static int {p}__push({p}_parser_t *p, uint8_t byte, {p}_msg_t *out)
{{
    const size_t need = {need};
    size_t at, size, end, first = p->first, n = p->n, wake = p->wake;
    uint8_t *const b = p->buf, *const v = p->verdict;
    if (first + n == {P}_MAX_FRAME) {{
        {p}__front(p);
        first = 0u;
        n = p->n;
        wake = p->wake;
    }}
    end = first + n;
    b[end] = byte;
    v[end] = 0u;
    end++;
    n++;
    p->n = n; /* the fields in locals: a store through b or v may change any byte of *p, as far as C knows */
    if ({starts}) {{ /* a header ends with this byte */
        v[end - {hl}] = {P}__C_NEW;
    }}
    if (n >= need && v[end - need] == {P}__C_NEW) {{
        at = end - need;
        size = {p}__size({P}__RX(p->dir), b + at);
        if (size == 0u) {{
            v[at] = 0u;
        }} else {{
            v[at] = {P}__C_SIZED;
            if (wake == 0u || at + size < wake) {{
                p->wake = wake = at + size;
            }}
        }}
    }}
    if (end == wake) {{
        return {p}__scan(p, out);
    }}
    if (v[first] == 0u && n >= {hl}) {{ /* no candidate at the front (any more) */
        if (n > 1u && v[first + 1u] != 0u && v[first + 1u] != {P}__C_CORRUPT) {{
            p->first = first + 1u; /* the scan's outcome when a live candidate follows: it holds the bytes from there */
            p->n = n - 1u;
            p->garbage++;
            return 0;
        }}
        return {p}__scan(p, out);
    }}
    return 0;
}}

#else
{small}
#endif

#if {P}_PARSER_WHOLE_FRAMES
/* A whole frame at data[0..len) while the parser holds fewer bytes than a header: taken at once when that gives what
 * pushing its bytes would (no header begins in the bytes held, a plausible frame that fits, no header inside it, so no
 * other candidate could end first). A frame that decodes: *taken 1; a corrupt one: *taken 0, counted in errors, its
 * last bytes held as the scan holds a tail. Returns the bytes of data it took, 0 when it does not apply. */
static size_t {p}__whole({p}_parser_t *p, const uint8_t *data, size_t len, {p}_msg_t *out, int *taken)
{{
    const size_t hl = {hl}, held = p->n;
    const uint8_t *h = {header}, *tail = p->buf;
    size_t i, k, size;
    if (len < {need} || !{p}__same(data, h, hl)) {{
        return 0u;
    }}
    size = {p}__size({P}__RX(p->dir), data);
    if (size == 0u || size > len) {{
        return 0u;
    }}
    for (i = 1u; i + hl <= size; i++) {{{skip}
        if (data[i] == h[0] && {p}__same(data + i, h, hl)) {{
            return 0u;
        }}
    }}
#if !{P}_PARSER_SMALL
    tail += p->first;
#endif
    for (i = 0u; i < held; i++) {{ /* the bytes held (no candidate: fewer than a header's) begin no header */
        for (k = 0u; k < hl && (i + k < held ? tail[i + k] : data[i + k - held]) == h[k]; k++) {{
        }}
        if (k == hl) {{
            return 0u;
        }}
    }}
    p->garbage += (uint32_t)held;
    p->n = 0u;
#if !{P}_PARSER_SMALL
    p->first = 0u;
    p->wake = 0u;
#endif
    *taken = {p}__take({P}__RX(p->dir), data, size, out) == {P}_OK;
    if (*taken) {{
        p->frames++;
        p->frame = data;
        p->frame_len = size;
        return size;
    }}
    p->errors++;
    p->garbage += (uint32_t)(size - {keep}u);
{tail_copy}    p->n = {keep}u;
    return size;
}}
#endif

{run_function}size_t {p}_parser_feed({p}_parser_t *parser, const uint8_t *data, size_t len, {p}_msg_t *out, bool *got)
{{
    size_t i;
    *got = false;
#if {P}_ROLE != {P}_ROLE_BOTH
    if (!{P}__DECODES(parser->dir)) {{ /* the other side's direction, left out of this build */
        return len;
    }}
#endif
    for (i = 0u; i < len; i++) {{
#if {P}_PARSER_WHOLE_FRAMES
        if (parser->n < {hl_feed}) {{
            int taken = 0;
            size_t size = {p}__whole(parser, data + i, len - i, out, &taken);
            if (taken) {{
                *got = true;
                return i + size;
            }}
            if (size > 0u) {{ /* a corrupt frame, counted */
                i += size - 1u;
                continue;
            }}
        }}
#endif{run_call}
        if ({p}__push(parser, data[i], out)) {{
            *got = true;
            return i + 1u;
        }}
    }}
    return len;
}}

void {p}_parser_gap({p}_parser_t *parser)
{{
    parser->garbage += (uint32_t)parser->n;
    parser->n = 0u;
#if !{P}_PARSER_SMALL
    parser->first = 0u;
    parser->wake = 0u;
#endif
}}
{parser_api.push_function(p, P, None)}{parser_api.frame_function(p)}{parser_api.expect_function(p, P, True)}#endif
"""


def run_skip(ctx: Ctx, layouts: list[FrameLayout], need: str, hl: str) -> tuple[str, str]:
    """The default parser's skip over a run of the header's byte (see run_byte), and its call in feed; nothing where
    it does not apply."""
    p, P = ctx.p, ctx.P
    byte = run_byte(layouts)
    if byte is None:
        return "", ""
    function = f"""#if !{P}_PARSER_SMALL
/* A run of 0x{byte:02x}, the header's byte, while the bytes held are that byte and fewer than a candidate's first
 * bytes: every candidate with its first bytes inside the run is no frame (a value of its prefix out of range), so the
 * parser ends as pushing the run byte by byte leaves it: holding the run's last first-bytes-less-one bytes (candidates
 * not sized yet), the rest garbage. The bytes of data taken, 0 when it does not apply. */
static size_t {p}__run({p}_parser_t *p, const uint8_t *data, size_t len)
{{
    const size_t need = {need}, hl = {hl};
    size_t i, r = 0u, held = p->n;
    if (held >= need) {{
        return 0u;
    }}
    for (i = 0u; i < held; i++) {{
        if (p->buf[p->first + i] != 0x{byte:02x}u) {{
            return 0u;
        }}
    }}
    while (r < len && data[r] == 0x{byte:02x}u) {{
        r++;
    }}
    if (held + r < need) {{
        return 0u;
    }}
    p->garbage += (uint32_t)(held + r - (need - 1u));
    p->n = need - 1u;
    p->first = 0u;
    p->wake = 0u;
    for (i = 0u; i < need - 1u; i++) {{
        p->buf[i] = 0x{byte:02x}u;
        p->verdict[i] = i + hl <= need - 1u ? {P}__C_NEW : 0u;
    }}
    return r;
}}
#endif

"""
    call = f"""
#if !{P}_PARSER_SMALL
        if (data[i] == 0x{byte:02x}u && i + {hl} < len && data[i + {hl}] == 0x{byte:02x}u) {{ /* a run: skipped */
            size_t run = {p}__run(parser, data + i, len - i);
            if (run > 0u) {{
                i += run - 1u;
                continue;
            }}
        }}
#endif"""
    return function, call


def small_push(ctx: Ctx, need: str, keep: int) -> str:
    """P_PARSER_SMALL's push: the same results as the default parser's (stream.py's scan fed one byte at a time) in
    the least flash, with no state but the bytes held. At each byte it walks the candidates held in order: the first
    one whose last byte this is and that decodes is taken (a frame ending before this byte would have been taken at
    its own); before the first candidate that waits for bytes, one that is no frame is dropped and one complete and
    corrupt counted in `errors`; the bytes from that waiting candidate on (or a tail that could begin a header) are
    kept, moved to the front of the buffer. Per byte: a header compare per byte held, a size per candidate, and each
    candidate decoded at most once (at its last byte)."""
    protocol, p, P = ctx.protocol, ctx.p, ctx.P
    layouts = {d: protocol.framing.alternatives[d][0] for d in DIRECTIONS if d in protocol.framing.alternatives}
    heads = {layout.header for layout in layouts.values()}
    if len(heads) == 1:
        (head,) = heads
        width = f"{len(head)}u"
        starts = " || ".join(f"f[{i}] != 0x{c:02x}u" for i, c in enumerate(head))
    else:
        width = _by_direction(protocol, P, {d: f"{len(layout.header)}u" for d, layout in layouts.items()})
        header = _by_direction(protocol, P, {d: f"{p}__h_{d.value}_0" for d in layouts})
        starts = f"!{p}__same(f, {header}, {width})"
    tail = {0: "end", 1: "end - 1"}.get(keep, f"(size_t)(end - b) > {keep}u ? end - {keep}u : b")
    most = max(prefix(layout) for layout in layouts.values())
    return f"""/* {P}_MAX_FRAME must hold a candidate's first bytes, which the small parser holds before it sizes it. */
typedef char {p}__max_frame_holds_a_prefix[({P}_MAX_FRAME >= {most}u) ? 1 : -1];

/* One byte in: stream.py's scan over the bytes held, at each byte (P_PARSER_SMALL: see docs/c.md). */
static int {p}__push({p}_parser_t *p, uint8_t byte, {p}_msg_t *out)
{{
    uint8_t *const b = p->buf, *const end = b + p->n + 1u;
    uint8_t *f, *hold = NULL; /* the first candidate that waits for bytes */
    size_t size, n;
    int got = 0;
    end[-1] = byte;
    for (f = b; f + {width} <= end; f++) {{
        if ({starts}) {{
            continue;
        }}
        /* a candidate: its size, or (size_t)-1 while its first bytes have not all come */
        size = (size_t)(end - f) >= {need} ? {p}__size({P}__RX(p->dir), f) : (size_t)-1;
        if (size == (size_t)(end - f) && {p}__take({P}__RX(p->dir), f, size, out) == {P}_OK) {{
            hold = f;
            got = 1;
            break;
        }}
        if (hold == NULL) {{
            if (size > (size_t)(end - f)) {{
                hold = f;
            }} else if (size != 0u) {{ /* complete and corrupt (0: no frame) */
                p->errors++;
            }}
        }}
    }}
    if (hold == NULL) {{ /* keep a tail that could begin a header */
        hold = {tail};
    }}
    p->garbage += (uint32_t)(hold - b);
    n = (size_t)(end - hold);
    for (f = b; hold < end;) {{ /* a loop: no library memmove */
        *f++ = *hold++;
    }}
    if (got) {{ /* the frame, now at the front of the buffer */
        p->frames++;
        p->frame = b;
        p->frame_len = n;
        n = 0u;
    }}
    p->n = n;
    return got;
}}
"""


def take_function(ctx: Ctx) -> str:
    """p__take: p_decode of a candidate the parser sized, without the checks the sizing made (the straight unwrap's
    `sized`), so a parser-only build links no p_decode_expect."""
    protocol, p, P = ctx.protocol, ctx.p, ctx.P
    layouts = {d: protocol.framing.alternatives[d][0] for d in DIRECTIONS if d in protocol.framing.alternatives}
    cases = []
    for d in layouts:
        cases += [
            f"    case {P}_{d.name}:",
            f"        r = {p}__unwrap_{d.value}_0(f, n, &code, values, &c, &clen, 1);",
            "        break;",
        ]
    take_cases = "\n".join(cases)
    return f"""/* {p}_decode of a candidate the parser sized (its header, the ranges of its values before the
 * content and its length checked already): the checks left (the checksum, the content) and the message. */
static int {p}__take({p}_direction_t dir, const uint8_t *f, size_t n, {p}_msg_t *out)
{{
    uint32_t code = 0u, values[{P}__MAX_ELEMENTS] = {{0u}};
    const uint8_t *c = NULL;
    size_t clen = 0u;
    int r;
    switch (dir) {{
{take_cases}
    default:
        r = {P}_E_ARG;
        break;
    }}
    if (r == {P}_OK) {{ /* one call, as p_decode_expect's: GCC keeps it in line */
        r = {p}__decode_content(dir, {p}__has_command(dir, 0u) ? (long)code : {P}__NO_CODE, {P}_KIND_NONE,
                                c, clen, values, out);
    }}
    if (r != {P}_OK) {{
        out->kind = {P}_KIND_NONE;
    }}
    return r;
}}
"""
