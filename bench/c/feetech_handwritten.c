/* A hand-written FEETECH SMS parser, the way firmware usually has one (a byte state machine, no rescan after a bad
 * checksum), for bench/c_target.py to compare the generated C with: flash on Cortex-M0+ and throughput on this host.
 * It frames and checks packets (FF FF id len instr/error params checksum) and hands back id, instruction and params. */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

typedef struct {
    uint8_t id;
    uint8_t instruction;
    uint8_t length;
    uint8_t params[253];
} hw_packet_t;

typedef struct {
    uint8_t state;
    uint8_t sum;
    uint8_t got;
    hw_packet_t packet;
} hw_parser_t;

void hw_init(hw_parser_t *p);
int hw_push(hw_parser_t *p, uint8_t b, hw_packet_t *out);

void hw_init(hw_parser_t *p)
{
    memset(p, 0, sizeof(*p));
}

/* 1 when b completes a packet whose checksum holds (copied to out). */
int hw_push(hw_parser_t *p, uint8_t b, hw_packet_t *out)
{
    switch (p->state) {
    case 0:
        p->state = b == 0xFFu ? 1u : 0u;
        return 0;
    case 1:
        p->state = b == 0xFFu ? 2u : 0u;
        return 0;
    case 2:
        if (b == 0xFFu) {
            return 0; /* a third FF: still a header */
        }
        if (b > 0xFEu) {
            p->state = 0u;
            return 0;
        }
        p->packet.id = b;
        p->sum = b;
        p->state = 3u;
        return 0;
    case 3:
        if (b < 2u) {
            p->state = 0u;
            return 0;
        }
        p->packet.length = (uint8_t)(b - 2u);
        p->sum = (uint8_t)(p->sum + b);
        p->state = 4u;
        return 0;
    case 4:
        p->packet.instruction = b;
        p->sum = (uint8_t)(p->sum + b);
        p->got = 0u;
        p->state = p->packet.length ? 5u : 6u;
        return 0;
    case 5:
        p->packet.params[p->got++] = b;
        p->sum = (uint8_t)(p->sum + b);
        if (p->got == p->packet.length) {
            p->state = 6u;
        }
        return 0;
    default:
        p->state = 0u;
        if ((uint8_t)~p->sum != b) {
            return 0;
        }
        memcpy(out, &p->packet, sizeof(*out));
        return 1;
    }
}
