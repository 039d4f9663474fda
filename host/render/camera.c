/* Camera maths (see camera.h). */
#include "host/render/camera.h"

#include <math.h>
#include <string.h>

static void rot_identity(float r[9])
{
    static const float id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    memcpy(r, id, sizeof(id));
}

/* r = a · b (row-major 3×3). */
static void rot_mul(const float a[9], const float b[9], float r[9])
{
    float t[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            t[i * 3 + j] = a[i * 3] * b[j] + a[i * 3 + 1] * b[3 + j] + a[i * 3 + 2] * b[6 + j];
    memcpy(r, t, sizeof(t));
}

/* Rodrigues' rotation of angle about the unit axis, row-major. */
static void rot_axis_angle(vec3_t axis, float angle, float r[9])
{
    const float c = cosf(angle), s = sinf(angle), t = 1.0f - c;
    const float x = axis.x, y = axis.y, z = axis.z;
    const float m[9] = {t * x * x + c,     t * x * y - s * z, t * x * z + s * y,
                        t * x * y + s * z, t * y * y + c,     t * y * z - s * x,
                        t * x * z - s * y, t * y * z + s * x, t * z * z + c};
    memcpy(r, m, sizeof(m));
}

/* Keeps r orthonormal after many small products (Gram–Schmidt on the rows). */
static void rot_orthonormalise(float r[9])
{
    vec3_t a = vec3(r[0], r[1], r[2]), b = vec3(r[3], r[4], r[5]);
    a = vec3_scale(a, 1.0f / vec3_norm(a));
    b = vec3_sub(b, vec3_scale(a, vec3_dot(a, b)));
    b = vec3_scale(b, 1.0f / vec3_norm(b));
    const vec3_t c = vec3_cross(a, b);
    const float m[9] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z};
    memcpy(r, m, sizeof(m));
}

void camera_frame(camera_t *c, vec3_t lo_m, vec3_t hi_m)
{
    c->center_m = vec3_scale(vec3_add(lo_m, hi_m), 0.5f);
    c->radius_m = 0.5f * vec3_norm(vec3_sub(hi_m, lo_m));
    if (!(c->radius_m > 1e-6f))
        c->radius_m = 1e-3f;
    rot_identity(c->rot);
    c->fov_y_rad = 35.0f * (float)M_PI / 180.0f;
    /* The largest half-extent spans ~65 % of the view's height: its angular radius θ has
     * tan θ = 0.65 tan(fov / 2), and a sphere of that radius subtends θ at r / sin θ. */
    const vec3_t half = vec3_scale(vec3_sub(hi_m, lo_m), 0.5f);
    float ext = fmaxf(half.x, fmaxf(half.y, half.z));
    if (!(ext > 1e-6f))
        ext = c->radius_m;
    const float theta = atanf(0.65f * tanf(0.5f * c->fov_y_rad));
    c->dist_m = fmaxf(ext / sinf(theta), 1.05f * c->radius_m);
}

/* A pixel on the arcball: inside the circle on the unit sphere, outside on its rim. */
static vec3_t arcball_point(double x, double y, int width, int height)
{
    const double s = 2.0 / (double)(width < height ? width : height);
    const float px = (float)((x - 0.5 * width) * s), py = (float)((0.5 * height - y) * s);
    const float d2 = px * px + py * py;
    if (d2 <= 1.0f)
        return vec3(px, py, sqrtf(1.0f - d2));
    const float inv = 1.0f / sqrtf(d2);
    return vec3(px * inv, py * inv, 0.0f);
}

