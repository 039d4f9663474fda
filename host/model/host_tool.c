/* The session's host tool setting: names, defaults and limits. */
#include "host/model/host_tool.h"

#include <math.h>
#include <string.h>

static const char *const ACTION_NAMES[HOST_ACT_COUNT] = {
    "carve", "add", "toothpaste", "soft-erase", "smooth",
    "stamp", "chisel", "squirt", "interior-carve", "paint", "soft-paint"};
static const char *const SHAPE_NAMES[HOST_SHAPE_COUNT] = {"sphere", "box", "cylinder", "torus"};

/* Per second held: toothpaste / soft erase move the density at the tool centre by 5 a second
 * (0.05 a 10 ms solve step, so a stroke builds up over a few tenths of a second); smoothing
 * blends a fifth of the way to the neighbours' mean per step; a stamp presses its full dent in
 * about half a second; chisel and squirt move the surface 2 mm a second; soft paint blends at
 * most a fifth of the way to its colour per step (x the tool's profile and the density: 86 % in
 * 0.1 s at a 4 mm ball's centre, tests/unit/test_gsolve_colour.c). */
static const float DEFAULT_STRENGTH[HOST_ACT_COUNT] = {
    [HOST_ACT_TOOTHPASTE] = 5.0f, [HOST_ACT_SOFT_ERASE] = 5.0f, [HOST_ACT_SMOOTH] = 20.0f,
    [HOST_ACT_STAMP] = 2.0f,      [HOST_ACT_CHISEL] = 2.0f,     [HOST_ACT_SQUIRT] = 2.0f,
    [HOST_ACT_SOFT_PAINT] = 20.0f};

void host_tool_default(host_tool_t *t)
{
    memset(t, 0, sizeof(*t));
    t->action = HOST_ACT_CARVE;
    t->shape = HOST_SHAPE_SPHERE;
    t->mirror = 0;
    t->strength = 0.0f;
    t->rgb[0] = HOST_PAINT_R;
    t->rgb[1] = HOST_PAINT_G;
    t->rgb[2] = HOST_PAINT_B;
}

bool host_tool_is_default(const host_tool_t *t)
{
    return t->action == HOST_ACT_CARVE && t->shape == HOST_SHAPE_SPHERE && t->mirror == 0;
}

bool host_tool_valid(const host_tool_t *t)
{
    return (unsigned)t->action < HOST_ACT_COUNT && (unsigned)t->shape < HOST_SHAPE_COUNT &&
           t->mirror <= HOST_MIRROR_ALL && isfinite(t->strength) && t->strength >= 0.0f &&
           t->strength <= HOST_STRENGTH_MAX;
}

const char *host_action_name(host_action_t a)
{
    return (unsigned)a < HOST_ACT_COUNT ? ACTION_NAMES[a] : "?";
}

const char *host_shape_name(host_shape_t s)
{
    return (unsigned)s < HOST_SHAPE_COUNT ? SHAPE_NAMES[s] : "?";
}

int host_action_from_name(const char *name)
{
    for (int k = 0; k < HOST_ACT_COUNT; k++)
        if (strcmp(name, ACTION_NAMES[k]) == 0)
            return k;
    return -1;
}

int host_shape_from_name(const char *name)
{
    for (int k = 0; k < HOST_SHAPE_COUNT; k++)
        if (strcmp(name, SHAPE_NAMES[k]) == 0)
            return k;
    return -1;
}

bool host_action_has_strength(host_action_t a)
{
    return (unsigned)a < HOST_ACT_COUNT && DEFAULT_STRENGTH[a] > 0.0f;
}

float host_action_default_strength(host_action_t a)
{
    return (unsigned)a < HOST_ACT_COUNT ? DEFAULT_STRENGTH[a] : 0.0f;
}

bool host_action_paints(host_action_t a)
{
    return a == HOST_ACT_PAINT || a == HOST_ACT_SOFT_PAINT;
}

void host_mirror_name(uint32_t mirror, char *out)
{
    size_t n = 0;
    for (int a = 0; a < 3; a++)
        if (mirror & (1u << a))
            out[n++] = (char)('x' + a);
    if (n == 0)
        strcpy(out, "none");
    else
        out[n] = '\0';
}

int host_mirror_from_name(const char *name)
{
    if (strcmp(name, "none") == 0)
        return 0;
    uint32_t bits = 0;
    size_t n = 0;
    for (; name[n] != '\0'; n++) {
        if (n >= 3 || name[n] < 'x' || name[n] > 'z')
            return -1;
        const uint32_t b = 1u << (name[n] - 'x');
        if (bits & b)
            return -1;
        bits |= b;
    }
    return n == 0 ? -1 : (int)bits;
}
