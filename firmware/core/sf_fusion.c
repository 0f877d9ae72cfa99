/* sf_fusion.c — see sf_fusion.h for the model. Layout: the fusion math (prediction, innovation, α,
 * blend) first, then the control (judge), then the public calls; sf_fusion_fix() reads top to bottom
 * like PX4's aid-source update(): predict, innovate, judge, apply, record. */
#include "sf_fusion.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "sf_assert.h"
#include "sf_error.h"
#include "sf_fusion_internal.h"

static double us_to_s(const int64_t dt_us)
{
    return (double)dt_us / 1e6; /* correctly rounded: whole seconds come out exact */
}

static int16_t to_floor(const int32_t v)
{
    return (int16_t)(v < INT16_MIN ? INT16_MIN : (v > INT16_MAX ? INT16_MAX : v));
}

static const sf_scheme_row_t *row_of(const sf_fusion_t *const f)
{
    return sf_fusion_row(f->scheme);
}

static bool blends(const sf_fusion_t *const f)
{
    return row_of(f)->mode == mode_blend;
}

static bool predicts(const sf_fusion_t *const f)
{
    return row_of(f)->mode != mode_follow_fixes;
}

static bool is_ekf(const sf_fusion_t *const f)
{
    return row_of(f)->mode == mode_ekf;
}

static bool is_particle(const sf_fusion_t *const f)
{
    return row_of(f)->mode == mode_particle;
}

/* An isotropic variance as a covariance [xx, xy, yy]. */
static void iso_cov(const double var_m2, double cov_m2[3])
{
    cov_m2[0] = var_m2;
    cov_m2[1] = 0.0;
    cov_m2[2] = var_m2;
}

static int16_t scheme_floor(const sf_fusion_t *const f, const int16_t baro_floor)
{
    if (row_of(f)->mode == mode_follow_fixes) {
        return to_floor(f->floor_offset);
    }
    return to_floor((int32_t)baro_floor + f->floor_offset);
}

/* ---- fusion: the math ---------------------------------------------------------------------------- */

/* A fresh ekf filter: the parameters' priors, then the site's fix model if it measured one. */
static void start_ekf(sf_fusion_t *const f, const sf_params_t *const p)
{
    sf_ekf_start(&f->ekf, p);
    sf_ekf_use_site_model(&f->ekf, p, f->fix_model);
}

/* Time update of the variance up to t_us (Δt < 0 counts as backwards and adds nothing). */
static void predict_to(sf_fusion_t *const f, const sf_params_t *const p, const int64_t t_us)
{
    if (f->t_us == SF_FUSION_T_FIRST_INPUT) { /* a config start: its time is the first input's */
        f->t_us = t_us;
        f->last_fix_t_us = t_us;
        return;
    }
    if (t_us < f->t_us) {
        f->backwards++;
        return;
    }
    if (f->initialised && is_ekf(f)) {
        sf_ekf_time(&f->ekf, p, us_to_s(t_us - f->t_us));
    } else if (f->initialised && predicts(f) && !is_particle(f)) {
        f->var_m2 += p->fusion_q_time_m2_per_s * us_to_s(t_us - f->t_us);
    }
    f->t_us = t_us;
}

/* The scheme's blend weight for an accepted fix (its row's gain law). */
static double scheme_alpha(const sf_fusion_t *const f, const sf_params_t *const p, const sf_fix_t *const fix,
                           const double r_m2, sf_fix_audit_t *const audit)
{
    return row_of(f)->alpha(f, p, fix, r_m2, audit);
}

/* position ← position + α·ν; variance of the blend (Kalman form for kalman, Joseph form otherwise). */
static void blend(sf_fusion_t *const f, const sf_params_t *const p, const double alpha, const double nu_x,
                  const double nu_y, const double r_m2)
{
    f->x_m += alpha * nu_x;
    f->y_m += alpha * nu_y;
    const double keep = 1.0 - alpha;
    const double var =
        row_of(f)->kalman_variance ? keep * f->var_m2 : keep * keep * f->var_m2 + alpha * alpha * r_m2;
    f->var_m2 = fmax(var, p->fusion_var_min_m2);
}

