/* The host's density grid: the sampled field the tools edit, the springs move, the mesher reads
 * and the board's local window is cut from. Sparse (Ferley et al. §3.1): samples live in
 * GRID_B³ blocks held in a hash by block index of any sign, so the clay can grow in every
 * direction; a block wholly at rest at one density (empty space, solid interior) holds no
 * sample memory, and a block never written holds nothing at all. */
#ifndef ARGIL_GRID_H
#define ARGIL_GRID_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/model/block_table.h"
#include "shared/argil_err.h"
#include "shared/density_springs.h"
#include "shared/vec3.h"

/* Largest number of samples a grid may be created with (its nominal dims box). */
#define GRID_SAMPLES_MAX ((int64_t)1 << 30)

#define GRID_B 8                              /* samples per block edge */
#define GRID_BN (GRID_B * GRID_B * GRID_B)
#define GRID_INDEX_MAX ((int32_t)1 << 30)     /* samples live at indices in [-max, max) */

/* Painted material channels (Hua & Qin §6.3), the sampled view of the B-spline model's
 * FS_STIFF, FS_MASS, FS_DAMP and FS_RESTLEN: scales of the base material (1 = unpainted) and
 * the rest-length offset (density units, 0 = none). The numbers are the file formats' channel
 * ids (docs/files.md): never reorder them. */
typedef enum {
    GRID_MAT_STIFFNESS = 0,
    GRID_MAT_MASS = 1,
    GRID_MAT_DAMPING = 2,
    GRID_MAT_RESTLEN = 3,
    GRID_MAT_N = 4
} grid_mat_t;

/* One block of the hash (internal to grid.c). */
typedef struct {
    int32_t key[3];             /* block index: floor(sample index / GRID_B); the table's key */
    float uniform;              /* data NULL: density = rest = uniform, velocity = force = 0 */
    float *data;                /* GRID_CH_N * GRID_BN floats, channel-major, x fastest */
    float *mat;                 /* GRID_MAT_N * GRID_BN floats; NULL = every channel default */
    uint8_t *rgb;               /* 3 * GRID_BN bytes, r g b per sample; NULL = GRID_RGB_DEFAULT */
} grid_block_t;

typedef struct {
    int32_t dims[3];            /* the nominal box [0, dims) it was made with (always held) */
    float spacing_m;            /* distance between neighbouring samples */
    vec3_t origin_m;            /* model-space position of sample (0,0,0) */
    float iso;                  /* surface level, 0.5 */
    float band_m;               /* half-width of the density ramp across the surface */
    spring_material_t material;
    block_table_t blocks;       /* grid_block_t by key; entries NULL = not initialised */
    size_t data_blocks, mat_blocks; /* blocks holding sample / painted arrays */
    size_t rgb_blocks;          /* blocks holding a colour array */
    int32_t blo[3], bhi[3];     /* sample box of the blocks that hold anything (lo > hi: none) */
    bool painted[GRID_MAT_N];   /* channel written since init (absent: default everywhere) */
    uint32_t mat_writes;        /* +1 whenever a mat channel changes (the journal then looks) */
    uint32_t rgb_writes;        /* +1 whenever rgb changes (the journal then looks) */
} grid_t;

/* The colour of unpainted clay in every channel: the model's FS_R/G/B default 0.8 as a byte
 * (host/model/field.c; 0.8 x 255 = 204, a light grey). */
#define GRID_RGB_DEFAULT 204u

/* Allocates a grid with all densities 0, iso 0.5, band 4 spacings, the default material.
 * ARGIL_ERR_ARG for dims < 1, more than GRID_SAMPLES_MAX samples, or a spacing that is not
 * finite and > 0; ARGIL_ERR_NONFINITE for a non-finite origin; ARGIL_ERR_NOMEM. */
argil_err_t grid_init(grid_t *g, const int32_t dims[3], float spacing_m, vec3_t origin_m);

/* Releases the arrays; g may then be initialised again. */
void grid_free(grid_t *g);

/* The value an unpainted sample holds in channel ch: 1 (scales) or 0 (rest-length offset). */
float grid_mat_default(grid_mat_t ch);

/* True when v may be stored in channel ch: finite; mass scale > 0, stiffness and damping
 * scales >= 0 (what host/model/material.c keeps them to). */
bool grid_mat_valid(grid_mat_t ch, float v);

/* True when the two grids' samples hold the same bits in channel ch (an absent channel reads
 * as the default everywhere); false when their sample counts differ. */
bool grid_mat_equal(const grid_t *a, const grid_t *b, grid_mat_t ch);

/* One explicit density-spring step (shared/density_springs.h) over the sample box [lo, hi)
 * with the grid's material; returns what springs_step returns (the largest |acceleration|). */
