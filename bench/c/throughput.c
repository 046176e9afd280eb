/* Parse throughput on this host: a stream of frames (hex file) fed to the generated parser, or to the hand-written
 * FEETECH parser (-DHANDWRITTEN), ROUNDS times; prints MB/s and the messages found per round (bench/c_target.py). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifdef HANDWRITTEN
#include <stdint.h>
typedef struct {
    uint8_t id, instruction, length, params[253];
} hw_packet_t;
typedef struct {
    uint8_t state, sum, got;
    hw_packet_t packet;
} hw_parser_t;
void hw_init(hw_parser_t *p);
int hw_push(hw_parser_t *p, uint8_t b, hw_packet_t *out);
static hw_parser_t parser;
static hw_packet_t packet;
#else
#define CAT2(a, b) a##b
#define CAT(a, b) CAT2(a, b)
#define P(name) CAT(PROTO, CAT(_, name))
#define PU(name) CAT(PROTO_UPPER, CAT(_, name))
static P(parser_t) parser;
static P(msg_t) msg;
#endif

static unsigned char data[1 << 22];

int main(int argc, char **argv)
{
    FILE *f = fopen(argv[1], "r");
    int rounds = atoi(argv[2]), r, dir = argc > 3 && strcmp(argv[3], "response") == 0;
    size_t n = 0;
    unsigned v;
    long found = 0;
    struct timespec t0, t1;
    double seconds;
    while (f != NULL && n < sizeof(data) && fscanf(f, "%2x", &v) == 1) {
        data[n++] = (unsigned char)v;
    }
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (r = 0; r < rounds; r++) {
        size_t at = 0;
        found = 0;
#ifdef HANDWRITTEN
        (void)dir;
        hw_init(&parser);
        for (at = 0; at < n; at++) {
            found += hw_push(&parser, data[at], &packet);
        }
#else
        P(parser_init)(&parser, dir ? PU(RESPONSE) : PU(REQUEST));
        while (at < n) {
            bool got;
            at += P(parser_feed)(&parser, data + at, n - at, &msg, &got);
            found += got;
        }
#endif
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    seconds = (double)(t1.tv_sec - t0.tv_sec) + (double)(t1.tv_nsec - t0.tv_nsec) / 1e9;
    printf("%.3f %ld\n", (double)n * rounds / seconds / 1e6, found);
    return 0;
}
