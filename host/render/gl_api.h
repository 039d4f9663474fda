/* The OpenGL 3.3 core entry points the renderer uses, as one table of function pointers resolved
 * at run time through the backend's get-proc-address (EGL or GLFW), so nothing links to libGL. */
#ifndef ARGIL_GL_API_H
#define ARGIL_GL_API_H

#include <stddef.h>

#include <GL/glcorearb.h>

#include "shared/argil_err.h"

/* X(type, name): the table field is `name`, the GL symbol is "gl" #name. */
#define GL_API_FUNCS(X)                                                                          \
    X(PFNGLGETSTRINGPROC, GetString)                                                             \
    X(PFNGLGETINTEGERVPROC, GetIntegerv)                                                         \
    X(PFNGLGETERRORPROC, GetError)                                                               \
    X(PFNGLVIEWPORTPROC, Viewport)                                                               \
    X(PFNGLCLEARCOLORPROC, ClearColor)                                                           \
    X(PFNGLCLEARPROC, Clear)                                                                     \
    X(PFNGLENABLEPROC, Enable)                                                                   \
    X(PFNGLDISABLEPROC, Disable)                                                                 \
    X(PFNGLBLENDFUNCPROC, BlendFunc)                                                             \
    X(PFNGLDEPTHMASKPROC, DepthMask)                                                             \
    X(PFNGLDEPTHFUNCPROC, DepthFunc)                                                             \
    X(PFNGLCULLFACEPROC, CullFace)                                                               \
    X(PFNGLPOLYGONMODEPROC, PolygonMode)                                                         \
    X(PFNGLCREATESHADERPROC, CreateShader)                                                       \
    X(PFNGLSHADERSOURCEPROC, ShaderSource)                                                       \
    X(PFNGLCOMPILESHADERPROC, CompileShader)                                                     \
    X(PFNGLGETSHADERIVPROC, GetShaderiv)                                                         \
    X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                                               \
    X(PFNGLDELETESHADERPROC, DeleteShader)                                                       \
    X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                                     \
    X(PFNGLATTACHSHADERPROC, AttachShader)                                                       \
    X(PFNGLLINKPROGRAMPROC, LinkProgram)                                                         \
    X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                                       \
    X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                                             \
    X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                                                     \
    X(PFNGLUSEPROGRAMPROC, UseProgram)                                                           \
    X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                                           \
    X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                                               \
    X(PFNGLUNIFORM3FVPROC, Uniform3fv)                                                           \
    X(PFNGLUNIFORM4FVPROC, Uniform4fv)                                                           \
    X(PFNGLUNIFORM1FPROC, Uniform1f)                                                             \
    X(PFNGLUNIFORM1IPROC, Uniform1i)                                                             \
    X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                                                 \
    X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                                                 \
    X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                                           \
    X(PFNGLGENBUFFERSPROC, GenBuffers)                                                           \
    X(PFNGLBINDBUFFERPROC, BindBuffer)                                                           \
    X(PFNGLBUFFERDATAPROC, BufferData)                                                           \
    X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                                     \
    X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                                         \
    X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)                                 \
    X(PFNGLDISABLEVERTEXATTRIBARRAYPROC, DisableVertexAttribArray)                               \
    X(PFNGLVERTEXATTRIB3FPROC, VertexAttrib3f)                                                   \
    X(PFNGLDRAWELEMENTSPROC, DrawElements)                                                       \
    X(PFNGLDRAWARRAYSPROC, DrawArrays)                                                           \
    X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                                                 \
    X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                                                 \
    X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                                           \
    X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)                                               \
    X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)                                               \
    X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers)                                         \
    X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)                                         \
    X(PFNGLRENDERBUFFERSTORAGEMULTISAMPLEPROC, RenderbufferStorageMultisample)                   \
    X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)                                 \
    X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                                   \
    X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer)                                                 \
    X(PFNGLREADBUFFERPROC, ReadBuffer)                                                           \
    X(PFNGLREADPIXELSPROC, ReadPixels)                                                           \
    X(PFNGLPIXELSTOREIPROC, PixelStorei)                                                         \
    X(PFNGLFINISHPROC, Finish)

#define GL_API_FIELD(type, name) type name;
typedef struct {
    GL_API_FUNCS(GL_API_FIELD)
} gl_api_t;
#undef GL_API_FIELD

/* Resolves a GL symbol by name ("glClear"); NULL when the context does not provide it. */
typedef void (*gl_proc_t)(void);
typedef gl_proc_t (*gl_get_proc_fn)(const char *name, void *ctx);

/* Fills every entry of gl through get_proc; ARGIL_ERR_STATE with the first missing name in err. */
argil_err_t gl_api_load(gl_api_t *gl, gl_get_proc_fn get_proc, void *ctx, char *err,
                        size_t err_len);

/* Loads the shared library soname into *lib and a zeroed table of fns_bytes (for its entry
 * points) into *fns, both left as they were on failure: ARGIL_ERR_STATE when the library is
 * missing (err: "what: cannot load soname (install packages: ...)"), ARGIL_ERR_NOMEM. The
 * library stays loaded for the process: GL drivers run exit handlers from it. */
argil_err_t gl_lib_open(const char *soname, const char *what, const char *packages,
                        size_t fns_bytes, void **lib, void **fns, char *err, size_t err_len);

#endif
