/* test_floor.c — sf_floor on simulated barometer signals (seeded noise and drift): stair climbs and
 * descents, a 5-minute flat walk without false changes, an elevator ride over three floors, a site
 * table with uneven floors, bad samples, gaps, determinism; a dog-leg landing at half a storey after
 * weather drift, a lift's commit time, virtual floors beyond the table, shift and at-floor. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sf_error.h"
#include "sf_floor.h"
#include "sf_params.h"
#include "sf_test_gait.h" /* rng */

#define P0_PA 100500.0      /* site pressure at the datum */
#define PA_PER_M 12.0       /* ≈ ρg near sea level */
#define T0_US 7000000LL

/* A vertical profile: piecewise-linear true height over time. */
typedef struct {
    int n;
    double t_s[8];
    double h_m[8];
} profile_t;

static double profile_height(const profile_t *const pr, const double t)
{
    if (t <= pr->t_s[0]) {
        return pr->h_m[0];
    }
    for (int i = 1; i < pr->n; i++) {
        if (t <= pr->t_s[i]) {
            const double w = (t - pr->t_s[i - 1]) / (pr->t_s[i] - pr->t_s[i - 1]);
            return pr->h_m[i - 1] + w * (pr->h_m[i] - pr->h_m[i - 1]);
        }
    }
    return pr->h_m[pr->n - 1];
}

typedef struct {
    double rate_hz, jitter;
    double noise_pa;      /* white, per sample */
    double drift_pa_per_s; /* weather: pressure rising (height falling) */
    uint64_t seed;
} baro_model_t;

static const baro_model_t k_baro25 = {25.0, 0.2, 1.5, 0.02, 1};
static const baro_model_t k_baro10 = {10.0, 0.3, 1.5, 0.02, 2};

typedef struct {
    int16_t floor_at_end;
    int changes;            /* floor changes seen */
    double first_change_s;  /* time of the first change, −1 if none */
    double max_abs_vspeed;  /* after a 5 s warm-up */
    double min_vspeed, max_vspeed;
    sf_floor_t f;
} result_t;

static result_t g_res, g_res2;

static void run(result_t *const r, sf_params_t *const p, const profile_t *const pr, const double duration_s,
                const baro_model_t *const m, const double *table, const int n_table, const int16_t lowest)
{
    memset(r, 0, sizeof *r);
    r->first_change_s = -1.0;
    r->min_vspeed = 1e9;
    r->max_vspeed = -1e9;
    rng_t rng = {m->seed};
    sf_floor_init(&r->f, p);
    if (table != NULL) {
        assert_int_equal(sf_floor_set_heights(&r->f, table, n_table, lowest), SF_OK);
    }
    int16_t floor = sf_floor_current(&r->f);
    for (double t = 0.0; t < duration_s; t += (1.0 / m->rate_hz) * (1.0 + m->jitter * rng_pm1(&rng))) {
        const double pa = P0_PA - PA_PER_M * profile_height(pr, t) + m->drift_pa_per_s * t + m->noise_pa * rng_gauss(&rng);
        sf_floor_update(&r->f, p, T0_US + (int64_t)llround(t * 1e6), pa);
        if (sf_floor_current(&r->f) != floor) {
            floor = sf_floor_current(&r->f);
            r->changes++;
            if (r->first_change_s < 0) {
                r->first_change_s = t;
            }
        }
        if (t > 5.0) {
            const double v = sf_floor_vertical_speed_mps(&r->f);
            r->max_abs_vspeed = fmax(r->max_abs_vspeed, fabs(v));
            r->min_vspeed = fmin(r->min_vspeed, v);
            r->max_vspeed = fmax(r->max_vspeed, v);
        }
    }
    r->floor_at_end = sf_floor_current(&r->f);
}

