"""The frame engine every generated .c carries: the spec's layouts as tables, walked by code that follows
serialspec.runtime.framing (Layout.wrap, Layout.unwrap, FrameCodec.probe). PFX_/pfx_ stand for the protocol's prefix."""

HEAD = r"""/* ---- the frame engine: the spec's layouts as tables (runtime/framing.py's Layout, as C) ---- */

#define PFX__ROLE_CONSTANT 0u
#define PFX__ROLE_VALUE 1u
#define PFX__ROLE_COMMAND 2u
#define PFX__ROLE_LENGTH 3u
#define PFX__ROLE_CONTENT 4u
#define PFX__ROLE_CHECKSUM 5u
#define PFX__ROLE_EXTRA 6u /* an optional element sent: fixed bytes the message gives (a layout's variant) */

/* A value in range (and, in a variant of a layout with optional elements, with the flag bit the variant has:
 * first = the bit's number + 1, last = 1 set / 0 clear). */
#define PFX__PLAUSIBLE(e, value) \
    ((((value) >= (e)->minimum && (value) <= (e)->maximum) || ((e)->has_also && (value) == (e)->also)) && \
     (!PFX__OPTIONAL || (e)->first == 0u || (((value) >> ((e)->first - 1u)) & 1u) == (e)->last))

#if PFX_ENABLE_DECODE || PFX__STUFFED
/* 1 when a[0..n) and b[0..n) hold the same bytes (memcmp's test, without the library's memcmp in the build) */
static int pfx__same(const uint8_t *a, const uint8_t *b, size_t n)
{
    size_t i;
    for (i = 0u; i < n; i++) {
        if (a[i] != b[i]) {
            return 0;
        }
    }
    return 1;
}
#endif

/* Byte stuffing over part of a layout (constant 0 when no layout has it: that code left out) */
#define PFX__T(L) (PFX__STUFFED && (L)->has_t)

#define PFX__WAIT (-2L)
#define PFX__NONE (-1L)

typedef struct {
    uint8_t role;     /* PFX__ROLE_... */
    uint8_t size;     /* bytes (0 for the content) */
    uint8_t big;      /* big-endian */
    uint8_t first;    /* length: elements counted; checksum: elements covered (indexes, inclusive); extra: which */
    uint8_t last;
    uint8_t check;    /* checksum: which algorithm (pfx__check) */
    uint8_t has_also; /* value: one more value allowed (a broadcast address) */
    int32_t adds;     /* length: added to the counted size */
    uint32_t minimum; /* value, command: the plausible values */
    uint32_t maximum;
    uint32_t also;
    const uint8_t *constant; /* constant: its bytes (size of them) */
} pfx__element_t;

typedef struct {
    const uint8_t *plain;
    const uint8_t *wire;
    uint8_t plain_len;
    uint8_t wire_len;
} pfx__pair_t;

typedef struct {
    const pfx__element_t *e;
    uint8_t count;
    int8_t content;    /* index of the content, -1 without */
    int8_t command;    /* index of the command code, -1 without */
    uint8_t has_t;     /* transform of elements t_first..t_last: 1 substitution (pairs), 2.. pfx__transform; 0 none */
    uint8_t t_first;
    uint8_t t_last;
    const pfx__pair_t *pairs;
    uint8_t npairs;
    uint8_t header_len; /* the leading constant's size (0: no header) */
    uint8_t prefix;     /* the classic parser waits for this many bytes before it judges a candidate (else 0) */
    uint32_t error_flag; /* a command code with these bits set is an error reply (0: none; all 1s: an error header) */
    uint16_t overhead;   /* every element's size but the content's */
    uint16_t before;     /* bytes before the variable part (the stuffed span, else the content) */
    uint16_t after;      /* bytes after it */
    int8_t length;       /* index of the length element (before the variable part), -1 without */
    uint16_t length_off; /* its offset */
    uint16_t counted;    /* the fixed sizes of the elements it counts */
    int8_t error_status; /* index of the status whose error_bits set make a frame an error reply, -1 without */
    uint32_t error_bits;
} pfx__layout_t;

/* Where each element of a frame lies: wire bytes (start, end) and, inside the stuffed span, plain bytes. */
typedef struct {
    size_t ws[PFX__MAX_ELEMENTS];
    size_t we[PFX__MAX_ELEMENTS];
    size_t ps[PFX__MAX_ELEMENTS];
    size_t pe[PFX__MAX_ELEMENTS];
} pfx__where_t;

#if PFX_ENABLE_DECODE
"""

