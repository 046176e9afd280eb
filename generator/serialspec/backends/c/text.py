"""The C of a text protocol (`framing: {kind: text}`: NMEA 0183 sentences, ASCII command sets): the same four files
and public API as a binary protocol's (p_decode, p_encode, p_parser_feed, p_to_json), from the text model
(lang/model.py TextFrame). The generic part is text_runtime.py's; this module writes what the spec says: the
message structs, the letters, the codes, each field's reader, writer and range check."""

from __future__ import annotations

from decimal import Decimal
from typing import assert_never

from serialspec.backends import Unsupported
from serialspec.backends.c import parser_api
from serialspec.backends.c.emit import comment, ident, spec_hash
from serialspec.backends.c.files import banner as binary_banner
from serialspec.backends.c.files import role_macros
from serialspec.backends.c.text_runtime import (
    BEFORE_PARSER,
    CHECKED_READ,
    CHECKED_WRITE,
    DECIMAL_CHECKED_READ,
    DECIMAL_CHECKED_WRITE,
    HEAD,
    LINES_PUSH,
    MIDDLE,
    PARSER,
    START_PUSH,
    Piece,
    used,
    written,
)
from serialspec.backends.common.text_frames import C_TAKES, refuse_text_frames
from serialspec.checksums.base import NoCode
from serialspec.lang.model import Protocol, TextField, TextFrame, TextLayout, TextMessage, TextRepeat

RESULTS = ("OK", "E_BUFFER", "E_RANGE", "E_LENGTH", "E_CHECKSUM", "E_UNKNOWN", "E_FRAME", "E_CONTENT", "E_CAPACITY")


def refuse(text: TextFrame) -> None:
    """Unsupported naming what of a text spec the C target cannot generate yet."""
    refuse_text_frames(text, C_TAKES)
    if text.checksum is not None:
        try:
            text.checksum.c_code("p")
        except NoCode as exc:
            raise Unsupported(f"the text checksum: {exc}") from None
        if text.digits > 8:
            raise Unsupported(f"a text checksum of {text.digits} hex digits")


def mid(m: TextMessage) -> str:
    return f"{ident(m.key)}_{m.direction.value}"


def _snake(name: str) -> str:
    return "".join(f"_{c.lower()}" if c.isupper() and i else c.lower() for i, c in enumerate(name))


def _byte(c: str) -> str:
    return f"0x{ord(c):02X}u"


def _items(m: TextMessage) -> list[TextField | TextRepeat]:
    return list(m.fields)


def _sent(m: TextMessage) -> list[TextField | TextRepeat]:
    """The fields written after the code: all but an address (`framing.address`: its digits come before it)."""
    return [f for f in m.fields if not (isinstance(f, TextField) and f.address)]


