/* A hand-written FEETECH SMS host parser with the checks the spec asks of a reply, for bench/c_target.py to compare
 * the generated C with like for like (feetech_handwritten.c is the usual firmware state machine, which checks less):
 *   - the header FF FF; the id in 0..253 or 254 (broadcast); the length byte at least 2 (the error byte and the sum);
 *   - the sum; the status packet's id, error and data handed back, the data's length kept;
 *   - no byte lost on a failed candidate: the bytes held are kept and scanning resumes one byte after its header
 *     (the shift-the-buffer resynchronisation, rust-mavlink's backtracking), counted in frames, garbage and errors.
 * What it does not do that the generated parser does: find a frame that starts inside a candidate still waiting for
 * its bytes before that candidate is judged (the Python parser's "the frame that completes first"), the whole-frame
 * path, the raw-frame pointer. */
#include <stddef.h>
#include <stdint.h>

#define HC_MAX_FRAME 259u /* FF FF id len(255) ... */

typedef struct {
    uint8_t id;
    uint8_t error;
    uint8_t data[253];
    size_t data_len;
} hc_reply_t;

typedef struct {
    size_t n;
    uint32_t frames, garbage, errors;
    uint8_t buf[HC_MAX_FRAME];
} hc_parser_t;

void hc_init(hc_parser_t *p);
int hc_push(hc_parser_t *p, uint8_t b, hc_reply_t *out);

void hc_init(hc_parser_t *p)
{
    p->n = 0u;
    p->frames = p->garbage = p->errors = 0u;
}

static void hc_drop(hc_parser_t *p, size_t k)
{
    size_t i;
    for (i = k; i < p->n; i++) {
        p->buf[i - k] = p->buf[i];
    }
    p->n -= k;
}

/* 1 when b completes a valid reply (decoded into out). */
int hc_push(hc_parser_t *p, uint8_t b, hc_reply_t *out)
{
    if (p->n == HC_MAX_FRAME) {
        hc_drop(p, 1u);
        p->garbage++;
    }
    p->buf[p->n++] = b;
    for (;;) {
        size_t i = 0u, size, k;
        uint8_t sum = 0u;
        while (i < p->n && !(p->buf[i] == 0xFFu && (i + 1u == p->n || p->buf[i + 1u] == 0xFFu))) {
            i++;
        }
        hc_drop(p, i);
        p->garbage += (uint32_t)i;
        if (p->n < 4u) {
            return 0;
        }
        if (p->buf[2] > 0xFEu || p->buf[3] < 2u) { /* no frame here: on from the next byte */
            hc_drop(p, 1u);
            p->garbage++;
            continue;
        }
        size = (size_t)p->buf[3] + 4u;
        if (p->n < size) {
            return 0;
        }
        for (k = 2u; k + 1u < size; k++) {
            sum = (uint8_t)(sum + p->buf[k]);
        }
        sum = (uint8_t)(255u - sum);
        if (sum != p->buf[size - 1u]) {
            p->errors++;
            hc_drop(p, 1u);
            p->garbage++;
            continue;
        }
        out->id = p->buf[2];
        out->error = p->buf[4];
        out->data_len = size - 6u;
        for (k = 0u; k < out->data_len; k++) {
            out->data[k] = p->buf[5u + k];
        }
        hc_drop(p, size);
        p->frames++;
        return 1;
    }
}
