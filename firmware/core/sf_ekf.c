/* sf_ekf.c — the `ekf` scheme's filter (see sf_ekf.h for the model). Plain loops over 4×4 and 2×2
 * arrays: small enough that a matrix library would cost more than it saves. */
#include "sf_ekf.h"

#include <math.h>

enum { n = 4 }; /* [δx, δy, δb, δs] */

static double clamp(const double v, const double lo, const double hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

static void symmetrise(sf_ekf_t *const e)
{
    for (int i = 0; i < n; i++) {
        for (int j = i + 1; j < n; j++) {
            const double m = 0.5 * (e->P[i][j] + e->P[j][i]);
            e->P[i][j] = m;
            e->P[j][i] = m;
        }
    }
}

/* Keeps a symmetric 2×2 [xx, xy, yy]'s eigenvalues in [lo, hi] (closed form). */
static void clamp_eigen2(double m[3], const double lo, const double hi)
{
    const double mean = 0.5 * (m[0] + m[2]);
    const double half = 0.5 * (m[0] - m[2]);
    const double rad = sqrt(half * half + m[1] * m[1]);
    const double l1 = clamp(mean + rad, lo, hi), l2 = clamp(mean - rad, lo, hi);
    /* eigenvector angle of the larger eigenvalue */
    const double phi = rad > 0.0 ? 0.5 * atan2(m[1], half) : 0.0;
    const double c = cos(phi), s = sin(phi);
    m[0] = l1 * c * c + l2 * s * s;
    m[1] = (l1 - l2) * c * s;
    m[2] = l1 * s * s + l2 * c * c;
}

static double min_eigen2(const double m[3])
{
    const double half = 0.5 * (m[0] - m[2]);
    return 0.5 * (m[0] + m[2]) - sqrt(half * half + m[1] * m[1]);
}

static void set_position_block(sf_ekf_t *const e, const double pos_cov_m2[3])
{
    for (int i = 0; i < 2; i++) {
        for (int j = 0; j < n; j++) {
            e->P[i][j] = 0.0;
            e->P[j][i] = 0.0;
        }
    }
    e->P[0][0] = pos_cov_m2[0];
    e->P[0][1] = e->P[1][0] = pos_cov_m2[1];
    e->P[1][1] = pos_cov_m2[2];
}

void sf_ekf_start(sf_ekf_t *const e, const sf_params_t *const p, const double pos_cov_m2[3])
{
    *e = (sf_ekf_t){.heading_bias_rad = 0.0, .stride_scale = 1.0};
    set_position_block(e, pos_cov_m2);
    e->P[2][2] = p->ekf_init_bias_sigma_rad * p->ekf_init_bias_sigma_rad;
    e->P[3][3] = p->ekf_init_scale_sigma * p->ekf_init_scale_sigma;
    e->fix_model[0] = p->ekf_fix_var_x_per_acc2;
    e->fix_model[1] = p->ekf_fix_cov_xy_per_acc2;
    e->fix_model[2] = p->ekf_fix_var_y_per_acc2;
    clamp_eigen2(e->fix_model, p->ekf_r_min, p->ekf_r_max);
    e->model_floor = min_eigen2(e->fix_model);
}

void sf_ekf_restart_position(sf_ekf_t *const e, const double pos_cov_m2[3])
{
    set_position_block(e, pos_cov_m2);
}

void sf_ekf_step(sf_ekf_t *const e, const sf_params_t *const p, const double length_m, const double heading_rad,
                 double d_m[2])
{
    const double s = e->stride_scale, theta = heading_rad + e->heading_bias_rad;
    const double c = cos(theta), sn = sin(theta), sl = s * length_m;
    d_m[0] = sl * c;
    d_m[1] = sl * sn;
    /* F = I + the columns of ∂d/∂b and ∂d/∂s in rows 0 and 1 */
    double F[n][n] = {{1, 0, -sl * sn, length_m * c}, {0, 1, sl * c, length_m * sn}, {0, 0, 1, 0}, {0, 0, 0, 1}};
    double FP[n][n] = {{0}};
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            for (int k = 0; k < n; k++) {
                FP[i][j] += F[i][k] * e->P[k][j];
            }
        }
    }
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            double v = 0.0;
            for (int k = 0; k < n; k++) {
                v += FP[i][k] * F[j][k];
            }
            e->P[i][j] = v;
        }
    }
    /* step noise: along the step (length) and across it (direction) */
    const double along = (s * p->ekf_step_length_sigma * length_m) * (s * p->ekf_step_length_sigma * length_m);
    const double across = (sl * p->ekf_step_heading_sigma_rad) * (sl * p->ekf_step_heading_sigma_rad);
    e->P[0][0] += along * c * c + across * sn * sn;
    e->P[0][1] += (along - across) * c * sn;
    e->P[1][0] += (along - across) * c * sn;
    e->P[1][1] += along * sn * sn + across * c * c;
    e->P[2][2] += p->ekf_bias_rw_rad2_per_m * length_m;
    e->P[3][3] += p->ekf_scale_rw_per_m * length_m;
    symmetrise(e);
}

void sf_ekf_time(sf_ekf_t *const e, const sf_params_t *const p, const double dt_s)
{
    if (dt_s > 0.0) {
        e->P[0][0] += p->fusion_q_time_m2_per_s * dt_s;
        e->P[1][1] += p->fusion_q_time_m2_per_s * dt_s;
    }
}

