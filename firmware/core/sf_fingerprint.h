/* sf_fingerprint.h — Wi-Fi fingerprint matching: a scan against the radio map (sf_radiomap.h) gives a
 * position fix (sf_fix_t, method sf_fix_wifi) with a 1σ accuracy, or no fix and a reason.
 *
 * Query. Each scan passed to sf_fingerprint_match goes into a ring of the last SF_FINGERPRINT_RING_SCANS
 * scans. On the way in, readings that are not finite (`bad`) or weaker than fingerprint_min_rssi_dbm
 * (`weak`, Ramadhan 2016: −90 dBm) are dropped, a BSSID repeated within one scan keeps its strongest
 * reading, and a scan with more than SF_FINGERPRINT_SCAN_APS readings keeps the strongest ones
 * (`truncated`). The query is the per-BSSID mean over the last fingerprint_average_scans scans that heard
 * it (SmartLocator: mean of 3 scans), among those no older than fingerprint_average_max_age_ms before the
 * current one; a scan earlier than the previous one empties the ring (`backwards`). Query BSSIDs not in
 * the map are ignored (audit.n_unknown); the rest are the APs used, s_a [dBm] for map AP a. Fewer than
 * fingerprint_min_aps of them: no fix, SF_ERANGE, audit.reason = sf_fp_too_few_aps.
 *
 * Candidates (cost follows the APs heard). Only the map entries of the used APs are visited: for each
 * used AP a, entries ap_first[a] … ap_first[a+1]−1 (audit.n_entries_visited counts them), accumulating
 * per-RP partial sums in the caller's workspace. Reference points (RPs) that heard none of the used APs
 * are not candidates. Unless any_floor, entries of RPs on floors other than floor_hint are skipped.
 * Below, R_r is the set of APs the map has at RP r (mean μ, std σ, detection rate q = count/rp_scans).
 *
 * Pre-selection (WkNN fill mode, when the workspace has its arrays and fingerprint_preselect_aps > 0;
 * sf_fingerprint_preselect.c). On a large map each heard AP reaches hundreds of RPs, so the full visit
 * costs E_Q ≈ |Q| × (RPs per AP). Instead, the partial distance over the S = preselect_aps strongest
 * used APs, LB_r = Σ_{a∈S} (g(s_a) − g(μ_ra))² ≤ d_r² (a lower bound: d² is a sum of such terms), ranks
 * the RPs they reach, and the preselect_rps of least LB are scored exactly from their own entries
 * (an RP-major copy), with the full visit's terms in its order, so a scored RP's d is bit-identical.
 * When the bound proves that no RP left out can rank (audit.preselected 1) the fix is the full
 * visit's; otherwise (2) it is the k best of those scored — an approximation: a winner of the full
 * visit whose strongest APs look unlike the scan's is missed, and the strong APs weigh more, which on
 * synthetic grids made the fixes slightly better, not worse (tests/c/test_fingerprint_preselect.c).
 * It runs only on a map of at least fingerprint_preselect_min_scans scans per RP (3: a surveyed map,
 * where an AP missing at an RP was not heard there; an AP heard 70 % of the time is missed by 1 scan
 * in 30 % and by 3 in 2.7 %), and only where it at least halves the entries visited (2 × (S's entries +
 * preselect_rps × n_entries/n_rp) ≤ E_Q). Not, therefore, on the walk-built maps of realbench (msindoor
 * 1.5, gsd 1.9 scans per RP), whose fixes are unchanged: forced there, the RPs the strongest APs reach
 * missed the full visit's winners often enough to cost 0.22 m of Wi-Fi-only mean error on site1/F2
 * (and gain 0.32 m on site2/F3). The estimator's position prior is not used:
 * a wrong prior would hold the fixes to it, the one failure a fix exists to correct.
 *
 * WkNN (fingerprint_method 0; Ramadhan 2016, Couceiro 2017). Distance in signal space [dB]:
 *   missing_mode 0 (fill, f = fingerprint_fill_dbm, −100): an AP missing on one side takes the level f,
 *     d_r² = Σ_{a∈Q∩R} (s_a − μ_ra)² + Σ_{a∈Q∖R} (s_a − f)² + Σ_{a∈R∖Q} (μ_ra − f)²
 *          = F_r + Σ_{a∈Q} (s_a − f)² − 2 Σ_{a∈Q∩R} (s_a − f)(μ_ra − f),
 *     F_r = Σ_{a∈R} (μ_ra − f)² is precomputed per RP by sf_fingerprint_prepare, so only Q∩R is visited.
 *   missing_mode 1 (common APs only): d_r = √(Σ_{a∈Q∩R} (s_a − μ_ra)² / n_r), n_r = |Q∩R|; an RP with
 *     n_r < fingerprint_min_common_aps is not a candidate.
 *   The k = fingerprint_k nearest win (ties: lower RP index), weights w = 1/max(d, SF_FINGERPRINT_D_MIN_DB)
 *   (the guard makes a perfect match dominate without dividing by zero).
 *
 * Gaussian naive Bayes (fingerprint_method 1; Jäger, Süß, Becker). Every map AP is modelled at every RP:
 * heard at level s with probability q'·N(s; μ, σ'), not heard with probability 1 − q', where
 * q' = clamp(q, p, 1 − p), p = fingerprint_nb_p_min, and σ' = max(σ, fingerprint_sigma_floor_db). An AP
 * the map lacks at r is a phantom entry q' = p, μ = fingerprint_fill_dbm, σ' = sigma_floor_db: so an AP
 * heard in the scan but unknown at the RP costs log p + log N(s; f, σ_floor) (the stronger it is heard, the
 * more), and an AP of the RP missing from the scan costs log(1 − q'), i.e. log p for an AP the RP always
 * heard (the detection-rate choice the brief left open; the fixed fill enters only through μ of phantoms).
 * The log-likelihood over all n_ap map APs,
 *     L_r = B_r + Σ_{a∈Q} C_a + Σ_{a∈Q∩R} [log q' + log N(s_a; μ, σ') − log(1 − q') − C_a],
 *     B_r = Σ_{a∈R} log(1 − q'_ra) + (n_ap − |R_r|)·log(1 − p)                      (prepared),
 *     C_a = log p + log N(s_a; f, σ_floor) − log(1 − p)                              (per scan AP),
 * is exact, not an approximation, and again only Q∩R is visited. Posterior P(r|s) = softmax of L over
 * the candidates (uniform prior); the k most probable win, weighted by their posterior (paper: k = 3).
 *
 * Representation. WkNN compares levels through g(v) = v − f (fingerprint_powed_beta 1: the formulas
 * above as written) or the "powed" g(v) = |f|·((v − f)/|f|)^β of Torres-Sospedra et al. (2015; they
 * found β = e best on their data sets): every s and μ above is replaced by g(s), g(μ) and f by g(f) = 0,
 * so F_r and the visited-entry sums keep their form. stridefix realbench chooses β per fold by
 * cross-validation in the training walks.
 * WkNN map levels. μ_ra above is entry_level: with fingerprint_map_level 1 (default) the mean over all
 * rp_scans of the RP with the misses at f, (count·mean + (rp_scans − count)·f) / rp_scans, i.e. the RP's
 * fingerprint in the same terms as the query; with 0 the stored mean of the scans that heard the AP.
 * Censoring: a scan never reports a level below fingerprint_min_rssi_dbm, so a map level below it is
 * treated as not heard (an entry at f) in both WkNN modes, in F_r as in the visited entries — otherwise
 * an RP pays (μ − f)² for an AP the scan could not have kept. On the real msindoor site1/F2 walks (1,511
 * scans, leave one walk out, 2 m cells) censoring and map_level 1 together took the per-scan WkNN error
 * from 8.2 to 5.8 m mean (the query's former 64-reading cap did the same harm as the missing censoring:
 * half of the scans there hear more than 64 APs above −90 dBm). Naive Bayes uses the stored entries.
 *
 * Fix. Floor = the floor with the largest summed weight among the k winners (tie: the best winner's
 * floor); x, y = the weighted mean of the winners on that floor; n_ap_used = APs used. Accuracy (1σ, m):
 *     accuracy_m = √(spread² + fingerprint_accuracy_floor_m²) · max(1, √(fingerprint_accuracy_ref_aps / n_used)),
 * spread = weighted RMS distance from the fix of the winners on its floor (WkNN, weights 1/d), or of all
 * candidates on its floor with their posterior (naive Bayes: the posterior's own spread, so a split
 * posterior reads as poor accuracy even when the k best agree). It feeds the fusion's α and gate.
 *
 * Memory. sizeof(sf_fingerprint_t) = 12 744 B on x86-64, at most 12.5 KiB (checked): the ring of
 * 4 × 255 readings and the audit; 16 320 B of stack (at most 16 KiB, checked in sf_fingerprint.c) while
 * the query is built. The last query (up to 1020 APs, 12 240 B) is scratch in the workspace.
 * Workspace: the query scratch (≈ 12.3 kB, fixed) and caller-owned arrays sized to the map:
 * SF_FINGERPRINT_WS_BYTES_PER_RP = 36 bytes per RP (two prepared double arrays, one double and two int32
 * scratch arrays, the RP-major index), SF_FINGERPRINT_WS_BYTES_PER_ENTRY = 20 per map entry (the
 * levels g, AP-major for the full visit and the bound, RP-major with their APs for exact scores) and _PER_AP = 8 per AP (the
 * query's weights); e.g. 10 000 RPs hearing 50 APs each → 10.4 MB, allocated by the board layer at
 * site load. The scratch is left as found (n_common and ap_query_w all zero) on every return.
 * Cost. sf_fingerprint_prepare: O(n_ap + n_rp + n_entries), once per map (and again after
 * fingerprint_fill_dbm, _nb_p_min, _min_rssi_dbm, _map_level or _powed_beta change). sf_fingerprint_match: O(n_scan·255) to store the
 * scan (O(n_scan) when its BSSIDs come ascending), O(m log m) (m ≤ 1020) to build the query (O(m) when
 * one ascending scan is averaged), O(|Q| log n_ap) lookups, then either the full visit,
 * O(E_Q) for the visited entries (E_Q = total entries of the used APs; one log and one division per
 * entry for naive Bayes) and O(T·k) to select among the T touched RPs, or the pre-selection,
 * O(E_S + T_S log C + C·e) (E_S: the S APs' entries, T_S ≤ E_S the RPs they reach, C = preselect_rps,
 * e: entries per RP) — independent of the map size.
 * Measured (`stridefix bench perf`, WkNN defaults, synthetic 2 m grids, one AP per 40 m²): full visit
 * (~70 instructions per visited entry) 78 k instructions per fix at 100 RPs, 1.48 M at 2 025 RPs (34
 * APs heard, 20 k entries visited), 2.2 M at 20 164 RPs; with the pre-selection 28 k, 136 k and 167 k.
 * The query is sorted by sf_sort (no qsort: it may allocate).
 * No heap, no I/O, no clock; deterministic (fixed summation order: APs by BSSID, entries by RP).
 *
 * Errors. sf_fingerprint_prepare: SF_EINVAL (NULL, empty map n_rp = 0 or n_ap = 0, workspace smaller than
 * the map), SF_ERANGE (sf_radiomap_check fails). sf_fingerprint_match: SF_EINVAL (NULL, empty map, bad
 * scan arrays, workspace not prepared for this map or these parameters; the scan is not stored),
 * SF_ERANGE (no fix: too few usable APs, or no candidate RP — audit.reason says which; the scan is
 * stored). Bad readings are not errors: they are counted and skipped. */