static void test_pressure_to_height(void **state)
{
    (void)state;
    assert_true(fabs(sf_floor_pressure_to_height_m(101325.0)) < 1e-9);
    /* ≈ −1/12 m/Pa at sea level */
    const double slope = sf_floor_pressure_to_height_m(101325.0 + 0.5) - sf_floor_pressure_to_height_m(101325.0 - 0.5);
    assert_true(fabs(slope - (-0.0832)) < 0.0005);
    /* 1000 hPa ≈ 111 m, 900 hPa ≈ 989 m (ICAO table) */
    assert_true(fabs(sf_floor_pressure_to_height_m(100000.0) - 110.9) < 0.5);
    assert_true(fabs(sf_floor_pressure_to_height_m(90000.0) - 988.5) < 1.0);
}

/* GIVEN a barometer's samples (noise, a 30 m climb and descent, the extremes of the range) WHEN
 * sf_floor_update's series turns them into heights (sf_floor_baro_height_m) THEN every height is within
 * 1e-8 m of the pow form (the bound sf_floor.c derives: 2e-9 m), and a pow runs only once per ≈ 8.5 m of
 * climb (the reference moves ~8 times, not on every sample). */
static void test_baro_height_series_matches_pow(void **state)
{
    (void)state;
    sf_floor_t f = {0};
    double worst_m = 0.0;
    int anchors = 0;
    for (int k = 0; k < 20000; k++) {
        const double climb_m = 30.0 * sin(3.14159265358979323846 * k / 20000.0); /* up and back down */
        const double noise_pa = 2.0 * sin(12.9898 * k) * cos(78.233 * k);         /* deterministic jitter */
        const double p_pa = 101325.0 - 12.0 * climb_m + noise_pa;
        const double ref_pa = f.baro_ref_pa;
        worst_m = fmax(worst_m, fabs(sf_floor_baro_height_m(&f, p_pa) - sf_floor_pressure_to_height_m(p_pa)));
        anchors += f.baro_ref_pa != ref_pa;
    }
    const double ends_pa[] = {SF_FLOOR_MIN_PA, SF_FLOOR_MIN_PA + 29.0, SF_FLOOR_MAX_PA, SF_FLOOR_MAX_PA - 50.0};
    for (size_t i = 0; i < sizeof ends_pa / sizeof ends_pa[0]; i++) {
        worst_m = fmax(worst_m, fabs(sf_floor_baro_height_m(&f, ends_pa[i]) - sf_floor_pressure_to_height_m(ends_pa[i])));
    }
    printf("baro height series: largest |difference| from pow %.2e m, %d references for a 2 x 30 m climb\n", worst_m,
           anchors);
    assert_true(worst_m < 1e-8);
    assert_true(anchors >= 2 && anchors <= 20);
}

/* GIVEN a walker on floor 0, WHEN she climbs 3.5 m of stairs in 10 s and stays on the landing, THEN
 * the floor becomes 1 once, no later than 3 s after the landing, and the altimeter reads the landing. */
static void check_climb(const baro_model_t *const m)
{
    sf_params_t p;
    sf_params_default(&p);
    const profile_t climb = {4, {0, 20, 30, 1000}, {0, 0, 3.5, 3.5}};
    run(&g_res, &p, &climb, 60.0, m, NULL, 0, 0);
    assert_int_equal(g_res.floor_at_end, 1);
    assert_int_equal(g_res.changes, 1);
    assert_true(g_res.first_change_s > 25.0 && g_res.first_change_s < 30.0 + 3.0);
    assert_true(fabs(sf_floor_height_m(&g_res.f) - 3.5) < 0.3);
    assert_true(g_res.f.rereferences >= 1);
    /* the climb speed (0.35 m/s) shows in the vertical speed */
    assert_true(g_res.max_vspeed > 0.25 && g_res.max_vspeed < 0.45);
    assert_int_equal(g_res.f.gaps + g_res.f.bad + g_res.f.backwards, 0);
}

static void test_stair_climb_25hz(void **state)
{
    (void)state;
    check_climb(&k_baro25);
}

