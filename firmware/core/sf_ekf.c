/* sf_ekf.c — the `ekf` scheme's filter (see sf_ekf.h for the model). Plain loops over 6×6 and 2×2
 * arrays: small enough that a matrix library would cost more than it saves. */
#include "sf_ekf.h"

#include <math.h>

#include "sf_assert.h"
#include "sf_math.h"

enum { n = SF_EKF_N, ix = 0, iy = 1, ib = 2, is = 3, icx = 4, icy = 5 };

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

/* P ← A P Aᵀ (A n×n). */
static void congruence(sf_ekf_t *const e, double A[n][n]) /* not const: C11 forbids the conversion */
{
    double AP[n][n] = {{0}};
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            for (int k = 0; k < n; k++) {
                AP[i][j] += A[i][k] * e->P[k][j];
            }
        }
    }
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            double v = 0.0;
            for (int k = 0; k < n; k++) {
                v += AP[i][k] * A[j][k];
            }
            e->P[i][j] = v;
        }
    }
}

static double min_eigen2(const double m[3])
{
    const double half = 0.5 * (m[0] - m[2]);
    return 0.5 * (m[0] + m[2]) - sqrt(half * half + m[1] * m[1]);
}

/* Keeps a symmetric 2×2 [xx, xy, yy]'s eigenvalues in [lo, hi] (closed form). */
static void clamp_eigen2(double m[3], const double lo, const double hi)
{
    const double mean = 0.5 * (m[0] + m[2]);
    const double half = 0.5 * (m[0] - m[2]);
    const double rad = sqrt(half * half + m[1] * m[1]);
    const double l1 = sf_clamp(mean + rad, lo, hi), l2 = sf_clamp(mean - rad, lo, hi);
    const double phi = rad > 0.0 ? 0.5 * atan2(m[1], half) : 0.0; /* the larger eigenvalue's direction */
    const double c = cos(phi), s = sin(phi);
    m[0] = l1 * c * c + l2 * s * s;
    m[1] = (l1 - l2) * c * s;
    m[2] = l1 * s * s + l2 * c * c;
}

/* σ_c²: c's stationary variance per axis. */
static double c_var(const sf_ekf_t *const e)
{
    return e->bias_sigma_m * e->bias_sigma_m;
}

/* Clears the rows and columns of P from index `first` through `last`. */
static void clear_rows(sf_ekf_t *const e, const int first, const int last)
{
    for (int i = first; i <= last; i++) {
        for (int j = 0; j < n; j++) {
            e->P[i][j] = 0.0;
            e->P[j][i] = 0.0;
        }
    }
}

/* Clears the rows and columns of the position and c, and c itself. */
static void clear_position_and_bias(sf_ekf_t *const e)
{
    clear_rows(e, ix, iy);
    clear_rows(e, icx, icy);
    e->fix_bias_m[0] = e->fix_bias_m[1] = 0.0;
}

/* The fix-error model's constants: M (the prior of the learning) and the correlated part. */
static void set_model(sf_ekf_t *const e, const sf_params_t *const p, const double floor_cov_m2[3],
                      const double cov_per_acc2[3], const double bias_sigma_m, const double bias_length_m,
                      const double white_share)
{
    for (int i = 0; i < 3; i++) {
        e->fix_model[i] = cov_per_acc2[i];
        e->fix_floor_m2[i] = floor_cov_m2[i];
    }
    clamp_eigen2(e->fix_floor_m2, 0.0, INFINITY);
    clamp_eigen2(e->fix_model, p->ekf_r_min, p->ekf_r_max);
    e->model_floor = min_eigen2(e->fix_model);
    e->model_fixes = 0;
    e->bias_sigma_m = bias_sigma_m;
    e->bias_length_m = bias_length_m;
    e->white_share = white_share;
}

