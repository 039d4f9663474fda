/* Run-time resolution of the GL 3.3 core entry points (see gl_api.h). */
#include "host/render/gl_api.h"

#include <stdio.h>
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
