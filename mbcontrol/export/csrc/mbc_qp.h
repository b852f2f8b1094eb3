/* A dense, strictly convex QP by the dual active-set method of Goldfarb and Idnani (1983):
 *
 *     minimise 1/2 x'Hx + g'x  subject to  lbx <= x <= ubx,  lba <= A x <= uba
 *
 * H (n x n, positive definite) and A (m x n, given by its nonzeros row by row) are fixed; g
 * and the bounds change per solve (+-INFINITY: no bound). The method starts from the
 * unconstrained minimum and adds the most violated constraint at a time, so it ends in an
 * exact active set (no tolerance on the optimum beyond round-off) or reports the problem
 * infeasible. No allocation: the caller gives the workspace (MBC_QP_WORK doubles and
 * MBC_QP_IWORK ints for n, m). Written for mbcontrol's exported MPC; C99, libm only. */
#ifndef MBC_QP_H
#define MBC_QP_H

#define MBC_QP_WORK(n, m) (3 * (n) * (n) + 6 * (n) + 3 * (m) + 1)
#define MBC_QP_IWORK(n, m) (3 * (n) + 2 * (m))

enum { MBC_QP_SOLVED = 0, MBC_QP_INFEASIBLE = 1, MBC_QP_MAX_ITER = 2, MBC_QP_NOT_PD = 3 };

typedef struct {
    int n, m;
    const double *H;      /* n*n, row-major */
    const int *A_start;   /* m + 1: row r's nonzeros are A_start[r] .. A_start[r + 1] - 1 */
    const int *A_col;     /* their columns */
    const double *A_val;  /* their values */
    double *Jt0;          /* n*n: (L^-T)' = L^-1 for H = L L' (set by mbc_qp_setup) */
    double *work;         /* MBC_QP_WORK(n, m) */
    int *iwork;           /* MBC_QP_IWORK(n, m) */
    int iterations;       /* of the last solve */
    int max_iter;         /* iterations at most (0: 10 (n + 2n + 2m)): a solve's time bound */
} mbc_qp;

/* Factor H once (after the fields above are set): MBC_QP_SOLVED or MBC_QP_NOT_PD. */
int mbc_qp_setup(mbc_qp *qp);

/* Solve for x (n): MBC_QP_SOLVED, MBC_QP_INFEASIBLE or MBC_QP_MAX_ITER (x then not the
 * optimum: the caller falls back). */
int mbc_qp_solve(mbc_qp *qp, const double *g, const double *lbx, const double *ubx,
                 const double *lba, const double *uba, double *x);

#endif
