/* sf_magcal.c — see sf_magcal.h for the model. */
#include "sf_magcal.h"

#include <math.h>

#include "sf_assert.h"

#define MIN_SAMPLES 20.0        /* W needed before a solve (header: "≥ 20 samples in memory") */
#define LOCK_SPREAD_UT 1000.0   /* ridge along unobserved directions (header: "4W·(1000 µT)²") */
#define JACOBI_SWEEPS 16        /* bound on the eigen-decomposition (3×3 converges in ~5) */
#define PIVOT_REL 1e-12         /* pivot below this × the largest diagonal entry: singular */


static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static bool finite3(const double a[3])
{
    return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]);
}

/* Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations (Numerical Recipes §11.1).
 * a is overwritten (it ends diagonal). w: eigenvalues, descending; v: eigenvectors as columns
 * (v[i][k] = component i of vector k). Not const: C11 does not convert double[3][3] to a
 * pointer-to-const-array (the reason a is worked on in place). */
static void eig_sym3(double a[3][3], double w[3], double v[3][3])
{
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            v[i][j] = i == j ? 1.0 : 0.0;
        }
    }
    for (int sweep = 0; sweep < JACOBI_SWEEPS; sweep++) {
        const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if (off <= 1e-30 * diag || off == 0.0) {
            break;
        }
        for (int p = 0; p < 2; p++) {
            for (int q = p + 1; q < 3; q++) {
                if (a[p][q] == 0.0) {
                    continue;
                }
                /* rotation P (P_pp = P_qq = c, P_pq = s, P_qp = −s) with (PᵀAP)_pq = 0 */
                const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                const double t = (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                const double c = 1.0 / sqrt(t * t + 1.0);
                const double s = t * c;
                /* A ← PᵀAP and V ← VP touching only what P moves: columns p, q of AP and VP, then
                 * rows p, q of Pᵀ(AP). The full 3×3 products this replaced added exact zeros and
                 * multiplied by exact ones, so every element is the same double (a zero's sign
                 * aside), at a fifth of the cost. */
                const double ms = -s;
                for (int i = 0; i < 3; i++) {
                    const double aip = a[i][p], aiq = a[i][q];
                    a[i][p] = aip * c + aiq * ms; /* AP */
                    a[i][q] = aip * s + aiq * c;
                    const double vip = v[i][p], viq = v[i][q];
                    v[i][p] = vip * c + viq * ms;
                    v[i][q] = vip * s + viq * c;
                }
                for (int j = 0; j < 3; j++) {
                    const double apj = a[p][j], aqj = a[q][j];
                    a[p][j] = c * apj + ms * aqj; /* Pᵀ(AP) */
                    a[q][j] = s * apj + c * aqj;
                }
                a[p][q] = a[q][p] = 0.0;
            }
        }
    }
    int order[3] = {0, 1, 2};
    for (int i = 0; i < 2; i++) { /* three elements: a stable selection sort, descending */
        for (int j = i + 1; j < 3; j++) {
            if (a[order[j]][order[j]] > a[order[i]][order[i]]) {
                const int tmp = order[i];
                order[i] = order[j];
                order[j] = tmp;
            }
        }
    }
    double vs[3][3];
    for (int k = 0; k < 3; k++) {
        w[k] = a[order[k]][order[k]];
        for (int i = 0; i < 3; i++) {
            vs[i][k] = v[i][order[k]];
        }
    }
    for (int i = 0; i < 3; i++) {
        for (int k = 0; k < 3; k++) {
            v[i][k] = vs[i][k];
        }
    }
}

/* Solves m x = r (4×4) by Gaussian elimination with partial pivoting, on an augmented copy (m_in is
 * not written; not const for the reason given at eig_sym3). Returns false when a pivot is below
 * PIVOT_REL × the largest diagonal magnitude. */
