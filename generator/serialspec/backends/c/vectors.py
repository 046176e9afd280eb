"""Golden vectors for the C target: `<protocol>/test/vectors.h` and `<protocol>/test/check_vectors.c`.

Firmware developers vendor the generated C without serialspec; these two files let their own build check it: every
example frame the spec records (decoded to its message, encoded back byte for byte, and found by the parser fed one
byte at a time) and every frame an erratum says the document prints wrong (refused by the decoder). The same
program runs in our tests under every compiler of the matrix.
"""

from __future__ import annotations

from serialspec.backends.c import requests as asking
from serialspec.backends.c.emit import Ctx, comment, msg_id
from serialspec.backends.c.files import banner
from serialspec.lang.model import Direction, Message, Protocol

_PER_LINE = 12  # bytes per line of a frame's initializer


def _message(protocol: Protocol, command: str, subcommand: str | None, direction: Direction) -> Message | None:
    return next(
        (m for m in protocol.messages() if (m.command, m.subcommand, m.direction) == (command, subcommand, direction)),
        None,
    )


def _bytes(frame: bytes) -> str:
    rows = [", ".join(f"0x{b:02X}" for b in frame[i : i + _PER_LINE]) for i in range(0, len(frame), _PER_LINE)]
    return ",\n    ".join(rows)


def _c_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def vectors(ctx: Ctx) -> tuple[list[tuple[str, Direction, str, bytes]], list[tuple[str, Direction, bytes]]]:
    """(name, direction, kind constant, frame) of every example; (name, direction, frame) of every `frame_fails`
    erratum frame. (A `frame_decodes_as` erratum frame may hold values out of range: decoded, but not encoded back.)"""
    protocol, P = ctx.protocol, ctx.P
    good: list[tuple[str, Direction, str, bytes]] = []
    for example in protocol.examples:
        message = _message(protocol, example.command, example.subcommand, example.direction)
        if message is not None:
            good.append((example.name, example.direction, f"{P}_{msg_id(message).upper()}", example.frame))
    refused: list[tuple[str, Direction, bytes]] = []
    for erratum in protocol.errata:
        check = erratum.check
        if check.frame is None or check.direction is None:
            continue
        if check.kind == "frame_fails":
            refused.append((erratum.name, check.direction, check.frame))
    return good, refused


def request_frame(protocol: Protocol, name: str) -> bytes | None:
    """The frame of the request an example answers (its `request:` example, else the first example of its command's
    request), where replies are read with their request; None otherwise."""
    example = next(e for e in protocol.examples if e.name == name)
    if example.direction != Direction.RESPONSE or not asking.asks(protocol):
        return None
    if example.request:
        return next(e.frame for e in protocol.examples if e.name == example.request)
    return next(
        (
            e.frame
            for e in protocol.examples
            if (e.command, e.subcommand, e.direction) == (example.command, example.subcommand, Direction.REQUEST)
        ),
        None,
    )


def vectors_header(ctx: Ctx) -> str:
    protocol, p, P = ctx.protocol, ctx.p, ctx.P
    good, refused = vectors(ctx)
    asks = asking.asks(protocol)
    arrays: list[str] = []
    rows: list[str] = []
    for i, (name, direction, kind, frame) in enumerate(good):
        arrays.append(f"static const uint8_t {p}__vector_{i}[] = {{\n    {_bytes(frame)}\n}};")
        asked = ""
        if asks:  # the request a reply answers (decoded, then given to p_decode_reply): its frame
            request = request_frame(protocol, name)
            if request is not None:
                arrays.append(f"static const uint8_t {p}__request_{i}[] = {{\n    {_bytes(request)}\n}};")
            asked = f", {p}__request_{i}, {len(request)}u" if request is not None else ", NULL, 0u"
        rows.append(f"    {{{_c_string(name)}, {P}_{direction.name}, {kind}, {p}__vector_{i}, {len(frame)}u{asked}}},")
    none = ", NULL, 0u" if asks else ""
    refused_rows: list[str] = []
    for i, (name, direction, frame) in enumerate(refused):
        arrays.append(f"static const uint8_t {p}__refused_{i}[] = {{\n    {_bytes(frame)}\n}};")
        refused_rows.append(
            f"    {{{_c_string(name)}, {P}_{direction.name}, {P}_KIND_NONE, {p}__refused_{i}, {len(frame)}u{none}}},"
        )
    end = f"    {{NULL, {P}_REQUEST, {P}_KIND_NONE, NULL, 0u{none}}} /* end */"
    return (
        banner(protocol)
        + f"/* Golden vectors of {comment(protocol.title)}: every example frame the spec records (a frame, its\n"
        " * direction and the message it decodes to) and every frame an erratum says the document prints wrong (the\n"
        " * decoder refuses it). test/check_vectors.c checks the codec and the parser against them. */\n\n"
        f"#ifndef {P}_VECTORS_H\n#define {P}_VECTORS_H\n\n"
        f'#include "../{p}.h"\n\n'
        "typedef struct {\n"
        "    const char *name;      /* its name in the spec */\n"
        f"    {p}_direction_t direction;\n"
        f"    {p}_kind_t kind;        /* the message it decodes to ({P}_KIND_NONE: refused) */\n"
        "    const uint8_t *frame;\n"
        "    size_t len;\n"
        + (
            "    const uint8_t *request; /* a reply's: the frame of the request it answers (NULL: none) */\n"
            "    size_t request_len;\n"
            if asks
            else ""
        )
        + f"}} {p}_vector_t;\n\n"
        + "".join(a + "\n\n" for a in arrays)
        + f"#define {P}_VECTOR_COUNT {len(good)}u\n"
        f"static const {p}_vector_t {p}_vectors[] = {{\n" + "".join(r + "\n" for r in rows) + end + "\n};\n\n"
        f"#define {P}_REFUSED_COUNT {len(refused)}u\n"
        f"static const {p}_vector_t {p}_refused[] = {{\n"
        + "".join(r + "\n" for r in refused_rows)
        + end
        + "\n};\n\n"
        + f"#endif /* {P}_VECTORS_H */\n"
    )