class TextC:
    """One text protocol's C."""

    def __init__(self, protocol: Protocol, text: TextFrame) -> None:
        refuse(text)
        self.protocol, self.text = protocol, text
        self.p, self.P = protocol.name, protocol.name.upper()
        # the longest frame the parser holds: max_length and the longer line ending (each direction may have its own)
        self.limit = text.max_length + max(len(text.end), len(text.response_end))
        self.bare_macros = ""  # replies of values alone: the macros that tell their kinds (bare_decode)
        self.calls: set[str] = set()  # the runtime's helpers the code written calls (text_runtime.used)

    def call(self, helper: str) -> str:
        """The name of the runtime's helper pfx__<helper>, which the code written calls."""
        self.calls.add(helper)
        return f"{self.p}__{helper}"

    # --- the header ------------------------------------------------------------------------------------------------

    def member(self, f: TextField) -> list[str]:
        p, P, n = self.p, self.P, ident(f.name)
        doc = comment(f.description or f.name) + (f" [{comment(f.unit)}]" if f.unit else "")
        has = f"    bool has_{n}; /* the field was sent (an empty field: absent) */"
        match f.kind:
            case "decimal":
                t = f"    {p}_decimal_t {n}; /* {doc} */"
            case "integer":
                t = f"    int64_t {n}; /* {doc} */"
            case "angle":
                t = f"    {p}_angle_t {n}; /* {doc} */"
            case "char":
                letters = f" ({p}_{_snake(f.letters_class)}_t)" if f.letters else ""
                t = f"    char {n}; /* {doc}{letters} */"
            case "text":
                t = f"    char {n}[{P}_TEXT_MAX]; /* {doc} (not NUL-terminated: {n}_len characters) */\n"
                t += f"    uint16_t {n}_len;"
            case "time":
                t = f"    {p}_time_t {n}; /* {doc} */"
            case "date":
                t = f"    {p}_date_t {n}; /* {doc} */"
            case _:
                assert_never(f.kind)
        return [has, t]

    def structs(self) -> str:
        p, out = self.p, []
        for m in self.text.messages:
            mems: list[str] = []
            for item in _items(m):
                if isinstance(item, TextField):
                    mems += self.member(item)
                    continue
                group = f"{p}_{mid(m)}_{ident(item.name)}_t"
                inner = [line for f in item.fields for line in self.member(f)]
                out.append("typedef struct {\n" + "\n".join(inner) + f"\n}} {group};")
                if item.label:  # found by its label: absent where the frame leaves it out
                    mems.append(f"    bool has_{ident(item.name)}; /* its label was sent */")
                if item.count:
                    mems.append(f"    {group} {ident(item.name)}[{item.count}]; /* {comment(item.description)} */")
                else:
                    mems.append(f"    {group} {ident(item.name)}[{item.max_count}]; /* {comment(item.description)} */")
                    mems.append(f"    uint8_t {ident(item.name)}_count; /* groups sent, up to {item.max_count} */")
            body = "\n".join(mems) or "    uint8_t unused_;"
            title = f"/* {comment(m.title)} ({comment(m.code)}, {m.direction.value}) */"
            out.append(f"{title}\ntypedef struct {{\n{body}\n}} {p}_{mid(m)}_t;")
        return "\n\n".join(out)

    def header(self) -> str:
        p, P, t = self.p, self.P, self.text
        letters = []
        for name, pairs in t.letter_sets().items():
            rows = ",\n".join(
                f"    {P}_{_snake(name).upper()}_{ident(label).upper()} = {_byte(letter)}" for label, letter in pairs
            )
            letters.append(f"typedef enum {{\n{rows}\n}} {p}_{_snake(name)}_t;")
        kinds = ",\n".join(f"    {P}_{mid(m).upper()}" for m in t.messages)
        union = "\n".join(f"        {p}_{mid(m)}_t {mid(m)};" for m in t.messages)
        check = ""
        if t.checksum is not None:
            check = (
                f"/* The checksum of the characters between start and marker. */\n{t.checksum.c_code(p).prototype}\n"
            )
        results = ",\n".join(f"    {P}_{r}" + (" = 0" if r == "OK" else "") for r in RESULTS)
        overlong = (
            ""
            if t.start
            else "    uint8_t overlong; /* frames without a start: the line being read was dropped as too long */\n"
        )
        if any(m.values_only for m in t.messages):  # replies of values alone: read as the reply awaited
            overlong += (
                f"    {p}_kind_t awaited; /* the reply awaited ({p}_parser_expect), until a response of it */\n"
                f"    {p}_kind_t asked;   /* the reply of values alone of the request just read */\n"
            )
        return f"""{banner(self.protocol)}
#ifndef {P}_H
#define {P}_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {{
#endif

#define {P}_SPEC_SHA256 "{spec_hash(self.protocol)}"

/* Feature switches: define as 0 to leave encode, decode or the stream parser out. */
#ifndef {P}_ENABLE_ENCODE
#define {P}_ENABLE_ENCODE 1
#endif
#ifndef {P}_ENABLE_DECODE
#define {P}_ENABLE_DECODE 1
#endif
#ifndef {P}_ENABLE_PARSER
#define {P}_ENABLE_PARSER 1
#endif
{role_macros(P)}
/* The longest frame p_decode takes ({P}_E_CAPACITY beyond): by default the longest the stream parser gives, the
 * spec's max_length ({t.max_length} characters), the line ending and one more (as runtime/text.py's parser). */
#ifndef {P}_MAX_FRAME
#define {P}_MAX_FRAME {self.limit + 1}u
#endif
/* The room of a text field (characters). */
#ifndef {P}_TEXT_MAX
#define {P}_TEXT_MAX {t.max_length}u
#endif

typedef enum {{
{results},
    {P}_E_ARG
}} {p}_result_t;

typedef enum {{ {P}_REQUEST = 0, {P}_RESPONSE = 1 }} {p}_direction_t;

/* A decimal number as sent: value / 10^scale, `width` digits before the point (leading zeros kept), negative also
 * for a zero sent with its minus sign (-0.0). Encode writes `scale` fraction digits (at most 18). */
typedef struct {{
    int64_t value;
    uint8_t scale;
    uint8_t width;
    bool negative;
}} {p}_decimal_t;

/* Degrees and minutes (ddmm.mmmm): the hemisphere is a field of its own. */
typedef struct {{
    uint32_t degrees;
    {p}_decimal_t minutes;
}} {p}_angle_t;

/* A time of day (hhmmss[.ss]): `digits` fraction digits of a second written, the first 6 from micro. */
typedef struct {{
    uint8_t hour;
    uint8_t minute;
    uint8_t second;
    uint32_t micro;
    uint16_t digits;
}} {p}_time_t;

/* A date (ddmmyy): the year in full (yy 69..99 is 1969..1999, 00..68 2000..2068). */
typedef struct {{
    uint8_t day;
    uint8_t month;
    uint16_t year;
}} {p}_date_t;

{chr(10).join(letters)}

{self.structs()}

typedef enum {{
    {P}_KIND_NONE = 0,
{kinds},
    {P}_KIND_COUNT
}} {p}_kind_t;

/* One message: its kind, the frame-level talker, how many fields the frame had after the address (-1: every
 * declared one; encode writes that many, so a decoded sentence encodes to the same text), whether it came without
 * its optional checksum (encode then writes none) and its fields. */
typedef struct {{
    {p}_kind_t kind;
    char talker[{t.talker + 1}];
    int32_t sent;
    bool unchecked; /* sent without its optional checksum: encode leaves it out too */
    union {{
{union}
    }} u;
}} {p}_msg_t;

{parser_api.event_type(p, P)}
/* All parser state (runtime/text.py TextStreamParser): the line being read and the counters. */
typedef struct {{
    {p}_direction_t dir;
    size_t n;
    uint8_t buf[{self.limit + 1}u];
{overlong}    uint32_t frames;
    uint32_t garbage; /* not counted for text frames (always 0) */
    uint32_t errors;  /* frames dropped: cut short, too long, or not decoded */
    uint32_t unknown; /* of those, frames with a good checksum and an unknown code ({P}_EVENT_FRAME_UNKNOWN) */
    const uint8_t *frame; /* the last frame delivered, as received ({p}_parser_frame) */
    size_t frame_len;
}} {p}_parser_t;

{check}int {p}_decode(const uint8_t *frame, size_t len, {p}_direction_t dir, {p}_msg_t *out);
/* p_decode, refusing a frame of another kind than `expect` ({P}_KIND_NONE: any) with {P}_E_UNKNOWN. */
int {p}_decode_expect(const uint8_t *frame, size_t len, {p}_direction_t dir, {p}_kind_t expect, {p}_msg_t *out);
int {p}_encode(const {p}_msg_t *msg, uint8_t *buf, size_t cap, size_t *len);
/* The address and the fields as encode writes them, joined by the separator, without range checks (p_to_json). */
int {p}_field_texts(const {p}_msg_t *msg, uint8_t *buf, size_t cap, size_t *len);
void {p}_parser_init({p}_parser_t *parser, {p}_direction_t dir);
size_t {p}_parser_feed({p}_parser_t *parser, const uint8_t *data, size_t len, {p}_msg_t *out, bool *got);
{parser_api.push_prototype(p)}\
/* The line went idle: no frame spans a gap, so a frame begun is dropped as cut short (counted in errors), as Python's
 * TextStreamParser.gap() does. */
void {p}_parser_gap({p}_parser_t *parser);
/* The raw bytes of the last frame delivered (NULL and 0 before the first), in the parser's buffer: valid until the
 * next call on the parser. */
const uint8_t *{p}_parser_frame(const {p}_parser_t *parser, size_t *len);
/* The reply the next frames answer: Python's TextStreamParser reads each frame by its text code alone, so it changes
 * nothing (there for the same API as a binary protocol's). */
void {p}_parser_expect({p}_parser_t *parser, {p}_kind_t reply);
const char *{p}_kind_name({p}_kind_t kind);
const char *{p}_result_name(int result);

#ifdef __cplusplus
}}
#endif

#endif
"""

    # --- the source ------------------------------------------------------------------------------------------------

    def read(self, f: TextField, lv: str, cursor: str = "c") -> str:
        """Decode statements of the next field of `cursor` (a pointer) into the member `lv` (an lvalue path without
        the member name)."""
        return f"    {self.call('rest' if f.rest else 'next')}({cursor}, &s, &len);\n" + self.value(f, lv, cursor)

    def value(self, f: TextField, lv: str, cursor: str = "c") -> str:
        """Decode statements of one field's text, `cursor`->b[s, s + len), into the member `lv` (empty: absent)."""
        P, n = self.P, ident(f.name)
        target = f"{lv}{n}"
        text = f"{cursor}->b + s, len"
        match f.kind:
            case "decimal":
                call = f"{self.call('get_decimal')}({text}, &{target})"
            case "integer" if f.base == 16:
                call = f"{self.call('get_hex_integer')}({text}, &{target})"
            case "integer":
                call = f"{self.call('get_integer')}({text}, &{target})"
            case "angle":
                call = f"{self.call('get_angle')}({text}, {f.width or 2}u, &{target})"
            case "char":
                call = f"{self.call('get_char')}({text}, &{target})"
            case "text":
                call = f"{self.call('get_text')}({text}, {target}, {P}_TEXT_MAX, &{target}_len)"
            case "time":
                call = f"{self.call('get_time')}({text}, &{target})"
            case "date":
                call = f"{self.call('get_date')}({text}, &{target})"
            case _:
                assert_never(f.kind)
        letters = ""
        if f.letters:
            allowed = " && ".join(f"{target} != '{_c_char(letter)}'" for _, letter in f.letters)
            letters = f"\n        if (r == {P}_OK && {allowed}) {{\n            r = {P}_E_CONTENT;\n        }}"
        return f"""    {lv}has_{n} = len > 0u;
    if (len > 0u) {{
        r = {call};{letters}
        if (r != {P}_OK) {{
            return r;
        }}
    }}"""

    def decoder(self, m: TextMessage) -> str:
        p, P = self.p, self.P
        if m.layout is not None and m.layout.labelled:
            return self.labelled_decoder(m, m.layout)
        lines: list[str] = []
        at = 0
        for item in _sent(m):
            if isinstance(item, TextField):
                lines.append(self.read(item, "m->"))
                at += 1
                continue
            name, size = ident(item.name), len(item.fields)
            if item.count:
                groups = f"{item.count}u"
            else:
                lines.append(
                    f"    groups = sent > {at}u ? (sent - {at}u + {size - 1}u) / {size}u : 0u;\n"
                    f"    if (groups > {item.max_count}u) {{\n        groups = {item.max_count}u;\n    }}\n"
                    f"    m->{name}_count = (uint8_t)groups;"
                )
                groups = "groups"
            body = "\n".join(self.read(f, f"m->{name}[g].").replace("\n", "\n    ") for f in item.fields)
            lines.append(f"    for (g = 0u; g < {groups}; g++) {{\n    {body}\n    }}")
            at += size * item.count  # a repeat up to max_count comes last
        used = "\n".join(lines)
        head = f"{comment(m.title)} ({comment(m.code)}, {m.direction.value})"
        return f"""/* {head}: each field in turn, an empty one absent. */
static int {p}__dec_{mid(m)}({p}__cursor_t *c, size_t sent, {p}_{mid(m)}_t *m)
{{
    size_t s = 0u, len = 0u, g = 0u, groups = 0u;
    int r = {P}_OK;
    (void)s;
    (void)len;
    (void)g;
    (void)groups;
    (void)sent;
    (void)r;
    (void)m;
{used}
    return c->more ? {P}_E_LENGTH : {P}_OK; /* more fields than the message has */
}}"""

    def labelled_decoder(self, m: TextMessage, layout: TextLayout) -> str:
        """A message's own text with labels (runtime/text.py _decode_labelled, _glued, _labelled_values): each part
        found by its label, in any order (an unknown one, or one sent twice, P_E_CONTENT), a repeat's values split by
        `list` (a wrong number of them P_E_LENGTH); an absent label leaves its field absent. The cursor holds the
        text after the code (and what follows it); in a text with a start, from the code on: its part holds the value
        labelled with the code where it holds `named` (GRBL's `Hold:0`); glued to its labels, from the code on where
        a field is labelled with it (LSS's `D1800`, its value the code's)."""
        p, P = self.p, self.P
        items = _sent(m)
        order = sorted(range(len(items)), key=lambda i: -len(items[i].label))  # the longest label first
        labels = ", ".join(c_text(items[i].label) for i in order)
        named = _byte(layout.named) if layout.named else "0u"
        cases = []
        for index, i in enumerate(order):
            item = items[i]
            if isinstance(item, TextField):
                body = self.value(item, "m->")
            else:
                name, size = ident(item.name), len(item.fields)
                wrong = f"values % {size}u != 0u || " if size > 1 else ""
                wrong += f"values != {item.count * size}u" if item.count else f"values > {item.max_count * size}u"
                count = "" if item.count else f"\n    m->{name}_count = (uint8_t)(values / {size}u);"
                reads = "\n".join(self.read(f, f"m->{name}[g].", "(&v)") for f in item.fields)
                body = f"""    for (g = s; g < s + len; g++) {{
        values += c->b[g] == {_byte(layout.list)} ? 1u : 0u;
    }}
    if ({wrong}) {{
        return {P}_E_LENGTH; /* not the repeat's number of values */
    }}
    m->has_{name} = true;{count}
    v.b = c->b + s;
    v.n = len;
    v.pos = 0u;
    v.more = 1;
    v.sep = {_byte(layout.list)};
    v.list = {_byte(layout.list)};
    for (g = 0u; g < values / {size}u; g++) {{
    {reads.replace(chr(10), chr(10) + "    ")}
    }}"""
            cases.append(
                f"        case {index}u: /* {comment(item.label)}: {item.name} */\n"
                + "\n".join("        " + line if line else line for line in body.split("\n"))
                + "\n            break;"
            )
        head = ""
        if layout.start:  # the code's own part: a value where it holds `named`, else the code alone
            sep_ = _byte(layout.separator)
            head = f"""    for (g = c->pos; g < c->n && c->b[g] != {sep_} && c->b[g] != {named}; g++) {{
    }}
    if (g >= c->n || c->b[g] != {named}) {{
        {self.call("next")}(c, &s, &len); /* the code alone */
    }}
"""
        self.call("pair")
        sep = int(bool(layout.separator))
        cursor = (
            f"    {p}__cursor_t v; /* a repeat's values */\n" if any(isinstance(i, TextRepeat) for i in items) else ""
        )
        head_c = f"{comment(m.title)} ({comment(m.code)}, {m.direction.value})"
        return f"""/* {head_c}, in its own text: its fields found by their labels. */
static int {p}__dec_{mid(m)}({p}__cursor_t *c, size_t sent, {p}_{mid(m)}_t *m)
{{
    static const char *const labels[] = {{{labels}}};
    uint8_t seen[{len(items)}];
    size_t s = 0u, len = 0u, g = 0u, which = 0u, values = 1u;
{cursor}    int r = {P}_OK;
    (void)sent;
    (void)g;
    (void)values;
    memset(seen, 0, sizeof(seen));
    c->list = c->sep; /* a repeat's values are split by its list in its part */
{head}    while (c->more) {{
        r = {p}__pair(c, {named}, {sep}, labels, {len(items)}u, &which, &s, &len);
        if (r != {P}_OK) {{
            return r;
        }}
        if (seen[which]) {{
            return {P}_E_CONTENT; /* a label sent twice */
        }}
        seen[which] = 1u;
        values = 1u;
        switch (which) {{
{chr(10).join(cases)}
        default:
            break;
        }}
    }}
    return {P}_OK;
}}"""

    def check(self, f: TextField, lv: str, own: str = "", rest_own: str = "") -> str:
        """The range checks of one field (encode refuses with P_E_RANGE before it writes); `own`: the characters of
        the message's own layout, which its texts may not hold either."""
        P, n = self.P, ident(f.name)
        v = f"{lv}{n}"
        tests: list[str] = []

        def bounds(value: str, scale: str) -> None:
            for bound, sign in ((f.minimum, "<"), (f.maximum, ">")):
                if bound is not None:
                    mantissa, exponent = _exact(bound)
                    tests.append(f"{self.call('compare')}({value}, {scale}, {mantissa}, {exponent}u) {sign} 0")

        match f.kind:
            case "decimal":
                tests.append(f"{v}.scale > 18u")
                bounds(f"{v}.value", f"{v}.scale")
            case "integer":
                bounds(v, "0u")
            case "angle":
                tests.append(f"{v}.minutes.scale > 18u || {v}.minutes.value < 0")
                tests.append(f"{self.call('compare')}({v}.minutes.value, {v}.minutes.scale, 60, 0u) >= 0")
                if f.minimum is not None:
                    tests.append(f"{self.call('angle_value')}(&{v}) < {float(f.minimum)!r}")
                if f.maximum is not None:
                    tests.append(f"{self.call('angle_value')}(&{v}) > {float(f.maximum)!r}")
            case "char":
                if f.letters:
                    tests.append(" && ".join(f"{v} != '{_c_char(letter)}'" for _, letter in f.letters))
                tests.append(f"!{self.call('carried')}({v})")
                if own:
                    tests.append(f"!{self.call('avoids')}(&{v}, 1u, {_c_string(own)})")
            case "text":
                ok = self.call("rest_ok" if f.rest else "text_ok")
                tests.append(f"{v}_len > {P}_TEXT_MAX || !{ok}({v}, {v}_len)")
                mine = rest_own if f.rest else own  # a text to the end of the line may hold the separators
                if mine:
                    tests.append(f"!{self.call('avoids')}({v}, {v}_len, {_c_string(mine)})")
            case "time":
                tests.append(f"!{self.call('time_ok')}(&{v})")
            case "date":
                tests.append(f"!{self.call('date_ok')}(&{v})")
            case _:
                assert_never(f.kind)
        return "\n".join(f"    if ({lv}has_{n} && ({t})) {{\n        return {P}_E_RANGE;\n    }}" for t in tests)

    def write(self, f: TextField, lv: str, part: str = "") -> str:
        """The writing of one field after the framing's separator, or (`part`: the separator of a message's own
        layout, as C) as a part of its layout, after that separator where a part comes before it."""
        n = ident(f.name)
        v = f"{lv}{n}"
        call = self.put_value(f, v)
        before = f"{self.call('part')}(o, &first, {part})" if part else f"{self.call('put')}(o, {self.P}__SEPARATOR)"
        if f.rest and not part:  # the separators in it are its own (p__trim)
            before += ";\n    o->rest = o->n"
        return f"    {before};\n    if ({lv}has_{n}) {{\n        {call};\n    }}"

    def put_value(self, f: TextField, v: str) -> str:
        """The call that writes the value of the member `v` as its text."""
        match f.kind:
            case "decimal":
                call = f"{self.call('put_decimal')}(o, &{v}, {v}.width)"
            case "integer" if f.base == 16:
                call = f"{self.call('put_hex_integer')}(o, {v}, {f.width}u, {int(f.lower)}u)"
            case "integer":
                call = f"{self.call('put_integer')}(o, {v}, {f.width}u)"
            case "angle":
                call = f"{self.call('put_angle')}(o, &{v}, {f.width or 2}u)"
            case "char":
                call = f"{self.call('put')}(o, (uint8_t){v})"
            case "text":
                call = f"{self.call('put_text')}(o, {v}, {v}_len < {self.P}_TEXT_MAX ? {v}_len : {self.P}_TEXT_MAX)"
            case "time":
                call = f"{self.call('put_time')}(o, &{v})"
            case "date":
                call = f"{self.call('put_date')}(o, &{v})"
            case _:
                assert_never(f.kind)
        return call

    def encoder(self, m: TextMessage) -> str:
        p, P = self.p, self.P
        checks: list[str] = []
        writes: list[str] = []
        layout = m.layout
        own, part, joined = "", "", ""
        if layout is not None:  # its own separator (a repeat's values joined by `list`) and characters
            chars = {layout.start, layout.end, layout.separator, layout.named, layout.list, layout.after_code or ""}
            own = "".join(sorted(chars - {""}))
            if not layout.labelled:
                part, joined = _byte(layout.separator), _byte(layout.list or layout.separator)
        rest_own = (
            "".join(sorted(set(own) - {layout.separator, layout.after_code or "", self.text.separator}))
            if layout
            else ""
        )
        t = self.text
        if not self.marked() and t.checksum is not None and m.direction.value in t.checksum_directions:
            own, rest_own = own + t.marker, rest_own + t.marker  # its frames carry the checksum after the marker
        labelled = layout is not None and layout.labelled  # written by labelled_writes
        for item in _sent(m):
            if isinstance(item, TextField):
                checks.append(self.check(item, "m->", own, rest_own))
                if not labelled:
                    writes.append(self.write(item, "m->", part))
                continue
            name = ident(item.name)
            groups = f"{item.count}u" if item.count else f"m->{name}_count"
            if item.label:  # absent where its label is not sent: nothing to check
                groups = f"(m->has_{name} ? {groups} : 0u)"
            if not item.count:
                checks.append(f"    if ({groups} > {item.max_count}u) {{\n        return {P}_E_RANGE;\n    }}")
            inner = "\n".join(self.check(f, f"m->{name}[g].", own) for f in item.fields).replace("\n", "\n    ")
            checks.append(f"    for (g = 0u; g < {groups}; g++) {{\n    {inner}\n    }}")
            if labelled:
                continue
            inner = "\n".join(
                self.write(f, f"m->{name}[g].", (f"g == 0u ? {part} : {joined}" if k == 0 else joined) if part else "")
                for k, f in enumerate(item.fields)
            ).replace("\n", "\n    ")
            writes.append(f"    for (g = 0u; g < {groups}; g++) {{\n    {inner}\n    }}")
        head = f"{comment(m.title)} ({comment(m.code)}, {m.direction.value})"
        written = "\n".join(writes)
        if layout is not None and labelled:
            written = self.labelled_writes(m, layout)
            head += ", in its own text with labels"
        elif layout is not None:  # runtime/text.py _encode_in: after the code, its fields only where they have text
            after = layout.follows_code
            written = (
                f"    {self.call('put_text')}(o, {_c_string(after)}, {len(after)}u);\n    fields = o->n;\n{written}\n"
                f"    if ({'first' if layout.start else 'o->n == fields'}) {{ /* no field's text: the code alone */\n"
                f"        o->n = code;\n    }}\n"
                f"    {self.call('put_text')}(o, {_c_string(layout.end)}, {len(layout.end)}u);"
            )
            head += ", in its own layout"
        return f"""/* {head}: the range checks (when asked), then each
 * field after a separator, an absent one empty. */
static int {p}__enc_{mid(m)}(const {p}_{mid(m)}_t *m, {p}__out_t *o, int check)
{{
    size_t g = 0u, code = o->n, fields = o->n;
    int first = 1;
    (void)g;
    (void)m;
    (void)o;
    (void)code;
    (void)fields;
    (void)first;
    if (check) {{
{chr(10).join(checks).replace(chr(10), chr(10) + "    ") if checks else ""}
    }}
{written}
    return {P}_OK;
}}"""

    def labelled_writes(self, m: TextMessage, layout: TextLayout) -> str:
        """runtime/text.py _encode_in of a message whose fields have labels: the value labelled with the code right
        after it, then what follows the code and each other field present as its label, `named` and its value (a
        repeat's values joined by `list`), joined by the separator; none present: the code alone."""
        items = _sent(m)
        lines = []
        for item in items:
            if isinstance(item, TextField) and item.label == m.code:  # GRBL's `Hold:0`, LSS's `D1800`
                v = f"m->{ident(item.name)}"
                lines.append(
                    f"    if (m->has_{ident(item.name)}) {{ /* the value labelled with the code, right after it */\n"
                    f"        {self.call('put_text')}(o, {_c_string(layout.named)}, {len(layout.named)}u);\n"
                    f"        {self.put_value(item, v)};\n    }}"
                )
        after = layout.follows_code
        lines.append(f"    code = o->n;\n    {self.call('put_text')}(o, {_c_string(after)}, {len(after)}u);")
        part = f"{self.call('part')}(o, &first, {_byte(layout.separator)})" if layout.separator else "first = 0"
        for item in items:
            name = ident(item.name)
            if item.label == m.code:
                continue
            label = item.label + layout.named
            present = (
                f"m->has_{name}"
                if isinstance(item, TextField) or item.count
                else f"m->has_{name} && m->{name}_count > 0u"
            )
            head = f"        {part};\n        {self.call('put_text')}(o, {_c_string(label)}, {len(label)}u);\n"
            if isinstance(item, TextField):
                lines.append(f"    if ({present}) {{\n{head}        {self.put_value(item, f'm->{name}')};\n    }}")
                continue
            groups = f"{item.count}u" if item.count else f"m->{name}_count"
            inner = []
            for k, f in enumerate(item.fields):
                between = f"{self.call('put')}(o, {_byte(layout.list)});"
                if k == 0:
                    between = f"if (g > 0u) {{\n                {between}\n            }}"
                value = f"m->{name}[g].{ident(f.name)}"
                inner.append(
                    f"            {between}\n            if (m->{name}[g].has_{ident(f.name)}) {{\n"
                    f"                {self.put_value(f, value)};\n            }}"
                )
            lines.append(
                f"    if ({present}) {{\n{head}        for (g = 0u; g < {groups}; g++) {{\n"
                + "\n".join(inner)
                + "\n        }\n    }"
            )
        lines.append(
            "    if (first) { /* no field but the code's own: the code alone */\n        o->n = code;\n    }\n"
            f"    {self.call('put_text')}(o, {_c_string(layout.end)}, {len(layout.end)}u);"
        )
        return "\n".join(lines)

    def bare_decode(self, bare: list[TextMessage]) -> tuple[str, str, str, str]:
        """Replies of values alone (`values_only`: ODrive's `r vbus_voltage` answered `24.1`), read as the reply
        awaited where a frame's first field is no code of its direction (runtime/text.py TextFraming.decode's
        `reply`): the helpers before the decoder, the decoder's reading of one, encode's dropping of the separator
        before its first value, and decode_expect's reply awaited."""
        p, P, t = self.p, self.P, self.text
        if not bare:
            return "", "    (void)reply;\n", "", f"{P}_KIND_NONE"
        cases = []
        for m in bare:
            same = [o for o in t.messages if o.code == m.code]
            labels = "".join(f"    case {P}_{mid(o).upper()}:\n" for o in same)
            cases.append(f"{labels}        return {P}_{mid(m).upper()};")
        coded = [m for m in t.messages if not m.values_only]
        requests = [m for m in t.messages if m.direction.value == "request"]
        responses = [m for m in t.messages if m.direction.value == "response"]

        def kinds(found: list[TextMessage]) -> str:
            return " || ".join(f"(kind) == {P}_{mid(m).upper()}" for m in found) or "0"

        coded_cases = [f"    case {P}_{mid(m).upper()}:\n        return dir == {P}_{m.direction.name};" for m in coded]
        self.bare_macros = f"""/* Replies of values alone (`values_only`): no code, so read as the reply awaited. */
#define {P}__BARE(kind) ({kinds(bare)})
#define {P}__IS_REQUEST(kind) ({kinds(requests)})
#define {P}__IS_RESPONSE(kind) ({kinds(responses)})
"""
        helpers = f"""/* The reply of values alone that answers `kind`'s code (its request's, or its own), or none. */
static {p}_kind_t {p}__bare_reply({p}_kind_t kind)
{{
    switch (kind) {{
{chr(10).join(cases)}
    default:
        return {P}_KIND_NONE;
    }}
}}

/* 1 when `kind` (what a frame's code names) is a message sent with its code, in `dir`. */
static int {p}__coded({p}_kind_t kind, {p}_direction_t dir)
{{
    switch (kind) {{
{chr(10).join(coded_cases)}
    default:
        return 0;
    }}
}}

#if {P}_ENABLE_PARSER
/* After a message the parser gives (runtime/text.py TextStreamParser._decoded): the reply awaited answered; a
 * request read, whose reply of values alone is read next. */
static void {p}__answered({p}_parser_t *p, const {p}_msg_t *out)
{{
    if (out->kind == p->awaited && {P}__IS_RESPONSE(out->kind)) {{
        p->awaited = {P}_KIND_NONE;
    }}
    p->asked = {P}__IS_REQUEST(out->kind) ? {p}__bare_reply(out->kind) : {P}_KIND_NONE;
}}
#endif

"""
        read = f"""    if (reply != {P}_KIND_NONE && dir != {P}_REQUEST && !{p}__coded(kind, dir)) {{
        /* the reply of values alone awaited: its values from the first field on, no talker */
        kind = reply;
        out->talker[0] = '\\0';
        out->sent = (int32_t)(seps + 1u);
        c.more = 1;
        c.pos = 0u;
    }}
"""
        write = f"""    for (at = {P}__S; at < o.n && o.b[at] >= 0x30u && o.b[at] <= 0x39u; at++) {{
    }} /* past an address */
    if ({P}__BARE(msg->kind) && !o.full && o.n > at && o.b[at] == {P}__SEPARATOR) {{
        for (i = at; i + 1u < o.n; i++) {{ /* a reply of values alone: no separator before its first value */
            o.b[i] = o.b[i + 1u];
        }}
        o.n--;
    }}
"""
        return helpers, read, write, f"{p}__bare_reply(expect)"

    def address(self) -> tuple[str, str, str]:
        """An address before the code (`framing.address`: Lynxmotion LSS's servo id, `#5QD`): every message's first
        field, its decimal digits right after the start (runtime/text.py TextFraming._decode_body): the decoder's
        reading of them, __body's writing of them (range-checked first) and the decoder's setting of every message's
        member after its fields."""
        P, f = self.P, self.text.address
        if f is None:
            return "", "", ""
        n = ident(f.name)
        sets = "\n".join(
            f"        case {P}_{mid(m).upper()}:\n            out->u.{mid(m)}.{n} = number;\n"
            f"            out->u.{mid(m)}.has_{n} = digits > 0u;\n            break;"
            for m in self.text.messages
        )
        read = f"""    while (digits < n && frame[body + digits] >= 0x30u && frame[body + digits] <= 0x39u) {{
        digits++; /* the address: the digits right after the start */
    }}
    if (digits > 18u) {{
        return {P}_E_CAPACITY;
    }}
    for (i = 0u; i < digits; i++) {{
        number = number * 10 + (int64_t)(frame[body + i] - 0x30u);
    }}
    body += digits;
    n -= digits;
"""
        set_ = f"""    if (r == {P}_OK) {{
        switch (kind) {{ /* the address, every message's first field */
{sets}
        default:
            break;
        }}
    }}
"""
        writes = "\n".join(
            f"    case {P}_{mid(m).upper()}:\n"
            + "\n".join("    " + line for line in self.check(f, f"msg->u.{mid(m)}.").split("\n")).replace(
                f"    if (msg->u.{mid(m)}.has_{n} &&", f"    if (check && msg->u.{mid(m)}.has_{n} &&"
            )
            + f"\n        if (msg->u.{mid(m)}.has_{n}) {{\n"
            f"            {self.call('put_integer')}(o, msg->u.{mid(m)}.{n}, {f.width}u);\n        }}\n        break;"
            for m in self.text.messages
        )
        write = f"""    switch (msg->kind) {{ /* the address first, its digits before the talker and code */
{writes}
    default:
        break;
    }}
"""
        return read, write, set_

    def framed(self) -> tuple[str, str]:
        """Messages in their own text with a start (GRBL's `[MSG:...]`, runtime/text.py TextFraming._decode_in): the
        decoder's reading of a frame whose text starts with a layout's start and ends with its end (the talker and
        code up to its separator, then its fields), and __body's writing of the start before the talker."""
        p, P, t = self.p, self.P, self.text
        layouts = list(dict.fromkeys(m.layout for m in t.messages if m.layout is not None and m.layout.start))
        if not layouts:
            return "", ""
        reads = []
        for index, layout in enumerate(layouts):
            kinds = " || ".join(f"kind == {P}_{mid(m).upper()}" for m in t.messages if m.layout == layout)
            s, e = len(layout.start), len(layout.end)
            code = f"        kind = {p}__lookup(t + talker, cut - talker, dir);\n"
            fields = (
                "        c.b = t + (cut < inner ? cut + 1u : inner);\n"
                "        c.n = cut < inner ? inner - cut - 1u : 0u;\n"
                "        c.pos = 0u;\n        c.more = cut < inner;\n"
            )
            if layout.named:  # the code up to `named`: its part may hold the value labelled with it (`Hold:0`)
                code = (
                    f"        for (k = talker; k < cut && t[k] != {_byte(layout.named)}; k++) {{\n        }}\n"
                    f"        kind = {p}__lookup(t + talker, k - talker, dir);\n"
                )
                fields = "        c.b = t + talker;\n        c.n = inner - talker;\n"
                fields += "        c.pos = 0u;\n        c.more = 1;\n"
            starts = f'{self.call("alone")}(frame + body, n, {_c_string(layout.start)}, {s}u, "", 0u, '
            ends = f"{_c_string(layout.end)}, {e}u, &at, &inner)"
            reads.append(f"""    if (!own && {starts}{ends} &&
        n >= {s + e}u) {{ /* its own text: {comment(repr(layout.start))} ... (layout {index}) */
        const uint8_t *t = frame + body + {s}u;
        size_t cut = 0u, k = 0u;
        inner = n - {s + e}u;
        own = 1;
        while (cut < inner && t[cut] != {_byte(layout.separator)}) {{
            cut++;
        }}
        talker = {f"cut < {t.talker}u ? cut : {t.talker}u" if t.talker else "0u"};
        for (k = 0u; k < talker; k++) {{
            out->talker[k] = (char)t[k];
        }}
        out->talker[talker] = '\\0';
{code}        if (kind == {P}_KIND_NONE || !({kinds})) {{
            return {P}_E_UNKNOWN; /* no message of this text */
        }}
{fields}        c.sep = {_byte(layout.separator)};
        c.list = {_byte(layout.list or layout.separator)};
        seps = cut < inner ? 1u : 0u;
        for (k = 0u; k < c.n; k++) {{
            if (c.b[k] == c.sep || c.b[k] == c.list) {{
                seps++;
            }}
        }}
        out->sent = -1;
    }}
""")
        inner = "\n".join("    " + line if line else line for line in "".join(reads).split("\n"))
        read = "    {\n        size_t at = 0u, inner = 0u;\n" + inner + "    }\n"
        writes = "\n".join(
            f"    case {P}_{mid(m).upper()}:\n"
            f"        {self.call('put_text')}(o, {_c_string(m.layout.start)}, {len(m.layout.start)}u);\n        break;"
            for m in t.messages
            if m.layout is not None and m.layout.start
        )
        write = (
            f"    switch (msg->kind) {{ /* a message's own start, before the talker */\n{writes}\n"
            "    default:\n        break;\n    }\n"
        )
        return "    int own = 0; /* a frame in a message's own text with a start */\n" + read, write

    def alone_decode(self) -> tuple[str, str, str]:
        """Messages in their own layout, found by their code alone (an ELM327's reply `41 0C 1A F8 `, an AT modem's
        `+CSQ: 20,99`; runtime/text.py TextFraming._decode_alone), tried where the frame's first field is no code of
        a message of `dir` in the framing's own text: the helper before the decoder, the decoder's reading of one,
        and the test of the kinds whose frames are written in their own layout (encode ignores `sent` there)."""
        p, P, t = self.p, self.P, self.text
        own_kinds = " || ".join(f"msg->kind == {P}_{mid(m).upper()}" for m in t.messages if m.layout) or "0"
        found = [m for m in t.messages if m.layout is not None and not m.layout.start]  # by their code alone
        alone = sorted(found, key=lambda m: -len(m.code))
        if not alone:
            return "", "", own_kinds
        plain = [m for m in t.messages if m.layout is None and not m.values_only]
        cases = "\n".join(
            f"    case {P}_{mid(m).upper()}:\n        return dir == {P}_{m.direction.name};" for m in plain
        )
        body = f"    switch (kind) {{\n{cases}\n    default:\n        return 0;\n    }}" if plain else "    return 0;"
        helpers = f"""/* 1 when `kind` (a frame's first field's) is a message of `dir` in the framing's text. */
static int {p}__plain({p}_kind_t kind, {p}_direction_t dir)
{{
    (void)kind;
    (void)dir;
{body}
}}

"""
        skip = f"({t.talker}u < n ? {t.talker}u : n)" if t.talker else "0u"
        tries: list[str] = []
        for m in alone:
            layout = m.layout
            assert layout is not None
            after = m.read_after_code
            separator = _byte(layout.separator) if layout.separator else "0x00u"  # none: labels glued to numbers
            call = (
                f"{self.call('alone')}(t, tn, {_c_string(m.code)}, {len(m.code)}u, {_c_string(after)}, {len(after)}u, "
                f"{_c_string(layout.end)}, {len(layout.end)}u, &at, &inner)"
            )
            tries.append(
                f"        {'if' if not tries else '} else if'} (dir == {P}_{m.direction.name} &&\n"
                f"            {call}) {{\n"
                f"            kind = {P}_{mid(m).upper()};\n"
                f"            c.sep = {separator};\n"
                f"            c.list = {_byte(layout.list) if layout.list else separator};\n"
                # glued to its labels, one of them the code: read from the code on (LSS's `D1800`)
                f"            head = {len(m.code) if layout.glued and m.code_labelled else 0}u;"
            )
        read = f"""    if (!{p}__plain(kind, dir)) {{ /* found by its code alone, of `dir`: longest code first */
        const uint8_t *t = frame + body + {skip};
        size_t tn = n - {skip}, at = 0u, inner = 0u, head = 0u;
        int found = 1;
{chr(10).join(tries)}
        }} else {{
            found = 0;
        }}
        if (found) {{ /* its fields, between its own separators */
            c.b = t + at - head;
            c.n = inner + head;
            c.pos = 0u;
            c.more = c.n > 0u;
            seps = inner > 0u ? 1u : 0u;
            for (i = 0u; i < inner; i++) {{
                if (c.b[i] == c.sep || c.b[i] == c.list) {{
                    seps++;
                }}
            }}
            out->sent = -1;
        }}
    }}
"""
        return helpers, read, own_kinds

    def ends(self) -> str:
        """The line endings as C: the requests' (`end`), the responses' where they have their own (ELM327's CR CR
        `>`), and the macros that give a direction's."""
        p, P, t = self.p, self.P, self.text

        def array(name: str, ending: str, what: str) -> str:
            bytes_ = ", ".join(_byte(c) for c in ending)
            return f"static const uint8_t {p}__{name}[] = {{{bytes_}, 0x00u}}; /* {comment(repr(ending))}, {what} */\n"

        if not t.response_end:
            return (
                array("end", t.end, "the line ending")
                + f"#define {P}__END(dir) {p}__end\n#define {P}__END_LEN(dir) (sizeof({p}__end) - 1u)\n"
            )
        return (
            array("end", t.end, "the requests' line ending")
            + array("response_end", t.response_end, "the responses' line ending")
            + f"#define {P}__END(dir) ((dir) == {P}_RESPONSE ? {p}__response_end : {p}__end)\n"
            + f"#define {P}__END_LEN(dir) \\\n"
            + f"    ((dir) == {P}_RESPONSE ? sizeof({p}__response_end) - 1u : sizeof({p}__end) - 1u)\n"
        )

    def marked(self) -> bool:
        """Whether every frame carries the checksum's marker (else texts of the directions without may hold it)."""
        t = self.text
        return t.checksum is not None and len(t.checksum_directions) == 2

    def direction(self) -> str:
        """The direction of a message of each kind (encode writes its line ending)."""
        p, P = self.p, self.P
        cases = "\n".join(
            f"    case {P}_{mid(m).upper()}:" for m in self.text.messages if m.direction.value == "response"
        )
        body = (
            f"    switch (kind) {{\n{cases}\n        return {P}_RESPONSE;\n"
            f"    default:\n        return {P}_REQUEST;\n    }}"
            if cases
            else f"    (void)kind;\n    return {P}_REQUEST;"
        )
        return f"""/* The direction of a message of `kind`. */
static {p}_direction_t {p}__direction({p}_kind_t kind)
{{
{body}
}}"""

    def bare_expect(self) -> str:
        """p_parser_expect where replies of values alone are read as the reply awaited (TextStreamParser.expect)."""
        p = self.p
        return f"""
void {p}_parser_expect({p}_parser_t *parser, {p}_kind_t reply)
{{
    parser->awaited = reply;
}}
"""

    def source(self) -> str:
        p, P, t = self.p, self.P, self.text
        bare = [m for m in t.messages if m.values_only]  # replies of values alone (`values_only`)
        ends = self.ends()
        # the checksum's marker where every frame carries it (else: a check of the messages of the directions that do)
        marker = t.marker if self.marked() else ""
        special_characters = sorted({t.start, t.response_start, t.separator, marker, *t.end, *t.response_end} - {""})
        one_way = t.checksum is not None and len(t.checksum_directions) == 1
        checks = (
            "0" if t.checksum is None else "1" if not one_way else f"((dir) == {P}_{t.checksum_directions[0].upper()})"
        )
        again = (
            f"    if (r == {P}_OK && !again && {P}__CHECKS(dir) && !{P}__CHECKS({p}__direction(kind))) {{\n"
            f"        return {P}__AGAIN; /* a code of the other direction alone (runtime/text.py _decode_checked) */\n"
            f"    }}\n"
            if one_way
            else ""
        )
        direction = f"#if {P}_ENABLE_ENCODE || ({P}_ENABLE_DECODE && {int(one_way)})\n{self.direction()}\n#endif\n\n"
        checked = t.checksum is not None
        checksum, reflects = "", False
        if t.checksum is not None:
            code = t.checksum.c_code(p)
            reflects = code.reflects
            finish = code.finish.format(a="acc")
            checksum = f"""{code.definition}
#if {P}_ENABLE_DECODE || {P}_ENABLE_ENCODE
static uint32_t {p}__checksum(const uint8_t *d, size_t n)
{{
    {code.ctype} acc = {code.start};
    acc = {code.name}(acc, d, n);
    return (uint32_t)({finish});
}}
#endif
"""
        reflect = ""
        if reflects:
            reflect = f"""static uint32_t {p}__reflect(uint32_t v, int width)
{{
    uint32_t r = 0u;
    int i;
    for (i = 0; i < width; i++) {{
        r = (r << 1) | (v & 1u);
        v >>= 1;
    }}
    return r;
}}
"""
        decoders = "\n\n".join(self.decoder(m) for m in t.messages)
        alone_helpers, alone_read, own_kinds = self.alone_decode()
        address_read, address_write, address_set = self.address()
        start_read, start_write = self.framed()
        address_decl = "    size_t digits = 0u;\n    int64_t number = 0;\n" if address_read else ""
        encoders = "\n\n".join(self.encoder(m) for m in t.messages)
        by_code: dict[str, list[TextMessage]] = {}
        for m in t.messages:
            by_code.setdefault(m.code, []).append(m)
        lookups = []
        for name, found in by_code.items():
            if len(found) == 1:
                pick = f"{P}_{mid(found[0]).upper()}"
            else:
                req = next(m for m in found if m.direction.value == "request")
                res = next(m for m in found if m.direction.value == "response")
                pick = f"dir == {P}_REQUEST ? {P}_{mid(req).upper()} : {P}_{mid(res).upper()}"
            lookups.append(f"    if ({p}__is(code, n, {c_text(name)})) {{\n        return {pick};\n    }}")
        dec_cases = "\n".join(
            f"    case {P}_{mid(m).upper()}:\n        memset(&out->u.{mid(m)}, 0, sizeof(out->u.{mid(m)}));\n"
            f"        r = {p}__dec_{mid(m)}(&c, seps, &out->u.{mid(m)});\n"
            + (
                f"        if (out->sent > {len(_sent(m))}) {{ /* a text to the end of the line is one field */\n"
                f"            out->sent = {len(_sent(m))};\n        }}\n"
                if _ends_with_rest(m)
                else ""
            )
            + "        break;"
            for m in t.messages
        )
        enc_cases = "\n".join(
            f"    case {P}_{mid(m).upper()}:\n"
            f"        if (check && !{P}_ENCODES_{m.direction.name}S) {{\n"
            f"            return {P}_E_ARG; /* left out */\n        }}\n"
            + ("" if m.values_only else f"        {self.call('put_text')}(o, {c_text(m.code)}, {len(m.code)}u);\n")
            + f"        return {p}__enc_{mid(m)}(&msg->u.{mid(m)}, o, check);"
            for m in t.messages
        )
        talkers = " && ".join(f'!{p}__is((const uint8_t *)msg->talker, {t.talker}u, "{x}")' for x in t.talkers)
        talker_read = "    talker = 0u;\n    out->talker[0] = '\\0';"
        if t.talker:
            talker_read = f"""    talker = address < {t.talker}u ? address : {t.talker}u;
    for (i = 0u; i < talker; i++) {{
        out->talker[i] = (char)frame[body + i];
    }}
    out->talker[talker] = '\\0';"""
        talker_check = f"""    for (i = 0u; i < {t.talker}u; i++) {{
        if (msg->talker[i] == '\\0') {{
            return {P}_E_RANGE; /* the talker has {t.talker} characters */
        }}
    }}"""
        if not t.talker:
            talker_check = "    (void)i;"
        if talkers:
            talker_check += (
                f"\n    if ({talkers}) {{\n        return {P}_E_RANGE; /* not one of the spec's talkers */\n    }}"
            )
        talker_write = (
            ""
            if not t.talker
            else f"""    size_t i;
    for (i = 0u; i < {t.talker}u && msg->talker[i] != '\\0'; i++) {{
        {self.call("put")}(o, (uint8_t)msg->talker[i]);
    }}"""
        )
        special = Piece(
            f"""/* The framing's own characters: no field may hold one. */
static int {p}__special(uint8_t c)
{{
    return {" || ".join(f"c == {_byte(c)}" for c in special_characters)};
}}

""",
            "special",
        )
        decimal = t.checksum_format == "decimal"  # written in decimal (G-code's `*71`), not as hex digits
        read, write = (DECIMAL_CHECKED_READ, DECIMAL_CHECKED_WRITE) if decimal else (CHECKED_READ, CHECKED_WRITE)
        parts = [*HEAD, read, MIDDLE, write, BEFORE_PARSER] if checked else [*HEAD, MIDDLE, BEFORE_PARSER]
        push = START_PUSH if t.start else LINES_PUSH  # frames without a start character: every line a frame
        helpers = used([special, *parts, push, PARSER], self.calls)

        def prefixed(pieces: list[Piece]) -> str:
            return written(pieces, helpers).replace("PFX_", f"{P}_").replace("pfx_", f"{p}_")

        runtime = prefixed(parts)
        # the firmware API beside the parser (parser_api.py), inside the parser's feature switch: before its last
        # #endif (the others close role checks inside functions)
        body, closing, _ = prefixed([push, PARSER]).rpartition("}\n#endif\n")
        assert closing, "the parser piece ends its feature switch"
        parser = (
            body
            + "}\n"
            + parser_api.push_function(p, P, None)
            + parser_api.frame_function(p)
            + (parser_api.expect_function(p, P, True) if not bare else self.bare_expect())
            + "#endif\n"
        )
        kind_names = "\n".join(f'    case {P}_{mid(m).upper()}:\n        return "{mid(m)}";' for m in t.messages)
        results = ", ".join(f'"{r}"' for r in (*RESULTS, "E_ARG"))
        separated = [m for m in t.messages if m.direction.value in t.checksum_separated]
        separated_dirs = " || ".join(f"(dir) == {P}_{d.upper()}" for d in t.checksum_separated)
        separated_dirs = f"({separated_dirs})" if separated_dirs else "0"
        separated_kinds = " || ".join(f"msg->kind == {P}_{mid(m).upper()}" for m in separated) or "0"
        bare_helpers, bare_read, bare_write, expect_reply = self.bare_decode(bare)
        if start_read:  # a frame in a layout with a start is read as it, nothing else
            alone_read = alone_read.replace(f"    if (!{p}__plain(", f"    if (!own && !{p}__plain(", 1)
            bare_read = bare_read.replace("    if (reply != ", "    if (!own && reply != ", 1)
        talker_write_bare = talker_write
        if bare and talker_write:  # a reply of values alone: no talker written
            talker_write_bare = f"    if (!{P}__BARE(msg->kind)) {{\n{talker_write}\n    }}"
        reply_macros = (
            f"/* the reply of values alone the parser reads next (the reply awaited's, or the last request's) */\n"
            f"#define {P}__REPLY(p) ((p)->awaited != {P}_KIND_NONE ? {p}__bare_reply((p)->awaited) : (p)->asked)\n"
            f"#define {P}__ANSWERED(p, out) {p}__answered((p), (out))\n"
            f"#define {P}__INIT_REPLY(p) ((p)->awaited = {P}_KIND_NONE, (p)->asked = {P}_KIND_NONE)\n"
            + self.bare_macros
            if bare
            else f"#define {P}__REPLY(p) {P}_KIND_NONE\n#define {P}__ANSWERED(p, out) ((void)0)\n"
            f"#define {P}__INIT_REPLY(p) ((void)0)\n"
        )
        start = ""
        if t.start and not t.response_start:
            start = (
                f"#define {P}__START {_byte(t.start)} /* {comment(repr(t.start))} */\n"
                f"#define {P}__START_OF(dir) {P}__START\n#define {P}__IS_START(c) ((c) == {P}__START)\n"
            )
        elif t.start:  # each direction its own (Lynxmotion LSS: `#` asks, `*` answers)
            start = (
                f"#define {P}__START {_byte(t.start)} /* {comment(repr(t.start))}: the requests' */\n"
                f"#define {P}__RESPONSE_START {_byte(t.response_start)} /* {comment(repr(t.response_start))}: the "
                "responses' */\n"
                f"#define {P}__START_OF(dir) ((dir) == {P}_RESPONSE ? {P}__RESPONSE_START : {P}__START)\n"
                f"#define {P}__IS_START(c) ((c) == {P}__START || (c) == {P}__RESPONSE_START)\n"
            )
        room = f"    if (cap < 1u) {{\n        return {P}_E_BUFFER;\n    }}\n" if t.start else ""
        text = f"""{banner(self.protocol)}
#include "{p}.h"

#include <string.h>

#if {P}_ENABLE_PARSER && !{P}_ENABLE_DECODE
#error "{P}_ENABLE_PARSER needs {P}_ENABLE_DECODE"
#endif
/* The directions the build decodes ({P}_ROLE): the other side's is refused. */
#define {P}__DECODES(dir) ((dir) == {P}_REQUEST ? {P}_DECODES_REQUESTS : (dir) == {P}_RESPONSE && {P}_DECODES_RESPONSES)

/* ---- the frame, as the spec says ({comment(t.description or "")}) ---- */
#define {P}__S {len(t.start)}u /* the start character's bytes: 1, or 0 where every line is a frame */
{start}#define {P}__SEPARATOR {_byte(t.separator)}    /* {comment(repr(t.separator))} */
#define {P}__MARKER {_byte(t.marker)}          /* {comment(repr(t.marker))}: the checksum follows */
#define {P}__CHECKED {int(checked)}            /* a checksum is written */
#define {P}__CHECKS(dir) {checks} /* the frames of `dir` carry it */
#define {P}__AGAIN (-1) /* p__decode_in: read it again as the other direction's (no checksum) */
#define {P}__REQUIRED {int(t.required)}        /* a frame without one is refused */
#define {P}__DIGITS {t.digits}u                /* hex digits of the checksum */
#define {P}__SEPARATED(dir) {separated_dirs} /* a separator before the marker */
/* the parser drops a line longer than this without its line ending */
#define {P}__LIMIT(dir) ({t.max_length}u + {P}__END_LEN(dir))
{reply_macros}#if {P}_ENABLE_DECODE || {P}_ENABLE_ENCODE || {P}_ENABLE_PARSER
{ends}#endif
#define {P}__OTHER(dir) ((dir) == {P}_REQUEST ? {P}_RESPONSE : {P}_REQUEST)

#if {P}_ENABLE_DECODE || {P}_ENABLE_PARSER
/* 1 when a[0..n) and b[0..n) hold the same bytes */
static int {p}__same(const uint8_t *a, const uint8_t *b, size_t n)
{{
    size_t i;
    for (i = 0u; i < n; i++) {{
        if (a[i] != b[i]) {{
            return 0;
        }}
    }}
    return 1;
}}
#endif

#if {P}_ENABLE_DECODE || ({P}_ENABLE_ENCODE && {int(bool(t.talkers))})
/* 1 when b[0..n) is the text s */
static int {p}__is(const uint8_t *b, size_t n, const char *s)
{{
    size_t i;
    for (i = 0u; i < n; i++) {{
        if (s[i] == '\\0' || b[i] != (uint8_t)s[i]) {{
            return 0;
        }}
    }}
    return s[n] == '\\0';
}}
#endif

{written([special], helpers)}{reflect}{checksum}{runtime}
{direction}#if {P}_ENABLE_DECODE
{decoders}

/* The message a text code names: the one it names, or the one of `dir` where it names a request and a response. */
static {p}_kind_t {p}__lookup(const uint8_t *code, size_t n, {p}_direction_t dir)
{{
    (void)dir;
{chr(10).join(lookups)}
    return {P}_KIND_NONE;
}}

{bare_helpers}{alone_helpers}/* `reply`: a reply of values alone awaited ({P}_KIND_NONE: none), read where the frame's
 * first field is no code of `dir` (runtime/text.py TextFraming.decode's `reply`). `again`: a frame of the other
 * direction's (its line ending taken off), read as `dir`, which carries no checksum. */
static int {p}__decode_in(const uint8_t *frame, size_t len, {p}_direction_t dir, int again, {p}_kind_t expect,
                          {p}_kind_t reply, {p}_msg_t *out)
{{
    const {p}_direction_t sent_as = again ? {P}__OTHER(dir) : dir;
{address_decl}
    size_t body = 0u, n = 0u, i, address, seps = 0u, talker;
    {p}__cursor_t c;
    {p}_kind_t kind;
    int r, unchecked = 0;
    if (frame == NULL || out == NULL) {{
        return {P}_E_ARG;
    }}
    out->kind = {P}_KIND_NONE;
    if (!{P}__DECODES(sent_as)) {{ /* the other side's direction, left out of this build */
        return {P}_E_ARG;
    }}
    if (len > {P}_MAX_FRAME) {{
        return {P}_E_CAPACITY;
    }}
    r = {p}__unframe(frame, len, sent_as, !again && {P}__CHECKS(dir), &body, &n, &unchecked);
    if (r != {P}_OK) {{
        return r;
    }}
{address_read}    address = n;
    for (i = n; i > 0u; i--) {{
        if (frame[body + i - 1u] == {P}__SEPARATOR) {{
            seps++;
            address = i - 1u;
        }}
    }}
{talker_read}
    kind = {p}__lookup(frame + body + talker, address - talker, dir);
    out->sent = (int32_t)seps;
    c.b = frame + body;
    c.n = n;
    c.more = address < n;
    c.pos = address < n ? address + 1u : n;
    c.sep = {P}__SEPARATOR;
    c.list = {P}__SEPARATOR;
{start_read}{alone_read}{bare_read}    if (kind == {P}_KIND_NONE || (expect != {P}_KIND_NONE && expect != kind)) {{
        return {P}_E_UNKNOWN;
    }}
    out->unchecked = unchecked != 0;
    switch (kind) {{
{dec_cases}
    case {P}_KIND_NONE:
    case {P}_KIND_COUNT:
    default:
        return {P}_E_UNKNOWN;
    }}
{again}{address_set}    if (r == {P}_OK) {{
        out->kind = kind;
    }}
    return r;
}}

static int {p}__decode(const uint8_t *frame, size_t len, {p}_direction_t dir, {p}_kind_t expect, {p}_kind_t reply,
                       {p}_msg_t *out)
{{
    int r = {p}__decode_in(frame, len, dir, 0, expect, reply, out);
    if (r == {P}__AGAIN) {{ /* a code of the other direction alone: its frame is text to its end, the marker too */
        r = {p}__decode_in(frame, len, {P}__OTHER(dir), 1, expect, reply, out);
    }}
    return r;
}}

int {p}_decode_expect(const uint8_t *frame, size_t len, {p}_direction_t dir, {p}_kind_t expect, {p}_msg_t *out)
{{
    return {p}__decode(frame, len, dir, expect, {expect_reply}, out);
}}

int {p}_decode(const uint8_t *frame, size_t len, {p}_direction_t dir, {p}_msg_t *out)
{{
    return {p}__decode(frame, len, dir, {P}_KIND_NONE, {P}_KIND_NONE, out);
}}
#endif

{encoders}

/* Address, talker, code and fields (range-checked when `check`), from o's position on. */
static int {p}__body(const {p}_msg_t *msg, {p}__out_t *o, int check)
{{
{address_write}{start_write}{talker_write_bare}
    switch (msg->kind) {{
{enc_cases}
    case {P}_KIND_NONE:
    case {P}_KIND_COUNT:
    default:
        return {P}_E_ARG;
    }}
}}

int {p}_field_texts(const {p}_msg_t *msg, uint8_t *buf, size_t cap, size_t *len)
{{
    {p}__out_t o;
    int r;
    if (msg == NULL || buf == NULL || len == NULL) {{
        return {P}_E_ARG;
    }}
    o.b = buf;
    o.cap = cap;
    o.n = 0u;
    o.full = 0;
    o.rest = 0u;
    r = {p}__body(msg, &o, 0);
    if (r == {P}_OK && o.full) {{
        r = {P}_E_BUFFER;
    }}
    *len = o.n;
    return r;
}}

{parser}
#if {P}_ENABLE_ENCODE

int {p}_encode(const {p}_msg_t *msg, uint8_t *buf, size_t cap, size_t *len)
{{
    {p}__out_t o;
    size_t i, at = 0u;
    int r;
    (void)at;
    if (msg == NULL || buf == NULL || len == NULL) {{
        return {P}_E_ARG;
    }}
{talker_check}
{room}    o.b = buf;
    o.cap = cap;
    o.n = {P}__S;
    o.full = 0;
    o.rest = 0u;
    r = {p}__body(msg, &o, 1);
    if (r != {P}_OK) {{
        return r;
    }}
    if (msg->sent >= 0 && !o.full && !({own_kinds})) {{ /* as many fields as the sentence had */
        r = {p}__trim(&o, (size_t)msg->sent);
        if (r != {P}_OK) {{
            return r;
        }}
    }}
{bare_write}
    return {p}__frame(&o, len, msg->unchecked, {separated_kinds}, {p}__direction(msg->kind));
}}
#endif

const char *{p}_kind_name({p}_kind_t kind)
{{
    switch (kind) {{
{kind_names}
    case {P}_KIND_NONE:
    case {P}_KIND_COUNT:
    default:
        return "";
    }}
}}

const char *{p}_result_name(int result)
{{
    static const char *const names[] = {{{results}}};
    if (result < 0 || result > (int){P}_E_ARG) {{
        return "";
    }}
    return names[result];
}}
"""
        return text


