/* test_fingerprint_preselect.c — the WkNN candidate pre-selection (sf_fingerprint_preselect.c) against
 * the full visit on a 40 × 40 grid of two floors: on a noisy walk no less accurate than the full
 * visit (within 5 cm), far fewer RPs scored; the floor hint and censoring respected; a proven fix
 * always the full visit's; the full visit where it does not apply, on a walk-built map, or where it
 * costs less (a small map); a capped ranking; misuse of the arrays. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sf_error.h"
#include "sf_fingerprint.h"
#include "sf_params.h"
#include "sf_test_rng.h"

#define SIDE 40
#define N_RP (SIDE * SIDE * 2) /* two floors, the same grid */
#define N_AP 100 /* one per 64 m² */
#define CAP_ENTRIES (N_RP * N_AP)

typedef struct {
    int64_t bssid[N_AP];
    int32_t first[N_AP + 1];
    float x[N_RP], y[N_RP];
    int16_t floor[N_RP];
    int32_t scans[N_RP];
    int32_t rp[CAP_ENTRIES], count[CAP_ENTRIES];
    float mean[CAP_ENTRIES], std[CAP_ENTRIES];
    double ap_x[N_AP], ap_y[N_AP];
    sf_radiomap_t map;
} grid_t;

/* The workspace, with or without the pre-selection's arrays. */
typedef struct {
    double fill[N_RP], miss[N_RP], acc[N_RP];
    int32_t n_common[N_RP], touched[N_RP];
    double rp_entry_g[CAP_ENTRIES], ap_w[N_AP];
    int32_t rp_first[N_RP + 1], rp_ap[CAP_ENTRIES];
    double entry_g[CAP_ENTRIES];
    sf_fingerprint_workspace_t ws;
} ws_mem_t;

static grid_t g_grid;
static ws_mem_t g_pre, g_full;

/* Log-distance levels (exponent 3), one AP per 64 m² at seeded places, a floor slab 15 dB. */
static double model_dbm(const grid_t *const g, const int a, const double x, const double y, const int dfloor)
{
    const double d = hypot(x - g->ap_x[a], y - g->ap_y[a]);
    return -35.0 - 30.0 * log10(d > 1.0 ? d : 1.0) - 15.0 * dfloor;
}

static void make_grid(grid_t *const g)
{
    rng_t rng = {77};
    for (int a = 0; a < N_AP; a++) {
        g->ap_x[a] = 80.0 * rng_uniform01(&rng);
        g->ap_y[a] = 80.0 * rng_uniform01(&rng);
        g->bssid[a] = 0xB0000000LL + 4 * a;
    }
    for (int r = 0; r < N_RP; r++) {
        const int c = r % (SIDE * SIDE);
        g->x[r] = (float)(2 * (c % SIDE) + 1);
        g->y[r] = (float)(2 * (c / SIDE) + 1);
        g->floor[r] = (int16_t)(r / (SIDE * SIDE));
        g->scans[r] = 4;
    }
    int32_t n = 0;
    for (int a = 0; a < N_AP; a++) {
        g->first[a] = n;
        const int ap_floor = a % 2; /* even APs on floor 0, odd on floor 1 */
        for (int r = 0; r < N_RP; r++) {
            const double v = model_dbm(g, a, g->x[r], g->y[r], abs(g->floor[r] - ap_floor));
            if (v >= -95.0) { /* some below min_rssi_dbm −90: censored entries */
                g->rp[n] = r;
                g->mean[n] = (float)v;
                g->std[n] = 3.0f;
                g->count[n] = 1 + (r + a) % 4; /* map_level 1 mixes in the misses */
                n++;
            }
        }
    }
    g->first[N_AP] = n;
    g->map = (sf_radiomap_t){N_AP, g->bssid, g->first, N_RP, g->x, g->y, g->floor, g->scans,
                             n, g->rp, g->mean, g->std, g->count};
}

static void ws_setup(ws_mem_t *const m, const bool preselect)
{
    m->ws = (sf_fingerprint_workspace_t){.n_rp = N_RP, .rp_fill_sq_db2 = m->fill, .rp_miss_loglik = m->miss,
                                         .acc = m->acc, .n_common = m->n_common, .touched = m->touched};
    if (preselect) {
        m->ws.n_entries = CAP_ENTRIES;
        m->ws.n_ap = N_AP;
        m->ws.rp_entry_first = m->rp_first;
        m->ws.rp_entry_ap = m->rp_ap;
        m->ws.rp_entry_level_db = m->rp_entry_g;
        m->ws.ap_query_w = m->ap_w;
        m->ws.entry_level_db = m->entry_g;
    }
}

