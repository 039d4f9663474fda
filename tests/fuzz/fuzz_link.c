/* libFuzzer target for the host link's parsers: arbitrary bytes as a device string
 * (link_spec_parse) and as a USB configuration descriptor (usb_desc_find_endpoints). A parse
 * that succeeds must give fields inside their documented ranges. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "host/link/link_spec.h"
#include "host/link/link_usb_desc.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check(int ok)
{
    if (!ok)
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char s[512];
    const size_t n = size < sizeof(s) - 1 ? size : sizeof(s) - 1;
    memcpy(s, data, n);
    s[n] = '\0';
    link_spec_t spec;
    const link_spec_err_t e = link_spec_parse(s, &spec);
    check(link_spec_err_text(e) != NULL);
    if (e == LINK_SPEC_OK) {
        check(spec.kind == LINK_KIND_SIM || spec.kind == LINK_KIND_UDP ||
              spec.kind == LINK_KIND_USB);
        if (spec.kind == LINK_KIND_UDP) {
            check(spec.port >= 1);
            check(strlen(spec.host) >= 1 && strlen(spec.host) < LINK_SPEC_HOST_MAX);
        }
        if (spec.kind == LINK_KIND_USB && spec.by_path) {
            check(spec.bus >= 1 && spec.n_ports >= 1 && spec.n_ports <= LINK_SPEC_PORTS_MAX);
            for (uint8_t i = 0; i < spec.n_ports; i++)
                check(spec.ports[i] >= 1);
            check(usb_desc_path_match(&spec, spec.bus, spec.ports, spec.n_ports));
        }
    }
    usb_endpoints_t ep;
    if (usb_desc_find_endpoints(data, size, &ep) == USB_DESC_OK) {
        check((ep.ep_in & 0x80u) != 0);
        check((ep.ep_out & 0x80u) == 0);
        check(ep.in_max_packet <= 0x7FFu && ep.out_max_packet <= 0x7FFu);
    }
    return 0;
}
