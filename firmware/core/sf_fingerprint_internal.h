/* sf_fingerprint_internal.h — what sf_fingerprint.c, its query (sf_fingerprint_query.c) and its
 * pre-selection (sf_fingerprint_preselect.c) share. Not part of the core's API. The query and the
 * pre-selection are leaves: sf_fingerprint.c calls them, they call nothing of sf_fingerprint.c. */
#ifndef SF_FINGERPRINT_INTERNAL_H
#define SF_FINGERPRINT_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_assert.h"
#include "sf_fingerprint.h"

typedef struct {
    double key; /* lower is better: WkNN d, naive Bayes −L */
    int32_t rp;
} sf_fp_ranked_t;

/* Stores the scan in fp's ring (sf_fingerprint_query.c); returns the number of weak readings dropped. */
int32_t sf_fp_store_scan(sf_fingerprint_t *fp, const sf_params_t *p, const sf_radiomap_t *map,
                         const sf_wifi_scan_t *scan);

/* Builds ws->query_* (map APs ascending, mean levels) from the last scans; fills the audit's counts. */
void sf_fp_build_query(sf_fingerprint_t *fp, sf_fingerprint_workspace_t *ws, const sf_params_t *p);

/* Inserts (key, rp) into best[0 .. *n_best), kept sorted by key then RP index, at most k long: the k-best
 * list that both the full visit (sf_fingerprint.c) and the pre-selection fill, kept here so that
 * neither calls into the other's file. O(k). */
static inline void sf_fp_insert_best(sf_fp_ranked_t *const best, int32_t *const n_best, const int32_t k,
                                     const double key, const int32_t rp)
{
    SF_ASSERT(k >= 1 && k <= SF_FINGERPRINT_K_MAX && *n_best >= 0 && *n_best <= k);
    int32_t pos = *n_best;
    while (pos > 0 && (key < best[pos - 1].key || (key == best[pos - 1].key && rp < best[pos - 1].rp))) {
        pos--;
    }
    if (pos >= k) {
        return;
    }
    const int32_t last = *n_best < k ? *n_best : k - 1;
    for (int32_t i = last; i > pos; i--) {
        best[i] = best[i - 1];
    }
    best[pos] = (sf_fp_ranked_t){key, rp};
    if (*n_best < k) {
        (*n_best)++;
    }
}

/* The pre-selection's RP-major copy of the prepared levels (sf_fingerprint_preselect.c): ws->entry_level_db
 * (AP-major, −1 censored) counting-sorted by RP, the APs ascending within an RP as the AP-major visit
 * meets them, censored entries 0. ws->touched is its scratch and is left zero. O(n_rp + n_entries). */
void sf_fp_preselect_prepare(sf_fingerprint_workspace_t *ws, const sf_radiomap_t *map);

/* WkNN fill mode with the pre-selection's arrays and fingerprint_preselect_aps > 0: the k best of the
 * pre-selected candidates (sf_fingerprint_preselect.c). ws->ap_query_w holds the query; scan_sum =
 * Σ g(s)². True when there were at least k: best[0 .. *n_best) and the audit's n_touched,
 * n_candidates and preselected are set. False: *n_best = 0 (the caller visits every entry). The
 * scratch is left as found either way. */
bool sf_fp_preselect(const sf_radiomap_t *map, sf_fingerprint_workspace_t *ws, const sf_params_t *p, int16_t floor_hint,
                     bool any_floor, double scan_sum, int32_t k, sf_fp_ranked_t *best, int32_t *n_best,
                     sf_fingerprint_audit_t *au);

#endif
