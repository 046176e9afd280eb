/* For the golden-vector program on an 8-bit AVR under simavr (tests/test_c_backend.py): stdout goes out on USART0,
 * whose bytes simavr prints, and returning from main stops the simulation (interrupts off, then sleep, which simavr
 * reads as the program's end). Nothing of serialspec's: avr-libc alone. */
#include <avr/io.h>
#include <stdio.h>

static int put(char c, FILE *stream)
{
    (void)stream;
    loop_until_bit_is_set(UCSR0A, UDRE0);
    UDR0 = (uint8_t)c;
    return 0;
}

static FILE out = FDEV_SETUP_STREAM(put, NULL, _FDEV_SETUP_WRITE);

/* run by the C start-up code before main (section .init8) */
void avr_stdout_init(void) __attribute__((section(".init8"), naked, used));
void avr_stdout_init(void)
{
    UCSR0B = _BV(TXEN0);
    stdout = &out;
}

/* run by exit() after main returns (section .fini0) */
void avr_stop(void) __attribute__((section(".fini0"), naked, used));
void avr_stop(void)
{
    __asm__ volatile("cli\n\tsleep");
}