void sf_ekf_fix_r(const sf_ekf_t *const e, const sf_params_t *const p, const double accuracy_m, double r_m2[3])
{
    const double a2 = accuracy_m * accuracy_m;
    r_m2[0] = fmax(a2 * e->fix_model[0], p->fusion_var_min_m2);
    r_m2[1] = a2 * e->fix_model[1];
    r_m2[2] = fmax(a2 * e->fix_model[2], p->fusion_var_min_m2);
    /* keep R positive definite after the floors */
    const double lim = sqrt(r_m2[0] * r_m2[2]) * 0.999;
    r_m2[1] = clamp(r_m2[1], -lim, lim);
}

void sf_ekf_update_r(const sf_ekf_t *const e, const sf_params_t *const p, const double accuracy_m,
                     double r_m2[3])
{
    sf_ekf_fix_r(e, p, accuracy_m, r_m2);
    for (int i = 0; i < 3; i++) {
        r_m2[i] *= p->ekf_fix_run_factor;
    }
}

double sf_ekf_nis(const sf_ekf_t *const e, const double nu_m[2], const double r_m2[3], double s_m2[3])
{
    s_m2[0] = e->P[0][0] + r_m2[0];
    s_m2[1] = e->P[0][1] + r_m2[1];
    s_m2[2] = e->P[1][1] + r_m2[2];
    const double det = s_m2[0] * s_m2[2] - s_m2[1] * s_m2[1];
    if (!(det > 0.0)) {
        return INFINITY;
    }
    return (s_m2[2] * nu_m[0] * nu_m[0] - 2.0 * s_m2[1] * nu_m[0] * nu_m[1] + s_m2[0] * nu_m[1] * nu_m[1]) / det;
}

void sf_ekf_learn_fix_model(sf_ekf_t *const e, const sf_params_t *const p, const double nu_m[2],
                            const double accuracy_m, const double nis_max)
{
    if (!(accuracy_m > 0.0) || p->ekf_r_window <= 0) {
        return;
    }
    double r_m2[3], s_m2[3];
    sf_ekf_fix_r(e, p, accuracy_m, r_m2);
    const double nis = sf_ekf_nis(e, nu_m, r_m2, s_m2);
    /* an innovation beyond the gate enters shrunk onto it: evidence that R is too small, bounded */
    const double k = isfinite(nis) && nis > nis_max ? sqrt(nis_max / nis) : 1.0;
    const double vx = k * nu_m[0], vy = k * nu_m[1], a2 = accuracy_m * accuracy_m;
    const double sample[3] = {(vx * vx - e->P[0][0]) / a2, (vx * vy - e->P[0][1]) / a2,
                              (vy * vy - e->P[1][1]) / a2};
    e->model_fixes++;
    const double w = 1.0 / fmin((double)e->model_fixes + 1.0, (double)p->ekf_r_window); /* +1: the prior */
    for (int i = 0; i < 3; i++) {
        e->fix_model[i] += w * (sample[i] - e->fix_model[i]);
    }
    clamp_eigen2(e->fix_model, e->model_floor, p->ekf_r_max);
}

double sf_ekf_update(sf_ekf_t *const e, const sf_params_t *const p, const double nu_m[2], const double r_m2[3],
                     double dpos_m[2])
{
    double s_m2[3];
    (void)sf_ekf_nis(e, nu_m, r_m2, s_m2);
    const double det = s_m2[0] * s_m2[2] - s_m2[1] * s_m2[1];
    const double Si[2][2] = {{s_m2[2] / det, -s_m2[1] / det}, {-s_m2[1] / det, s_m2[0] / det}};
    double W[n][2];
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < 2; j++) {
            W[i][j] = e->P[i][0] * Si[0][j] + e->P[i][1] * Si[1][j];
        }
    }
    double delta[n];
    for (int i = 0; i < n; i++) {
        delta[i] = W[i][0] * nu_m[0] + W[i][1] * nu_m[1];
    }
    /* Joseph form: P ← A P Aᵀ + W R Wᵀ, A = I − W H */
    double A[n][n], AP[n][n] = {{0}};
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            A[i][j] = (i == j ? 1.0 : 0.0) - (j < 2 ? W[i][j] : 0.0);
        }
    }
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            for (int k = 0; k < n; k++) {
                AP[i][j] += A[i][k] * e->P[k][j];
            }
        }
    }
    const double R[2][2] = {{r_m2[0], r_m2[1]}, {r_m2[1], r_m2[2]}};
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            double v = 0.0;
            for (int k = 0; k < n; k++) {
                v += AP[i][k] * A[j][k];
            }
            for (int a = 0; a < 2; a++) {
                for (int b = 0; b < 2; b++) {
                    v += W[i][a] * R[a][b] * W[j][b];
                }
            }
            e->P[i][j] = v;
        }
    }
    symmetrise(e);
    /* closed-loop reset: the error state goes into the nominal one and back to zero */
    dpos_m[0] = delta[0];
    dpos_m[1] = delta[1];
    e->heading_bias_rad = atan2(sin(e->heading_bias_rad + delta[2]), cos(e->heading_bias_rad + delta[2]));
    e->stride_scale = clamp(e->stride_scale + delta[3], p->ekf_scale_min, p->ekf_scale_max);
    return 0.5 * (W[0][0] + W[1][1]);
}
