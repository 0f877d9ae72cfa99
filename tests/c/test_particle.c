/* test_particle.c — the particle scheme (sf_particle.h, sf_fusion_particle.c): bit-identical replays by
 * seed, resampling keeps N and brings the ESS back, no particle crosses a wall over a long walk in a
 * building, a kidnapped walker is found again, floors change only at ports, and in a corridor the walls
 * make the fused track better than the fixes it is fed. Memory as the header states. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "sf_error.h"
#include "sf_fusion.h"
#include "sf_particle.h"
#include "sf_test_rng.h"
#include "sf_wall_grid.h"

static sf_particle_state_t states[2][SF_PARTICLE_MAX];
static int16_t pfloors[2][SF_PARTICLE_MAX];
static int32_t grid_mem[1 << 16];

enum { MAX_W = 64 };
static float wx0[MAX_W], wy0[MAX_W], wx1[MAX_W], wy1[MAX_W];
static int16_t wfl[MAX_W];
static int n_w;

static void wall(const float x0, const float y0, const float x1, const float y1)
{
    wx0[n_w] = x0, wy0[n_w] = y0, wx1[n_w] = x1, wy1[n_w] = y1, wfl[n_w] = 0;
    n_w++;
}

static sf_floor_plan_t plan_of(void)
{
    return (sf_floor_plan_t){.n_walls = n_w, .x0_m = wx0, .y0_m = wy0, .x1_m = wx1, .y1_m = wy1, .floor = wfl};
}

static bool crosses_any(const double ax, const double ay, const double bx, const double by)
{
    for (int i = 0; i < n_w; i++) {
        if (sf_wall_segments_cross(ax, ay, bx, by, wx0[i], wy0[i], wx1[i], wy1[i])) {
            return true;
        }
    }
    return false;
}

static void test_memory_and_contract(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_particle_t c;
    assert_int_equal(sf_particle_init(&c, &p, NULL, pfloors[0], 10), SF_EINVAL);
    assert_int_equal(sf_particle_init(&c, &p, states[0], pfloors[0], 0), SF_EINVAL);
    assert_int_equal(sf_particle_init(&c, &p, states[0], pfloors[0], SF_PARTICLE_MAX + 1), SF_EINVAL);
    assert_int_equal(sf_particle_init(&c, &p, states[0], pfloors[0], 300), SF_OK);
    assert_int_equal(c.n, 300); /* min(particle.count, capacity) */
    assert_int_equal(sizeof(sf_particle_state_t), 32);
    assert_int_equal(SF_PARTICLE_BYTES_PER, 34);
    assert_true(sizeof(sf_particle_t) <= 128);
    printf("memory: %zu B per particle, %zu B for 1 000, %zu B header\n", SF_PARTICLE_BYTES_PER,
           1000 * SF_PARTICLE_BYTES_PER, sizeof(sf_particle_t));
}

/* A walk of steps with a fix every 5th, the poses' bits into out[]. */
static void replay(const int32_t seed, const int k, double out[200][2])
{
    sf_params_t p;
    sf_params_default(&p);
    p.particle_seed = seed;
    sf_particle_t c;
    assert_int_equal(sf_particle_init(&c, &p, states[k], pfloors[k], SF_PARTICLE_MAX), SF_OK);
    sf_particle_seed(&c, &p, 0.0, 0.0, 2.0, 0, false);
    for (int i = 0; i < 200; i++) {
        sf_particle_step(&c, &p, 0.7, 0.01 * i, 0);
        if (i % 5 == 4) {
            double ess;
            (void)sf_particle_update(&c, &p, 0.7 * i, 0.0, 3.0, &ess);
        }
        sf_particle_summary_t s;
        sf_particle_summary(&c, &s);
        out[i][0] = s.x_m;
        out[i][1] = s.y_m;
    }
}

static void test_determinism(void **state)
{
    (void)state;
    static double a[200][2], b[200][2], d[200][2];
    replay(7, 0, a);
    replay(7, 1, b);
    replay(8, 1, d);
    assert_memory_equal(a, b, sizeof a); /* same seed: bit-identical */
    assert_true(memcmp(a, d, sizeof a) != 0);
    assert_true(fabs(a[199][0] - d[199][0]) > 1e-9); /* another seed: another cloud */
}

