/* Goldfarb-Idnani dual active-set QP; see mbc_qp.h. Invariants: J J' = H^-1 and, for the q
 * active constraints with normals c_1..c_q, J' [c_1 .. c_q] = [R; 0] with R upper
 * triangular; every change of the active set is a sequence of Givens rotations. J is kept
 * transposed (Jt = J', row-major), so each rotation runs along contiguous memory. */
#include <math.h>
#include <string.h>
#include "mbc_qp.h"

#define TOL 1e-11          /* feasibility tolerance, in the scaled units of the problem */

int mbc_qp_setup(mbc_qp *qp)
{
    int n = qp->n, i, j, k;
    double *L = qp->work;  /* lower Cholesky factor */
    memcpy(L, qp->H, sizeof(double) * n * n);
    for (j = 0; j < n; ++j) {
        double s = L[j * n + j];
        for (k = 0; k < j; ++k) s -= L[j * n + k] * L[j * n + k];
        if (!(s > 0.0)) return MBC_QP_NOT_PD;
        L[j * n + j] = sqrt(s);
        for (i = j + 1; i < n; ++i) {
            double t = L[i * n + j];
            for (k = 0; k < j; ++k) t -= L[i * n + k] * L[j * n + k];
            L[i * n + j] = t / L[j * n + j];
        }
        for (k = j + 1; k < n; ++k) L[j * n + k] = 0.0;
    }
    /* Jt0 = L^-1 (lower), column by column: L y = e_j */
    memset(qp->Jt0, 0, sizeof(double) * n * n);
    for (j = 0; j < n; ++j)
        for (i = j; i < n; ++i) {
            double t = (i == j) ? 1.0 : 0.0;
            for (k = j; k < i; ++k) t -= L[i * n + k] * qp->Jt0[k * n + j];
            qp->Jt0[i * n + j] = t / L[i * n + i];
        }
    return MBC_QP_SOLVED;
}

/* constraint c: 0..2n-1 bounds (k = c / 2, lower if even), then 2m rows of A (row (c-2n)/2) */
static double slack(const mbc_qp *qp, int c, const double *x, const double *ax,
                    const double *lbx, const double *ubx, const double *lba, const double *uba)
{
    int n = qp->n, r;
    if (c < 2 * n) return (c % 2 == 0) ? x[c / 2] - lbx[c / 2] : ubx[c / 2] - x[c / 2];
    r = (c - 2 * n) / 2;
    return (c % 2 == 0) ? ax[r] - lba[r] : uba[r] - ax[r];
}

/* a row's nonzeros as one dense run when its columns are consecutive (the MPC's stroke and
 * slew rows are): returns the run's length (0: not consecutive), its values and first column */
static int row_run(const mbc_qp *qp, int r, const double **val, int *first)
{
    int a = qp->A_start[r], b = qp->A_start[r + 1];
    if (b == a || qp->A_col[b - 1] - qp->A_col[a] != b - 1 - a) return 0;
    *val = qp->A_val + a;
    *first = qp->A_col[a];
    return b - a;
}

/* four partial sums: the compiler may then use vector registers (it keeps one sum's order) */
static double dense_dot(const double *a, const double *b, int len)
{
    int k;
    double t0 = 0.0, t1 = 0.0, t2 = 0.0, t3 = 0.0;
    for (k = 0; k + 3 < len; k += 4) {
        t0 += a[k] * b[k];
        t1 += a[k + 1] * b[k + 1];
        t2 += a[k + 2] * b[k + 2];
        t3 += a[k + 3] * b[k + 3];
    }
    for (; k < len; ++k) t0 += a[k] * b[k];
    return (t0 + t1) + (t2 + t3);
}

static double row_dot(const mbc_qp *qp, int r, const double *v)
{
    const double *val;
    int k, first, len = row_run(qp, r, &val, &first);
    double t = 0.0;
    if (len) return dense_dot(val, v + first, len);
    for (k = qp->A_start[r]; k < qp->A_start[r + 1]; ++k) t += qp->A_val[k] * v[qp->A_col[k]];
    return t;
}

