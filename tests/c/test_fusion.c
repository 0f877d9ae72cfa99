/* test_fusion.c — the six fusion schemes side by side: the adaptive α law on its table values (knots,
 * clamping), each scheme's pose after a step + fix sequence worked out by hand, every audit field,
 * the gate and the recovery (diverged → recovered), floors, bad data, uninitialised schemes and
 * bit-identical replay. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "sf_error.h"
#include "sf_fusion.h"
#include "sf_params.h"

#define TOL 1e-12
#define S_US 1000000LL

static void near(const double got, const double want)
{
    if (!(fabs(got - want) <= TOL * (1.0 + fabs(want)))) {
        fail_msg("got %.17g, want %.17g", got, want);
    }
}

static sf_fix_t fix_at(const double t_s, const int8_t method, const double x, const double y, const int16_t floor,
                       const double acc_m, const int16_t n_ap)
{
    return (sf_fix_t){.t_us = (int64_t)(t_s * 1e6),
                      .method = method,
                      .x_m = x,
                      .y_m = y,
                      .floor = floor,
                      .accuracy_m = acc_m,
                      .n_ap_used = n_ap};
}

static sf_fix_t wifi(const double t_s, const double x, const double y, const double acc_m, const int16_t n_ap)
{
    return fix_at(t_s, sf_fix_wifi, x, y, 0, acc_m, n_ap);
}

/* Each init_all takes the next of these clouds for its particle scheme (two runs compared side by side
 * need two clouds). */
enum { N_CLOUDS = 4 };
static sf_particle_state_t cloud_states[N_CLOUDS][SF_PARTICLE_MAX];
static int16_t cloud_floors[N_CLOUDS][SF_PARTICLE_MAX];
static sf_particle_t clouds[N_CLOUDS];
static int next_cloud;

static void init_all(sf_fusion_t f[sf_scheme_count])
{
    sf_params_t p;
    sf_params_default(&p);
    for (int s = 0; s < sf_scheme_count; s++) {
        assert_int_equal(sf_fusion_init(&f[s], (int8_t)s), SF_OK);
    }
    const int k = next_cloud++ % N_CLOUDS;
    assert_int_equal(sf_particle_init(&clouds[k], &p, cloud_states[k], cloud_floors[k], SF_PARTICLE_MAX), SF_OK);
    sf_fusion_set_cloud(&f[sf_scheme_particle], &p, &clouds[k]);
}

/* Checks every judgement field of an audit record, and that the fix fields are copied. */
static void check_audit(const sf_fix_audit_t *a, const sf_fix_t *fix, const int8_t scheme, const int8_t reason,
                        const bool accepted, const double alpha, const double nu_x, const double nu_y,
                        const double s_m2, const double gate)
{
    assert_int_equal(a->t_us, fix->t_us);
    assert_int_equal(a->method, fix->method);
    assert_true(a->x_m == fix->x_m && a->y_m == fix->y_m);
    assert_int_equal(a->floor, fix->floor);
    assert_true(a->accuracy_m == fix->accuracy_m);
    assert_int_equal(a->n_ap_used, fix->n_ap_used);
    assert_int_equal(a->scheme, scheme);
    assert_int_equal(a->reason, reason);
    assert_int_equal(a->accepted, accepted);
    near(a->alpha, alpha);
    near(a->innovation_m[0], nu_x);
    near(a->innovation_m[1], nu_y);
    near(a->innovation_var_m2, s_m2);
    near(a->test_ratio, s_m2 > 0.0 ? (nu_x * nu_x + nu_y * nu_y) / (gate * gate * s_m2) : 0.0);
}

static void test_contract(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    assert_true(p.fusion_gate_sigma == 3.0);
    assert_int_equal(p.fusion_max_rejections, 3);
    assert_true(p.fusion_static_alpha == 0.5);
    assert_true(p.fusion_drift_per_s == 0.01 && p.fusion_drift_max == 0.5);
    assert_true(p.fusion_acc_landmark == 1.0);
    /* the reasons are fix_t.REASON_* */
    assert_int_equal(sf_fix_reason_accepted, 0);
    assert_int_equal(sf_fix_reason_gate, 1);
    assert_int_equal(sf_fix_reason_too_few_aps, 2);
    assert_int_equal(sf_fix_reason_no_map, 3);
    assert_int_equal(sf_fix_reason_floor_mismatch, 4);
    assert_int_equal(sf_fix_reason_not_initialised, 5);
    assert_int_equal(sf_fix_reason_initialised, 6);
    assert_int_equal(sf_fix_reason_recovery, 7);
    assert_int_equal(sf_fix_reason_scheme_ignores, 8);
    for (int r = -1; r <= sf_fix_reason_count; r++) {
        assert_non_null(sf_fix_reason_text(r));
    }
    assert_string_equal(sf_fix_reason_text(sf_fix_reason_gate), "rejected: outside the innovation gate");
    sf_fusion_t f;
    assert_int_equal(sf_fusion_init(NULL, 0), SF_EINVAL);
    assert_int_equal(sf_fusion_init(&f, -1), SF_EINVAL);
    assert_int_equal(sf_fusion_init(&f, sf_scheme_count), SF_EINVAL);
    assert_int_equal(sf_fusion_init(&f, sf_scheme_kalman), SF_OK);
    assert_int_equal(sf_fusion_init_at(&f, &p, 0, NAN, 0.0, 0, 1.0, 0), SF_EINVAL);
    assert_int_equal(sf_fusion_init_at(&f, &p, 0, 0.0, INFINITY, 0, 1.0, 0), SF_EINVAL);
    assert_int_equal(sf_fusion_init_at(&f, &p, 0, 0.0, 0.0, 0, -1.0, 0), SF_EINVAL);
    assert_false(f.initialised);
    assert_int_equal(sf_fusion_init_at(&f, &p, 0, 0.0, 0.0, 0, 1.0, 0), SF_OK);
    assert_true(f.initialised);
}