static void test_stair_climb_10hz(void **state)
{
    (void)state;
    check_climb(&k_baro10);
}

static void test_stair_descent(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    p.init_floor = 1;
    const profile_t down = {4, {0, 20, 30, 1000}, {3.5, 3.5, 0, 0}};
    run(&g_res, &p, &down, 60.0, &k_baro25, NULL, 0, 0);
    assert_int_equal(g_res.floor_at_end, 0);
    assert_int_equal(g_res.changes, 1);
    assert_true(g_res.first_change_s > 25.0 && g_res.first_change_s < 33.0);
    assert_true(g_res.min_vspeed < -0.25);
}

/* Five minutes on one floor with baro noise, weather drift (0.03 Pa/s ≈ 0.75 m in 5 min) and a slow
 * ventilation swing: no floor change, and the vertical speed stays far below the stairs threshold. */
static void test_flat_walk_no_false_change(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    const profile_t flat = {2, {0, 1000}, {0, 0}};
    for (uint64_t seed = 1; seed <= 3; seed++) {
        const baro_model_t m = {25.0, 0.3, 2.0, 0.03, seed};
        run(&g_res, &p, &flat, 300.0, &m, NULL, 0, 0);
        assert_int_equal(g_res.changes, 0);
        assert_int_equal(g_res.floor_at_end, 0);
        assert_true(g_res.max_abs_vspeed < 0.5 * p.activity_stairs_vspeed_mps);
        assert_true(fabs(sf_floor_height_m(&g_res.f)) < 0.5); /* drift absorbed */
    }
    /* without the drift removal the same drift still does not change the floor in 5 minutes */
    p.floor_drift_tau_s = 1e6;
    const baro_model_t m = {25.0, 0.3, 2.0, 0.03, 9};
    run(&g_res, &p, &flat, 300.0, &m, NULL, 0, 0);
    assert_int_equal(g_res.changes, 0);
    assert_true(sf_floor_height_m(&g_res.f) < -0.5); /* the drift shows: pressure up, height down */
}

/* An elevator: 10.5 m up at 1.5 m/s; floor 3 at the end, vertical speed near 1.5 m/s on the way. */
static void test_elevator_three_floors(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    const profile_t lift = {4, {0, 10, 17, 1000}, {0, 0, 10.5, 10.5}};
    run(&g_res, &p, &lift, 40.0, &k_baro25, NULL, 0, 0);
    assert_int_equal(g_res.floor_at_end, 3);
    assert_true(g_res.max_vspeed > 1.2 && g_res.max_vspeed < 1.7);
    assert_true(fabs(sf_floor_height_m(&g_res.f) - 10.5) < 0.3);
}

/* A site table: basement −1 at −3.5 m, lobby 0 at 0, a 5 m lobby ceiling, then 3.2 m floors. */
static void test_site_table_uneven_floors(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    const double table[] = {-3.5, 0.0, 5.0, 8.2, 11.4};
    /* 0 → 1 needs 5 m */
    const profile_t up5 = {4, {0, 20, 34, 1000}, {0, 0, 5.0, 5.0}};
    run(&g_res, &p, &up5, 60.0, &k_baro25, table, 5, -1);
    assert_int_equal(g_res.floor_at_end, 1);
    assert_true(fabs(sf_floor_height_m(&g_res.f) - 5.0) < 0.3);
    /* 2.3 m (below the 2.5 m mid-height plus hysteresis) stays on 0, though 3.5 m floors would change */
    const profile_t up23 = {4, {0, 20, 27, 1000}, {0, 0, 2.3, 2.3}};
    run(&g_res, &p, &up23, 40.0, &k_baro25, table, 5, -1);
    assert_int_equal(g_res.changes, 0);
    run(&g_res, &p, &up23, 40.0, &k_baro25, NULL, 0, 0);
    assert_int_equal(g_res.floor_at_end, 1);
    /* down into the basement, then to the top floor (the table's end) */
    const profile_t tour = {6, {0, 10, 20, 60, 80, 1000}, {0, 0, -3.5, -3.5, 11.4, 11.4}};
    run(&g_res, &p, &tour, 120.0, &k_baro25, table, 5, -1);
    assert_int_equal(g_res.floor_at_end, 3);
    assert_true(fabs(sf_floor_height_m(&g_res.f) - 11.4) < 0.3);
}