#ifndef SF_FINGERPRINT_H
#define SF_FINGERPRINT_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_params.h"
#include "sf_radiomap.h"
#include "sf_types.h"

#define SF_FINGERPRINT_RING_SCANS 4  /* scans kept for averaging: fingerprint_average_scans ≤ this */
#define SF_FINGERPRINT_SCAN_APS 255  /* readings kept per scan (the strongest); = the CAN scan's limit */
#define SF_FINGERPRINT_POOL_READINGS (2 * SF_FINGERPRINT_SCAN_APS) /* the ring's readings: two full scans */
#define SF_FINGERPRINT_QUERY_APS SF_FINGERPRINT_POOL_READINGS
#define SF_FINGERPRINT_MAX_MAP_APS 65535 /* a stored reading names its map AP in 16 bits */
#define SF_FINGERPRINT_K_MAX 16      /* fingerprint_k ≤ this */
#define SF_FINGERPRINT_D_MIN_DB 0.01 /* WkNN weight guard: w = 1/max(d, this) */
#define SF_FINGERPRINT_WS_BYTES_PER_RP (3 * sizeof(double) + 3 * sizeof(int32_t))
#define SF_FINGERPRINT_WS_BYTES_PER_ENTRY (2 * sizeof(double) + sizeof(int32_t))
#define SF_FINGERPRINT_WS_BYTES_PER_AP sizeof(double)
#define SF_FINGERPRINT_PRESELECT_APS_MAX 16  /* fingerprint_preselect_aps ≤ this */
#define SF_FINGERPRINT_PRESELECT_RPS_MAX 256 /* fingerprint_preselect_rps ≤ this */
_Static_assert(SF_FINGERPRINT_RING_SCANS >= 3, "SmartLocator averages 3 scans");
_Static_assert(SF_FINGERPRINT_QUERY_APS <= INT16_MAX, "n_ap_used and the slots' first and n are int16");
_Static_assert(SF_FINGERPRINT_K_MAX >= 3, "the papers use k = 3");
_Static_assert(SF_FINGERPRINT_WS_BYTES_PER_RP == 36, "the model above promises 36 bytes per RP");
_Static_assert(SF_FINGERPRINT_WS_BYTES_PER_ENTRY == 20, "the model above promises 20 bytes per map entry");