/* Default tables: Wi-Fi (2,0.1) (4,0.25) (6,0.45) (8,0.6); GNSS (6,0.8) (12,0.6) (21,0.3) (30,0);
 * drift 0.01/s capped at 0.5. */
static void test_alpha_law_tables(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    const struct {
        int16_t n_ap;
        double factor;
    } wifi_cases[] = {{0, 0.1},  {1, 0.1},  {2, 0.1},  {3, 0.175}, {4, 0.25}, {5, 0.35},
                      {6, 0.45}, {7, 0.525}, {8, 0.6}, {9, 0.6},   {40, 0.6}};
    for (size_t i = 0; i < sizeof wifi_cases / sizeof wifi_cases[0]; i++) {
        const sf_fix_t fx = wifi(1.0, 0.0, 0.0, 3.0, wifi_cases[i].n_ap);
        near(sf_fusion_accuracy_factor(&p, &fx), wifi_cases[i].factor);
        p.fusion_acc_wifi_scale = 0.5; /* the learnt scale multiplies the Wi-Fi table only */
        near(sf_fusion_accuracy_factor(&p, &fx), 0.5 * wifi_cases[i].factor);
        p.fusion_acc_wifi_scale = 1.0;
    }
    const double gnss_cases[][2] = {{0.5, 0.8}, {6.0, 0.8}, {9.0, 0.7}, {12.0, 0.6}, {15.0, 0.5},
                                    {21.0, 0.3}, {25.5, 0.15}, {30.0, 0.0}, {500.0, 0.0}};
    for (size_t i = 0; i < sizeof gnss_cases / sizeof gnss_cases[0]; i++) {
        const sf_fix_t fx = fix_at(1.0, sf_fix_gnss, 0.0, 0.0, 0, gnss_cases[i][0], 0);
        p.fusion_acc_wifi_scale = 0.5;
        near(sf_fusion_accuracy_factor(&p, &fx), gnss_cases[i][1]);
        p.fusion_acc_wifi_scale = 1.0;
    }
    const sf_fix_t lm = fix_at(1.0, sf_fix_landmark, 0.0, 0.0, 0, 0.2, 0);
    assert_true(sf_fusion_accuracy_factor(&p, &lm) == 1.0);
    const sf_fix_t unknown = fix_at(1.0, 9, 0.0, 0.0, 0, 1.0, 8);
    assert_true(sf_fusion_accuracy_factor(&p, &unknown) == 0.0);

    /* drift: linear, capped, zero for no or negative time */
    assert_true(sf_fusion_drift(&p, 0.0) == 0.0);
    assert_true(sf_fusion_drift(&p, -5.0) == 0.0);
    near(sf_fusion_drift(&p, 10.0), 0.1);
    near(sf_fusion_drift(&p, 49.0), 0.49);
    assert_true(sf_fusion_drift(&p, 50.0) == 0.5);
    assert_true(sf_fusion_drift(&p, 1e6) == 0.5);

    /* α = clamp(accuracy + drift, 0, 1) */
    const sf_fix_t w3 = wifi(1.0, 0.0, 0.0, 3.0, 3), w8 = wifi(1.0, 0.0, 0.0, 3.0, 8);
    near(sf_fusion_adaptive_alpha(&p, &w3, 10.0), 0.275);
    near(sf_fusion_adaptive_alpha(&p, &w8, 30.0), 0.9);
    assert_true(sf_fusion_adaptive_alpha(&p, &w8, 40.0) == 1.0);  /* 0.6 + 0.4: exactly 1 */
    assert_true(sf_fusion_adaptive_alpha(&p, &w8, 100.0) == 1.0); /* 0.6 + 0.5 clamped at 1 */
    assert_true(sf_fusion_adaptive_alpha(&p, &lm, 3.0) == 1.0);   /* landmark overwrites */
    /* clamped at 0: a zero table and no drift */
    p.fusion_acc_wifi_val1 = 0.0;
    assert_true(sf_fusion_adaptive_alpha(&p, &(sf_fix_t){.method = sf_fix_wifi, .n_ap_used = 1}, 0.0) == 0.0);
    assert_true(sf_fusion_adaptive_alpha(&p, &unknown, -1.0) == 0.0);
    /* exact on binary-exact knots: (0,0) (4,0.5) (8,0.75) (16,1), drift 1/64 per s */
    p.fusion_acc_wifi_ap1 = 0.0, p.fusion_acc_wifi_ap2 = 4.0, p.fusion_acc_wifi_ap3 = 8.0, p.fusion_acc_wifi_ap4 = 16.0;
    p.fusion_acc_wifi_val1 = 0.0, p.fusion_acc_wifi_val2 = 0.5, p.fusion_acc_wifi_val3 = 0.75, p.fusion_acc_wifi_val4 = 1.0;
    p.fusion_drift_per_s = 1.0 / 64.0;
    const sf_fix_t w2 = wifi(1.0, 0.0, 0.0, 3.0, 2), w12 = wifi(1.0, 0.0, 0.0, 3.0, 12);
    assert_true(sf_fusion_adaptive_alpha(&p, &w2, 8.0) == 0.25 + 0.125);
    assert_true(sf_fusion_adaptive_alpha(&p, &w12, 4.0) == 0.875 + 0.0625);
    assert_true(sf_fusion_adaptive_alpha(&p, &w12, 8.0) == 1.0);  /* 0.875 + 0.125: the knee */
    assert_true(sf_fusion_adaptive_alpha(&p, &w12, 16.0) == 1.0); /* 0.875 + 0.25 clamped */
    assert_true(sf_fusion_adaptive_alpha(&p, &w12, 0.0) == 0.875);
    /* badly ordered knots: a jump, never NaN */
    p.fusion_acc_wifi_ap2 = 0.0;
    for (int16_t n = 0; n < 20; n++) {
        const double a = sf_fusion_accuracy_factor(&p, &(sf_fix_t){.method = sf_fix_wifi, .n_ap_used = n});
        assert_true(isfinite(a) && a >= 0.0 && a <= 1.0);
    }
}

