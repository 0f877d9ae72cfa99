/* sf_attitude.c — see sf_attitude.h for the model. */
#include "sf_attitude.h"

#include <math.h>

#include "sf_assert.h"
#include "sf_math.h"
#include "sf_quat.h"

#define PI 3.14159265358979323846
#define G_MPS2 9.80665
#define MAG_DT_MAX_S 0.2     /* clamp of the mag blend interval (header: "clamped to [0, 0.2] s") */
#define MIN_ACCEL_MPS2 1.0   /* below this the accelerometer carries no usable "up" */
#define MIN_HORIZONTAL 0.01  /* horizontal field / |m| below this: no yaw information */
#define FUSE_DT_MAX_S 0.1    /* clamp of the interval used by the accelerometer corrections */
#define INTEGRAL_MAX_ERR_RAD (10.0 * PI / 180.0) /* anti-windup: larger errors do not feed the bias */

/* q ← exp(r_nav) ⊗ q: rotate the body by r_nav expressed in the nav frame. */
static void rotate_in_nav(sf_attitude_t *const att, const double r_nav[3])
{
    double dq[4];
    sf_qexp(r_nav, dq);
    double out[4];
    sf_qmul(dq, att->q, out);
    sf_qnormalise(out);
    for (int i = 0; i < 4; i++) {
        att->q[i] = out[i];
    }
}

/* q ← exp(ẑ·angle) ⊗ q: rotate_in_nav for a turn about nav up (the magnetometer's yaw correction),
 * the product with (cos, 0, 0, sin) of half the angle written out: 8 products instead of 16, the same
 * numbers but for the sign of a zero term. */
static void rotate_about_up(sf_attitude_t *const att, const double angle_rad)
{
    const double r[3] = {0.0, 0.0, angle_rad};
    double dq[4];
    sf_qexp(r, dq);
    const double c = dq[0], s = dq[3];
    const double w = att->q[0], x = att->q[1], y = att->q[2], z = att->q[3];
    double out[4] = {c * w - s * z, c * x - s * y, c * y + s * x, c * z + s * w};
    sf_qnormalise(out);
    for (int i = 0; i < 4; i++) {
        att->q[i] = out[i];
    }
}

/* The rotation (nav frame, axis × angle) that takes the measured up direction onto nav z.
 * Horizontal axis, so it never changes yaw about the vertical. */
static void tilt_error_nav(const sf_attitude_t *const att, const double accel_mps2[3], double r_nav[3])
{
    double u[3];
    sf_qrotate(att->q, false, accel_mps2, u);
    const double n = sf_norm3(u);
    const double c[3] = {u[1] / n, -u[0] / n, 0.0}; /* (u/|u|) × ẑ */
    const double s = sqrt(c[0] * c[0] + c[1] * c[1]);
    const double angle = sf_atan2_half(sqrt(u[0] * u[0] + u[1] * u[1]), u[2], n); /* atan2(s, u_z/n) */
    if (s < 1e-15) {
        r_nav[0] = r_nav[1] = r_nav[2] = 0.0; /* aligned (or exactly upside down: no axis; next sample) */
        return;
    }
    r_nav[0] = c[0] / s * angle;
    r_nav[1] = c[1] / s * angle;
    r_nav[2] = 0.0;
}

/* The tilt error in body axes (axis × angle): the rotation, applied on the right (q ⊗ exp(e)), that
 * takes the measured up a/|a| onto the estimated up v = Rᵀ(q)·ẑ. It is Rᵀ of tilt_error_nav's
 * rotation (rotations keep cross products: Rᵀ(u × ẑ) = a × v), without rotating a into nav: e = (a × v)
 * · θ/|a × v|, θ = 2·atan(t), t = |a × v|/(|a| + a·v) = tan(θ/2). For |t| ≤ SF_ATAN_SERIES_MAX (θ ≤
 * 11.4°) θ/|a × v| = 2·P(t²)/(|a| + a·v), P = atan(t)/t by its series (sf_math.h's, to t¹²): no sqrt
 * and no atan2; larger errors take atan2. a_norm = |a| > 0. */