/* position ← fix, variance ← R, floor from the fix: initialisation, recovery, wifi_only. The ekf's
 * position block restarts at its 2×2 R (ekf_r_m2), bias and scale keep what they learnt. */
static void reset_to_fix(sf_fusion_t *const f, const sf_params_t *const p, const sf_fix_t *const fix,
                         const double r_m2, const double ekf_r_m2[3])
{
    f->initialised = true;
    f->x_m = fix->x_m;
    f->y_m = fix->y_m;
    f->var_m2 = fmax(r_m2, p->fusion_var_min_m2);
    if (is_ekf(f)) {
        sf_ekf_restart_at_fix(&f->ekf, ekf_r_m2);
    }
    f->floor_offset = predicts(f) ? 0 : (int32_t)fix->floor; /* the caller's floor is the floor */
}

/* ---- control: which fixes to fuse ---------------------------------------------------------------- */

/* The decision for an initialised scheme, from the named conditions of the header. */
static int8_t judge(const sf_fusion_t *const f, const sf_params_t *const p, const sf_fix_t *const fix,
                    const double test_ratio, const bool between_floors)
{
    if (row_of(f)->mode == mode_dead_reckoning) {
        return sf_fix_reason_scheme_ignores;
    }
    if (row_of(f)->mode == mode_follow_fixes) {
        return sf_fix_reason_accepted; /* no gate: the scheme is the fixes */
    }
    /* a landmark is not a measurement to doubt: the walker is there (a tag is read within centimetres,
     * on its floor), however far the dead reckoning has drifted */
    if (sf_fix_is_known_position(fix->method)) {
        return sf_fix_reason_accepted;
    }
    /* The floor: between floors no fix is of the map's floors; on a floor, the fix's floor is one vote
     * on the caller's floor (sf_floor_vote.h) and its position is judged on the gate like any other (a
     * radio map's floor guess fails far more often than its position; sf_fusion.h, Floors). */
    if (between_floors) {
        return sf_fix_reason_floor_mismatch;
    }
    if (test_ratio <= 1.0) {
        return sf_fix_reason_accepted;
    }
    if (f->rejections >= p->fusion_max_rejections) {
        return sf_fix_reason_recovery;
    }
    return sf_fix_reason_gate;
}

static bool fix_usable(const sf_fix_t *const fix)
{
    const bool method_ok =
        fix->method == sf_fix_wifi || fix->method == sf_fix_gnss || fix->method == sf_fix_landmark ||
        fix->method == sf_fix_ble || fix->method == sf_fix_port;
    return method_ok && isfinite(fix->x_m) && isfinite(fix->y_m) && isfinite(fix->accuracy_m) &&
           fix->accuracy_m >= 0.0;
}

static void audit_begin(sf_fix_audit_t *const a, const sf_fusion_t *const f, const sf_fix_t *const fix)
{
    *a = (sf_fix_audit_t){
        .t_us = fix->t_us,
        .method = fix->method,
        .x_m = fix->x_m,
        .y_m = fix->y_m,
        .floor = fix->floor,
        .accuracy_m = fix->accuracy_m,
        .n_ap_used = fix->n_ap_used,
        .scheme = f->scheme,
        .accepted = false,
        .reason = sf_fix_reason_gate,
    };
}

/* ---- public -------------------------------------------------------------------------------------- */

int sf_fusion_init(sf_fusion_t *const f, const int8_t scheme)
{
    if (f == NULL || scheme < 0 || scheme >= sf_scheme_count) {
        return SF_EINVAL;
    }
    *f = (sf_fusion_t){.scheme = scheme, .initialised = false, .var_m2 = 0.0};
    return SF_OK;
}