/* GIVEN every scheme at (0,0) with σ = 1 m, q_step 0.05 m²/m, no time term,
 * WHEN one 2 m step east and a Wi-Fi fix at (3,1) ±1 m (8 APs) 1 s after the start,
 * THEN each scheme lands where the hand computation says, and every audit field matches. */
static void test_schemes_by_hand(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    p.fusion_q_time_m2_per_s = 0.0;
    p.fusion_q_step_m2_per_m = 0.05; /* the hand computation's value, whatever the default */
    sf_fusion_t f[sf_scheme_count];
    init_all(f);
    for (int s = 0; s < sf_scheme_count; s++) {
        assert_int_equal(sf_fusion_init_at(&f[s], &p, 0, 0.0, 0.0, 0, 1.0, 0), SF_OK);
        sf_fusion_step(&f[s], &p, S_US / 2, 2.0, 0.0, 2.0);
    }
    const sf_fix_t fx = wifi(1.0, 3.0, 1.0, 1.0, 8);
    sf_fix_audit_t a[sf_scheme_count];
    for (int s = 0; s < sf_scheme_count; s++) {
        assert_int_equal(sf_fusion_fix(&f[s], &p, &fx, 0, &a[s]), SF_OK);
    }
    const double P = 1.0 + 0.05 * 2.0, R = 1.0, S = P + R; /* predicted variance 1.1 */
    sf_pose_t pose;

    /* pdr_only: ignores the fix, still reports ν and S */
    check_audit(&a[sf_scheme_pdr_only], &fx, sf_scheme_pdr_only, sf_fix_reason_scheme_ignores, false, 0.0, 1.0, 1.0,
                S, 3.0);
    assert_true(sf_fusion_pose(&f[sf_scheme_pdr_only], &p, S_US, 0, &pose));
    assert_true(pose.x_m == 2.0 && pose.y_m == 0.0);
    near(pose.sigma_m, sqrt(P));
    assert_int_equal(pose.scheme, sf_scheme_pdr_only);

    /* wifi_only: ignored the step; ν against its last position (the init), S = 1 + 1 */
    check_audit(&a[sf_scheme_wifi_only], &fx, sf_scheme_wifi_only, sf_fix_reason_accepted, true, 1.0, 3.0, 1.0, 2.0,
                3.0);
    assert_true(sf_fusion_pose(&f[sf_scheme_wifi_only], &p, S_US, 0, &pose));
    assert_true(pose.x_m == 3.0 && pose.y_m == 1.0 && pose.sigma_m == 1.0);

    /* overwrite: jumps to the fix, variance R */
    check_audit(&a[sf_scheme_overwrite], &fx, sf_scheme_overwrite, sf_fix_reason_accepted, true, 1.0, 1.0, 1.0, S,
                3.0);
    assert_true(sf_fusion_pose(&f[sf_scheme_overwrite], &p, S_US, 0, &pose));
    assert_true(pose.x_m == 3.0 && pose.y_m == 1.0);
    near(pose.sigma_m, 1.0);

    /* static: half-way, variance ¼P + ¼R */
    check_audit(&a[sf_scheme_static], &fx, sf_scheme_static, sf_fix_reason_accepted, true, 0.5, 1.0, 1.0, S, 3.0);
    assert_true(sf_fusion_pose(&f[sf_scheme_static], &p, S_US, 0, &pose));
    assert_true(pose.x_m == 2.5 && pose.y_m == 0.5);
    near(pose.sigma_m, sqrt(0.25 * P + 0.25 * R));

    /* adaptive: α = acc(8 APs) + drift(1 s) = 0.6 + 0.01 */
    const double aa = 0.61;
    check_audit(&a[sf_scheme_adaptive], &fx, sf_scheme_adaptive, sf_fix_reason_accepted, true, aa, 1.0, 1.0, S, 3.0);
    near(a[sf_scheme_adaptive].accuracy_factor, 0.6);
    near(a[sf_scheme_adaptive].drift, 0.01);
    assert_true(sf_fusion_pose(&f[sf_scheme_adaptive], &p, S_US, 0, &pose));
    near(pose.x_m, 2.0 + aa);
    near(pose.y_m, aa);
    near(pose.sigma_m, sqrt((1 - aa) * (1 - aa) * P + aa * aa * R));

    /* kalman: α = P/(P+R) exactly, P ← (1−α)P */
    const double ak = P / (P + R);
    check_audit(&a[sf_scheme_kalman], &fx, sf_scheme_kalman, sf_fix_reason_accepted, true, ak, 1.0, 1.0, S, 3.0);
    assert_true(a[sf_scheme_kalman].alpha == P / (P + R)); /* to the bit */
    assert_true(sf_fusion_pose(&f[sf_scheme_kalman], &p, S_US, 0, &pose));
    near(pose.x_m, 2.0 + ak);
    near(pose.y_m, ak);
    near(f[sf_scheme_kalman].var_m2, (1.0 - ak) * P);
    near(pose.sigma_m, sqrt(P * R / (P + R)));
    /* the non-adaptive schemes record no adaptive terms */
    assert_true(a[sf_scheme_kalman].accuracy_factor == 0.0 && a[sf_scheme_kalman].drift == 0.0);

    /* a second step moves every scheme but wifi_only by exactly the step; the ekf by the step turned
     * by its learnt heading bias and scaled by its learnt stride scale (test_ekf.c) */
    sf_pose_t before[sf_scheme_count], after[sf_scheme_count];
    for (int s = 0; s < sf_scheme_count; s++) {
        sf_fusion_pose(&f[s], &p, S_US, 0, &before[s]);
        sf_fusion_step(&f[s], &p, 2 * S_US, 0.0, -0.75, 0.75);
        sf_fusion_pose(&f[s], &p, 2 * S_US, 0, &after[s]);
        if (s == sf_scheme_ekf) {
            const double b = before[s].heading_bias_rad, k = before[s].stride_scale, h = atan2(-0.75, 0.0);
            near(after[s].x_m, before[s].x_m + k * 0.75 * cos(h + b));
            near(after[s].y_m, before[s].y_m + k * 0.75 * sin(h + b));
            continue;
        }
        if (s == sf_scheme_particle) { /* every particle by the step with its own scale, bias and noise
                                        * (test_particle.c): the mean by about the step, E[cos b] ≈ 0.96 */
            assert_true(fabs(after[s].x_m - before[s].x_m) < 0.05);
            assert_true(fabs(after[s].y_m - before[s].y_m + 0.75 * exp(-0.5 * 0.3 * 0.3)) < 0.05);
            continue;
        }
        const double dy = s == sf_scheme_wifi_only ? 0.0 : -0.75;
        assert_true(after[s].x_m == before[s].x_m && after[s].y_m == before[s].y_m + dy);
    }
}