/* sqrt(a^2 + b^2) for a Givens rotation: libm's hypot guards against overflow at a cost
 * that was a tenth of a solve; the plain form is exact enough wherever it cannot overflow */
static double norm2(double a, double b)
{
    double h = sqrt(a * a + b * b);
    return (h > 1e-150 && h < 1e150) ? h : hypot(a, b);
}

static void product(const mbc_qp *qp, const double *x, double *ax)
{
    int r;
    for (r = 0; r < qp->m; ++r) ax[r] = row_dot(qp, r, x);
}


/* d = J' c_p: row j of Jt dotted with the normal */
static void project(const mbc_qp *qp, const double *Jt, int c, double *d)
{
    int n = qp->n, j;
    double sign = (c % 2 == 0) ? 1.0 : -1.0;
    if (c < 2 * n) {
        for (j = 0; j < n; ++j) d[j] = sign * Jt[j * n + c / 2];
        return;
    }
    {
        const double *val;
        int first, len = row_run(qp, (c - 2 * n) / 2, &val, &first);
        for (j = 0; j < n; ++j)
            d[j] = sign * (len ? dense_dot(val, Jt + j * n + first, len)
                               : row_dot(qp, (c - 2 * n) / 2, Jt + j * n));
    }
}

static double normal_dot(const mbc_qp *qp, int c, const double *z)
{
    int n = qp->n;
    double sign = (c % 2 == 0) ? 1.0 : -1.0;
    if (c < 2 * n) return sign * z[c / 2];
    return sign * row_dot(qp, (c - 2 * n) / 2, z);
}

/* rotate rows a, b of Jt (columns of J) by (cs, sn) */
static void rotate(double *Jt, int n, int a, int b, double cs, double sn)
{
    double *ra = Jt + a * n, *rb = Jt + b * n;
    int k;
    for (k = 0; k < n; ++k) {
        double t = ra[k];
        ra[k] = cs * t + sn * rb[k];
        rb[k] = -sn * t + cs * rb[k];
    }
}