static int setup(void **state)
{
    (void)state;
    make_grid(&g_grid);
    return 0;
}

/* A scan at (x, y) on floor fl with gauss_db of noise: every AP heard above −88 dBm. */
static int scan_at(const grid_t *const g, rng_t *const rng, const double x, const double y, const int fl,
                   const double gauss_db, int64_t *const b, float *const v)
{
    int n = 0;
    for (int a = 0; a < N_AP; a++) {
        const double lv = model_dbm(g, a, x, y, abs(fl - a % 2)) + gauss_db * rng_gauss(rng);
        if (lv > -88.0) {
            b[n] = g->bssid[a];
            v[n] = (float)round(lv);
            n++;
        }
    }
    return n;
}

typedef struct {
    int fixes, identical, preselected, proven;
    double scored_sum;
    double err_pre_m, err_full_m; /* mean distance to the scan's true position */
} walk_stats_t;

/* A noisy walk over both floors, each scan matched with and without the pre-selection. */
static walk_stats_t walk(const sf_params_t *const p, const double gauss_db, const bool any_floor)
{
    const grid_t *const g = &g_grid;
    ws_setup(&g_pre, true);
    ws_setup(&g_full, false);
    assert_int_equal(sf_fingerprint_prepare(&g_pre.ws, &g->map, p), SF_OK);
    assert_int_equal(sf_fingerprint_prepare(&g_full.ws, &g->map, p), SF_OK);
    static sf_fingerprint_t f_pre, f_full;
    sf_fingerprint_init(&f_pre);
    sf_fingerprint_init(&f_full);
    rng_t rng = {2024};
    walk_stats_t st = {0};
    for (int s = 0; s < 300; s++) {
        const int fl = s < 150 ? 0 : 1;
        const double x = 3.0 + 74.0 * rng_uniform01(&rng), y = 3.0 + 74.0 * rng_uniform01(&rng);
        int64_t b[N_AP];
        float v[N_AP];
        const int n = scan_at(g, &rng, x, y, fl, gauss_db, b, v);
        const sf_wifi_scan_t scan = {1000000LL * (s + 1), n, b, v};
        sf_fix_t x_pre = {0}, x_full = {0};
        const int r_pre = sf_fingerprint_match(&f_pre, p, &g->map, &g_pre.ws, &scan, (int16_t)fl, any_floor, &x_pre);
        const int r_full =
            sf_fingerprint_match(&f_full, p, &g->map, &g_full.ws, &scan, (int16_t)fl, any_floor, &x_full);
        assert_int_equal(r_pre, r_full);
        assert_int_equal(f_full.audit.preselected, 0);
        if (r_full != SF_OK) {
            continue;
        }
        st.fixes++;
        st.identical += memcmp(&x_pre, &x_full, sizeof x_pre) == 0;
        st.preselected += f_pre.audit.preselected != 0;
        st.proven += f_pre.audit.preselected == 1;
        if (f_pre.audit.preselected == 1) { /* proven: the full visit's fix */
            assert_memory_equal(&x_pre, &x_full, sizeof x_pre);
        }
        st.scored_sum += f_pre.audit.n_candidates;
        st.err_pre_m += hypot(x_pre.x_m - x, x_pre.y_m - y);
        st.err_full_m += hypot(x_full.x_m - x, x_full.y_m - y);
        if (!any_floor) {
            for (int i = 0; i < f_pre.audit.k_used; i++) {
                assert_int_equal(g->floor[f_pre.audit.winner_rp[i]], fl);
            }
        }
    }
    st.err_pre_m /= st.fixes > 0 ? st.fixes : 1;
    st.err_full_m /= st.fixes > 0 ? st.fixes : 1;
    for (int r = 0; r < N_RP; r++) { /* the scratch left as found */
        assert_int_equal(g_pre.n_common[r], 0);
    }
    for (int a = 0; a < N_AP; a++) {
        assert_true(g_pre.ap_w[a] == 0.0);
    }
    return st;
}