float grid_springs_step(grid_t *g, const int32_t lo[3], const int32_t hi[3], float dt_s);

/* ---- Sample access: every consumer reads and writes the grid through these ---- */

/* The per-sample channels besides the painted ones. */
typedef enum {
    GRID_DENSITY = 0,
    GRID_REST = 1,
    GRID_VELOCITY = 2,
    GRID_FORCE = 3,
    GRID_CH_N = 4
} grid_ch_t;

/* The sample box [lo, hi) outside which every sample reads as empty clay (density, rest,
 * velocity and force 0, material the default); hi > lo on every axis. */
void grid_bounds(const grid_t *g, int32_t lo[3], int32_t hi[3]);

/* Number of samples in grid_bounds' box. */
size_t grid_count(const grid_t *g);

/* The part [clo, chi) of the sample box [lo, hi) the grid can hold; false when empty. */
bool grid_clip(const grid_t *g, const int32_t lo[3], const int32_t hi[3], int32_t clo[3],
               int32_t chi[3]);

/* True when sample (x,y,z) can hold a value (every index in [-GRID_INDEX_MAX, GRID_INDEX_MAX)). */
bool grid_holds(const grid_t *g, int32_t x, int32_t y, int32_t z);

/* Channel ch of sample (x,y,z); 0 where the grid holds nothing. */
float grid_get(const grid_t *g, grid_ch_t ch, int32_t x, int32_t y, int32_t z);

/* Stores v in channel ch of sample (x,y,z). ARGIL_ERR_ARG where the grid cannot hold it. */
argil_err_t grid_set(grid_t *g, grid_ch_t ch, int32_t x, int32_t y, int32_t z, float v);

/* Copies channel ch over the box [lo, lo+n) into out (x fastest); outside reads 0. */
void grid_read_box(const grid_t *g, grid_ch_t ch, const int32_t lo[3], const int32_t n[3],
                   float *out);

/* Stores the box [lo, lo+n) of channel ch from in (x fastest); samples the grid cannot hold are
 * skipped. ARGIL_ERR_NOMEM when storage could not be made. */
argil_err_t grid_write_box(grid_t *g, grid_ch_t ch, const int32_t lo[3], const int32_t n[3],
                           const float *in);

/* Painted channel ch of sample (x,y,z) (the default where unpainted or not held). */
float grid_mat_get(const grid_t *g, grid_mat_t ch, int32_t x, int32_t y, int32_t z);

/* Stores v in painted channel ch at (x,y,z) (making the channel present); bumps mat_writes only
 * when the caller does. ARGIL_ERR_ARG outside the grid or ch out of range, NOMEM. */
argil_err_t grid_mat_set(grid_t *g, grid_mat_t ch, int32_t x, int32_t y, int32_t z, float v);

/* Copies painted channel ch over [lo, lo+n) into out; the default where unpainted. */
void grid_mat_read_box(const grid_t *g, grid_mat_t ch, const int32_t lo[3], const int32_t n[3],
                       float *out);

/* Stores painted channel ch over [lo, lo+n) from in (making the channel present). ARGIL_ERR_ARG
 * for ch out of range, NOMEM. */
argil_err_t grid_mat_write_box(grid_t *g, grid_mat_t ch, const int32_t lo[3], const int32_t n[3],
                               const float *in);

/* True when channel ch has been painted (stored) anywhere. */
bool grid_mat_painted(const grid_t *g, grid_mat_t ch);

/* A newly allocated copy of channel ch over grid_bounds' box (x fastest), its box written to
 * lo / n; NULL when out of memory. The caller frees it. */
float *grid_dense_copy(const grid_t *g, grid_ch_t ch, int32_t lo[3], int32_t n[3]);

/* The same for painted channel ch (the default where unpainted). */
float *grid_dense_copy_mat(const grid_t *g, grid_mat_t ch, int32_t lo[3], int32_t n[3]);

/* Model-space position of sample lo (origin_m itself, bit for bit, when lo is 0). */
vec3_t grid_box_origin(const grid_t *g, const int32_t lo[3]);

/* Bytes the grid holds: block arrays and the hash table. */
size_t grid_bytes(const grid_t *g);

/* Frees the arrays of blocks that became uniform (one density and rest, no velocity, force or
 * paint) and shrinks the bounds to what still holds anything. */
void grid_compact(grid_t *g);

/* ---- Painted colour: r g b bytes per sample, GRID_RGB_DEFAULT where unpainted ---- */

/* Colour of sample (x,y,z) into rgb (GRID_RGB_DEFAULT in each channel where unpainted). */
void grid_rgb_get(const grid_t *g, int32_t x, int32_t y, int32_t z, uint8_t rgb[3]);

/* Stores rgb at (x,y,z); bumps rgb_writes only when the caller does. ARGIL_ERR_ARG where the
 * grid cannot hold it, NOMEM. */
