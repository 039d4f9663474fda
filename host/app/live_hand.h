/* Sculpting with the mouse (no arm): the cursor's ray is cast against the density field, and
 * the virtual hand's target follows it — hovering over the surface while the button is up,
 * pressing in (or, for the adding tools, drawing out) from the point first touched while it is
 * held — so the whole board and haptics path still runs. */
#ifndef ARGIL_LIVE_HAND_H
#define ARGIL_LIVE_HAND_H

#include <stdbool.h>

#include "host/model/grid.h"
#include "shared/vec3.h"

typedef struct {
    float hover_m;                /* gap between the tool's sphere and the surface when up */
    float press_extra_m;          /* deepest press: tool radius + this below the touched point */
    float pull_m;                 /* farthest draw-out above the touched point */
    float press_rate_m_s;         /* how fast the depth grows while the button is held */
    float max_speed_m_s;          /* the target never moves faster than this */
} live_hand_cfg_t;

typedef struct {
    bool have_target;
    vec3_t target_m;              /* hand target, model space */
    bool pressing;
    vec3_t anchor_m;              /* surface point under the cursor when the button went down */
    vec3_t plane_n;               /* the ray's direction then: drags move across this plane */
    float depth_m;                /* along plane_n from the anchor (negative: drawn out) */
} live_hand_t;

void live_hand_cfg_default(live_hand_cfg_t *c);
void live_hand_init(live_hand_t *h);

/* The first point where the ray (unit dir) enters density ≥ iso within the grid, to within
 * 1/256 of a spacing; false when it misses or the ray is not finite. */
bool live_hand_raycast(const grid_t *g, vec3_t origin_m, vec3_t dir, vec3_t *hit_m);

/* Advances the hand by dt_s toward where the cursor's ray puts it; `outward` for tools that add
 * material (draw out instead of pressing in). Writes the hand's target, its velocity and
 * buttons (bit 0 held while pressing). */
void live_hand_step(live_hand_t *h, const live_hand_cfg_t *cfg, const grid_t *g,
                    vec3_t origin_m, vec3_t dir, bool button_down, bool outward,
                    float tool_radius_m, float dt_s, vec3_t *pos_m, vec3_t *vel_m_s,
                    int *buttons);

#endif