/* The pre-selection's promise: on the whole no less accurate than the full visit, each fix decided by
 * it, the proven ones bit-identical (checked in walk), and few RPs scored. */
static void assert_like_full_visit(const walk_stats_t *const st, const int eligible_rp, const double tol_m)
{
    print_message("%d fixes, %d identical, %d pre-selected (%d proven), %.0f of %d RPs scored per fix, mean error "
                  "%.3f m (full visit %.3f m)\n",
                  st->fixes, st->identical, st->preselected, st->proven, st->scored_sum / st->fixes, eligible_rp,
                  st->err_pre_m, st->err_full_m);
    assert_true(st->fixes >= 290);
    assert_true(st->err_pre_m <= st->err_full_m + tol_m);
    assert_int_equal(st->preselected, st->fixes);
    assert_true(st->scored_sum / st->fixes <= SF_FINGERPRINT_PRESELECT_RPS_MAX);
    assert_true(st->scored_sum / st->fixes < 0.1 * eligible_rp);
}

/* Default parameters, 4 dB of noise (indoor shadowing), on the scan's floor and on any floor. */
static void test_like_full_visit(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    for (int any = 0; any <= 1; any++) {
        const walk_stats_t st = walk(&p, 4.0, any == 1);
        assert_like_full_visit(&st, any ? N_RP : SIDE * SIDE, 0.05);
    }
}

/* Other WkNN settings that the pre-selection serves (powed β, stored levels, k = 1 and 8), within
 * 15 cm of the full visit (the defaults: 5 cm). */
static void test_like_full_visit_other_settings(void **state)
{
    (void)state;
    for (int c = 0; c < 4; c++) {
        sf_params_t p;
        sf_params_default(&p);
        p.fingerprint_powed_beta = c == 0 ? 2.718281828 : 1.0;
        p.fingerprint_map_level = c == 1 ? 0 : 1;
        p.fingerprint_k = c == 2 ? 1 : (c == 3 ? 8 : 3);
        const walk_stats_t st = walk(&p, 4.0, false);
        print_message("case %d: ", c);
        assert_like_full_visit(&st, SIDE * SIDE, 0.15); /* k = 1 picks one RP: a miss costs more */
    }
}

/* Off (preselect_aps 0), naive Bayes and common-APs mode: the full visit, with the arrays present. */
static void test_full_visit_when_not_applicable(void **state)
{
    (void)state;
    for (int c = 0; c < 3; c++) {
        sf_params_t p;
        sf_params_default(&p);
        p.fingerprint_preselect_aps = c == 0 ? 0 : p.fingerprint_preselect_aps;
        p.fingerprint_method = c == 1 ? 1 : 0;
        p.fingerprint_missing_mode = c == 2 ? 1 : 0;
        const walk_stats_t st = walk(&p, 3.0, true);
        assert_true(st.fixes > 0);
        assert_int_equal(st.identical, st.fixes);
        assert_int_equal(st.preselected, 0);
    }
}

/* A walk-built map (2 scans per RP, under preselect_min_scans 3): the full visit, every fix. */
static void test_walk_built_map_full_visit(void **state)
{
    (void)state;
    for (int r = 0; r < N_RP; r++) {
        g_grid.scans[r] = 2;
    }
    for (int32_t i = 0; i < g_grid.map.n_entries; i++) {
        g_grid.count[i] = g_grid.count[i] > 2 ? 2 : g_grid.count[i];
    }
    sf_params_t p;
    sf_params_default(&p);
    const walk_stats_t st = walk(&p, 4.0, false);
    make_grid(&g_grid); /* as the other tests have it */
    assert_true(st.fixes >= 290);
    assert_int_equal(st.preselected, 0);
    assert_int_equal(st.identical, st.fixes);
}

/* Ranking only k RPs (preselect_rps 1 → k) with one AP: mostly unproven (preselected 2), and then the
 * full visit's winners may be missed; a proven one is the full visit's fix. */
static void test_capped_ranking(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    p.fingerprint_preselect_aps = 1;
    p.fingerprint_preselect_rps = 1;
    const walk_stats_t st = walk(&p, 6.0, false);
    print_message("capped: %d fixes, %d identical, %d proven\n", st.fixes, st.identical, st.proven);
    assert_int_equal(st.preselected, st.fixes);
    assert_true(st.proven < st.fixes / 2);
    assert_true(st.identical >= st.proven);
    assert_true(st.identical < st.fixes);
}

