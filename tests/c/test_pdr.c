/* test_pdr.c — sf_pdr on synthetic 100 Hz IMU signals with seeded noise: step count, mounting
 * independence, heading integration, standing still, and gaps. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "sf_params.h"
#include "sf_pdr.h"

#define PI 3.14159265358979323846
#define G 9.80665
#define RATE_HZ 100
#define DT_US (1000000 / RATE_HZ)

#define STEP_HZ 1.8
#define BUMP_MPS2 2.5
#define N_STEPS 100
#define LEAD_S 2.0 /* still before the first step: the gravity filter settles */
#define TAIL_S 2.0 /* still after the last step: the last excursion ends */
#define NOISE_MPS2 0.05
#define GYRO_NOISE_RADPS 0.002

/* ---- seeded noise (xorshift64* + Box-Muller), the same on every platform ---- */
static uint64_t g_rng;

static double uniform01(void)
{
    g_rng ^= g_rng >> 12;
    g_rng ^= g_rng << 25;
    g_rng ^= g_rng >> 27;
    return (double)((g_rng * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}

static double gauss(void)
{
    const double u1 = uniform01() + 1e-300;
    const double u2 = uniform01();
    return sqrt(-2.0 * log(u1)) * cos(2.0 * PI * u2);
}

/* Board mountings: R maps the world frame (z up) into sensor axes. */
typedef struct {
    const char *name;
    double r[3][3];
} mount_t;

static const mount_t k_flat = {"z up", {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
/* -x up: world up (0,0,1) reads as (-1,0,0); world x → sensor z; world y → sensor y */
static const mount_t k_minus_x_up = {"-x up", {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}};

/* An arbitrary tilt: rotation by 30° about x then 40° about y. */
static mount_t tilted(void)
{
    const double a = 30 * PI / 180, b = 40 * PI / 180;
    const double rx[3][3] = {{1, 0, 0}, {0, cos(a), -sin(a)}, {0, sin(a), cos(a)}};
    const double ry[3][3] = {{cos(b), 0, sin(b)}, {0, 1, 0}, {-sin(b), 0, cos(b)}};
    mount_t m = {"tilted", {{0}}};
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            for (int k = 0; k < 3; k++) {
                m.r[i][j] += ry[i][k] * rx[k][j];
            }
        }
    }
    return m;
}

static void rotate(const mount_t *const m, const double w[3], double s[3])
{
    for (int i = 0; i < 3; i++) {
        s[i] = m->r[i][0] * w[0] + m->r[i][1] * w[1] + m->r[i][2] * w[2];
    }
}

/* World-frame vertical specific force at time t: gravity plus one half-sine bump per step, the
 * bump lasting half the step period. */
static double walk_vertical(const double t)
{
    const double period = 1.0 / STEP_HZ;
    const double u = t - LEAD_S;
    if (u < 0 || u >= N_STEPS * period) {
        return G;
    }
    const double phase = fmod(u, period) / (period / 2);
    return G + (phase < 1.0 ? BUMP_MPS2 * sin(PI * phase) : 0.0);
}

typedef struct {
    int steps_reported;
    sf_pdr_t pdr;
    sf_pose_t pose;
} run_t;

/* Feeds duration_s of samples: vertical(t) and yaw rate about world up, through mount m. */
static run_t run(const mount_t *const m, double (*vertical)(double), const double yaw_radps,
                 const double duration_s, const uint64_t seed)
{
    sf_params_t p;
    sf_params_default(&p);
    run_t r;
    memset(&r, 0, sizeof r);
    sf_pdr_init(&r.pdr, &p);
    g_rng = seed;
    const int n = (int)lround(duration_s * RATE_HZ) + 1;
    int last_index = 0;
    for (int k = 0; k < n; k++) {
        const double t = (double)k / RATE_HZ;
        const double fw[3] = {NOISE_MPS2 * gauss(), NOISE_MPS2 * gauss(), vertical(t) + NOISE_MPS2 * gauss()};
        const double ww[3] = {GYRO_NOISE_RADPS * gauss(), GYRO_NOISE_RADPS * gauss(), yaw_radps};
        sf_imu_sample_t s;
        s.t_us = 5000000 + (int64_t)k * DT_US;
        rotate(m, fw, s.accel_mps2);
        rotate(m, ww, s.gyro_radps);
        sf_step_t step;
        if (sf_pdr_update(&r.pdr, &p, &s, &step)) {
            r.steps_reported++;
            assert_int_equal(step.index, last_index + 1);
            assert_true(step.length_m == p.pdr_stride_m);
            assert_true(step.t_us == s.t_us);
            last_index = step.index;
        }
    }
    sf_pdr_pose(&r.pdr, &p, &r.pose);
    return r;
}

static double still(const double t)
{
    (void)t;
    return G;
}

static void check_walk(const mount_t *const m, const uint64_t seed)
{
    const run_t r = run(m, walk_vertical, 0.0, LEAD_S + N_STEPS / STEP_HZ + TAIL_S, seed);
    if (r.steps_reported != N_STEPS) {
        fail_msg("%s, seed %llu: %d steps, want %d", m->name, (unsigned long long)seed, r.steps_reported, N_STEPS);
    }
    assert_int_equal(r.pose.step_count, N_STEPS);
    assert_int_equal(r.pdr.gaps, 0);
    /* walking along +x (heading 0, no yaw): 100 × 0.70 m; gyro noise turns the heading a little */
    assert_true(fabs(r.pose.x_m - N_STEPS * 0.70) < 0.1);
    assert_true(fabs(r.pose.y_m) < 1.0);
}

static void test_walk_100_steps_flat(void **state)
{
    (void)state;
    for (uint64_t seed = 1; seed <= 5; seed++) {
        check_walk(&k_flat, seed);
    }
}

static void test_walk_100_steps_minus_x_up(void **state)
{
    (void)state;
    for (uint64_t seed = 1; seed <= 5; seed++) {
        check_walk(&k_minus_x_up, seed);
    }
}

static void test_walk_100_steps_tilted(void **state)
{
    (void)state;
    const mount_t m = tilted();
    for (uint64_t seed = 1; seed <= 5; seed++) {
        check_walk(&m, seed);
    }
}

static void check_yaw(const mount_t *const m)
{
    const run_t r = run(m, still, 0.1, 10.0, 42);
    /* 1000 intervals of 10 ms at 0.1 rad/s: 1.0 rad from the initial heading 0 */
    if (fabs(r.pose.heading_rad - 1.0) > 0.01) {
        fail_msg("%s: heading %.6f rad after 10 s at 0.1 rad/s, want 1.0 ± 0.01", m->name, r.pose.heading_rad);
    }
    assert_int_equal(r.pose.step_count, 0);
}

static void test_yaw_rate_integrates_to_heading(void **state)
{
    (void)state;
    check_yaw(&k_flat);
    check_yaw(&k_minus_x_up);
    const mount_t m = tilted();
    check_yaw(&m);
}

static void test_heading_wraps_to_pi(void **state)
{
    (void)state;
    /* 2.5 rad/s for 2 s: 5 rad, wrapped into (-π, π] */
    const run_t r = run(&k_flat, still, 2.5, 2.0, 7);
    assert_true(fabs(r.pose.heading_rad - (5.0 - 2 * PI)) < 0.02);
}

static void test_still_no_steps_no_motion(void **state)
{
    (void)state;
    const mount_t m = tilted();
    const run_t r = run(&m, still, 0.0, 30.0, 3);
    assert_int_equal(r.steps_reported, 0);
    assert_int_equal(r.pose.step_count, 0);
    assert_true(r.pose.x_m == 0.0 && r.pose.y_m == 0.0);
    assert_true(r.pose.sigma_m == 0.0);
    assert_int_equal(r.pdr.gaps, 0);
    assert_int_equal(r.pose.t_us, 5000000 + 3000 * (int64_t)DT_US);
}

static void test_gaps_restart_and_are_counted(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_pdr_t pdr;
    sf_pdr_init(&pdr, &p);
    sf_imu_sample_t s = {.t_us = 1000000, .accel_mps2 = {0, 0, G}, .gyro_radps = {0, 0, 0.5}};
    sf_step_t step;
    assert_false(sf_pdr_update(&pdr, &p, &s, &step)); /* first sample: starts */
    s.t_us += 10000;
    assert_false(sf_pdr_update(&pdr, &p, &s, &step));
    assert_int_equal(pdr.gaps, 0);
    const double h = pdr.heading_rad;
    assert_true(fabs(h - 0.005) < 1e-9);

    s.t_us += (int64_t)p.pdr_max_gap_ms * 1000 + 1; /* just over max_gap */
    assert_false(sf_pdr_update(&pdr, &p, &s, &step));
    assert_int_equal(pdr.gaps, 1);
    assert_true(pdr.heading_rad == h); /* nothing integrated over the gap */

    s.t_us += (int64_t)p.pdr_max_gap_ms * 1000; /* exactly max_gap: not a gap */
    assert_false(sf_pdr_update(&pdr, &p, &s, &step));
    assert_int_equal(pdr.gaps, 1);

    assert_false(sf_pdr_update(&pdr, &p, &s, &step)); /* same time again */
    assert_int_equal(pdr.gaps, 2);
    s.t_us -= 20000; /* backwards */
    assert_false(sf_pdr_update(&pdr, &p, &s, &step));
    assert_int_equal(pdr.gaps, 3);
    assert_int_equal(pdr.last_t_us, s.t_us);
}

static void test_init_pose_from_params(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    p.init_x_m = 12.5;
    p.init_y_m = -3.0;
    p.init_heading_rad = PI / 2;
    p.init_floor = 3;
    sf_pdr_t pdr;
    sf_pdr_init(&pdr, &p);
    sf_pose_t pose;
    sf_pdr_pose(&pdr, &p, &pose);
    assert_true(pose.x_m == 12.5 && pose.y_m == -3.0);
    assert_true(pose.heading_rad == PI / 2);
    assert_int_equal(pose.floor, 3);
    assert_int_equal(pose.step_count, 0);
    assert_int_equal(pose.scheme, sf_scheme_pdr_only);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_walk_100_steps_flat),
        cmocka_unit_test(test_walk_100_steps_minus_x_up),
        cmocka_unit_test(test_walk_100_steps_tilted),
        cmocka_unit_test(test_yaw_rate_integrates_to_heading),
        cmocka_unit_test(test_heading_wraps_to_pi),
        cmocka_unit_test(test_still_no_steps_no_motion),
        cmocka_unit_test(test_gaps_restart_and_are_counted),
        cmocka_unit_test(test_init_pose_from_params),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