void sf_ekf_start(sf_ekf_t *const e, const sf_params_t *const p)
{
    SF_ASSERT(e != NULL && p != NULL);
    *e = (sf_ekf_t){.heading_bias_rad = 0.0, .stride_scale = 1.0};
    e->P[ib][ib] = p->ekf_init_bias_sigma_rad * p->ekf_init_bias_sigma_rad;
    e->P[is][is] = p->ekf_init_scale_sigma * p->ekf_init_scale_sigma;
    const double m[3] = {p->ekf_fix_var_x_per_acc2, p->ekf_fix_cov_xy_per_acc2, p->ekf_fix_var_y_per_acc2};
    const double f[3] = {p->ekf_fix_floor_xx_m2, p->ekf_fix_floor_xy_m2, p->ekf_fix_floor_yy_m2};
    set_model(e, p, f, m, p->ekf_fix_bias_sigma_m, p->ekf_fix_bias_length_m, p->ekf_fix_white_share);
    e->P[icx][icx] = e->P[icy][icy] = c_var(e);
}

void sf_ekf_use_site_model(sf_ekf_t *const e, const sf_params_t *const p, const sf_fix_model_t *const model)
{
    if (model == NULL || !model->valid) {
        return;
    }
    set_model(e, p, model->floor_cov_m2, model->cov_per_acc2, model->bias_sigma_m, model->bias_length_m,
              model->white_share);
    /* c starts afresh with the site's σ_c, uncorrelated (a start before any fix) */
    clear_rows(e, icx, icy);
    e->fix_bias_m[0] = e->fix_bias_m[1] = 0.0;
    e->P[icx][icx] = e->P[icy][icy] = c_var(e);
}

void sf_ekf_restart_at_fix(sf_ekf_t *const e, const double r_white_m2[3])
{
    SF_ASSERT(e != NULL && r_white_m2 != NULL);
    clear_position_and_bias(e);
    const double c2 = c_var(e);
    e->P[ix][ix] = r_white_m2[0] + c2;
    e->P[ix][iy] = e->P[iy][ix] = r_white_m2[1];
    e->P[iy][iy] = r_white_m2[2] + c2;
    e->P[icx][icx] = e->P[icy][icy] = c2;
    e->P[ix][icx] = e->P[icx][ix] = -c2; /* p = z − c − w: its error is −(c + w) */
    e->P[iy][icy] = e->P[icy][iy] = -c2;
}

void sf_ekf_restart_known(sf_ekf_t *const e, const double pos_cov_m2[3])
{
    /* the caller's σ² (sf_fusion_init_at refuses a σ that is not finite and ≥ 0) */
    SF_ASSERT(e != NULL && pos_cov_m2 != NULL && pos_cov_m2[0] >= 0.0 && pos_cov_m2[2] >= 0.0);
    clear_position_and_bias(e);
    const double c2 = c_var(e);
    e->P[ix][ix] = pos_cov_m2[0];
    e->P[ix][iy] = e->P[iy][ix] = pos_cov_m2[1];
    e->P[iy][iy] = pos_cov_m2[2];
    e->P[icx][icx] = e->P[icy][icy] = c2;
}

void sf_ekf_step(sf_ekf_t *const e, const sf_params_t *const p, const double length_m, const double heading_rad,
                 double d_m[2])
{
    SF_ASSERT(e != NULL && p != NULL && d_m != NULL);
    SF_ASSERT(isfinite(length_m) && length_m >= 0.0); /* sf_fusion counts and skips any other step */
    const double s = e->stride_scale, theta = heading_rad + e->heading_bias_rad;
    const double c = cos(theta), sn = sin(theta), sl = s * length_m;
    d_m[0] = sl * c;
    d_m[1] = sl * sn;
    /* c decorrelates with the distance walked */
    const double phi = e->bias_length_m > 0.0 ? exp(-sl / e->bias_length_m) : 0.0;
    e->fix_bias_m[0] *= phi;
    e->fix_bias_m[1] *= phi;
    double F[n][n] = {{0}};
    for (int i = 0; i < n; i++) {
        F[i][i] = 1.0;
    }
    F[ix][ib] = -sl * sn;
    F[ix][is] = length_m * c;
    F[iy][ib] = sl * c;
    F[iy][is] = length_m * sn;
    F[icx][icx] = F[icy][icy] = phi;
    congruence(e, F);
    /* step noise: along the step (length) and across it (direction) */
    const double sa = s * p->ekf_step_length_sigma * length_m, sc = sl * p->ekf_step_heading_sigma_rad;
    const double along = sa * sa, across = sc * sc;
    e->P[ix][ix] += along * c * c + across * sn * sn;
    e->P[ix][iy] += (along - across) * c * sn;
    e->P[iy][ix] += (along - across) * c * sn;
    e->P[iy][iy] += along * sn * sn + across * c * c;
    e->P[ib][ib] += p->ekf_bias_rw_rad2_per_m * length_m;
    e->P[is][is] += p->ekf_scale_rw_per_m * length_m;
    const double qc = (1.0 - phi * phi) * e->bias_sigma_m * e->bias_sigma_m;
    e->P[icx][icx] += qc;
    e->P[icy][icy] += qc;
    symmetrise(e);
}

