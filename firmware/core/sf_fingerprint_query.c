/* sf_fingerprint_query.c — the matcher's query (sf_fingerprint.h, "Query"): each scan filtered into the
 * ring (readings of map APs, in a pool shared by the ring's scans), and the per-AP mean over the last
 * scans (SmartLocator: the mean of 3 scans). */
#include <math.h>
#include <stddef.h>

#include "sf_assert.h"
#include "sf_fingerprint_internal.h"
#include "sf_sort.h"

/* Filters a scan into ap/rssi (map AP indices, at most SF_FINGERPRINT_SCAN_APS, the strongest); returns
 * how many were kept, *weak and *unknown the readings dropped as too weak and as not in the map. */
static int32_t filter_scan(sf_fingerprint_t *const fp, const sf_params_t *const p, const sf_radiomap_t *const map,
                           const sf_wifi_scan_t *const scan, uint16_t *const ap, float *const rssi,
                           int32_t *const weak, int32_t *const unknown)
{
    int32_t n = 0;
    /* an upper bound on the AP indices kept so far: a reading above it cannot repeat one, so the
     * usual scan (BSSIDs ascending, as receivers and importers list them) skips the O(n) search */
    int32_t ap_bound = -1;
    for (int32_t i = 0; i < scan->n_ap; i++) {
        const float v = scan->rssi_dbm[i];
        if (!isfinite(v)) {
            fp->readings_bad++;
            continue;
        }
        if ((double)v < p->fingerprint_min_rssi_dbm) {
            (*weak)++;
            continue;
        }
        const int32_t a = sf_radiomap_find_ap(map, scan->bssid[i]);
        if (a < 0) {
            (*unknown)++;
            continue;
        }
        int32_t j = a > ap_bound ? n : 0;
        while (j < n && ap[j] != (uint16_t)a) {
            j++;
        }
        ap_bound = a > ap_bound ? a : ap_bound;
        if (j < n) { /* repeated BSSID: keep the strongest */
            rssi[j] = v > rssi[j] ? v : rssi[j];
            continue;
        }
        if (n < SF_FINGERPRINT_SCAN_APS) {
            ap[n] = (uint16_t)a;
            rssi[n] = v;
            n++;
            continue;
        }
        fp->readings_truncated++; /* full: the weakest reading goes */
        int32_t w = 0;
        for (int32_t m = 1; m < n; m++) {
            if (rssi[m] < rssi[w]) {
                w = m;
            }
        }
        if (v > rssi[w]) {
            ap[w] = (uint16_t)a;
            rssi[w] = v;
        }
    }
    return n;
}

/* Stores a scan in the ring (its readings in the pool, the oldest scans giving way when it is full);
 * returns the number of weak readings dropped. */
int32_t sf_fp_store_scan(sf_fingerprint_t *const fp, const sf_params_t *const p, const sf_radiomap_t *const map,
                         const sf_wifi_scan_t *const scan)
{
    if (fp->map != map) { /* AP indices name the map's APs: another map, another meaning */
        fp->count = 0;
        fp->map = map;
    }
    if (fp->count > 0 && scan->t_us < fp->ring[fp->newest].t_us) {
        fp->count = 0;
        fp->backwards++;
    }
    uint16_t ap[SF_FINGERPRINT_SCAN_APS];
    float rssi[SF_FINGERPRINT_SCAN_APS];
    int32_t weak = 0, unknown = 0;
    const int32_t n = filter_scan(fp, p, map, scan, ap, rssi, &weak, &unknown);
    /* The slot after the newest (the oldest's, when the ring is full), and room in the pool. */
    const int32_t slot_i = fp->count == 0 ? 0 : (fp->newest + 1) % SF_FINGERPRINT_RING_SCANS;
    const int32_t start = fp->count == 0 ? 0
                                         : (fp->ring[fp->newest].first + fp->ring[fp->newest].n) %
                                               SF_FINGERPRINT_POOL_READINGS;
    fp->count -= fp->count == SF_FINGERPRINT_RING_SCANS;
    int32_t kept = 0;
    for (int32_t age = 0; age < fp->count; age++) {
        kept += fp->ring[(fp->newest - age + SF_FINGERPRINT_RING_SCANS) % SF_FINGERPRINT_RING_SCANS].n;
    }
    while (fp->count > 0 && kept + n > SF_FINGERPRINT_POOL_READINGS) {
        kept -= fp->ring[(fp->newest - fp->count + 1 + SF_FINGERPRINT_RING_SCANS) % SF_FINGERPRINT_RING_SCANS].n;
        fp->count--;
        fp->pool_evictions++;
    }
    sf_fingerprint_scan_slot_t *const slot = &fp->ring[slot_i];
    slot->t_us = scan->t_us;
    slot->first = (int16_t)start;
    slot->n = (int16_t)n;
    slot->n_unknown = (int16_t)(unknown < INT16_MAX ? unknown : INT16_MAX);
    for (int32_t j = 0; j < n; j++) {
        fp->pool_ap[(start + j) % SF_FINGERPRINT_POOL_READINGS] = ap[j];
        fp->pool_rssi_dbm[(start + j) % SF_FINGERPRINT_POOL_READINGS] = rssi[j];
    }
    fp->readings_weak += (uint32_t)weak;
    fp->readings_unknown += (uint32_t)unknown;
    fp->newest = slot_i;
    fp->count++;
    return weak;
}

