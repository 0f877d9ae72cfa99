/* test_estimator.c — the whole PDR chain (sf_estimator) on a synthetic walk with known answers.
 *
 * GIVEN a walker standing 5 s, walking N steps straight along a known direction, then standing
 * 10 s, with the device level and yawed by a fixed mounting offset, WHEN every IMU and magnetometer
 * sample goes through sf_estimator, THEN the step count is N, the displacement points along the
 * walking direction, the position does not move while standing, and the same input gives
 * bit-identical output. The gait follows the inverted pendulum: forward acceleration is in antiphase
 * with vertical velocity. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sf_estimator.h"

#define PI 3.14159265358979323846
#define G 9.80665

typedef struct {
    int steps;              /* accepted steps */
    double x_m, y_m;        /* final position */
    double walk_end_x_m, walk_end_y_m; /* position when the walk stopped */
    double mid_x_m, mid_y_m; /* position half-way through the walk */
    sf_step_t last_step;
    uint64_t digest;        /* FNV-1a over every output, for determinism */
} run_result_t;

static uint64_t fnv(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) {
        h = (h ^ p[i]) * 1099511628211ull;
    }
    return h;
}

/* Rotates a nav vector into a level body frame whose x axis points at yaw (CCW from east). */
static void nav_to_body(const double v[3], double yaw, double out[3])
{
    out[0] = cos(yaw) * v[0] + sin(yaw) * v[1];
    out[1] = -sin(yaw) * v[0] + cos(yaw) * v[1];
    out[2] = v[2];
}

/* Sample index whose accelerometer z and, 300 samples later, gyroscope z carry a flipped int16 sign bit
 * (a corrupt frame), or -1. */
static int g_corrupt_k = -1;
/* Samples [g_gap_k, g_gap_k + 500) never arrive (a 5 s bus silence), or -1; g_no_bridge turns the
 * gap bridge off. */
static int g_gap_k = -1;
static bool g_no_bridge = false;

/* climb_mps: the walker rises at this speed while walking (stairs; the barometer at 10 Hz sees it,
 * the IMU does not: the same gait as on level ground) */
static run_result_t run_walk(int n_steps, double walk_dir_rad, double mount_offset_rad, double step_hz,
                             double climb_mps)
{
    sf_params_t p;
    sf_params_default(&p);
    p.gap_bridge = g_no_bridge ? 0 : 1;
    sf_estimator_t est;
    sf_estimator_init(&est, &p);
    run_result_t r = {0};
    r.digest = 1469598103934665603ull;

    const double rate_hz = 100.0, still0_s = 5.0, still1_s = 10.0;
    /* n heel strikes (peaks of a_z at phase ¼), ending at phase ½ of the last cycle: the walker
     * stops in stance, not mid-rise (a cut-off rise would read as one more step) */
    const double walk_s = (n_steps - 0.5) / step_hz;
    const double total_s = still0_s + walk_s + still1_s;
    const double device_yaw = walk_dir_rad - mount_offset_rad; /* offset = walk − device yaw */
    const double dip = 60.0 * PI / 180.0, field = 48.0;
    const double m_nav[3] = {0.0, field * cos(dip), -field * sin(dip)};
    const double a_v = 2.5, w = 2.0 * PI * step_hz;
    unsigned rng = 12345u;
    for (int k = 0; k < (int)(total_s * rate_hz); k++) {
        const double t = k / rate_hz;
        const double tw = t - still0_s;
        if (g_gap_k >= 0 && k >= g_gap_k && k < g_gap_k + 500) {
            continue;
        }
        const bool walking = tw >= 0.0 && tw < walk_s;
        /* vertical: a_z = A sin(ωt); v_z = −A/ω cos(ωt); forward a_f = −c·v_z (inverted pendulum) */
        const double az = walking ? a_v * sin(w * tw) : 0.0;
        const double af = walking ? 1.2 * cos(w * tw) : 0.0;
        const double al = walking ? 0.3 * sin(0.5 * w * tw) : 0.0;
        rng = rng * 1103515245u + 12345u;
        const double noise = ((double)(rng >> 8) / 16777216.0 - 0.5) * 0.1;
        const double f_nav[3] = {af * cos(walk_dir_rad) - al * sin(walk_dir_rad),
                                 af * sin(walk_dir_rad) + al * cos(walk_dir_rad), G + az + noise};
        sf_imu_sample_t s = {.t_us = (int64_t)llround(t * 1e6)};
        nav_to_body(f_nav, device_yaw, s.accel_mps2);
        if (k == g_corrupt_k) {
            s.accel_mps2[2] -= 156.9; /* the sign bit of the DBC's int16 at 16 g full scale */
        }
        if (k == g_corrupt_k + 300) {
            s.gyro_radps[2] += 34.9; /* the sign bit at 2000 deg/s */
        }
        if (k % 2 == 0) {
            double m_body[3];
            nav_to_body(m_nav, device_yaw, m_body);
            sf_estimator_mag(&est, &p, s.t_us, m_body);
        }
        if (k % 10 == 0) {
            const double h_m = climb_mps * fmin(fmax(tw, 0.0), walk_s);
            /* the inverse of sf_floor's height(p) = 44330.77 (1 − (p/101325)^0.190263) */
            sf_estimator_baro(&est, &p, s.t_us, 101325.0 * pow(1.0 - h_m / 44330.77, 1.0 / 0.190263));
        }
        sf_step_t steps[SF_ESTIMATOR_MAX_STEPS];
        memset(steps, 0, sizeof steps); /* padding too: the digest hashes raw bytes */
        const int n = sf_estimator_imu(&est, &p, &s, steps);
        for (int i = 0; i < n; i++) {
            r.steps++;
            r.last_step = steps[i];
            r.digest = fnv(r.digest, &steps[i], sizeof steps[i]);
            if (r.steps == n_steps / 2) {
                r.mid_x_m = est.x_m;
                r.mid_y_m = est.y_m;
            }
        }
        if (walking || tw < walk_s + 1.0) {
            r.walk_end_x_m = est.x_m;
            r.walk_end_y_m = est.y_m;
        }
        sf_pose_t pose;
        memset(&pose, 0, sizeof pose);
        sf_estimator_pose(&est, &pose);
        r.digest = fnv(r.digest, &pose, sizeof pose);
    }
    r.x_m = est.x_m;
    r.y_m = est.y_m;
    return r;
}

