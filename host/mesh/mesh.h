/* Indexed triangle mesh in model space: the mesher fills it, the renderer and exporters read it. */
#ifndef ARGIL_MESH_H
#define ARGIL_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "shared/argil_err.h"
#include "shared/vec3.h"

typedef struct {
    float *pos;      /* xyz per vertex, model-space m */
    float *normal;   /* xyz per vertex, unit, outward */
    uint32_t *tri;   /* 3 vertex indices per triangle, CCW seen from outside */
    uint8_t *rgb;    /* r g b per vertex (painted material) when has_rgb, else NULL */
    size_t n_vert, n_tri, cap_vert, cap_tri;
    int has_rgb;     /* set by mesh_enable_rgb: rgb grows with the vertices */
} mesh_t;

/* Makes m an empty mesh that owns no memory. */
void mesh_init(mesh_t *m);

/* Releases m's arrays and leaves it empty (as after mesh_init). */
void mesh_free(mesh_t *m);

/* Empties m but keeps its capacity for reuse. */
void mesh_clear(mesh_t *m);

/* Ensures room for at least n_vert vertices and n_tri triangles in total (ARGIL_ERR_NOMEM or
 * ARGIL_ERR_ARG beyond 2^32 vertices); the contents are kept. */
argil_err_t mesh_reserve(mesh_t *m, size_t n_vert, size_t n_tri);

/* Resizes the vertex arrays to cap vertices: pos and normal, and rgb when it is not NULL. On
 * ARGIL_ERR_NOMEM the arrays that were resized keep their new size (each stays valid). */
argil_err_t mesh_vert_arrays_resize(float **pos, float **normal, uint8_t **rgb, size_t cap);

/* Resizes a triangle index array to cap triangles; ARGIL_ERR_NOMEM leaves it as it was. */
argil_err_t mesh_tri_array_resize(uint32_t **tri, size_t cap);

/* Gives m a colour per vertex (existing vertices become mid grey 128); ARGIL_ERR_NOMEM. */
argil_err_t mesh_enable_rgb(mesh_t *m);

/* Stores position pos_m and normal as vertex i of the pos and normal arrays (3 floats each). */
static inline void mesh_vert_put(float *pos, float *normal, size_t i, vec3_t pos_m, vec3_t n)
{
    float *p = pos + 3 * i, *q = normal + 3 * i;
    p[0] = pos_m.x;
    p[1] = pos_m.y;
    p[2] = pos_m.z;
    q[0] = n.x;
    q[1] = n.y;
    q[2] = n.z;
}

/* Appends a vertex and stores its index in *index_out (may be NULL). */
argil_err_t mesh_add_vertex(mesh_t *m, vec3_t pos_m, vec3_t normal, uint32_t *index_out);

/* Appends a vertex with colour rgb (mesh_enable_rgb first, else ARGIL_ERR_STATE). */
argil_err_t mesh_add_vertex_rgb(mesh_t *m, vec3_t pos_m, vec3_t normal, const uint8_t rgb[3],
                                uint32_t *index_out);

/* Appends triangle (a, b, c); ARGIL_ERR_ARG when an index names no vertex. */
argil_err_t mesh_add_triangle(mesh_t *m, uint32_t a, uint32_t b, uint32_t c);

#endif