static void test_set_heights_validation(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_floor_t f;
    sf_floor_init(&f, &p);
    const double ok[] = {0.0, 4.0, 7.5};
    const double not_increasing[] = {0.0, 4.0, 4.0};
    const double with_nan[] = {0.0, NAN, 7.5};
    assert_int_equal(sf_floor_set_heights(&f, NULL, 3, 0), SF_EINVAL);
    assert_int_equal(sf_floor_set_heights(&f, ok, 0, 0), SF_EINVAL);
    assert_int_equal(sf_floor_set_heights(&f, ok, SF_FLOOR_CAPACITY + 1, 0), SF_EINVAL);
    assert_int_equal(sf_floor_set_heights(&f, not_increasing, 3, 0), SF_EINVAL);
    assert_int_equal(sf_floor_set_heights(&f, with_nan, 3, 0), SF_EINVAL);
    assert_int_equal(sf_floor_set_heights(&f, ok, 3, INT16_MAX), SF_EINVAL);
    assert_int_equal(f.n_floors, SF_FLOOR_CAPACITY); /* unchanged */
    /* the current floor outside the new table moves to its nearest end */
    p.init_floor = 7;
    sf_floor_init(&f, &p);
    assert_int_equal(sf_floor_current(&f), 7);
    assert_int_equal(sf_floor_set_heights(&f, ok, 3, 0), SF_OK);
    assert_int_equal(sf_floor_current(&f), 2);
    /* once started, a new table re-references at once */
    sf_floor_update(&f, &p, 1000000, P0_PA);
    assert_true(sf_floor_height_m(&f) == 7.5);
    const double other[] = {0.0, 3.0, 6.0};
    assert_int_equal(sf_floor_set_heights(&f, other, 3, 0), SF_OK);
    assert_true(sf_floor_height_m(&f) == 6.0);
}

static void test_default_table(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    p.init_floor = -2;
    p.floor_height_m = 4.0;
    sf_floor_t f;
    sf_floor_init(&f, &p);
    assert_int_equal(sf_floor_current(&f), -2);
    assert_int_equal(f.lowest_floor, -2 - SF_FLOOR_DEFAULT_BELOW);
    assert_true(f.height_m[SF_FLOOR_DEFAULT_BELOW] == -8.0); /* floor −2 at −2 × 4 m */
    sf_floor_update(&f, &p, 1000000, P0_PA);
    assert_true(sf_floor_height_m(&f) == -8.0);
    assert_true(sf_floor_vertical_speed_mps(&f) == 0.0);
}

static void test_bad_samples_gaps_backwards(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_floor_t f;
    sf_floor_init(&f, &p);
    sf_floor_update(&f, &p, 1000000, NAN);
    sf_floor_update(&f, &p, 1000000, 0.0);
    sf_floor_update(&f, &p, 1000000, 2e5);
    assert_int_equal(f.bad, 3);
    assert_false(f.started);
    sf_floor_update(&f, &p, 1000000, P0_PA);
    sf_floor_update(&f, &p, 1040000, P0_PA);
    sf_floor_update(&f, &p, 1040000, P0_PA); /* same time */
    sf_floor_update(&f, &p, 1000000, P0_PA); /* backwards */
    assert_int_equal(f.backwards, 2);
    /* a gap: 10 s later the pressure shows 3.5 m up; the filters restart there, no speed spike */
    sf_floor_update(&f, &p, 11040000, P0_PA - PA_PER_M * 3.5);
    assert_int_equal(f.gaps, 1);
    const double up_m = sf_floor_pressure_to_height_m(P0_PA - PA_PER_M * 3.5) - sf_floor_pressure_to_height_m(P0_PA);
    assert_true(fabs(up_m - 3.5) < 0.03); /* 12 Pa/m is the sea-level slope; at 100.5 kPa it is 11.95 */
    assert_true(fabs(sf_floor_height_m(&f) - up_m) < 1e-9);
    assert_true(sf_floor_vertical_speed_mps(&f) == 0.0);
    /* ... and the floor follows after the confirmation time */
    for (int64_t t = 11080000; t < 11080000 + 3000000; t += 40000) {
        sf_floor_update(&f, &p, t, P0_PA - PA_PER_M * 3.5);
    }
    assert_int_equal(sf_floor_current(&f), 1);
}

