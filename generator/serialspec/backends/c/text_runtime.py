"""The C every text protocol's .c carries (`framing: {kind: text}`): the field readers and writers, the sentence
cursor and the line parser, following serialspec.runtime.text (decode_field, encode_field, TextStreamParser).
PFX_/pfx_ stand for the protocol's prefix; text.py writes what is the spec's (messages, codes, letters, ranges).

The runtime is a row of pieces: a static helper function is a piece of its own that says which helpers it calls, so
text.py writes only the helpers its code calls (`used`), without reading the C it wrote."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass


@dataclass(frozen=True)
class Piece:
    """A stretch of the runtime's C. `name` "": always written; else it is the static function pfx__<name> (its
    comment, its definition and the blank lines after it), written only where code written calls it. `needs`: the
    helpers (pfx__<name>) the stretch calls."""

    text: str
    name: str = ""
    needs: tuple[str, ...] = ()


def used(pieces: Iterable[Piece], calls: Iterable[str]) -> set[str]:
    """The helpers called: by the code written around the pieces (`calls`), by the pieces always written, and by
    the helpers they call, to the end (-Wunused-function: no other is written)."""
    pieces = list(pieces)
    needs = {piece.name: piece.needs for piece in pieces if piece.name}
    todo = [*calls, *(name for piece in pieces if not piece.name for name in piece.needs)]
    found: set[str] = set()
    while todo:
        name = todo.pop()
        if name not in found:
            found.add(name)
            todo.extend(needs.get(name, ()))
    return found


def written(pieces: Iterable[Piece], helpers: set[str]) -> str:
    """The pieces' text, the helpers not in `helpers` left out."""
    return "".join(piece.text for piece in pieces if not piece.name or piece.name in helpers)