/* A config start (truth-initialised) comes before any input: the clock starts at the first input, so a
 * log in epoch time (1.57e9 s) does not add 1.57e9 s of variance and the first fix is weighed against
 * the start's σ, not snapped to. */
static void test_config_start_clock(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    for (int s = sf_scheme_kalman; s <= sf_scheme_ekf; s++) {
        sf_fusion_t k;
        sf_fusion_init(&k, (int8_t)s);
        assert_int_equal(sf_fusion_init_at(&k, &p, SF_FUSION_T_FIRST_INPUT, 0.0, 0.0, 0, 1.0, 0), SF_OK);
        sf_pose_t pose;
        assert_true(sf_fusion_pose(&k, &p, 1574586414000000LL, 0, &pose));
        near(pose.sigma_m, 1.0);
        sf_fix_audit_t a;
        const sf_fix_t fx = wifi(1574586414.0, 4.0, 0.0, 2.0, 6);
        sf_fusion_fix(&k, &p, &fx, 0, &a);
        if (s == sf_scheme_kalman) {
            check_audit(&a, &fx, sf_scheme_kalman, sf_fix_reason_accepted, true, 0.2, 4.0, 0.0, 5.0, 3.0);
        } else {
            assert_true(a.alpha > 0.1 && a.alpha < 0.3); /* 1 / (1 + 4·M) with M = 1 */
        }
    }
}

/* Time term: a still walker's variance grows by q_time per second, also between events (pose). */
static void test_kalman_time_term(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    p.fusion_q_time_m2_per_s = 0.25;
    sf_fusion_t k;
    sf_fusion_init(&k, sf_scheme_kalman);
    sf_fusion_init_at(&k, &p, 0, 0.0, 0.0, 0, 1.0, 0);
    sf_pose_t pose;
    sf_fusion_pose(&k, &p, 12 * S_US, 0, &pose);
    assert_true(pose.sigma_m == 2.0); /* 1 + 0.25·12 = 4 */
    sf_fix_audit_t a;
    const sf_fix_t fx = wifi(12.0, 4.0, 0.0, 2.0, 6);
    sf_fusion_fix(&k, &p, &fx, 0, &a);
    check_audit(&a, &fx, sf_scheme_kalman, sf_fix_reason_accepted, true, 0.5, 4.0, 0.0, 8.0, 3.0);
    sf_fusion_pose(&k, &p, 12 * S_US, 0, &pose);
    assert_true(pose.x_m == 2.0);
    near(pose.sigma_m, sqrt(2.0));
}

/* GIVEN a scheme tracking near the origin, WHEN fixes 30 m away with 3 m accuracy arrive, THEN each is
 * rejected by the gate and the pose does not move; after max_rejections of them the next is accepted
 * with α = 1 (recovery), and the scheme follows fixes from there (diverged → recovered). */
