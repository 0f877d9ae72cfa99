/* test_ekf.c — the ekf scheme's filter (sf_ekf.h) and its place among the schemes (sf_fusion.h):
 * the step Jacobian against finite differences, the update against the scalar Kalman result, the
 * learnt heading bias and stride scale on a walk whose PDR is rotated and scaled, the fix model that
 * can only grow, and the ekf pose and audit through sf_fusion. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>

#include "sf_ekf.h"
#include "sf_error.h"
#include "sf_fusion.h"
#include "sf_params.h"
#include "sf_test_rng.h"

static void near(const double got, const double want, const double tol)
{
    if (!(fabs(got - want) <= tol)) {
        fail_msg("got %.17g, want %.17g (tol %g)", got, want, tol);
    }
}

static sf_params_t params(void)
{
    sf_params_t p;
    sf_params_default(&p);
    return p;
}

/* A fresh filter at a known position of covariance cov [xx, xy, yy]. */
static sf_ekf_t known_start(const sf_params_t *const p, const double cov[3])
{
    sf_ekf_t e;
    sf_ekf_start(&e, p);
    sf_ekf_restart_known(&e, cov);
    return e;
}

/* Propagating P = diag(0, 0, σb², σs²) through one step equals J diag(σb², σs²) Jᵀ plus the step's
 * noise, J = ∂(displacement)/∂(b, s) by central differences of the displacement itself. */
static void test_step_jacobian(void **state)
{
    (void)state;
    sf_params_t p = params();
    p.ekf_step_length_sigma = 0.0;
    p.ekf_step_heading_sigma_rad = 0.0;
    p.ekf_bias_rw_rad2_per_m = 0.0;
    p.ekf_scale_rw_per_m = 0.0;
    const double zero[3] = {0, 0, 0};
    sf_ekf_t e = known_start(&p, zero);
    e.heading_bias_rad = 0.3;
    e.stride_scale = 1.1;
    const double vb = e.P[2][2], vs = e.P[3][3], L = 0.7, psi = 1.2;
    double J[2][2];
    for (int k = 0; k < 2; k++) { /* column k: b, then s */
        const double h = 1e-6;
        sf_ekf_t plus = e, minus = e;
        double dp[2], dm[2];
        if (k == 0) {
            plus.heading_bias_rad += h, minus.heading_bias_rad -= h;
        } else {
            plus.stride_scale += h, minus.stride_scale -= h;
        }
        sf_ekf_step(&plus, &p, L, psi, dp);
        sf_ekf_step(&minus, &p, L, psi, dm);
        J[0][k] = (dp[0] - dm[0]) / (2 * h);
        J[1][k] = (dp[1] - dm[1]) / (2 * h);
    }
    double d[2];
    sf_ekf_step(&e, &p, L, psi, d);
    near(d[0], 1.1 * L * cos(psi + 0.3), 1e-15);
    near(d[1], 1.1 * L * sin(psi + 0.3), 1e-15);
    near(e.P[0][0], J[0][0] * J[0][0] * vb + J[0][1] * J[0][1] * vs, 1e-9);
    near(e.P[0][1], J[0][0] * J[1][0] * vb + J[0][1] * J[1][1] * vs, 1e-9);
    near(e.P[1][1], J[1][0] * J[1][0] * vb + J[1][1] * J[1][1] * vs, 1e-9);
    near(e.P[0][2], J[0][0] * vb, 1e-9);
    near(e.P[1][3], J[1][1] * vs, 1e-9);
}

