/* The viewing camera: orbits a centre at a distance, turned by a virtual trackball (Shoemake's
 * arcball) and zoomed by the wheel; gives column-major view and projection matrices for GL. */
#ifndef ARGIL_CAMERA_H
#define ARGIL_CAMERA_H

#include "shared/vec3.h"

typedef struct {
    vec3_t center_m;    /* the point the camera orbits */
    float radius_m;     /* radius of what must stay in view */
    float rot[9];       /* model rotation, row-major 3×3 */
    float dist_m;       /* eye to centre */
    float fov_y_rad;
} camera_t;

/* A camera looking along −z at the box [lo, hi], far enough that its largest extent fills about
 * 65 % of the view's height. */
void camera_frame(camera_t *c, vec3_t lo_m, vec3_t hi_m);

/* Turns the model by the arcball drag from (x0, y0) to (x1, y1), pixels from the top-left of a
 * width × height view. */
void camera_arcball(camera_t *c, double x0, double y0, double x1, double y1, int width,
                    int height);

/* Moves the eye toward the centre by 10 % per wheel step (away for negative steps), within
 * [1.05 radius, 20 radius]. */
void camera_zoom(camera_t *c, double steps);

/* Rotates the model by yaw about the view's up axis, then pitch about its right axis (radians). */
void camera_orbit(camera_t *c, float yaw_rad, float pitch_rad);

/* The model-space ray (eye position, unit direction) through pixel (x, y) from the top-left of
 * a width × height view. */
void camera_ray(const camera_t *c, double x, double y, int width, int height, vec3_t *origin_m,
                vec3_t *dir);

/* Fills column-major 4×4 view and projection matrices for a view of the given aspect ratio. */
void camera_matrices(const camera_t *c, float aspect, float view[16], float proj[16]);

#endif