/* A dog-leg stair (SIL tour): the landing sits at exactly half a storey, where the truth
 * already counts the upper floor. Climbing, the mid-height is enough, so the change commits on the
 * landing (confirm_ms after arriving), not a flight later; and the landing is no floor, so nothing is
 * re-referenced there (a re-reference would put floor 1 at 1.75 m and make the second flight floor 2).
 * 200 s of weather drift first (0.02 Pa/s: the relaxation lags it by 0.2 m, more than the landing's
 * margin): leaving floor 0 re-references it. */
static void test_dogleg_landing(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    const profile_t stair = {6, {0, 200, 207, 211, 218, 1000}, {0, 0, 1.75, 1.75, 3.5, 3.5}};
    run(&g_res, &p, &stair, 260.0, &k_baro25, NULL, 0, 0);
    assert_int_equal(g_res.changes, 1);
    assert_int_equal(g_res.floor_at_end, 1);
    assert_true(g_res.first_change_s > 207.0 && g_res.first_change_s < 208.5);
    assert_true(fabs(sf_floor_height_m(&g_res.f) - 3.5) < 0.3);
    /* descending the same stair commits on the landing too (toward the lower floor) */
    const profile_t down = {6, {0, 20, 27, 31, 38, 1000}, {3.5, 3.5, 1.75, 1.75, 0, 0}};
    sf_params_t p1 = p;
    p1.init_floor = 1;
    run(&g_res, &p1, &down, 80.0, &k_baro25, NULL, 0, 0);
    assert_int_equal(g_res.changes, 1);
    assert_int_equal(g_res.floor_at_end, 0);
    assert_true(g_res.first_change_s > 27.0 && g_res.first_change_s < 28.5);
}

/* The lead-corrected height: a lift at 1 m/s over one storey commits within 1 s of passing the
 * mid-height (the low-passed height alone lags it by τ = 1 s). */
static void test_lift_commits_near_mid_height(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    const profile_t lift = {4, {0, 10, 13.5, 1000}, {0, 0, 3.5, 3.5}}; /* mid-height at 11.75 s */
    run(&g_res, &p, &lift, 40.0, &k_baro25, NULL, 0, 0);
    assert_int_equal(g_res.changes, 1);
    assert_true(g_res.first_change_s > 11.75 && g_res.first_change_s < 12.75);
}

/* Beyond the table the floors go on, one end storey apart (a wrong start floor shows there). */
static void test_virtual_floors(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    const double table[] = {0.0, 2.5, 6.0};
    const profile_t down2 = {4, {0, 10, 30, 1000}, {0, 0, -5.0, -5.0}};
    run(&g_res, &p, &down2, 60.0, &k_baro25, table, 3, 0); /* floor 0 is the lowest */
    assert_int_equal(g_res.floor_at_end, -2); /* two virtual floors of 2.5 m (the bottom storey) */
    assert_true(fabs(sf_floor_height_m(&g_res.f) + 5.0) < 0.3);
    const profile_t up = {4, {0, 10, 30, 1000}, {0, 0, 9.5, 9.5}};
    run(&g_res, &p, &up, 60.0, &k_baro25, table, 3, 0);
    assert_int_equal(g_res.floor_at_end, 3); /* 6 + 3.5 m (the top storey) */
}