# A frame element's value from its bytes: the engine's for stuffed layouts, and the content code's where it asks
# (Ctx.helpers "get"); left out of a spec whose C calls it nowhere
GET = r"""static uint32_t pfx__get(const uint8_t *b, uint8_t size, uint8_t big)
{
    uint32_t v = 0u;
    uint8_t i;
    for (i = 0u; i < size; i++) {
        v = (v << 8) | b[big ? i : (uint8_t)(size - 1u - i)];
    }
    return v;
}

"""

TAIL = r"""#endif

#if PFX_ENABLE_ENCODE
static void pfx__put(uint8_t *b, uint8_t size, uint8_t big, uint32_t v)
{
    uint8_t i;
    for (i = 0u; i < size; i++) {
        b[big ? (uint8_t)(size - 1u - i) : i] = (uint8_t)((v >> (8u * i)) & 0xFFu);
    }
}
#endif

#if PFX_ENABLE_ENCODE || PFX__STUFFED
/* The elements before the variable part (the stuffed span, else the content) and after it. */
static uint8_t pfx__inner_first(const pfx__layout_t *L)
{
    if (PFX__T(L)) {
        return L->t_first;
    }
    return L->content >= 0 ? (uint8_t)L->content : L->count;
}
#endif

#if PFX_ENABLE_ENCODE || PFX__STUFFED
static int pfx__inner_last(const pfx__layout_t *L)
{
    if (PFX__T(L)) {
        return (int)L->t_last;
    }
    return L->content >= 0 ? (int)L->content : (int)L->count - 1;
}
#endif

#if PFX__STUFFED /* no layout stuffed: the rewriting code is left out (it would be compiled and never run) */
/* ---- transforms ---- */

/* Each plain sequence rewritten as its wire sequence (to_wire) or back, leftmost first, the pairs tried in order at
 * each position. With cmp: compare the result with cmp[0..cap) instead of writing it (1: equal). */
static int pfx__rewrite(const pfx__layout_t *L, int to_wire, const uint8_t *src, size_t n, uint8_t *dst,
                        const uint8_t *cmp, size_t cap, size_t *out)
{
    size_t i = 0u, o = 0u;
    uint8_t k;
    if (L->has_t >= 2u) {
        return pfx__transform(L->has_t, to_wire, src, n, dst, cmp, cap, out);
    }
    while (i < n) {
        int matched = 0;
        for (k = 0u; k < L->npairs; k++) {
            const uint8_t *from = to_wire ? L->pairs[k].plain : L->pairs[k].wire;
            size_t flen = to_wire ? L->pairs[k].plain_len : L->pairs[k].wire_len;
            const uint8_t *to = to_wire ? L->pairs[k].wire : L->pairs[k].plain;
            size_t tlen = to_wire ? L->pairs[k].wire_len : L->pairs[k].plain_len;
            if (flen <= n - i && pfx__same(src + i, from, flen)) {
                if (tlen > cap - o) {
                    return 0;
                }
                if (cmp != NULL) {
                    if (!pfx__same(cmp + o, to, tlen)) {
                        return 0;
                    }
                } else {
                    size_t t;
                    for (t = 0u; t < tlen; t++) { /* a loop: a decoder-only build has no other use for memcpy */
                        dst[o + t] = to[t];
                    }
                }
                o += tlen;
                i += flen;
                matched = 1;
                break;
            }
        }
        if (!matched) {
            if (o >= cap) {
                return 0;
            }
            if (cmp != NULL) {
                if (cmp[o] != src[i]) {
                    return 0;
                }
            } else {
                dst[o] = src[i];
            }
            o++;
            i++;
        }
    }
    *out = o;
    return cmp == NULL || o == cap;
}
#endif

#if PFX_ENABLE_ENCODE || PFX__STUFFED
/* The bytes of elements a..b: the plain bytes when they lie inside the stuffed span, else the wire bytes. */
static const uint8_t *pfx__range(const pfx__layout_t *L, const pfx__where_t *w, const uint8_t *wire,
                                 const uint8_t *plain, uint8_t a, uint8_t b, size_t *n)
{
    if (PFX__T(L) && a >= L->t_first && b <= L->t_last) {
        *n = w->pe[b] - w->ps[a];
        return plain + w->ps[a];
    }
    *n = w->we[b] - w->ws[a];
    return wire + w->ws[a];
}
#endif

/*@gather@*/
#if PFX_ENABLE_ENCODE
/* The frame around a content already in place (at out + prefix, or in span + its offset when stuffed): the frame
 * engine's wrap (runtime/framing.py Layout.wrap), its checks in its order. */
static int pfx__wrap(const pfx__layout_t *L, uint8_t *out, size_t cap, uint8_t *span, size_t clen, uint32_t code,
                     const uint32_t *values, const uint8_t *const *extras, size_t *len)
{
    pfx__where_t w = {0}; /* (each entry is set before it is read; gcc -Os cannot always tell) */
    size_t pos = 0u, i, sz;
    uint8_t k, v = 0u;
    uint8_t first = pfx__inner_first(L);
    int last = pfx__inner_last(L);
    const uint8_t *bytes;
    /*@covered@*/
    /* plain bytes of the stuffed span: its elements laid out around the content, inner checksums over them */
#if PFX__STUFFED
    if (PFX__T(L)) {
        size_t p = 0u;
        for (k = L->t_first; k <= L->t_last; k++) {
            const pfx__element_t *e = &L->e[k];
            w.ps[k] = p;
            sz = e->role == PFX__ROLE_CONTENT ? clen : e->size;
            if (sz > PFX_MAX_FRAME - p) {
                return PFX_E_BUFFER;
            }
            if (e->role == PFX__ROLE_CONSTANT) {
                memcpy(span + p, e->constant, e->size);
            } else if (e->role == PFX__ROLE_COMMAND) {
                pfx__put(span + p, e->size, e->big, code);
            } else if (e->role != PFX__ROLE_CONTENT) {
                memset(span + p, 0, e->size);
            }
            p += sz;
            w.pe[k] = p;
        }
        for (k = 0u; k < L->count; k++) {
            if (L->e[k].role == PFX__ROLE_VALUE) {
                if (k >= L->t_first && k <= L->t_last) {
                    pfx__put(span + w.ps[k], L->e[k].size, L->e[k].big, values[v]);
                }
                v++;
            }
        }
        /*@inner_lengths@*/for (k = L->t_first; k <= L->t_last; k++) {
            const pfx__element_t *e = &L->e[k];
            if (e->role == PFX__ROLE_CHECKSUM) {
                bytes = span + w.ps[e->first];
                pfx__put(span + w.ps[k], e->size, e->big, pfx__check(e->check, bytes, w.pe[e->last] - w.ps[e->first]));
            }
        }
    }
#endif
    /* the wire bytes, element by element (the stuffed span rewritten as a whole) */
    v = 0u;
    for (k = 0u; k < L->count; k++) {
        const pfx__element_t *e = &L->e[k];
#if PFX__STUFFED
        if (PFX__T(L) && k == L->t_first) {
            size_t made;
            if (!pfx__rewrite(L, 1, span, w.pe[L->t_last], out + pos, NULL, cap - pos, &made)) {
                return PFX_E_BUFFER;
            }
            for (i = L->t_first; i <= L->t_last; i++) {
                w.ws[i] = pos;
                w.we[i] = pos + made;
            }
            for (i = L->t_first; i <= L->t_last; i++) {
                if (L->e[i].role == PFX__ROLE_VALUE) {
                    v++;
                }
            }
            pos += made;
            k = L->t_last;
            continue;
        }
#endif
        sz = e->role == PFX__ROLE_CONTENT ? clen : e->size;
        if (sz > cap - pos) {
            return PFX_E_BUFFER;
        }
        w.ws[k] = pos;
        if (e->role == PFX__ROLE_CONSTANT) {
            memcpy(out + pos, e->constant, e->size);
        } else if (e->role == PFX__ROLE_COMMAND) {
            pfx__put(out + pos, e->size, e->big, code);
        } else if (e->role == PFX__ROLE_VALUE) {
            pfx__put(out + pos, e->size, e->big, values[v++]);
        } else if (PFX__OPTIONAL && e->role == PFX__ROLE_EXTRA) {
            memcpy(out + pos, extras[e->first], e->size);
        } else if (e->role != PFX__ROLE_CONTENT) {
            memset(out + pos, 0, e->size);
        }
        pos += sz;
        w.we[k] = pos;
    }
    (void)first;
    (void)last;
    (void)extras;
    (void)i;
    /* lengths, then the checksums outside the stuffed span, over the wire bytes */
    for (k = 0u; k < L->count; k++) {
        const pfx__element_t *e = &L->e[k];
        if (e->role == PFX__ROLE_LENGTH/*@outer_length@*/) {
            int32_t value;
            uint32_t top = e->size >= 4u ? 0xFFFFFFFFu : ((uint32_t)1u << (8u * e->size)) - 1u;
            (void)pfx__range(L, &w, out, span, e->first, e->last, &sz);
            value = (int32_t)sz + e->adds;
            if (value < 0 || (uint32_t)value > top) {
                return PFX_E_LENGTH;
            }
            if ((uint32_t)value < e->minimum || (uint32_t)value > e->maximum) {
                return PFX_E_RANGE; /* outside its range */
            }
            pfx__put(out + w.ws[k], e->size, e->big, (uint32_t)value);
        }
    }
    for (k = 0u; k < L->count; k++) {
        const pfx__element_t *e = &L->e[k];
        if (e->role == PFX__ROLE_CHECKSUM && !(PFX__T(L) && k >= L->t_first && k <= L->t_last)) {
            bytes = pfx__range(L, &w, out, span, e->first, e->last, &sz);
            /*@skip@*/
            pfx__put(out + w.ws[k], e->size, e->big, pfx__check(e->check, bytes, sz));
        }
    }
    *len = pos;
    return PFX_OK;
}
#endif

#if PFX_ENABLE_DECODE && PFX__STUFFED
/* Check a complete frame (constants, values, lengths, stuffing, checksums) and take it apart: the frame engine's
 * unwrap (runtime/framing.py Layout.unwrap). plain: room for the unstuffed span. */
static int pfx__unwrap(const pfx__layout_t *L, const uint8_t *frame, size_t n, uint8_t *plain, uint32_t *code,
                       uint32_t *values, const uint8_t **content, size_t *clen)
{
    pfx__where_t w;
    size_t before = 0u, after = 0u, pos, sz;
    uint8_t k, v = 0u;
    uint8_t first = pfx__inner_first(L);
    int last = pfx__inner_last(L);
    const uint8_t *bytes;
    const uint8_t *body = frame;
    before = L->before;
    after = L->after;
    if (n < before + after) {
        return PFX_E_LENGTH;
    }
    pos = 0u;
    for (k = 0u; k < first; k++) {
        w.ws[k] = pos;
        pos += L->e[k].size;
        w.we[k] = pos;
    }
    pos = n;
    for (k = L->count; (int)k - 1 > last; k--) {
        w.we[k - 1u] = pos;
        pos -= L->e[k - 1u].size;
        w.ws[k - 1u] = pos;
    }
    if (PFX__T(L)) {
        size_t pn, fixed = 0u, p = 0u;
        if (!pfx__rewrite(L, 0, frame + before, n - before - after, plain, NULL, PFX_MAX_FRAME, &pn)) {
            return L->has_t >= 2u ? PFX_E_FRAME : PFX_E_CAPACITY; /* no form of the transform (never longer than it) */
        }
        if (!pfx__rewrite(L, 1, plain, pn, NULL, frame + before, n - before - after, &sz)) {
            return PFX_E_FRAME; /* bad stuffing: not the stuffed form of any bytes */
        }
        for (k = L->t_first; k <= L->t_last; k++) {
            fixed += L->e[k].size;
        }
        if ((L->content < (int)L->t_first || L->content > (int)L->t_last) ? pn != fixed : pn < fixed) {
            return PFX_E_LENGTH;
        }
        for (k = L->t_first; k <= L->t_last; k++) {
            w.ws[k] = before;
            w.we[k] = n - after;
            w.ps[k] = p;
            p += L->e[k].role == PFX__ROLE_CONTENT ? pn - fixed : L->e[k].size;
            w.pe[k] = p;
        }
        body = plain;
    } else if (L->content >= 0) {
        w.ws[L->content] = before;
        w.we[L->content] = n - after;
    }
    for (k = 0u; k < L->count; k++) {
        const pfx__element_t *e = &L->e[k];
        bytes = PFX__T(L) && k >= L->t_first && k <= L->t_last ? body + w.ps[k] : frame + w.ws[k];
        if (e->role == PFX__ROLE_CONSTANT && !pfx__same(bytes, e->constant, e->size)) {
            return PFX_E_FRAME;
        }
    }
    *code = 0u;
    for (k = 0u; k < L->count; k++) {
        const pfx__element_t *e = &L->e[k];
        bytes = PFX__T(L) && k >= L->t_first && k <= L->t_last ? body + w.ps[k] : frame + w.ws[k];
        if (e->role == PFX__ROLE_COMMAND) {
            *code = pfx__get(bytes, e->size, e->big);
        } else if (e->role == PFX__ROLE_VALUE) {
            uint32_t value = pfx__get(bytes, e->size, e->big);
            if (!(PFX__PLAUSIBLE(e, value))) {
                return PFX_E_RANGE;
            }
            values[v++] = value;
        }
    }
    for (k = 0u; k < L->count; k++) {
        const pfx__element_t *e = &L->e[k];
        if (e->role == PFX__ROLE_LENGTH) {
            bytes = PFX__T(L) && k >= L->t_first && k <= L->t_last ? body + w.ps[k] : frame + w.ws[k];
            uint32_t length = pfx__get(bytes, e->size, e->big);
            if (length < e->minimum || length > e->maximum) {
                return PFX_E_RANGE; /* outside its range: as the parser, which sees no frame there */
            }
            (void)pfx__range(L, &w, frame, body, e->first, e->last, &sz);
            if ((int32_t)length != (int32_t)sz + e->adds) {
                return PFX_E_LENGTH;
            }
        }
    }
    for (k = 0u; k < L->count; k++) {
        const pfx__element_t *e = &L->e[k];
        if (e->role == PFX__ROLE_CHECKSUM) {
            const uint8_t *stored = PFX__T(L) && k >= L->t_first && k <= L->t_last ? body + w.ps[k] : frame + w.ws[k];
            bytes = pfx__range(L, &w, frame, body, e->first, e->last, &sz);
            if (pfx__check(e->check, bytes, sz) != pfx__get(stored, e->size, e->big)) {
                return PFX_E_CHECKSUM;
            }
        }
    }
    if (L->content >= 0) {
        int inside = PFX__T(L) && L->content >= (int)L->t_first && L->content <= (int)L->t_last;
        *content = inside ? body + w.ps[L->content] : frame + w.ws[L->content];
        *clen = inside ? w.pe[L->content] - w.ps[L->content] : w.we[L->content] - w.ws[L->content];
    } else {
        *content = frame;
        *clen = 0u;
    }
    return PFX_OK;
}
#endif

/*@plain_prefix@*/#if PFX_ENABLE_PARSER && PFX__STUFFED
static int pfx__bounds(pfx_direction_t dir, long code, size_t *low, size_t *high, int *bounded);
#if PFX__SIZED
static long pfx__content_size(pfx_direction_t dir, long code, const uint8_t *c, size_t avail);
#endif

/* The size of a plausible frame of layout L at b[0..avail): PFX__WAIT for more bytes, PFX__NONE when none starts
 * there (runtime/framing.py FrameCodec.probe). */
static long pfx__probe(const pfx__layout_t *L, pfx_direction_t dir, const uint8_t *b, size_t avail)
{
    size_t pos = 0u, low = 0u, high = 0u, before = 0u;
    int bounded = 0;
    uint8_t k, first = pfx__inner_first(L);
    long code = PFX__NO_CODE;
    int refused = 0; /* the status's error bits set (`error_bits`): an error reply, whatever its code */
    if (avail < L->prefix) {
        return PFX__WAIT;
    }
    for (k = 0u; k < first; k++) {
        const pfx__element_t *e = &L->e[k];
        size_t stop = pos + e->size;
        if (avail < stop) {
            return PFX__WAIT;
        }
        if (e->role == PFX__ROLE_CONSTANT) {
            if (!pfx__same(b + pos, e->constant, e->size)) {
                return PFX__NONE;
            }
        } else if (e->role == PFX__ROLE_COMMAND) {
            uint32_t value = pfx__get(b + pos, e->size, e->big);
            /* (error_flag 0xFFFFFFFF: an error header's layout, every frame of it an error reply) */
            code = (L->error_flag == 0xFFFFFFFFu || (value & L->error_flag) != 0u) ? PFX__ERROR_CODE : (long)value;
            if (L->error_status < 0 && !pfx__bounds(dir, code, &low, &high, &bounded)) {
                return PFX__NONE;
            }
        } else if (e->role == PFX__ROLE_VALUE) {
            uint32_t value = pfx__get(b + pos, e->size, e->big);
            if (!(PFX__PLAUSIBLE(e, value))) {
                return PFX__NONE;
            }
            if ((int)k == (int)L->error_status && (value & L->error_bits) != 0u) {
                refused = 1;
            }
        }
        pos = stop;
    }
    if (L->error_status >= 0 && code != PFX__NO_CODE) { /* told by the status: its bounds, or the code's */
        code = refused ? PFX__ERROR_CODE : code;
        if (!pfx__bounds(dir, code, &low, &high, &bounded)) {
            return PFX__NONE;
        }
    }
    before = pos;
    if (L->command < 0) {
        if (!pfx__bounds(dir, PFX__NO_CODE, &low, &high, &bounded)) {
            return PFX__NONE;
        }
    } else if (code == PFX__NO_CODE) {
        low = 0u; /* the code lies in the stuffed span: no bounds before the frame is unstuffed */
        bounded = 0;
    }
    if (PFX__LENGTHS || L->length >= 0) {
        const pfx__element_t *e = &L->e[L->length];
        /*@inner_size@*/uint32_t length = pfx__get(b + L->length_off, e->size, e->big);
        long counted = (long)length - (long)e->adds;
        long content = counted - (long)L->counted;
        if (length < e->minimum || length > e->maximum) {
            return PFX__NONE; /* outside its range */
        }
        if (content < (long)low || (!PFX__T(L) && bounded && content > (long)high)) {
            return PFX__NONE;
        }
        return (long)(L->overhead - L->counted) + counted;
    }
    if (PFX__T(L) && L->e[L->count - 1u].role == PFX__ROLE_CONSTANT && L->count > 1u) {
        const pfx__element_t *t = &L->e[L->count - 1u];
        size_t i;
        long ended = pfx__span_end(L->has_t, b, before, avail);
        if (ended == PFX__WAIT) {
            return PFX__WAIT;
        }
        if (ended >= 0) {
            /* the transform tells where its span ends (runtime/framing.py _to_trailer): the trailer is right there */
            size_t at = (size_t)ended, have = avail - at < t->size ? avail - at : t->size;
            if (!pfx__same(b + at, t->constant, have)) {
                return PFX__NONE;
            }
            return have < t->size ? PFX__WAIT : (long)(at + t->size);
        }
        for (i = before; i + t->size <= avail; i++) {
            if (pfx__same(b + i, t->constant, t->size)) {
                return (long)(i + t->size);
            }
        }
        return PFX__WAIT;
    }
#if PFX__SIZED
    {
        /* no length: the content's size follows from its own leading fields (a size rule), by code */
        long size = pfx__content_size(dir, code, b + before, avail - before);
        if (size < 0) {
            return size;
        }
        if ((size_t)size < low || (bounded && (size_t)size > high)) {
            return PFX__NONE;
        }
        return (long)L->overhead + size;
    }
#else
    return PFX__NONE; /* no layout sized by its content: each one without a length ended at its trailer above */
#endif
}
#endif
"""