HEAD = (
    Piece(
        r"""/* ---- the text runtime (runtime/text.py, as C) ---- */

""",
        "",
        (),
    ),
    Piece(
        r"""static int64_t pfx__pow10(unsigned k)
{
    int64_t v = 1;
    while (k-- > 0u) {
        v *= 10;
    }
    return v;
}

""",
        "pow10",
        (),
    ),
    Piece(
        r"""#if PFX_ENABLE_DECODE
""",
        "",
        (),
    ),
    Piece(
        r"""static int pfx__digit(uint8_t c)
{
    return c >= 0x30u && c <= 0x39u;
}
""",
        "digit",
        (),
    ),
    Piece(
        r"""#endif

/* The fields of a sentence one after another: pos is where the next one starts; more is 0 after the last; sep and
 * list end a field (the framing's separator, or a message's own separator and list character). */
typedef struct {
    const uint8_t *b;
    size_t n;
    size_t pos;
    int more;
    uint8_t sep;
    uint8_t list;
} pfx__cursor_t;

#if PFX_ENABLE_DECODE
""",
        "",
        (),
    ),
    Piece(
        r"""/* The next field (start and length), or an empty one past the last field the sentence has. */
static void pfx__next(pfx__cursor_t *c, size_t *start, size_t *len)
{
    size_t i = c->pos;
    if (!c->more) {
        *start = c->n;
        *len = 0u;
        return;
    }
    while (i < c->n && c->b[i] != c->sep && c->b[i] != c->list) {
        i++;
    }
    *start = c->pos;
    *len = i - c->pos;
    c->more = i < c->n;
    c->pos = i < c->n ? i + 1u : i;
}

""",
        "next",
        (),
    ),
    Piece(
        r"""/* A message found by its code alone (runtime/text.py TextFraming._decode_alone): 1 when t[0..n) starts with
 * code[0..k) and the rest is empty or starts with after[0..a) and ends with end[0..e); its fields are then
 * t[*at, *at + *len). */
static int pfx__alone(const uint8_t *t, size_t n, const char *code, size_t k, const char *after, size_t a,
                      const char *end, size_t e, size_t *at, size_t *len)
{
    size_t i;
    if (n < k) {
        return 0;
    }
    for (i = 0u; i < k; i++) {
        if (t[i] != (uint8_t)code[i]) {
            return 0;
        }
    }
    if (n == k) {
        *at = k;
        *len = 0u;
        return 1;
    }
    if (n - k < a || n - k < e) {
        return 0;
    }
    for (i = 0u; i < a; i++) {
        if (t[k + i] != (uint8_t)after[i]) {
            return 0;
        }
    }
    for (i = 0u; i < e; i++) {
        if (t[n - e + i] != (uint8_t)end[i]) {
            return 0;
        }
    }
    *at = k + a;
    *len = n - k >= a + e ? n - k - a - e : 0u;
    return 1;
}

""",
        "alone",
        (),
    ),
    Piece(
        r"""/* A text to the end of the line (`size: rest`): the rest of the sentence, separators included. */
static void pfx__rest(pfx__cursor_t *c, size_t *start, size_t *len)
{
    *start = c->more ? c->pos : c->n;
    *len = c->n - *start;
    c->more = 0;
    c->pos = c->n;
}

""",
        "rest",
        (),
    ),
    Piece(
        r"""/* The next labelled value of a message's own text (runtime/text.py _decode_labelled, _glued): the index
 * of its label in labels[0..count) (the longest first) and its text [*start, *start + *len); PFX_E_CONTENT for a
 * part with no label of them. named: the character between label and value (0: the label glued to it, the
 * longest it begins with); sep 0: no separator, each value the run of number characters after its label (LSS's
 * `D1800T1500`). */
static int pfx__pair(pfx__cursor_t *c, uint8_t named, int sep, const char *const *labels, size_t count,
                     size_t *which, size_t *start, size_t *len)
{
    size_t s = c->pos, n = c->n - c->pos, k = 0u, i;
    if (sep) {
        pfx__next(c, &s, &n);
    }
    if (named != 0u) {
        while (k < n && c->b[s + k] != named) {
            k++;
        }
        if (k == n) {
            return PFX_E_CONTENT; /* no label */
        }
    }
    for (i = 0u; i < count; i++) {
        size_t m = 0u;
        while (labels[i][m] != '\0' && m < n && c->b[s + m] == (uint8_t)labels[i][m]) {
            m++;
        }
        if (labels[i][m] == '\0' && (named == 0u || m == k)) {
            k = m;
            break;
        }
    }
    if (i == count) {
        return PFX_E_CONTENT; /* an unknown label */
    }
    *which = i;
    *start = s + k + (named != 0u ? 1u : 0u);
    *len = s + n - *start;
    if (!sep) { /* the number ends where a label begins */
        for (k = *start; k < c->n; k++) {
            uint8_t b = c->b[k];
            if (!((b >= 0x30u && b <= 0x39u) || b == 0x2Bu || b == 0x2Du || b == 0x2Eu)) {
                break;
            }
        }
        *len = k - *start;
        c->pos = k;
        c->more = k < c->n;
    }
    return PFX_OK;
}

""",
        "pair",
        ("next",),
    ),
    Piece(
        "/* Digits d[0..n) as a number (at most 18 digits: PFX_E_CAPACITY beyond, "
        r"""a number an int64_t may not hold). */
static int pfx__digits(const uint8_t *d, size_t n, int64_t *out)
{
    int64_t v = 0;
    size_t i;
    if (n > 18u) {
        return PFX_E_CAPACITY;
    }
    for (i = 0u; i < n; i++) {
        v = v * 10 + (int64_t)(d[i] - 0x30u);
    }
    *out = v;
    return PFX_OK;
}

""",
        "digits",
        (),
    ),
    Piece(
        r"""/* decimal: [+-]?(digits[.digits]|.digits), its digits kept (runtime/text.py Fixed). */
static int pfx__get_decimal(const uint8_t *t, size_t n, pfx_decimal_t *out)
{
    size_t i = 0u, whole, point, fraction;
    int64_t a = 0, b = 0, scale = 1;
    int r;
    out->negative = false;
    if (i < n && (t[i] == 0x2Bu || t[i] == 0x2Du)) {
        out->negative = t[i] == 0x2Du;
        i++;
    }
    whole = i;
    while (i < n && pfx__digit(t[i])) {
        i++;
    }
    point = i;
    if (i < n && t[i] == 0x2Eu) {
        i++;
    }
    fraction = i;
    while (i < n && pfx__digit(t[i])) {
        i++;
    }
    if (i != n || (point == whole && (fraction == point || fraction == n))) {
        return PFX_E_CONTENT;
    }
    if (point - whole + (n - fraction) > 18u) {
        return PFX_E_CAPACITY;
    }
    r = pfx__digits(t + whole, point - whole, &a);
    if (r == PFX_OK) {
        r = pfx__digits(t + fraction, n - fraction, &b);
    }
    for (i = fraction; i < n; i++) {
        scale *= 10;
    }
    out->value = (a * scale + b) * (out->negative ? -1 : 1);
    out->scale = (uint8_t)(n - fraction);
    out->width = (uint8_t)(point - whole);
    return r;
}

""",
        "get_decimal",
        ("digit", "digits"),
    ),
    Piece(
        r"""/* integer: [+-]?digits. */
static int pfx__get_integer(const uint8_t *t, size_t n, int64_t *out)
{
    size_t i = 0u, first;
    int r;
    if (n > 0u && (t[0] == 0x2Bu || t[0] == 0x2Du)) {
        i = 1u;
    }
    first = i;
    while (i < n && pfx__digit(t[i])) {
        i++;
    }
    if (i != n || i == first) {
        return PFX_E_CONTENT;
    }
    r = pfx__digits(t + first, n - first, out);
    if (first == 1u && t[0] == 0x2Du) {
        *out = -*out;
    }
    return r;
}

""",
        "get_integer",
        ("digit", "digits"),
    ),
    Piece(
        r"""/* integer in hex digits, either case: [+-]?[0-9A-Fa-f]+ (at most 15 digits: PFX_E_CAPACITY beyond). */
static int pfx__get_hex_integer(const uint8_t *t, size_t n, int64_t *out)
{
    size_t i = 0u, first;
    int64_t v = 0;
    if (n > 0u && (t[0] == 0x2Bu || t[0] == 0x2Du)) {
        i = 1u;
    }
    first = i;
    for (; i < n; i++) {
        uint8_t c = t[i];
        if (!((c >= 0x30u && c <= 0x39u) || (c >= 0x41u && c <= 0x46u) || (c >= 0x61u && c <= 0x66u))) {
            return PFX_E_CONTENT;
        }
    }
    if (n == first) {
        return PFX_E_CONTENT;
    }
    if (n - first > 15u) {
        return PFX_E_CAPACITY;
    }
    for (i = first; i < n; i++) {
        uint8_t c = t[i];
        v = v * 16 + (int64_t)(c <= 0x39u ? c - 0x30u : (c | 0x20u) - 0x57u);
    }
    *out = first == 1u && t[0] == 0x2Du ? -v : v;
    return PFX_OK;
}

""",
        "get_hex_integer",
        (),
    ),
    Piece(
        r"""/* angle: 1..width digits of degrees, two of minutes, [.digits]; minutes below 60. */
static int pfx__get_angle(const uint8_t *t, size_t n, unsigned width, pfx_angle_t *out)
{
    size_t k = 0u;
    int64_t degrees = 0;
    int r;
    while (k < n && pfx__digit(t[k])) {
        k++;
    }
    if (k < 3u || k > width + 2u || (k < n && t[k] != 0x2Eu)) {
        return PFX_E_CONTENT;
    }
    r = pfx__get_decimal(t + k - 2u, n - (k - 2u), &out->minutes);
    if (r != PFX_OK) {
        return r;
    }
    if (out->minutes.value >= 60 * pfx__pow10(out->minutes.scale)) {
        return PFX_E_CONTENT;
    }
    r = pfx__digits(t, k - 2u, &degrees);
    out->degrees = (uint32_t)degrees;
    return r;
}

""",
        "get_angle",
        ("digit", "get_decimal", "pow10", "digits"),
    ),
    Piece(
        r"""/* time: hhmmss[.digits], a valid time of day; the fraction's first 6 digits kept as microseconds. */
static int pfx__get_time(const uint8_t *t, size_t n, pfx_time_t *out)
{
    size_t i;
    uint32_t micro = 0u, scale = 100000u;
    for (i = 0u; i < 6u; i++) {
        if (i >= n || !pfx__digit(t[i])) {
            return PFX_E_CONTENT;
        }
    }
    if (n > 6u && t[6] != 0x2Eu) {
        return PFX_E_CONTENT;
    }
    for (i = 7u; i < n; i++) {
        if (!pfx__digit(t[i])) {
            return PFX_E_CONTENT;
        }
        micro += (uint32_t)(t[i] - 0x30u) * scale;
        scale /= 10u;
    }
    out->hour = (uint8_t)((t[0] - 0x30u) * 10u + (t[1] - 0x30u));
    out->minute = (uint8_t)((t[2] - 0x30u) * 10u + (t[3] - 0x30u));
    out->second = (uint8_t)((t[4] - 0x30u) * 10u + (t[5] - 0x30u));
    out->micro = micro;
    out->digits = (uint16_t)(n > 7u ? n - 7u : 0u);
    if (n > 0xFFFFu + 7u || out->hour > 23u || out->minute > 59u || out->second > 59u) {
        return PFX_E_CONTENT;
    }
    return PFX_OK;
}
""",
        "get_time",
        ("digit",),
    ),
    Piece(
        r"""#endif

""",
        "",
        (),
    ),
    Piece(
        r"""/* The days of a month (Gregorian). */
static unsigned pfx__days(unsigned month, unsigned year)
{
    static const uint8_t days[12] = {31u, 28u, 31u, 30u, 31u, 30u, 31u, 31u, 30u, 31u, 30u, 31u};
    int leap = (year % 4u == 0u && year % 100u != 0u) || year % 400u == 0u;
    return month == 2u && leap ? 29u : days[month - 1u];
}

""",
        "days",
        (),
    ),
    Piece(
        r"""#if PFX_ENABLE_DECODE
""",
        "",
        (),
    ),
    Piece(
        r"""/* date: ddmmyy, a valid date; yy 69..99 is 1969..1999, 00..68 2000..2068 (as strptime's %y). */
static int pfx__get_date(const uint8_t *t, size_t n, pfx_date_t *out)
{
    size_t i;
    unsigned yy;
    if (n != 6u) {
        return PFX_E_CONTENT;
    }
    for (i = 0u; i < 6u; i++) {
        if (!pfx__digit(t[i])) {
            return PFX_E_CONTENT;
        }
    }
    out->day = (uint8_t)((t[0] - 0x30u) * 10u + (t[1] - 0x30u));
    out->month = (uint8_t)((t[2] - 0x30u) * 10u + (t[3] - 0x30u));
    yy = (unsigned)((t[4] - 0x30u) * 10u + (t[5] - 0x30u));
    out->year = (uint16_t)(yy < 69u ? 2000u + yy : 1900u + yy);
    if (out->month < 1u || out->month > 12u || out->day < 1u || out->day > pfx__days(out->month, out->year)) {
        return PFX_E_CONTENT;
    }
    return PFX_OK;
}

""",
        "get_date",
        ("digit", "days"),
    ),
    Piece(
        r"""/* char: one character. */
static int pfx__get_char(const uint8_t *t, size_t n, char *out)
{
    if (n != 1u) {
        return PFX_E_CONTENT;
    }
    *out = (char)t[0];
    return PFX_OK;
}

""",
        "get_char",
        (),
    ),
    Piece(
        r"""/* text: the characters as sent (PFX_E_CAPACITY past cap). */
static int pfx__get_text(const uint8_t *t, size_t n, char *out, size_t cap, uint16_t *len)
{
    size_t i;
    if (n > cap) {
        return PFX_E_CAPACITY;
    }
    for (i = 0u; i < n; i++) {
        out[i] = (char)t[i];
    }
    *len = (uint16_t)n;
    return PFX_OK;
}
""",
        "get_text",
        (),
    ),
    Piece(
        r"""#endif

/* ---- writing: the text of each kind, as runtime/text.py encode_field writes it ---- */

typedef struct {
    uint8_t *b;
    size_t cap;
    size_t n;
    int full;    /* something did not fit */
    size_t rest; /* where a text to the end of the line begins (0: none; the separators in it are its own) */
} pfx__out_t;

""",
        "",
        (),
    ),
    Piece(
        r"""static void pfx__put(pfx__out_t *o, uint8_t c)
{
    if (o->n < o->cap) {
        o->b[o->n++] = c;
    } else {
        o->full = 1;
    }
}

""",
        "put",
        (),
    ),
    Piece(
        r"""/* Between the parts of a message in its own layout: `c` before every part but the first. */
static void pfx__part(pfx__out_t *o, int *first, uint8_t c)
{
    if (!*first) {
        pfx__put(o, c);
    }
    *first = 0;
}

""",
        "part",
        ("put",),
    ),
    Piece(
        r"""/* v's decimal digits, at least `width` (zeros in front). */
static void pfx__put_digits(pfx__out_t *o, uint64_t v, unsigned width)
{
    uint8_t d[20];
    unsigned k = 0u;
    do {
        d[k++] = (uint8_t)(0x30u + (unsigned)(v % 10u));
        v /= 10u;
    } while (v > 0u);
    while (width > k) {
        pfx__put(o, 0x30u);
        width--;
    }
    while (k > 0u) {
        pfx__put(o, d[--k]);
    }
}

""",
        "put_digits",
        ("put",),
    ),
    Piece(
        r"""static uint64_t pfx__magnitude(int64_t v)
{
    return v < 0 ? (uint64_t)(-(v + 1)) + 1u : (uint64_t)v;
}

""",
        "magnitude",
        (),
    ),
    Piece(
        r"""static void pfx__put_integer(pfx__out_t *o, int64_t v, unsigned width)
{
    if (v < 0) {
        pfx__put(o, 0x2Du);
    }
    pfx__put_digits(o, pfx__magnitude(v), width);
}

""",
        "put_integer",
        ("put", "put_digits", "magnitude"),
    ),
    Piece(
        r"""/* integer in hex digits, zero-padded to width digits, upper case (lower: lower case). */
static void pfx__put_hex_integer(pfx__out_t *o, int64_t v, unsigned width, unsigned lower)
{
    uint8_t d[16];
    unsigned k = 0u;
    uint64_t m = pfx__magnitude(v);
    if (v < 0) {
        pfx__put(o, 0x2Du);
    }
    do {
        unsigned x = (unsigned)(m & 0xFu);
        d[k++] = (uint8_t)(x < 10u ? 0x30u + x : (lower ? 0x57u : 0x37u) + x);
        m >>= 4;
    } while (m > 0u);
    while (width > k) {
        pfx__put(o, 0x30u);
        width--;
    }
    while (k > 0u) {
        pfx__put(o, d[--k]);
    }
}

""",
        "put_hex_integer",
        ("put", "magnitude"),
    ),
    Piece(
        r"""static void pfx__put_decimal(pfx__out_t *o, const pfx_decimal_t *d, unsigned width)
{
    uint64_t m = pfx__magnitude(d->value), scale = 1u;
    unsigned i;
    for (i = 0u; i < d->scale && i < 19u; i++) {
        scale *= 10u;
    }
    if (d->value < 0 || (d->value == 0 && d->negative)) {
        pfx__put(o, 0x2Du);
    }
    pfx__put_digits(o, m / scale, width);
    if (d->scale > 0u) {
        pfx__put(o, 0x2Eu);
        pfx__put_digits(o, m % scale, d->scale);
    }
}

""",
        "put_decimal",
        ("magnitude", "put", "put_digits"),
    ),
    Piece(
        r"""static void pfx__put_angle(pfx__out_t *o, const pfx_angle_t *a, unsigned width)
{
    pfx__put_digits(o, a->degrees, width);
    pfx__put_decimal(o, &a->minutes, 2u);
}

""",
        "put_angle",
        ("put_digits", "put_decimal"),
    ),
    Piece(
        r"""static void pfx__put_time(pfx__out_t *o, const pfx_time_t *t)
{
    unsigned i;
    uint32_t scale = 100000u;
    pfx__put_digits(o, t->hour, 2u);
    pfx__put_digits(o, t->minute, 2u);
    pfx__put_digits(o, t->second, 2u);
    if (t->digits > 0u) {
        pfx__put(o, 0x2Eu);
    }
    for (i = 0u; i < t->digits; i++) {
        pfx__put(o, i < 6u ? (uint8_t)(0x30u + t->micro / scale % 10u) : 0x30u);
        scale /= 10u;
    }
}

""",
        "put_time",
        ("put_digits", "put"),
    ),
    Piece(
        r"""static void pfx__put_date(pfx__out_t *o, const pfx_date_t *d)
{
    pfx__put_digits(o, d->day, 2u);
    pfx__put_digits(o, d->month, 2u);
    pfx__put_digits(o, d->year % 100u, 2u);
}

""",
        "put_date",
        ("put_digits",),
    ),
    Piece(
        r"""static void pfx__put_text(pfx__out_t *o, const char *t, size_t n)
{
    size_t i;
    for (i = 0u; i < n; i++) {
        pfx__put(o, (uint8_t)t[i]);
    }
}

""",
        "put_text",
        ("put",),
    ),
    Piece(
        r"""/* ---- range checks (encode refuses with PFX_E_RANGE before a byte is written) ---- */

""",
        "",
        (),
    ),
    Piece(
        "/* a / 10^as compared with b / 10^bs: -1, 0 or 1 (exact; "
        r"""a scaled value that overflows is the larger in size). */
static int pfx__compare(int64_t a, unsigned as, int64_t b, unsigned bs)
{
    while (as < bs) {
        if (a > INT64_MAX / 10 || a < INT64_MIN / 10) {
            return a < 0 ? -1 : 1;
        }
        a *= 10;
        as++;
    }
    while (bs < as) {
        if (b > INT64_MAX / 10 || b < INT64_MIN / 10) {
            return b < 0 ? 1 : -1;
        }
        b *= 10;
        bs++;
    }
    return a < b ? -1 : a > b ? 1 : 0;
}

""",
        "compare",
        (),
    ),
    Piece(
        r"""static int pfx__time_ok(const pfx_time_t *t)
{
    return t->hour < 24u && t->minute < 60u && t->second < 60u && t->micro < 1000000u;
}

""",
        "time_ok",
        (),
    ),
    Piece(
        r"""static int pfx__date_ok(const pfx_date_t *d)
{
    return d->year >= 1u && d->year <= 9999u && d->month >= 1u && d->month <= 12u && d->day >= 1u &&
           d->day <= pfx__days(d->month, d->year);
}

""",
        "date_ok",
        ("days",),
    ),
    Piece(
        r"""/* A character a text frame can carry in a field: printable ASCII, none of the framing's own characters. */
static int pfx__carried(char c)
{
    return c >= 0x20 && c <= 0x7E && !pfx__special((uint8_t)c);
}

""",
        "carried",
        ("special",),
    ),
    Piece(
        r"""static int pfx__text_ok(const char *t, size_t n)
{
    size_t i;
    for (i = 0u; i < n; i++) {
        if (!pfx__carried(t[i])) {
            return 0;
        }
    }
    return 1;
}

""",
        "text_ok",
        ("carried",),
    ),
    Piece(
        r"""/* A text to the end of the line: printable ASCII, none of the framing's characters but its separator. */
static int pfx__rest_ok(const char *t, size_t n)
{
    size_t i;
    for (i = 0u; i < n; i++) {
        if (t[i] < 0x20 || t[i] > 0x7E || (pfx__special((uint8_t)t[i]) && (uint8_t)t[i] != PFX__SEPARATOR)) {
            return 0;
        }
    }
    return 1;
}

""",
        "rest_ok",
        ("special",),
    ),
    Piece(
        r"""/* 1 when none of t[0..n) is one of a message's own characters `own` (its layout's). */
static int pfx__avoids(const char *t, size_t n, const char *own)
{
    size_t i, k;
    for (i = 0u; i < n; i++) {
        for (k = 0u; own[k] != '\0'; k++) {
            if (t[i] == own[k]) {
                return 0;
            }
        }
    }
    return 1;
}

""",
        "avoids",
        (),
    ),
    Piece(
        r"""/* A decimal angle (degrees + minutes / 60) for the range check, as runtime/text.py's float. */
static double pfx__angle_value(const pfx_angle_t *a)
{
    const int64_t unit = pfx__pow10(a->minutes.scale); /* not cast in place: -Wbad-function-cast */
    return (double)a->degrees + (double)a->minutes.value / (double)unit / 60.0;
}

""",
        "angle_value",
        ("pow10",),
    ),
    Piece(
        r"""/* ---- the frame: start, address, fields, checksum after the marker, end ---- */

#if PFX_ENABLE_DECODE
""",
        "",
        (),
    ),
    Piece(
        r"""static int pfx__hex_value(uint8_t c)
{
    if (c >= 0x30u && c <= 0x39u) {
        return (int)c - 0x30;
    }
    if (c >= 0x41u && c <= 0x46u) {
        return (int)c - 0x37;
    }
    if (c >= 0x61u && c <= 0x66u) {
        return (int)c - 0x57;
    }
    return -1;
}

""",
        "hex_value",
        (),
    ),
    Piece(
        r"""/* The fields between start and marker (or end): [*body, *body + *n), the checksum checked where `check`;
 * PFX_E_FRAME, PFX_E_CHECKSUM. *unchecked: 1 for a frame without its (optional) checksum. `dir`: the line ending
 * taken off; where its frames write the separator before the marker, it is no part of the fields. */
static int pfx__unframe(const uint8_t *f, size_t len, pfx_direction_t dir, int check, size_t *body, size_t *n,
                        int *unchecked)
{
    size_t i, end = len, stop, ascii, own = PFX__END_LEN(dir), other = PFX__END_LEN(PFX__OTHER(dir));
    *unchecked = 0;
    (void)dir;
    (void)check;
    if (len >= own && pfx__same(f + len - own, PFX__END(dir), own)) {
        end = len - own; /* the direction's line ending */
    }
    ascii = end; /* before the longest line ending of either direction the frame ends with */
    if (len >= other && other > len - end && pfx__same(f + len - other, PFX__END(PFX__OTHER(dir)), other)) {
        ascii = len - other;
    }
    for (i = 0u; i < ascii; i++) { /* (the line ending may hold bytes above 0x7F: Nextion's FF FF FF) */
        if (f[i] > 0x7Fu) {
            return PFX_E_FRAME; /* a non-ASCII byte */
        }
    }
#if PFX__S
    if (end < 1u || f[0] != PFX__START_OF(dir)) { /* the direction's start */
        return PFX_E_FRAME;
    }
#endif
    stop = end;
""",
        "",
        ("unframe", "same"),
    ),
)