static void test_gate_and_recovery(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    for (int s = sf_scheme_overwrite; s <= sf_scheme_kalman; s++) {
        sf_fusion_t f;
        sf_fusion_init(&f, (int8_t)s);
        sf_fix_audit_t a;
        sf_fix_t fx = wifi(0.0, 0.0, 0.0, 3.0, 8);
        assert_int_equal(sf_fusion_fix(&f, &p, &fx, 0, &a), SF_OK);
        check_audit(&a, &fx, (int8_t)s, sf_fix_reason_initialised, true, 1.0, 0.0, 0.0, 9.0, 3.0);
        sf_fusion_step(&f, &p, S_US / 2, 0.7, 0.0, 0.7);

        for (int k = 0; k < 3; k++) {
            sf_pose_t before, after;
            sf_fusion_pose(&f, &p, (1 + k) * S_US, 0, &before);
            const double var = f.var_m2 + p.fusion_q_time_m2_per_s * ((1.0 + k) - (double)f.t_us / 1e6);
            fx = wifi(1.0 + k, 30.7, 0.0, 3.0, 8);
            assert_int_equal(sf_fusion_fix(&f, &p, &fx, 0, &a), SF_OK);
            check_audit(&a, &fx, (int8_t)s, sf_fix_reason_gate, false, 0.0, 30.0, 0.0, var + 9.0, 3.0);
            assert_true(a.test_ratio > 1.0);
            sf_fusion_pose(&f, &p, (1 + k) * S_US, 0, &after);
            assert_true(after.x_m == before.x_m && after.y_m == before.y_m);
            assert_int_equal(f.rejections, k + 1);
        }
        /* the fourth consecutive far fix: recovery */
        fx = wifi(4.0, 30.7, 0.0, 3.0, 8);
        assert_int_equal(sf_fusion_fix(&f, &p, &fx, 0, &a), SF_OK);
        assert_int_equal(a.reason, sf_fix_reason_recovery);
        assert_true(a.accepted && a.alpha == 1.0);
        assert_true(a.test_ratio > 1.0);
        sf_pose_t pose;
        sf_fusion_pose(&f, &p, 4 * S_US, 0, &pose);
        assert_true(pose.x_m == 30.7 && pose.y_m == 0.0 && pose.sigma_m == 3.0);
        assert_int_equal(f.rejections, 0);
        assert_int_equal(f.recoveries, 1);
        assert_int_equal(f.rejected_gate, 3);
        /* the recovered scheme follows: the next nearby fix passes the gate */
        sf_fusion_step(&f, &p, 4 * S_US + S_US / 2, 0.7, 0.0, 0.7);
        fx = wifi(5.0, 32.0, 0.5, 3.0, 8);
        sf_fusion_fix(&f, &p, &fx, 0, &a);
        assert_int_equal(a.reason, sf_fix_reason_accepted);
        assert_true(a.accepted && a.test_ratio <= 1.0 && a.alpha > 0.0);
        sf_fusion_pose(&f, &p, 5 * S_US, 0, &pose);
        assert_true(pose.x_m >= 31.4 && pose.x_m <= 32.0);
        assert_int_equal(f.accepted, 1);
        assert_int_equal(f.initialisations, 1);
    }
}

/* The count is of *consecutive* rejections: an accepted fix in between clears it. */
static void test_recovery_needs_consecutive_rejections(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_fusion_t f;
    sf_fusion_init(&f, sf_scheme_static);
    sf_fusion_init_at(&f, &p, 0, 0.0, 0.0, 0, 1.0, 0);
    sf_fix_audit_t a;
    const int8_t want[] = {sf_fix_reason_gate,     sf_fix_reason_gate, sf_fix_reason_accepted, sf_fix_reason_gate,
                           sf_fix_reason_gate,     sf_fix_reason_gate, sf_fix_reason_recovery};
    const double xs[] = {50.0, 50.0, 0.5, 50.0, 50.0, 50.0, 50.0};
    for (size_t i = 0; i < sizeof xs / sizeof xs[0]; i++) {
        const sf_fix_t fx = wifi(1.0 + (double)i, xs[i], 0.0, 1.0, 8);
        sf_fusion_fix(&f, &p, &fx, 0, &a);
        assert_int_equal(a.reason, want[i]);
    }
    /* max_rejections = 0: nothing is ever refused for long: the first outlier is a recovery */
    p.fusion_max_rejections = 0;
    sf_fusion_init(&f, sf_scheme_kalman);
    sf_fusion_init_at(&f, &p, 0, 0.0, 0.0, 0, 1.0, 0);
    const sf_fix_t far = wifi(1.0, 100.0, 0.0, 1.0, 8);
    sf_fusion_fix(&f, &p, &far, 0, &a);
    assert_int_equal(a.reason, sf_fix_reason_recovery);
    assert_true(f.x_m == 100.0);
}

/* pdr_only: initialised by the first fix, then dead reckoning only, whatever the fixes say. */
static void test_pdr_only_ignores_fixes(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_fusion_t f;
    sf_fusion_init(&f, sf_scheme_pdr_only);
    sf_fix_audit_t a;
    const sf_fix_t first = wifi(0.0, 5.0, 5.0, 2.0, 8);
    sf_fusion_fix(&f, &p, &first, 0, &a);
    assert_int_equal(a.reason, sf_fix_reason_initialised);
    double x = 5.0, y = 5.0;
    for (int i = 1; i <= 20; i++) {
        sf_fusion_step(&f, &p, i * S_US, 0.5, 0.25, sqrt(0.3125));
        x += 0.5, y += 0.25;
        const sf_fix_t fx = wifi(i + 0.5, -40.0 * i, 17.0, 0.5, 8);
        assert_int_equal(sf_fusion_fix(&f, &p, &fx, 0, &a), SF_OK);
        assert_int_equal(a.reason, sf_fix_reason_scheme_ignores);
        assert_false(a.accepted);
        assert_true(a.alpha == 0.0);
        near(a.innovation_m[0], -40.0 * i - x);
    }
    sf_pose_t pose;
    assert_true(sf_fusion_pose(&f, &p, 21 * S_US, 0, &pose));
    assert_true(pose.x_m == x && pose.y_m == y);
    assert_int_equal(f.rejections, 0);
    assert_int_equal(f.steps, 20);
}

