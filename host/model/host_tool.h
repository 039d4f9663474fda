/* The session's host tool (docs/model.md "In the session"): what the host model does at the
 * stylus while the board's tool is carve and button 1 is held — an action of host/model/tools.h
 * with a shape, mirror planes and a strength. One setting shared by scripts (`action`,
 * `action_shape`, `mirror`), the live window's keys and the peer (peer_set_host_tool). */
#ifndef ARGIL_HOST_TOOL_H
#define ARGIL_HOST_TOOL_H

#include <stdbool.h>
#include <stdint.h>

typedef enum {
    HOST_ACT_CARVE = 0,       /* Ferley's eraser (the default: every earlier session's carve) */
    HOST_ACT_ADD,             /* the tool's shape becomes clay */
    HOST_ACT_TOOTHPASTE,      /* clay added progressively (strength per second) */
    HOST_ACT_SOFT_ERASE,      /* clay removed progressively */
    HOST_ACT_SMOOTH,          /* local low-pass of the field */
    HOST_ACT_STAMP,           /* Ferley's def(v): a dent with a rim */
    HOST_ACT_CHISEL,          /* the surface sinks along its normal (strength: mm per second) */
    HOST_ACT_SQUIRT,          /* the surface rises along its normal */
    HOST_ACT_INTERIOR_CARVE,  /* carve inside the solid, the outer shell kept */
    HOST_ACT_PAINT,           /* Ferley's paint: the samples inside the tool take its colour */
    HOST_ACT_SOFT_PAINT,      /* colour blended in progressively (strength per second) */
    HOST_ACT_COUNT
} host_action_t;

typedef enum {
    HOST_SHAPE_SPHERE = 0,    /* radius = the tool radius (the default) */
    HOST_SHAPE_BOX,           /* a cube of half side = radius, faces along the tool axis */
    HOST_SHAPE_CYLINDER,      /* radius and half length = radius, along the tool axis */
    HOST_SHAPE_TORUS,         /* major radius = radius, tube radius / 3, about the tool axis */
    HOST_SHAPE_COUNT
} host_shape_t;

#define HOST_MIRROR_X 1u      /* also applied mirrored across the model's plane x = 0 */
#define HOST_MIRROR_Y 2u
#define HOST_MIRROR_Z 4u
#define HOST_MIRROR_ALL 7u
#define HOST_STRENGTH_MAX 100.0f
#define HOST_TORUS_TUBE_FRACTION (1.0f / 3.0f)
/* The paint colour a session starts with: terracotta red, far from the clay's grey. */
#define HOST_PAINT_R 200u
#define HOST_PAINT_G 60u
#define HOST_PAINT_B 40u

typedef struct {
    host_action_t action;
    host_shape_t shape;
    uint32_t mirror;          /* HOST_MIRROR_* bits, about the model's origin planes */
    float strength;           /* per second held: toothpaste / soft erase (density at the tool
                               * centre), smooth (low-pass rate), stamp (def amplitude); chisel /
                               * squirt: mm per second; soft paint: blend rate; unused by
                               * carve, add, interior carve, paint */
    uint8_t rgb[3];           /* the colour paint and soft paint lay down */
} host_tool_t;

/* Carve, sphere, no mirror, paint colour HOST_PAINT_R/G/B (what the board's carve always did
 * on the host). */
void host_tool_default(host_tool_t *t);

/* True for the default setting: the session applies exactly the one-sphere eraser it always
 * applied. */
bool host_tool_is_default(const host_tool_t *t);

/* Every field in range (action and shape known, mirror ≤ 7, strength finite in 0 … MAX). */
bool host_tool_valid(const host_tool_t *t);

/* Names as scripts write them ("soft-erase", "interior-carve"); "?" when out of range. */
const char *host_action_name(host_action_t a);
const char *host_shape_name(host_shape_t s);
/* The value for a name, or -1. */
int host_action_from_name(const char *name);
int host_shape_from_name(const char *name);

/* Whether the action takes a strength, and its default (per second held). */
bool host_action_has_strength(host_action_t a);
float host_action_default_strength(host_action_t a);

/* True for paint and soft paint: the action changes colour only, never the clay's shape. */
bool host_action_paints(host_action_t a);

/* "none", "x", "xz", ... into out (≥ 5 bytes). */
void host_mirror_name(uint32_t mirror, char *out);
/* Bits for "none" or one word of the letters x, y, z each at most once; -1 otherwise. */
int host_mirror_from_name(const char *name);

#endif
