/* An Arduino Mega (ATmega2560 at 16 MHz) on a FEETECH servo bus, with the generated C and avr-libc alone (no Arduino
 * core): every 20 ms it reads servo 1's present position and sends it to servo 2 as its goal, so servo 2 follows
 * servo 1 turned by hand. USART1 (pins 18 TX, 19 RX) runs the half-duplex bus at 1 Mbaud through the usual
 * tri-state adapter; its receive interrupt puts bytes in a ring that the main loop feeds to the reply parser.
 *
 *   avr-gcc -mmcu=atmega2560 -DF_CPU=16000000UL -Os -std=c99 \
 *      -DFEETECH_SMS_ROLE=FEETECH_SMS_ROLE_HOST -DFEETECH_SMS_PARSER_SMALL=1 -DFEETECH_SMS_PARSER_WHOLE_FRAMES=0 \
 *      -DFEETECH_SMS_SYNC_WRITE_REQUEST_SERVOS_MAX=4 -DFEETECH_SMS_SYNC_WRITE_REQUEST_SERVOS_DATA_MAX=8 \
 *      -DFEETECH_SMS_WRITE_REQUEST_DATA_MAX=8 -DFEETECH_SMS_REG_WRITE_REQUEST_DATA_MAX=8 \
 *      -DFEETECH_SMS_SYNC_READ_REQUEST_IDS_MAX=4 -DFEETECH_SMS_REPLY_RESPONSE_DATA_MAX=8 \
 *      -I generated/c/feetech_sms examples/c/avr_servo_follow.c generated/c/feetech_sms/feetech_sms.c -o follow.elf
 *   avr-objcopy -O ihex follow.elf follow.hex    # then avrdude -c wiring -p m2560 -U flash:w:follow.hex
 *
 * The -D lines size the message union for 8 KiB of RAM: by default a SYNC WRITE holds 32 servos of 253 bytes.
 * The host role keeps the request encoders and the reply parser; the small parser keeps no per-byte verdicts. */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/delay.h>

#include "feetech_sms.h"

#define SERVO_LEADER 1u
#define SERVO_FOLLOWER 2u
#define PRESENT_POSITION 56u /* the control table's addresses (the servo's memory map, not the protocol's) */
#define GOAL_POSITION 42u

#define RING_SIZE 64u /* a power of two */
static volatile uint8_t ring[RING_SIZE];
static volatile uint8_t ring_head; /* written by the interrupt */
static volatile uint8_t ring_tail; /* written by the main loop */

ISR(USART1_RX_vect)
{
    uint8_t byte = UDR1;
    uint8_t next = (uint8_t)((ring_head + 1u) & (RING_SIZE - 1u));
    if (next != ring_tail) { /* a full ring drops the byte: the parser resynchronises on the next header */
        ring[ring_head] = byte;
        ring_head = next;
    }
}

static void bus_init(void)
{
    UCSR1A = _BV(U2X1);
    UBRR1 = 1u; /* 16 MHz / (8 * (1 + 1)) = 1 Mbaud */
    UCSR1C = _BV(UCSZ11) | _BV(UCSZ10); /* 8N1 */
    UCSR1B = _BV(RXEN1) | _BV(RXCIE1) | _BV(TXEN1);
}

/* Encode and send a request, the receiver off meanwhile: on a half-duplex bus it would hear the request itself. */
static int bus_send(const feetech_sms_msg_t *request)
{
    uint8_t frame[FEETECH_SMS_MAX_FRAME];
    size_t len, i;
    int r = feetech_sms_encode(request, frame, sizeof(frame), &len);
    if (r != FEETECH_SMS_OK) {
        return r;
    }
    UCSR1B = (uint8_t)(UCSR1B & ~_BV(RXEN1));
    UCSR1A = (uint8_t)(UCSR1A | _BV(TXC1)); /* writing 1 clears the transmit-complete flag */
    for (i = 0u; i < len; i++) {
        loop_until_bit_is_set(UCSR1A, UDRE1);
        UDR1 = frame[i];
    }
    loop_until_bit_is_set(UCSR1A, TXC1);
    UCSR1B = (uint8_t)(UCSR1B | _BV(RXEN1));
    return FEETECH_SMS_OK;
}

/* Feed the ring's bytes to the parser until a reply comes (1) or about 5 ms pass (0). */
static int bus_reply(feetech_sms_parser_t *parser, feetech_sms_msg_t *reply)
{
    uint16_t waited;
    for (waited = 0u; waited < 500u; waited++) {
        while (ring_tail != ring_head) {
            uint8_t byte = ring[ring_tail];
            bool got;
            ring_tail = (uint8_t)((ring_tail + 1u) & (RING_SIZE - 1u));
            (void)feetech_sms_parser_feed(parser, &byte, 1u, reply, &got);
            if (got) {
                return 1;
            }
        }
        _delay_us(10);
    }
    return 0;
}

int main(void)
{
    static feetech_sms_parser_t parser; /* static: the message union and the parser stay off the stack */
    static feetech_sms_msg_t request, reply;
    bus_init();
    sei();
    for (;;) {
        request.kind = FEETECH_SMS_READ_REQUEST;
        request.u.read_request.id = SERVO_LEADER;
        request.u.read_request.address = PRESENT_POSITION;
        request.u.read_request.length = 2u;
        feetech_sms_parser_init(&parser, FEETECH_SMS_RESPONSE);
        if (bus_send(&request) == FEETECH_SMS_OK && bus_reply(&parser, &reply) &&
            reply.kind == FEETECH_SMS_REPLY_RESPONSE && reply.u.reply_response.id == SERVO_LEADER &&
            reply.u.reply_response.data_len == 2u) {
            /* the position as the leader sent it (two bytes, the servo's byte order), written back as they are */
            request.kind = FEETECH_SMS_WRITE_REQUEST;
            request.u.write_request.id = SERVO_FOLLOWER;
            request.u.write_request.address = GOAL_POSITION;
            request.u.write_request.data[0] = reply.u.reply_response.data[0];
            request.u.write_request.data[1] = reply.u.reply_response.data[1];
            request.u.write_request.data_len = 2u;
            (void)bus_send(&request);
        }
        _delay_ms(20);
    }
}
