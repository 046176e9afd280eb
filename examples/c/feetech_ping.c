/* A C host talking FEETECH SMS through a serial port with the generated C (generated/c/feetech_sms/): it pings a
 * servo, reads its first 6 control-table bytes and prints each reply as JSON. Try it against a virtual servo:
 *
 *   serialspec sim specs/feetech_sms.yaml --id 1          # prints the pseudo-terminal's path
 *   cc -std=c99 -I generated/c/feetech_sms examples/c/feetech_ping.c generated/c/feetech_sms/feetech_sms.c \
 *      generated/c/feetech_sms/feetech_sms_json.c -o feetech_ping
 *   ./feetech_ping /dev/pts/N 1
 *
 * POSIX (termios, poll); the generated code itself needs none of it. */
#define _DEFAULT_SOURCE /* cfmakeraw */
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <termios.h>
#include <unistd.h>

#include "feetech_sms.h"
#include "feetech_sms_json.h"

static int open_port(const char *path)
{
    struct termios t;
    int fd = open(path, O_RDWR | O_NOCTTY);
    if (fd < 0) {
        perror(path);
        return -1;
    }
    if (tcgetattr(fd, &t) == 0) {
        cfmakeraw(&t);
        cfsetispeed(&t, B1000000);
        cfsetospeed(&t, B1000000);
        tcsetattr(fd, TCSANOW, &t);
    }
    return fd;
}

/* Send one request, then feed what arrives to the reply parser until a reply comes or 500 ms pass. */
static int transact(int fd, const feetech_sms_msg_t *request, feetech_sms_msg_t *reply)
{
    uint8_t frame[FEETECH_SMS_MAX_FRAME], in[64];
    size_t len;
    feetech_sms_parser_t parser;
    int r = feetech_sms_encode(request, frame, sizeof(frame), &len);
    if (r != FEETECH_SMS_OK) {
        fprintf(stderr, "encode: %s\n", feetech_sms_result_name(r));
        return -1;
    }
    if (write(fd, frame, len) != (ssize_t)len) {
        perror("write");
        return -1;
    }
    feetech_sms_parser_init(&parser, FEETECH_SMS_RESPONSE);
    for (;;) {
        struct pollfd p = {0};
        ssize_t n;
        size_t at = 0u;
        p.fd = fd;
        p.events = POLLIN;
        if (poll(&p, 1, 500) <= 0) {
            fprintf(stderr, "no reply within 500 ms\n");
            return -1;
        }
        n = read(fd, in, sizeof(in));
        if (n <= 0) {
            return -1;
        }
        while (at < (size_t)n) {
            bool got;
            at += feetech_sms_parser_feed(&parser, in + at, (size_t)n - at, reply, &got);
            if (got) {
                return 0;
            }
        }
    }
}

int main(int argc, char **argv)
{
    feetech_sms_msg_t request, reply;
    char json[512];
    int fd;
    uint8_t id = (uint8_t)(argc > 2 ? atoi(argv[2]) : 1);
    if (argc < 2) {
        fprintf(stderr, "usage: %s PORT [ID]\n", argv[0]);
        return 2;
    }
    fd = open_port(argv[1]);
    if (fd < 0) {
        return 1;
    }
    request.kind = FEETECH_SMS_PING_REQUEST;
    request.u.ping_request.id = id;
    if (transact(fd, &request, &reply) != 0) {
        return 1;
    }
    feetech_sms_to_json(&reply, json, sizeof(json));
    printf("%s\n", json);
    request.kind = FEETECH_SMS_READ_REQUEST;
    request.u.read_request.id = id;
    request.u.read_request.address = 0;
    request.u.read_request.length = 6;
    if (transact(fd, &request, &reply) != 0) {
        return 1;
    }
    feetech_sms_to_json(&reply, json, sizeof(json));
    printf("%s\n", json);
    close(fd);
    return 0;
}