# A checksum over a span that leaves out elements (`skip`: HerkuleX's checksums inside their own span): the table's
# `minimum` of a checksum element holds them, one bit each, and wrap gathers the other elements' bytes. Put in place
# of the markers only where a layout has such a checksum (every other protocol's C stays as it was).
GATHER = r"""#if PFX_ENABLE_ENCODE
/* The bytes a checksum covers when its span leaves out elements (skip: e->minimum, one bit each), gathered into to
 * (room for PFX_MAX_FRAME bytes): the other elements' bytes as sent (runtime/framing.py Layout._covered). */
static int pfx__gather(const pfx__element_t *e, const pfx__where_t *w, const uint8_t *wire, uint8_t *to, size_t *n)
{
    size_t m = 0u, i;
    uint8_t k;
    for (k = e->first; k <= e->last; k++) {
        if (((e->minimum >> k) & 1u) != 0u) {
            continue;
        }
        if (w->we[k] - w->ws[k] > PFX_MAX_FRAME - m) {
            return 0;
        }
        for (i = w->ws[k]; i < w->we[k]; i++) {
            to[m++] = wire[i];
        }
    }
    *n = m;
    return 1;
}
#endif

"""
SKIP = r"""if (e->minimum != 0u) { /* a span that leaves out elements (skip) */
                if (!pfx__gather(e, &w, out, covered, &sz)) {
                    return PFX_E_BUFFER;
                }
                bytes = covered;
            }
            """
