/* Device strings of the host link: parsed field by field, every rule with its own error. */
#include "link_spec.h"

#include <string.h>

#include "shared/hex_digit.h"

/* A decimal number lo..hi made of the whole of [s, s+len); false otherwise. */
static bool parse_dec(const char *s, size_t len, unsigned lo, unsigned hi, unsigned *out)
{
    if (len == 0 || len > 5)
        return false;
    unsigned v = 0;
    for (size_t i = 0; i < len; i++) {
        if (s[i] < '0' || s[i] > '9')
            return false;
        v = v * 10u + (unsigned)(s[i] - '0');
    }
    if (v < lo || v > hi)
        return false;
    *out = v;
    return true;
}

/* 1..4 hex digits making the whole of [s, s+len). */
static bool parse_hex16(const char *s, size_t len, uint16_t *out)
{
    if (len == 0 || len > 4)
        return false;
    unsigned v = 0;
    for (size_t i = 0; i < len; i++) {
        const int d = hex_digit_value(s[i]);
        if (d < 0)
            return false;
        v = v * 16u + (unsigned)d;
    }
    *out = (uint16_t)v;
    return true;
}

static link_spec_err_t parse_udp(const char *s, link_spec_t *spec)
{
    const char *colon = strrchr(s, ':');
    if (!colon)
        return LINK_SPEC_ERR_UDP_FORM;
    const size_t hlen = (size_t)(colon - s);
    if (hlen == 0 || hlen >= LINK_SPEC_HOST_MAX)
        return LINK_SPEC_ERR_UDP_HOST;
    for (size_t i = 0; i < hlen; i++) {
        const char c = s[i];
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                        (c >= '0' && c <= '9') || c == '.' || c == '-' || c == '_';
        if (!ok)
            return LINK_SPEC_ERR_UDP_HOST;
    }
    unsigned port;
    if (!parse_dec(colon + 1, strlen(colon + 1), 1, 65535, &port))
        return LINK_SPEC_ERR_UDP_PORT;
    memcpy(spec->host, s, hlen);
    spec->host[hlen] = '\0';
    spec->port = (uint16_t)port;
    return LINK_SPEC_OK;
}

static link_spec_err_t parse_usb_path(const char *s, link_spec_t *spec)
{
    const char *dash = strchr(s, '-');
    unsigned v;
    if (!parse_dec(s, (size_t)(dash - s), 1, 255, &v))
        return LINK_SPEC_ERR_USB_BUS;
    spec->bus = (uint8_t)v;
    spec->by_path = true;
    const char *p = dash + 1;
    for (;;) {
        const char *dot = strchr(p, '.');
        const size_t len = dot ? (size_t)(dot - p) : strlen(p);
        if (spec->n_ports == LINK_SPEC_PORTS_MAX)
            return LINK_SPEC_ERR_USB_DEPTH;
        if (!parse_dec(p, len, 1, 255, &v))
            return LINK_SPEC_ERR_USB_PORT;
        spec->ports[spec->n_ports++] = (uint8_t)v;
        if (!dot)
            return LINK_SPEC_OK;
        p = dot + 1;
    }
}

static link_spec_err_t parse_usb(const char *s, link_spec_t *spec)
{
    const char *colon = strchr(s, ':');
    if (colon) {
        if (!parse_hex16(s, (size_t)(colon - s), &spec->vid) ||
            !parse_hex16(colon + 1, strlen(colon + 1), &spec->pid))
            return LINK_SPEC_ERR_USB_ID;
        return LINK_SPEC_OK;
    }
    if (strchr(s, '-'))
        return parse_usb_path(s, spec);
    return LINK_SPEC_ERR_USB_FORM;
}

link_spec_err_t link_spec_parse(const char *s, link_spec_t *spec)
{
    memset(spec, 0, sizeof(*spec));
    spec->vid = LINK_SPEC_DEFAULT_VID;
    spec->pid = LINK_SPEC_DEFAULT_PID;
    if (!s || !*s)
        return LINK_SPEC_ERR_EMPTY;
    if (strncmp(s, "sim", 3) == 0 && (s[3] == '\0' || s[3] == ':')) {
        spec->kind = LINK_KIND_SIM;
        if (s[3] == '\0')
            return LINK_SPEC_OK;
        if (strcmp(s + 4, "press") != 0)
            return LINK_SPEC_ERR_SIM_ARGS;
        spec->sim_hand = LINK_SIM_HAND_PRESS;
        return LINK_SPEC_OK;
    }
    if (strncmp(s, "udp", 3) == 0 && (s[3] == '\0' || s[3] == ':')) {
        spec->kind = LINK_KIND_UDP;
        return s[3] == '\0' ? LINK_SPEC_ERR_UDP_FORM : parse_udp(s + 4, spec);
    }
    if (strncmp(s, "usb", 3) == 0 && (s[3] == '\0' || s[3] == ':')) {
        spec->kind = LINK_KIND_USB;
        return s[3] == '\0' ? LINK_SPEC_OK : parse_usb(s + 4, spec);
    }
    return LINK_SPEC_ERR_KIND;
}

const char *link_spec_err_text(link_spec_err_t err)
{
    switch (err) {
    case LINK_SPEC_OK: return "ok";
    case LINK_SPEC_ERR_EMPTY: return "empty; use sim[:press], udp:HOST:PORT or usb[:VID:PID|:BUS-PORT[.PORT...]]";
    case LINK_SPEC_ERR_KIND: return "unknown kind; use sim[:press], udp:HOST:PORT or usb[:VID:PID|:BUS-PORT[.PORT...]]";
    case LINK_SPEC_ERR_SIM_ARGS: return "'sim' takes nothing after it but ':press'";
    case LINK_SPEC_ERR_UDP_FORM: return "expected udp:HOST:PORT";
    case LINK_SPEC_ERR_UDP_HOST: return "the UDP host must be an IPv4 address or a host name (letters, digits, '.', '-', '_'; at most 63)";
    case LINK_SPEC_ERR_UDP_PORT: return "the UDP port must be a whole number 1..65535";
    case LINK_SPEC_ERR_USB_ID: return "expected usb:VID:PID with 1 to 4 hex digits each (e.g. usb:1209:0001)";
    case LINK_SPEC_ERR_USB_BUS: return "the USB bus must be a number 1..255 (usb:BUS-PORT[.PORT...], as in lsusb -t)";
    case LINK_SPEC_ERR_USB_PORT: return "each USB port must be a number 1..255 (usb:BUS-PORT[.PORT...])";
    case LINK_SPEC_ERR_USB_DEPTH: return "a USB port path has at most 7 ports";
    case LINK_SPEC_ERR_USB_FORM: return "expected usb, usb:VID:PID or usb:BUS-PORT[.PORT...]";
    }
    return "unknown error";
}
