/* core_cost.c — the estimator core's cost harness (against its cost budget), measured under callgrind by `stridefix-lab bench
 * perf` (lab/stridefix_lab/bench/perf.py), which counts the instructions inside one core call
 * (--toggle-collect) and divides by the calls this harness reports.
 *
 *   core_cost sensors SECONDS   a walk of SECONDS through the core's sensor calls at the board's rates:
 *                               IMU 100 Hz (sf_estimator_imu), MAG 50 Hz (sf_estimator_mag), BARO
 *                               20 Hz (sf_estimator_baro); a 1.8 Hz gait (sf_test_gait.h) on gravity,
 *                               a slow turn on the gyro, a constant 50 µT field with a hard-iron offset.
 *   core_cost wifi N_RP SCANS   SCANS Wi-Fi fixes (sf_fingerprint_match, default parameters) on a map of
 *                               N_RP reference points 2 m apart on a square grid of a building that
 *                               grows with the map: one AP per 40 m² (200 APs at 2 000 RPs), levels
 *                               −40 − 30·log10(d) dBm (+ 4 dB noise in the scans), an entry where the
 *                               mean is above −85 dBm, a scan hearing every AP above −80 dBm (~31).
 *                               With stridefixd's workspace and defaults, or with "full" after SCANS
 *                               fingerprint.preselect_aps = 0 (every entry of every AP heard visited).
 *   core_cost wifiheard N_RP SCANS HEARD_DBM
 *                               the wifi mode (pre-selection) with scans that hear every AP above
 *                               HEARD_DBM instead of −80 dBm: the fix's cost against the APs heard.
 *   core_cost wifidump N_RP SCANS PATH [full]
 *                               the wifi mode's map and scans, and each scan's fix, written to PATH as
 *                               text for a peer matcher (bench/perf_peers.py): "rp I X Y" per RP,
 *                               "e RP AP MEAN_DBM" per entry, "q X Y OK FX FY N AP RSSI ..." per scan
 *                               (truth, fix, the readings by AP index).
 *   The wifi modes' JSON has match_s: the wall time inside sf_fingerprint_match (CLOCK_MONOTONIC).
 *   core_cost samples SECONDS   the sensors walk's IMU and MAG samples as text, for a peer filter.
 *   core_cost yaw SECONDS       the sensors walk, printing "t_s yaw_rad" per IMU sample instead of the
 *                               JSON: our attitude's device yaw after the sample (and the tick's MAG
 *                               sample), to set beside the peer's on the samples mode's lines.
 *   core_cost sizes             sizeof of the core's state structs.
 *
 * Prints one JSON object (counts and what was built); exit 0, 2 on bad usage. The harness may use the
 * heap (the map is the caller's memory by design); the core calls never do (ctest core_symbols). */
/* clock_gettime (POSIX) under -std=c11: the harness times the matcher calls */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sf_estimator.h"
#include "sf_fingerprint.h"
#include "sf_params.h"
#include "sf_radiomap.h"
#include "sf_test_gait.h"
#include "sf_test_rng.h"

static int usage(void)
{
    fprintf(stderr, "usage: core_cost sensors SECONDS | yaw SECONDS | samples SECONDS | wifi N_RP SCANS [full] | wifidump N_RP SCANS PATH [full] | "
                    "wifiheard N_RP SCANS HEARD_DBM | sizes\n");
    return 2;
}

/* The walk's samples (both modes read the same stream): IMU at 100 Hz, MAG at 50 Hz (the even IMU ticks),
 * BARO at 20 Hz (every 5th). */
typedef struct {
    rng_t r;
    gait_t g;
} walk_t;

static void walk_init(walk_t *const w, const double seconds)
{
    w->r = (rng_t){0x2545F4914F6CDD1DULL};
    const int n_steps = (int)fmin(GAIT_MAX_STEPS, seconds * 1.8);
    gait_make(&w->g, &k_normal, n_steps, 2.0, &w->r);
}

static sf_imu_sample_t walk_imu(walk_t *const w, const int64_t k)
{
    const double t = (double)k / 100.0;
    /* the gait repeats when the walk is longer than GAIT_MAX_STEPS steps */
    const double tg = fmod(t, w->g.t_s[w->g.n] + 2.0);
    const double yaw_rate = 0.05 * sin(0.1 * t); /* a slow meander [rad/s] */
    rng_t *const r = &w->r;
    const sf_imu_sample_t s = {
        k * 10000,
        {0.05 * rng_gauss(r), 0.05 * rng_gauss(r), 9.81 + gait_accel(&w->g, tg) + 0.05 * rng_gauss(r)},
        {0.002 * rng_gauss(r), 0.002 * rng_gauss(r), yaw_rate + 0.002 * rng_gauss(r)},
    };
    return s;
}