def _ends_with_rest(m: TextMessage) -> bool:
    """Whether the message's last field is a text to the end of the line (`size: rest`)."""
    return bool(m.fields) and isinstance(m.fields[-1], TextField) and m.fields[-1].rest


def _c_string(text: str) -> str:
    """Any text as a C string literal: letters and digits as they are, every other character as an octal escape (no
    trigraph, no escape that runs on)."""
    return '"' + "".join(c if c.isascii() and c.isalnum() else f"\\{ord(c):03o}" for c in text) + '"'


def _c_char(c: str) -> str:
    return {"'": "\\'", "\\": "\\\\"}.get(c, c)


def _exact(value: float) -> tuple[int, int]:
    """A spec bound as mantissa and decimal exponent: value = mantissa / 10^exponent, from its shortest repr."""
    number = Decimal(repr(float(value))).normalize()
    sign, digits, exponent = number.as_tuple()
    assert isinstance(exponent, int)
    mantissa = int("".join(map(str, digits)) or "0") * (-1 if sign else 1)
    if exponent > 0:
        return mantissa * 10**exponent, 0
    return mantissa, -exponent


def banner(protocol: Protocol) -> str:
    return binary_banner(protocol)


def json_header(protocol: Protocol) -> str:
    p, P = protocol.name, protocol.name.upper()
    return f"""{banner(protocol)}
#ifndef {P}_JSON_H
#define {P}_JSON_H

#include "{p}.h"

#ifdef __cplusplus
extern "C" {{
#endif

/* The message as `serialspec decode --json` shows it: command, subcommand, direction, talker, sent, and each field
 * as its text ("" when absent). snprintf-like: the length of the whole text, at most cap - 1 characters written. */
size_t {p}_to_json(const {p}_msg_t *msg, char *out, size_t cap);

#ifdef __cplusplus
}}
#endif

#endif
"""


