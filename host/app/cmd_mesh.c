/* argil mesh: a saved model (.argil) to a mesh file for other tools, at any iso-value and
 * resolution, for the whole model or a box of it, with painted colours. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "host/app/cli_opts.h"
#include "host/app/commands.h"
#include "host/io/argil_file.h"
#include "host/io/mesh_export.h"
#include "host/mesh/mc_blocks.h"
#include "host/mesh/mesh_check.h"

/* The text of `argil mesh --help`. */
static void usage_mesh(FILE *f)
{
    fprintf(f,
            "usage: argil mesh MODEL.argil -o OUT.{ply,stl,obj} [--resolution N] [--iso V]\n"
            "                  [--region X0 Y0 Z0 X1 Y1 Z1] [--ascii] [--quiet]\n"
            "\n"
            "Extracts the model's surface with marching cubes (closed, manifold, one vertex per\n"
            "grid edge, normals from the field gradient, colours from painted material) and\n"
            "writes it atomically. The format follows OUT's extension.\n"
            "\n"
            "options:\n"
            "  -o OUT          output file: .ply (binary, vertex colours), .stl (binary), .obj\n"
            "  --resolution N  samples along the model's longest axis, 2..1024 (default: the\n"
            "                  model's own grid). With an octree B-spline or RBF form saved\n"
            "                  in the model it is evaluated directly, otherwise the grid is\n"
            "                  resampled trilinearly\n"
            "  --iso V         density level of the surface, 0 < V < 1 (default: the model's)\n"
            "  --region ...    only the box [X0,X1) x [Y0,Y1) x [Z0,Z1) of the model, in metres\n"
            "                  (model space); the piece is closed where the box cuts it\n"
            "  --ascii         ASCII PLY instead of binary\n"
            "  --quiet         no summary line\n"
            "  -h, --help      this text\n");
}

/* Resamples the model on a new grid of about n samples along its longest axis: from the octree
 * B-spline or RBF form when the model holds one (as argil fit sampled it), else trilinearly. */
static argil_err_t resample(const argil_doc_t *d, int n, float **dens, uint8_t **rgb,
                            int32_t dims[3], float *spacing, vec3_t *origin)
{
    const grid_t *g = &d->grid;
    const float ext[3] = {(float)(g->dims[0] - 1) * g->spacing_m, (float)(g->dims[1] - 1) * g->spacing_m,
                          (float)(g->dims[2] - 1) * g->spacing_m};
    float longest = ext[0] > ext[1] ? ext[0] : ext[1];
    longest = longest > ext[2] ? longest : ext[2];
    *spacing = longest > 0 ? longest / (float)(n - 1) : g->spacing_m;
    *origin = g->origin_m;
    size_t total = 1;
    for (int a = 0; a < 3; a++) {
        dims[a] = (int32_t)(ext[a] / *spacing + 1.5f);
        if (dims[a] < 1)
            dims[a] = 1;
        total *= (size_t)dims[a];
    }
    *dens = malloc(total * sizeof(float));
    *rgb = d->rgb != NULL ? malloc(3 * total) : NULL;
    if (*dens == NULL || (d->rgb != NULL && *rgb == NULL))
        return ARGIL_ERR_NOMEM;
    size_t i = 0;
    for (int32_t z = 0; z < dims[2]; z++)
        for (int32_t y = 0; y < dims[1]; y++)
            for (int32_t x = 0; x < dims[0]; x++, i++) {
                const vec3_t p = vec3(origin->x + *spacing * (float)x, origin->y + *spacing * (float)y,
                                      origin->z + *spacing * (float)z);
                if (d->has_octree && d->octree.kind == OCTFIT_INTENSITY)
                    (*dens)[i] = fminf(1.0f, fmaxf(0.0f, g->iso + octfit_eval(&d->octree, p)));
                else if (d->has_octree)
                    (*dens)[i] = grid_profile(octfit_eval(&d->octree, p), g->band_m);
                else if (d->has_rbf)
                    (*dens)[i] = grid_profile(rbf_eval(&d->rbf, p), g->band_m);
                else
                    (*dens)[i] = grid_density_at(g, p);
                if (*rgb != NULL) {
                    int32_t s[3] = {(int32_t)((p.x - g->origin_m.x) / g->spacing_m + 0.5f),
                                    (int32_t)((p.y - g->origin_m.y) / g->spacing_m + 0.5f),
                                    (int32_t)((p.z - g->origin_m.z) / g->spacing_m + 0.5f)};
                    for (int a = 0; a < 3; a++)
                        s[a] = s[a] < 0 ? 0 : (s[a] >= g->dims[a] ? g->dims[a] - 1 : s[a]);
                    memcpy(*rgb + 3 * i,
                           d->rgb + 3 * ((size_t)s[0] + (size_t)g->dims[0] * ((size_t)s[1] + (size_t)g->dims[1] * (size_t)s[2])),
                           3);
                }
            }
    return ARGIL_OK;
}

/* What argil mesh's command line asks for. */
typedef struct {
    const char *in, *out;
    double res, iso;                /* 0, -1: the model's own grid and iso */
    double region[6];               /* --region's corners, metres (NAN: the whole model) */
    bool ascii, quiet;
} mesh_opts_t;