static const double k_field_ut[3] = {20.0 + 12.0, 0.0 - 7.0, -45.0 + 3.0}; /* 50 µT + hard iron */

/* yaw: NULL, or where "t_s yaw_rad" goes after each IMU sample's tick (its MAG and BARO samples
 * included): the attitude filter's device yaw (sf_attitude_yaw_rad; nav x east, y north, z up). */
static int run_sensors(const double seconds, FILE *const yaw)
{
    static sf_params_t p;
    static sf_estimator_t est;
    sf_params_default(&p);
    sf_estimator_init(&est, &p);
    static walk_t w;
    walk_init(&w, seconds);
    const int64_t n_imu = (int64_t)(seconds * 100.0);
    long imu = 0, mag = 0, baro = 0, steps = 0;
    for (int64_t k = 0; k < n_imu; k++) {
        const sf_imu_sample_t s = walk_imu(&w, k);
        sf_step_t out[SF_ESTIMATOR_MAX_STEPS];
        steps += sf_estimator_imu(&est, &p, &s, out);
        imu++;
        if (k % 2 == 0) {
            sf_estimator_mag(&est, &p, s.t_us + 1000, k_field_ut);
            mag++;
        }
        if (k % 5 == 0) {
            sf_estimator_baro(&est, &p, s.t_us + 2000, 101325.0 + 2.0 * rng_gauss(&w.r));
            baro++;
        }
        if (yaw != NULL) {
            fprintf(yaw, "%.6f %.17g\n", (double)s.t_us * 1e-6, sf_attitude_yaw_rad(&est.attitude));
        }
    }
    if (yaw != NULL) {
        return 0;
    }
    printf("{\"mode\": \"sensors\", \"seconds\": %.1f, \"imu\": %ld, \"mag\": %ld, \"baro\": %ld, \"steps\": %ld}\n",
           seconds, imu, mag, baro, steps);
    return 0;
}

/* The same walk's IMU and MAG samples as text for a peer (one line per IMU sample: t_s, accel [m/s²],
 * gyro [rad/s], field [µT] of the latest MAG sample), without the BARO draws' noise in between kept
 * in step: the RNG draws the same sequence as run_sensors. */
static int run_samples(const double seconds)
{
    static walk_t w;
    walk_init(&w, seconds);
    const int64_t n_imu = (int64_t)(seconds * 100.0);
    for (int64_t k = 0; k < n_imu; k++) {
        const sf_imu_sample_t s = walk_imu(&w, k);
        printf("%.6f %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", (double)s.t_us * 1e-6, s.accel_mps2[0],
               s.accel_mps2[1], s.accel_mps2[2], s.gyro_radps[0], s.gyro_radps[1], s.gyro_radps[2], k_field_ut[0],
               k_field_ut[1], k_field_ut[2]);
        if (k % 5 == 0) {
            (void)rng_gauss(&w.r); /* the BARO sample's draw, so the IMU noise is run_sensors' */
        }
    }
    return 0;
}

/* a scan hears every AP above this level [dBm] (~31 APs at 2 000 RPs); wifiheard sets it */
#define WIFI_HEARD_DBM (-80.0)

