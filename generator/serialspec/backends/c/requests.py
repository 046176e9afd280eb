"""Replies read with the request they answer, in C (runtime/framing.py: FrameCodec's `replies`, a checksum's
`request` elements): replies that carry no code, read in the layout of the reply awaited (layouts chosen by
command), and reply checksums that take in bytes of the request first (`from_request`). The API takes the request
as a message (p_decode_reply, p_encode_reply, p_parser_expect_reply): its bytes are made from its members, as the
request's frame carries them, and the reply it awaits is its command's."""

from __future__ import annotations

from serialspec.backends import Unsupported
from serialspec.backends.c.emit import Ctx, ident, messages, msg_id
from serialspec.backends.common.frames import layout_index
from serialspec.backends.common.pairing import layout_refusals
from serialspec.lang.model import VALUE_ROLES, Bytes, Direction, Message, Protocol, fixed_size


def asks(protocol: Protocol) -> bool:
    """Some reply is read with its request: the C API takes it (the functions below are generated)."""
    return protocol.framing.from_request or protocol.framing.by_request(Direction.RESPONSE)


def asked_replies(protocol: Protocol) -> list[tuple[Message, Message, str, int]]:
    """Replies whose last bytes are as many as a field of their request says (`size_from`) in a layout without a
    length, read as the reply awaited: (reply, its request, the request's field, the reply's bytes before them). The
    parser keeps that field's value (`asked`, from p_parser_expect_reply) to size them (runtime SizeRule.request)."""
    found = []
    for reply in protocol.messages():
        *before, last = reply.fields or (None,)
        if reply.direction != Direction.RESPONSE or not isinstance(last, Bytes) or not last.size_from:
            continue
        if protocol.layout(reply).length is not None or not by_reply(protocol, Direction.RESPONSE):
            continue
        request = next(
            m for m in protocol.messages() if m.direction == Direction.REQUEST and reply_of(protocol, m) is reply
        )
        fixed = sum(fixed_size(f) or 0 for f in before) + last.size_from_adds  # `request.count + 1`
        found.append((reply, request, last.size_from, fixed))
    return found


def by_reply(protocol: Protocol, direction: Direction) -> bool:
    """The direction's frames carry no code: each is read in the layout of the reply awaited (layouts chosen by
    command, or one layout's code-less replies that only the reply awaited sizes: Framing.by_request)."""
    return protocol.framing.by_request(direction)


def kind_name(ctx: Ctx, message: Message) -> str:
    return f"{ctx.P}_{msg_id(message).upper()}"  # (files.kind_name's)


def reply_of(protocol: Protocol, request: Message) -> Message | None:
    """The reply a request awaits: its command's (its sub-command's) response."""
    command = protocol.command(request.command)
    sub = next((s for s in command.subcommands if s.name == request.subcommand), None)
    return sub.response if sub is not None else command.response


def taken_names(protocol: Protocol, reply: Message) -> tuple[str, ...]:
    """The request elements a reply's checksums take in first (one list per layout)."""
    found = {c.from_request for c in protocol.layout(reply).checksums if c.from_request}
    if len(found) > 1:
        raise Unsupported(f"checksums over different bytes of the request (`from_request`, {reply.key})")
    return next(iter(found), ())


