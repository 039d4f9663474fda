/* EGL surfaceless backend (see backend_egl.h). */
#define EGL_EGL_PROTOTYPES 0
#include "host/render/backend_egl.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    PFNEGLGETPROCADDRESSPROC GetProcAddress;
    PFNEGLGETPLATFORMDISPLAYEXTPROC GetPlatformDisplayEXT;
    PFNEGLINITIALIZEPROC Initialize;
    PFNEGLTERMINATEPROC Terminate;
    PFNEGLBINDAPIPROC BindAPI;
    PFNEGLCHOOSECONFIGPROC ChooseConfig;
    PFNEGLCREATECONTEXTPROC CreateContext;
    PFNEGLDESTROYCONTEXTPROC DestroyContext;
    PFNEGLMAKECURRENTPROC MakeCurrent;
    PFNEGLGETERRORPROC GetError;
    PFNEGLQUERYSTRINGPROC QueryString;
} egl_fns_t;

static gl_proc_t egl_get_proc(const char *name, void *ctx)
{
    const egl_fns_t *f = ctx;
    return (gl_proc_t)f->GetProcAddress(name);
}

static argil_err_t fail(egl_offscreen_t *e, const char *what, char *err, size_t err_len)
{
    const egl_fns_t *f = e->fns;
    const unsigned code = (f && f->GetError) ? (unsigned)f->GetError() : 0u;
    snprintf(err, err_len, "offscreen OpenGL (EGL surfaceless): %s (EGL error 0x%04x)", what,
             code);
    egl_offscreen_close(e);
    return ARGIL_ERR_STATE;
}

argil_err_t egl_offscreen_open(egl_offscreen_t *e, gl_api_t *gl, char *err, size_t err_len)
{
    memset(e, 0, sizeof(*e));
    const argil_err_t st = gl_lib_open("libEGL.so.1", "offscreen OpenGL",
                                       "libegl1 and libegl-mesa0", sizeof(egl_fns_t), &e->lib,
                                       &e->fns, err, err_len);
    if (st != ARGIL_OK)
        return st;
    egl_fns_t *f = e->fns;
    void *gpa = dlsym(e->lib, "eglGetProcAddress");
    if (gpa == NULL)
        return fail(e, "libEGL has no eglGetProcAddress", err, err_len);
    memcpy(&f->GetProcAddress, &gpa, sizeof(gpa));
#define EGL_LOAD(field, name)                                                                    \
    f->field = (__typeof__(f->field))f->GetProcAddress(name);                                    \
    if (f->field == NULL)                                                                        \
        return fail(e, "libEGL has no " name, err, err_len);
    EGL_LOAD(GetPlatformDisplayEXT, "eglGetPlatformDisplayEXT")
    EGL_LOAD(Initialize, "eglInitialize")
    EGL_LOAD(Terminate, "eglTerminate")
    EGL_LOAD(BindAPI, "eglBindAPI")
    EGL_LOAD(ChooseConfig, "eglChooseConfig")
    EGL_LOAD(CreateContext, "eglCreateContext")
    EGL_LOAD(DestroyContext, "eglDestroyContext")
    EGL_LOAD(MakeCurrent, "eglMakeCurrent")
    EGL_LOAD(GetError, "eglGetError")
    EGL_LOAD(QueryString, "eglQueryString")
#undef EGL_LOAD

    EGLDisplay dpy = f->GetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY,
                                              NULL);
    if (dpy == EGL_NO_DISPLAY)
        return fail(e, "no surfaceless display (is libegl-mesa0 installed?)", err, err_len);
    EGLint major = 0, minor = 0;
    if (!f->Initialize(dpy, &major, &minor))
        return fail(e, "eglInitialize failed on the surfaceless platform", err, err_len);
    e->display = dpy;
    if (!f->BindAPI(EGL_OPENGL_API))
        return fail(e, "desktop OpenGL is not available through EGL", err, err_len);
    /* Any config will do (drawing goes to an FBO); without one, EGL_KHR_no_config_context. */
    const EGLint cfg_attr[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                               EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig cfg = EGL_NO_CONFIG_KHR;
    EGLint n_cfg = 0;
    if (!f->ChooseConfig(dpy, cfg_attr, &cfg, 1, &n_cfg) || n_cfg < 1) {
        const char *ext = f->QueryString(dpy, EGL_EXTENSIONS);
        if (ext == NULL || strstr(ext, "EGL_KHR_no_config_context") == NULL)
            return fail(e, "no EGL config renders desktop OpenGL", err, err_len);
        cfg = EGL_NO_CONFIG_KHR;
    }
    const EGLint ctx_attr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext ctx = f->CreateContext(dpy, cfg, EGL_NO_CONTEXT, ctx_attr);
    if (ctx == EGL_NO_CONTEXT)
        return fail(e, "cannot create an OpenGL 3.3 core context", err, err_len);
    e->context = ctx;
    if (!f->MakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx))
        return fail(e, "cannot make the surfaceless context current", err, err_len);
    const argil_err_t rc = gl_api_load(gl, egl_get_proc, f, err, err_len);
    if (rc != ARGIL_OK) {
        egl_offscreen_close(e);
        return rc;
    }
    return ARGIL_OK;
}

void egl_offscreen_close(egl_offscreen_t *e)
{
    egl_fns_t *f = e->fns;
    if (f != NULL && e->display != NULL) {
        f->MakeCurrent(e->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (e->context != NULL)
            f->DestroyContext(e->display, e->context);
        f->Terminate(e->display);
    }
    free(f);
    /* libEGL stays loaded: Mesa registers exit handlers that must still find their code. */
    memset(e, 0, sizeof(*e));
}