void sf_ekf_time(sf_ekf_t *const e, const sf_params_t *const p, const double dt_s)
{
    SF_ASSERT(e != NULL && p != NULL);
    if (dt_s > 0.0) {
        e->P[ix][ix] += p->fusion_q_time_m2_per_s * dt_s;
        e->P[iy][iy] += p->fusion_q_time_m2_per_s * dt_s;
    }
}

static double kappa(const bool correlated)
{
    return correlated ? 1.0 : 0.0;
}

void sf_ekf_fix_total(const sf_ekf_t *const e, const double accuracy_m, double total_m2[3])
{
    /* only a usable fix gets here: sf_fusion refuses one whose accuracy is not finite and ≥ 0 */
    SF_ASSERT(e != NULL && total_m2 != NULL && isfinite(accuracy_m) && accuracy_m >= 0.0);
    const double a2 = accuracy_m * accuracy_m;
    for (int i = 0; i < 3; i++) {
        total_m2[i] = e->fix_floor_m2[i] + a2 * e->fix_model[i];
    }
}

void sf_ekf_fix_r(const sf_ekf_t *const e, const sf_params_t *const p, const double accuracy_m,
                  double r_white_m2[3])
{
    SF_ASSERT(p != NULL && r_white_m2 != NULL);
    const double c2 = c_var(e);
    double total[3];
    sf_ekf_fix_total(e, accuracy_m, total);
    r_white_m2[0] = total[0] - c2;
    r_white_m2[1] = total[1];
    r_white_m2[2] = total[2] - c2;
    /* a fix better than the median keeps its white share: c's variance is one figure for all fixes */
    const double white_min = e->white_share * min_eigen2(total);
    clamp_eigen2(r_white_m2, fmax(p->fusion_var_min_m2, white_min), INFINITY);
}

void sf_ekf_innovation(const sf_ekf_t *const e, const bool correlated, double nu_m[2])
{
    nu_m[0] -= kappa(correlated) * e->fix_bias_m[0];
    nu_m[1] -= kappa(correlated) * e->fix_bias_m[1];
}

/* H P Hᵀ, H = [I 0 0 κI] (κ = 1 for a Wi-Fi fix, which carries c; 0 for the other sources): the
 * covariance of p + κc [xx, xy, yy]. */
static void hph(const sf_ekf_t *const e, const double k, double m[3])
{
    m[0] = e->P[ix][ix] + 2.0 * k * e->P[ix][icx] + k * k * e->P[icx][icx];
    m[1] = e->P[ix][iy] + k * (e->P[ix][icy] + e->P[icx][iy]) + k * k * e->P[icx][icy];
    m[2] = e->P[iy][iy] + 2.0 * k * e->P[iy][icy] + k * k * e->P[icy][icy];
}