static double angle_deg(double a)
{
    return fabs(atan2(sin(a), cos(a))) * 180.0 / PI;
}

static void test_counts_steps_and_walks_straight(void **state)
{
    (void)state;
    const double dir = 30.0 * PI / 180.0;
    const run_result_t r = run_walk(100, dir, 0.0, 1.8, 0.0);
    assert_int_equal(r.steps, 100);
    const double dist = hypot(r.x_m, r.y_m);
    assert_true(dist > 30.0 && dist < 120.0); /* Weinberg with the default K, 0.3–1.2 m per step */
    assert_true(angle_deg(atan2(r.y_m, r.x_m) - dir) < 3.0);
    assert_true(angle_deg(r.last_step.heading_rad - dir) < 3.0);
    assert_true(r.last_step.accel_range_mps2 > 3.0 && r.last_step.accel_range_mps2 < 6.0);
}

static void test_one_corrupt_sample_changes_nothing(void **state)
{
    (void)state;
    const double dir = 30.0 * PI / 180.0;
    const run_result_t clean = run_walk(100, dir, 0.0, 1.8, 0.0);
    g_corrupt_k = 2000; /* mid-walk */
    const run_result_t bad = run_walk(100, dir, 0.0, 1.8, 0.0);
    g_corrupt_k = -1;
    assert_int_equal(bad.steps, clean.steps);
    assert_true(hypot(bad.x_m - clean.x_m, bad.y_m - clean.y_m) < 0.2);
}

static void test_a_silence_mid_walk_is_bridged(void **state)
{
    (void)state;
    const double dir = 30.0 * PI / 180.0;
    const run_result_t clean = run_walk(100, dir, 0.0, 1.8, 0.0);
    g_gap_k = 2000; /* 15 s into the walk: 5 s, 9 steps, never arrive */
    g_no_bridge = true;
    const run_result_t lost = run_walk(100, dir, 0.0, 1.8, 0.0);
    g_no_bridge = false;
    const run_result_t bridged = run_walk(100, dir, 0.0, 1.8, 0.0);
    g_gap_k = -1;
    const double d_clean = hypot(clean.x_m, clean.y_m);
    const double d_lost = hypot(lost.x_m, lost.y_m);
    const double d_bridged = hypot(bridged.x_m, bridged.y_m);
    assert_true(lost.steps <= clean.steps - 8);
    assert_int_equal(bridged.steps, lost.steps); /* bridging credits distance, not steps */
    assert_true(d_clean - d_lost > 0.08 * d_clean);
    assert_true(fabs(d_bridged - d_clean) < 0.03 * d_clean);
    assert_true(angle_deg(atan2(bridged.y_m, bridged.x_m) - dir) < 3.0);
}

static void test_still_does_not_drift(void **state)
{
    (void)state;
    const run_result_t r = run_walk(60, 0.0, 0.0, 1.8, 0.0);
    /* 9 s of standing after the walk: not a millimetre */
    assert_true(r.x_m == r.walk_end_x_m && r.y_m == r.walk_end_y_m);
}

static void test_mounting_offset_is_learnt(void **state)
{
    (void)state;
    const double dir = -60.0 * PI / 180.0;
    const run_result_t r = run_walk(120, dir, 90.0 * PI / 180.0, 1.8, 0.0);
    /* the second half of the walk, after the offset is learnt, goes the right way */
    const double dx = r.x_m - r.mid_x_m, dy = r.y_m - r.mid_y_m;
    assert_true(angle_deg(atan2(dy, dx) - dir) < 5.0);
    assert_true(angle_deg(r.last_step.heading_rad - dir) < 5.0);
}