/* Why the last match gave no fix. */
enum { sf_fp_ok = 0, sf_fp_too_few_aps = 1, sf_fp_no_candidate = 2 };

/* Caller-owned memory sized to the map: set the pointers and n_rp, then call sf_fingerprint_prepare. */
typedef struct {
    int32_t n_rp;             /* capacity of each array, ≥ map->n_rp */
    double *rp_fill_sq_db2;   /* [n_rp] prepared: F_r (WkNN, fill mode) [dB²] */
    double *rp_miss_loglik;   /* [n_rp] prepared: B_r (naive Bayes) */
    double *acc;              /* [n_rp] scratch: per-RP partial sum */
    int32_t *n_common;        /* [n_rp] scratch: |Q∩R_r|; all 0 between calls */
    int32_t *touched;         /* [n_rp] scratch: RPs with n_common > 0, in order of first touch */
    /* the pre-selection's arrays (see Candidates above): all set, or all NULL for the full visit */
    int32_t n_entries;          /* capacity of the per-entry arrays, ≥ map->n_entries */
    int32_t n_ap;               /* capacity of ap_query_w, ≥ map->n_ap */
    int32_t *rp_entry_first;    /* [n_rp + 1] prepared: RP r's entries, RP-major, are first[r] … first[r+1]−1 */
    int32_t *rp_entry_ap;       /* [n_entries] prepared: the AP of each RP-major entry, ascending per RP */
    double *rp_entry_level_db;  /* [n_entries] prepared: g(μ) RP-major; 0 = censored */
    double *entry_level_db;     /* [n_entries] prepared, AP-major: g(μ) as the full visit uses it; −1 = censored */
    double *ap_query_w;         /* [n_ap] scratch: −2·g(s) of a used AP, 0 for the others */
    /* set by the caller: the map is never changed in place, so a workspace already prepared for it
     * (the same arrays, the same counts) with the same parameters is kept as it is (a process that
     * replays many walks on one site prepares it once) */
    bool reuse_prepared;
    /* set by sf_fingerprint_prepare */
    bool prepared;
    const float *map_entry_mean_dbm; /* the map's arrays it was prepared for (with the counts below) */
    int32_t map_n_ap, map_n_rp, map_n_entries; /* the map it was prepared for */
    double fill_dbm, nb_p_min, min_rssi_dbm;    /* the parameters it was prepared with */
    int32_t map_level;
    double powed_beta;
    double rp_scans_mean; /* the map's scans per RP (the pre-selection's gate) */
    /* scratch of sf_fingerprint_match, rebuilt by every call (so not the estimator's state): the last
     * query, its used APs (map indices ascending) and their mean levels */
    int32_t n_query;
    int32_t query_ap[SF_FINGERPRINT_QUERY_APS];
    double query_rssi_dbm[SF_FINGERPRINT_QUERY_APS];
} sf_fingerprint_workspace_t;

