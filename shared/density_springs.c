/* Density-spring dynamics shared by the board window and the host field (Hua & Qin §5.1). */
#include "density_springs.h"

#include <math.h>

void spring_material_default(spring_material_t *m)
{
    m->node_mass = 1.0f;
    m->stiffness = 2.0f;
    m->coupling = 4.0f;
    m->damping = 40.0f;
    m->plastic_rate_hz = 20.0f;
}

bool spring_material_valid(const spring_material_t *m)
{
    return isfinite(m->node_mass) && m->node_mass > 0.0f && isfinite(m->stiffness) &&
           m->stiffness >= 0.0f && isfinite(m->coupling) && m->coupling >= 0.0f &&
           isfinite(m->damping) && m->damping >= 0.0f && isfinite(m->plastic_rate_hz) &&
           m->plastic_rate_hz >= 0.0f;
}

float springs_stable_dt_s(const spring_material_t *m)
{
    /* With per-node stiffness, pass the largest node stiffness in m->stiffness. */
    /* Semi-implicit Euler on m x'' + c x' + k x: stable for dt < 2/(c/m + sqrt(k/m)) roughly;
     * the six neighbour springs add up to 12*coupling of effective stiffness. Half that, to
     * keep a margin. */
    float k = m->stiffness + 12.0f * m->coupling;
    float w = sqrtf(k / m->node_mass);
    float c = m->damping / m->node_mass;
    return 1.0f / (c + w);
}

static float clamp01(float v)
{
    return v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
}

float springs_step(spring_field_t *f, const spring_material_t *m, const int32_t lo[3],
                   const int32_t hi[3], float dt_s)
{
    const int32_t nx = f->dims[0], ny = f->dims[1], nz = f->dims[2];
    const int32_t sy = nx, sz = nx * ny;
    int32_t b0[3], b1[3];
    const int32_t n[3] = {nx, ny, nz};
    for (int a = 0; a < 3; a++) {
        b0[a] = lo[a] < 0 ? 0 : lo[a];
        b1[a] = hi[a] > n[a] ? n[a] : hi[a];
        if (b1[a] <= b0[a])
            return 0.0f;
    }
    const float inv_m = 1.0f / m->node_mass;
    const float plastic = m->plastic_rate_hz * dt_s > 1.0f ? 1.0f : m->plastic_rate_hz * dt_s;
    float max_acc = 0.0f;

    /* Velocities first (all forces from the old densities), then positions. Interior nodes
     * (all six neighbours present) take a branch-free path; the rest count their neighbours. */
    for (int32_t z = b0[2]; z < b1[2]; z++) {
        for (int32_t y = b0[1]; y < b1[1]; y++) {
            const bool row_inner = y > 0 && y + 1 < ny && z > 0 && z + 1 < nz;
            for (int32_t x = b0[0]; x < b1[0]; x++) {
                const int32_t i = x + y * sy + z * sz;
                const float dev = f->density[i] - f->rest[i];
                float nb_dev;
                if (row_inner && x > 0 && x + 1 < nx) {
                    /* Σ over neighbours of (their deviation − ours): 4D springs, density part. */
                    nb_dev = (f->density[i - 1] - f->rest[i - 1]) + (f->density[i + 1] - f->rest[i + 1]) +
                             (f->density[i - sy] - f->rest[i - sy]) +
                             (f->density[i + sy] - f->rest[i + sy]) +
                             (f->density[i - sz] - f->rest[i - sz]) +
                             (f->density[i + sz] - f->rest[i + sz]) - 6.0f * dev;
                } else {
                    nb_dev = 0.0f;
                    if (x > 0) nb_dev += f->density[i - 1] - f->rest[i - 1] - dev;
                    if (x + 1 < nx) nb_dev += f->density[i + 1] - f->rest[i + 1] - dev;
                    if (y > 0) nb_dev += f->density[i - sy] - f->rest[i - sy] - dev;
                    if (y + 1 < ny) nb_dev += f->density[i + sy] - f->rest[i + sy] - dev;
                    if (z > 0) nb_dev += f->density[i - sz] - f->rest[i - sz] - dev;
                    if (z + 1 < nz) nb_dev += f->density[i + sz] - f->rest[i + sz] - dev;
                }
                /* Neighbour springs act on deviations from the rest shape, so a field at rest
                 * stays at rest: only differences from the rest shape are smoothed. */
                const float k = f->stiffness ? f->stiffness[i] : m->stiffness;
                const float force = f->force[i] - k * dev + m->coupling * nb_dev -
                                    m->damping * f->velocity[i];
                const float acc = force * inv_m;
                f->velocity[i] += acc * dt_s;
                f->force[i] = 0.0f;
                const float a_abs = fabsf(acc);
                if (a_abs > max_acc)
                    max_acc = a_abs;
            }
        }
    }
    for (int32_t z = b0[2]; z < b1[2]; z++) {
        for (int32_t y = b0[1]; y < b1[1]; y++) {
            for (int32_t x = b0[0]; x < b1[0]; x++) {
                const int32_t i = x + y * sy + z * sz;
                float d = f->density[i] + f->velocity[i] * dt_s;
                const float c = clamp01(d);
                if (c != d)
                    f->velocity[i] = 0.0f;
                f->density[i] = c;
                f->rest[i] += plastic * (c - f->rest[i]);
            }
        }
    }
    return max_acc;
}
