/* test_heading.c — sf_heading on a synthetic gait with seeded noise: mounting offset from PCA +
 * inverted-pendulum sign, map rotation, fallback before confidence, turning, uneven sampling, and the
 * whole chain body sensors → sf_attitude → sf_heading.
 *
 * The gait (nav frame, one cycle per step, phase φ = 2π f t): the body is highest at φ = 0, so
 *   vertical position  z = Z cos φ,  a_up = −Z ω² cos φ,  v_up = −Z ω sin φ;
 *   forward speed is lowest when the body is highest: v_f = V − B cos φ, a_f = B ω sin φ (+ a heel-strike
 *   harmonic), so a_f is anti-correlated with v_up;
 *   lateral sway at half the step rate; noise on every axis and a constant horizontal bias (tilt error).
 * The device yaw is walking direction − offset (plus noise). */
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
#include "sf_heading.h"
#include "sf_params.h"
#include "sf_test_rng.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)
#define G 9.80665

#define STEP_HZ 1.8
#define Z_M 0.03      /* vertical bounce amplitude: a_up peak 3.8 m/s² */
#define B_MPS 0.15    /* forward speed swing: a_f peak 1.7 m/s² */
#define HARM_MPS2 0.4 /* heel-strike harmonic on a_f */
#define SWAY_MPS2 0.6 /* lateral, half the step rate */
#define NOISE_MPS2 0.15

static rng_t g_rng; /* seeded per test (sf_test_rng.h) */

static double wrap(const double a)
{
    return atan2(sin(a), cos(a));
}

typedef struct {
    double walk_deg;       /* walking direction (nav, CCW from east) at the start */
    double turn_deg;       /* turned over steps 10–15, linearly */
    double offset_deg;     /* true mounting offset: walking − device yaw */
    int n_steps;
    double imu_hz, jitter;
    int pendulum_sign;     /* +1 physical; −1 forward acceleration in phase with v_up (not a gait) */
    double map_rotation_deg;
    double mount_offset_deg; /* param fallback */
} gait_t;

typedef struct {
    sf_heading_t h;
    sf_params_t p;
    double last_yaw;
    double last_walk_nav;
} gait_result_t;

static double walk_dir(const gait_t *const g, const double steps_done)
{
    const double u = steps_done < 10 ? 0 : (steps_done > 15 ? 1 : (steps_done - 10) / 5);
    return (g->walk_deg + u * g->turn_deg) * DEG;
}

/* Gait acceleration (nav, gravity included) at time t for walking direction psi. */
static void gait_accel(const gait_t *const g, const double t, const double psi, double a[3])
{
    const double w = 2 * PI * STEP_HZ;
    const double ph = w * t;
    const double a_up = -Z_M * w * w * cos(ph);
    const double a_f = g->pendulum_sign * B_MPS * w * sin(ph) + HARM_MPS2 * sin(2 * ph + 0.7);
    const double a_l = SWAY_MPS2 * sin(0.5 * ph + 0.3);
    a[0] = a_f * cos(psi) - a_l * sin(psi) + 0.10 + NOISE_MPS2 * rng_gauss(&g_rng);
    a[1] = a_f * sin(psi) + a_l * cos(psi) - 0.05 + NOISE_MPS2 * rng_gauss(&g_rng);
    a[2] = G + a_up + NOISE_MPS2 * rng_gauss(&g_rng);
}

static gait_result_t walk(const gait_t *const g, const uint64_t seed)
{
    gait_result_t r;
    memset(&r, 0, sizeof r);
    sf_params_default(&r.p);
    r.p.heading_map_rotation_deg = g->map_rotation_deg;
    r.p.heading_mount_offset_deg = g->mount_offset_deg;
    sf_heading_init(&r.h, &r.p);
    g_rng.s = seed;
    const double lead_s = 0.4; /* the detector fires 0.1 s after the lowest point (φ = π) */
    int steps = 0;
    double t = 0.0;
    while (steps < g->n_steps) {
        const double psi = walk_dir(g, STEP_HZ * t);
        double a[3];
        gait_accel(g, t, psi, a);
        const double yaw = wrap(psi - g->offset_deg * DEG + 1.0 * DEG * rng_gauss(&g_rng));
        const int64_t t_us = 2000000 + (int64_t)llround(t * 1e6);
        sf_heading_update(&r.h, &r.p, t_us, a, yaw);
        r.last_yaw = yaw;
        r.last_walk_nav = psi;
        if (t >= (steps + 0.5) / STEP_HZ + 0.1 && t > lead_s) {
            sf_heading_on_step(&r.h, &r.p, t_us);
            steps++;
        }
        t += (1.0 / g->imu_hz) * (1.0 + g->jitter * (2 * rng_uniform01(&g_rng) - 1));
    }
    return r;
}