# the checksum read and written where the protocol has one (text.py leaves them out otherwise)
_CHECKED_READ = Piece(
    r"""#if PFX__CHECKED
    if (check) {
        size_t at = end, k;
        uint32_t written = 0u;
        while (at > PFX__S && f[at - 1u] != PFX__MARKER) {
            at--;
        }
        if (at > PFX__S) {
@DIGITS_READ@            stop = at - 1u;
            if (written != pfx__checksum(f + PFX__S, stop - PFX__S)) {
                return PFX_E_CHECKSUM;
            }
            if (PFX__SEPARATED(dir) && stop > PFX__S && f[stop - 1u] == PFX__SEPARATOR) {
                stop--; /* the separator before the marker, covered by the checksum */
            }
        } else if (PFX__REQUIRED) {
            return PFX_E_CHECKSUM;
        } else {
            *unchecked = 1;
        }
    }
#endif
""",
    needs=("hex_value", "checksum"),
)

HEX_READ = """            if (end - at != PFX__DIGITS) {
                return PFX_E_CHECKSUM;
            }
            for (k = at; k < end; k++) {
                int v = pfx__hex_value(f[k]);
                if (v < 0) {
                    return PFX_E_CHECKSUM;
                }
                written = (written << 4) | (uint32_t)v;
            }
"""
DECIMAL_READ = """            if (end - at < 1u || end - at > 3u) { /* 1 to 3 decimal digits */
                return PFX_E_CHECKSUM;
            }
            for (k = at; k < end; k++) {
                if (f[k] < 0x30u || f[k] > 0x39u) {
                    return PFX_E_CHECKSUM;
                }
                written = written * 10u + (uint32_t)(f[k] - 0x30u);
            }
"""
CHECKED_READ = Piece(_CHECKED_READ.text.replace("@DIGITS_READ@", HEX_READ), needs=("hex_value", "checksum"))
DECIMAL_CHECKED_READ = Piece(_CHECKED_READ.text.replace("@DIGITS_READ@", DECIMAL_READ), needs=("checksum",))