COVERED = "uint8_t covered[PFX_MAX_FRAME]; /* a checksum's bytes, its span less the elements it skips */\n    "
MARKERS = ("/*@gather@*/\n", "/*@skip@*/\n            ", "/*@covered@*/\n    ")


# A length inside the stuffed span that counts plain bytes (XBee API mode 2: the length escaped with the rest):
# made before the span is stuffed, and read by the parser through the substitution. Put in place of its markers only
# where a layout has one.
INNER_LENGTHS = r"""/* lengths inside the span count its plain bytes: made before it is stuffed */
        for (k = L->t_first; k <= L->t_last; k++) {
            const pfx__element_t *e = &L->e[k];
            if (e->role == PFX__ROLE_LENGTH) {
                int32_t value = (int32_t)(w.pe[e->last] - w.ps[e->first]) + e->adds;
                uint32_t top = e->size >= 4u ? 0xFFFFFFFFu : ((uint32_t)1u << (8u * e->size)) - 1u;
                if (value < 0 || (uint32_t)value > top) {
                    return PFX_E_LENGTH;
                }
                if ((uint32_t)value < e->minimum || (uint32_t)value > e->maximum) {
                    return PFX_E_RANGE; /* outside its range */
                }
                pfx__put(span + w.ps[k], e->size, e->big, (uint32_t)value);
            }
        }
        """
