/* site_match.c — the Wi-Fi matcher on a real site file, for the scikit-learn peer on a real floor
 * (the cost budget; lab/stridefix_lab/bench/perf_peers.py, measure_knn_peer_real).
 *
 *   site_match SITE QUERIES DUMP [full]
 *
 * SITE is a site file (stridefix radiomap build), loaded and checked by the board's sf_site_load and
 * given stridefixd's workspace (sf_workspace_alloc) and default parameters; with "full",
 * fingerprint.preselect_aps = 0 (every entry of every AP heard visited). QUERIES has one scan per line,
 * "q X_M Y_M N BSSID RSSI_DBM ..." (the scan's true position, then its readings). Each scan is matched
 * on its own (sf_fingerprint_match; scans 30 s apart, so none is averaged with the one before) and DUMP
 * gets the wifidump text of tests/perf/core_cost.c: "rp I X Y" per RP, "e RP AP LEVEL_DBM" per map
 * entry — the level the WkNN compares, fingerprint_fill_dbm + the prepared representation
 * (entry_level_db; censored entries left out) — and "q X Y OK FX FY N AP RSSI ..." per scan with the
 * readings the matcher uses (map APs, at least fingerprint_min_rssi_dbm) by AP index.
 *
 * Prints one JSON object (counts, match_s: the wall time inside sf_fingerprint_match); exit 0, 1 when
 * a file cannot be read or written, 2 on bad usage. The harness allocates freely (it is not the core). */
/* clock_gettime (POSIX) under -std=c11 */
#define _POSIX_C_SOURCE 199309L
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sf_error.h"
#include "sf_fingerprint.h"
#include "sf_params.h"
#include "sf_site.h"
#include "sf_workspace.h"

#define MAX_READINGS 1024

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The map's index of bssid (ascending BSSIDs), or −1. */
static int32_t ap_index(const sf_radiomap_t *const map, const int64_t bssid)
{
    int32_t lo = 0, hi = map->n_ap - 1;
    while (lo <= hi) {
        const int32_t mid = lo + (hi - lo) / 2;
        if (map->ap_bssid[mid] == bssid) {
            return mid;
        }
        if (map->ap_bssid[mid] < bssid) {
            lo = mid + 1;
        } else {
            hi = mid - 1;
        }
    }
    return -1;
}

static void dump_map(FILE *const dump, const sf_radiomap_t *const map, const sf_fingerprint_workspace_t *const ws,
                     const sf_params_t *const p)
{
    for (int32_t i = 0; i < map->n_rp; i++) {
        fprintf(dump, "rp %d %.9g %.9g\n", i, map->rp_x_m[i], map->rp_y_m[i]);
    }
    for (int32_t a = 0; a < map->n_ap; a++) {
        for (int32_t e = map->ap_first[a]; e < map->ap_first[a + 1]; e++) {
            if (ws->entry_level_db[e] >= 0.0) {
                fprintf(dump, "e %d %d %.9g\n", map->entry_rp[e], a, p->fingerprint_fill_dbm + ws->entry_level_db[e]);
            }
        }
    }
}