MIDDLE = Piece(
    r"""    *body = PFX__S;
    *n = stop - PFX__S;
    return PFX_OK;
}
#endif

#if PFX_ENABLE_ENCODE
/* Exactly `sent` fields after the address (o->b[PFX__S..n): the address, then each field after a separator): the fields
 * after the last one sent must be empty (PFX_E_LENGTH), missing ones are written empty. A text to the end of the line
 * (from o->rest on) is one field, the separators in it its own. */
static int pfx__trim(pfx__out_t *o, size_t sent)
{
    size_t i, k, fields = 0u, rest = o->rest > 0u ? o->rest : o->n;
    for (i = PFX__S; i < rest; i++) {
        if (o->b[i] == PFX__SEPARATOR && ++fields > sent) {
            break;
        }
    }
    if (fields > sent) {
        for (k = i; k < o->n; k++) {
            if (o->b[k] != PFX__SEPARATOR || k >= rest) {
                return PFX_E_LENGTH; /* a field after the last one sent has a value */
            }
        }
        o->n = i;
    }
    while (fields < sent) {
        pfx__put(o, PFX__SEPARATOR);
        fields++;
    }
    return PFX_OK;
}

/* The frame around fields already written from buf[PFX__S]: the start before them, checksum (unless `unchecked`: a
 * frame decoded without its optional one) and end after them. */
static int pfx__frame(pfx__out_t *o, size_t *len, bool unchecked, int separated, pfx_direction_t dir)
{
    size_t k;
    (void)separated;
    (void)dir;
#if PFX__S
    o->b[0] = PFX__START_OF(dir);
#endif
    (void)unchecked;
""",
    needs=("trim", "put", "frame"),
)

