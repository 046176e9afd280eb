/* What a firmware links in: main() reaching the parts a build enables (bench/c_target.py measures its flash). */
#include <stddef.h>
#include <stdint.h>

#ifdef HANDWRITTEN
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
#elif defined(CHECKED)
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
static hc_parser_t parser;
static hc_reply_t reply;
#elif defined(PROTO)
#define CAT2(a, b) a##b
#define CAT(a, b) CAT2(a, b)
#define P(name) CAT(PROTO, CAT(_, name))
#define PU(name) CAT(PROTO_UPPER, CAT(_, name))
static P(parser_t) parser;
static P(msg_t) msg;
static uint8_t frame[64];
#endif

volatile uint8_t sink;

int main(void)
{
#ifdef HANDWRITTEN
    hw_init(&parser);
    sink = (uint8_t)hw_push(&parser, sink, &packet);
#elif defined(CHECKED)
    hc_init(&parser);
    sink = (uint8_t)hc_push(&parser, sink, &reply);
#elif defined(PROTO)
#if PU(ENABLE_PARSER)
    {
        bool got;
        P(parser_init)(&parser, PU(DECODES_RESPONSES) ? PU(RESPONSE) : PU(REQUEST)); /* the side the build reads */
        sink = (uint8_t)P(parser_feed)(&parser, frame, sink, &msg, &got);
    }
#endif
#if PU(ENABLE_ENCODE)
    {
        size_t len;
        sink = (uint8_t)P(encode)(&msg, frame, sizeof(frame), &len);
    }
#endif
#endif
    return sink;
}