/* With no correlation to bias and scale, the update is two scalar Kalman updates: gain v / (v + r). */
static void test_update_is_kalman(void **state)
{
    (void)state;
    sf_params_t p = params();
    const double cov[3] = {4.0, 0.0, 4.0}, r[3] = {1.0, 0.0, 1.0}, nu[2] = {2.0, -1.0};
    sf_ekf_t e = known_start(&p, cov);
    double s[3];
    near(sf_ekf_nis(&e, true, nu, r, s), (4.0 + 1.0) / 5.0, 1e-12);
    double dpos[2];
    const double alpha = sf_ekf_update(&e, &p, true, nu, r, dpos);
    near(alpha, 0.8, 1e-12);
    near(dpos[0], 1.6, 1e-12);
    near(dpos[1], -0.8, 1e-12);
    near(e.P[0][0], 0.8, 1e-12); /* (1 − k)·v */
    near(e.P[0][1], 0.0, 1e-12);
    near(e.heading_bias_rad, 0.0, 0.0);
    near(e.stride_scale, 1.0, 0.0);
}

/* A square walk whose PDR is rotated by −0.25 rad and 20 % short (truth: bias +0.25, scale 1.25),
 * noisy fixes (σ 2 m) every 4 steps: the filter learns both, and its track beats the raw PDR. */
static void test_learns_bias_and_scale(void **state)
{
    (void)state;
    const sf_params_t p = params();
    rng_t rng = {.s = 12345};
    const double true_bias = 0.25, true_scale = 1.25, L = 0.6, sigma_fix = 2.0;
    const double cov0[3] = {4.0, 0.0, 4.0};
    sf_ekf_t e = known_start(&p, cov0);
    double x = 0, y = 0, tx = 0, ty = 0, px = 0, py = 0, err_ekf = 0, err_pdr = 0;
    int n = 0;
    for (int k = 0; k < 800; k++) {
        const double walk = (double)((k / 50) % 4) * (3.14159265358979323846 / 2); /* 30 m legs */
        tx += true_scale * L * cos(walk);
        ty += true_scale * L * sin(walk);
        const double pdr_heading = walk - true_bias;
        px += L * cos(pdr_heading);
        py += L * sin(pdr_heading);
        double d[2];
        sf_ekf_step(&e, &p, L, pdr_heading, d);
        x += d[0], y += d[1];
        if (k % 4 == 3) {
            const double nu[2] = {tx + sigma_fix * rng_gauss(&rng) - x, ty + sigma_fix * rng_gauss(&rng) - y};
            const double r[3] = {sigma_fix * sigma_fix, 0.0, sigma_fix * sigma_fix};
            double dpos[2];
            (void)sf_ekf_update(&e, &p, true, nu, r, dpos);
            x += dpos[0], y += dpos[1];
        }
        if (k >= 400) {
            err_ekf += hypot(x - tx, y - ty);
            err_pdr += hypot(px - tx, py - ty);
            n++;
        }
    }
    printf("ekf learnt bias %.3f rad (true %.2f), scale %.3f (true %.2f); mean error second half %.2f m, "
           "PDR %.2f m\n",
           e.heading_bias_rad, true_bias, e.stride_scale, true_scale, err_ekf / n, err_pdr / n);
    near(e.heading_bias_rad, true_bias, 0.05);
    near(e.stride_scale, true_scale, 0.08);
    assert_true(err_ekf / n < 2.0);
    assert_true(err_ekf / n < 0.2 * err_pdr / n);
}

/* The fix model starts at the prior, grows under innovations larger than P + R predicts (clipped at
 * the gate), and never drops below the prior's smallest eigenvalue under tiny ones. */