_CHECKED_WRITE = Piece(
    r"""#if PFX__CHECKED
    if ((!unchecked || PFX__REQUIRED) && PFX__CHECKS(dir)) {
        uint32_t sum;
        if (separated) { /* the separator before the marker, covered by the checksum */
            pfx__put(o, PFX__SEPARATOR);
        }
        sum = pfx__checksum(o->b + PFX__S, o->n - PFX__S);
        pfx__put(o, PFX__MARKER);
@DIGITS_WRITE@    }
#endif
""",
    needs=("checksum", "put"),
)

HEX_WRITE = """        for (k = PFX__DIGITS; k > 0u; k--) {
            uint32_t nibble = (sum >> (4u * (k - 1u))) & 0xFu;
            pfx__put(o, (uint8_t)(nibble < 10u ? 0x30u + nibble : 0x37u + nibble));
        }
"""
DECIMAL_WRITE = """        for (k = 0u; k == 0u || sum > 0u; k++) { /* decimal digits, backwards */
            digits[k] = (uint8_t)(0x30u + sum % 10u);
            sum /= 10u;
        }
        while (k > 0u) {
            pfx__put(o, digits[--k]);
        }
"""
CHECKED_WRITE = Piece(_CHECKED_WRITE.text.replace("@DIGITS_WRITE@", HEX_WRITE), needs=("checksum", "put"))
DECIMAL_CHECKED_WRITE = Piece(
    _CHECKED_WRITE.text.replace("@DIGITS_WRITE@", DECIMAL_WRITE).replace(
        "        uint32_t sum;\n", "        uint32_t sum;\n        uint8_t digits[10];\n"
    ),
    needs=("checksum", "put"),
)

