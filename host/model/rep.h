/* The seam every sculptable representation implements (DESIGN.md "Representations"): what the
 * board's window is cut from, where its impulses go, how the clay moves and is tooled, what
 * changed, what is drawn and what is saved. The peer, the session and the files hold a rep_t and
 * never know which representation is behind it; the board only ever sees the density window. */
#ifndef ARGIL_REP_H
#define ARGIL_REP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/mesh/mesh.h"
#include "host/model/grid.h"
#include "host/model/host_tool.h"
#include "shared/argil_err.h"
#include "shared/density_springs.h"
#include "shared/vec3.h"

/* A box of lattice sample indices [lo, hi); empty when lo >= hi on any axis. */
typedef struct {
    int32_t lo[3], hi[3];
} rep_box_t;

/* What one call changed. */
typedef struct {
    rep_box_t box;                    /* samples whose density, material or colour changed: what
                                       * is re-meshed and journaled */
    bool felt;                        /* a density or stiffness a board's window is cut from
                                       * changed in box: the board needs a new window */
} rep_change_t;

/* The lattice the board's windows and impulses are indexed on, and the material it feels. */
typedef struct {
    vec3_t origin_m;                  /* model-space position of sample (0, 0, 0) */
    float spacing_m;                  /* distance between neighbouring samples */
    float iso;                        /* surface level of the density */
    float band_m;                     /* half-width of the density ramp across the surface */
    spring_material_t material;       /* base material of the window's density springs */
} rep_lattice_t;

typedef enum { REP_MAT_STIFFNESS = 0, REP_MAT_MASS } rep_material_t;

typedef struct {
    /* The lattice and base material now (changes only through the entries below). */
    void (*lattice)(const void *st, rep_lattice_t *out);
    /* The corner sample (may lie beyond the clay) of a dims window whose centre is nearest
     * centre_m; corner 0 on an axis where centre_m is not finite. */
    void (*window_corner)(const void *st, vec3_t centre_m, const int32_t dims[3],
                          int32_t corner[3]);
    /* Fills density[0..dims³) (x fastest, 0 beyond the clay) and returns true when it also
     * filled stiffness_n_per_m[0..dims³) with each node's spring stiffness (painted clay); false
     * leaves stiffness_n_per_m unspecified: every node has the lattice's stiffness. */
    bool (*window_samples)(const void *st, const int32_t corner[3], const int32_t dims[3],
                           float *density, float *stiffness_n_per_m);
    /* Adds a board impulse as the force force_per_s (impulse / the next step's dt) on the node
     * at sample node[]; it acts over the next step. ARGIL_ERR_ARG outside the clay's lattice,
     * ARGIL_ERR_NONFINITE for a force that is not finite; nothing changes then. */
    argil_err_t (*add_node_force)(void *st, const int32_t node[3], float force_per_s);
    /* One step of dt_s of the clay's dynamics within region (NULL: no board window this period;
     * only forces left over are dropped), taking the forces there; regions earlier steps left
     * while still moving settle on. ARGIL_ERR_* of the solve (the clay keeps its state). */
    argil_err_t (*step)(void *st, const rep_box_t *region, float dt_s, rep_change_t *changed);
    /* True when apply_tool accepts this host tool setting. */
    bool (*tool_supported)(const void *st, const host_tool_t *tool);
    /* Applies the host tool once along pts_m[0..n_pts) (n_pts >= 1, the last is the stylus) with
     * the board tool's radius and axis, its per-second strength acting for dt_s. ARGIL_ERR_ARG for
     * a setting it does not take or bad values, ARGIL_ERR_NONFINITE, ARGIL_ERR_NOMEM. */
    argil_err_t (*apply_tool)(void *st, const host_tool_t *tool, float radius_m, vec3_t axis,
                              const vec3_t *pts_m, size_t n_pts, float dt_s,
                              rep_change_t *changed);
    /* Paints the stiffness or mass scale toward scale within radius_m of centre_m (linear
     * falloff). ARGIL_ERR_STATE when its material is uniform, ARGIL_ERR_ARG for bad values. */
    argil_err_t (*paint)(void *st, rep_material_t ch, vec3_t centre_m, float radius_m,
                         float scale, rep_change_t *changed);
    /* The painted scale of ch at x_m (1 = the base material, everywhere when uniform). */
    float (*material_at)(const void *st, rep_material_t ch, vec3_t x_m);
    /* Makes its degrees of freedom finer without changing the shape; max_change (may be NULL)
     * the largest |density change| of a sample. ARGIL_ERR_STATE when it cannot (nothing
     * changed), ARGIL_ERR_NOMEM. */
    argil_err_t (*refine)(void *st, float *max_change, rep_change_t *changed);
    /* Lattice samples per degree of freedom along an axis now (0: its samples are its state). */
    int32_t (*samples_per_dof)(const void *st);
    /* After its state in box was set back (undo, redo): in-flight motion stops and what it
     * shows follows; ARGIL_ERR_NOMEM. */
    argil_err_t (*restored)(void *st, const rep_box_t *box, rep_change_t *changed);
    /* Fills out (emptied first) with the surface to draw: a closed mesh, or a point set as
     * vertices with normals and no triangles. ARGIL_ERR_NOMEM. */
    argil_err_t (*surface)(const void *st, mesh_t *out);
    /* The sample grid its .argil section, journal records and undo diffs are written from and
     * recovered into (NULL: it keeps none, and is not saved). */
    grid_t *(*samples)(void *st);
    /* Releases what the representation allocated (the state's own storage stays the owner's). */
    void (*free)(void *st);
} rep_ops_t;

/* One sculptable representation: its entries and its state. */
typedef struct {
    const rep_ops_t *ops;
    void *st;
} rep_t;

#endif