def inner(protocol: Protocol) -> list[Direction]:
    """The directions where a frame may hold a shorter frame that the parser rightly takes first: beside other
    layouts, one of content alone (no header, no command: RPLIDAR's measurements) reads a frame from any bytes, so
    bytes inside an example (a response descriptor's `5A 03 00 00 00`) can be one, as the Python parser reads them."""
    return [
        d
        for d, layouts in protocol.framing.alternatives.items()
        if len(layouts) > 1
        and not protocol.framing.by_request(d)  # (the parser reads the layout of the reply awaited alone)
        and any(not layout.header and not layout.has_command for layout in layouts)
    ]


def first_frame(ctx: Ctx) -> str:
    """Where a frame may hold a shorter one (`inner`): the function giving the frame the parser must take first from
    a vector's bytes, by the decoder alone (runtime/stream.py's rule: the valid frame that ends first, of those the
    one that starts first; the vector itself where no part of it decodes)."""
    p, P = ctx.p, ctx.P
    if not inner(ctx.protocol):
        return ""
    return (
        f"#if {P}_ENABLE_PARSER\n"
        "/* The frame the parser fed v's bytes must take first, by the decoder alone: the valid frame that ends\n"
        " * first, of those the one that starts first (a layout of content alone reads a frame from bytes inside\n"
        " * another). */\n"
        f"static void {p}__first_frame(const {p}_vector_t *v, size_t *from, size_t *to)\n"
        "{\n"
        "    size_t end, start;\n"
        f"    {p}_msg_t msg;\n"
        "    for (end = 1u; end < v->len; end++) {\n"
        "        for (start = 0u; start < end; start++) {\n"
        f"            if ({p}_decode(v->frame + start, end - start, v->direction, &msg) == {P}_OK) {{\n"
        "                *from = start;\n"
        "                *to = end;\n"
        "                return;\n"
        "            }\n"
        "        }\n"
        "    }\n"
        "    *from = 0u;\n"
        "    *to = v->len;\n"
        "}\n"
        "#endif\n\n"
    )


