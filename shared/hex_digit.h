/* One hex digit's value: the key file, link device strings (usb:VID:PID) and the candump log
 * reader all read hex, by this one rule. Freestanding, header only. */
#ifndef ARGIL_HEX_DIGIT_H
#define ARGIL_HEX_DIGIT_H

/* The value 0..15 of hex digit c (either case), or -1 when c is not one. */
static inline int hex_digit_value(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

#endif