double sf_ekf_nis(const sf_ekf_t *const e, const bool correlated, const double nu_m[2], const double r_white_m2[3],
                  double s_m2[3])
{
    SF_ASSERT(e != NULL && nu_m != NULL && r_white_m2 != NULL && s_m2 != NULL);
    hph(e, kappa(correlated), s_m2);
    for (int i = 0; i < 3; i++) {
        s_m2[i] += r_white_m2[i];
    }
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
    double r_m2[3], s_m2[3], m[3];
    sf_ekf_fix_r(e, p, accuracy_m, r_m2);
    const double nis = sf_ekf_nis(e, true, nu_m, r_m2, s_m2);
    /* an innovation beyond the gate enters shrunk onto it: evidence that R is too small, bounded */
    const double k = isfinite(nis) && nis > nis_max ? sqrt(nis_max / nis) : 1.0;
    const double vx = k * nu_m[0], vy = k * nu_m[1], a2 = accuracy_m * accuracy_m;
    const double c2 = c_var(e);
    hph(e, 1.0, m);
    /* E[ννᵀ] = H P Hᵀ + F + a²M − σ_c² I, solved for M */
    const double *const f = e->fix_floor_m2;
    const double sample[3] = {(vx * vx - m[0] + c2 - f[0]) / a2, (vx * vy - m[1] - f[1]) / a2,
                              (vy * vy - m[2] + c2 - f[2]) / a2};
    e->model_fixes++;
    const double w = 1.0 / fmin((double)e->model_fixes + 1.0, (double)p->ekf_r_window); /* +1: the prior */
    for (int i = 0; i < 3; i++) {
        e->fix_model[i] += w * (sample[i] - e->fix_model[i]);
    }
    clamp_eigen2(e->fix_model, e->model_floor, p->ekf_r_max);
}

double sf_ekf_update(sf_ekf_t *const e, const sf_params_t *const p, const bool correlated, const double nu_m[2],
                     const double r_white_m2[3], double dpos_m[2])
{
    SF_ASSERT(p != NULL && dpos_m != NULL); /* e, nu_m, r_white_m2: sf_ekf_nis's */
    const double k = kappa(correlated);
    double s_m2[3];
    (void)sf_ekf_nis(e, correlated, nu_m, r_white_m2, s_m2);
    const double det = s_m2[0] * s_m2[2] - s_m2[1] * s_m2[1];
    const double Si[2][2] = {{s_m2[2] / det, -s_m2[1] / det}, {-s_m2[1] / det, s_m2[0] / det}};
    /* P Hᵀ: the columns x + κc_x and y + κc_y */
    double W[n][2];
    for (int i = 0; i < n; i++) {
        const double ph0 = e->P[i][ix] + k * e->P[i][icx], ph1 = e->P[i][iy] + k * e->P[i][icy];
        W[i][0] = ph0 * Si[0][0] + ph1 * Si[1][0];
        W[i][1] = ph0 * Si[0][1] + ph1 * Si[1][1];
    }
    double delta[n];
    for (int i = 0; i < n; i++) {
        delta[i] = W[i][0] * nu_m[0] + W[i][1] * nu_m[1];
    }
    /* Joseph form: P ← A P Aᵀ + W R Wᵀ, A = I − W H */
    double A[n][n];
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            const double hx = j == ix ? 1.0 : (j == icx ? k : 0.0), hy = j == iy ? 1.0 : (j == icy ? k : 0.0);
            const double wh = W[i][0] * hx + W[i][1] * hy;
            A[i][j] = (i == j ? 1.0 : 0.0) - wh;
        }
    }
    congruence(e, A);
    const double R[2][2] = {{r_white_m2[0], r_white_m2[1]}, {r_white_m2[1], r_white_m2[2]}};
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            for (int a = 0; a < 2; a++) {
                for (int b = 0; b < 2; b++) {
                    e->P[i][j] += W[i][a] * R[a][b] * W[j][b];
                }
            }
        }
    }
    symmetrise(e);
    /* closed-loop reset: the error state goes into the nominal one and back to zero */
    dpos_m[0] = delta[ix];
    dpos_m[1] = delta[iy];
    e->heading_bias_rad = atan2(sin(e->heading_bias_rad + delta[ib]), cos(e->heading_bias_rad + delta[ib]));
    e->stride_scale = sf_clamp(e->stride_scale + delta[is], p->ekf_scale_min, p->ekf_scale_max);
    e->fix_bias_m[0] += delta[icx];
    e->fix_bias_m[1] += delta[icy];
    return 0.5 * (W[ix][0] + W[iy][1]);
}
