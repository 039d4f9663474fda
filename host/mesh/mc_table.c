/* The marching-cubes case table, derived at run time from the cube's faces: on each face the
 * crossed edges are joined by segments (a saddle face always separates its inside corners), the
 * segments chain into closed loops around the cube, and each loop becomes a triangle fan. Since a
 * face's segments depend only on its four corners, neighbouring cells agree and the surface is
 * closed and edge-manifold. Shared by the whole-grid and the block mesher. */
#include "host/mesh/mc_table.h"

#include <stdbool.h>

static int mc_edge_id(int axis, int bit_u, int bit_v)
{
    return axis * 4 + bit_u + 2 * bit_v;
}

/* The edge joining two corners that differ in one bit. */
static int mc_edge_between(int c0, int c1)
{
    const int d = c0 ^ c1;
    const int a = d == 1 ? 0 : (d == 2 ? 1 : 2);
    const int base = c0 & c1;
    return mc_edge_id(a, (base >> ((a + 1) % 3)) & 1, (base >> ((a + 2) % 3)) & 1);
}

/* True when two distinct cube edges lie on a common face. */
static bool mc_edges_share_face(int e0, int e1)
{
    int f[2][2];
    const int e[2] = {e0, e1};
    for (int k = 0; k < 2; k++) {
        const int a = e[k] / 4;
        f[k][0] = ((a + 1) % 3) * 2 + (e[k] & 1);
        f[k][1] = ((a + 2) % 3) * 2 + ((e[k] >> 1) & 1);
    }
    return f[0][0] == f[1][0] || f[0][0] == f[1][1] || f[0][1] == f[1][0] || f[0][1] == f[1][1];
}

/* Links every crossed edge to the next one around its loop. On each face, walked CCW as seen
 * from outside the cube, an "entry" edge (outside corner → inside corner) is joined to the next
 * "exit" edge (inside → outside): each run of inside corners is cut off on its own, which splits
 * a saddle face between its inside corners. The link entry → exit keeps the outside corners on
 * the left, so every crossed edge gets exactly one successor (it is an entry on one of its two
 * faces and an exit on the other). */
static void mc_link_face_segments(unsigned mask, int next[MC_EDGES])
{
    static const int cu_ccw[4] = {0, 1, 1, 0}, cv_ccw[4] = {0, 0, 1, 1};
    for (int f = 0; f < 6; f++) {
        const int a = f / 2, side = f & 1, u = (a + 1) % 3, v = (a + 2) % 3;
        int q[4];
        bool in[4];
        for (int k = 0; k < 4; k++) {
            /* (u, v) is right-handed about +axis: that order is CCW seen from +axis; reversed
             * for the face at side 0, whose outside is -axis. */
            const int cu = side ? cu_ccw[k] : cv_ccw[k];
            const int cv = side ? cv_ccw[k] : cu_ccw[k];
            q[k] = (side << a) | (cu << u) | (cv << v);
            in[k] = ((mask >> q[k]) & 1u) != 0;
        }
        for (int k = 0; k < 4; k++) {
            if (in[k] || !in[(k + 1) & 3])
                continue; /* not an entry edge */
            for (int j = 1; j < 4; j++) {
                const int b = (k + j) & 3;
                if (in[b] && !in[(b + 1) & 3]) {
                    next[mc_edge_between(q[k], q[(k + 1) & 3])] =
                        mc_edge_between(q[b], q[(b + 1) & 3]);
                    break;
                }
            }
        }
    }
}

/* Fans one loop from the first vertex whose diagonals all cross the cube's interior (exhaustive
 * enumeration shows every loop of every case has one), so no triangle lies in a face and no
 * diagonal can be shared with a neighbouring cell. */
static void mc_fan_loop(const int *loop, int n, mc_case_t *c)
{
    int apex = 0;
    for (int k = 0; k < n; k++) {
        bool ok = true;
        for (int j = 0; j < n && ok; j++) {
            if (j == k || j == (k + 1) % n || j == (k + n - 1) % n)
                continue;
            if (mc_edges_share_face(loop[k], loop[j]))
                ok = false;
        }
        if (ok) {
            apex = k;
            break;
        }
    }
    for (int i = 1; i + 1 < n; i++) {
        uint8_t *t = c->edge + 3 * c->n_tri;
        t[0] = (uint8_t)loop[apex];
        t[1] = (uint8_t)loop[(apex + i) % n];
        t[2] = (uint8_t)loop[(apex + i + 1) % n];
        c->n_tri++;
    }
}

void mc_table_build(mc_table_t *tab)
{
    for (unsigned mask = 0; mask < 256; mask++) {
        mc_case_t *c = &tab->cases[mask];
        int next[MC_EDGES];
        bool seen[MC_EDGES] = {false};
        c->n_tri = 0;
        for (int e = 0; e < MC_EDGES; e++)
            next[e] = -1;
        mc_link_face_segments(mask, next);
        for (int e = 0; e < MC_EDGES; e++) {
            if (next[e] < 0 || seen[e])
                continue;
            int loop[MC_EDGES], n = 0, cur = e;
            while (cur >= 0 && !seen[cur] && n < MC_EDGES) {
                seen[cur] = true;
                loop[n++] = cur;
                cur = next[cur];
            }
            mc_fan_loop(loop, n, c);
        }
    }
}

