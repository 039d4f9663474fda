/* CGLS on a small dense least-squares problem whose solution is known: d = A x* + e with e
 * orthogonal to A's columns, so x* is the least-squares solution and e the residual left. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "host/model/cgls.h"

#define ROWS 5
#define COLS 3

static const float A[ROWS][COLS] = {
    {1, 0, 1}, {1, 1, 0}, {1, 2, -1}, {1, 3, 2}, {1, 4, 0},
};
static const float X_STAR[COLS] = {0.5f, -1.25f, 2.0f};
static const float E[ROWS] = {0.25f, -0.5f, 0.25f, 0.0f, 0.0f}; /* Aᵀ e = 0 */

typedef struct {
    int fixed; /* unknown held fixed, or -1 */
    int calls;
} ctx_t;

static void apply_a(void *vctx, const float *x, float *out)
{
    ctx_t *c = vctx;
    c->calls++;
    for (int i = 0; i < ROWS; i++) {
        out[i] = 0.0f;
        for (int j = 0; j < COLS; j++)
            out[i] += A[i][j] * x[j];
    }
}

static void apply_at(void *vctx, const float *r, float *out)
{
    const ctx_t *c = vctx;
    for (int j = 0; j < COLS; j++) {
        out[j] = 0.0f;
        for (int i = 0; i < ROWS; i++)
            out[j] += A[i][j] * r[i];
    }
    if (c->fixed >= 0)
        out[c->fixed] = 0.0f;
}

/* r = d - A p for d = A x* + e. */
static void residual(const float *p, float *r)
{
    ctx_t c = {-1, 0};
    float ax[ROWS], ap[ROWS];
    apply_a(&c, X_STAR, ax);
    apply_a(&c, p, ap);
    for (int i = 0; i < ROWS; i++)
        r[i] = ax[i] + E[i] - ap[i];
}

static void test_reaches_the_least_squares_solution(void **state)
{
    (void)state;
    ctx_t c = {-1, 0};
    const cgls_op_t op = {apply_a, apply_at, &c, COLS, ROWS};
    float p[COLS] = {0, 0, 0}, r[ROWS], s[COLS], q[COLS], t[ROWS];
    residual(p, r);
    const int it = cgls_solve(&op, COLS, p, r, s, q, t); /* n unknowns: n iterations */
    assert_int_equal(it, COLS);
    for (int j = 0; j < COLS; j++)
        assert_true(fabsf(p[j] - X_STAR[j]) < 1e-4f);
    for (int i = 0; i < ROWS; i++) /* what is left is e, which no p can fit */
        assert_true(fabsf(r[i] - E[i]) < 1e-4f);
}

static void test_fixed_unknown_stays(void **state)
{
    (void)state;
    ctx_t c = {2, 0};
    const cgls_op_t op = {apply_a, apply_at, &c, COLS, ROWS};
    float p[COLS] = {0, 0, 1.5f}, r[ROWS], s[COLS], q[COLS], t[ROWS];
    residual(p, r);
    (void)cgls_solve(&op, 10, p, r, s, q, t);
    assert_true(p[2] == 1.5f);
    float g[COLS];
    apply_at(&c, r, g); /* the free unknowns are optimal: the gradient is zero there */
    assert_true(fabsf(g[0]) < 1e-4f && fabsf(g[1]) < 1e-4f);
}

static void test_stops_at_zero_gradient_and_at_iters(void **state)
{
    (void)state;
    ctx_t c = {-1, 0};
    const cgls_op_t op = {apply_a, apply_at, &c, COLS, ROWS};
    float p[COLS], r[ROWS], s[COLS], q[COLS], t[ROWS];
    memcpy(p, X_STAR, sizeof(p));
    residual(p, r);
    assert_int_equal(cgls_solve(&op, 5, p, r, s, q, t), 0); /* already the solution */
    assert_int_equal(c.calls, 0);
    assert_true(memcmp(p, X_STAR, sizeof(p)) == 0);
    memset(p, 0, sizeof(p));
    residual(p, r);
    assert_int_equal(cgls_solve(&op, 1, p, r, s, q, t), 1);
    assert_int_equal(c.calls, 1);
    float r1[ROWS];
    residual(p, r1);
    for (int i = 0; i < ROWS; i++) /* r stays d - A p */
        assert_true(fabsf(r[i] - r1[i]) < 1e-5f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reaches_the_least_squares_solution),
        cmocka_unit_test(test_fixed_unknown_stays),
        cmocka_unit_test(test_stops_at_zero_gradient_and_at_iters),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