static void test_resampling_keeps_n_and_ess_recovers(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_particle_t c;
    assert_int_equal(sf_particle_init(&c, &p, states[0], pfloors[0], SF_PARTICLE_MAX), SF_OK);
    sf_particle_seed(&c, &p, 0.0, 0.0, 5.0, 0, false);
    p.particle_resample_ess_ratio = 0.0; /* see the ESS fall first */
    double ess;
    const double alpha = sf_particle_update(&c, &p, 3.0, 0.0, 1.0, &ess);
    printf("a 1 m fix 3 m off a 5 m cloud: ESS %.0f of %d, alpha %.3f\n", ess, c.n, alpha);
    assert_true(ess < 0.5 * c.n && alpha > 0.3 && alpha < 1.0); /* below the default resampling ratio */
    sf_particle_summary_t before;
    sf_particle_summary(&c, &before);
    sf_particle_resample(&c);
    assert_int_equal(c.n, 1000);
    assert_true(fabs(sf_particle_ess(&c) - 1000.0) < 1e-6);
    double sw = 0.0;
    for (int i = 0; i < c.n; i++) {
        sw += c.p[i].w;
    }
    assert_true(fabs(sw - 1.0) < 1e-12);
    sf_particle_summary_t after;
    sf_particle_summary(&c, &after);
    assert_true(fabs(after.x_m - before.x_m) < 0.3 && fabs(after.y_m - before.y_m) < 0.3); /* same distribution */
    assert_int_equal(c.resamples, 1);
}

/* A building of 30 × 20 m: outer walls, an inner wall at x = 15 with a 1.2 m door, a room. The walker
 * bounces off walls; the PDR heading has noise and a 5° bias. */
static void building(void)
{
    n_w = 0;
    wall(0, 0, 30, 0), wall(30, 0, 30, 20), wall(30, 20, 0, 20), wall(0, 20, 0, 0);
    wall(15, 0, 15, 9.4f), wall(15, 10.6f, 15, 20);
    wall(20, 12, 26, 12), wall(26, 12, 26, 17), wall(20, 17, 24, 17); /* a room with a 2 m opening */
}

static void test_no_particle_crosses_a_wall(void **state)
{
    (void)state;
    building();
    const sf_floor_plan_t plan = plan_of();
    sf_wall_grid_t g;
    assert_int_equal(sf_wall_grid_build(&g, &plan, 2.0, grid_mem, sf_wall_grid_bytes(&plan, 2.0)), SF_OK);
    sf_params_t p;
    sf_params_default(&p);
    sf_particle_t c;
    assert_int_equal(sf_particle_init(&c, &p, states[0], pfloors[0], SF_PARTICLE_MAX), SF_OK);
    sf_particle_set_map(&c, &g, NULL);
    rng_t r = {.s = 99};
    double x = 5.0, y = 5.0, h = 0.3;
    sf_particle_seed(&c, &p, x, y, 0.3, 0, false);
    static double px[SF_PARTICLE_MAX], py[SF_PARTICLE_MAX];
    int crossings = 0;
    for (int i = 0; i < 3000; i++) {
        h += 0.15 * rng_gauss(&r);
        double nx = x + 0.7 * cos(h), ny = y + 0.7 * sin(h);
        while (crosses_any(x, y, nx, ny)) { /* the walker turns away from the wall */
            h += 1.0 + rng_uniform01(&r);
            nx = x + 0.7 * cos(h), ny = y + 0.7 * sin(h);
        }
        x = nx, y = ny;
        for (int k = 0; k < c.n; k++) {
            px[k] = c.p[k].x_m, py[k] = c.p[k].y_m;
        }
        const uint32_t resamples = c.resamples;
        sf_particle_step(&c, &p, 0.7, h + 0.087 + 0.05 * rng_gauss(&r), 0);
        for (int k = 0; k < c.n && c.resamples == resamples; k++) { /* same slots: each particle's move */
            crossings += c.p[k].w > 0.0 && crosses_any(px[k], py[k], c.p[k].x_m, c.p[k].y_m);
        }
        for (int k = 0; k < c.n; k++) { /* always: every live particle inside the building (a dead one,
                                          * w = 0, lies where its step took it until resampling) */
            assert_true(c.p[k].w == 0.0 ||
                        (c.p[k].x_m > 0.0 && c.p[k].x_m < 30.0 && c.p[k].y_m > 0.0 && c.p[k].y_m < 20.0));
        }
    }
    sf_particle_summary_t s;
    sf_particle_summary(&c, &s);
    printf("3 000 steps in a building: %u particle deaths at walls, %u resamples, %u all-blocked steps, "
           "%d surviving crossings; final error %.2f m\n",
           c.deaths, c.resamples, c.all_blocked, crossings, hypot(s.x_m - x, s.y_m - y));
    assert_int_equal(crossings, 0);
    assert_int_equal(c.all_blocked, 0);
    assert_true(c.deaths > 1000);
}