static gait_t base_gait(const double offset_deg)
{
    const gait_t g = {.walk_deg = 20, .offset_deg = offset_deg, .n_steps = 20, .imu_hz = 100, .pendulum_sign = 1};
    return g;
}

static double offset_err_deg(const gait_result_t *const r, const double offset_deg)
{
    return fabs(wrap(sf_heading_offset_rad(&r->h, &r->p) - offset_deg * DEG)) / DEG;
}

static void check_offset(const gait_t *const g, const uint64_t seed, const char *what)
{
    const gait_result_t r = walk(g, seed);
    const double e = offset_err_deg(&r, g->offset_deg);
    printf("  %-26s offset true %7.1f est %7.2f deg (err %.2f); good %d/%d steps, ratio %.1f corr %.2f\n", what,
           g->offset_deg, sf_heading_offset_rad(&r.h, &r.p) / DEG, e, r.h.good_steps, r.h.steps, r.h.last_step.ratio,
           r.h.last_step.corr);
    assert_true(r.h.confident);
    if (e >= 5.0) {
        fail_msg("%s: offset %g deg estimated with error %.2f deg, want < 5", what, g->offset_deg, e);
    }
}

/* GIVEN a gait with the device yawed 0°, 90°, −135° from the walking direction WHEN 20 steps are walked
 * THEN the estimated mounting offset is within 5° (−135° needs the pendulum sign: PCA alone gives 45°). */
static void test_offset_after_20_steps(void **state)
{
    (void)state;
    const double offsets[] = {0.0, 90.0, -135.0};
    for (size_t i = 0; i < sizeof offsets / sizeof offsets[0]; i++) {
        for (uint64_t seed = 1; seed <= 5; seed++) {
            const gait_t g = base_gait(offsets[i]);
            check_offset(&g, seed, "100 Hz, straight");
        }
    }
}

/* GIVEN the same gait at 50 Hz with ±30 % interval jitter THEN the same bound holds. */
static void test_offset_uneven_sampling(void **state)
{
    (void)state;
    const double offsets[] = {0.0, 90.0, -135.0};
    for (size_t i = 0; i < sizeof offsets / sizeof offsets[0]; i++) {
        gait_t g = base_gait(offsets[i]);
        g.imu_hz = 50;
        g.jitter = 0.3;
        check_offset(&g, 21, "50 Hz +-30 % jitter");
    }
}

/* GIVEN the walker (device fixed to them) turns 90° over steps 10–15 THEN the offset still holds. */
static void test_offset_through_a_turn(void **state)
{
    (void)state;
    gait_t g = base_gait(-135.0);
    g.turn_deg = 90;
    g.n_steps = 30;
    check_offset(&g, 31, "turning 90 deg");
}

/* Teeth for the sign: forward acceleration in phase with v_up (not how people walk) gives the axis
 * reversed, i.e. the offset 180° away. */
static void test_sign_comes_from_the_pendulum(void **state)
{
    (void)state;
    gait_t g = base_gait(90.0);
    g.pendulum_sign = -1;
    const gait_result_t r = walk(&g, 41);
    const double e = fabs(wrap(sf_heading_offset_rad(&r.h, &r.p) - (90.0 - 180.0) * DEG)) / DEG;
    printf("  reversed pendulum: est %.2f deg, want -90 (err %.2f)\n", sf_heading_offset_rad(&r.h, &r.p) / DEG, e);
    assert_true(e < 5.0);
}

