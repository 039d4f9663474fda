/* PLY / STL / OBJ writers. Binary fields are encoded byte by byte (little-endian). */
#include "host/io/mesh_export.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "host/io/io_util.h"
#include "shared/wire.h"

typedef struct {
    const mesh_t *m;
    export_format_t fmt;
} export_ctx_t;

bool export_format_from_path(const char *path, export_format_t *fmt)
{
    const char *dot = path != NULL ? strrchr(path, '.') : NULL;
    if (dot == NULL)
        return false;
    if (strcasecmp(dot, ".ply") == 0)
        *fmt = EXPORT_PLY_BINARY;
    else if (strcasecmp(dot, ".stl") == 0)
        *fmt = EXPORT_STL;
    else if (strcasecmp(dot, ".obj") == 0)
        *fmt = EXPORT_OBJ;
    else
        return false;
    return true;
}

static vec3_t ex_pos(const mesh_t *m, uint32_t i)
{
    return vec3(m->pos[3 * (size_t)i], m->pos[3 * (size_t)i + 1], m->pos[3 * (size_t)i + 2]);
}

static vec3_t ex_normal(const mesh_t *m, size_t i)
{
    if (m->normal == NULL)
        return vec3(0, 0, 0);
    return vec3(m->normal[3 * i], m->normal[3 * i + 1], m->normal[3 * i + 2]);
}

static const char *ex_ply(FILE *f, const mesh_t *m, bool ascii)
{
    const bool rgb = m->has_rgb && m->rgb != NULL;
    if (fprintf(f, "ply\nformat %s 1.0\ncomment argil mesh, model space, metres\n"
                   "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n"
                   "property float nx\nproperty float ny\nproperty float nz\n%s"
                   "element face %zu\nproperty list uchar int vertex_indices\nend_header\n",
                ascii ? "ascii" : "binary_little_endian", m->n_vert,
                rgb ? "property uchar red\nproperty uchar green\nproperty uchar blue\n" : "",
                m->n_tri) < 0)
        return "fprintf";
    uint8_t rec[27];
    for (size_t v = 0; v < m->n_vert; v++) {
        const vec3_t p = ex_pos(m, (uint32_t)v), n = ex_normal(m, v);
        if (ascii) {
            if (fprintf(f, "%.9g %.9g %.9g %.6g %.6g %.6g", (double)p.x, (double)p.y, (double)p.z,
                        (double)n.x, (double)n.y, (double)n.z) < 0)
                return "fprintf";
            if (rgb && fprintf(f, " %u %u %u", m->rgb[3 * v], m->rgb[3 * v + 1],
                               m->rgb[3 * v + 2]) < 0)
                return "fprintf";
            if (fputc('\n', f) == EOF)
                return "fputc";
        } else {
            const float val[6] = {p.x, p.y, p.z, n.x, n.y, n.z};
            for (int k = 0; k < 6; k++)
                le_put_f32(rec + 4 * k, val[k]);
            size_t len = 24;
            if (rgb) {
                memcpy(rec + 24, m->rgb + 3 * v, 3);
                len = 27;
            }
            if (fwrite(rec, 1, len, f) != len)
                return "fwrite";
        }
    }
    for (size_t t = 0; t < m->n_tri; t++) {
        const uint32_t *i = m->tri + 3 * t;
        if (ascii) {
            if (fprintf(f, "3 %u %u %u\n", i[0], i[1], i[2]) < 0)
                return "fprintf";
        } else {
            rec[0] = 3;
            for (int k = 0; k < 3; k++)
                le_put_u32(rec + 1 + 4 * k, i[k]);
            if (fwrite(rec, 1, 13, f) != 13)
                return "fwrite";
        }
    }
    return NULL;
}

static const char *ex_stl(FILE *f, const mesh_t *m)
{
    uint8_t head[84] = {0};
    const char title[] = "argil mesh, binary STL, model space in metres";
    memcpy(head, title, sizeof(title) - 1);
    le_put_u32(head + 80, (uint32_t)m->n_tri);
    if (fwrite(head, 1, 84, f) != 84)
        return "fwrite";
    uint8_t rec[50];
    for (size_t t = 0; t < m->n_tri; t++) {
        const uint32_t *i = m->tri + 3 * t;
        const vec3_t a = ex_pos(m, i[0]), b = ex_pos(m, i[1]), c = ex_pos(m, i[2]);
        vec3_t n = vec3_cross(vec3_sub(b, a), vec3_sub(c, a));
        const float len = vec3_norm(n);
        n = len > 0.0f ? vec3_scale(n, 1.0f / len) : vec3(0, 0, 0);
        const vec3_t v[4] = {n, a, b, c};
        for (int k = 0; k < 4; k++) {
            le_put_f32(rec + 12 * k, v[k].x);
            le_put_f32(rec + 12 * k + 4, v[k].y);
            le_put_f32(rec + 12 * k + 8, v[k].z);
        }
        rec[48] = rec[49] = 0;
        if (fwrite(rec, 1, 50, f) != 50)
            return "fwrite";
    }
    return NULL;
}