int sf_fusion_init_at(sf_fusion_t *const f, const sf_params_t *const p, const int64_t t_us, const double x_m,
                      const double y_m, const int16_t floor, const double sigma_m, const int16_t baro_floor)
{
    if (!(isfinite(x_m) && isfinite(y_m) && isfinite(sigma_m) && sigma_m >= 0.0)) {
        return SF_EINVAL;
    }
    f->initialised = true;
    f->x_m = x_m;
    f->y_m = y_m;
    f->var_m2 = fmax(sigma_m * sigma_m, p->fusion_var_min_m2);
    if (is_ekf(f)) {
        double cov_m2[3];
        iso_cov(f->var_m2, cov_m2);
        start_ekf(f, p);
        sf_ekf_restart_known(&f->ekf, cov_m2);
    }
    if (is_particle(f)) {
        sf_fusion_particle_init_at(f, p, x_m, y_m, sigma_m, baro_floor);
    }
    f->floor_offset = predicts(f) ? 0 : (int32_t)floor;
    f->t_us = t_us;
    f->last_fix_t_us = t_us;
    f->rejections = 0;
    f->initialisations++;
    return SF_OK;
}

void sf_fusion_step(sf_fusion_t *const f, const sf_params_t *const p, const int64_t t_us, const double dx_m,
                    const double dy_m, const double length_m)
{
    sf_fusion_step_on_floor(f, p, t_us, dx_m, dy_m, length_m, SF_FUSION_FLOOR_KEEP);
}

void sf_fusion_step_on_floor(sf_fusion_t *const f, const sf_params_t *const p, const int64_t t_us, const double dx_m,
                             const double dy_m, const double length_m, const int16_t baro_floor)
{
    SF_ASSERT(f != NULL && p != NULL);
    if (!predicts(f)) {
        return; /* wifi_only ignores steps */
    }
    if (!(isfinite(dx_m) && isfinite(dy_m) && isfinite(length_m) && length_m >= 0.0)) {
        f->bad_steps++;
        return;
    }
    predict_to(f, p, t_us);
    if (!f->initialised) {
        return; /* nothing to move yet */
    }
    if (is_particle(f)) {
        sf_fusion_particle_step(f, p, dx_m, dy_m, length_m, baro_floor);
    } else if (is_ekf(f)) { /* the filter applies its learnt bias and scale to the PDR step */
        double d_m[2];
        sf_ekf_step(&f->ekf, p, length_m, atan2(dy_m, dx_m), d_m);
        f->x_m += d_m[0];
        f->y_m += d_m[1];
    } else {
        f->x_m += dx_m;
        f->y_m += dy_m;
        f->var_m2 += p->fusion_q_step_m2_per_m * length_m;
    }
    f->steps++;
}

int sf_fusion_fix(sf_fusion_t *const f, const sf_params_t *const p, const sf_fix_t *const fix,
                  const int16_t baro_floor, sf_fix_audit_t *const audit)
{
    return sf_fusion_fix_on_floor(f, p, fix, baro_floor, false, audit);
}

