/* Walks a raw USB configuration descriptor for argil's vendor interface and its endpoints. */
#include "link_usb_desc.h"

#include <string.h>

#include "shared/wire.h"

enum {
    DT_CONFIG = 2,
    DT_INTERFACE = 4,
    DT_ENDPOINT = 5,
    CLASS_VENDOR = 0xFF,
    XFER_BULK = 2,
};

usb_desc_err_t usb_desc_find_endpoints(const uint8_t *cfg, size_t len, usb_endpoints_t *out)
{
    if (len < 9)
        return USB_DESC_ERR_SHORT;
    if (cfg[0] < 9 || cfg[1] != DT_CONFIG)
        return USB_DESC_ERR_TYPE;
    const size_t total = le_get_u16(cfg + 2);
    if (total < 9 || total > len)
        return USB_DESC_ERR_SHORT;
    bool in_vendor = false;
    usb_endpoints_t cur;
    memset(&cur, 0, sizeof(cur));
    size_t at = cfg[0];
    while (at < total) {
        const uint8_t dlen = cfg[at];
        if (dlen < 2 || dlen > total - at)
            return USB_DESC_ERR_LENGTH;
        const uint8_t type = cfg[at + 1];
        if (type == DT_INTERFACE && dlen >= 9) {
            if (in_vendor && cur.ep_in && cur.ep_out)
                break;
            in_vendor = cfg[at + 5] == CLASS_VENDOR;
            memset(&cur, 0, sizeof(cur));
            cur.interface = cfg[at + 2];
            cur.alt_setting = cfg[at + 3];
        } else if (type == DT_ENDPOINT && dlen >= 7 && in_vendor &&
                   (cfg[at + 3] & 3u) == XFER_BULK) {
            const uint8_t addr = cfg[at + 2];
            const uint16_t mps = le_get_u16(cfg + at + 4) & 0x7FFu;
            if ((addr & 0x80u) && !cur.ep_in) {
                cur.ep_in = addr;
                cur.in_max_packet = mps;
            } else if (!(addr & 0x80u) && !cur.ep_out) {
                cur.ep_out = addr;
                cur.out_max_packet = mps;
            }
        }
        at += dlen;
    }
    if (!in_vendor || !cur.ep_in || !cur.ep_out)
        return USB_DESC_ERR_NO_INTERFACE;
    *out = cur;
    return USB_DESC_OK;
}

const char *usb_desc_err_text(usb_desc_err_t e)
{
    switch (e) {
    case USB_DESC_OK: return "ok";
    case USB_DESC_ERR_SHORT: return "configuration descriptor truncated";
    case USB_DESC_ERR_TYPE: return "not a configuration descriptor";
    case USB_DESC_ERR_LENGTH: return "a descriptor length runs past the configuration";
    case USB_DESC_ERR_NO_INTERFACE:
        return "no vendor-class interface with a bulk IN and a bulk OUT endpoint";
    }
    return "unknown error";
}

bool usb_desc_path_match(const link_spec_t *spec, uint8_t bus, const uint8_t *ports,
                         int n_ports)
{
    if (!spec->by_path || bus != spec->bus || n_ports != (int)spec->n_ports)
        return false;
    return memcmp(ports, spec->ports, spec->n_ports) == 0;
}