static double level_dbm(const double d_m)
{
    return -40.0 - 30.0 * log10(fmax(d_m, 1.0));
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* dump: NULL, or where the map, the scans and the fixes go as text (wifidump) */
static int run_wifi(const int32_t n_rp_want, const int32_t n_scans, const bool preselect, const double heard_dbm,
                    FILE *const dump)
{
    const int32_t side = (int32_t)ceil(sqrt((double)n_rp_want));
    const int32_t n_rp = side * side;
    const double size_m = 2.0 * side;
    const int32_t n_ap = (int32_t)fmax(1.0, round(size_m * size_m / 40.0));
    rng_t r = {0x9E3779B97F4A7C15ULL};
    double *ax = malloc(sizeof *ax * (size_t)n_ap), *ay = malloc(sizeof *ay * (size_t)n_ap);
    int64_t *bssid = malloc(sizeof *bssid * (size_t)n_ap);
    int32_t *ap_first = malloc(sizeof *ap_first * (size_t)(n_ap + 1));
    float *rx = malloc(sizeof *rx * (size_t)n_rp), *ry = malloc(sizeof *ry * (size_t)n_rp);
    int16_t *rf = calloc((size_t)n_rp, sizeof *rf);
    int32_t *rscans = malloc(sizeof *rscans * (size_t)n_rp);
    for (int32_t a = 0; a < n_ap; a++) {
        ax[a] = size_m * rng_uniform01(&r);
        ay[a] = size_m * rng_uniform01(&r);
        bssid[a] = 0x0000A0B0C0000000LL + a; /* ascending */
    }
    for (int32_t i = 0; i < n_rp; i++) {
        rx[i] = (float)(2.0 * (i % side) + 1.0);
        ry[i] = (float)(2.0 * (i / side) + 1.0);
        rscans[i] = 3;
    }
    /* entries grouped by AP, RPs ascending within an AP: count first, then fill */
    const double reach_m = pow(10.0, (-40.0 + 85.0) / 30.0);
    size_t cap = 0;
    for (int32_t a = 0; a < n_ap; a++) {
        cap += (size_t)(GAIT_PI * reach_m * reach_m / 4.0) + 64;
    }
    int32_t *erp = malloc(sizeof *erp * cap), *ecount = malloc(sizeof *ecount * cap);
    float *emean = malloc(sizeof *emean * cap), *estd = malloc(sizeof *estd * cap);
    int32_t n_entries = 0;
    for (int32_t a = 0; a < n_ap; a++) {
        ap_first[a] = n_entries;
        /* only the grid cells within reach (RP (c, w) sits at (2c + 1, 2w + 1)), in ascending RP order */
        const int32_t c0 = (int32_t)fmax(0.0, floor((ax[a] - reach_m) / 2.0));
        const int32_t c1 = (int32_t)fmin(side - 1.0, ceil((ax[a] + reach_m) / 2.0));
        const int32_t w0 = (int32_t)fmax(0.0, floor((ay[a] - reach_m) / 2.0));
        const int32_t w1 = (int32_t)fmin(side - 1.0, ceil((ay[a] + reach_m) / 2.0));
        for (int32_t w = w0; w <= w1; w++) {
            for (int32_t c = c0; c <= c1 && (size_t)n_entries < cap; c++) {
                const int32_t i = w * side + c;
                const double m = level_dbm(hypot(rx[i] - ax[a], ry[i] - ay[a]));
                if (m > -85.0) {
                    erp[n_entries] = i;
                    emean[n_entries] = (float)m;
                    estd[n_entries] = 4.0f;
                    ecount[n_entries] = 3;
                    n_entries++;
                }
            }
        }
    }
    ap_first[n_ap] = n_entries;
    if (dump != NULL) {
        for (int32_t i = 0; i < n_rp; i++) {
            fprintf(dump, "rp %d %.9g %.9g\n", i, rx[i], ry[i]);
        }
        for (int32_t a = 0; a < n_ap; a++) {
            for (int32_t e = ap_first[a]; e < ap_first[a + 1]; e++) {
                fprintf(dump, "e %d %d %.9g\n", erp[e], a, emean[e]);
            }
        }
    }
    const sf_radiomap_t map = {n_ap, bssid, ap_first, n_rp, rx, ry, rf, rscans, n_entries, erp, emean, estd, ecount};
    static sf_params_t p;
    sf_params_default(&p);
    sf_fingerprint_workspace_t ws = {0};
    ws.n_rp = n_rp;
    ws.rp_fill_sq_db2 = malloc(sizeof(double) * (size_t)n_rp);
    ws.rp_miss_loglik = malloc(sizeof(double) * (size_t)n_rp);
    ws.acc = malloc(sizeof(double) * (size_t)n_rp);
    ws.n_common = calloc((size_t)n_rp, sizeof(int32_t));
    ws.touched = malloc(sizeof(int32_t) * (size_t)n_rp);
    p.fingerprint_preselect_aps = preselect ? p.fingerprint_preselect_aps : 0;
    ws.n_entries = n_entries;
    ws.n_ap = n_ap;
    ws.rp_entry_first = malloc(sizeof(int32_t) * (size_t)(n_rp + 1));
    ws.rp_entry_ap = malloc(sizeof(int32_t) * (size_t)n_entries);
    ws.rp_entry_level_db = malloc(sizeof(double) * (size_t)n_entries);
    ws.ap_query_w = malloc(sizeof(double) * (size_t)n_ap);
    ws.entry_level_db = malloc(sizeof(double) * (size_t)n_entries);
    const int rc = sf_fingerprint_prepare(&ws, &map, &p);
    if (rc != 0) {
        fprintf(stderr, "core_cost: sf_fingerprint_prepare: %d\n", rc);
        return 1;
    }
    static sf_fingerprint_t fp;
    sf_fingerprint_init(&fp);
    int64_t *sb = malloc(sizeof *sb * (size_t)n_ap);
    float *sr = malloc(sizeof *sr * (size_t)n_ap);
    long heard = 0, fixes = 0, preselected = 0, scored = 0;
    double err_sum_m = 0.0, match_s = 0.0;
    for (int32_t q = 0; q < n_scans; q++) {
        const double qx = 4.0 + (size_m - 8.0) * rng_uniform01(&r);
        const double qy = 4.0 + (size_m - 8.0) * rng_uniform01(&r);
        int32_t n = 0;
        for (int32_t a = 0; a < n_ap; a++) {
            const double lv = level_dbm(hypot(qx - ax[a], qy - ay[a])) + 4.0 * rng_gauss(&r);
            if (lv > heard_dbm) {
                sb[n] = bssid[a];
                sr[n] = (float)round(lv);
                n++;
            }
        }
        heard += n;
        /* scans 30 s apart: each fix stands alone (no averaging with the previous scan) */
        const sf_wifi_scan_t scan = {(int64_t)(q + 1) * 30000000LL, n, sb, sr};
        sf_fix_t fix;
        const double t0_s = now_s();
        const int ok = sf_fingerprint_match(&fp, &p, &map, &ws, &scan, 0, true, &fix) == 0;
        match_s += now_s() - t0_s;
        if (dump != NULL) {
            fprintf(dump, "q %.9g %.9g %d %.9g %.9g %d", qx, qy, ok, ok ? fix.x_m : 0.0, ok ? fix.y_m : 0.0, n);
            for (int32_t j = 0; j < n; j++) {
                fprintf(dump, " %d %.0f", (int)(sb[j] - bssid[0]), sr[j]);
            }
            fputc('\n', dump);
        }
        if (ok) {
            fixes++;
            preselected += fp.audit.preselected != 0;
            scored += fp.audit.n_candidates;
            err_sum_m += hypot(fix.x_m - qx, fix.y_m - qy);
        }
    }
    printf("{\"mode\": \"wifi\", \"n_rp\": %d, \"n_ap\": %d, \"n_entries\": %d, \"scans\": %d, \"mean_heard\": %.1f, "
           "\"fixes\": %ld, \"mean_error_m\": %.17g, \"size_m\": %.0f, \"preselect\": %s, \"preselected\": %ld, "
           "\"mean_scored\": %.1f, \"heard_dbm\": %.1f, \"match_s\": %.9g}\n",
           n_rp, n_ap, n_entries, n_scans, (double)heard / (double)n_scans, fixes, fixes ? err_sum_m / (double)fixes : -1.0,
           size_m, preselect ? "true" : "false", preselected, fixes ? (double)scored / (double)fixes : 0.0, heard_dbm, match_s);
    return 0;
}

static int run_sizes(void)
{
    printf("{\"mode\": \"sizes\", \"sf_estimator_t\": %zu, \"sf_fingerprint_t\": %zu, \"sf_fusion_t\": %zu, "
           "\"sf_controller_t\": %zu, \"sf_params_t\": %zu}\n",
           sizeof(sf_estimator_t), sizeof(sf_fingerprint_t), sizeof(sf_fusion_t), sizeof(sf_controller_t),
           sizeof(sf_params_t));
    return 0;
}

int main(const int argc, char **const argv)
{
    if (argc == 3 && strcmp(argv[1], "sensors") == 0) {
        const double s = atof(argv[2]);
        return s > 0.0 ? run_sensors(s, NULL) : usage();
    }
    if (argc == 3 && strcmp(argv[1], "yaw") == 0) {
        const double s = atof(argv[2]);
        return s > 0.0 ? run_sensors(s, stdout) : usage();
    }
    if ((argc == 4 || (argc == 5 && strcmp(argv[4], "full") == 0)) && strcmp(argv[1], "wifi") == 0) {
        const int n_rp = atoi(argv[2]), n_scans = atoi(argv[3]);
        return n_rp > 0 && n_scans > 0 ? run_wifi(n_rp, n_scans, argc == 4, WIFI_HEARD_DBM, NULL) : usage();
    }
    if (argc == 5 && strcmp(argv[1], "wifiheard") == 0) {
        const int n_rp = atoi(argv[2]), n_scans = atoi(argv[3]);
        const double heard_dbm = atof(argv[4]);
        return n_rp > 0 && n_scans > 0 && heard_dbm < -40.0 ? run_wifi(n_rp, n_scans, true, heard_dbm, NULL) : usage();
    }
    if ((argc == 5 || (argc == 6 && strcmp(argv[5], "full") == 0)) && strcmp(argv[1], "wifidump") == 0) {
        const int n_rp = atoi(argv[2]), n_scans = atoi(argv[3]);
        if (n_rp <= 0 || n_scans <= 0) {
            return usage();
        }
        FILE *const dump = fopen(argv[4], "w");
        if (dump == NULL) {
            fprintf(stderr, "core_cost: cannot write %s\n", argv[4]);
            return 1;
        }
        const int rc = run_wifi(n_rp, n_scans, argc == 5, WIFI_HEARD_DBM, dump);
        return fclose(dump) == 0 ? rc : 1;
    }
    if (argc == 3 && strcmp(argv[1], "samples") == 0) {
        const double s = atof(argv[2]);
        return s > 0.0 ? run_samples(s) : usage();
    }
    if (argc == 2 && strcmp(argv[1], "sizes") == 0) {
        return run_sizes();
    }
    return usage();
}