int sf_fusion_fix_on_floor(sf_fusion_t *const f, const sf_params_t *const p, const sf_fix_t *const fix,
                           const int16_t baro_floor, const bool between_floors, sf_fix_audit_t *const audit)
{
    /* baro_floor: the particle scheme's floors; the others are on the caller's floor (Floors) */
    SF_ASSERT(f != NULL && p != NULL && fix != NULL && audit != NULL);
    audit_begin(audit, f, fix);
    f->fixes++;
    if (!fix_usable(fix)) {
        f->bad_fixes++;
        audit->test_ratio = INFINITY; /* no accuracy, no pass */
        return SF_ERANGE;
    }
    const double r_m2 = fix->accuracy_m * fix->accuracy_m;
    /* the paper's baselines, wifi_only and pdr_only (which starts at its first fix), are Wi-Fi's:
     * the other sources are not their fixes */
    if ((row_of(f)->mode == mode_follow_fixes || row_of(f)->mode == mode_dead_reckoning) &&
        fix->method != sf_fix_wifi) {
        audit->reason = sf_fix_reason_scheme_ignores;
        return SF_OK;
    }
    /* the ekf's correlated error c is the radio map's: only a Wi-Fi fix carries it (sf_ekf.h) */
    const bool correlated = fix->method == sf_fix_wifi;

    /* fusion: predict to the fix's time */
    predict_to(f, p, fix->t_us);
    if (is_particle(f)) { /* its own likelihood, judgement and audit (sf_fusion_particle.c) */
        sf_fusion_particle_fix(f, p, fix, baro_floor, between_floors, audit);
        return SF_OK;
    }
    /* the ekf's white R from its fix-error model */
    double ekf_r_m2[3] = {r_m2, 0.0, r_m2};
    if (is_ekf(f)) {
        if (!f->initialised) {
            start_ekf(f, p);
        }
        if (correlated) { /* the other sources' R is their own accuracy, white */
            sf_ekf_fix_r(&f->ekf, p, fix->accuracy_m, ekf_r_m2);
        }
    }

    /* control: start */
    if (!f->initialised) {
        reset_to_fix(f, p, fix, r_m2, ekf_r_m2);
        f->last_fix_t_us = fix->t_us;
        f->rejections = 0;
        f->initialisations++;
        audit->innovation_var_m2 = is_ekf(f) ? 0.5 * (f->ekf.P[0][0] + f->ekf.P[1][1]) : r_m2;
        audit->alpha = 1.0;
        audit->accepted = true;
        audit->reason = sf_fix_reason_initialised;
        return SF_OK;
    }

    /* fusion: innovation, its variance, the test ratio */
    double nu_m[2] = {fix->x_m - f->x_m, fix->y_m - f->y_m};
    if (is_ekf(f)) { /* the ekf predicts the fix at its position plus the fixes' correlated error */
        sf_ekf_innovation(&f->ekf, correlated, nu_m);
    }
    const double nu_x = nu_m[0], nu_y = nu_m[1];
    const double gate = p->fusion_gate_sigma;
    audit->innovation_m[0] = nu_x;
    audit->innovation_m[1] = nu_y;
    if (is_ekf(f)) { /* the full 2×2 S: NIS, χ² with 2 dof, on the same gate */
        double s3_m2[3];
        audit->test_ratio = sf_ekf_nis(&f->ekf, correlated, nu_m, ekf_r_m2, s3_m2) / (gate * gate);
        audit->innovation_var_m2 = 0.5 * (s3_m2[0] + s3_m2[2]);
    } else {
        const double s_m2 = f->var_m2 + r_m2;
        audit->innovation_var_m2 = s_m2;
        audit->test_ratio = (nu_x * nu_x + nu_y * nu_y) / (gate * gate * s_m2);
    }

    /* control: judge, then apply */
    const int8_t reason = judge(f, p, fix, audit->test_ratio, between_floors);
    audit->reason = reason;
    if (is_ekf(f) && correlated && reason == sf_fix_reason_accepted) { /* a rejected fix says nothing about R */
        sf_ekf_learn_fix_model(&f->ekf, p, nu_m, fix->accuracy_m, gate * gate);
    }
    switch (reason) {
    case sf_fix_reason_accepted:
        if (blends(f)) {
            audit->alpha = scheme_alpha(f, p, fix, r_m2, audit);
            blend(f, p, audit->alpha, nu_x, nu_y, r_m2);
        } else if (is_ekf(f)) {
            double dpos_m[2];
            audit->alpha = sf_ekf_update(&f->ekf, p, correlated, nu_m, ekf_r_m2, dpos_m);
            f->x_m += dpos_m[0];
            f->y_m += dpos_m[1];
        } else { /* wifi_only */
            audit->alpha = 1.0;
            reset_to_fix(f, p, fix, r_m2, ekf_r_m2);
        }
        f->accepted++;
        break;
    case sf_fix_reason_recovery:
        audit->alpha = 1.0;
        reset_to_fix(f, p, fix, r_m2, ekf_r_m2);
        f->recoveries++;
        break;
    case sf_fix_reason_gate:
        f->rejected_gate++;
        f->rejections++;
        return SF_OK;
    case sf_fix_reason_floor_mismatch:
        f->rejected_floor++; /* not the scheme's divergence: no step toward recovery */
        return SF_OK;
    default: /* scheme_ignores: pdr_only keeps its dead reckoning */
        return SF_OK;
    }
    audit->accepted = true;
    f->last_fix_t_us = fix->t_us;
    f->rejections = 0;
    return SF_OK;
}