OUTER_LENGTH = " && !(PFX__T(L) && k >= L->t_first && k <= L->t_last)"
INNER_SIZE = r"""if (PFX__T(L) && e->first >= L->t_first && e->last <= L->t_last) {
            return pfx__inner_size(L, e, b, before, avail, low, high, bounded);
        }
        """
PLAIN_PREFIX = r"""#if PFX_ENABLE_PARSER && PFX__STUFFED
/* The wire bytes from b[start] on that give the first `count` plain bytes of the stuffed span (runtime/framing.py
 * Transparency.plain_prefix: at each position the first pair whose wire sequence is there, else the byte itself);
 * PFX__WAIT while a wire sequence may be cut off at avail. The plain bytes from index `from` on go to dst. */
static long pfx__plain_prefix(const pfx__layout_t *L, const uint8_t *b, size_t start, size_t avail, size_t count,
                              size_t from, uint8_t *dst)
{
    size_t n = 0u, pos = start, t;
    uint8_t k;
    /*@transform_prefix@*/while (n < count) {
        int matched = 0;
        if (pos >= avail) {
            return PFX__WAIT;
        }
        for (k = 0u; k < L->npairs && !matched; k++) {
            const pfx__pair_t *q = &L->pairs[k];
            if (q->wire_len <= avail - pos && pfx__same(b + pos, q->wire, q->wire_len)) {
                for (t = 0u; t < q->plain_len; t++, n++) {
                    if (n >= from && n < count) {
                        dst[n - from] = q->plain[t];
                    }
                }
                pos += q->wire_len;
                matched = 1;
            } else if (q->wire_len > avail - pos && pfx__same(b + pos, q->wire, avail - pos)) {
                return PFX__WAIT; /* the buffer may end inside this wire sequence */
            }
        }
        if (!matched) {
            if (n >= from) {
                dst[n - from] = b[pos];
            }
            n++;
            pos++;
        }
    }
    return (long)(pos - start);
}

/* The size of a frame whose length counts plain bytes inside the stuffed span (runtime/framing.py _inner_size): its
 * value read through the substitution where it lies inside the span, then as many plain bytes of the span. */
static long pfx__inner_size(const pfx__layout_t *L, const pfx__element_t *e, const uint8_t *b, size_t before,
                            size_t avail, size_t low, size_t high, int bounded)
{
    uint8_t value[4];
    size_t at = 0u, fixed = 0u;
    uint32_t length;
    long counted, content, used;
    uint8_t k;
    for (k = L->t_first; k <= L->t_last; k++) {
        if ((int)k < (int)L->length) {
            at += L->e[k].size;
        }
        fixed += L->e[k].size;
    }
    if ((int)L->length >= (int)L->t_first) {
        used = pfx__plain_prefix(L, b, before, avail, at + e->size, at, value);
        if (used < 0) {
            return used;
        }
        length = pfx__get(value, e->size, e->big);
    } else {
        length = pfx__get(b + L->length_off, e->size, e->big);
    }
    if (length < e->minimum || length > e->maximum) {
        return PFX__NONE; /* outside its range */
    }
    counted = (long)length - (long)e->adds;
    content = counted - (long)L->counted;
    if (content < (long)low || (bounded && content > (long)high)) {
        return PFX__NONE;
    }
    used = pfx__plain_prefix(L, b, before, avail, fixed - L->counted + (size_t)counted, (size_t)-1, value);
    if (used < 0) {
        return used;
    }
    return (long)before + used + (long)L->after;
}
#endif

"""
INNER_MARKERS = ("/*@inner_lengths@*/", "/*@outer_length@*/", "/*@inner_size@*/", "/*@plain_prefix@*/")


