/* sf_source_quality.h — how good each auxiliary fix source (GNSS, BLE) is on this walk, learnt online
 * against the Wi-Fi fixes, so a source that claims more than it delivers is trusted by what it delivers.
 *
 * Why. A phone's GNSS accuracy in a basement (ipin2023 Trial26: 8 m claimed, 27 m delivered) or a BLE
 * proximity fix among beacons heard across floors (9–15 m delivered, 4–6 m claimed) arrives at 1 Hz,
 * four times as often as the Wi-Fi scans, with errors that persist for many seconds: fused at its
 * claim it outweighs the radio map and the schemes gate the good Wi-Fi fixes out. The radio map's
 * fixes are the reference: the site measured them (sf_radiomap.h fix model), the others only report.
 *
 * Model. Reference r(t) = the latest Wi-Fi fix z_w the kalman scheme accepted (the caller's choice:
 * one it gated is off the walk, as outdoors beyond the radio map) + the PDR displacement since it, valid for
 * quality_ref_max_age_s after that fix, per axis variance σ_w² (its accuracy²) + fusion_q_step_m2_per_m
 * × the distance walked since (the schemes' own PDR noise). For a fix z_s of source s with claimed
 * accuracy σ_s, d = z_s − r and, were both claims true, E[|d|²]/2 = σ_s² + σ_w² + σ_dr². Per source
 * two running means over its last quality_memory_fixes comparisons (the mean of all until then):
 *   e_s = mean(|d|²/2 − σ_w² − σ_dr²)   (the variance the source delivers, per axis)
 *   c_s = mean(σ_s²)                     (the variance it claims)
 * Persistence: a source's errors outlast its fix interval (GNSS multipath, a beacon heard across the
 * slab: the same tens of metres for a minute), and the schemes fuse each fix as independent. With the
 * lag-one correlation of consecutive residuals ρ_s = mean(d_k·d_{k−1}) / mean(|d|²), clamped to
 * [0, quality_max_rho] (consecutive: at most quality_ref_max_age_s apart, and judged against two
 * different Wi-Fi fixes, since a pair judged against one shares its error), n fixes carry the
 * information of n(1 − ρ)/(1 + ρ) independent ones (AR(1) errors), so the variance of each is
 * inflated by (1 + ρ)/(1 − ρ). The factor is
 *   k_s = clamp(√(max(e_s / c_s, 1) · (1 + ρ_s)/(1 − ρ_s)), 1, quality_max_factor)
 * once quality_min_fixes comparisons are in (1 before): the fix is offered with accuracy k_s·σ_s. A
 * source is never trusted more than it claims (k ≥ 1), and a walk with no Wi-Fi reference leaves
 * every factor at 1. A fix without a fresh reference (outdoors, beyond the radio map) moves the means
 * by the same weight toward a source as good as it claims (e_s → σ_s², the lag term → 0): where the
 * source is all there is, what was learnt among the buildings fades over quality_memory_fixes fixes. Wi-Fi itself is not judged here (it is the reference; the schemes' gates and the
 * ekf's correlated-error state judge it).
 *
 * Cost: O(1) per fix (a sqrt). Memory: sizeof(sf_source_quality_t) = 208 B on x86-64 (at most 256 B,
 * checked). No heap, no I/O, no clock. Functions cannot fail; NULL arguments break the contract
 * (SF_ASSERT). */
#ifndef SF_SOURCE_QUALITY_H
#define SF_SOURCE_QUALITY_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_params.h"
#include "sf_types.h"

/* One judged source's running means. */
typedef struct {
    double excess_m2;  /* e_s */
    double claimed_m2; /* c_s */
    double square_m2;  /* mean |d|² */
    double lag_m2;     /* mean d_k·d_{k−1} of consecutive comparisons */
    double prev_dx_m, prev_dy_m;
    int64_t prev_t_us; /* INT64_MIN: none */
    int64_t prev_ref_t_us; /* the reference it was judged against */
    uint32_t n;        /* comparisons so far (counter, never decreases) */
    uint32_t n_lag;    /* consecutive pairs so far */
} sf_source_stats_t;

typedef struct {
    bool has_ref;
    int64_t ref_t_us;
    double ref_x_m, ref_y_m, ref_var_m2;       /* the latest Wi-Fi fix */
    double ref_pdr_x_m, ref_pdr_y_m, ref_walked_m; /* the PDR track and distance walked at it */
    sf_source_stats_t gnss, ble;
} sf_source_quality_t;
_Static_assert(sizeof(sf_source_quality_t) <= 256, "sf_source_quality.h promises at most 256 B");

void sf_source_quality_init(sf_source_quality_t *q);

/* A Wi-Fi fix (the reference) with the PDR track (x, y) and the distance walked at its time. */
void sf_source_quality_reference(sf_source_quality_t *q, const sf_fix_t *fix, double pdr_x_m, double pdr_y_m,
                                 double walked_m);

/* A GNSS or BLE fix as the source reported it (other methods: nothing): compared with the reference
 * when one is fresh. Returns the source's factor k_s now (after this comparison). */
double sf_source_quality_judge(sf_source_quality_t *q, const sf_params_t *p, const sf_fix_t *fix, double pdr_x_m,
                               double pdr_y_m, double walked_m);

/* k_s of a source (1 for Wi-Fi, landmarks and ports, and before quality_min_fixes comparisons). */
double sf_source_quality_factor(const sf_source_quality_t *q, const sf_params_t *p, int8_t method);

#endif