/* The record of the last match (published with the FIX message). */
typedef struct {
    int64_t t_us;
    int8_t method;              /* fingerprint_method used */
    int8_t missing_mode;        /* WkNN: fingerprint_missing_mode used */
    int8_t reason;              /* sf_fp_* */
    int32_t n_scans_averaged;   /* scans in the query (≥ 1) */
    int32_t n_readings_weak;    /* of the current scan: below min_rssi_dbm */
    int32_t n_heard;            /* distinct BSSIDs in the query */
    int32_t n_unknown;          /* of them, not in the map */
    int32_t n_used;             /* of them, in the map: |Q| */
    int32_t n_entries_visited;  /* map entries visited (Σ entries of the used APs) */
    int32_t n_touched;          /* RPs sharing at least one used AP (on the allowed floor) */
    int32_t n_candidates;       /* of them, eligible and scored (pre-selection: scored exactly) */
    int8_t preselected;         /* pre-selection: 0 not used, 1 proven exact, 2 best of the ranked (n_touched: RPs its APs reach) */
    int32_t k_used;             /* min(k, n_candidates) */
    int32_t winner_rp[SF_FINGERPRINT_K_MAX];    /* best first */
    double winner_score[SF_FINGERPRINT_K_MAX];  /* WkNN: d [dB]; naive Bayes: L [log-likelihood] */
    double winner_weight[SF_FINGERPRINT_K_MAX]; /* WkNN: 1/d; naive Bayes: posterior P(r|s) */
    double spread_m;            /* accuracy before the floor and the AP scaling */
} sf_fingerprint_audit_t;