static void test_paces(void **state)
{
    (void)state;
    const double hz[] = {1.4, 1.8, 2.2};
    for (int i = 0; i < 3; i++) {
        const run_result_t r = run_walk(150, 1.0, 0.0, hz[i], 0.0);
        assert_int_equal(r.steps, 150);
    }
}

/* GIVEN the same gait on level ground and climbing stairs (0.3 m/s: a 17 cm riser per step at 1.8 Hz)
 * WHEN both walks go through the estimator
 * THEN a stairs step advances Blondel's going G = L − 2R (L the level step, R = v·T its rise) and a
 * level step L: the last steps differ by 2 · 0.3 m/s · T, within 1 cm. */
static void test_stairs_step_is_the_going(void **state)
{
    (void)state;
    const run_result_t level = run_walk(60, 0.5, 0.0, 1.8, 0.0);
    const run_result_t stairs = run_walk(60, 0.5, 0.0, 1.8, 0.3);
    assert_int_equal(level.last_step.activity, sf_activity_walking);
    assert_int_equal(stairs.last_step.activity, sf_activity_stairs_up);
    assert_int_equal(stairs.steps, level.steps);
    const double rise_m = 0.3 * stairs.last_step.period_s;
    assert_true(fabs(stairs.last_step.period_s - 1.0 / 1.8) < 0.05);
    assert_true(fabs((level.last_step.length_m - stairs.last_step.length_m) - 2.0 * rise_m) < 0.01);
    assert_true(stairs.last_step.length_m > 0.2 && stairs.last_step.length_m < level.last_step.length_m - 0.25);
}

static void test_same_input_gives_identical_output(void **state)
{
    (void)state;
    const run_result_t a = run_walk(80, 2.0, 0.5, 1.9, 0.0);
    const run_result_t b = run_walk(80, 2.0, 0.5, 1.9, 0.0);
    assert_true(a.digest == b.digest);
    assert_true(a.x_m == b.x_m && a.y_m == b.y_m && a.steps == b.steps);
    assert_true(a.last_step.length_m == b.last_step.length_m && a.last_step.t_us == b.last_step.t_us);
}

/* GIVEN a site of floors −2, −1, 0 (3 m storeys, no radio map) and the default init.floor 0, WHEN the
 * barometer climbs one storey, THEN the start floor is proven wrong (nothing is above 0): the walk
 * started on −1 and is on 0 now, for the status and for every scheme alike. */
static void test_site_floors_prove_the_start(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    static sf_estimator_t est;
    sf_estimator_init(&est, &p);
    const double heights[] = {0.0, 3.0, 6.0};
    const sf_site_t site = {.lowest_floor = -2, .n_floors = 3, .floor_height_m = heights};
    static sf_fingerprint_workspace_t ws;
    assert_int_equal(sf_estimator_attach_site(&est, &p, &site, &ws), 0);
    assert_true(est.floor_vote_active);
    const double pa0 = 100000.0, pa_per_m = 1.0 / 0.0843; /* near 100 kPa */
    for (int i = 0; i <= 60 * 25; i++) { /* 25 Hz: 10 s still, 12 s up 3 m, still again */
        const double t_s = i / 25.0;
        const double h_m = t_s < 10.0 ? 0.0 : (t_s < 22.0 ? (t_s - 10.0) * 0.25 : 3.0);
        sf_estimator_baro(&est, &p, 1000000 + (int64_t)i * 40000, pa0 - pa_per_m * h_m);
    }
    sf_estimator_status_t st;
    sf_estimator_status(&est, &st);
    assert_int_equal(st.floor, 0);
    assert_int_equal(est.floor_vote.start, -1);
    assert_int_equal(est.floor_vote.proofs, 1);
    assert_int_equal(est.floor.changes, 1);
    assert_true(fabs(sf_floor_height_m(&est.floor) - 6.0) < 0.2); /* H(0), re-referenced */
    sf_pose_t pose;
    for (int s = 0; s < sf_scheme_count; s++) {
        (void)sf_estimator_scheme_pose(&est, &p, s, &pose);
        assert_int_equal(pose.floor, 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_counts_steps_and_walks_straight),
        cmocka_unit_test(test_one_corrupt_sample_changes_nothing),
        cmocka_unit_test(test_a_silence_mid_walk_is_bridged),
        cmocka_unit_test(test_still_does_not_drift),
        cmocka_unit_test(test_mounting_offset_is_learnt),
        cmocka_unit_test(test_paces),
        cmocka_unit_test(test_stairs_step_is_the_going),
        cmocka_unit_test(test_same_input_gives_identical_output),
        cmocka_unit_test(test_site_floors_prove_the_start),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