/* wifi_only: the latest fix, whatever it is; steps and the barometer do not matter. */
static void test_wifi_only_is_last_fix(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_fusion_t f;
    sf_fusion_init(&f, sf_scheme_wifi_only);
    sf_fix_audit_t a;
    const double xs[] = {1.0, 3.0, 250.0, -7.5};
    const double acc[] = {2.0, 4.0, 1.5, 6.0};
    for (int i = 0; i < 4; i++) {
        sf_fusion_step(&f, &p, i * S_US + 1, 10.0, 10.0, 14.0);
        const sf_fix_t fx = fix_at(i + 0.5, sf_fix_wifi, xs[i], -xs[i], (int16_t)(i + 1), acc[i], 5);
        sf_fusion_fix(&f, &p, &fx, 7, &a);
        assert_int_equal(a.reason, i == 0 ? sf_fix_reason_initialised : sf_fix_reason_accepted);
        assert_true(a.accepted && a.alpha == 1.0);
        if (i > 0) {
            check_audit(&a, &fx, sf_scheme_wifi_only, sf_fix_reason_accepted, true, 1.0, xs[i] - xs[i - 1],
                        -(xs[i] - xs[i - 1]), acc[i - 1] * acc[i - 1] + acc[i] * acc[i], 3.0);
        }
        sf_pose_t pose;
        sf_fusion_pose(&f, &p, (i + 5) * S_US, 7, &pose);
        assert_true(pose.x_m == xs[i] && pose.y_m == -xs[i] && pose.sigma_m == acc[i]);
        assert_int_equal(pose.floor, i + 1);
    }
    assert_int_equal(f.steps, 0);
}

/* Every scheme is uninitialised until its first fix (steps do nothing), which initialises it. */
static void test_uninitialised_until_first_fix(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_fusion_t f[sf_scheme_count];
    init_all(f);
    for (int s = 0; s < sf_scheme_count; s++) {
        sf_pose_t pose = {.t_us = 123, .heading_rad = 0.5, .step_count = 9};
        sf_fusion_step(&f[s], &p, S_US, 1.0, 0.0, 1.0);
        assert_false(sf_fusion_pose(&f[s], &p, S_US, 2, &pose));
        assert_true(pose.sigma_m == SF_FUSION_SIGMA_UNKNOWN_M);
        assert_true(pose.x_m == 0.0 && pose.y_m == 0.0);
        assert_int_equal(pose.floor, 2);
        assert_int_equal(pose.scheme, s);
        assert_true(pose.t_us == 123 && pose.heading_rad == 0.5 && pose.step_count == 9); /* caller's */
        assert_int_equal(f[s].steps, 0);

        const sf_fix_t fx = fix_at(2.0, sf_fix_wifi, 10.0, -4.0, 1, 2.5, 4);
        sf_fix_audit_t a;
        assert_int_equal(sf_fusion_fix(&f[s], &p, &fx, 2, &a), SF_OK);
        check_audit(&a, &fx, (int8_t)s, sf_fix_reason_initialised, true, 1.0, 0.0, 0.0, 6.25, 3.0);
        assert_true(a.test_ratio == 0.0);
        assert_true(sf_fusion_pose(&f[s], &p, 2 * S_US, 2, &pose));
        if (s == sf_scheme_particle) { /* particle.count (1 000) particles drawn about the fix with σ = 2.5 m */
            assert_true(fabs(pose.x_m - 10.0) < 0.2 && fabs(pose.y_m + 4.0) < 0.2 && fabs(pose.sigma_m - 2.5) < 0.1);
            assert_true(fabs(pose.ess - 1000.0) < 1e-6); /* equal weights */
        } else {
            assert_true(pose.x_m == 10.0 && pose.y_m == -4.0 && pose.sigma_m == 2.5);
        }
        assert_int_equal(pose.floor, s == sf_scheme_wifi_only ? 1 : 2); /* the caller's floor */
        assert_int_equal(f[s].initialisations, 1);
    }
}

/* Floors: every predicting scheme is on the caller's floor, whatever its fixes say; a fix on
 * another floor is judged on the gate alone (its floor voted already, sf_floor_vote.h); between floors
 * every fix is refused FLOOR_MISMATCH without counting toward a recovery. */
