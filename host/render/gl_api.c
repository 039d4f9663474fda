/* Run-time resolution of the GL 3.3 core entry points (see gl_api.h). */
#include "host/render/gl_api.h"

#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

argil_err_t gl_api_load(gl_api_t *gl, gl_get_proc_fn get_proc, void *ctx, char *err,
                        size_t err_len)
{
    memset(gl, 0, sizeof(*gl));
#define GL_API_LOAD(type, name)                                                                  \
    {                                                                                            \
        gl_proc_t p = get_proc("gl" #name, ctx);                                                 \
        if (p == NULL) {                                                                         \
            snprintf(err, err_len, "the OpenGL context has no gl%s", #name);                    \
            return ARGIL_ERR_STATE;                                                              \
        }                                                                                        \
        memcpy(&gl->name, &p, sizeof(p));                                                        \
    }
    GL_API_FUNCS(GL_API_LOAD)
#undef GL_API_LOAD
    return ARGIL_OK;
}

argil_err_t gl_lib_open(const char *soname, const char *what, const char *packages,
                        size_t fns_bytes, void **lib, void **fns, char *err, size_t err_len)
{
    void *h = dlopen(soname, RTLD_NOW | RTLD_LOCAL);
    if (h == NULL) {
        snprintf(err, err_len, "%s: cannot load %s (install %s: toolchain/install-deps.sh render)",
                 what, soname, packages);
        return ARGIL_ERR_STATE;
    }
    void *f = calloc(1, fns_bytes);
    if (f == NULL) {
        snprintf(err, err_len, "%s: out of memory", what);
        return ARGIL_ERR_NOMEM;
    }
    *lib = h;
    *fns = f;
    return ARGIL_OK;
}
