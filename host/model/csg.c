/* Evaluation of the patch tree bottom-up (children precede parents), no recursion. */
#include "host/model/csg.h"

#include <math.h>
#include <string.h>

void csg_init(csg_t *c, double iso)
{
    memset(c, 0, sizeof(*c));
    c->iso = iso;
}

argil_err_t csg_add_patch(csg_t *c, const bspline_t *s, const double lin[3][3],
                          const double offset[3], int32_t *patch)
{
    if (s == NULL)
        return ARGIL_ERR_ARG;
    if (c->npatches >= CSG_NODES_MAX)
        return ARGIL_ERR_FULL;
    for (int i = 0; i < 3; i++) {
        if (!isfinite(offset[i]))
            return ARGIL_ERR_NONFINITE;
        for (int j = 0; j < 3; j++)
            if (!isfinite(lin[i][j]))
                return ARGIL_ERR_NONFINITE;
    }
    csg_patch_t *p = &c->patches[c->npatches];
    p->spline = s;
    memcpy(p->lin, lin, sizeof(p->lin));
    memcpy(p->offset, offset, sizeof(p->offset));
    if (patch != NULL)
        *patch = c->npatches;
    c->npatches++;
    return ARGIL_OK;
}

argil_err_t csg_add_node(csg_t *c, csg_op_t op, int32_t a, int32_t b, int32_t *node)
{
    if (c->nnodes >= CSG_NODES_MAX)
        return ARGIL_ERR_FULL;
    if (op == CSG_LEAF) {
        if (a < 0 || a >= c->npatches)
            return ARGIL_ERR_ARG;
    } else if (op > CSG_DIFFERENCE || a < 0 || b < 0 || a >= c->nnodes || b >= c->nnodes) {
        return ARGIL_ERR_ARG;
    }
    c->nodes[c->nnodes].op = op;
    c->nodes[c->nnodes].a = a;
    c->nodes[c->nnodes].b = b;
    if (node != NULL)
        *node = c->nnodes;
    c->nnodes++;
    return ARGIL_OK;
}

static double csg_patch_eval(const csg_patch_t *p, const double x[3], double g[3])
{
    double u[3], gu[3];
    for (int i = 0; i < 3; i++)
        u[i] = p->lin[i][0] * x[0] + p->lin[i][1] * x[1] + p->lin[i][2] * x[2] + p->offset[i];
    const double v = bspline_eval(p->spline, u, gu);
    for (int j = 0; j < 3; j++) /* chain rule: grad_x = Lᵀ grad_u */
        g[j] = p->lin[0][j] * gu[0] + p->lin[1][j] * gu[1] + p->lin[2][j] * gu[2];
    return v;
}

double csg_eval(const csg_t *c, const double x_m[3], double grad[3])
{
    double val[CSG_NODES_MAX], g[CSG_NODES_MAX][3];
    if (grad != NULL)
        grad[0] = grad[1] = grad[2] = 0.0;
    if (c->nnodes == 0)
        return 0.0;
    for (int32_t n = 0; n < c->nnodes; n++) {
        const csg_node_t *nd = &c->nodes[n];
        if (nd->op == CSG_LEAF) {
            val[n] = csg_patch_eval(&c->patches[nd->a], x_m, g[n]);
            continue;
        }
        const double va = val[nd->a], vb = val[nd->b];
        const double *ga = g[nd->a], *gb = g[nd->b];
        switch (nd->op) {
        case CSG_SUM: /* Hua & Qin eq. 3 */
            val[n] = va + vb;
            for (int i = 0; i < 3; i++)
                g[n][i] = ga[i] + gb[i];
            break;
        case CSG_UNION: /* Hua & Qin eq. 4, Ω = union */
            val[n] = va >= vb ? va : vb;
            memcpy(g[n], va >= vb ? ga : gb, sizeof(g[n]));
            break;
        case CSG_INTERSECT:
            val[n] = va <= vb ? va : vb;
            memcpy(g[n], va <= vb ? ga : gb, sizeof(g[n]));
            break;
        default: { /* difference: a ∩ complement(b), complement = 2 iso - b */
            const double cb = 2.0 * c->iso - vb;
            val[n] = va <= cb ? va : cb;
            for (int i = 0; i < 3; i++)
                g[n][i] = va <= cb ? ga[i] : -gb[i];
            break;
        }
        }
    }
    const int32_t root = c->nnodes - 1;
    if (grad != NULL)
        memcpy(grad, g[root], sizeof(double) * 3);
    return val[root];
}