/* A small map (each AP at a few RPs, each RP hearing every AP): the full visit is the cheaper, so it
 * runs (preselected 0), arrays or not. */
static void test_small_map_full_visit(void **state)
{
    (void)state;
    static const int64_t bssid[3] = {0x100, 0x200, 0x300};
    static const int32_t first[4] = {0, 4, 8, 12};
    static const float x[4] = {0, 4, 0, 4}, y[4] = {0, 0, 4, 4};
    static const int16_t fl[4] = {0, 0, 0, 0};
    static const int32_t scans[4] = {10, 10, 10, 10};
    static const int32_t rp[12] = {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3};
    static const float mean[12] = {-40, -60, -50, -48, -60, -40, -70, -52, -70, -80, -50, -66};
    static const float sd[12] = {2, 4, 4, 4, 5, 4, 4, 4, 3, 6, 4, 4};
    static const int32_t count[12] = {10, 10, 10, 10, 10, 10, 10, 10, 10, 10, 10, 10};
    const sf_radiomap_t map = {3, bssid, first, 4, x, y, fl, scans, 12, rp, mean, sd, count};
    sf_params_t p;
    sf_params_default(&p);
    ws_setup(&g_pre, true);
    ws_setup(&g_full, false);
    assert_int_equal(sf_fingerprint_prepare(&g_pre.ws, &map, &p), SF_OK);
    assert_int_equal(sf_fingerprint_prepare(&g_full.ws, &map, &p), SF_OK);
    static sf_fingerprint_t f_pre, f_full;
    sf_fingerprint_init(&f_pre);
    sf_fingerprint_init(&f_full);
    static const float rssi[3] = {-45, -62, -60};
    const sf_wifi_scan_t scan = {1, 3, bssid, rssi};
    sf_fix_t a = {0}, b = {0};
    assert_int_equal(sf_fingerprint_match(&f_pre, &p, &map, &g_pre.ws, &scan, 0, true, &a), SF_OK);
    assert_int_equal(sf_fingerprint_match(&f_full, &p, &map, &g_full.ws, &scan, 0, true, &b), SF_OK);
    assert_int_equal(f_pre.audit.preselected, 0);
    assert_int_equal(f_pre.audit.n_touched, 4);
    assert_memory_equal(&a, &b, sizeof a);
}

/* The arrays come all together, large enough for the map, or not at all. */
static void test_prepare_checks_arrays(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    ws_setup(&g_pre, true);
    g_pre.ws.rp_entry_ap = NULL;
    assert_int_equal(sf_fingerprint_prepare(&g_pre.ws, &g_grid.map, &p), SF_EINVAL);
    ws_setup(&g_pre, true);
    g_pre.ws.n_entries = g_grid.map.n_entries - 1;
    assert_int_equal(sf_fingerprint_prepare(&g_pre.ws, &g_grid.map, &p), SF_EINVAL);
    ws_setup(&g_pre, true);
    g_pre.ws.n_ap = N_AP - 1;
    assert_int_equal(sf_fingerprint_prepare(&g_pre.ws, &g_grid.map, &p), SF_EINVAL);
    ws_setup(&g_pre, true);
    assert_int_equal(sf_fingerprint_prepare(&g_pre.ws, &g_grid.map, &p), SF_OK);
    /* RP-major: every RP's entries, APs ascending, the same count as the AP-major map */
    assert_int_equal(g_pre.rp_first[N_RP], g_grid.map.n_entries);
    for (int r = 0; r < N_RP; r++) {
        for (int32_t j = g_pre.rp_first[r] + 1; j < g_pre.rp_first[r + 1]; j++) {
            assert_true(g_pre.rp_ap[j - 1] < g_pre.rp_ap[j]);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_like_full_visit),
        cmocka_unit_test(test_like_full_visit_other_settings),
        cmocka_unit_test(test_full_visit_when_not_applicable),
        cmocka_unit_test(test_capped_ranking),
        cmocka_unit_test(test_small_map_full_visit),
        cmocka_unit_test(test_walk_built_map_full_visit),
        cmocka_unit_test(test_prepare_checks_arrays),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