static void tilt_error_body(const double q[4], const double a[3], const double a_norm, double e[3])
{
    double v[3];
    sf_up_to_body(q, 1.0, v);
    const double c[3] = {a[1] * v[2] - a[2] * v[1], a[2] * v[0] - a[0] * v[2], a[0] * v[1] - a[1] * v[0]};
    const double s2 = sf_dot3(c, c);
    const double d = a_norm + sf_dot3(a, v);
    double f; /* θ / |a × v| */
    if (d > 0.0 && s2 <= SF_ATAN_SERIES_MAX * SF_ATAN_SERIES_MAX * d * d) {
        const double t2 = s2 / (d * d);
        f = 2.0 * sf_atan_series(t2) / d;
    } else {
        const double sn = sqrt(s2);
        if (sn < 1e-15 * a_norm) {
            e[0] = e[1] = e[2] = 0.0; /* aligned, or exactly upside down (no axis; next sample) */
            return;
        }
        f = atan2(sn, sf_dot3(a, v)) / sn;
    }
    e[0] = c[0] * f;
    e[1] = c[1] * f;
    e[2] = c[2] * f;
}

/* Roll/pitch from one accelerometer sample, yaw 0 (body x towards east, or as close as tilt allows). */
static void init_tilt(sf_attitude_t *const att, const double accel_mps2[3])
{
    att->q[0] = 1.0;
    att->q[1] = att->q[2] = att->q[3] = 0.0;
    double r[3];
    tilt_error_nav(att, accel_mps2, r);
    if (r[0] == 0.0 && r[1] == 0.0 && accel_mps2[2] < 0.0) {
        r[0] = PI; /* upside down: half turn about east */
    }
    rotate_in_nav(att, r);
    const double yaw_r[3] = {0.0, 0.0, -sf_attitude_yaw_rad(att)};
    rotate_in_nav(att, yaw_r);
    att->tilt_initialised = true;
}

static void clamp_bias(sf_attitude_t *const att, const sf_params_t *const p)
{
    const double m = p->attitude_gyro_bias_max_radps;
    for (int i = 0; i < 3; i++) {
        att->gyro_bias_radps[i] = sf_clamp(att->gyro_bias_radps[i], -m, m);
    }
}

static void judge_mag(sf_attitude_t *att, const sf_params_t *p, int64_t t_us, const double field_ut[3]);

void sf_attitude_init(sf_attitude_t *const att)
{
    *att = (sf_attitude_t){0};
    att->q[0] = 1.0;
    att->last_mag.dip_rad = (double)NAN;
}

void sf_attitude_update_imu(sf_attitude_t *const att, const sf_params_t *const p, const int64_t t_us,
                            const double accel_mps2[3], const double gyro_radps[3])
{
    SF_ASSERT(att != NULL && p != NULL && accel_mps2 != NULL && gyro_radps != NULL);
    if (!sf_finite3(accel_mps2) || !sf_finite3(gyro_radps)) {
        att->imu_invalid++;
        return;
    }
    sf_attitude_update_imu_finite(att, p, t_us, accel_mps2, gyro_radps);
}