static const char *ex_obj(FILE *f, const mesh_t *m)
{
    const bool rgb = m->has_rgb && m->rgb != NULL;
    if (fprintf(f, "# argil mesh, model space, metres: %zu vertices, %zu triangles\n", m->n_vert,
                m->n_tri) < 0)
        return "fprintf";
    for (size_t v = 0; v < m->n_vert; v++) {
        const vec3_t p = ex_pos(m, (uint32_t)v);
        if (fprintf(f, "v %.9g %.9g %.9g", (double)p.x, (double)p.y, (double)p.z) < 0)
            return "fprintf";
        if (rgb && fprintf(f, " %.4f %.4f %.4f", m->rgb[3 * v] / 255.0, m->rgb[3 * v + 1] / 255.0,
                           m->rgb[3 * v + 2] / 255.0) < 0)
            return "fprintf";
        if (fputc('\n', f) == EOF)
            return "fputc";
    }
    for (size_t v = 0; v < m->n_vert; v++) {
        const vec3_t n = ex_normal(m, v);
        if (fprintf(f, "vn %.6g %.6g %.6g\n", (double)n.x, (double)n.y, (double)n.z) < 0)
            return "fprintf";
    }
    for (size_t t = 0; t < m->n_tri; t++) {
        const uint32_t *i = m->tri + 3 * t;
        if (fprintf(f, "f %u//%u %u//%u %u//%u\n", i[0] + 1, i[0] + 1, i[1] + 1, i[1] + 1,
                    i[2] + 1, i[2] + 1) < 0)
            return "fprintf";
    }
    return NULL;
}

static const char *ex_write(FILE *f, const void *ctx)
{
    const export_ctx_t *c = ctx;
    switch (c->fmt) {
    case EXPORT_PLY_BINARY: return ex_ply(f, c->m, false);
    case EXPORT_PLY_ASCII: return ex_ply(f, c->m, true);
    case EXPORT_STL: return ex_stl(f, c->m);
    default: return ex_obj(f, c->m);
    }
}

argil_err_t mesh_export(const char *path, const mesh_t *m, export_format_t fmt, char *err,
                        size_t err_len)
{
    if (path == NULL || m == NULL || (unsigned)fmt > EXPORT_OBJ) {
        io_err(err, err_len, "mesh_export: no path, no mesh or unknown format");
        return ARGIL_ERR_ARG;
    }
    if (m->n_vert > (size_t)INT32_MAX || (fmt == EXPORT_STL && m->n_tri > (size_t)UINT32_MAX)) {
        io_err(err, err_len, "mesh_export: %s: %zu vertices / %zu triangles exceed the format",
               path, m->n_vert, m->n_tri);
        return ARGIL_ERR_ARG;
    }
    if ((m->n_vert > 0 && m->pos == NULL) || (m->n_tri > 0 && m->tri == NULL)) {
        io_err(err, err_len, "mesh_export: %s: mesh arrays missing", path);
        return ARGIL_ERR_ARG;
    }
    for (size_t i = 0; i < 3 * m->n_vert; i++)
        if (!isfinite(m->pos[i]) || (m->normal != NULL && !isfinite(m->normal[i]))) {
            io_err(err, err_len, "mesh_export: %s: vertex %zu is not finite", path, i / 3);
            return ARGIL_ERR_NONFINITE;
        }
    for (size_t i = 0; i < 3 * m->n_tri; i++)
        if (m->tri[i] >= m->n_vert) {
            io_err(err, err_len, "mesh_export: %s: triangle %zu names vertex %u of %zu", path,
                   i / 3, (unsigned)m->tri[i], m->n_vert);
            return ARGIL_ERR_ARG;
        }
    const export_ctx_t c = {m, fmt};
    return io_write_atomic(path, ex_write, &c, "mesh_export", err, err_len);
}