BEFORE_PARSER = Piece(
    r"""    for (k = 0u; k < PFX__END_LEN(dir); k++) {
        pfx__put(o, PFX__END(dir)[k]);
    }
    if (o->full) {
        return PFX_E_BUFFER;
    }
    *len = o->n;
    return PFX_OK;
}
#endif

""",
    needs=("put",),
)

# the line parser (text.py writes one of the two pushes, then PARSER, after the messages' code)
START_PUSH = Piece(
    r"""#if PFX_ENABLE_PARSER
/* Where a start (of either direction) is in b[from..n), n if nowhere. */
static size_t pfx__find(const uint8_t *b, size_t from, size_t n)
{
    while (from < n && !PFX__IS_START(b[from])) {
        from++;
    }
    return from;
}

/* Where the line ending of `dir` is in b[from..n), n if nowhere. */
static size_t pfx__find_end(const uint8_t *b, size_t from, size_t n, pfx_direction_t dir)
{
    size_t k = PFX__END_LEN(dir);
    (void)dir;
    for (; from + k <= n; from++) {
        if (pfx__same(b + from, PFX__END(dir), k)) {
            return from;
        }
    }
    return n;
}

static void pfx__drop(pfx_parser_t *p, size_t k)
{
    size_t i;
    for (i = k; i < p->n; i++) {
        p->buf[i - k] = p->buf[i];
    }
    p->n -= k;
}

/* One byte in: runtime/text.py TextStreamParser.feed of that byte. A frame cut short by a new start, or longer
 * than the spec's max_length, is dropped (counted in errors), as is one that does not decode. */
static int pfx__push(pfx_parser_t *p, uint8_t byte, pfx_msg_t *out)
{
    const size_t limit = PFX__LIMIT(p->dir), k = PFX__END_LEN(p->dir);
    if (p->n < limit + 1u) {
        p->buf[p->n++] = byte;
    }
    for (;;) {
        size_t start = pfx__find(p->buf, 0u, p->n), end, restart;
        if (start == p->n) {
            p->n = 0u;
            return 0;
        }
        pfx__drop(p, start);
        end = pfx__find_end(p->buf, 1u, p->n, p->dir);
        restart = pfx__find(p->buf, 1u, p->n);
        if (end == p->n || restart < end) {
            if (restart < p->n) {
                p->errors++;
                pfx__drop(p, restart);
                continue;
            }
            if (p->n > limit) {
                p->errors++;
                pfx__drop(p, 1u);
                continue;
            }
            return 0;
        }
        {
            int r = pfx__decode(p->buf, end + k, p->dir, PFX_KIND_NONE, PFX__REPLY(p), out);
            pfx__drop(p, end + k);
            if (r == PFX_OK) {
                PFX__ANSWERED(p, out);
                p->frames++;
                p->frame = p->buf; /* it ends with the byte just pushed: nothing held after it */
                p->frame_len = end + k;
                return 1;
            }
            p->errors++;
            if (r == PFX_E_UNKNOWN && p->n == 0u) { /* a good checksum, an unknown code: still in the buffer */
                p->unknown++;
                p->frame = p->buf;
                p->frame_len = end + k;
                return 2;
            }
        }
    }
}

void pfx_parser_gap(pfx_parser_t *parser)
{
    if (parser->n > 0u) { /* it begins with a start character */
        parser->errors++;
    }
    parser->n = 0u;
}

""",
    needs=("same", "decode"),
)

