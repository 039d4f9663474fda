/* PNG output through stb_image_write (see png_write.h). */
#include "host/render/png_write.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-prototypes"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

typedef struct {
    FILE *f;
    int failed;
} png_sink_t;

static void sink_write(void *ctx, void *data, int size)
{
    png_sink_t *s = ctx;
    if (size > 0 && fwrite(data, 1, (size_t)size, s->f) != (size_t)size)
        s->failed = 1;
}

argil_err_t png_write_rgb(const char *path, int width, int height, const uint8_t *rgb, char *err,
                          size_t err_len)
{
    if (width < 1 || height < 1 || width > 65535 || height > 65535 || rgb == NULL) {
        snprintf(err, err_len, "%s: image size %d x %d is not writable", path, width, height);
        return ARGIL_ERR_ARG;
    }
    char tmp[4096];
    if ((size_t)snprintf(tmp, sizeof(tmp), "%s.tmp", path) >= sizeof(tmp)) {
        snprintf(err, err_len, "%s: path too long", path);
        return ARGIL_ERR_ARG;
    }
    png_sink_t s = {fopen(tmp, "wb"), 0};
    if (s.f == NULL) {
        snprintf(err, err_len, "%s: cannot create: %s", tmp, strerror(errno));
        return ARGIL_ERR_IO;
    }
    const int ok = stbi_write_png_to_func(sink_write, &s, width, height, 3, rgb, width * 3);
    const int close_failed = fclose(s.f) != 0;
    if (!ok || s.failed || close_failed) {
        const int e = errno;
        remove(tmp);
        snprintf(err, err_len, "%s: %s", path, !ok ? "PNG encoding failed (out of memory?)"
                                                   : strerror(e));
        return ok ? ARGIL_ERR_IO : ARGIL_ERR_NOMEM;
    }
    if (rename(tmp, path) != 0) {
        const int e = errno;
        remove(tmp);
        snprintf(err, err_len, "%s: cannot rename into place: %s", path, strerror(e));
        return ARGIL_ERR_IO;
    }
    return ARGIL_OK;
}