def request_bytes(ctx: Ctx) -> tuple[str, int]:
    """{p}__request_bytes: a request's bytes its reply's checksum takes in first, and the reply it awaits; and the
    most bytes any request gives (at least 1)."""
    protocol, p, P = ctx.protocol, ctx.p, ctx.P
    cases: list[str] = []
    most = 1
    for m in messages(protocol):
        if m.direction != Direction.REQUEST:
            continue
        reply = reply_of(protocol, m)
        body = [f"    case {kind_name(ctx, m)}:"]
        if reply is not None:
            body.append(f"        *reply = {kind_name(ctx, reply)};")
            layout = protocol.layout(m)
            at = 0
            for name in taken_names(protocol, reply):
                e = next(e for e in layout.elements if e.name == name)
                size = e.size or len(e.constant)
                if e.role in VALUE_ROLES:
                    value = f"(uint32_t)request->u.{msg_id(m)}.{ident(name)}"
                elif e.role == "command":
                    code = protocol.command(m.command).wire_code(Direction.REQUEST)
                    value = f"{code or 0}UL"
                elif e.constant:
                    value = f"{int.from_bytes(e.constant, 'big')}UL"
                    size = len(e.constant)
                else:
                    raise Unsupported(f"a reply checksum over the request's {e.role} element {name} (`from_request`)")
                for i in range(size):
                    shift = 8 * (size - 1 - i) if e.endian == ">" or e.constant else 8 * i
                    body.append(f"        pre[{at + i}u] = (uint8_t)(({value} >> {shift}u) & 0xFFu); /* {name} */")
                at += size
            body.append(f"        *n = {at}u;")
            most = max(most, at)
        body.append("        return 1;")
        cases.append("\n".join(body))
    text = f"""
#if {P}_ENABLE_ENCODE || {P}_ENABLE_DECODE
/* A request's bytes that its reply's checksum takes in first (`from_request`, as the request's frame carries them),
 * and the reply it awaits (its command's); 0 for no request. */
static int {p}__request_bytes(const {p}_msg_t *request, uint8_t *pre, size_t *n, {p}_kind_t *reply)
{{
    *n = 0u;
    *reply = {P}_KIND_NONE;
    (void)pre;
    if (request == NULL) {{
        return 0;
    }}
    switch (request->kind) {{
{chr(10).join(cases)}
    default:
        return 0;
    }}
}}
#endif
"""
    return text, most


def reply_layout(ctx: Ctx) -> str:
    """{p}__reply_layout: the index of the response layout a reply kind travels in (-1: no reply), where replies
    carry no code."""
    protocol, p = ctx.protocol, ctx.p
    if not by_reply(protocol, Direction.RESPONSE):
        return ""
    names = [layout.name for layout in protocol.framing.alternatives[Direction.RESPONSE]]
    cases = [
        f"    case {kind_name(ctx, m)}:\n        return {names.index(protocol.layout(m).name)};"
        for m in messages(protocol)
        if m.direction == Direction.RESPONSE
    ]
    return f"""
/* The response layout a reply travels in (replies carry no code: read in the layout of the reply awaited); -1 for
 * a kind that is no reply. */
static int {p}__reply_layout({p}_kind_t kind)
{{
    switch (kind) {{
{chr(10).join(cases)}
    default:
        return -1;
    }}
}}
"""


def refusal_kinds(ctx: Ctx) -> dict[str, list[tuple[str, int]]]:
    """Reply kind awaited -> (kind, layout index) of each reply refusing its request in a layout of its own."""
    return {
        kind_name(ctx, reply): [(kind_name(ctx, m), layout_index(ctx.protocol, m)) for m in others]
        for reply, others in layout_refusals(ctx.protocol)
    }


def refusal(ctx: Ctx, unwrap: str) -> str:
    """Lines of {p}__decode_with after the reply awaited failed to unwrap in its layout (`r`, layout `k`): a frame
    that starts with the header of a reply refusing the request, in a layout of its own, is that reply
    (FrameCodec.unwrap's `refusals`); `unwrap` is the call that unwraps in layout k."""
    P, p = ctx.P, ctx.p
    found = refusal_kinds(ctx)
    if not found:
        return f"""        if (r != {P}_OK) {{
            return r;
        }}"""
    cases = []
    for awaited, others in found.items():
        tests = "\n".join(
            f"""                h = {p}__header(dir, {index}u, &hl);
                if (refused == {P}_KIND_NONE && hl <= len && {p}__same(frame, h, hl)) {{
                    refused = {kind};
                    k = {index}u;
                }}"""
            for kind, index in others
        )
        cases.append(f"            case {awaited}:\n{tests}\n                break;")
    return f"""        if (r != {P}_OK) {{ /* a reply that refuses the request in a layout of its own (`refused_by`)? */
            {p}_kind_t refused = {P}_KIND_NONE;
            size_t hl;
            const uint8_t *h;
            switch (expect) {{
{chr(10).join(cases)}
            default:
                break;
            }}
            if (refused == {P}_KIND_NONE) {{
                return r;
            }}
            expect = refused;
            r = {unwrap};
            if (r != {P}_OK) {{
                return r;
            }}
        }}"""