static bool solve4(double m_in[4][4], const double r_in[4], double x[4])
{
    double m[4][5];
    double scale = 0.0;
    for (int i = 0; i < 4; i++) {
        for (int j = 0; j < 4; j++) {
            m[i][j] = m_in[i][j];
        }
        m[i][4] = r_in[i];
        scale = fmax(scale, fabs(m_in[i][i]));
    }
    if (!(scale > 0.0) || !isfinite(scale)) {
        return false;
    }
    for (int col = 0; col < 4; col++) {
        int piv = col;
        for (int i = col + 1; i < 4; i++) {
            if (fabs(m[i][col]) > fabs(m[piv][col])) {
                piv = i;
            }
        }
        if (!(fabs(m[piv][col]) > PIVOT_REL * scale)) {
            return false;
        }
        if (piv != col) {
            for (int j = 0; j < 5; j++) {
                const double tmp = m[col][j];
                m[col][j] = m[piv][j];
                m[piv][j] = tmp;
            }
        }
        for (int i = col + 1; i < 4; i++) {
            const double f = m[i][col] / m[col][col];
            for (int j = col; j < 5; j++) {
                m[i][j] -= f * m[col][j];
            }
        }
    }
    for (int i = 3; i >= 0; i--) {
        double s = m[i][4];
        for (int j = i + 1; j < 4; j++) {
            s -= m[i][j] * x[j];
        }
        x[i] = s / m[i][i];
    }
    return isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]) && isfinite(x[3]);
}

void sf_magcal_init(sf_magcal_t *const cal, const sf_params_t *const p)
{
    (void)p;
    *cal = (sf_magcal_t){0};
    cal->last.sample = sf_magcal_used;
    cal->last.solve = sf_magcal_not_solved;
}

static void reject(sf_magcal_t *const cal, const sf_magcal_sample_verdict_t v)
{
    cal->samples_rejected++;
    cal->by_sample[v]++;
    cal->last.sample = v;
    cal->by_solve[sf_magcal_not_solved]++;
}

/* Fusion: the solve over the current normal equations, with observability and the ridge prior.
 * Fills the audit's spread/observed/candidate fields; returns the verdict; on success b and R. */