static void test_floors(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_fusion_t f;
    sf_fusion_init(&f, sf_scheme_kalman);
    sf_fix_audit_t a;
    sf_pose_t pose;
    /* the caller says floor 0, the first fix says floor 2: the scheme starts at the fix, on floor 0 */
    sf_fix_t fx = fix_at(0.0, sf_fix_wifi, 0.0, 0.0, 2, 2.0, 6);
    sf_fusion_fix(&f, &p, &fx, 0, &a);
    assert_int_equal(a.reason, sf_fix_reason_initialised);
    sf_fusion_pose(&f, &p, 0, 0, &pose);
    assert_int_equal(pose.floor, 0);
    /* the caller's floor moves (a lift, or its vote renumbered it): so does the scheme's */
    sf_fusion_pose(&f, &p, 0, 1, &pose);
    assert_int_equal(pose.floor, 1);
    /* fixes on floor 5 at the same spot: accepted on the gate, the floor stays the caller's */
    for (int k = 0; k < 3; k++) {
        fx = fix_at(1.0 + k, sf_fix_wifi, 0.5, 0.0, 5, 2.0, 6);
        sf_fusion_fix(&f, &p, &fx, 1, &a);
        assert_int_equal(a.reason, sf_fix_reason_accepted);
        assert_true(a.accepted && a.alpha > 0.0 && a.test_ratio <= 1.0);
    }
    sf_fusion_pose(&f, &p, 4 * S_US, 1, &pose);
    assert_int_equal(pose.floor, 1);
    assert_int_equal(f.rejected_floor, 0);
    /* between floors: five fixes in a row refused, none a step toward recovery, the state untouched */
    const sf_fusion_t before = f;
    for (int k = 0; k < 5; k++) {
        fx = fix_at(5.0 + k, sf_fix_wifi, 40.0, 0.0, 1, 2.0, 6); /* far: would also fail the gate */
        assert_int_equal(sf_fusion_fix_on_floor(&f, &p, &fx, 1, true, &a), SF_OK);
        assert_int_equal(a.reason, sf_fix_reason_floor_mismatch);
        assert_false(a.accepted);
        assert_true(a.alpha == 0.0 && a.test_ratio > 1.0);
    }
    assert_int_equal(f.rejected_floor, 5);
    assert_int_equal(f.rejections, 0);
    assert_int_equal(f.recoveries, 0);
    assert_true(f.x_m == before.x_m && f.y_m == before.y_m);
    /* back on a floor, the same far fix is a gate rejection, and the fourth in a row recovers */
    for (int k = 0; k < 3; k++) {
        fx = fix_at(10.0 + k, sf_fix_wifi, 40.0, 0.0, 1, 2.0, 6);
        sf_fusion_fix_on_floor(&f, &p, &fx, 1, false, &a);
        assert_int_equal(a.reason, sf_fix_reason_gate);
    }
    fx = fix_at(13.0, sf_fix_wifi, 40.0, 0.0, 1, 2.0, 6);
    sf_fusion_fix(&f, &p, &fx, 1, &a);
    assert_int_equal(a.reason, sf_fix_reason_recovery);
    assert_true(f.x_m == 40.0);
    /* wifi_only is the fixes: its floor is the latest fix's, and between floors it still follows */
    sf_fusion_t w;
    sf_fusion_init(&w, sf_scheme_wifi_only);
    fx = fix_at(0.0, sf_fix_wifi, 1.0, 1.0, 3, 2.0, 6);
    sf_fusion_fix_on_floor(&w, &p, &fx, 0, true, &a);
    fx = fix_at(1.0, sf_fix_wifi, 2.0, 1.0, 4, 2.0, 6);
    sf_fusion_fix_on_floor(&w, &p, &fx, 0, true, &a);
    assert_int_equal(a.reason, sf_fix_reason_accepted);
    sf_fusion_pose(&w, &p, S_US, 0, &pose);
    assert_int_equal(pose.floor, 4);
    /* truth initialisation on floor 3 while the caller reads 0: the caller's floor wins */
    sf_fusion_t t;
    sf_fusion_init(&t, sf_scheme_pdr_only);
    sf_fusion_init_at(&t, &p, 0, 1.0, 2.0, 3, 0.5, 0);
    sf_fusion_pose(&t, &p, 0, 0, &pose);
    assert_int_equal(pose.floor, 0);
    assert_true(pose.x_m == 1.0 && pose.y_m == 2.0 && pose.sigma_m == 0.5);
    sf_fusion_pose(&t, &p, 0, -1, &pose);
    assert_int_equal(pose.floor, -1);
}

/* Bad data is counted and skipped; it never moves a scheme nor counts toward a recovery. */
static void test_bad_data(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_fusion_t f;
    sf_fusion_init(&f, sf_scheme_adaptive);
    sf_fusion_init_at(&f, &p, 10 * S_US, 1.0, 1.0, 0, 1.0, 0);
    const sf_fusion_t saved = f;
    sf_fix_audit_t a;
    const sf_fix_t bad[] = {
        wifi(11.0, NAN, 0.0, 2.0, 5),     wifi(11.0, 0.0, INFINITY, 2.0, 5), wifi(11.0, 0.0, 0.0, -1.0, 5),
        wifi(11.0, 0.0, 0.0, NAN, 5),     fix_at(11.0, 0, 0.0, 0.0, 0, 1.0, 0), fix_at(11.0, 6, 1.0, 1.0, 0, 1.0, 0), /* 6: no method (5 is METHOD_PORT) */
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(sf_fusion_fix(&f, &p, &bad[i], 0, &a), SF_ERANGE);
        assert_false(a.accepted);
        assert_int_equal(a.reason, sf_fix_reason_gate);
        assert_true(isinf(a.test_ratio) && a.alpha == 0.0);
        assert_int_equal(a.scheme, sf_scheme_adaptive);
    }
    assert_int_equal(f.bad_fixes, 6);
    assert_int_equal(f.fixes, 6);
    assert_int_equal(f.rejections, 0);
    assert_true(f.x_m == saved.x_m && f.y_m == saved.y_m && f.var_m2 == saved.var_m2 && f.t_us == saved.t_us);
    /* bad steps */
    sf_fusion_step(&f, &p, 11 * S_US, NAN, 0.0, 1.0);
    sf_fusion_step(&f, &p, 11 * S_US, 0.0, 0.0, -1.0);
    sf_fusion_step(&f, &p, 11 * S_US, 0.0, 0.0, INFINITY);
    assert_int_equal(f.bad_steps, 3);
    assert_int_equal(f.steps, 0);
    assert_true(f.x_m == 1.0 && f.var_m2 == saved.var_m2);
    /* time going backwards: counted, no negative variance growth */
    sf_fusion_step(&f, &p, 5 * S_US, 1.0, 0.0, 1.0);
    assert_int_equal(f.backwards, 1);
    near(f.var_m2, saved.var_m2 + p.fusion_q_step_m2_per_m);
    assert_true(f.x_m == 2.0);
    /* a refused scan's record, written by the caller */
    const sf_fix_t scan = wifi(12.0, 0.0, 0.0, 0.0, 1);
    sf_fusion_audit_refused(&f, &scan, sf_fix_reason_too_few_aps, &a);
    assert_int_equal(a.reason, sf_fix_reason_too_few_aps);
    assert_false(a.accepted);
    assert_true(a.alpha == 0.0 && a.test_ratio == 0.0 && a.innovation_var_m2 == 0.0);
    assert_int_equal(a.scheme, sf_scheme_adaptive);
    assert_int_equal(a.n_ap_used, 1);
}

/* A pseudo-random walk with fixes (some far, some on other floors, some between floors, one bad) through
 * all six schemes. */
/* The sources of the deterministic run: Wi-Fi, GNSS and BLE in turn, a landmark now and then (rarely:
 * every scheme takes a landmark, which would keep the run from its rejections and recoveries). */
