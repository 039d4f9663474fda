/* USB FunctionFS transport of the host link: the daemon writes the interface and endpoint
 * descriptors to ep0; the gadget's VID:PID (1209:0001) come from the configfs setup
 * (firmware/board/argil-gadget.sh). Endpoint files: ep1 = bulk OUT, ep2 = bulk IN. */
#include <errno.h>
#include <fcntl.h>
#include <linux/usb/functionfs.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "link_io.h"
#include "shared/wire.h"

/* One speed's descriptors: interface + bulk OUT + bulk IN; returns 23 bytes. */
static size_t speed_descs(uint8_t *p, uint16_t max_packet)
{
    const uint8_t intf[9] = {9, 4 /* INTERFACE */, 0, 0, 2, 0xFF /* vendor */, 0, 0, 1};
    memcpy(p, intf, 9);
    uint8_t *e = p + 9;
    const uint8_t addrs[2] = {0x01 /* OUT */, 0x82 /* IN */};
    for (int i = 0; i < 2; i++, e += 7) {
        e[0] = 7;
        e[1] = 5; /* ENDPOINT */
        e[2] = addrs[i];
        e[3] = 2; /* bulk */
        le_put_u16(e + 4, max_packet);
        e[6] = 0;
    }
    return 23;
}

size_t link_ffs_descriptors(uint8_t *buf, size_t cap)
{
    const size_t total = 12u + 8u + 2u * 23u;
    if (cap < total)
        return 0;
    le_put_u32(buf, FUNCTIONFS_DESCRIPTORS_MAGIC_V2);
    le_put_u32(buf + 4, (uint32_t)total);
    le_put_u32(buf + 8, FUNCTIONFS_HAS_FS_DESC | FUNCTIONFS_HAS_HS_DESC);
    le_put_u32(buf + 12, 3); /* full-speed descriptor count */
    le_put_u32(buf + 16, 3); /* high-speed descriptor count */
    size_t at = 20;
    at += speed_descs(buf + at, 64);
    at += speed_descs(buf + at, 512);
    return at;
}

size_t link_ffs_strings(uint8_t *buf, size_t cap)
{
    static const char name[] = "argil haptic board";
    const size_t total = 16u + 2u + sizeof(name);
    if (cap < total)
        return 0;
    le_put_u32(buf, FUNCTIONFS_STRINGS_MAGIC);
    le_put_u32(buf + 4, (uint32_t)total);
    le_put_u32(buf + 8, 1);  /* strings per language */
    le_put_u32(buf + 12, 1); /* languages */
    le_put_u16(buf + 16, 0x0409);
    memcpy(buf + 18, name, sizeof(name));
    return total;
}

argil_err_t link_ffs_open(link_ffs_t *f, const char *dir, char *err, size_t err_len)
{
    memset(f, 0, sizeof(*f));
    f->ep0 = f->ep_in = f->ep_out = -1;
    char path[512];
    snprintf(path, sizeof(path), "%s/ep0", dir);
    f->ep0 = open(path, O_RDWR | O_CLOEXEC);
    if (f->ep0 < 0) {
        snprintf(err, err_len, "host link 'ffs:%s': cannot open %s (%s); is FunctionFS mounted "
                 "there (firmware/board/argil-gadget.sh)?", dir, path, strerror(errno));
        return ARGIL_ERR_IO;
    }
    uint8_t blob[128];
    size_t n = link_ffs_descriptors(blob, sizeof(blob));
    if (write(f->ep0, blob, n) != (ssize_t)n) {
        snprintf(err, err_len, "host link 'ffs:%s': the gadget refused the descriptors (%s)", dir,
                 strerror(errno));
        link_ffs_close(f);
        return ARGIL_ERR_IO;
    }
    n = link_ffs_strings(blob, sizeof(blob));
    if (write(f->ep0, blob, n) != (ssize_t)n) {
        snprintf(err, err_len, "host link 'ffs:%s': the gadget refused the strings (%s)", dir,
                 strerror(errno));
        link_ffs_close(f);
        return ARGIL_ERR_IO;
    }
    snprintf(path, sizeof(path), "%s/ep1", dir);
    f->ep_out = open(path, O_RDONLY | O_CLOEXEC);
    snprintf(path, sizeof(path), "%s/ep2", dir);
    f->ep_in = open(path, O_WRONLY | O_CLOEXEC);
    if (f->ep_out < 0 || f->ep_in < 0) {
        snprintf(err, err_len, "host link 'ffs:%s': cannot open the bulk endpoints ep1/ep2 (%s)",
                 dir, strerror(errno));
        link_ffs_close(f);
        return ARGIL_ERR_IO;
    }
    return ARGIL_OK;
}

void link_ffs_close(link_ffs_t *f)
{
    if (f->ep_in >= 0)
        close(f->ep_in);
    if (f->ep_out >= 0)
        close(f->ep_out);
    if (f->ep0 >= 0)
        close(f->ep0);
    f->ep0 = f->ep_in = f->ep_out = -1;
}