/* argil mesh's command line (cli_parse). */
static const cli_flag_t MESH_FLAGS[] = {
    {"--ascii", offsetof(mesh_opts_t, ascii), true},
    {"--quiet", offsetof(mesh_opts_t, quiet), true},
};
static const cli_number_t MESH_NUMBERS[] = {
    {"--resolution", 2, 1024, offsetof(mesh_opts_t, res), 1, false},
    {"--iso", 1e-6, 1 - 1e-6, offsetof(mesh_opts_t, iso), 1, false},
    {"--region", -1e6, 1e6, offsetof(mesh_opts_t, region), 6, false},
};
static const cli_cmd_t MESH_CLI = {
    .name = "mesh", .usage = usage_mesh,
    .flags = MESH_FLAGS, .n_flags = 2, .numbers = MESH_NUMBERS, .n_numbers = 3,
    .out_needs = "a value", .out = offsetof(mesh_opts_t, out),
    .inputs = true, .input = offsetof(mesh_opts_t, in),
};

/* argil mesh MODEL.argil -o OUT: the model's surface into a mesh file. */
argil_err_t cmd_mesh(int argc, char **argv, int *exit_status)
{
    mesh_opts_t mo = {NULL, NULL, 0, -1, {NAN, NAN, NAN, NAN, NAN, NAN}, false, false};
    bool done;
    const argil_err_t pe = cli_parse(&MESH_CLI, &mo, argc, argv, &done, exit_status);
    if (done)
        return pe;
    const char *in = mo.in, *out = mo.out;
    const double res = mo.res, iso = mo.iso, *region = mo.region;
    export_format_t fmt;
    if (in == NULL || out == NULL) {
        fprintf(stderr, "argil mesh: needs MODEL.argil and -o OUT (see --help)\n");
        return cmd_end(exit_status, 2, ARGIL_ERR_ARG);
    }
    if (!export_format_from_path(out, &fmt)) {
        fprintf(stderr, "argil mesh: %s: output must end in .ply, .stl or .obj\n", out);
        return cmd_end(exit_status, 2, ARGIL_ERR_ARG);
    }
    if (mo.ascii && fmt == EXPORT_PLY_BINARY)
        fmt = EXPORT_PLY_ASCII;
    argil_doc_t d;
    char err[1024];
    argil_err_t e = argil_file_err_argil(argil_file_read(in, &d, err, sizeof(err)));
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil mesh: %s\n", err);
        return cmd_end(exit_status, 1, e);
    }
    /* A loaded model's samples fill the file's box: bounds start at 0 and rgb matches them. */
    int32_t blo[3], dims[3];
    float *own_d = grid_dense_copy(&d.grid, GRID_DENSITY, blo, dims), *dens = own_d;
    float spacing = d.grid.spacing_m;
    uint8_t *rgb = d.rgb;
    vec3_t origin = grid_box_origin(&d.grid, blo);
    uint8_t *own_c = NULL;
    e = own_d != NULL ? ARGIL_OK : ARGIL_ERR_NOMEM;
    if (e == ARGIL_OK && res > 0) {
        free(own_d);
        own_d = NULL;
        e = resample(&d, (int)res, &own_d, &own_c, dims, &spacing, &origin);
        dens = own_d;
        rgb = own_c;
    }
    int32_t lo[3] = {0, 0, 0}, hi[3] = {dims[0], dims[1], dims[2]};
    if (e == ARGIL_OK && !isnan(region[0])) {
        const float o3[3] = {origin.x, origin.y, origin.z};
        for (int a = 0; a < 3; a++) {
            double l = (region[a] - o3[a]) / spacing, h = (region[3 + a] - o3[a]) / spacing;
            lo[a] = l < 0 ? 0 : (l > dims[a] ? dims[a] : (int32_t)(l + 0.999));
            hi[a] = h < 0 ? 0 : (h > dims[a] ? dims[a] : (int32_t)h + 1);
            if (hi[a] > dims[a])
                hi[a] = dims[a];
            if (lo[a] >= hi[a]) {
                fprintf(stderr, "argil mesh: --region misses the model on axis %c\n", 'x' + a);
                argil_doc_free(&d);
                free(own_d);
                free(own_c);
                return cmd_end(exit_status, 2, ARGIL_ERR_ARG);
            }
        }
    }
    mesh_t m;
    mesh_init(&m);
    if (e == ARGIL_OK)
        e = mc_extract_region(dens, rgb, dims, spacing, origin, iso > 0 ? (float)iso : d.grid.iso,
                              lo, hi, &m);
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil mesh: %s: meshing failed (%s)\n", in,
                e == ARGIL_ERR_NOMEM ? "out of memory" : "bad model values");
    } else if (m.n_tri == 0) {
        fprintf(stderr, "argil mesh: %s: no surface at iso %g in that region\n", in,
                iso > 0 ? iso : (double)d.grid.iso);
        e = ARGIL_ERR_EMPTY;
    } else if ((e = mesh_export(out, &m, fmt, err, sizeof(err))) != ARGIL_OK) {
        fprintf(stderr, "argil mesh: %s\n", err);
    } else {
        if (!mo.quiet) {
            size_t boundary = 0, nonman = 0;
            const bool closed = mesh_watertight(&m, &boundary, &nonman);
            printf("argil mesh: %s: %zu triangles, %zu vertices, %s, volume %.3f cm3, grid "
                   "%dx%dx%d\n", out, m.n_tri, m.n_vert,
                   closed ? "watertight" : "NOT watertight", mesh_volume_m3(&m) * 1e6,
                   hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
        }
    }
    mesh_free(&m);
    free(own_d);
    free(own_c);
    argil_doc_free(&d);
    return cmd_end(exit_status, e == ARGIL_OK ? 0 : 1, e);
}
