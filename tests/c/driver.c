/* A test driver for one protocol's generated C: hex in, JSON out, one command a line (tests/test_c_backend.py).
 *
 * Built with -DPROTO=<protocol> -include <protocol>_json.h. Commands, each answered by one line (stream: several):
 *   dec DIR HEX [KIND]       decode a frame: "ok <json>" or "err <result>"
 *   rt DIR HEX [KIND]        decode, then encode the message again: "ok <hex>" or "err <result>"
 *   stream DIR SIZES HEX [KIND|-] [GAPS]
 *                            feed the bytes in pieces of SIZES (comma-separated, repeated), after parser_expect(KIND)
 *                            and with parser_gap() at each offset of GAPS (comma-separated, ascending): "msg <json>"
 *                            and "frame <hex>" (parser_frame) per message, then "end <frames> <garbage> <errors> <held>"
 *   enc1 DIR HEX CAP         decode, then encode into CAP bytes with canary bytes after them: "ok <hex>" / "err <r>"
 *   raw DIR HEX [KIND]       decode: "ok <the msg_t's bytes in hex>" or "err <result>" (for encraw in another build)
 *   encraw DIR HEX           a msg_t from its bytes in hex (raw's, same compiler), encoded: "ok <hex>" / "err <r>"
 *   args DIR                 the API given what it refuses (NULL pointers, no direction, no kind, no result), each
 *                            answer: "args <result or text> ..." (one line)
 *   kinds DIR                every kind encoded from a zeroed message: "kinds <kind>=<result> ..." (one line)
 *   each DIR                 with -DDRIVER_EACH="file": the file's each_encoder() (every message's own encoder called)
 *   req DIR HEX|-            with -DDRIVER_REPLIES (a protocol whose replies are read with their request): the request
 *                            frame HEX decoded, then given to every reply's decode, encode and parser_expect
 *                            (p_decode_reply, p_encode_reply, p_parser_expect_reply) until "req DIR -": "ok"/"err <r>"
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CAT2(a, b) a##b
#define CAT(a, b) CAT2(a, b)
#define P(name) CAT(PROTO, CAT(_, name))

static P(msg_t) msg;
#ifdef DRIVER_REPLIES
static P(msg_t) request;
static int asked = 0;
#define DECODE(f, n, d, kind, m) \
    (asked && (d) == CAT(PROTO_UPPER, _RESPONSE) ? P(decode_reply)(f, n, &request, m) : P(decode_expect)(f, n, d, kind, m))
#define ENCODE(m, d, b, cap, len) \
    (asked && (d) == CAT(PROTO_UPPER, _RESPONSE) ? P(encode_reply)(m, &request, b, cap, len) : P(encode)(m, b, cap, len))
#else
#define DECODE(f, n, d, kind, m) P(decode_expect)(f, n, d, kind, m)
#define ENCODE(m, d, b, cap, len) P(encode)(m, b, cap, len)
#endif
static P(parser_t) parser;
static uint8_t frame[1 << 17];
static uint8_t out[1 << 17];
static char json[1 << 20];
static char line[1 << 19];

static size_t unhex(const char *s, uint8_t *b, size_t cap)
{
    size_t n = 0u;
    while (s[0] != '\0' && s[1] != '\0' && n < cap) {
        unsigned v;
        if (sscanf(s, "%2x", &v) != 1) {
            break;
        }
        b[n++] = (uint8_t)v;
        s += 2;
    }
    return n;
}

static void puthex(const uint8_t *b, size_t n)
{
    size_t i;
    for (i = 0u; i < n; i++) {
        printf("%02x", b[i]);
    }
}

#ifdef DRIVER_EACH
#include DRIVER_EACH
#endif

static P(kind_t) kind_of(const char *name)
{
    int k;
    if (name == NULL) {
        return CAT(PROTO_UPPER, _KIND_NONE);
    }
    for (k = 1; k < (int)CAT(PROTO_UPPER, _KIND_COUNT); k++) {
        if (strcmp(P(kind_name)((P(kind_t))k), name) == 0) {
            return (P(kind_t))k;
        }
    }
    return CAT(PROTO_UPPER, _KIND_NONE);
}

int main(void)
{
    while (fgets(line, sizeof(line), stdin) != NULL) {
        char *cmd = strtok(line, " \n");
        char *dir_text = strtok(NULL, " \n");
        P(direction_t) dir;
        if (cmd == NULL || dir_text == NULL) {
            printf("bad\n");
            fflush(stdout);
            continue;
        }
        dir = strcmp(dir_text, "request") == 0 ? CAT(PROTO_UPPER, _REQUEST) : CAT(PROTO_UPPER, _RESPONSE);
        if (strcmp(cmd, "raw") == 0 || strcmp(cmd, "encraw") == 0) {
            char *hex = strtok(NULL, " \n");
            char *extra = strtok(NULL, " \n");
            size_t n = unhex(hex ? hex : "", frame, sizeof(frame)), len = 0u;
            int r;
            if (strcmp(cmd, "raw") == 0) {
                r = P(decode_expect)(frame, n, dir, kind_of(extra), &msg);
                if (r == 0) {
                    memcpy(out, &msg, sizeof(msg));
                    len = sizeof(msg);
                }
            } else {
                memcpy(&msg, frame, n < sizeof(msg) ? n : sizeof(msg));
                r = P(encode)(&msg, out, sizeof(out), &len);
            }
            if (r != 0) {
                printf("err %s\n", P(result_name)(r));
            } else {
                printf("ok ");
                puthex(out, len);
                printf("\n");
            }
        } else if (strcmp(cmd, "dec") == 0 || strcmp(cmd, "rt") == 0 || strcmp(cmd, "enc1") == 0) {
            char *hex = strtok(NULL, " \n");
            char *extra = strtok(NULL, " \n");
            size_t n = unhex(hex ? hex : "", frame, sizeof(frame));
            int r;
            if (strcmp(cmd, "enc1") == 0) {
                r = DECODE(frame, n, dir, CAT(PROTO_UPPER, _KIND_NONE), &msg);
            } else {
                r = DECODE(frame, n, dir, kind_of(extra), &msg);
            }
            if (r != 0) {
                printf("err %s\n", P(result_name)(r));
            } else if (strcmp(cmd, "dec") == 0) {
                size_t need = P(to_json)(&msg, json, sizeof(json));
                printf("ok %s\n", need < sizeof(json) ? json : "{}");
            } else {
                size_t len = 12345u, cap = sizeof(out) - 64u, i;
                if (strcmp(cmd, "enc1") == 0) {
                    cap = (size_t)strtoul(extra ? extra : "0", NULL, 10);
                }
                memset(out, 0xA5, cap + 64u);
                r = ENCODE(&msg, dir, out, cap, &len);
                for (i = cap; i < cap + 64u; i++) {
                    if (out[i] != 0xA5) {
                        printf("overrun\n");
                        return 1;
                    }
                }
                if (r != 0) {
                    printf("err %s %lu\n", P(result_name)(r), (unsigned long)len);
                } else {
                    printf("ok ");
                    puthex(out, len);
                    printf("\n");
                }
            }
        } else if (strcmp(cmd, "push") == 0) { /* byte by byte through parser_push: every event */
            char *hex = strtok(NULL, " \n");
            size_t n = unhex(hex ? hex : "", frame, sizeof(frame)), at;
            P(parser_init)(&parser, dir);
            for (at = 0u; at < n; at++) {
                P(event_t) ev = P(parser_push)(&parser, frame[at], &msg);
                size_t flen;
                const uint8_t *f = P(parser_frame)(&parser, &flen);
                if (ev == CAT(PROTO_UPPER, _EVENT_MESSAGE)) {
                    P(to_json)(&msg, json, sizeof(json));
                    printf("msg %s\nframe ", json);
                    puthex(f, flen);
                    printf("\n");
                } else if (ev == CAT(PROTO_UPPER, _EVENT_FRAME_UNKNOWN)) {
                    printf("unknown ");
                    puthex(f, flen);
                    printf("\n");
                }
            }
            printf("end %lu %lu %lu %lu %lu\n", (unsigned long)parser.frames, (unsigned long)parser.garbage,
                   (unsigned long)parser.errors, (unsigned long)parser.n, (unsigned long)parser.unknown);
        } else if (strcmp(cmd, "stream") == 0) {
            char *sizes = strtok(NULL, " \n");
            char *hex = strtok(NULL, " \n");
            char *expect = strtok(NULL, " \n");
            char *gaps = strtok(NULL, " \n");
            size_t n = unhex(hex ? hex : "", frame, sizeof(frame)), at = 0u;
            size_t piece[64], npieces = 0u, which = 0u, gap[64], ngaps = 0u, nextgap = 0u;
            char *s = sizes;
            while (gaps != NULL && *gaps != '\0' && ngaps < 64u) {
                gap[ngaps++] = (size_t)strtoul(gaps, &gaps, 10);
                if (*gaps == ',') {
                    gaps++;
                }
            }
            while (s != NULL && *s != '\0' && npieces < 64u) {
                piece[npieces++] = (size_t)strtoul(s, &s, 10);
                if (*s == ',') {
                    s++;
                }
            }
            if (npieces == 0u) {
                piece[npieces++] = 1u;
            }
            P(parser_init)(&parser, dir);
            if (expect != NULL && strcmp(expect, "-") != 0) {
                P(parser_expect)(&parser, kind_of(expect));
#ifdef DRIVER_REPLIES
                if (asked) {
                    P(parser_expect_reply)(&parser, &request);
                }
#endif
            }
            while (at <= n) {
                size_t take = piece[which++ % npieces];
                size_t used;
                bool got;
                while (nextgap < ngaps && gap[nextgap] <= at) {
                    P(parser_gap)(&parser);
                    nextgap++;
                }
                if (take > n - at) {
                    take = n - at;
                }
                if (nextgap < ngaps && take > gap[nextgap] - at) {
                    take = gap[nextgap] - at;
                }
                /* a piece may hold several messages: feed it until it is used up, then once more with nothing */
                for (;;) {
                    used = P(parser_feed)(&parser, frame + at, take, &msg, &got);
                    at += used;
                    take -= used;
                    if (got) {
                        size_t flen;
                        const uint8_t *f = P(parser_frame)(&parser, &flen);
                        P(to_json)(&msg, json, sizeof(json));
                        printf("msg %s\nframe ", json);
                        puthex(f, flen);
                        printf("\n");
                    }
                    if (!got && take == 0u) {
                        break;
                    }
                }
                if (at >= n) {
                    break;
                }
            }
            while (nextgap < ngaps) { /* gaps at the stream's end */
                P(parser_gap)(&parser);
                nextgap++;
            }
            printf("end %lu %lu %lu %lu\n", (unsigned long)parser.frames, (unsigned long)parser.garbage,
                   (unsigned long)parser.errors, (unsigned long)parser.n);
#ifdef DRIVER_REPLIES
        } else if (strcmp(cmd, "req") == 0) {
            char *hex = strtok(NULL, " \n");
            int r = 0;
            asked = 0;
            if (hex != NULL && strcmp(hex, "-") != 0) {
                size_t n = unhex(hex, frame, sizeof(frame));
                r = P(decode)(frame, n, CAT(PROTO_UPPER, _REQUEST), &request);
                asked = r == 0;
            }
            if (r != 0) {
                printf("err %s\n", P(result_name)(r));
            } else {
                printf("ok\n");
            }
#endif
        } else if (strcmp(cmd, "args") == 0) {
            size_t len = 1u;
            bool got = true;
            P(direction_t) none = (P(direction_t))7; /* no direction */
            memset(&msg, 0, sizeof(msg));
            frame[0] = 0u;
            printf("args %s", P(result_name)(P(decode)(NULL, 0u, dir, &msg)));
            printf(" %s", P(result_name)(P(decode)(frame, 1u, dir, NULL)));
            printf(" %s", P(result_name)(P(decode)(frame, 1u, none, &msg)));
            printf(" %s", P(result_name)(P(encode)(NULL, out, sizeof(out), &len)));
            printf(" %s", P(result_name)(P(encode)(&msg, NULL, sizeof(out), &len)));
            printf(" %s", P(result_name)(P(encode)(&msg, out, sizeof(out), &len)));
            printf(" %lu", (unsigned long)len);
            printf(" [%s]", P(kind_name)(CAT(PROTO_UPPER, _KIND_NONE)));
            printf(" [%s]", P(kind_name)(CAT(PROTO_UPPER, _KIND_COUNT)));
            printf(" [%s] [%s]", P(result_name)(-1), P(result_name)(1000));
            P(to_json)(NULL, json, sizeof(json));
            printf(" %s", json);
            P(to_json)(&msg, json, sizeof(json));
            printf(" %s", json);
            P(parser_init)(&parser, none);
            printf(" %lu", (unsigned long)P(parser_feed)(&parser, frame, 1u, &msg, &got));
            printf(" %d", (int)got);
            printf(" %d", (int)P(parser_push)(&parser, 0u, &msg));
            printf("\n");
        } else if (strcmp(cmd, "kinds") == 0) {
            int k;
            printf("kinds");
            for (k = 1; k < (int)CAT(PROTO_UPPER, _KIND_COUNT); k++) {
                size_t len = 0u;
                memset(&msg, 0, sizeof(msg));
                msg.kind = (P(kind_t))k;
                printf(" %s=%s", P(kind_name)(msg.kind), P(result_name)(P(encode)(&msg, out, sizeof(out), &len)));
            }
            printf("\n");
#ifdef DRIVER_EACH
        } else if (strcmp(cmd, "each") == 0) {
            each_encoder();
#endif
        } else {
            printf("bad\n");
        }
        fflush(stdout);
    }
    return 0;
}
