/* bench/c/feetech_checked.c (the hand-written FEETECH host parser with the spec's checks, the flash baseline) fed a
 * stream in hex on one line: "<id> <error> <data hex>" per reply, then "end <frames> <garbage and held> <errors>"
 * (the bytes held at the end and the garbage summed: the Python parser keeps a byte that could begin a header). */
#include <stdio.h>
#include <stdint.h>
#include <stddef.h>

typedef struct {
    uint8_t id, error, data[253];
    size_t data_len;
} hc_reply_t;
typedef struct {
    size_t n;
    uint32_t frames, garbage, errors;
    uint8_t buf[259];
} hc_parser_t;
void hc_init(hc_parser_t *p);
int hc_push(hc_parser_t *p, uint8_t b, hc_reply_t *out);

int main(void)
{
    static hc_parser_t p;
    static hc_reply_t r;
    unsigned x;
    size_t i;
    hc_init(&p);
    while (scanf("%2x", &x) == 1) {
        if (hc_push(&p, (uint8_t)x, &r)) {
            printf("%u %u ", r.id, r.error);
            for (i = 0u; i < r.data_len; i++) {
                printf("%02x", r.data[i]);
            }
            printf("\n");
        }
    }
    printf("end %lu %lu %lu\n", (unsigned long)p.frames, (unsigned long)(p.garbage + p.n),
           (unsigned long)p.errors);
    return 0;
}
