/* test_attitude.c — sf_attitude on synthetic IMU + magnetometer signals with seeded noise, both modes:
 * convergence from a wrong start, rotation with gyro bias, bias at rest, magnetic disturbance
 * rejection (with a control run showing the test has teeth), uneven sampling, sample order, and
 * bit-identical replay. Truth is generated here: q_true(t) = Rz(yaw0 + rate·t) ⊗ q_tilt, sensors are
 * the truth seen through q_true plus bias and noise. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sf_attitude.h"
#include "sf_math.h"
#include "sf_params.h"
#include "sf_test_rng.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)
#define G 9.80665

static rng_t g_rng; /* seeded per test (sf_test_rng.h) */

/* ---- quaternion helpers (w, x, y, z), body → nav ---- */
static void qmul(const double a[4], const double b[4], double o[4])
{
    o[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    o[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    o[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    o[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}

static void qaxis(const double ax, const double ay, const double az, const double angle, double q[4])
{
    const double n = sqrt(ax * ax + ay * ay + az * az);
    q[0] = cos(angle / 2);
    q[1] = sin(angle / 2) * ax / n;
    q[2] = sin(angle / 2) * ay / n;
    q[3] = sin(angle / 2) * az / n;
}

/* v_out = R(q) v (transpose = false) or R(q)ᵀ v */
static void qrot(const double q[4], const int transpose, const double v[3], double o[3])
{
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                            {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                            {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    for (int i = 0; i < 3; i++) {
        o[i] = transpose ? r[0][i] * v[0] + r[1][i] * v[1] + r[2][i] * v[2]
                         : r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2];
    }
}

static double q_yaw(const double q[4])
{
    return atan2(2 * (q[1] * q[2] + q[0] * q[3]), 1 - 2 * (q[2] * q[2] + q[3] * q[3]));
}

/* angle of the rotation between two attitudes */
static double q_angle(const double a[4], const double b[4])
{
    const double d = fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]);
    return 2 * acos(d > 1 ? 1 : d);
}

static double wrap(const double a)
{
    return atan2(sin(a), cos(a));
}

/* ---- scenario ---- */
#define FIELD_UT 48.0
#define DIP_DEG 60.0

typedef enum { dist_none, dist_zone } disturbance_t;

typedef struct {
    int mode;
    double tilt_axis[3], tilt_deg;   /* fixed tilt of the device */
    double yaw0_deg, rate_dps;       /* yaw about nav z: yaw0 + rate·t */
    double bias_radps[3];
    double duration_s;
    double imu_hz, mag_hz, jitter;   /* jitter: ± fraction of the nominal interval, uniform */
    double eval_from_s;              /* errors are collected from here to the end */
    int wrong_start;                 /* 0.3 s in another attitude, then 1 s without samples */
    disturbance_t dist;
    double field_tol_ut, dip_tol_deg; /* 0: defaults */
    double gyro_noise, accel_noise, mag_noise;
} scenario_t;

typedef struct {
    double max_angle_deg; /* full attitude error */
    double max_yaw_deg;
    double max_tilt_deg;
    sf_attitude_t att;
} result_t;

static void truth_q(const scenario_t *const s, const double t, double q[4])
{
    double qt[4], qz[4];
    qaxis(s->tilt_axis[0], s->tilt_axis[1], s->tilt_axis[2], s->tilt_deg * DEG, qt);
    qaxis(0, 0, 1, (s->yaw0_deg + s->rate_dps * t) * DEG, qz);
    qmul(qz, qt, q);
}

/* The wrong start: tilted 50° about (1, -1, 0) and yawed by 150° from the scenario start. */
static void wrong_q(double q[4])
{
    double a[4], b[4];
    qaxis(1, -1, 0, 50 * DEG, a);
    qaxis(0, 0, 1, 150 * DEG, b);
    qmul(b, a, q);
}

/* The nav-frame field at time t. Zone 15–22 s: +60 % strength (≈ +29 µT) and turned 40° about up;
 * zone 22–30 s: same strength, tilted 30° about east (dip 60° → 30°) and turned 40°. */
static void field_nav(const scenario_t *const s, const double t, double m[3])
{
    const double m0[3] = {0.0, FIELD_UT * cos(DIP_DEG * DEG), -FIELD_UT * sin(DIP_DEG * DEG)};
    if (s->dist == dist_none || t < 15.0 || t >= 30.0) {
        memcpy(m, m0, sizeof m0);
        return;
    }
    double qz[4];
    qaxis(0, 0, 1, 40 * DEG, qz);
    if (t < 22.0) {
        double v[3];
        qrot(qz, 0, m0, v);
        for (int i = 0; i < 3; i++) {
            m[i] = 1.6 * v[i];
        }
    } else {
        double qx[4], q[4];
        qaxis(1, 0, 0, 30 * DEG, qx);
        qmul(qz, qx, q);
        qrot(q, 0, m0, m);
    }
}

static double next_interval(const double hz, const double jitter)
{
    return (1.0 / hz) * (1.0 + jitter * (2.0 * rng_uniform01(&g_rng) - 1.0));
}

static result_t run(const scenario_t *const s, const uint64_t seed)
{
    sf_params_t p;
    sf_params_default(&p);
    p.attitude_mode = s->mode;
    if (s->field_tol_ut > 0) {
        p.attitude_mag_field_tol_ut = s->field_tol_ut;
    }
    if (s->dip_tol_deg > 0) {
        p.attitude_mag_dip_tol_deg = s->dip_tol_deg;
    }
    g_rng.s = seed;
    result_t r;
    memset(&r, 0, sizeof r);
    sf_attitude_init(&r.att);

    const int64_t t0_us = 1000000;
    double t_imu = s->wrong_start ? -1.3 : 0.0;
    double t_mag = t_imu + 0.003;
    double qt[4];
    truth_q(s, 0.0, qt);
    double w_body[3];
    const double w_nav[3] = {0, 0, s->rate_dps * DEG};
    qrot(qt, 1, w_nav, w_body); /* constant: Rz does not change Rᵀ ẑ */
    while (t_imu < s->duration_s || t_mag < s->duration_s) {
        const int imu_next = t_imu <= t_mag;
        const double t = imu_next ? t_imu : t_mag;
        if (t >= s->duration_s) {
            break;
        }
        const int in_wrong = s->wrong_start && t < -1.0;
        const int in_gap = s->wrong_start && t >= -1.0 && t < 0.0;
        double q[4];
        if (in_wrong) {
            wrong_q(q);
        } else {
            truth_q(s, t, q);
        }
        const int64_t t_us = t0_us + (int64_t)llround(t * 1e6);
        if (imu_next) {
            if (!in_gap) {
                const double f_nav[3] = {0, 0, G};
                double f[3], w[3];
                qrot(q, 1, f_nav, f);
                for (int i = 0; i < 3; i++) {
                    f[i] += s->accel_noise * rng_gauss(&g_rng);
                    w[i] = (in_wrong ? 0.0 : w_body[i]) + s->bias_radps[i] + s->gyro_noise * rng_gauss(&g_rng);
                }
                sf_attitude_update_imu(&r.att, &p, t_us, f, w);
            }
            t_imu += next_interval(s->imu_hz, s->jitter);
        } else {
            if (!in_gap) {
                double m_nav[3], m[3];
                field_nav(s, t, m_nav);
                qrot(q, 1, m_nav, m);
                for (int i = 0; i < 3; i++) {
                    m[i] += s->mag_noise * rng_gauss(&g_rng);
                }
                sf_attitude_update_mag(&r.att, &p, t_us, m);
            }
            t_mag += next_interval(s->mag_hz, s->jitter);
        }
        if (t >= s->eval_from_s && imu_next) {
            const double e = q_angle(r.att.q, q) / DEG;
            const double ey = fabs(wrap(sf_attitude_yaw_rad(&r.att) - q_yaw(q))) / DEG;
            double up_est[3], up_true[3];
            const double z[3] = {0, 0, 1};
            qrot(r.att.q, 1, z, up_est);
            qrot(q, 1, z, up_true);
            const double c = up_est[0] * up_true[0] + up_est[1] * up_true[1] + up_est[2] * up_true[2];
            const double et = acos(c > 1 ? 1 : c) / DEG;
            r.max_angle_deg = fmax(r.max_angle_deg, e);
            r.max_yaw_deg = fmax(r.max_yaw_deg, ey);
            r.max_tilt_deg = fmax(r.max_tilt_deg, et);
        }
    }
    return r;
}

static scenario_t base(const int mode)
{
    const scenario_t s = {
        .mode = mode,
        .tilt_axis = {1, 0.5, 0},
        .tilt_deg = 25,
        .yaw0_deg = 30,
        .rate_dps = 0,
        .duration_s = 20,
        .imu_hz = 100,
        .mag_hz = 50,
        .jitter = 0,
        .eval_from_s = 15,
        .gyro_noise = 0.003,
        .accel_noise = 0.05,
        .mag_noise = 0.4,
    };
    return s;
}

static const char *mode_name(const int mode)
{
    return mode == sf_attitude_mahony ? "mahony" : "complementary";
}

static void report(const char *what, const scenario_t *s, const result_t *r)
{
    printf("  %-28s %-13s max error %.3f deg (yaw %.3f, tilt %.3f); mag acc %u rej %u (field %u dip %u "
           "settling %u); gaps %u gated %u\n",
           what, mode_name(s->mode), r->max_angle_deg, r->max_yaw_deg, r->max_tilt_deg, r->att.mag_accepted,
           r->att.mag_rejected, r->att.mag_by_verdict[sf_mag_field], r->att.mag_by_verdict[sf_mag_dip],
           r->att.mag_by_verdict[sf_mag_settling], r->att.imu_gaps, r->att.accel_gated);
}

/* GIVEN a static device WHEN the filter starts 50° tilted and 150° off in yaw (samples from another
 * attitude, then a 1 s gap) THEN it converges to within 2° and yaw is absolute. */
static void test_static_wrong_start_converges(void **state)
{
    (void)state;
    for (int mode = 0; mode <= 1; mode++) {
        scenario_t s = base(mode);
        s.wrong_start = 1;
        const result_t r = run(&s, 11);
        report("static, wrong start", &s, &r);
        assert_int_equal(r.att.imu_gaps, 1);
        assert_true(r.att.yaw_absolute);
        if (r.max_angle_deg >= 2.0) {
            fail_msg("%s: error %.3f deg over 15-20 s, want < 2", mode_name(mode), r.max_angle_deg);
        }
    }
}

/* GIVEN a device turning at 30°/s about up, tilted 25°, with gyro bias (0.6°/s per axis)
 * WHEN it runs 60 s THEN over the last 30 s the error stays below 2°. */
static void test_rotating_with_bias(void **state)
{
    (void)state;
    for (int mode = 0; mode <= 1; mode++) {
        scenario_t s = base(mode);
        s.rate_dps = 30;
        s.bias_radps[0] = 0.010;
        s.bias_radps[1] = -0.008;
        s.bias_radps[2] = 0.012;
        s.duration_s = 60;
        s.eval_from_s = 30;
        s.wrong_start = 1;
        const result_t r = run(&s, 12);
        report("rotating 30 deg/s + bias", &s, &r);
        if (r.max_angle_deg >= 2.0) {
            fail_msg("%s: error %.3f deg, want < 2", mode_name(mode), r.max_angle_deg);
        }
    }
}

/* GIVEN a device at rest with a gyro bias of (0.02, -0.015, 0.01) rad/s and 0.003 rad/s noise
 * WHEN Mahony runs 30 s THEN each bias component is within 0.001 rad/s and at_rest is set. */
static void test_mahony_bias_at_rest(void **state)
{
    (void)state;
    scenario_t s = base(sf_attitude_mahony);
    const double b[3] = {0.02, -0.015, 0.01};
    memcpy(s.bias_radps, b, sizeof b);
    s.duration_s = 30;
    s.eval_from_s = 20;
    const result_t r = run(&s, 13);
    report("rest bias", &s, &r);
    assert_true(r.att.at_rest);
    for (int i = 0; i < 3; i++) {
        const double e = r.att.gyro_bias_radps[i] - b[i];
        printf("    bias[%d] est %.5f true %.5f err %.2e rad/s\n", i, r.att.gyro_bias_radps[i], b[i], e);
        if (fabs(e) > 0.001) {
            fail_msg("bias[%d] error %.5f rad/s, want <= 0.001", i, e);
        }
    }
    assert_true(r.max_angle_deg < 1.0);

    /* the complementary filter has no bias state: it stays zero */
    s.mode = sf_attitude_complementary;
    const result_t c = run(&s, 13);
    assert_true(c.att.gyro_bias_radps[0] == 0.0 && c.att.gyro_bias_radps[1] == 0.0 && c.att.gyro_bias_radps[2] == 0.0);
}

/* GIVEN a device turning at 15°/s through a zone where the field is +29 µT and turned 40° (15–22 s),
 * then dip 30° and turned 40° (22–30 s) WHEN rejection is on THEN yaw stays within 5° of truth and the
 * samples are rejected for field, dip and settling; WHEN rejection is off (huge tolerances) THEN the
 * yaw error exceeds 15°. */
static void test_mag_disturbance_rejected(void **state)
{
    (void)state;
    for (int mode = 0; mode <= 1; mode++) {
        scenario_t s = base(mode);
        s.rate_dps = 15;
        s.bias_radps[0] = 0.002;
        s.bias_radps[1] = -0.002;
        s.bias_radps[2] = 0.002;
        s.duration_s = 40;
        s.eval_from_s = 5;
        s.dist = dist_zone;
        const result_t r = run(&s, 14);
        report("disturbed zone, rejection", &s, &r);
        if (r.max_yaw_deg >= 5.0) {
            fail_msg("%s: yaw error %.3f deg with rejection, want < 5", mode_name(mode), r.max_yaw_deg);
        }
        assert_true(r.att.mag_by_verdict[sf_mag_field] > 250); /* 7 s at 50 Hz = 350 */
        assert_true(r.att.mag_by_verdict[sf_mag_dip] > 300);   /* 8 s at 50 Hz = 400 */
        assert_true(r.att.mag_by_verdict[sf_mag_settling] >= 40); /* ≈ 1 s at 50 Hz after the zone */
        assert_true(r.att.mag_rejected == r.att.mag_by_verdict[sf_mag_field] + r.att.mag_by_verdict[sf_mag_dip] +
                                              r.att.mag_by_verdict[sf_mag_settling]);
        assert_true(r.att.mag_accepted > 1000);

        s.field_tol_ut = 1e6;
        s.dip_tol_deg = 360;
        const result_t off = run(&s, 14);
        report("disturbed zone, no rejection", &s, &off);
        if (off.max_yaw_deg <= 15.0) {
            fail_msg("%s: yaw error %.3f deg without rejection, want > 15 (test has no teeth)", mode_name(mode),
                     off.max_yaw_deg);
        }
        assert_int_equal(off.att.mag_rejected, 0);
    }
}

/* GIVEN IMU at 50 Hz and mag at 25 Hz, each interval ±30 % uniformly random, device turning at 20°/s
 * with bias WHEN it runs 60 s THEN the error stays below 2° over the last 40 s. */
static void test_uneven_sampling(void **state)
{
    (void)state;
    for (int mode = 0; mode <= 1; mode++) {
        scenario_t s = base(mode);
        s.rate_dps = 20;
        s.bias_radps[0] = 0.005;
        s.bias_radps[1] = 0.005;
        s.bias_radps[2] = -0.005;
        s.imu_hz = 50;
        s.mag_hz = 25;
        s.jitter = 0.3;
        s.duration_s = 60;
        s.eval_from_s = 20;
        s.wrong_start = 1;
        const result_t r = run(&s, 15);
        report("50 Hz +-30 % jitter", &s, &r);
        assert_int_equal(r.att.imu_time_errors, 0);
        if (r.max_angle_deg >= 2.0) {
            fail_msg("%s: error %.3f deg with jitter, want < 2", mode_name(mode), r.max_angle_deg);
        }
    }
}

/* GIVEN one mag sample before any IMU sample WHEN the first IMU sample arrives THEN the held mag sample
 * is judged then: yaw is absolute and right at once. Without mag, yaw starts at 0, not absolute. */
static void test_mag_before_imu_and_initial_yaw(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    const scenario_t s = base(sf_attitude_complementary);
    double q[4];
    truth_q(&s, 0.0, q);
    const double f_nav[3] = {0, 0, G}, w[3] = {0, 0, 0};
    double f[3], m[3], m_nav[3];
    field_nav(&s, 0.0, m_nav);
    qrot(q, 1, f_nav, f);
    qrot(q, 1, m_nav, m);

    sf_attitude_t att;
    sf_attitude_init(&att);
    sf_attitude_update_imu(&att, &p, 1000, f, w);
    assert_true(att.tilt_initialised);
    assert_false(att.yaw_absolute);
    assert_true(fabs(sf_attitude_yaw_rad(&att)) < 1e-9);

    sf_attitude_init(&att);
    sf_attitude_update_mag(&att, &p, 1000, m);
    assert_int_equal(att.last_mag.verdict, sf_mag_no_tilt);
    assert_int_equal(att.mag_accepted, 0);
    sf_attitude_update_imu(&att, &p, 1000, f, w); /* same time stamp, other order */
    assert_true(att.yaw_absolute);
    assert_int_equal(att.mag_accepted, 1);
    assert_int_equal(att.last_mag.verdict, sf_mag_accepted);
    const double err = q_angle(att.q, q) / DEG;
    printf("  mag-first init: error %.2e deg\n", err);
    assert_true(err < 1e-6);
    /* body_to_nav of the measured field points north and down */
    double mn[3];
    sf_attitude_body_to_nav(&att, m, mn);
    assert_true(fabs(mn[0]) < 1e-6 && mn[1] > 0 && mn[2] < 0);

    /* garbage is counted, not fused */
    const double bad[3] = {NAN, 0, 0};
    sf_attitude_update_imu(&att, &p, 2000, bad, w);
    assert_int_equal(att.imu_invalid, 1);
    const double zero[3] = {0, 0, 0};
    sf_attitude_update_mag(&att, &p, 3000, zero);
    assert_int_equal(att.last_mag.verdict, sf_mag_degenerate);
    assert_int_equal(att.mag_rejected, 1);
    sf_attitude_update_imu(&att, &p, 1000, f, w); /* backwards in time */
    assert_int_equal(att.imu_time_errors, 1);
}

/* Same inputs → bit-identical outputs, run after run (no hidden state). */
static void test_deterministic(void **state)
{
    (void)state;
    for (int mode = 0; mode <= 1; mode++) {
        scenario_t s = base(mode);
        s.rate_dps = 20;
        s.jitter = 0.3;
        s.dist = dist_zone;
        s.duration_s = 35;
        const result_t a = run(&s, 99);
        const result_t b = run(&s, 99);
        assert_memory_equal(a.att.q, b.att.q, sizeof a.att.q);
        assert_memory_equal(a.att.gyro_bias_radps, b.att.gyro_bias_radps, sizeof a.att.gyro_bias_radps);
        assert_memory_equal(a.att.mag_by_verdict, b.att.mag_by_verdict, sizeof a.att.mag_by_verdict);
        assert_true(memcmp(&a.max_angle_deg, &b.max_angle_deg, sizeof(double)) == 0);
    }
}

/* A seeded random attitude: a uniform point of [−1, 1]⁴ normalised to a unit quaternion. */
static sf_attitude_t random_attitude(rng_t *const rng)
{
    sf_attitude_t att;
    sf_attitude_init(&att);
    double n = 0.0;
    for (int i = 0; i < 4; i++) {
        att.q[i] = rng_pm1(rng);
        n += att.q[i] * att.q[i];
    }
    for (int i = 0; i < 4; i++) {
        att.q[i] /= sqrt(n);
    }
    return att;
}

/* GIVEN 10 000 seeded random attitudes, WHEN the yaw's cosine and sine come from the quaternion
 * (sf_attitude_yaw_dir, no sincos), THEN they are cos and sin of sf_attitude_yaw_rad within 1e-15;
 * and the yaw of a copy of q (sf_attitude_q_yaw_rad, the estimator's walking direction) is
 * sf_attitude_yaw_rad's bit for bit. */
static void test_yaw_dir_is_cos_sin_of_yaw(void **state)
{
    (void)state;
    rng_t rng = {.s = 0x5EED0016ULL};
    double worst = 0.0;
    for (int k = 0; k < 10000; k++) {
        const sf_attitude_t att = random_attitude(&rng);
        double c, s;
        sf_attitude_yaw_dir(&att, &c, &s);
        const double yaw = sf_attitude_yaw_rad(&att);
        assert_true(sf_attitude_q_yaw_rad(att.q) == yaw);
        worst = fmax(worst, fmax(fabs(c - cos(yaw)), fabs(s - sin(yaw))));
    }
    printf("yaw_dir: largest |difference| from cos/sin of the yaw %.2e\n", worst);
    assert_true(worst < 1e-15);
}

/* GIVEN angles over ±8π (and the edges ±π, ±3π), WHEN wrapped by sf_wrap_pi (whole turns taken off),
 * THEN each is in (−π, π] and within 3e-15 rad of atan2(sin a, cos a), the wrap it replaced (modulo
 * the one turn by which the two may place −π/π). */
static void test_wrap_pi_matches_atan2_wrap(void **state)
{
    (void)state;
    double worst = 0.0;
    for (int k = -200000; k <= 200000; k++) {
        const double a = 8.0 * 3.14159265358979323846 * (double)k / 200000.0;
        const double w = sf_wrap_pi(a);
        assert_true(w > -3.14159265358979323846 && w <= 3.14159265358979323846);
        double d = fabs(w - atan2(sin(a), cos(a)));
        d = fmin(d, fabs(d - 2.0 * 3.14159265358979323846));
        worst = fmax(worst, d);
    }
    printf("wrap_pi: largest |difference| from atan2(sin, cos) %.2e rad\n", worst);
    assert_true(worst < 3e-15);
    assert_true(sf_wrap_pi(-3.14159265358979323846) == 3.14159265358979323846);
    assert_true(isnan(sf_wrap_pi((double)NAN)));
    assert_true(isnan(sf_wrap_pi((double)INFINITY)));
}

/* GIVEN 100 000 seeded random attitudes and the axes' edge cases, WHEN sf_attitude_yaw_rad computes the
 * yaw without libm's atan2, THEN it is within 2e-15 rad of atan2 of the same projection, in (−π, π],
 * with atan2's answers on the axes (±0, ±π/2, π for −x). */
static void test_yaw_matches_atan2(void **state)
{
    (void)state;
    rng_t rng = {.s = 0x5EED0116ULL};
    double worst = 0.0;
    for (int k = 0; k < 100000; k++) {
        const sf_attitude_t att = random_attitude(&rng);
        const double w = att.q[0], x = att.q[1], y = att.q[2], z = att.q[3];
        const double ref = atan2(2 * (x * y + w * z), 1 - 2 * (y * y + z * z));
        const double yaw = sf_attitude_yaw_rad(&att);
        assert_true(yaw >= -3.14159265358979323846 && yaw <= 3.14159265358979323846);
        worst = fmax(worst, fabs(yaw - ref));
    }
    printf("yaw: largest |difference| from atan2 %.2e rad\n", worst);
    assert_true(worst < 2e-15);
    /* yaw ψ about up: q = (cos ψ/2, 0, 0, sin ψ/2); ψ = 0, ±π/2, π */
    const double psi[4] = {0.0, 0.5 * 3.14159265358979323846, -0.5 * 3.14159265358979323846, 3.14159265358979323846};
    for (int k = 0; k < 4; k++) {
        sf_attitude_t att;
        sf_attitude_init(&att);
        att.q[0] = cos(0.5 * psi[k]);
        att.q[3] = sin(0.5 * psi[k]);
        const double w = att.q[0], z = att.q[3];
        assert_true(sf_attitude_yaw_rad(&att) == atan2(2 * (w * z), 1 - 2 * (z * z)));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_static_wrong_start_converges),
        cmocka_unit_test(test_rotating_with_bias),
        cmocka_unit_test(test_mahony_bias_at_rest),
        cmocka_unit_test(test_mag_disturbance_rejected),
        cmocka_unit_test(test_uneven_sampling),
        cmocka_unit_test(test_mag_before_imu_and_initial_yaw),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_yaw_dir_is_cos_sin_of_yaw),
        cmocka_unit_test(test_wrap_pi_matches_atan2_wrap),
        cmocka_unit_test(test_yaw_matches_atan2),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