void sf_attitude_update_imu_finite(sf_attitude_t *const att, const sf_params_t *const p, const int64_t t_us,
                                   const double accel_mps2[3], const double gyro_radps[3])
{
    SF_ASSERT(att != NULL && p != NULL && sf_finite3(accel_mps2) && sf_finite3(gyro_radps));
    const double a_norm = sf_norm3(accel_mps2);
    const bool accel_usable = a_norm > MIN_ACCEL_MPS2;

    if (!att->imu_started) {
        att->imu_started = true;
        att->last_imu_t_us = t_us;
        for (int i = 0; i < 3; i++) {
            att->last_gyro_radps[i] = gyro_radps[i];
        }
        if (accel_usable) {
            init_tilt(att, accel_mps2);
        }
    } else {
        const int64_t dt_us = t_us - att->last_imu_t_us;
        if (dt_us <= 0) {
            att->imu_time_errors++;
            return; /* nothing to integrate; a repeated or backwards time is not a new sample */
        }
        const double dt_s = (double)dt_us * 1e-6;
        const bool gap = dt_us > (int64_t)p->attitude_max_gap_ms * 1000;
        if (gap) {
            att->imu_gaps++;
        }
        att->last_imu_t_us = t_us;

        /* rest detector (control): both conditions held for rest_time_s */
        const double w_c[3] = {gyro_radps[0] - att->gyro_bias_radps[0], gyro_radps[1] - att->gyro_bias_radps[1],
                               gyro_radps[2] - att->gyro_bias_radps[2]};
        const bool still = !gap && sf_norm3(w_c) < p->attitude_rest_gyro_radps &&
                           fabs(a_norm - G_MPS2) < p->attitude_rest_accel_mps2;
        if (!still) {
            att->rest_candidate = false;
        } else if (!att->rest_candidate) {
            att->rest_candidate = true;
            att->rest_since_t_us = t_us;
        }
        att->at_rest = att->rest_candidate &&
                       (double)(t_us - att->rest_since_t_us) * 1e-6 >= p->attitude_rest_time_s;

        if (!att->tilt_initialised) {
            if (accel_usable) {
                init_tilt(att, accel_mps2);
            }
        } else {
            const bool mahony = p->attitude_mode == sf_attitude_mahony;
            /* fusion: one body-frame rotation per sample, q ← q ⊗ exp(r), r = the gyro's turn over the
             * interval (trapezoid, bias removed; none after a gap) + k · the tilt error e (body axes,
             * from the attitude before this sample, as Mahony's ω − b̂ + Kp·e): one exp, one product,
             * one normalisation (the header's propagation and gravity paragraphs) */
            double r[3] = {0.0, 0.0, 0.0};
            if (!gap) {
                for (int i = 0; i < 3; i++) {
                    r[i] = (0.5 * (att->last_gyro_radps[i] + gyro_radps[i]) - att->gyro_bias_radps[i]) * dt_s;
                }
            }
            /* fusion: gravity */
            const bool gated = !accel_usable || fabs(a_norm - G_MPS2) > p->attitude_accel_gate_mps2;
            if (gated) {
                att->accel_gated++;
            } else {
                /* after a gap the interval says nothing about the gyro: clamp it, no integral */
                const double dt_f = sf_clamp(dt_s, 0.0, FUSE_DT_MAX_S);
                double e_body[3];
                tilt_error_body(att->q, accel_mps2, a_norm, e_body);
                double k;
                if (mahony) {
                    k = sf_clamp(p->attitude_mahony_kp * dt_f, 0.0, 1.0);
                    if (!gap && sf_dot3(e_body, e_body) < INTEGRAL_MAX_ERR_RAD * INTEGRAL_MAX_ERR_RAD) {
                        for (int i = 0; i < 3; i++) {
                            att->gyro_bias_radps[i] -= p->attitude_mahony_ki * e_body[i] * dt_f;
                        }
                    }
                } else {
                    k = 1.0 - p->attitude_tau_s / (p->attitude_tau_s + dt_f); /* 1 − α */
                }
                for (int i = 0; i < 3; i++) {
                    r[i] += k * e_body[i];
                }
            }
            double dq[4], out[4];
            sf_qexp(r, dq);
            sf_qmul(att->q, dq, out);
            sf_qnormalise(out);
            for (int i = 0; i < 4; i++) {
                att->q[i] = out[i];
            }
            /* fusion: fast bias at rest (Mahony only; the thesis filter has no bias state) */
            if (mahony && att->at_rest) {
                const double kb = dt_s / (p->attitude_rest_bias_tau_s + dt_s);
                for (int i = 0; i < 3; i++) {
                    att->gyro_bias_radps[i] += kb * (gyro_radps[i] - att->gyro_bias_radps[i]);
                }
            }
            if (mahony) {
                clamp_bias(att, p);
            }
        }
        for (int i = 0; i < 3; i++) {
            att->last_gyro_radps[i] = gyro_radps[i];
        }
    }

    if (att->tilt_initialised && att->mag_pending) {
        att->mag_pending = false;
        judge_mag(att, p, att->mag_pending_t_us, att->mag_pending_ut);
    }
}

static void reject(sf_attitude_t *const att, const sf_mag_verdict_t v)
{
    att->mag_rejected++;
    att->mag_by_verdict[v]++;
    att->last_mag.verdict = v;
}

void sf_attitude_update_mag(sf_attitude_t *const att, const sf_params_t *const p, const int64_t t_us,
                            const double field_ut[3])
{
    SF_ASSERT(att != NULL && p != NULL && field_ut != NULL);
    if (!att->tilt_initialised && sf_finite3(field_ut)) {
        if (att->mag_pending) {
            reject(att, sf_mag_no_tilt); /* the held sample is replaced by a newer one */
        }
        att->mag_pending = true;
        att->mag_pending_t_us = t_us;
        for (int i = 0; i < 3; i++) {
            att->mag_pending_ut[i] = field_ut[i];
        }
        att->last_mag = (sf_attitude_mag_audit_t){.t_us = t_us, .field_ut = sf_norm3(field_ut), .dip_rad = (double)NAN,
                                                  .verdict = sf_mag_no_tilt};
        return;
    }
    judge_mag(att, p, t_us, field_ut);
}