/* sf_floor_shift renumbers the floor and keeps the body where it is, or re-references it. */
static void test_shift_and_at_floor(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_floor_t f;
    sf_floor_init(&f, &p);
    const double table[] = {0.0, 3.0, 7.0};
    assert_int_equal(sf_floor_set_heights(&f, table, 3, -1), SF_OK); /* floors −1, 0, 1 */
    assert_int_equal(sf_floor_current(&f), 0);
    const double pa0 = 100000.0;
    int64_t t = T0_US;
    for (int i = 0; i < 50; i++, t += 40000) {
        sf_floor_update(&f, &p, t, pa0);
    }
    assert_true(fabs(sf_floor_height_m(&f) - 3.0) < 1e-9);
    assert_true(sf_floor_at_floor(&f, &p) && sf_floor_settled(&f, &p));
    /* 1.9 m up at 0.05 m/s (a ramp, slower than settle_vspeed) and held, drift removal off: short of
     * the change (5.15 m) and no longer at floor 0, |4.9 − 3| = 1.9 ≥ |4.9 − 7| − 2 · 0.15 = 1.8 */
    p.floor_drift_tau_s = 1e6;
    const double pa_up = pa0 - 1.9 / 0.0843;
    for (int i = 0; i < 1500; i++, t += 40000) {
        const double w = i < 950 ? (double)i / 950.0 : 1.0; /* 38 s ramp, then 22 s held */
        sf_floor_update(&f, &p, t, pa0 + w * (pa_up - pa0));
    }
    assert_int_equal(sf_floor_current(&f), 0);
    assert_true(fabs(sf_floor_height_m(&f) - 4.9) < 0.05);
    assert_false(sf_floor_at_floor(&f, &p));
    assert_false(sf_floor_settled(&f, &p));
    sf_floor_shift(&f, 1, false);
    assert_int_equal(sf_floor_current(&f), 1);
    assert_true(fabs(sf_floor_height_m(&f) - 8.9) < 0.05); /* H(1) + the same 1.9 m */
    sf_floor_shift(&f, -2, true);
    assert_int_equal(sf_floor_current(&f), -1);
    assert_true(sf_floor_height_m(&f) == 0.0); /* re-referenced to H(−1) */
    assert_int_equal(f.shifts, 2);
    sf_floor_shift(&f, 0, true);
    assert_int_equal(f.shifts, 2);
}

static void test_deterministic(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    const profile_t tour = {6, {0, 10, 20, 60, 80, 1000}, {0, 0, -3.5, -3.5, 7.0, 7.0}};
    run(&g_res, &p, &tour, 120.0, &k_baro10, NULL, 0, 0);
    run(&g_res2, &p, &tour, 120.0, &k_baro10, NULL, 0, 0);
    assert_memory_equal(&g_res, &g_res2, sizeof g_res);
    assert_int_equal(g_res.floor_at_end, 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pressure_to_height),
        cmocka_unit_test(test_baro_height_series_matches_pow),
        cmocka_unit_test(test_stair_climb_25hz),
        cmocka_unit_test(test_stair_climb_10hz),
        cmocka_unit_test(test_stair_descent),
        cmocka_unit_test(test_flat_walk_no_false_change),
        cmocka_unit_test(test_elevator_three_floors),
        cmocka_unit_test(test_site_table_uneven_floors),
        cmocka_unit_test(test_set_heights_validation),
        cmocka_unit_test(test_default_table),
        cmocka_unit_test(test_bad_samples_gaps_backwards),
        cmocka_unit_test(test_dogleg_landing),
        cmocka_unit_test(test_lift_commits_near_mid_height),
        cmocka_unit_test(test_virtual_floors),
        cmocka_unit_test(test_shift_and_at_floor),
        cmocka_unit_test(test_deterministic),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