def prototypes(ctx: Ctx) -> str:
    p = ctx.p
    return f"""
/* Replies read with the request they answer (replies without a code, read in the layout of the reply awaited; a
 * reply checksum over bytes of the request): give the request as a message, as it was sent. */
/* Decode a reply to `request` (the reply its command awaits). */
int {p}_decode_reply(const uint8_t *frame, size_t len, const {p}_msg_t *request, {p}_msg_t *out);
/* Encode a reply to `request` ({p}_encode and the per-message encoders refuse such a reply with {ctx.P}_E_ARG). */
int {p}_encode_reply(const {p}_msg_t *msg, const {p}_msg_t *request, uint8_t *buf, size_t cap, size_t *len);
/* The parser's {p}_parser_expect for the reply to `request`, with the request's bytes (NULL: no reply awaited). */
void {p}_parser_expect_reply({p}_parser_t *parser, const {p}_msg_t *request);
"""


def parser_members(ctx: Ctx) -> str:
    P = ctx.P
    asked = (
        "    long asked; /* the size the request awaited asks of its reply (`size_from`; -1: none) */\n"
        if asked_replies(ctx.protocol)
        else ""
    )
    return (
        f"    uint8_t request[{P}_REQUEST_BYTES];    /* the request replies answer ({ctx.p}_parser_expect_reply) */\n"
        "    size_t request_len;\n"
        "    uint8_t has_request;\n" + asked
    )


def functions(ctx: Ctx) -> tuple[str, str]:
    """p_decode_reply (after the decoder), and p_encode_reply (after the encoders)."""
    protocol, p, P = ctx.protocol, ctx.p, ctx.P
    decode = f"""
int {p}_decode_reply(const uint8_t *frame, size_t len, const {p}_msg_t *request, {p}_msg_t *out)
{{
    uint8_t pre[{P}_REQUEST_BYTES] = {{0u}}; /* zeroed: only n bytes are read, which gcc cannot tell */
    size_t n;
    {p}_kind_t reply;
    if (frame == NULL || out == NULL) {{
        return {P}_E_ARG;
    }}
    out->kind = {P}_KIND_NONE;
    if (!{p}__request_bytes(request, pre, &n, &reply)) {{
        return {P}_E_ARG;
    }}
    return {p}__decode_with(frame, len, {P}_RESPONSE, reply, pre, n, out);
}}
"""
    cases = "\n".join(
        f"    case {kind_name(ctx, m)}:\n"
        f"        return {p}__encode_{msg_id(m)}(&msg->u.{msg_id(m)}, pre, n, buf, cap, len);"
        for m in messages(protocol)
        if m.direction == Direction.RESPONSE
    )
    encode = f"""
int {p}_encode_reply(const {p}_msg_t *msg, const {p}_msg_t *request, uint8_t *buf, size_t cap, size_t *len)
{{
    uint8_t pre[{P}_REQUEST_BYTES] = {{0u}}; /* zeroed: only n bytes are read, which gcc cannot tell */
    size_t n;
    {p}_kind_t reply;
    if (msg == NULL || buf == NULL || len == NULL) {{
        return {P}_E_ARG;
    }}
    *len = 0u;
    (void)cap;
    if (!{P}_ENCODES_RESPONSES || !{p}__request_bytes(request, pre, &n, &reply)) {{
        return {P}_E_ARG;
    }}
    switch (msg->kind) {{
#if {P}_ENCODES_RESPONSES
{cases}
#endif
    default:
        return {P}_E_ARG;
    }}
}}
"""
    return decode, encode


def expect_reply(ctx: Ctx) -> str:
    p = ctx.p
    return f"""
void {p}_parser_expect_reply({p}_parser_t *parser, const {p}_msg_t *request)
{{
    {p}_kind_t reply;
    size_t n;
    int has = {p}__request_bytes(request, parser->request, &n, &reply);
    {p}_parser_expect(parser, reply);
    parser->has_request = (uint8_t)has;
    parser->request_len = n;{asked_lines(ctx)}
}}
"""


def asked_lines(ctx: Ctx) -> str:
    """p_parser_expect_reply's lines keeping the request's field that sizes its reply (asked_replies)."""
    found = asked_replies(ctx.protocol)
    if not found:
        return ""
    cases = "".join(
        f"\n    case {kind_name(ctx, request)}:\n        parser->asked = (long)request->u.{msg_id(request)}."
        f"{ident(field.removeprefix('request.'))}; /* {reply.key}: size_from request.{field} */\n        break;"
        for reply, request, field, _ in found
    )
    return f"""
    if (request == NULL) {{
        return;
    }}
    switch (request->kind) {{{cases}
    default:
        break;
    }}"""