LINES_PUSH = Piece(
    r"""#if PFX_ENABLE_PARSER
/* One byte in: runtime/text.py TextStreamParser.feed of that byte, for frames without a start character (its
 * _lines: every line a frame). A line longer than the spec's max_length is dropped to its end (counted in errors);
 * a blank line is skipped; CR and LF before a line (the rest of a longer line ending) are not part of it; a line
 * that does not decode is dropped. */
static int pfx__push(pfx_parser_t *p, uint8_t byte, pfx_msg_t *out)
{
    const size_t k = PFX__END_LEN(p->dir), limit = PFX__LIMIT(p->dir);
    size_t from = 0u, i;
    int r;
    if (p->n < limit + 1u) {
        p->buf[p->n++] = byte;
    }
    if (p->n < k || !pfx__same(p->buf + p->n - k, PFX__END(p->dir), k)) { /* byte by byte: an ending is at the tail */
        if (p->n > limit) {
            p->errors++;
            for (i = 0u; i + 1u < k; i++) { /* keep what may begin a line ending */
                p->buf[i] = p->buf[p->n - (k - 1u) + i];
            }
            p->n = k - 1u;
            p->overlong = 1u;
        }
        return 0;
    }
    if (p->overlong) { /* the rest of a line already dropped */
        p->overlong = 0u;
        p->n = 0u;
        return 0;
    }
    for (i = 0u; i < p->n - k; i++) {
        uint8_t c = p->buf[i];
        if (c != 0x20u && (c < 0x09u || c > 0x0Du)) {
            break;
        }
    }
    if (i == p->n - k) { /* a blank line */
        p->n = 0u;
        return 0;
    }
    while (p->buf[from] == 0x0Du || p->buf[from] == 0x0Au) {
        from++;
    }
    r = pfx__decode(p->buf + from, p->n - from, p->dir, PFX_KIND_NONE, PFX__REPLY(p), out);
    p->frame = p->buf + from; /* it ends with the byte just pushed: nothing held after it */
    p->frame_len = p->n - from;
    p->n = 0u;
    if (r == PFX_OK) {
        PFX__ANSWERED(p, out);
        p->frames++;
        return 1;
    }
    p->errors++;
    if (r == PFX_E_UNKNOWN) { /* a good checksum, an unknown code */
        p->unknown++;
        return 2;
    }
    return 0;
}

void pfx_parser_gap(pfx_parser_t *parser)
{
    size_t i;
    int begun = 0;
    for (i = 0u; i < parser->n; i++) { /* a line begun: more than line-ending bytes */
        begun |= parser->buf[i] != 0x0Du && parser->buf[i] != 0x0Au;
    }
    if (begun && !parser->overlong) {
        parser->errors++;
    }
    parser->n = 0u;
    parser->overlong = 0u;
}

""",
    needs=("same", "decode"),
)

PARSER = Piece(
    r"""void pfx_parser_init(pfx_parser_t *parser, pfx_direction_t dir)
{
    parser->dir = dir;
    parser->n = 0u;
#if !PFX__S
    parser->overlong = 0u;
#endif
    PFX__INIT_REPLY(parser);
    parser->frames = 0u;
    parser->garbage = 0u;
    parser->errors = 0u;
    parser->unknown = 0u;
    parser->frame = NULL;
    parser->frame_len = 0u;
}

size_t pfx_parser_feed(pfx_parser_t *parser, const uint8_t *data, size_t len, pfx_msg_t *out, bool *got)
{
    size_t i;
    *got = false;
#if PFX_ROLE != PFX_ROLE_BOTH
    if (!PFX__DECODES(parser->dir)) { /* the other side's direction, left out of this build */
        return len;
    }
#endif
    for (i = 0u; i < len; i++) {
        if (pfx__push(parser, data[i], out) == 1) {
            *got = true;
            return i + 1u;
        }
    }
    return len;
}
#endif
""",
)
