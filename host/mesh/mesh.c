/* Growable indexed triangle mesh (host heap). */
#include "host/mesh/mesh.h"

#include <stdlib.h>

#define MESH_MAX_VERTS ((size_t)UINT32_MAX)

void mesh_init(mesh_t *m)
{
    *m = (mesh_t){0};
}

void mesh_free(mesh_t *m)
{
    free(m->pos);
    free(m->normal);
    free(m->tri);
    free(m->rgb);
    mesh_init(m);
}

void mesh_clear(mesh_t *m)
{
    m->n_vert = 0;
    m->n_tri = 0;
}

/* Next capacity: doubling from 256, at least need, at most limit. */
static size_t next_cap(size_t cap, size_t need, size_t limit)
{
    size_t c = cap < 256 ? 256 : cap;
    while (c < need && c <= limit / 2)
        c *= 2;
    if (c < need)
        c = need;
    return c > limit ? limit : c;
}

argil_err_t mesh_vert_arrays_resize(float **pos, float **normal, uint8_t **rgb, size_t cap)
{
    float *p = realloc(*pos, cap * 3 * sizeof(float));
    if (p == NULL)
        return ARGIL_ERR_NOMEM;
    *pos = p;
    float *n = realloc(*normal, cap * 3 * sizeof(float));
    if (n == NULL)
        return ARGIL_ERR_NOMEM;
    *normal = n;
    if (rgb != NULL) {
        uint8_t *c = realloc(*rgb, cap * 3);
        if (c == NULL)
            return ARGIL_ERR_NOMEM;
        *rgb = c;
    }
    return ARGIL_OK;
}

argil_err_t mesh_tri_array_resize(uint32_t **tri, size_t cap)
{
    uint32_t *t = realloc(*tri, cap * 3 * sizeof(uint32_t));
    if (t == NULL)
        return ARGIL_ERR_NOMEM;
    *tri = t;
    return ARGIL_OK;
}

argil_err_t mesh_reserve(mesh_t *m, size_t n_vert, size_t n_tri)
{
    if (n_vert > MESH_MAX_VERTS || n_tri > SIZE_MAX / (3 * sizeof(uint32_t)))
        return ARGIL_ERR_ARG;
    if (n_vert > m->cap_vert) {
        size_t cap = next_cap(m->cap_vert, n_vert, MESH_MAX_VERTS);
        if (cap > SIZE_MAX / (3 * sizeof(float)))
            return ARGIL_ERR_NOMEM;
        /* On failure the arrays that grew keep their size; cap_vert stays, which is safe. */
        argil_err_t e =
            mesh_vert_arrays_resize(&m->pos, &m->normal, m->has_rgb ? &m->rgb : NULL, cap);
        if (e != ARGIL_OK)
            return e;
        m->cap_vert = cap;
    }
    if (n_tri > m->cap_tri) {
        size_t cap = next_cap(m->cap_tri, n_tri, SIZE_MAX / (3 * sizeof(uint32_t)));
        if (mesh_tri_array_resize(&m->tri, cap) != ARGIL_OK)
            return ARGIL_ERR_NOMEM;
        m->cap_tri = cap;
    }
    return ARGIL_OK;
}

argil_err_t mesh_enable_rgb(mesh_t *m)
{
    if (m->has_rgb)
        return ARGIL_OK;
    const size_t cap = m->cap_vert > 0 ? m->cap_vert : 1;
    uint8_t *c = malloc(cap * 3);
    if (c == NULL)
        return ARGIL_ERR_NOMEM;
    for (size_t i = 0; i < 3 * m->n_vert; i++)
        c[i] = 128;
    m->rgb = c;
    m->has_rgb = 1;
    if (m->cap_vert == 0) {
        /* keep rgb's size in step with cap_vert from the first growth on */
        free(m->rgb);
        m->rgb = NULL;
    }
    return ARGIL_OK;
}

argil_err_t mesh_add_vertex_rgb(mesh_t *m, vec3_t pos_m, vec3_t normal, const uint8_t rgb[3],
                                uint32_t *index_out)
{
    if (!m->has_rgb)
        return ARGIL_ERR_STATE;
    uint32_t id;
    argil_err_t e = mesh_add_vertex(m, pos_m, normal, &id);
    if (e != ARGIL_OK)
        return e;
    m->rgb[3 * (size_t)id] = rgb[0];
    m->rgb[3 * (size_t)id + 1] = rgb[1];
    m->rgb[3 * (size_t)id + 2] = rgb[2];
    if (index_out != NULL)
        *index_out = id;
    return ARGIL_OK;
}

argil_err_t mesh_add_vertex(mesh_t *m, vec3_t pos_m, vec3_t normal, uint32_t *index_out)
{
    if (m->n_vert >= m->cap_vert) {
        if (m->n_vert >= MESH_MAX_VERTS)
            return ARGIL_ERR_FULL;
        argil_err_t e = mesh_reserve(m, m->n_vert + 1, m->n_tri);
        if (e != ARGIL_OK)
            return e;
    }
    mesh_vert_put(m->pos, m->normal, m->n_vert, pos_m, normal);
    if (m->has_rgb) {
        uint8_t *c = m->rgb + 3 * m->n_vert;
        c[0] = c[1] = c[2] = 128;
    }
    if (index_out != NULL)
        *index_out = (uint32_t)m->n_vert;
    m->n_vert++;
    return ARGIL_OK;
}

argil_err_t mesh_add_triangle(mesh_t *m, uint32_t a, uint32_t b, uint32_t c)
{
    if (a >= m->n_vert || b >= m->n_vert || c >= m->n_vert)
        return ARGIL_ERR_ARG;
    if (m->n_tri >= m->cap_tri) {
        argil_err_t e = mesh_reserve(m, m->n_vert, m->n_tri + 1);
        if (e != ARGIL_OK)
            return e;
    }
    uint32_t *t = m->tri + 3 * m->n_tri;
    t[0] = a;
    t[1] = b;
    t[2] = c;
    m->n_tri++;
    return ARGIL_OK;
}
