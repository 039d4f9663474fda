/* Patches with affine maps combined by sum / union / intersection / difference (Hua & Qin eq. 3-4). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "host/model/csg.h"

static double rnd(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (double)(*s >> 8) / 16777216.0;
}

/* A blob: coefficients peak at the patch centre. */
static void make_blob(bspline_t *b, int32_t n, double cx)
{
    const int32_t nn[3] = {n, n, n};
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    assert_int_equal(bspline_init_uniform(b, nn, lo, hi), ARGIL_OK);
    for (int32_t z = 0; z < n; z++)
        for (int32_t y = 0; y < n; y++)
            for (int32_t x = 0; x < n; x++) {
                const double u = (x - cx * (n - 1)) / (n - 1), v = (y - 0.5 * (n - 1)) / (n - 1),
                             w = (z - 0.5 * (n - 1)) / (n - 1);
                b->coef[x + n * (y + n * z)] = (float)(1.0 - 3.0 * (u * u + v * v + w * w));
            }
}

typedef struct {
    bspline_t a, b;
    csg_t c;
    int32_t la, lb;
} fixture_t;

static void setup(fixture_t *f, csg_op_t op)
{
    make_blob(&f->a, 8, 0.4);
    make_blob(&f->b, 9, 0.6);
    csg_init(&f->c, 0.5);
    /* patch a: scaled and shifted; patch b: rotated 30° about z, scaled, shifted */
    const double la[3][3] = {{2.0, 0, 0}, {0, 2.0, 0}, {0, 0, 2.0}}, oa[3] = {0.5, 0.5, 0.5};
    const double cs = cos(0.5236), sn = sin(0.5236);
    const double lb[3][3] = {{1.8 * cs, 1.8 * sn, 0}, {-1.8 * sn, 1.8 * cs, 0}, {0, 0, 1.8}}, ob[3] = {0.4, 0.55, 0.5};
    int32_t pa, pb;
    assert_int_equal(csg_add_patch(&f->c, &f->a, la, oa, &pa), ARGIL_OK);
    assert_int_equal(csg_add_patch(&f->c, &f->b, lb, ob, &pb), ARGIL_OK);
    assert_int_equal(csg_add_node(&f->c, CSG_LEAF, pa, 0, &f->la), ARGIL_OK);
    assert_int_equal(csg_add_node(&f->c, CSG_LEAF, pb, 0, &f->lb), ARGIL_OK);
    assert_int_equal(csg_add_node(&f->c, op, f->la, f->lb, NULL), ARGIL_OK);
}

static void teardown(fixture_t *f)
{
    bspline_free(&f->a);
    bspline_free(&f->b);
}

static double leaf(const fixture_t *f, int which, const double x[3])
{
    const csg_patch_t *p = &f->c.patches[which];
    double u[3];
    for (int i = 0; i < 3; i++)
        u[i] = p->lin[i][0] * x[0] + p->lin[i][1] * x[1] + p->lin[i][2] * x[2] + p->offset[i];
    return bspline_eval(p->spline, u, NULL);
}

static void check_op(csg_op_t op)
{
    fixture_t f;
    setup(&f, op);
    uint32_t s = 3 + (uint32_t)op;
    int checked_grad = 0;
    for (int i = 0; i < 5000; i++) {
        const double x[3] = {-0.3 + 0.6 * rnd(&s), -0.3 + 0.6 * rnd(&s), -0.3 + 0.6 * rnd(&s)};
        const double a = leaf(&f, 0, x), b = leaf(&f, 1, x);
        double g[3];
        const double v = csg_eval(&f.c, x, g);
        const double want = op == CSG_SUM ? a + b
                            : op == CSG_UNION ? fmax(a, b)
                            : op == CSG_INTERSECT ? fmin(a, b)
                                                  : fmin(a, 1.0 - b);
        assert_float_equal(v, want, 1e-12);
        if (op != CSG_SUM && fabs(a - (op == CSG_DIFFERENCE ? 1.0 - b : b)) < 1e-3)
            continue; /* at a tie the min/max is not differentiable */
        for (int k = 0; k < 3; k++) {
            const double h = 1e-6;
            double xp[3] = {x[0], x[1], x[2]}, xm[3] = {x[0], x[1], x[2]};
            xp[k] += h;
            xm[k] -= h;
            const double fd = (csg_eval(&f.c, xp, NULL) - csg_eval(&f.c, xm, NULL)) / (2 * h);
            assert_float_equal(fd, g[k], 1e-4 * (1.0 + fabs(g[k])));
        }
        checked_grad++;
    }
    assert_true(checked_grad > 1000);
    teardown(&f);
}

static void test_sum(void **state) { (void)state; check_op(CSG_SUM); }
static void test_union(void **state) { (void)state; check_op(CSG_UNION); }
static void test_intersection(void **state) { (void)state; check_op(CSG_INTERSECT); }
static void test_difference(void **state) { (void)state; check_op(CSG_DIFFERENCE); }

static void test_tree_errors(void **state)
{
    (void)state;
    csg_t c;
    csg_init(&c, 0.0);
    const double x[3] = {0, 0, 0};
    assert_float_equal(csg_eval(&c, x, NULL), 0.0, 0.0);
    assert_int_equal(csg_add_node(&c, CSG_LEAF, 0, 0, NULL), ARGIL_ERR_ARG);
    assert_int_equal(csg_add_node(&c, CSG_UNION, 0, 1, NULL), ARGIL_ERR_ARG);
    const double l[3][3] = {{1, 0, 0}, {0, NAN, 0}, {0, 0, 1}}, o[3] = {0, 0, 0};
    bspline_t b;
    make_blob(&b, 4, 0.5);
    assert_int_equal(csg_add_patch(&c, NULL, l, o, NULL), ARGIL_ERR_ARG);
    assert_int_equal(csg_add_patch(&c, &b, l, o, NULL), ARGIL_ERR_NONFINITE);
    const double id[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int i = 0; i < CSG_NODES_MAX; i++)
        assert_int_equal(csg_add_patch(&c, &b, id, o, NULL), ARGIL_OK);
    assert_int_equal(csg_add_patch(&c, &b, id, o, NULL), ARGIL_ERR_FULL);
    bspline_free(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sum),
        cmocka_unit_test(test_union),
        cmocka_unit_test(test_intersection),
        cmocka_unit_test(test_difference),
        cmocka_unit_test(test_tree_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