def check_vectors(ctx: Ctx) -> str:
    protocol, p, P = ctx.protocol, ctx.p, ctx.P
    shorter = " || ".join(f"v->direction == {P}_{d.name}" for d in inner(protocol))
    if shorter:  # the frame the parser takes first: the vector, or a shorter frame inside it that ends first
        shorter = (
            f"            if ({shorter}) {{ /* a frame inside it that ends first is taken first (as in Python) */\n"
            f"                {p}__first_frame(v, &from, &to);\n"
            "            }\n"
        )
    decode = f"        int result = {p}_decode_expect(v->frame, v->len, v->direction, v->kind, &msg);\n"
    encode = f"            result = {p}_encode(&msg, buf, sizeof buf, &len);\n"
    expect = ""
    asked = ""
    if asking.asks(protocol):  # a reply read with its request: the request decoded from its frame, then given
        asked = (
            f"        {p}_msg_t req;\n"
            "        int asked = 0;\n"
            f"#if {P}_ENABLE_DECODE\n"
            "        if (v->request != NULL) {\n"
            f"            if (!{P}_DECODES_REQUESTS) {{\n"
            "                continue; /* a build that decodes no request cannot make it from its frame */\n"
            "            }\n"
            f"            asked = {p}_decode(v->request, v->request_len, {P}_REQUEST, &req) == {P}_OK;\n"
            "            if (!asked) {\n"
            f'                {p}__fail(&failed, v->name, "its request does not decode", {P}_OK);\n'
            "                continue;\n"
            "            }\n"
            "        }\n"
            "#endif\n"
            "        (void)req;\n"
            "        (void)asked;\n"
        )
        decode = (
            f"        int result = asked ? {p}_decode_reply(v->frame, v->len, &req, &msg)\n"
            f"                           : {p}_decode_expect(v->frame, v->len, v->direction, v->kind, &msg);\n"
        )
        encode = (
            f"            result = asked ? {p}_encode_reply(&msg, &req, buf, sizeof buf, &len)\n"
            f"                           : {p}_encode(&msg, buf, sizeof buf, &len);\n"
        )
        expect = f"            if (asked)\n                {p}_parser_expect_reply(&parser, &req);\n"
    return (
        banner(protocol)
        + f"/* Checks the generated {comment(protocol.title)} C against the spec's golden vectors: build it with\n"
        f" *     cc -std=c99 -I.. check_vectors.c ../{p}.c -o check_vectors && ./check_vectors\n"
        " * It prints one line per failure and a summary, and exits 1 when anything failed. */\n\n"
        "#include <stdio.h>\n#include <string.h>\n\n"
        '#include "vectors.h"\n\n'
        f"static void {p}__fail(unsigned *failed, const char *name, const char *what, int result)\n"
        "{\n"
        f'    printf("FAIL %s: %s (%s)\\n", name, what, {p}_result_name(result));\n'
        "    (*failed)++;\n"
        "}\n\n" + first_frame(ctx) + "int main(void)\n"
        "{\n"
        "    unsigned failed = 0;\n"
        f"    const {p}_vector_t *v;\n"
        f"    for (v = {p}_vectors; v->frame != NULL; v++) {{\n"
        f"        {p}_msg_t msg;\n"
        "        /* what the build keeps of this direction (its role: the other side's is refused) */\n"
        f"        const int decodes = v->direction == {P}_REQUEST ? {P}_DECODES_REQUESTS : {P}_DECODES_RESPONSES;\n"
        f"        const int encodes = v->direction == {P}_REQUEST ? {P}_ENCODES_REQUESTS : {P}_ENCODES_RESPONSES;\n"
        + asked
        + f"#if {P}_ENABLE_DECODE\n"
        + decode
        + f"        if (!decodes && result != {P}_E_ARG) {{\n"
        f'            {p}__fail(&failed, v->name, "the other side\'s frame is not refused", result);\n'
        "            continue;\n"
        "        }\n"
        f"        if (decodes && (result != {P}_OK || msg.kind != v->kind)) {{\n"
        f'            {p}__fail(&failed, v->name, "decode", result);\n'
        "            continue;\n"
        "        }\n"
        f"#if {P}_ENABLE_ENCODE\n"
        "        if (decodes && encodes) {\n"
        f"            uint8_t buf[{P}_MAX_FRAME];\n"
        "            size_t len = 0;\n"
        + encode
        + f"            if (result != {P}_OK || len != v->len || memcmp(buf, v->frame, len) != 0)\n"
        f'                {p}__fail(&failed, v->name, "encode gives other bytes", result);\n'
        "        }\n"
        "#endif\n"
        "#endif\n"
        f"#if {P}_ENABLE_PARSER\n"
        "        if (decodes) {\n"
        f"            {p}_parser_t parser;\n"
        "            size_t at = 0u, from = 0u, to = v->len, found = 0u;\n"
        "            const uint8_t *frame;\n"
        "            bool got = false;\n"
        + shorter
        + f"            {p}_parser_init(&parser, v->direction);\n"
        + expect
        + "            while (at < v->len && !got)  /* one byte at a time, as a UART interrupt hands them over */\n"
        f"                at += {p}_parser_feed(&parser, v->frame + at, 1, &msg, &got);\n"
        f"            frame = {p}_parser_frame(&parser, &found);\n"
        "            if (!got || at != to || found != to - from || memcmp(frame, v->frame + from, found) != 0)\n"
        f'                {p}__fail(&failed, v->name, "the parser does not find the frame", {P}_OK);\n'
        "        }\n"
        "#endif\n"
        "        (void)msg;\n"
        "        (void)decodes;\n"
        "        (void)encodes;\n"
        "    }\n"
        f"#if {P}_ENABLE_DECODE\n"
        f"    for (v = {p}_refused; v->frame != NULL; v++) {{\n"
        f"        {p}_msg_t msg;\n"
        f"        if ({p}_decode(v->frame, v->len, v->direction, &msg) == {P}_OK && (v->direction == {P}_REQUEST ?\n"
        f"                {P}_DECODES_REQUESTS : {P}_DECODES_RESPONSES))\n"
        f'            {p}__fail(&failed, v->name, "a frame the documents print wrong is accepted", {P}_OK);\n'
        "    }\n"
        "#endif\n"
        f'    printf("{p}: %u vectors, %u refused frames, %u failed\\n", (unsigned){P}_VECTOR_COUNT,\n'
        f"           (unsigned){P}_REFUSED_COUNT, failed);\n"
        f"    return failed == 0 ? 0 : 1;\n"
        "}\n"
    )