static sf_magcal_solve_verdict_t solve(const sf_magcal_t *const cal, const sf_params_t *const p,
                                       sf_magcal_audit_t *const audit, double b_ut[3], double *const radius_ut)
{
    const double w_n = cal->ata[3][3];
    if (w_n < MIN_SAMPLES) {
        return sf_magcal_too_few;
    }
    /* direction covariance C = E[m mᵀ] − E[m] E[m]ᵀ, from A (rows a = (2m, 1)) */
    double mean[3], cov[3][3];
    for (int i = 0; i < 3; i++) {
        mean[i] = cal->ata[i][3] / (2.0 * w_n);
    }
    for (int i = 0; i < 3; i++) { /* A is symmetric bit for bit (rows a_i a_j, scaled alike): so is C */
        for (int j = i; j < 3; j++) {
            cov[i][j] = cov[j][i] = cal->ata[i][j] / (4.0 * w_n) - mean[i] * mean[j];
        }
    }
    double ev[3], vec[3][3];
    eig_sym3(cov, ev, vec);
    int observed = 0;
    bool obs[3];
    for (int k = 0; k < 3; k++) {
        audit->spread_ut[k] = sqrt(fmax(ev[k], 0.0));
        obs[k] = audit->spread_ut[k] >= p->magcal_min_spread_ut;
        observed += obs[k] ? 1 : 0;
    }
    audit->observed = observed;
    if (observed < 2) {
        return sf_magcal_not_spread;
    }
    /* ridge prior toward b = 0: weak along observed directions, pinning along unobserved ones */
    double m[4][4];
    for (int i = 0; i < 4; i++) {
        for (int j = 0; j < 4; j++) {
            m[i][j] = cal->ata[i][j];
        }
    }
    for (int k = 0; k < 3; k++) {
        const double s_ut = obs[k] ? p->magcal_ridge_ut : LOCK_SPREAD_UT;
        const double rho = 4.0 * w_n * s_ut * s_ut;
        for (int i = 0; i < 3; i++) {
            for (int j = 0; j < 3; j++) {
                m[i][j] += rho * vec[i][k] * vec[j][k];
            }
        }
    }
    double theta[4];
    if (!solve4(m, cal->aty, theta)) {
        return sf_magcal_singular;
    }
    const double b[3] = {theta[0], theta[1], theta[2]};
    const double r2 = theta[3] + dot3(b, b);
    for (int i = 0; i < 3; i++) {
        audit->candidate_offset_ut[i] = b[i];
    }
    audit->candidate_radius_ut = r2 > 0.0 ? sqrt(r2) : 0.0;
    if (!(r2 > 0.0) || !isfinite(r2) || !(sqrt(dot3(b, b)) <= p->magcal_max_offset_ut)) {
        return sf_magcal_out_of_bound;
    }
    /* consistency: Σ(y − aθ)² = Σy² − 2θᵀr + θᵀAθ (A, r without the ridge) */
    double quad = 0.0, lin = 0.0;
    for (int i = 0; i < 4; i++) {
        lin += theta[i] * cal->aty[i];
        for (int j = 0; j < 4; j++) {
            quad += theta[i] * cal->ata[i][j] * theta[j];
        }
    }
    const double ss = fmax(cal->yty - 2.0 * lin + quad, 0.0);
    audit->candidate_rms_ut = sqrt(ss / w_n) / (2.0 * sqrt(r2));
    if (!(audit->candidate_rms_ut <= p->magcal_max_rms_ut)) {
        return sf_magcal_inconsistent;
    }
    for (int i = 0; i < 3; i++) {
        b_ut[i] = b[i];
    }
    *radius_ut = sqrt(r2);
    return sf_magcal_solved;
}