static int8_t method_of(const int i)
{
    static const int8_t cycle[3] = {sf_fix_wifi, sf_fix_gnss, sf_fix_ble};
    return i % 29 == 3 ? (int8_t)sf_fix_landmark : cycle[i % 3];
}

static void run(sf_fusion_t f[sf_scheme_count], sf_fix_audit_t audits[][sf_scheme_count], sf_pose_t poses[][sf_scheme_count],
                const int n)
{
    sf_params_t p;
    sf_params_default(&p);
    init_all(f);
    uint32_t seed = 12345u;
    double h = 0.0;
    for (int i = 0; i < n; i++) {
        seed = seed * 1664525u + 1013904223u;
        h += ((double)(seed >> 8) / 16777216.0 - 0.5) * 0.3;
        const int64_t t = (int64_t)i * 550000;
        for (int s = 0; s < sf_scheme_count; s++) {
            sf_fusion_step(&f[s], &p, t, 0.7 * cos(h), 0.7 * sin(h), 0.7);
        }
        const int16_t baro = (int16_t)(i / 40);
        const sf_fix_t fx = fix_at((double)t * 1e-6 + 0.1, method_of(i), 0.7 * i * 0.1 + (double)(seed % 97u),
                                   (double)(seed % 13u), (int16_t)(baro + (i % 17 == 0)), i == 33 ? NAN : 1.0 + i % 4,
                                   (int16_t)(i % 10));
        for (int s = 0; s < sf_scheme_count; s++) {
            sf_fusion_fix_on_floor(&f[s], &p, &fx, baro, i % 23 == 5, &audits[i][s]);
            poses[i][s] = (sf_pose_t){0};
            sf_fusion_pose(&f[s], &p, t + 200000, baro, &poses[i][s]);
        }
    }
}

static void test_deterministic(void **state)
{
    (void)state;
    enum { n = 120 };
    static sf_fusion_t f1[sf_scheme_count], f2[sf_scheme_count];
    static sf_fix_audit_t a1[n][sf_scheme_count], a2[n][sf_scheme_count];
    static sf_pose_t p1[n][sf_scheme_count], p2[n][sf_scheme_count];
    memset(a1, 0xA5, sizeof a1);
    memset(a2, 0x5A, sizeof a2);
    run(f1, a1, p1, n);
    run(f2, a2, p2, n);
    int reasons[sf_fix_reason_count] = {0};
    for (int i = 0; i < n; i++) {
        for (int s = 0; s < sf_scheme_count; s++) {
            const sf_fix_audit_t *x = &a1[i][s], *y = &a2[i][s];
            assert_memory_equal(x->innovation_m, y->innovation_m, sizeof x->innovation_m);
            assert_memory_equal(&x->innovation_var_m2, &y->innovation_var_m2, sizeof(double));
            assert_memory_equal(&x->test_ratio, &y->test_ratio, sizeof(double));
            assert_memory_equal(&x->alpha, &y->alpha, sizeof(double));
            assert_true(x->accepted == y->accepted && x->reason == y->reason);
            assert_memory_equal(&p1[i][s].x_m, &p2[i][s].x_m, sizeof(double));
            assert_memory_equal(&p1[i][s].y_m, &p2[i][s].y_m, sizeof(double));
            assert_memory_equal(&p1[i][s].sigma_m, &p2[i][s].sigma_m, sizeof(double));
            assert_int_equal(p1[i][s].floor, p2[i][s].floor);
            reasons[x->reason]++;
        }
    }
    /* the run exercised the paths it should have */
    assert_true(reasons[sf_fix_reason_accepted] > 0 && reasons[sf_fix_reason_gate] > 0);
    assert_true(reasons[sf_fix_reason_recovery] > 0 && reasons[sf_fix_reason_floor_mismatch] > 0);
    assert_int_equal(reasons[sf_fix_reason_initialised], sf_scheme_count);
    /* pdr_only ignores every fix but its initialising one and the bad one; wifi_only every fix of
     * another source after its own start */
    int ignored_by[sf_scheme_count] = {0}, not_wifi = 0;
    for (int i = 0; i < n; i++) {
        for (int s = 0; s < sf_scheme_count; s++) {
            ignored_by[s] += a1[i][s].reason == sf_fix_reason_scheme_ignores;
        }
        not_wifi += i != 33 && method_of(i) != sf_fix_wifi;
    }
    assert_int_equal(ignored_by[sf_scheme_pdr_only], n - 2); /* less the init and the bad fix */
    assert_int_equal(ignored_by[sf_scheme_wifi_only], not_wifi);
    assert_int_equal(reasons[sf_fix_reason_scheme_ignores], n - 2 + not_wifi);
    for (int s = 0; s < sf_scheme_count; s++) {
        assert_int_equal(f1[s].bad_fixes, 1);
        assert_true(memcmp(&f1[s].x_m, &f2[s].x_m, sizeof(double)) == 0);
        assert_true(memcmp(&f1[s].var_m2, &f2[s].var_m2, sizeof(double)) == 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_contract),
        cmocka_unit_test(test_alpha_law_tables),
        cmocka_unit_test(test_schemes_by_hand),
        cmocka_unit_test(test_kalman_time_term),
        cmocka_unit_test(test_config_start_clock),
        cmocka_unit_test(test_gate_and_recovery),
        cmocka_unit_test(test_recovery_needs_consecutive_rejections),
        cmocka_unit_test(test_pdr_only_ignores_fixes),
        cmocka_unit_test(test_wifi_only_is_last_fix),
        cmocka_unit_test(test_uninitialised_until_first_fix),
        cmocka_unit_test(test_floors),
        cmocka_unit_test(test_bad_data),
        cmocka_unit_test(test_deterministic),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