static int run(const char *const site_path, const char *const query_path, const char *const dump_path,
               const bool preselect)
{
    static sf_site_store_t store;
    static sf_site_t site;
    char err[512];
    if (sf_site_load(site_path, &store, &site, err, sizeof err) != SF_OK) {
        fprintf(stderr, "site_match: %s\n", err);
        return 1;
    }
    const sf_radiomap_t *const map = &site.radiomap;
    static sf_params_t p;
    sf_params_default(&p);
    p.fingerprint_preselect_aps = preselect ? p.fingerprint_preselect_aps : 0;
    sf_fingerprint_workspace_t ws = {0};
    void *ws_memory = NULL;
    if (map->n_rp < 1 || sf_workspace_alloc(map, &ws, &ws_memory) != SF_OK ||
        sf_fingerprint_prepare(&ws, map, &p) != SF_OK) {
        fprintf(stderr, "site_match: %s: no radio map, or its workspace cannot be prepared\n", site_path);
        return 1;
    }
    FILE *const in = fopen(query_path, "r");
    FILE *const dump = fopen(dump_path, "w");
    if (in == NULL || dump == NULL) {
        fprintf(stderr, "site_match: cannot read %s or write %s\n", query_path, dump_path);
        return 1;
    }
    dump_map(dump, map, &ws, &p);
    static sf_fingerprint_t fp;
    sf_fingerprint_init(&fp);
    static int64_t sb[MAX_READINGS];
    static float sr[MAX_READINGS];
    long scans = 0, fixes = 0, heard = 0, used = 0;
    double match_s = 0.0;
    double qx, qy;
    int n;
    int line = 0;
    while (fscanf(in, " q %lf %lf %d", &qx, &qy, &n) == 3) {
        line++;
        if (n < 0 || n > MAX_READINGS) {
            fprintf(stderr, "site_match: %s: scan %d: %d readings (0..%d)\n", query_path, line, n, MAX_READINGS);
            return 1;
        }
        for (int j = 0; j < n; j++) {
            long long b;
            if (fscanf(in, " %lld %f", &b, &sr[j]) != 2) {
                fprintf(stderr, "site_match: %s: scan %d: reading %d is not BSSID RSSI\n", query_path, line, j);
                return 1;
            }
            sb[j] = (int64_t)b;
        }
        heard += n;
        const sf_wifi_scan_t scan = {(int64_t)line * 30000000LL, n, sb, sr};
        sf_fix_t fix;
        const double t0_s = now_s();
        const int ok = sf_fingerprint_match(&fp, &p, map, &ws, &scan, 0, true, &fix) == 0;
        match_s += now_s() - t0_s;
        scans++;
        fixes += ok;
        int32_t n_used = 0;
        for (int j = 0; j < n; j++) {
            n_used += (double)sr[j] >= p.fingerprint_min_rssi_dbm && ap_index(map, sb[j]) >= 0;
        }
        used += n_used;
        fprintf(dump, "q %.9g %.9g %d %.9g %.9g %d", qx, qy, ok, ok ? fix.x_m : 0.0, ok ? fix.y_m : 0.0, n_used);
        for (int j = 0; j < n; j++) {
            const int32_t a = ap_index(map, sb[j]);
            if ((double)sr[j] >= p.fingerprint_min_rssi_dbm && a >= 0) {
                fprintf(dump, " %d %.9g", a, sr[j]);
            }
        }
        fputc('\n', dump);
    }
    if (!feof(in)) {
        fprintf(stderr, "site_match: %s: line after scan %d is not \"q X Y N ...\"\n", query_path, line);
        return 1;
    }
    fclose(in);
    const int closed = fclose(dump);
    printf("{\"mode\": \"site_match\", \"n_rp\": %d, \"n_ap\": %d, \"n_entries\": %d, \"scans\": %ld, "
           "\"fixes\": %ld, \"mean_heard\": %.1f, \"mean_used\": %.1f, \"preselect\": %s, \"match_s\": %.9g}\n",
           map->n_rp, map->n_ap, map->n_entries, scans, fixes, scans ? (double)heard / (double)scans : 0.0,
           scans ? (double)used / (double)scans : 0.0, preselect ? "true" : "false", match_s);
    sf_workspace_free(ws_memory);
    sf_site_store_free(&store);
    return closed == 0 ? 0 : 1;
}

int main(const int argc, char **const argv)
{
    if (argc == 4 || (argc == 5 && strcmp(argv[4], "full") == 0)) {
        return run(argv[1], argv[2], argv[3], argc == 4);
    }
    fprintf(stderr, "usage: site_match SITE QUERIES DUMP [full]\n");
    return 2;
}