/* Open space, fixes every 4 steps (σ 2 m); at step 100 the walker is carried 30 m away. */
static void test_kidnap_recovery(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_particle_t c;
    assert_int_equal(sf_particle_init(&c, &p, states[0], pfloors[0], SF_PARTICLE_MAX), SF_OK);
    sf_fusion_t f;
    sf_fusion_init(&f, sf_scheme_particle);
    sf_fusion_set_cloud(&f, &p, &c);
    rng_t r = {.s = 5};
    double x = 0.0, y = 0.0;
    int fixes_after = -1, back_after = -1;
    for (int i = 0; i < 300; i++) {
        const int64_t t = (int64_t)i * 500000;
        if (i == 100) {
            y += 30.0; /* kidnapped */
            fixes_after = 0;
        }
        const double h = 0.02 * i;
        x += 0.7 * cos(h), y += 0.7 * sin(h);
        sf_fusion_step_on_floor(&f, &p, t, 0.7 * cos(h), 0.7 * sin(h), 0.7, 0);
        if (i % 4 == 0) {
            const sf_fix_t fx = {.t_us = t + 1, .method = sf_fix_wifi, .x_m = x + 2.0 * rng_gauss(&r),
                                 .y_m = y + 2.0 * rng_gauss(&r), .accuracy_m = 2.0, .n_ap_used = 8};
            sf_fix_audit_t a;
            assert_int_equal(sf_fusion_fix(&f, &p, &fx, 0, &a), SF_OK);
            sf_pose_t pose = {0};
            assert_true(sf_fusion_pose(&f, &p, t + 1, 0, &pose));
            if (fixes_after >= 0) {
                fixes_after++;
                if (back_after < 0 && hypot(pose.x_m - x, pose.y_m - y) < 4.0) {
                    back_after = fixes_after;
                }
            }
        }
    }
    printf("kidnapped 30 m: back within 4 m after %d fixes (max_rejections %d), %u recoveries\n", back_after,
           p.fusion_max_rejections, f.recoveries);
    assert_true(back_after > 0 && back_after <= p.fusion_max_rejections + 3);
    assert_true(f.recoveries >= 1);
}

static void test_floor_changes_only_at_ports(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_particle_t c;
    assert_int_equal(sf_particle_init(&c, &p, states[0], pfloors[0], SF_PARTICLE_MAX), SF_OK);
    const int16_t kind[2] = {sf_port_door, sf_port_stairs};
    const float px[2] = {0.0f, 10.0f}, py[2] = {0.0f, 0.0f}, pr[2] = {3.0f, 1.5f};
    const int16_t lo[2] = {0, 0}, hi[2] = {0, 1};
    const sf_ports_t ports = {.n_ports = 2, .kind = kind, .x_m = px, .y_m = py, .radius_m = pr, .floor_lo = lo,
                              .floor_hi = hi};
    sf_particle_set_map(&c, NULL, &ports);
    sf_particle_seed(&c, &p, 0.0, 0.0, 0.2, 0, false);
    p.particle_heading_sigma_rad = 0.0, p.particle_length_sigma = 0.0, p.particle_bias_rw_rad2_per_m = 0.0;
    p.particle_init_bias_sigma_rad = 0.0;
    for (int i = 0; i < 8; i++) { /* the barometer says 1 while walking 5.6 m along x, not yet at the stairs */
        sf_particle_step(&c, &p, 0.7, 0.0, 1);
        for (int k = 0; k < c.n; k++) {
            assert_int_equal(c.floor[k], 0); /* a door joins no floors; elsewhere no port at all */
        }
    }
    for (int i = 0; i < 8; i++) { /* on to the stairs at x = 10 */
        sf_particle_step(&c, &p, 0.7, 0.0, 1);
    }
    sf_particle_summary_t s;
    sf_particle_summary(&c, &s);
    printf("floors: %u changes, pose floor %d at x = %.1f m\n", c.floor_changes, s.floor, s.x_m);
    assert_int_equal(s.floor, 1);
    for (int k = 0; k < c.n; k++) { /* everyone on floor 1 passed through the stairs' disc */
        assert_true(c.floor[k] == 0 || c.p[k].x_m > 8.0);
    }
    /* no ports joining floors: anywhere, at once */
    sf_particle_set_map(&c, NULL, NULL);
    sf_particle_step(&c, &p, 0.7, 0.0, 2);
    for (int k = 0; k < c.n; k++) {
        assert_int_equal(c.floor[k], 2);
    }
}