/* GIVEN map rotation 30° and fallback offset 12° WHEN fewer than min_steps steps THEN the walking
 * direction is yaw + 12° − 30° (to 1e-12 rad); WHEN 20 steps THEN it is the true walking direction − 30°,
 * within 5°; WHEN learn_offset is 0 THEN it is yaw + 12° − 30° again. */
static void test_map_rotation_and_fallback(void **state)
{
    (void)state;
    gait_t g = base_gait(90.0);
    g.map_rotation_deg = 30;
    g.mount_offset_deg = 12;
    g.n_steps = 5;
    const gait_result_t early = walk(&g, 51);
    assert_false(early.h.confident);
    const double want_early = wrap(early.last_yaw + (12.0 - 30.0) * DEG);
    assert_true(fabs(wrap(sf_heading_walk_rad(&early.h, &early.p, early.last_yaw) - want_early)) < 1e-12);

    g.n_steps = 20;
    const gait_result_t r = walk(&g, 51);
    assert_true(r.h.confident);
    const double walk_map = sf_heading_walk_rad(&r.h, &r.p, r.last_yaw);
    const double e = fabs(wrap(walk_map - (r.last_walk_nav - 30.0 * DEG))) / DEG;
    printf("  map rotation 30: walk map %.2f deg, want %.2f (err %.2f)\n", walk_map / DEG,
           r.last_walk_nav / DEG - 30.0, e);
    assert_true(e < 5.0);

    /* learn_offset 0: the same confident estimate is not used; the fallback 12° is. */
    gait_result_t fixed = r;
    fixed.p.heading_learn_offset = 0;
    assert_true(fixed.h.confident);
    const double want_fixed = wrap(r.last_yaw + (12.0 - 30.0) * DEG);
    assert_true(fabs(wrap(sf_heading_walk_rad(&fixed.h, &fixed.p, r.last_yaw) - want_fixed)) < 1e-12);
}

/* GIVEN standing still with step calls 3 s apart THEN windows are rejected and nothing is learned. */
static void test_long_windows_rejected(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_heading_t h;
    sf_heading_init(&h, &p);
    const double a[3] = {0, 0, G};
    for (int k = 0; k <= 3000; k++) {
        const int64_t t_us = (int64_t)k * 10000;
        sf_heading_update(&h, &p, t_us, a, 0.3);
        if (k % 300 == 0 && k > 0) {
            sf_heading_on_step(&h, &p, t_us);
        }
    }
    assert_int_equal(h.steps, 10);
    assert_int_equal(h.windows_rejected, 10);
    assert_int_equal(h.good_steps, 0);
    assert_false(h.confident);
    assert_true(sf_heading_offset_rad(&h, &p) == 0.0);
}

/* ---- the whole chain: body-frame sensors → sf_attitude → sf_heading ---- */
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