def _labelled_json(p: str, m: TextMessage, layout: TextLayout, text: TextFrame) -> str:
    """p_to_json's fields of a message whose fields have labels, from its text as encode writes it (its fields
    present, in order, the one labelled with the code right after it): where each value is, then each field in
    order, an absent one "" (a repeat: [])."""
    items = _sent(m)
    u = f"msg->u.{mid(m)}"
    numbers = int(layout.glued and not layout.separator)  # values that end where a label begins
    stop = _byte(layout.separator) if layout.separator else "0x00u"
    lines = [
        f"    for (c.pos = 0u; c.pos < {text.talker}u && msg->talker[c.pos] != '\\0'; c.pos++) {{\n    }}"
        if text.talker
        else "    c.pos = 0u;",
        f"    {p}__j_over(&c, {'lead + ' if text.address else ''}{len(layout.start) + len(m.code)}u);",
    ]
    if layout.end:
        lines.append(f"    c.n = len >= {len(layout.end)}u ? len - {len(layout.end)}u : 0u;")
    lines.append("    c.pos = c.pos < c.n ? c.pos : c.n;")
    # the code's own value first, then what follows the code, then the others in order
    written = [i for i, f in enumerate(items) if f.label == m.code] + [-1]
    written += [i for i, f in enumerate(items) if f.label != m.code]
    for i in written:
        if i < 0:
            lines.append(f"    {p}__j_over(&c, {len(layout.follows_code)}u);")
            continue
        item = items[i]
        own = item.label == m.code
        skip = len(layout.named) if own else len(item.label) + len(layout.named)
        lines.append(
            f"    if ({u}.has_{ident(item.name)}) {{\n        {p}__j_over(&c, {skip}u);\n        at[{i}] = c.pos;\n"
            f"        {p}__j_value(&c, {stop}, {numbers});\n        span[{i}] = c.pos - at[{i}];\n"
            + ("" if own else f"        {p}__j_over(&c, {len(layout.separator)}u);\n")
            + "    }"
        )
    first = text.address is None
    if text.address is not None:  # its digits, first in the text
        lines.append(f'    {p}__j_str(&j, "\\"{text.address.name}\\":");\n    {p}__j_text(&j, body, lead);')
    for i, item in enumerate(items):
        comma = "" if first else ","
        first = False
        if isinstance(item, TextField):
            lines.append(
                f'    {p}__j_str(&j, "{comma}\\"{item.name}\\":");\n    {p}__j_text(&j, body + at[{i}], span[{i}]);'
            )
            continue
        name = ident(item.name)
        groups = f"{item.count}u" if item.count else f"{u}.{name}_count"
        names = "\n".join(
            f'            {p}__j_str(&j, "{"" if k == 0 else ","}\\"{f.name}\\":");\n            {p}__j_field(&j, &d);'
            for k, f in enumerate(item.fields)
        )
        lines.append(
            f'    {p}__j_str(&j, "{comma}\\"{item.name}\\":[");\n'
            f"    if ({u}.has_{name}) {{\n"
            f"        d.b = body + at[{i}];\n        d.n = span[{i}];\n        d.pos = 0u;\n"
            f"        d.sep = {_byte(layout.list)};\n        d.list = {_byte(layout.list)};\n"
            f"        for (g = 0u; g < {groups}; g++) {{\n"
            f'            {p}__j_str(&j, g > 0u ? ",{{" : "{{");\n{names}\n            {p}__j_str(&j, "}}");\n'
            f"        }}\n    }}\n"
            f'    {p}__j_str(&j, "]");'
        )
    decls = f"    size_t at[{len(items)}] = {{0u}}, span[{len(items)}] = {{0u}};\n"
    if any(isinstance(i, TextRepeat) for i in items):
        decls += f"    {p}__jcur_t d;\n"
    return "{\n" + decls + "\n".join(lines) + "\n}"