/* Control (verdict) then fusion for one magnetometer sample; the tilt is known. */
static void judge_mag(sf_attitude_t *const att, const sf_params_t *const p, const int64_t t_us,
                      const double field_ut[3])
{
    const double deg = PI / 180.0;
    if (!att->mag_ref_set) {
        att->mag_ref_set = true;
        att->mag_ref_field_ut = att->mag_anchor_field_ut = p->attitude_mag_field_ut;
        att->mag_ref_dip_rad = att->mag_anchor_dip_rad = p->attitude_mag_dip_deg * deg;
        att->mag_acquire_start_t_us = t_us;
        att->mag_acquiring = p->attitude_mag_acquire_s > 0.0;
        att->mag_last_ok_t_us = t_us;
    }
    const double dt_s = att->mag_seen ? sf_clamp((double)(t_us - att->last_mag_t_us) * 1e-6, 0.0, MAG_DT_MAX_S) : 0.0;
    att->mag_seen = true;
    att->last_mag_t_us = t_us;

    sf_attitude_mag_audit_t *const audit = &att->last_mag;
    *audit = (sf_attitude_mag_audit_t){.t_us = t_us, .dip_rad = (double)NAN, .ref_field_ut = att->mag_ref_field_ut,
                                       .ref_dip_rad = att->mag_ref_dip_rad};
    const double f = sf_finite3(field_ut) ? sf_norm3(field_ut) : (double)NAN;
    audit->field_ut = f;
    double m_nav[3] = {0.0, 0.0, 0.0};
    if (isfinite(f) && f > 0.0) {
        sf_qrotate(att->q, false, field_ut, m_nav);
    }
    const double h = sqrt(m_nav[0] * m_nav[0] + m_nav[1] * m_nav[1]);
    if (!isfinite(f) || f <= 0.0 || h < MIN_HORIZONTAL * f) {
        reject(att, sf_mag_degenerate);
        return;
    }
    const double dip = asin(sf_clamp(-m_nav[2] / f, -1.0, 1.0));
    audit->dip_rad = dip;
    /* the angle from the horizontal field to north (nav +y), clockwise positive: π/2 − atan2(m_y, m_x)
     * wrapped, which is atan2(m_x, m_y) in one call (≤ 1 ulp, not an atan2, a sincos and another atan2) */
    audit->yaw_innov_rad = sf_atan2_half(m_nav[0], m_nav[1], h);

    /* control: acquisition. The expected field and dip depend on the site (48 µT / 60° in central
     * Europe, 45 µT / 45° in southern China, less indoors near steel) and on the sensor's own
     * calibration (a phone's OS refits its hard iron during the calibration gestures a walk starts
     * with: 51 → 40 µT within a minute on an IPIN 2023 log): while acquiring, the references follow the
     * quiet samples (exponential average, 2 s; the first one sets them) until they have covered
     * attitude_mag_acquire_s; afterwards they are the anchor of the bounded learning below. Quiet:
     * |ω − b̂| < attitude_mag_acquire_gyro_radps, since the dip needs the tilt, which the accelerometer
     * does not give while the device is waved. A field out of tolerance for attitude_mag_reacquire_s
     * without a break is no local disturbance (steel disturbs over metres, seconds of walking) but a
     * changed field or calibration: the acquisition starts again. */
    if (p->attitude_mag_reacquire_s > 0.0 && !att->mag_acquiring &&
        (double)(t_us - att->mag_last_ok_t_us) * 1e-6 >= p->attitude_mag_reacquire_s) {
        att->mag_acquiring = true;
        att->mag_acquire_n = 0;
        att->mag_acquired_s = 0.0;
        att->mag_acquire_start_t_us = t_us;
        att->mag_last_ok_t_us = t_us;
        att->mag_reacquisitions++;
    }
    if (att->mag_acquiring) {
        const double w[3] = {att->last_gyro_radps[0] - att->gyro_bias_radps[0],
                             att->last_gyro_radps[1] - att->gyro_bias_radps[1],
                             att->last_gyro_radps[2] - att->gyro_bias_radps[2]};
        /* provisional until the first quiet sample: the acquisition's first sample sets the
         * references, the next follow every sample (a device that never rests still gets a field) */
        const bool quiet = sf_norm3(w) < p->attitude_mag_acquire_gyro_radps;
        const bool first = att->mag_acquire_start_t_us == t_us;
        if (quiet || att->mag_acquire_n == 0) {
            const double k = first || (quiet && att->mag_acquire_n == 0) ? 1.0 : dt_s / (2.0 + dt_s);
            att->mag_ref_field_ut += k * (f - att->mag_ref_field_ut);
            att->mag_ref_dip_rad += k * (dip - att->mag_ref_dip_rad);
            att->mag_anchor_field_ut = att->mag_ref_field_ut;
            att->mag_anchor_dip_rad = att->mag_ref_dip_rad;
        }
        if (quiet) {
            att->mag_acquire_n++;
            att->mag_acquired_s += dt_s;
            att->mag_acquiring = att->mag_acquired_s < p->attitude_mag_acquire_s;
        }
        audit->ref_field_ut = att->mag_ref_field_ut;
        audit->ref_dip_rad = att->mag_ref_dip_rad;
    }

    /* control: disturbance tests, then the settle hysteresis */
    const bool field_ok = fabs(f - att->mag_ref_field_ut) <= p->attitude_mag_field_tol_ut;
    const bool dip_ok = fabs(dip - att->mag_ref_dip_rad) <= p->attitude_mag_dip_tol_deg * deg;
    if (field_ok && dip_ok) {
        att->mag_last_ok_t_us = t_us;
    } else {
        att->mag_disturbed = true;
        att->mag_consistent = false;
        reject(att, field_ok ? sf_mag_dip : sf_mag_field);
        return;
    }
    if (att->mag_disturbed) {
        if (!att->mag_consistent) {
            att->mag_consistent = true;
            att->mag_consistent_t_us = t_us;
        }
        if ((double)(t_us - att->mag_consistent_t_us) * 1e-6 < p->attitude_mag_settle_s) {
            reject(att, sf_mag_settling);
            return;
        }
        att->mag_disturbed = false;
        att->mag_consistent = false;
    }

    /* fusion: yaw about nav z only */
    double gain;
    if (!att->yaw_absolute) {
        gain = 1.0;
        att->yaw_absolute = true;
    } else if (p->attitude_mode == sf_attitude_mahony) {
        gain = sf_clamp(p->attitude_mahony_kp_mag * dt_s, 0.0, 1.0);
        if (fabs(audit->yaw_innov_rad) < INTEGRAL_MAX_ERR_RAD) {
            double e_body[3];
            sf_up_to_body(att->q, audit->yaw_innov_rad, e_body);
            for (int i = 0; i < 3; i++) {
                att->gyro_bias_radps[i] -= p->attitude_mahony_ki_mag * e_body[i] * dt_s;
            }
            clamp_bias(att, p);
        }
    } else {
        gain = 1.0 - p->attitude_tau_s / (p->attitude_tau_s + dt_s); /* 1 − α */
    }
    rotate_about_up(att, gain * audit->yaw_innov_rad);
    audit->gain = gain;
    audit->verdict = sf_mag_accepted;
    att->mag_accepted++;
    att->mag_by_verdict[sf_mag_accepted]++;

    /* control: learn the undisturbed references, bounded to configured ± tolerance */
    if (p->attitude_mag_learn_tau_s > 0.0) {
        const double k = dt_s / (p->attitude_mag_learn_tau_s + dt_s);
        const double f0 = att->mag_anchor_field_ut, ft = p->attitude_mag_field_tol_ut;
        const double d0 = att->mag_anchor_dip_rad, dtol = p->attitude_mag_dip_tol_deg * deg;
        att->mag_ref_field_ut = sf_clamp(att->mag_ref_field_ut + k * (f - att->mag_ref_field_ut), f0 - ft, f0 + ft);
        att->mag_ref_dip_rad = sf_clamp(att->mag_ref_dip_rad + k * (dip - att->mag_ref_dip_rad), d0 - dtol, d0 + dtol);
    }
}