static void qrot_t(const double q[4], const double v[3], double o[3]) /* Rᵀ v */
{
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                            {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                            {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    for (int i = 0; i < 3; i++) {
        o[i] = r[0][i] * v[0] + r[1][i] * v[1] + r[2][i] * v[2];
    }
}

/* GIVEN a device tilted 35° and mounted so that its yaw is 90° (resp. −135°) from the walking
 * direction, body-frame accel/gyro/mag, both attitude modes WHEN 30 steps THEN the offset is within 5°
 * and the walking direction (nav) within 5° of truth. */
static void test_chain_attitude_to_heading(void **state)
{
    (void)state;
    const double offsets[] = {90.0, -135.0};
    for (int mode = 0; mode <= 1; mode++) {
        for (size_t i = 0; i < 2; i++) {
            const gait_t g = base_gait(offsets[i]);
            sf_params_t p;
            sf_params_default(&p);
            p.attitude_mode = mode;
            sf_attitude_t att;
            sf_attitude_init(&att);
            sf_heading_t h;
            sf_heading_init(&h, &p);
            g_rng.s = 61;
            /* body → nav: Rz(device yaw) ⊗ tilt; the tilt axis is body-fixed, so yaw is about nav z */
            double q_tilt[4], q_yaw[4], q[4];
            qaxis(0.3, 1, 0, 35 * DEG, q_tilt);
            const double dev_yaw = (g.walk_deg - g.offset_deg) * DEG;
            qaxis(0, 0, 1, dev_yaw, q_yaw);
            qmul(q_yaw, q_tilt, q);
            const double m_nav[3] = {0, 48 * cos(60 * DEG), -48 * sin(60 * DEG)};
            const double zero[3] = {0, 0, 0};
            int steps = 0;
            double t = 0.0;
            const int n_steps = 30;
            for (int k = 0; steps < n_steps; k++) {
                t = k * 0.01;
                double a_nav[3], f[3], w[3], m[3];
                gait_accel(&g, t, g.walk_deg * DEG, a_nav);
                if (t < 2.0) { /* standing first: the filters settle */
                    a_nav[0] = NOISE_MPS2 * rng_gauss(&g_rng);
                    a_nav[1] = NOISE_MPS2 * rng_gauss(&g_rng);
                    a_nav[2] = G + NOISE_MPS2 * rng_gauss(&g_rng);
                }
                qrot_t(q, a_nav, f);
                for (int j = 0; j < 3; j++) {
                    w[j] = zero[j] + 0.003 * rng_gauss(&g_rng); /* held steady: walking straight */
                }
                const int64_t t_us = 1000000 + (int64_t)k * 10000;
                sf_attitude_update_imu(&att, &p, t_us, f, w);
                if (k % 2 == 0) {
                    qrot_t(q, m_nav, m);
                    for (int j = 0; j < 3; j++) {
                        m[j] += 0.4 * rng_gauss(&g_rng);
                    }
                    sf_attitude_update_mag(&att, &p, t_us + 2000, m);
                }
                double fn[3];
                sf_attitude_body_to_nav(&att, f, fn);
                sf_heading_update(&h, &p, t_us, fn, sf_attitude_yaw_rad(&att));
                if (t > 2.0 && t >= 2.0 + (steps + 0.5) / STEP_HZ + 0.1) {
                    sf_heading_on_step(&h, &p, t_us);
                    steps++;
                }
            }
            /* the offset is relative to the projected body x axis, whatever the tilt */
            const double yaw_true = atan2(2 * (q[1] * q[2] + q[0] * q[3]), 1 - 2 * (q[2] * q[2] + q[3] * q[3]));
            const double off_true = wrap(g.walk_deg * DEG - yaw_true);
            const double e_off = fabs(wrap(sf_heading_offset_rad(&h, &p) - off_true)) / DEG;
            const double e_walk =
                fabs(wrap(sf_heading_walk_rad(&h, &p, sf_attitude_yaw_rad(&att)) - g.walk_deg * DEG)) / DEG;
            printf("  chain %-13s offset %7.1f: est %7.2f (true %7.2f, err %.2f), walk err %.2f deg, good %d, "
                   "accel gated %u, mag rejected %u\n",
                   mode ? "mahony" : "complementary", offsets[i], sf_heading_offset_rad(&h, &p) / DEG, off_true / DEG,
                   e_off, e_walk, h.good_steps, att.accel_gated, att.mag_rejected);
            assert_true(h.confident);
            assert_true(e_off < 5.0);
            assert_true(e_walk < 5.0);
        }
    }
}

/* Same inputs → bit-identical outputs. */
static void test_deterministic(void **state)
{
    (void)state;
    gait_t g = base_gait(-135.0);
    g.jitter = 0.3;
    g.imu_hz = 50;
    const gait_result_t a = walk(&g, 71);
    const gait_result_t b = walk(&g, 71);
    assert_memory_equal(&a.h.offset_rad, &b.h.offset_rad, sizeof(double));
    assert_memory_equal(&a.h.sum, &b.h.sum, sizeof a.h.sum);
    assert_memory_equal(&a.h.mean_c, &b.h.mean_c, sizeof(double));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_offset_after_20_steps),
        cmocka_unit_test(test_offset_uneven_sampling),
        cmocka_unit_test(test_offset_through_a_turn),
        cmocka_unit_test(test_sign_comes_from_the_pendulum),
        cmocka_unit_test(test_map_rotation_and_fallback),
        cmocka_unit_test(test_long_windows_rejected),
        cmocka_unit_test(test_chain_attitude_to_heading),
        cmocka_unit_test(test_deterministic),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