argil_err_t grid_rgb_set(grid_t *g, int32_t x, int32_t y, int32_t z, const uint8_t rgb[3]);

/* Copies the colour over [lo, lo+n) into out (3 bytes per sample, x fastest). */
void grid_rgb_read_box(const grid_t *g, const int32_t lo[3], const int32_t n[3], uint8_t *out);

/* Stores the colour over [lo, lo+n) from in (3 bytes per sample); a block gets a colour array
 * only where some value is not the default. ARGIL_ERR_ARG uninitialised, NOMEM. */
argil_err_t grid_rgb_write_box(grid_t *g, const int32_t lo[3], const int32_t n[3],
                               const uint8_t *in);

/* True when some block holds a colour array (a colour off the default was stored). */
bool grid_rgb_any(const grid_t *g);

/* True when some sample's colour differs from GRID_RGB_DEFAULT. */
bool grid_rgb_painted(const grid_t *g);

/* True when the two grids have the same bounds and the same colour at every sample there. */
bool grid_rgb_equal(const grid_t *a, const grid_t *b);

/* A newly allocated copy of the colour over grid_bounds' box (3 bytes per sample), its box
 * written to lo / n; NULL when out of memory. The caller frees it. */
uint8_t *grid_dense_copy_rgb(const grid_t *g, int32_t lo[3], int32_t n[3]);

/* The density profile used everywhere: clamp(0.5 + 0.5*sd/band, 0, 1), sd positive inside. */
float grid_profile(float signed_dist_m, float band_m);

/* Sets density and rest to a solid sphere's profile, zeroes velocity and force; no effect for
 * a non-finite centre or a radius that is not finite and >= 0. */
void grid_fill_sphere(grid_t *g, vec3_t centre_m, float radius_m);

/* Trilinear density at p; samples beyond the grid count as 0 (0 for a non-finite p). */
float grid_density_at(const grid_t *g, vec3_t p_m);

/* Exact gradient (1/m) of the trilinear interpolant in the cell holding p (zero far outside). */
vec3_t grid_gradient_at(const grid_t *g, vec3_t p_m);

/* Removes material inside a sphere (Ferley's hard eraser): density and rest become
 * min(d, profile of the sphere's outside); changed samples lose their velocity. Writes the
 * index box [lo, hi) of changed samples (lo = hi = 0 when none changed). */
void grid_carve_sphere(grid_t *g, vec3_t centre_m, float radius_m, int32_t lo[3], int32_t hi[3]);

/* The corner sample index (may be negative or beyond the grid) of a win_dims window whose
 * centre is nearest p (corner 0 on any axis where p is not finite). */
void grid_window_corner(const grid_t *g, vec3_t p_m, const int32_t win_dims[3],
                        int32_t corner[3]);

/* Copies the win_dims window of densities starting at corner into out (x fastest); samples
 * outside the grid read 0. */
void grid_extract(const grid_t *g, const int32_t corner[3], const int32_t win_dims[3],
                  float *out);

/* Adds force to sample (x,y,z); false (no effect) outside the grid or for a non-finite force. */
bool grid_add_force(grid_t *g, int32_t x, int32_t y, int32_t z, float force);

/* ---- Block access, for copies of the grid kept per block (the autosave journal's) ---- */

/* What one block holds, read-only; valid until the grid next changes. */
typedef struct {
    int32_t key[3];             /* block index: sample index / GRID_B, rounded down */
    const float *density;       /* GRID_BN densities (x fastest); NULL: every one is uniform */
    float uniform;
    const float *mat;           /* GRID_MAT_N * GRID_BN painted values, channel-major; NULL:
                                 * every channel the default */
    const uint8_t *rgb;         /* 3 * GRID_BN bytes; NULL: GRID_RGB_DEFAULT */
} grid_block_view_t;

/* The index of the block holding sample index i (i / GRID_B rounded down). */
int32_t grid_block_index(int32_t i);

/* Block k into v; false when the grid holds no block there (v then reads as empty clay:
 * density 0, no arrays). */
bool grid_block_view(const grid_t *g, const int32_t k[3], grid_block_view_t *v);

/* The next block held at hash slot *slot or after it into v, *slot moved past it; false when
 * none is left. Start with *slot = 0; the order is the hash's. */
bool grid_block_next(const grid_t *g, size_t *slot, grid_block_view_t *v);

/* ---- Queries for the live mesher (host/mesh/grid_mesh.c) ---- */

/* True when every density sample of the box [lo, hi) is <= v (NaN is not), decided from the
 * blocks (a block not held reads 0, a uniform block its value): the mesher skips such blocks. */
bool grid_box_density_at_most(const grid_t *g, const int32_t lo[3], const int32_t hi[3], float v);

#endif