/* One stored scan: its readings (filtered, deduplicated, map APs only, at most SF_FINGERPRINT_SCAN_APS)
 * are n consecutive readings of the pool from first on, wrapping. */
typedef struct {
    int64_t t_us;
    int16_t first;     /* pool index of its first reading */
    int16_t n;         /* readings kept */
    int16_t n_unknown; /* readings of APs not in the map (counted, not kept) */
} sf_fingerprint_scan_slot_t;

typedef struct {
    sf_fingerprint_scan_slot_t ring[SF_FINGERPRINT_RING_SCANS];
    uint16_t pool_ap[SF_FINGERPRINT_POOL_READINGS];     /* map AP index */
    float pool_rssi_dbm[SF_FINGERPRINT_POOL_READINGS];
    const sf_radiomap_t *map; /* the map the pool's AP indices name (another empties the ring) */
    int32_t newest; /* ring index of the newest scan */
    int32_t count;  /* scans in the ring */
    sf_fingerprint_audit_t audit;
    /* counters, never decrease */
    uint32_t scans, fixes, rejected_too_few_aps, rejected_no_candidate;
    uint32_t readings_bad, readings_weak, readings_truncated, readings_unknown, backwards;
    uint32_t pool_evictions; /* older scans dropped to make room in the pool */
} sf_fingerprint_t;
_Static_assert(sizeof(sf_fingerprint_t) <= 4 * 1024 + 512, "sf_fingerprint.h promises at most 4.5 KiB");

/* Empty ring, zero counters. */
void sf_fingerprint_init(sf_fingerprint_t *fp);

/* Checks the map (sf_radiomap_check), fills the workspace's prepared arrays for it and for
 * fingerprint_fill_dbm / fingerprint_nb_p_min, and zeroes the scratch. */
int sf_fingerprint_prepare(sf_fingerprint_workspace_t *ws, const sf_radiomap_t *map, const sf_params_t *p);

/* Stores the scan, builds the query and matches it. On SF_OK, *fix is the fix (t_us = scan->t_us);
 * otherwise *fix is untouched. Candidates are restricted to floor_hint unless any_floor. fp->audit
 * describes the match on SF_OK and SF_ERANGE. */
int sf_fingerprint_match(sf_fingerprint_t *fp, const sf_params_t *p, const sf_radiomap_t *map,
                         sf_fingerprint_workspace_t *ws, const sf_wifi_scan_t *scan, int16_t floor_hint,
                         bool any_floor, sf_fix_t *fix);

#endif