bool sf_fusion_pose(const sf_fusion_t *const f, const sf_params_t *const p, const int64_t t_us,
                    const int16_t baro_floor, sf_pose_t *const pose)
{
    SF_ASSERT(f != NULL && p != NULL && pose != NULL);
    pose->scheme = f->scheme;
    pose->ess = 0.0;
    if (f->initialised && is_particle(f) && sf_fusion_particle_pose(f, pose)) {
        return true;
    }
    if (!f->initialised || is_particle(f)) { /* a particle scheme without a cloud has no position */
        pose->x_m = 0.0;
        pose->y_m = 0.0;
        pose->floor = baro_floor;
        pose->sigma_m = SF_FUSION_SIGMA_UNKNOWN_M;
        iso_cov(SF_FUSION_SIGMA_UNKNOWN_M * SF_FUSION_SIGMA_UNKNOWN_M, pose->cov_m2);
        pose->heading_bias_rad = 0.0;
        pose->stride_scale = 1.0;
        return false;
    }
    const bool clock = f->t_us != SF_FUSION_T_FIRST_INPUT;
    const double q_m2 =
        clock && predicts(f) && t_us > f->t_us ? p->fusion_q_time_m2_per_s * us_to_s(t_us - f->t_us) : 0.0;
    iso_cov(f->var_m2 + q_m2, pose->cov_m2);
    pose->heading_bias_rad = 0.0;
    pose->stride_scale = 1.0;
    if (is_ekf(f)) {
        pose->cov_m2[0] = f->ekf.P[0][0] + q_m2;
        pose->cov_m2[1] = f->ekf.P[0][1];
        pose->cov_m2[2] = f->ekf.P[1][1] + q_m2;
        pose->heading_bias_rad = f->ekf.heading_bias_rad;
        pose->stride_scale = f->ekf.stride_scale;
        pose->heading_rad = atan2(sin(pose->heading_rad + f->ekf.heading_bias_rad),
                                  cos(pose->heading_rad + f->ekf.heading_bias_rad));
    }
    pose->x_m = f->x_m;
    pose->y_m = f->y_m;
    pose->floor = scheme_floor(f, baro_floor);
    pose->sigma_m = sqrt(0.5 * (pose->cov_m2[0] + pose->cov_m2[2]));
    return true;
}

void sf_fusion_set_fix_model(sf_fusion_t *const f, const sf_params_t *const p, const sf_fix_model_t *const model)
{
    f->fix_model = model != NULL && model->valid ? model : NULL;
    /* the particle scheme takes its Wi-Fi R from the same model (sf_fusion_particle.c) */
    if ((is_particle(f) || (is_ekf(f) && f->initialised)) && f->fix_model != NULL) {
        sf_ekf_use_site_model(&f->ekf, p, f->fix_model);
    }
}

void sf_fusion_set_cloud(sf_fusion_t *const f, const sf_params_t *const p, sf_particle_t *const cloud)
{
    SF_ASSERT(f != NULL && p != NULL);
    if (!is_particle(f)) {
        return;
    }
    f->cloud = cloud;
    start_ekf(f, p); /* only its fix-error model: the Wi-Fi fixes' R (sf_fusion_particle.c) */
    if (cloud != NULL && f->initialised && !cloud->seeded) { /* a config start made before the cloud came */
        sf_particle_seed(cloud, p, f->x_m, f->y_m, sqrt(f->var_m2), (int16_t)p->init_floor, false);
    }
}

void sf_fusion_audit_refused(const sf_fusion_t *const f, const sf_fix_t *const fix, const int8_t reason,
                             sf_fix_audit_t *const audit)
{
    audit_begin(audit, f, fix);
    audit->reason = reason;
}