void camera_arcball(camera_t *c, double x0, double y0, double x1, double y1, int width,
                    int height)
{
    if (width <= 0 || height <= 0)
        return;
    const vec3_t a = arcball_point(x0, y0, width, height);
    const vec3_t b = arcball_point(x1, y1, width, height);
    vec3_t axis = vec3_cross(a, b);
    const float n = vec3_norm(axis);
    if (n < 1e-7f)
        return;
    axis = vec3_scale(axis, 1.0f / n);
    float d = vec3_dot(a, b);
    d = d > 1.0f ? 1.0f : (d < -1.0f ? -1.0f : d);
    float r[9];
    rot_axis_angle(axis, acosf(d), r);
    rot_mul(r, c->rot, c->rot);
    rot_orthonormalise(c->rot);
}

void camera_orbit(camera_t *c, float yaw_rad, float pitch_rad)
{
    float r[9];
    rot_axis_angle(vec3(0, 1, 0), yaw_rad, r);
    rot_mul(r, c->rot, c->rot);
    rot_axis_angle(vec3(1, 0, 0), pitch_rad, r);
    rot_mul(r, c->rot, c->rot);
    rot_orthonormalise(c->rot);
}

void camera_zoom(camera_t *c, double steps)
{
    c->dist_m *= powf(0.9f, (float)steps);
    const float lo = 1.05f * c->radius_m, hi = 20.0f * c->radius_m;
    c->dist_m = c->dist_m < lo ? lo : (c->dist_m > hi ? hi : c->dist_m);
}

void camera_matrices(const camera_t *c, float aspect, float view[16], float proj[16])
{
    /* view = T(0, 0, −dist) · R · T(−centre), column-major. */
    const float *r = c->rot;
    const vec3_t ce = c->center_m;
    memset(view, 0, 16 * sizeof(float));
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            view[j * 4 + i] = r[i * 3 + j];
    view[12] = -(r[0] * ce.x + r[1] * ce.y + r[2] * ce.z);
    view[13] = -(r[3] * ce.x + r[4] * ce.y + r[5] * ce.z);
    view[14] = -(r[6] * ce.x + r[7] * ce.y + r[8] * ce.z) - c->dist_m;
    view[15] = 1.0f;
    float zn = c->dist_m - 3.0f * c->radius_m;
    if (zn < 0.01f * c->dist_m)
        zn = 0.01f * c->dist_m;
    const float zf = c->dist_m + 3.0f * c->radius_m;
    const float f = 1.0f / tanf(0.5f * c->fov_y_rad);
    memset(proj, 0, 16 * sizeof(float));
    proj[0] = f / (aspect > 0.0f ? aspect : 1.0f);
    proj[5] = f;
    proj[10] = (zf + zn) / (zn - zf);
    proj[11] = -1.0f;
    proj[14] = 2.0f * zf * zn / (zn - zf);
}

void camera_ray(const camera_t *c, double x, double y, int width, int height, vec3_t *origin_m,
                vec3_t *dir)
{
    /* View space: eye at the origin looking down −z; model = Rᵀ · view + centre. */
    const float *r = c->rot;
    const float aspect = height > 0 ? (float)width / (float)height : 1.0f;
    const float t = tanf(0.5f * c->fov_y_rad);
    const float nx = width > 0 ? (float)(2.0 * x / width - 1.0) : 0.0f;
    const float ny = height > 0 ? (float)(1.0 - 2.0 * y / height) : 0.0f;
    const float v_eye[3] = {0.0f, 0.0f, c->dist_m};
    const float v_dir[3] = {nx * t * aspect, ny * t, -1.0f};
    float e[3], d[3];
    for (int k = 0; k < 3; k++) {
        e[k] = r[0 * 3 + k] * v_eye[0] + r[1 * 3 + k] * v_eye[1] + r[2 * 3 + k] * v_eye[2];
        d[k] = r[0 * 3 + k] * v_dir[0] + r[1 * 3 + k] * v_dir[1] + r[2 * 3 + k] * v_dir[2];
    }
    *origin_m = vec3_add(c->center_m, vec3(e[0], e[1], e[2]));
    const vec3_t dv = vec3(d[0], d[1], d[2]);
    *dir = vec3_scale(dv, 1.0f / vec3_norm(dv));
}