static void test_fix_model_only_grows(void **state)
{
    (void)state;
    sf_params_t p = params();
    p.ekf_fix_var_x_per_acc2 = 2.0;
    p.ekf_fix_var_y_per_acc2 = 2.0;
    const double cov[3] = {1.0, 0.0, 1.0};
    sf_ekf_t e = known_start(&p, cov);
    double r[3];
    sf_ekf_fix_r(&e, &p, 3.0, r);
    near(r[0], 18.0, 1e-12);
    near(r[2], 18.0, 1e-12);
    const double tiny[2] = {0.01, 0.0};
    for (int i = 0; i < 100; i++) {
        sf_ekf_learn_fix_model(&e, &p, tiny, 3.0, 9.0);
    }
    assert_true(e.fix_model[0] >= 2.0 - 1e-12 && e.fix_model[2] >= 2.0 - 1e-12);
    const double big[2] = {6.0, 0.0}; /* consistent with M_xx = (6² − P_xx) / 3² = 35/9 */
    for (int i = 0; i < 200; i++) {
        sf_ekf_learn_fix_model(&e, &p, big, 3.0, 9.0);
    }
    printf("fix model after 200 innovations of 6 m at accuracy 3 m: xx %.3f yy %.3f (prior 2)\n", e.fix_model[0],
           e.fix_model[2]);
    near(e.fix_model[0], 35.0 / 9.0, 0.02); /* it grew along x to what the innovations say ... */
    near(e.fix_model[2], 2.0, 1e-9);        /* ... and not along y */
    const double wild[2] = {300.0, 0.0}; /* beyond the gate: enters clipped onto it, bounded by r_max */
    for (int i = 0; i < 1000; i++) {
        sf_ekf_learn_fix_model(&e, &p, wild, 3.0, 9.0);
    }
    assert_true(e.fix_model[0] <= p.ekf_r_max + 1e-9);
}

/* A standing walker known at the origin (σ 1 m) gets the same wrong fix 5 m east 20 times. Taken as
 * independent, the fixes pull the position onto the wrong place; with the fixes' correlated error as a
 * state (σ_c 4 m) the filter sees one wrong fix repeated and the position stays near the truth. Then
 * 60 m of walking decorrelates c (ℓ 10 m): its variance returns to σ_c². */
static double stuck_fix_run(const double sigma_c_m, sf_ekf_t *const out)
{
    sf_params_t p = params();
    p.ekf_fix_var_x_per_acc2 = p.ekf_fix_var_y_per_acc2 = 25.0 / 9.0; /* one fix: 5 m σ at accuracy 3 m */
    p.ekf_fix_bias_sigma_m = sigma_c_m;
    p.ekf_r_window = 0;
    const double cov[3] = {1.0, 0.0, 1.0};
    sf_ekf_t e = known_start(&p, cov);
    double x = 0.0, y = 0.0;
    for (int i = 0; i < 20; i++) {
        double nu[2] = {5.0 - x, 0.0 - y}, r[3], dpos[2];
        sf_ekf_innovation(&e, true, nu);
        sf_ekf_fix_r(&e, &p, 3.0, r);
        (void)sf_ekf_update(&e, &p, true, nu, r, dpos);
        x += dpos[0], y += dpos[1];
    }
    *out = e;
    for (int k = 0; k < 100; k++) {
        double d[2];
        sf_ekf_step(out, &p, 0.6, 1.0, d);
    }
    return x;
}

static void test_correlated_fix_error(void **state)
{
    (void)state;
    sf_ekf_t white, coloured;
    const double x_white = stuck_fix_run(0.0, &white), x_coloured = stuck_fix_run(4.0, &coloured);
    printf("after 20 identical fixes 5 m off: position %.2f m (independent fixes), %.2f m (correlated error "
           "state, c = %.2f m)\n",
           x_white, x_coloured, coloured.fix_bias_m[0]);
    assert_true(x_white > 2.0); /* (0/1 + 20·5/25) / (1 + 20/25) = 2.22 m */
    assert_true(x_coloured < 0.5);
    near(coloured.P[4][4], 16.0, 0.3); /* after 60 m, c's variance is σ_c² again */
    near(coloured.fix_bias_m[0], 0.0, 0.05);
}

/* Through sf_fusion: the ekf initialises at the first fix with its R, publishes covariance, bias and
 * scale, gates on the NIS, and audits α = the mean position gain. */