/* A corridor 2.4 m wide and 80 m long; the PDR heading is 4° off, the fixes 3 m σ. */
static void test_corridor_beats_fixes(void **state)
{
    (void)state;
    n_w = 0;
    wall(-1, -1.2f, 81, -1.2f), wall(-1, 1.2f, 81, 1.2f), wall(-1, -1.2f, -1, 1.2f), wall(81, -1.2f, 81, 1.2f);
    const sf_floor_plan_t plan = plan_of();
    sf_wall_grid_t g;
    assert_int_equal(sf_wall_grid_build(&g, &plan, 2.0, grid_mem, sf_wall_grid_bytes(&plan, 2.0)), SF_OK);
    sf_params_t p;
    sf_params_default(&p);
    double err_pf = 0.0, err_fix = 0.0;
    int n_pf = 0, n_fix = 0;
    for (int run = 0; run < 5; run++) {
        sf_particle_t c;
        p.particle_seed = run + 1;
        assert_int_equal(sf_particle_init(&c, &p, states[0], pfloors[0], SF_PARTICLE_MAX), SF_OK);
        sf_particle_set_map(&c, &g, NULL);
        sf_fusion_t f;
        sf_fusion_init(&f, sf_scheme_particle);
        sf_fusion_set_cloud(&f, &p, &c);
        rng_t r = {.s = 1000u + (uint64_t)run};
        double x = 0.0;
        for (int i = 0; i < 110; i++) {
            const int64_t t = (int64_t)i * 500000;
            x += 0.7;
            const double h = 0.07 + 0.05 * rng_gauss(&r);
            sf_fusion_step_on_floor(&f, &p, t, 0.7 * cos(h), 0.7 * sin(h), 0.7, 0);
            if (i % 4 == 0) {
                const sf_fix_t fx = {.t_us = t + 1, .method = sf_fix_wifi, .x_m = x + 3.0 * rng_gauss(&r),
                                     .y_m = 3.0 * rng_gauss(&r), .accuracy_m = 3.0, .n_ap_used = 8};
                sf_fix_audit_t a;
                sf_fusion_fix(&f, &p, &fx, 0, &a);
                if (i >= 20) {
                    err_fix += hypot(fx.x_m - x, fx.y_m);
                    n_fix++;
                }
            }
            sf_pose_t pose = {0};
            if (i >= 20 && sf_fusion_pose(&f, &p, t + 2, 0, &pose)) {
                err_pf += hypot(pose.x_m - x, pose.y_m);
                n_pf++;
            }
        }
    }
    err_pf /= n_pf, err_fix /= n_fix;
    printf("corridor: particle mean error %.2f m, the fixes alone %.2f m\n", err_pf, err_fix);
    assert_true(err_pf < 0.6 * err_fix);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_memory_and_contract),
        cmocka_unit_test(test_determinism),
        cmocka_unit_test(test_resampling_keeps_n_and_ess_recovers),
        cmocka_unit_test(test_no_particle_crosses_a_wall),
        cmocka_unit_test(test_kidnap_recovery),
        cmocka_unit_test(test_floor_changes_only_at_ports),
        cmocka_unit_test(test_corridor_beats_fixes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
