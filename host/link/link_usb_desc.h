/* Reading the board's USB descriptors: which interface is argil's vendor interface and which
 * endpoint addresses its bulk IN and OUT got (a UDC may renumber them: 0x01/0x82 declared by
 * the gadget came back as 0x02/0x81 under dummy_hcd), and whether a device sits at a given
 * bus/port path. Pure: bytes in, fields out. */
#ifndef ARGIL_LINK_USB_DESC_H
#define ARGIL_LINK_USB_DESC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/link/link_spec.h"

typedef enum {
    USB_DESC_OK = 0,
    USB_DESC_ERR_SHORT = -1,      /* fewer than 9 bytes, or wTotalLength beyond the blob */
    USB_DESC_ERR_TYPE = -2,       /* the blob does not start with a configuration descriptor */
    USB_DESC_ERR_LENGTH = -3,     /* a descriptor's bLength is < 2 or runs past the end */
    USB_DESC_ERR_NO_INTERFACE = -4, /* no vendor-class (0xFF) interface with bulk IN and OUT */
} usb_desc_err_t;

typedef struct {
    uint8_t interface;          /* bInterfaceNumber */
    uint8_t alt_setting;
    uint8_t ep_in, ep_out;      /* endpoint addresses (ep_in has bit 7 set) */
    uint16_t in_max_packet, out_max_packet;
} usb_endpoints_t;

/* Finds the first vendor-class interface with a bulk IN and a bulk OUT endpoint in a raw
 * configuration descriptor (as GET_DESCRIPTOR(CONFIGURATION) returns it). */
usb_desc_err_t usb_desc_find_endpoints(const uint8_t *cfg, size_t len, usb_endpoints_t *out);

const char *usb_desc_err_text(usb_desc_err_t e);

/* True when a device on bus with these port numbers is the one spec names by path. */
bool usb_desc_path_match(const link_spec_t *spec, uint8_t bus, const uint8_t *ports,
                         int n_ports);

#endif