static void test_scheme_in_fusion(void **state)
{
    (void)state;
    sf_params_t p = params();
    p.ekf_fix_var_x_per_acc2 = 4.0;
    p.ekf_fix_var_y_per_acc2 = 4.0;
    sf_fusion_t f;
    assert_int_equal(sf_fusion_init(&f, sf_scheme_ekf), SF_OK);
    assert_true(sf_fusion_scheme_is_registered(sf_scheme_ekf));
    assert_string_equal(sf_fusion_scheme_name(sf_scheme_ekf), "ekf");
    sf_fix_t fix = {.t_us = 1000000, .method = sf_fix_wifi, .x_m = 10, .y_m = 5, .accuracy_m = 2.0, .n_ap_used = 9};
    sf_fix_audit_t a;
    assert_int_equal(sf_fusion_fix(&f, &p, &fix, 0, &a), SF_OK);
    assert_int_equal(a.reason, sf_fix_reason_initialised);
    near(a.innovation_var_m2, 16.0, 1e-12); /* R = 2² · 4 */
    sf_pose_t pose = {.heading_rad = 0.0};
    assert_true(sf_fusion_pose(&f, &p, 1000000, 0, &pose));
    near(pose.cov_m2[0], 16.0, 1e-12);
    near(pose.sigma_m, 4.0, 1e-12);
    near(pose.stride_scale, 1.0, 0.0);
    for (int k = 1; k <= 10; k++) {
        sf_fusion_step(&f, &p, 1000000 + k * 500000, 0.7, 0.0, 0.7);
    }
    fix.t_us = 7000000;
    fix.x_m = 17.5;
    fix.y_m = 7.0; /* 2 m left of the PDR track: the bias moves toward +y */
    assert_int_equal(sf_fusion_fix(&f, &p, &fix, 0, &a), SF_OK);
    assert_int_equal(a.reason, sf_fix_reason_accepted);
    assert_true(a.alpha > 0.0 && a.alpha < 1.0);
    assert_true(sf_fusion_pose(&f, &p, 7000000, 0, &pose));
    assert_true(pose.heading_bias_rad > 0.0);
    assert_true(pose.heading_rad > 0.0); /* the published heading carries the bias */
    fix.t_us = 8000000;
    fix.x_m = 500.0; /* far outside the gate */
    assert_int_equal(sf_fusion_fix(&f, &p, &fix, 0, &a), SF_OK);
    assert_int_equal(a.reason, sf_fix_reason_gate);
    assert_true(a.test_ratio > 1.0);
}

/* A site that measured its fix errors overrides the parameters' model: R = accuracy² · the site's M. */
static void test_site_fix_model(void **state)
{
    (void)state;
    const sf_params_t p = params();
    const sf_fix_model_t site = {
        .valid = true, .cov_per_acc2 = {9.0, 0.0, 9.0}, .bias_sigma_m = 0.0, .bias_length_m = 10.0, .white_share = 1.0};
    sf_fusion_t f;
    assert_int_equal(sf_fusion_init(&f, sf_scheme_ekf), SF_OK);
    sf_fusion_set_fix_model(&f, &p, &site);
    const sf_fix_t fix = {.t_us = 1000000, .method = sf_fix_wifi, .x_m = 1, .y_m = 2, .accuracy_m = 2.0, .n_ap_used = 9};
    sf_fix_audit_t a;
    assert_int_equal(sf_fusion_fix(&f, &p, &fix, 0, &a), SF_OK);
    near(a.innovation_var_m2, 36.0, 1e-12); /* 2² · 9, not the parameters' 2² · 1 */
    const sf_fix_model_t invalid = {.valid = false};
    sf_fusion_set_fix_model(&f, &p, &invalid);
    assert_null(f.fix_model);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_step_jacobian),
        cmocka_unit_test(test_update_is_kalman),
        cmocka_unit_test(test_learns_bias_and_scale),
        cmocka_unit_test(test_fix_model_only_grows),
        cmocka_unit_test(test_correlated_fix_error),
        cmocka_unit_test(test_scheme_in_fusion),
        cmocka_unit_test(test_site_fix_model),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