def json_source(protocol: Protocol, text: TextFrame) -> str:
    p, P = protocol.name, protocol.name.upper()
    grow = sum(
        (f.width + 3) * (item.count or item.max_count if isinstance(item, TextRepeat) else 1)
        for m in text.messages
        for item in m.fields
        for f in (item.fields if isinstance(item, TextRepeat) else (item,))
    )
    texts = sum(
        (item.count or item.max_count if isinstance(item, TextRepeat) else 1)
        for m in text.messages
        for item in m.fields
        for f in (item.fields if isinstance(item, TextRepeat) else (item,))
        if f.kind == "text"
    )
    cases = []
    for m in text.messages:
        parts = []
        first = True
        for item in m.fields:
            comma = "" if first else ","
            first = False
            if isinstance(item, TextField) and item.address:  # its digits, first in the text
                parts.append(f'    {p}__j_str(&j, "{comma}\\"{item.name}\\":");\n    {p}__j_text(&j, body, lead);')
                continue
            if isinstance(item, TextField):
                read = "j_rest" if item.rest else "j_field"
                parts.append(f'    {p}__j_str(&j, "{comma}\\"{item.name}\\":");\n    {p}__{read}(&j, &c);')
                continue
            groups = f"{item.count}u" if item.count else f"msg->u.{mid(m)}.{ident(item.name)}_count"
            names = []
            for k, f in enumerate(item.fields):
                sep = "" if k == 0 else ","
                names.append(f'        {p}__j_str(&j, "{sep}\\"{f.name}\\":");\n        {p}__j_field(&j, &c);')
            inner = "\n".join(names)
            parts.append(
                f'    {p}__j_str(&j, "{comma}\\"{item.name}\\":[");\n'
                f"    for (g = 0u; g < {groups}; g++) {{\n"
                f'        {p}__j_str(&j, g > 0u ? ",{{" : "{{");\n{inner}\n        {p}__j_str(&j, "}}");\n    }}\n'
                f'    {p}__j_str(&j, "]");'
            )
        body = "\n".join(parts)
        if m.layout is not None and m.layout.labelled:
            body = _labelled_json(p, m, m.layout, text)
        elif m.layout is not None:  # its own layout: the fields after the talker, code and what follows the code
            layout = m.layout
            after = layout.follows_code
            body = (
                (
                    f"    for (c.pos = 0u; c.pos < {text.talker}u && msg->talker[c.pos] != '\\0'; c.pos++) {{\n    }}\n"
                    if text.talker
                    else "    c.pos = 0u;\n"
                )
                + f"    c.pos += {'lead + ' if text.address else ''}{len(layout.start) + len(m.code) + len(after)}u;\n"
                + (f"    c.n = len >= {len(layout.end)}u ? len - {len(layout.end)}u : 0u;\n" if layout.end else "")
                + f"    c.pos = c.pos < c.n ? c.pos : c.n;\n"
                f"    c.sep = {_byte(layout.separator)};\n    c.list = {_byte(layout.list or layout.separator)};\n"
                + body
            )
        cases.append(
            f"    case {P}_{mid(m).upper()}:\n"
            f'        {p}__j_str(&j, "{{\\"command\\":\\"{m.key}\\",\\"subcommand\\":null,\\"direction\\":'
            f'\\"{m.direction.value}\\",");\n'
            f"        {p}__j_head(&j, msg);\n"
            + "\n".join("    " + line if line else line for line in body.split("\n"))
            + f'\n        {p}__j_str(&j, "}}}}");\n        break;'
        )
    rest = ""
    if any(_ends_with_rest(m) for m in text.messages):
        rest = f"""/* A text to the end of the line: the rest of the fields' text. */
static void {p}__j_rest({p}__json_t *j, {p}__jcur_t *c)
{{
    {p}__j_text(j, c->b + c->pos, c->n - c->pos);
    c->pos = c->n;
}}

"""
    if any(m.layout is not None and m.layout.labelled for m in text.messages):
        rest += f"""/* Past k characters (a label and what follows it), at most to the end. */
static void {p}__j_over({p}__jcur_t *c, size_t k)
{{
    c->pos = c->n - c->pos > k ? c->pos + k : c->n;
}}

/* Past a labelled value: to `sep`, or (numbers) past the run of number characters. */
static void {p}__j_value({p}__jcur_t *c, uint8_t sep, int numbers)
{{
    while (c->pos < c->n && (numbers ? (c->b[c->pos] >= 0x30u && c->b[c->pos] <= 0x39u) || c->b[c->pos] == 0x2Bu ||
                                           c->b[c->pos] == 0x2Du || c->b[c->pos] == 0x2Eu
                                     : c->b[c->pos] != sep)) {{
        c->pos++;
    }}
}}

"""
    field = ""
    if any(  # a field read in turn: of a message without labels (but an address or the rest of the line), a repeat's
        isinstance(item, TextRepeat) or not (item.address or item.rest or (m.layout is not None and m.layout.labelled))
        for m in text.messages
        for item in m.fields
    ):
        field = f"""static void {p}__j_field({p}__json_t *j, {p}__jcur_t *c)
{{
    size_t start = c->pos;
    while (c->pos < c->n && c->b[c->pos] != c->sep && c->b[c->pos] != c->list) {{
        c->pos++;
    }}
    {p}__j_text(j, c->b + start, c->pos - start);
    if (c->pos < c->n) {{
        c->pos++;
    }}
}}

"""
    lead = ""
    if text.address is not None:  # the address's digits, before the talker and code
        lead = "    while (lead < len && body[lead] >= 0x30u && body[lead] <= 0x39u) {\n        lead++;\n    }\n"
        lead += "    c.pos = lead;\n"
    # the talker, where the frames carry one (decode --json names none in a protocol without)
    talker_json, sent_lead = "", ""
    if text.talker:
        talker_json = (
            f'    size_t i;\n    {p}__j_str(j, "\\"talker\\":");\n'
            f"    for (i = 0u; i < {text.talker}u && msg->talker[i] != '\\0'; i++) {{\n    }}\n"
            f"    {p}__j_text(j, (const uint8_t *)msg->talker, i);\n"
        )
        sent_lead = ","
    return f"""{banner(protocol)}
#include "{p}_json.h"

#include <stdio.h>

/* the fields as text: the frame, numbers padded to their widths, texts at their room */
#define {P}__JSON_BODY ({P}_MAX_FRAME + {grow}u + {texts}u * {P}_TEXT_MAX)

typedef struct {{
    char *out;
    size_t cap;
    size_t n;
}} {p}__json_t;

static void {p}__j_char({p}__json_t *j, char c)
{{
    if (j->n + 1u < j->cap) {{
        j->out[j->n] = c;
    }}
    j->n++;
}}

static void {p}__j_str({p}__json_t *j, const char *s)
{{
    while (*s != '\\0') {{
        {p}__j_char(j, *s++);
    }}
}}

/* A JSON string of t[0..n). */
static void {p}__j_text({p}__json_t *j, const uint8_t *t, size_t n)
{{
    size_t i;
    {p}__j_char(j, '"');
    for (i = 0u; i < n; i++) {{
        char c = (char)t[i];
        if (c == '"' || c == '\\\\') {{
            {p}__j_char(j, '\\\\');
            {p}__j_char(j, c);
        }} else if (t[i] < 0x20u || t[i] > 0x7Eu) {{
            char esc[8];
            (void)snprintf(esc, sizeof(esc), "\\\\u%04x", (unsigned)t[i]);
            {p}__j_str(j, esc);
        }} else {{
            {p}__j_char(j, c);
        }}
    }}
    {p}__j_char(j, '"');
}}

/* The fields' texts one after another, as the frame has them after the address, ended by sep or list (a message's
 * own layout's). */
typedef struct {{
    const uint8_t *b;
    size_t n;
    size_t pos;
    uint8_t sep;
    uint8_t list;
}} {p}__jcur_t;

{field}{rest}static void {p}__j_head({p}__json_t *j, const {p}_msg_t *msg)
{{
    char number[40];
{talker_json}    (void)snprintf(number, sizeof(number), "{sent_lead}\\"sent\\":%d,\\"fields\\":{{", (int)msg->sent);
    {p}__j_str(j, number);
}}

size_t {p}_to_json(const {p}_msg_t *msg, char *out, size_t cap)
{{
    {p}__json_t j;
    {p}__jcur_t c;
    uint8_t body[{P}__JSON_BODY];
    size_t len = 0u, g = 0u, lead = 0u;
    (void)lead;
    j.out = out;
    j.cap = cap;
    j.n = 0u;
    (void)g;
    if ({p}_field_texts(msg, body, sizeof(body), &len) != {P}_OK) {{
        len = 0u;
    }}
    c.b = body;
    c.n = len;
    c.pos = 0u;
    c.sep = {_byte(text.separator)};
    c.list = {_byte(text.separator)};
{lead}    while (c.pos < c.n && body[c.pos] != {_byte(text.separator)}) {{ /* the talker and code: skipped */
        c.pos++;
    }}
    if (c.pos < c.n) {{
        c.pos++;
    }}
    switch (msg == NULL ? {P}_KIND_NONE : msg->kind) {{ /* no message: null, as the binary targets write */
{chr(10).join(cases)}
    case {P}_KIND_NONE:
    case {P}_KIND_COUNT:
    default:
        {p}__j_str(&j, "null");
        break;
    }}
    if (cap > 0u) {{
        out[j.n < cap ? j.n : cap - 1u] = '\\0';
    }}
    return j.n;
}}
"""


def files(protocol: Protocol, text: TextFrame) -> dict[str, str]:
    gen = TextC(protocol, text)
    p = protocol.name
    return {
        f"{p}/{p}.h": gen.header(),
        f"{p}/{p}.c": gen.source(),
        f"{p}/{p}_json.h": json_header(protocol),
        f"{p}/{p}_json.c": json_source(protocol, text),
    }


def c_text(code: str) -> str:
    """A text code as a C string literal: `?` escaped, so that `??=` is no trigraph (C99 reads them)."""
    return '"' + code.replace("?", "\\?") + '"'