typedef struct {
    int32_t ap;  /* map AP index */
    int32_t age; /* 0 = newest scan */
    float rssi_dbm;
} reading_t;
_Static_assert(sizeof(reading_t) * SF_FINGERPRINT_QUERY_APS <= 16 * 1024,
               "sf_fingerprint.h promises at most 16 KiB of stack");

static int reading_cmp(const void *const a, const void *const b)
{
    const reading_t *const x = a;
    const reading_t *const y = b;
    if (x->ap != y->ap) {
        return x->ap < y->ap ? -1 : 1;
    }
    return x->age < y->age ? -1 : (x->age > y->age ? 1 : 0);
}

/* Builds ws->query_* (map APs ascending, mean levels) from the last scans; fills the audit's counts. */
void sf_fp_build_query(sf_fingerprint_t *const fp, sf_fingerprint_workspace_t *const ws, const sf_params_t *const p)
{
    SF_ASSERT(fp->count > 0); /* store_scan has just run */
    reading_t readings[SF_FINGERPRINT_QUERY_APS]; /* 6 kB of stack */
    int32_t n = 0;
    int32_t n_scans = 0;
    int32_t want = p->fingerprint_average_scans;
    want = want < 1 ? 1 : (want > SF_FINGERPRINT_RING_SCANS ? SF_FINGERPRINT_RING_SCANS : want);
    if (want > fp->count) {
        want = fp->count;
    }
    const int64_t t_now = fp->ring[fp->newest].t_us;
    const int64_t max_age_us = (int64_t)p->fingerprint_average_max_age_ms * 1000;
    for (int32_t age = 0; age < want; age++) {
        const int32_t slot_i = (fp->newest - age + SF_FINGERPRINT_RING_SCANS) % SF_FINGERPRINT_RING_SCANS;
        const sf_fingerprint_scan_slot_t *const slot = &fp->ring[slot_i];
        if (age > 0 && t_now - slot->t_us > max_age_us) {
            break;
        }
        SF_ASSERT(slot->n >= 0 && n + slot->n <= SF_FINGERPRINT_QUERY_APS); /* the pool holds them all */
        for (int32_t j = 0; j < slot->n; j++) {
            const int32_t k = (slot->first + j) % SF_FINGERPRINT_POOL_READINGS;
            readings[n++] = (reading_t){fp->pool_ap[k], age, fp->pool_rssi_dbm[k]};
        }
        n_scans++;
    }
    /* One scan of ascending BSSIDs is in order already (its APs are distinct): the check is O(n), the
     * sort O(n log n) with a call per comparison. Keys are distinct (an AP once per scan), so either
     * way gives the same order. */
    bool sorted = true;
    for (int32_t i = 1; i < n && sorted; i++) {
        /* cppcheck-suppress uninitvar ; only the n readings written above are read */
        sorted = reading_cmp(&readings[i - 1], &readings[i]) < 0;
    }
    if (!sorted) {
        /* cppcheck-suppress uninitvar ; sf_sort reads only the n readings written above (none when n = 0) */
        sf_sort(readings, n, sizeof readings[0], reading_cmp);
    }
    ws->n_query = 0;
    fp->audit.n_scans_averaged = n_scans;
    fp->audit.n_unknown = fp->ring[fp->newest].n_unknown;
    for (int32_t i = 0; i < n;) {
        double sum = 0.0;
        int32_t j = i;
        while (j < n && readings[j].ap == readings[i].ap) {
            sum += (double)readings[j].rssi_dbm;
            j++;
        }
        ws->query_ap[ws->n_query] = readings[i].ap;
        ws->query_rssi_dbm[ws->n_query] = sum / (double)(j - i);
        ws->n_query++;
        i = j;
    }
    fp->audit.n_used = ws->n_query;
    fp->audit.n_heard = ws->n_query + fp->audit.n_unknown;
}