int mbc_qp_solve(mbc_qp *qp, const double *g, const double *lbx, const double *ubx,
                 const double *lba, const double *uba, double *x)
{
    int n = qp->n, m = qp->m, nc = 2 * n + 2 * m, q = 0, i, j, k, iter, max_iter;
    double *Jt = qp->work, *R = Jt + n * n, *d = R + n * n, *z = d + n, *r = z + n, *u = r + n;
    double *s = u + n + 1;                /* slacks of every constraint: nc */
    double *ax = s + nc;                  /* A x: m */
    int *active = qp->iwork, *is_active = active + n;
    memcpy(Jt, qp->Jt0, sizeof(double) * n * n);
    memset(is_active, 0, sizeof(int) * nc);
    /* unconstrained minimum x = -J J' g */
    for (j = 0; j < n; ++j) {
        double t = 0.0;
        for (k = 0; k < n; ++k) t += Jt[j * n + k] * g[k];
        d[j] = t;
    }
    memset(x, 0, sizeof(double) * n);
    for (j = 0; j < n; ++j)
        for (k = 0; k < n; ++k) x[k] -= Jt[j * n + k] * d[j];
    max_iter = qp->max_iter > 0 ? qp->max_iter : 10 * (n + nc);
    for (iter = 0; iter < max_iter; ++iter) {
        int p = -1;
        double worst = -TOL, up = 0.0;
        product(qp, x, ax);
        /* step 1: the most violated constraint (an infinite bound's slack is +inf) */
        for (k = 0; k < n; ++k) {
            s[2 * k] = x[k] - lbx[k];
            s[2 * k + 1] = ubx[k] - x[k];
        }
        for (k = 0; k < m; ++k) {
            s[2 * n + 2 * k] = ax[k] - lba[k];
            s[2 * n + 2 * k + 1] = uba[k] - ax[k];
        }
        for (i = 0; i < nc; ++i)
            if (s[i] < worst && !is_active[i]) { worst = s[i]; p = i; }
        if (p < 0) { qp->iterations = iter; return MBC_QP_SOLVED; }
        for (;;) {                          /* step 2: move towards satisfying p */
            double t1 = INFINITY, t2 = INFINITY, zz = 0.0, t;
            int l = -1;
            project(qp, Jt, p, d);
            memset(z, 0, sizeof(double) * n);   /* primal direction z = J2 d2, two rows a pass */
            for (j = q; j + 1 < n; j += 2) {
                const double *a = Jt + j * n, *b = a + n;
                for (k = 0; k < n; ++k) z[k] += a[k] * d[j] + b[k] * d[j + 1];
            }
            if (j < n)
                for (k = 0; k < n; ++k) z[k] += Jt[j * n + k] * d[j];
            zz = dense_dot(z, z, n);
            for (j = q - 1; j >= 0; --j)    /* dual direction r = R^-1 d1 */
                r[j] = (d[j] - dense_dot(R + j * n + j + 1, r + j + 1, q - j - 1)) / R[j * n + j];
            for (j = 0; j < q; ++j)
                if (r[j] > 0.0 && u[j] / r[j] < t1) { t1 = u[j] / r[j]; l = j; }
            if (zz > 1e-28) t2 = -s[p] / normal_dot(qp, p, z);
            if (!isfinite(t1) && !isfinite(t2)) { qp->iterations = iter; return MBC_QP_INFEASIBLE; }
            t = (t2 < t1) ? t2 : t1;
            if (isfinite(t2)) for (k = 0; k < n; ++k) x[k] += t * z[k];
            for (j = 0; j < q; ++j) u[j] -= t * r[j];
            up += t;
            if (isfinite(t2) && t2 <= t1) { /* full step: add p */
                for (j = n - 1; j > q; --j) {
                    double h = norm2(d[j - 1], d[j]), cs, sn;
                    if (h == 0.0) continue;
                    cs = d[j - 1] / h; sn = d[j] / h;
                    d[j - 1] = h; d[j] = 0.0;
                    rotate(Jt, n, j - 1, j, cs, sn);
                }
                for (j = 0; j <= q; ++j) R[j * n + q] = d[j];
                active[q] = p; u[q] = up; is_active[p] = 1;
                ++q;
                break;
            }
            /* partial step: drop active constraint l, restore R to triangular form */
            is_active[active[l]] = 0;
            for (j = l; j < q - 1; ++j) {
                active[j] = active[j + 1];
                u[j] = u[j + 1];
                for (k = 0; k < n; ++k) R[k * n + j] = R[k * n + j + 1];
            }
            --q;
            for (j = l; j < q; ++j) {
                double h = norm2(R[j * n + j], R[(j + 1) * n + j]), cs, sn;
                if (h == 0.0) continue;
                cs = R[j * n + j] / h; sn = R[(j + 1) * n + j] / h;
                for (k = j; k < q; ++k) {
                    double a = R[j * n + k];
                    R[j * n + k] = cs * a + sn * R[(j + 1) * n + k];
                    R[(j + 1) * n + k] = -sn * a + cs * R[(j + 1) * n + k];
                }
                rotate(Jt, n, j, j + 1, cs, sn);
            }
            if (p >= 2 * n) ax[(p - 2 * n) / 2] = row_dot(qp, (p - 2 * n) / 2, x);
            s[p] = slack(qp, p, x, ax, lbx, ubx, lba, uba);
            if (s[p] >= -TOL) break;        /* satisfied on the way: back to step 1 */
        }
    }
    qp->iterations = max_iter;
    return MBC_QP_MAX_ITER;
}
