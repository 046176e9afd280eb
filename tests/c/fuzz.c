/* A fuzz harness for one protocol's generated C: a libFuzzer entry point (clang -fsanitize=fuzzer,address,undefined
 * -DFUZZ_LIBFUZZER) or, built without it, a seeded random main() for gcc-only CI (tests/test_c_backend.py runs it).
 *
 * Built with -DPROTO=<protocol> -DPROTO_UPPER=<PROTOCOL> -include <protocol>_json.h. Properties, for any input:
 *   - no undefined behaviour, no read or write out of bounds (the sanitizers);
 *   - a frame that decodes encodes again, and that frame decodes to the same message (same JSON);
 *   - feeding the bytes in pieces gives the same messages and counters as feeding them one call at a time;
 *   - every decoded count fits its array (the JSON writer walks them: ASan would see an overrun).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CAT2(a, b) a##b
#define CAT(a, b) CAT2(a, b)
#define P(name) CAT(PROTO, CAT(_, name))
#define PU(name) CAT(PROTO_UPPER, CAT(_, name))

static P(msg_t) msg, again;
static P(parser_t) whole, pieces;
static uint8_t out[PU(MAX_FRAME) + 64];
static char json1[1 << 16], json2[1 << 16];

static void fail(const char *what)
{
    fprintf(stderr, "fuzz: %s\n", what);
    abort();
}

static void check_frame(const uint8_t *data, size_t size, P(direction_t) dir)
{
    size_t len = 0u;
    if (P(decode)(data, size, dir, &msg) != 0) {
        return;
    }
    (void)P(to_json)(&msg, json1, sizeof(json1));
    if (P(encode)(&msg, out, sizeof(out), &len) != 0) {
        return; /* a frame the codec reads but would not write (a value outside its range): allowed */
    }
    if (P(decode)(out, len, dir, &again) != 0) {
        fail("an encoded frame does not decode");
    }
    (void)P(to_json)(&again, json2, sizeof(json2));
    if (strcmp(json1, json2) != 0) {
        fail("a frame encoded again decodes to another message");
    }
}

static void check_stream(const uint8_t *data, size_t size, P(direction_t) dir, uint32_t seed)
{
    size_t at = 0u, got_whole = 0u, got_pieces = 0u;
    bool got;
    P(parser_init)(&whole, dir);
    P(parser_init)(&pieces, dir);
    while (at < size) { /* all the bytes in one call (again after each message) */
        at += P(parser_feed)(&whole, data + at, size - at, &msg, &got);
        got_whole += got ? 1u : 0u;
    }
    at = 0u;
    while (at < size) { /* in pieces of 0..7 bytes */
        size_t take;
        seed = seed * 1103515245u + 12345u;
        take = (size_t)((seed >> 16) % 8u);
        if (take > size - at) {
            take = size - at;
        }
        while (take > 0u) {
            size_t used = P(parser_feed)(&pieces, data + at, take, &msg, &got);
            at += used;
            take -= used;
            got_pieces += got ? 1u : 0u;
        }
    }
    if (got_whole != got_pieces || whole.frames != pieces.frames || whole.garbage != pieces.garbage ||
        whole.errors != pieces.errors || whole.n != pieces.n) {
        fail("pieces and one call disagree");
    }
    P(parser_init)(&pieces, dir); /* byte by byte through parser_push: the same messages and counters */
    got_pieces = 0u;
    for (at = 0u; at < size; at++) {
        P(event_t) ev = P(parser_push)(&pieces, data[at], &msg);
        got_pieces += ev == PU(EVENT_MESSAGE) ? 1u : 0u;
        if (ev == PU(EVENT_FRAME_UNKNOWN)) {
            size_t len;
            const uint8_t *f = P(parser_frame)(&pieces, &len);
            if (f == NULL || len == 0u || P(decode)(f, len, dir, &msg) != PU(E_UNKNOWN)) {
                fail("a frame reported as of an unknown command is not one");
            }
        }
    }
    if (got_whole != got_pieces || whole.frames != pieces.frames || whole.garbage != pieces.garbage ||
        whole.errors != pieces.errors || whole.n != pieces.n || whole.unknown != pieces.unknown) {
        fail("parser_push and parser_feed disagree");
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    check_frame(data, size, PU(REQUEST));
    check_frame(data, size, PU(RESPONSE));
    check_stream(data, size, PU(REQUEST), (uint32_t)size);
    check_stream(data, size, PU(RESPONSE), (uint32_t)size + 1u);
    return 0;
}

#ifndef FUZZ_LIBFUZZER
/* Seeded random inputs: the frames of zeroed messages of every kind, mutated and strung together with noise. */
static uint32_t state = 1u;

static uint32_t next(void)
{
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    return state;
}

static uint8_t seeds[PU(KIND_COUNT)][512];
static size_t seed_len[PU(KIND_COUNT)];
static uint8_t input[4096];

int main(int argc, char **argv)
{
    long runs = argc > 1 ? strtol(argv[1], NULL, 10) : 10000L, i;
    int k, nseeds = 0;
    state = argc > 2 ? (uint32_t)strtoul(argv[2], NULL, 10) | 1u : 1u;
    for (k = 1; k < (int)PU(KIND_COUNT); k++) {
        size_t len = 0u;
        memset(&msg, 0, sizeof(msg));
        msg.kind = (P(kind_t))k;
        if (P(encode)(&msg, out, sizeof(out), &len) == 0 && len <= sizeof(seeds[0])) {
            memcpy(seeds[nseeds], out, len);
            seed_len[nseeds++] = len;
        }
    }
    for (i = 0; i < runs; i++) {
        size_t n = 0u, parts = 1u + next() % 6u, j;
        for (j = 0u; j < parts; j++) {
            uint32_t what = next() % 4u;
            if (what < 2u && nseeds > 0) { /* a valid frame */
                int s = (int)(next() % (uint32_t)nseeds);
                if (n + seed_len[s] > sizeof(input)) {
                    break;
                }
                memcpy(input + n, seeds[s], seed_len[s]);
                if (what == 1u && seed_len[s] > 0u) { /* with a byte changed */
                    input[n + next() % seed_len[s]] ^= (uint8_t)(1u + next() % 255u);
                }
                n += seed_len[s];
            } else { /* noise */
                size_t noise = next() % 8u, m;
                for (m = 0u; m < noise && n < sizeof(input); m++) {
                    input[n++] = (uint8_t)next();
                }
            }
        }
        (void)LLVMFuzzerTestOneInput(input, n);
        for (j = 0u; j < parts && nseeds > 0; j++) { /* each seed alone, mutated, as a frame */
            int s = (int)(next() % (uint32_t)nseeds);
            memcpy(input, seeds[s], seed_len[s]);
            if (seed_len[s] > 0u) {
                input[next() % seed_len[s]] ^= (uint8_t)(1u << (next() % 8u));
            }
            check_frame(input, seed_len[s], PU(REQUEST));
            check_frame(input, seed_len[s], PU(RESPONSE));
        }
    }
    printf("fuzz: %ld runs, %d seed frames, no failure\n", runs, nseeds);
    return 0;
}
#endif