TRANSFORM_PREFIX = r"""if (L->has_t >= 2u) { /* a transform of its own C (serialspec/transforms/) */
        return pfx__transform_prefix(L->has_t, b, start, avail, count, from, dst);
    }
    """


def with_inner_lengths(engine: str, inner: bool, transformed: bool) -> str:
    """The engine with the code for lengths of plain bytes inside a stuffed span (inner; transformed: under a
    transform of its own C, not only substitution), or without it."""
    for marker, code in zip(INNER_MARKERS, (INNER_LENGTHS, OUTER_LENGTH, INNER_SIZE, PLAIN_PREFIX), strict=True):
        assert marker in engine
        engine = engine.replace(marker, code if inner else "")
    if inner:
        engine = engine.replace("/*@transform_prefix@*/", TRANSFORM_PREFIX if transformed else "")
    return engine


def with_skips(engine: str, skips: bool) -> str:
    """The engine with the code for checksums that skip elements (skips), or without it."""
    for marker, code in zip(MARKERS, (GATHER, SKIP, COVERED), strict=True):
        assert marker in engine
        engine = engine.replace(marker, code if skips else "")
    return engine


ENGINE = HEAD + GET + TAIL


# A reply checksum over bytes of its request (`from_request`): wrap takes the request's bytes (pre, pre_n; NULL: none
# given) and a checksum element whose has_also is set takes them in first. Put in only where a spec has one.
WRAP_SIGNATURE = "const uint32_t *values, const uint8_t *const *extras, size_t *len)"
WRAP_CHECKSUM = "pfx__put(out + w.ws[k], e->size, e->big, pfx__check(e->check, bytes, sz));"
TAKEN = r"""if (e->has_also) { /* the request's bytes first (`from_request`), then the span */
                uint8_t taken[PFX_REQUEST_BYTES + PFX_MAX_FRAME];
                size_t m = 0u, j;
                if (pre == NULL) {
                    return PFX_E_ARG; /* a reply whose checksum takes in its request's bytes: give the request */
                }
                if (sz > PFX_MAX_FRAME || pre_n > PFX_REQUEST_BYTES) {
                    return PFX_E_CAPACITY;
                }
                for (j = 0u; j < pre_n; j++) {
                    taken[m++] = pre[j];
                }
                for (j = 0u; j < sz; j++) {
                    taken[m++] = bytes[j];
                }
                pfx__put(out + w.ws[k], e->size, e->big, pfx__check(e->check, taken, m));
                continue;
            }
            """


def with_request(engine: str) -> str:
    """The engine whose wrap takes the request's bytes for reply checksums over them."""
    assert engine.count(WRAP_SIGNATURE) == 1 and engine.count(WRAP_CHECKSUM) == 1
    engine = engine.replace(
        WRAP_SIGNATURE, WRAP_SIGNATURE[:-1] + ",\n                     const uint8_t *pre, size_t pre_n)"
    )
    return engine.replace(WRAP_CHECKSUM, TAKEN + WRAP_CHECKSUM)