void sf_attitude_body_to_nav(const sf_attitude_t *const att, const double v_body[3], double v_nav[3])
{
    sf_qrotate(att->q, false, v_body, v_nav);
}

void sf_attitude_nav_to_body(const sf_attitude_t *const att, const double v_nav[3], double v_body[3])
{
    sf_qrotate(att->q, true, v_nav, v_body);
}

double sf_attitude_yaw_rad(const sf_attitude_t *const att)
{
    return sf_attitude_q_yaw_rad(att->q);
}

double sf_attitude_q_yaw_rad(const double q[4])
{
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    return sf_atan2(2 * (x * y + w * z), 1 - 2 * (y * y + z * z));
}

void sf_attitude_yaw_dir(const sf_attitude_t *const att, double *const cos_yaw, double *const sin_yaw)
{
    const double w = att->q[0], x = att->q[1], y = att->q[2], z = att->q[3];
    const double a = 1 - 2 * (y * y + z * z), b = 2 * (x * y + w * z);
    const double h = sqrt(a * a + b * b);
    if (h > 0.0) {
        *cos_yaw = a / h;
        *sin_yaw = b / h;
        return;
    }
    const double yaw = atan2(b, a);
    *cos_yaw = cos(yaw);
    *sin_yaw = sin(yaw);
}

double sf_attitude_tilt_rad(const sf_attitude_t *const att)
{
    const double x = att->q[1], y = att->q[2];
    return acos(sf_clamp(1 - 2 * (x * x + y * y), -1.0, 1.0));
}
