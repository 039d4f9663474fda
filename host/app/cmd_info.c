/* argil info: what a file holds (model, mesh, point cloud or volume), or why it cannot be read. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "host/app/commands.h"
#include "host/io/argil_file.h"
#include "host/io/mesh_import.h"
#include "host/io/volume.h"
#include "host/mesh/mesh_check.h"

/* The text of `argil info --help`. */
static void usage_info(FILE *f)
{
    fprintf(f, "usage: argil info FILE\n\n"
               "Prints what FILE holds: a model (.argil: grid, iso, material, tool, RBF or octree\n"
               "B-spline form), a mesh or point cloud (.ply .stl .obj .xyz .txt .pts: counts,\n"
               "bounds, normals, colours, watertightness, volume) or a volume (.nrrd .nhdr: size,\n"
               "spacing, range).\n"
               "A file that cannot be read gives one line naming the file, where and why.\n");
}

/* Whether path p ends in the extension e, in any case. */
static bool has_ext(const char *p, const char *e)
{
    const char *dot = strrchr(p, '.');
    return dot != NULL && strcasecmp(dot, e) == 0;
}

/* One line per painted material channel: how many samples differ from the base material, the
 * range of their values and the sample box they lie in (docs/files.md, section MTLS). */
static void print_painted(const grid_t *g)
{
    static const char *const names[GRID_MAT_N] = {"stiffness", "mass", "damping", "rest length"};
    const size_t n = grid_count(g);
    bool any = false;
    for (int ch = 0; ch < GRID_MAT_N; ch++) {
        if (!grid_mat_painted(g, (grid_mat_t)ch))
            continue;
        int32_t o[3], nd[3];
        float *m = grid_dense_copy_mat(g, (grid_mat_t)ch, o, nd);
        if (m == NULL) {
            printf("  painted   %s: out of memory to read it\n", names[ch]);
            continue;
        }
        const float def = grid_mat_default((grid_mat_t)ch);
        size_t count = 0;
        float lo = INFINITY, hi = -INFINITY;
        int32_t b0[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, b1[3] = {-1, -1, -1};
        for (size_t i = 0; i < n; i++) {
            if (memcmp(&m[i], &def, sizeof(float)) == 0)
                continue;
            count++;
            lo = fminf(lo, m[i]);
            hi = fmaxf(hi, m[i]);
            const int32_t s[3] = {o[0] + (int32_t)(i % (size_t)nd[0]),
                                  o[1] + (int32_t)(i / (size_t)nd[0] % (size_t)nd[1]),
                                  o[2] + (int32_t)(i / ((size_t)nd[0] * (size_t)nd[1]))};
            for (int a = 0; a < 3; a++) {
                b0[a] = s[a] < b0[a] ? s[a] : b0[a];
                b1[a] = s[a] > b1[a] ? s[a] : b1[a];
            }
        }
        free(m);
        if (count == 0)
            continue;
        any = true;
        printf("  painted   %s %s %.6g .. %.6g on %zu samples, box (%d, %d, %d) .. (%d, %d, %d)\n",
               names[ch], ch == GRID_MAT_RESTLEN ? "offset" : "scale", (double)lo, (double)hi,
               count, b0[0], b0[1], b0[2], b1[0], b1[1], b1[2]);
    }
    if (!any)
        printf("  painted   nothing (the base material everywhere)\n");
}

/* The painted colour (section COLR): how many samples differ from the unpainted clay's grey,
 * the most common such colour, and the sample box they lie in. */
static void print_colour(const grid_t *g, const uint8_t *rgb)
{
    const size_t n = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
    size_t count = 0, best_n = 0;
    uint8_t best[3] = {0, 0, 0};
    int32_t b0[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, b1[3] = {-1, -1, -1};
    /* The most common colour by a majority vote (Boyer-Moore), then its exact count. */
    size_t votes = 0;
    for (size_t i = 0; i < n; i++) {
        const uint8_t *c = rgb + 3 * i;
        if (c[0] == GRID_RGB_DEFAULT && c[1] == GRID_RGB_DEFAULT && c[2] == GRID_RGB_DEFAULT)
            continue;
        count++;
        if (votes == 0)
            memcpy(best, c, 3);
        votes = memcmp(best, c, 3) == 0 ? votes + 1 : votes - 1;
        const int32_t s[3] = {(int32_t)(i % (size_t)g->dims[0]),
                              (int32_t)(i / (size_t)g->dims[0] % (size_t)g->dims[1]),
                              (int32_t)(i / ((size_t)g->dims[0] * (size_t)g->dims[1]))};
        for (int a = 0; a < 3; a++) {
            b0[a] = s[a] < b0[a] ? s[a] : b0[a];
            b1[a] = s[a] > b1[a] ? s[a] : b1[a];
        }
    }
    for (size_t i = 0; i < n && count > 0; i++)
        best_n += memcmp(best, rgb + 3 * i, 3) == 0;
    if (count == 0) {
        printf("  colour    unpainted (every sample the clay's %u %u %u)\n", GRID_RGB_DEFAULT,
               GRID_RGB_DEFAULT, GRID_RGB_DEFAULT);
        return;
    }
    printf("  colour    painted on %zu samples (%u %u %u on %zu of them), box (%d, %d, %d) .. "
           "(%d, %d, %d); unpainted %u %u %u\n",
           count, best[0], best[1], best[2], best_n, b0[0], b0[1], b0[2], b1[0], b1[1], b1[2],
           GRID_RGB_DEFAULT, GRID_RGB_DEFAULT, GRID_RGB_DEFAULT);
}

argil_err_t cmd_read_mesh(const char *path, mesh_t *m, bool *normals, float lo[3], float hi[3],
                          char *err, size_t err_len)
{
    mesh_init(m);
    *normals = false;
    const argil_err_t e = import_err_argil(mesh_import(path, m, normals, err, err_len));
    if (e != ARGIL_OK) {
        mesh_free(m);
        return e;
    }
    for (int a = 0; a < 3; a++) {
        lo[a] = INFINITY;
        hi[a] = -INFINITY;
        for (size_t i = 0; i < m->n_vert; i++) {
            lo[a] = fminf(lo[a], m->pos[3 * i + (size_t)a]);
            hi[a] = fmaxf(hi[a], m->pos[3 * i + (size_t)a]);
        }
    }
    return ARGIL_OK;
}

void cmd_volume_range(const volume_t *v, float *lo, float *hi)
{
    const size_t n = (size_t)v->dims[0] * (size_t)v->dims[1] * (size_t)v->dims[2];
    *lo = INFINITY;
    *hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        *lo = fminf(*lo, v->value[i]);
        *hi = fmaxf(*hi, v->value[i]);
    }
}

/* Prints what the model file at path holds: grid, surface, material, paint, tool, fitted form;
 * why it cannot be read into err. */
static argil_err_t info_model(const char *path, char *err, size_t err_len)
{
    argil_doc_t d;
    const argil_err_t e = argil_file_err_argil(argil_file_read(path, &d, err, err_len));
    if (e != ARGIL_OK)
        return e;
    const grid_t *g = &d.grid;
    printf("%s: argil model, format version %u\n", path, d.file_version);
    printf("  grid      %d x %d x %d samples, spacing %.4g mm, origin (%.4g, %.4g, %.4g) mm\n",
           g->dims[0], g->dims[1], g->dims[2], g->spacing_m * 1e3, g->origin_m.x * 1e3,
           g->origin_m.y * 1e3, g->origin_m.z * 1e3);
    printf("  surface   iso %.3g, band %.4g mm, colours %s\n", g->iso, g->band_m * 1e3,
           d.rgb != NULL ? "painted" : "none");
    printf("  material  mass %g, stiffness %g, coupling %g, damping %g, plastic %g Hz\n",
           g->material.node_mass, g->material.stiffness, g->material.coupling,
           g->material.damping, g->material.plastic_rate_hz);
    print_painted(g);
    if (d.rgb != NULL)
        print_colour(g, d.rgb);
    printf("  tool      kind %u, radius %.4g mm, strength %.3g\n", d.tool.tool_kind,
           d.tool.radius_m * 1e3, d.tool.strength);
    if (d.has_rbf)
        printf("  rbf       %u centres (%u bytes), fit error rms %.4g mm, max %.4g mm\n",
               d.rbf.n, 28 + 16 * d.rbf.n, d.rbf.rms_err_m * 1e3, d.rbf.max_err_m * 1e3);
    if (d.has_octree) {
        const octfit_model_t *o = &d.octree;
        const unsigned long long bytes =
            40ull + 4ull * o->n_nodes + 4ull * OCTFIT_NCOEF * o->n_leaves;
        printf("  octree    %u nodes, %u leaves, depth %u, cube %.4g mm at (%.4g, %.4g, %.4g) mm "
               "(%llu bytes), ", o->n_nodes, o->n_leaves, o->depth, o->size_m * 1e3,
               o->origin_m[0] * 1e3, o->origin_m[1] * 1e3, o->origin_m[2] * 1e3, bytes);
        if (o->kind == OCTFIT_INTENSITY)
            printf("intensity error rms %.4g, max %.4g (of the range)\n", o->rms_err,
                   o->max_err);
        else
            printf("fit error rms %.4g mm, max %.4g mm\n", o->rms_err * 1e3, o->max_err * 1e3);
    }
    argil_doc_free(&d);
    return ARGIL_OK;
}

/* Prints what the volume file at path holds: size, spacing and the range of its values; why it
 * cannot be read into err. */
static argil_err_t info_volume(const char *path, char *err, size_t err_len)
{
    volume_t v;
    const argil_err_t e = volume_err_argil(volume_read_nrrd(path, &v, err, err_len));
    if (e != ARGIL_OK)
        return e;
    float lo, hi;
    cmd_volume_range(&v, &lo, &hi);
    printf("%s: volume %d x %d x %d, spacing %g %g %g, values %g .. %g\n", path, v.dims[0],
           v.dims[1], v.dims[2], v.spacing_m[0], v.spacing_m[1], v.spacing_m[2], lo, hi);
    volume_free(&v);
    return ARGIL_OK;
}

/* Prints what the mesh or point cloud at path holds: counts, closedness, bounds, attributes;
 * why it cannot be read into err. */
static argil_err_t info_mesh(const char *path, char *err, size_t err_len)
{
    mesh_t m;
    bool normals;
    float lo[3], hi[3];
    const argil_err_t e = cmd_read_mesh(path, &m, &normals, lo, hi, err, err_len);
    if (e != ARGIL_OK)
        return e;
    if (m.n_tri > 0) {
        size_t boundary = 0, nonman = 0;
        const bool closed = mesh_watertight(&m, &boundary, &nonman);
        printf("%s: mesh, %zu vertices, %zu triangles, %s (%zu boundary, %zu non-manifold edges), "
               "volume %.6g\n", path, m.n_vert, m.n_tri, closed ? "watertight" : "open", boundary,
               nonman, mesh_volume_m3(&m));
    } else {
        printf("%s: point cloud, %zu points\n", path, m.n_vert);
    }
    printf("  bounds    (%g, %g, %g) .. (%g, %g, %g)\n", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    printf("  normals   %s, colours %s\n", normals ? "yes" : "no", m.has_rgb ? "yes" : "no");
    mesh_free(&m);
    return ARGIL_OK;
}

/* argil info FILE: what FILE holds, by its extension; a file that cannot be read is exit 1. */
argil_err_t cmd_info(int argc, char **argv, int *exit_status)
{
    if (argc != 1 || strcmp(argv[0], "-h") == 0 || strcmp(argv[0], "--help") == 0) {
        usage_info(argc == 1 ? stdout : stderr);
        return argc == 1 ? cmd_end(exit_status, 0, ARGIL_OK)
                         : cmd_end(exit_status, 2, ARGIL_ERR_ARG);
    }
    const char *path = argv[0];
    char err[1024];
    argil_err_t e;
    if (has_ext(path, ".argil"))
        e = info_model(path, err, sizeof(err));
    else if (has_ext(path, ".nrrd") || has_ext(path, ".nhdr"))
        e = info_volume(path, err, sizeof(err));
    else
        e = info_mesh(path, err, sizeof(err));
    if (e != ARGIL_OK)
        fprintf(stderr, "argil info: %s\n", err);
    return cmd_end(exit_status, e == ARGIL_OK ? 0 : 1, e);
}