void sf_magcal_update(sf_magcal_t *const cal, const sf_params_t *const p, const int64_t t_us,
                      const double field_ut[3])
{
    SF_ASSERT(cal != NULL && p != NULL && field_ut != NULL);
    if (p->magcal_enable == 0) {
        return;
    }
    sf_magcal_audit_t *const audit = &cal->last;
    *audit = (sf_magcal_audit_t){.t_us = t_us,
                                 .spread_ut = {cal->last_spread_ut[0], cal->last_spread_ut[1], cal->last_spread_ut[2]},
                                 .observed = cal->last_observed,
                                 .solve = sf_magcal_not_solved};
    if (!finite3(field_ut)) {
        audit->field_ut = (double)NAN;
        audit->corrected_ut = (double)NAN;
        reject(cal, sf_magcal_invalid);
        return;
    }
    audit->field_ut = sqrt(dot3(field_ut, field_ut));
    const double c[3] = {field_ut[0] - cal->offset_ut[0], field_ut[1] - cal->offset_ut[1],
                         field_ut[2] - cal->offset_ut[2]};
    audit->corrected_ut = sqrt(dot3(c, c));
    audit->ref_ut = cal->valid ? cal->radius_ut : p->attitude_mag_field_ut;
    audit->tol_ut = cal->valid ? p->magcal_gate_ut : p->magcal_gate_ut + p->magcal_max_offset_ut;

    /* control: time, then forgetting (rejected samples still advance the clock), then the gate */
    if (cal->started && t_us < cal->last_t_us) {
        reject(cal, sf_magcal_time);
        return;
    }
    const double lambda =
        cal->started ? sf_exp_memo(&cal->forget, -(double)(t_us - cal->last_t_us) * 1e-6 / p->magcal_tau_s) : 1.0;
    const bool forget = cal->started;
    cal->started = true;
    cal->last_t_us = t_us;
    if (!(fabs(audit->corrected_ut - audit->ref_ut) <= audit->tol_ut)) {
        if (forget) {
            for (int i = 0; i < 4; i++) {
                for (int j = 0; j < 4; j++) {
                    cal->ata[i][j] *= lambda;
                }
                cal->aty[i] *= lambda;
            }
            cal->yty *= lambda;
        }
        reject(cal, sf_magcal_gated);
        return;
    }

    /* fusion: forget, then accumulate the row a = (2m, 1), y = |m|², in one pass over the ten distinct
     * elements of the symmetric AᵀA (each element is (x·λ) + aᵢaⱼ as in two passes, and aᵢaⱼ = aⱼaᵢ
     * exactly, so the matrix stays symmetric bit for bit; aᵢ·1 is aᵢ). Without forgetting λ = 1 and
     * x·1 = x: the same numbers as the accumulation alone. */
    const double a[4] = {2.0 * field_ut[0], 2.0 * field_ut[1], 2.0 * field_ut[2], 1.0};
    const double y = audit->field_ut * audit->field_ut;
    /* written out: gcc -O2 keeps the triangular loops, whose counters cost as much as the sums */
    cal->ata[0][0] = cal->ata[0][0] * lambda + a[0] * a[0];
    cal->ata[0][1] = cal->ata[1][0] = cal->ata[0][1] * lambda + a[0] * a[1];
    cal->ata[0][2] = cal->ata[2][0] = cal->ata[0][2] * lambda + a[0] * a[2];
    cal->ata[0][3] = cal->ata[3][0] = cal->ata[0][3] * lambda + a[0];
    cal->ata[1][1] = cal->ata[1][1] * lambda + a[1] * a[1];
    cal->ata[1][2] = cal->ata[2][1] = cal->ata[1][2] * lambda + a[1] * a[2];
    cal->ata[1][3] = cal->ata[3][1] = cal->ata[1][3] * lambda + a[1];
    cal->ata[2][2] = cal->ata[2][2] * lambda + a[2] * a[2];
    cal->ata[2][3] = cal->ata[3][2] = cal->ata[2][3] * lambda + a[2];
    cal->ata[3][3] = cal->ata[3][3] * lambda + 1.0;
    for (int i = 0; i < 4; i++) {
        cal->aty[i] = cal->aty[i] * lambda + a[i] * y;
    }
    cal->yty = cal->yty * lambda + y * y;
    cal->samples_used++;
    cal->by_sample[sf_magcal_used]++;
    audit->sample = sf_magcal_used;

    double b[3] = {0.0, 0.0, 0.0};
    double radius_ut = 0.0;
    sf_magcal_solve_verdict_t v = sf_magcal_deferred;
    if (++cal->used_since_solve >= SF_MAGCAL_SOLVE_EVERY) {
        cal->used_since_solve = 0;
        v = solve(cal, p, audit, b, &radius_ut);
        for (int k = 0; k < 3; k++) {
            cal->last_spread_ut[k] = audit->spread_ut[k];
        }
        cal->last_observed = audit->observed;
    }
    audit->solve = v;
    cal->by_solve[v]++;
    if (v == sf_magcal_solved) {
        for (int i = 0; i < 3; i++) {
            cal->offset_ut[i] = b[i];
        }
        cal->radius_ut = radius_ut;
        cal->valid = true;
    } else if (v == sf_magcal_inconsistent && !cal->valid) {
        /* control: a disturbance is in the bootstrap memory; start again (header: time-wise RANSAC) */
        for (int i = 0; i < 4; i++) {
            for (int j = 0; j < 4; j++) {
                cal->ata[i][j] = 0.0;
            }
            cal->aty[i] = 0.0;
        }
        cal->yty = 0.0;
        cal->restarts++;
        audit->restarted = true;
    }
}

void sf_magcal_apply(const sf_magcal_t *const cal, const double field_ut[3], double corrected_ut[3])
{
    for (int i = 0; i < 3; i++) {
        corrected_ut[i] = field_ut[i] - cal->offset_ut[i];
    }
}
