/* sf_fusion.h — PDR + absolute-fix fusion: every scheme of pose_t.SCHEME_* (eight today), side by side
 * on the same inputs.
 *
 * Ownership. One sf_fusion_t is one scheme. The estimator owns an array
 *     sf_fusion_t fusion[sf_scheme_count];   sf_fusion_init(&fusion[s], (int8_t)s) for each s,
 * and feeds every scheme the same steps and fixes, so one log compares all of them (DESIGN.md,
 * evaluation protocol). A scheme never looks at another; there is no shared state.
 * Scheme ids and names come from pose_t.SCHEME_* (generated sf_schemes.h); what each scheme does is
 * one row of the registry in sf_fusion.c (mode: dead reckoning, follow the fixes, or blend with a gain
 * law), so adding a scheme is the pose_t.lcm constant plus one row (and its law, if new).
 *
 * Frame and units: map frame x, y [m], floors as int16 indices, times int64 µs carried by the inputs
 * (no clock). Position uncertainty is isotropic: `var_m2` is the variance of each axis [m²], the fix's
 * accuracy_m is its per-axis 1σ, R = accuracy_m², and the pose's sigma_m = √var_m2.
 *
 * Process model (prediction), the same for every scheme that has one, so the gate is identical across
 * schemes and only α differs: each step moves the position by the caller's (dx_m, dy_m) and adds
 *     var += fusion_q_step_m2_per_m · length_m + fusion_q_time_m2_per_s · Δt
 * (a random walk per metre walked, plus per second for missed steps); the time term is also added up
 * to each fix's time. wifi_only has no prediction (it ignores steps).
 *
 * Fusion (the math). Innovation ν = fix − predicted position (2-D), S = var + R, test ratio
 * τ = |ν|² / (gate² · S) with gate = fusion_gate_sigma; |ν|²/S is χ² with 2 dof, so gate 3 passes
 * 98.9 % of consistent fixes. An accepted fix blends
 *     position ← position + α·ν   (= α·fix + (1−α)·pdr)
 * with α per scheme:
 *   pdr_only   never blends after initialisation (reason SCHEME_IGNORES; ν, S, τ still recorded, so
 *              the log shows the PDR drift against each fix).
 *   wifi_only  position = the latest fix, var = R: every fix accepted, no gate (τ recorded against the
 *              previous fix, S = var + R, for information only).
 *   overwrite  α = 1 (traditional dead reckoning).
 *   static     α = fusion_static_alpha (0.5: Jäger et al.'s baseline); a landmark α = 1.
 *   adaptive   α = clamp(accuracy(fix) + drift(Δt), 0, 1) (Jäger, Süß, Becker eq. 9, with the printed
 *              max(…, 1) read as min), Δt = time since this scheme's last accepted fix [s]:
 *                accuracy: Wi-Fi  piecewise-linear in n_ap_used over the knots
 *                                 (fusion_acc_wifi_ap1..4, fusion_acc_wifi_val1..4), flat outside;
 *                          GNSS   piecewise-linear in accuracy_m over (fusion_acc_gnss_m1..4,
 *                                 fusion_acc_gnss_val1..4), falling, flat outside;
 *                          BLE    the same law in its accuracy_m (the paper has no BLE figure);
 *                          landmark fusion_acc_landmark (1: overwrite, as NFC in the paper);
 *                drift = min(fusion_drift_per_s · Δt, fusion_drift_max).
 *              The paper prints no numbers; the defaults are placeholders to tune in SIL (sf_params.h).
 *              Knots must increase; if not, the value jumps at the first knot reached (no division by 0).
 *   kalman     (ours) α = var / (var + R), the Kalman gain of the random-walk model above.
 *   ekf        (ours) the error-state Kalman filter of sf_ekf.h: state position, heading bias, stride
 *              scale and the fixes' correlated error, a full 6×6 covariance propagated per step, R a full
 *              2×2 from the site's fix-error model, ν = fix − position − correlated error, the gate on
 *              the NIS (test ratio NIS / gate², χ² 2 dof like the others), α recorded = the mean
 *              position gain; its initialisation and recovery restart the position from the fix (bias
 *              and scale keep what they learnt); its pose carries the covariance, the bias (added to the
 *              heading) and the scale. Floors and control as for the blends.
 *   particle   (ours) the map-aware particle filter of sf_particle.h over a cloud in caller memory
 *              (sf_fusion_set_cloud; without one the scheme has no position and every fix is recorded
 *              NOT_INITIALISED): steps move every particle with its own stride scale, heading bias and
 *              noise, walls kill particles, floors change only at ports; a fix is a likelihood (its
 *              Gaussian with σ = accuracy_m mixed with particle.outlier_share of uniform). Control
 *              (sf_fusion_particle.c): the first fix seeds the cloud (σ = accuracy; INITIALISED);
 *              between floors FLOOR_MISMATCH as below; ν against the cloud's weighted mean, S = the
 *              cloud's covariance + R (mean of the diagonal recorded), τ = νᵀS⁻¹ν / gate²; the fix is
 *              accepted when the cloud's evidence E = Σ w·exp(−d²/2σ²) ≥ exp(−gate²/2) (as much as a
 *              single particle at the gate's distance), α = the weights' change (total variation);
 *              otherwise rejected GATE; RECOVERY (re-seed around the fix, α = 1) after
 *              fusion_max_rejections consecutive rejections, at once for a landmark (a known
 *              position), or when the update leaves ESS < particle.reseed_ess_ratio · N. Its pose is
 *              the weighted mean and covariance, the weight's majority floor, the mean bias (added to
 *              the heading) and scale, and the effective sample size (pose.ess; 0 for every other scheme).
 * Variance after an accepted fix: kalman var ← (1 − α)·var; the fixed-gain schemes take the Joseph form
 * var ← (1 − α)²·var + α²·R (the true variance of a blend with an arbitrary gain; equal to the Kalman
 * form when α is the Kalman gain). Every variance is floored at fusion_var_min_m2.
 *
 * Sources (fix.method, the FIX record's source). Wi-Fi, GNSS, BLE and landmark fixes go through the
 * same control with their own R = accuracy_m² (the ekf: a Wi-Fi fix's R from the site's fix model and
 * the correlated error c in its innovation; the other sources white, without c). The paper's
 * baselines, wifi_only and pdr_only (which starts at its first fix), ignore every other source
 * (SCHEME_IGNORES): their rows stay the Wi-Fi-only comparisons they were. A landmark (the paper's NFC tag)
 * is where the walker is: every scheme that fuses accepts it whatever the gate says (and between
 * floors), the fixed-gain blends with α = 1, adaptive by its law (fusion_acc_landmark, default 1),
 * kalman and ekf by their gain with its tiny R. The multi-scheme controller's staircase-endpoint
 * recalibration (METHOD_PORT, sf_controller.h) is a known position too and is taken the same way
 * (sf_fix_is_known_position, sf_types.h).
 *
 * Control (when to fuse), for the blending schemes overwrite/static/adaptive/kalman, in this order:
 *   start        uninitialised: the first fix initialises (α = 1, var = R; reason INITIALISED), or
 *                sf_fusion_init_at() initialises from a known pose (truth-initialised runs; the caller
 *                decides). Before that the pose is not valid.
 *   floor        the caller is between floors (sf_fusion_fix_on_floor: stairs, a moving lift) →
 *                rejected, FLOOR_MISMATCH: a radio map is of floors, and a scan from a stairwell
 *                matches none of them (SIL tour: fixes 8–10 m off on the flights, inside the gate).
 *                Not a sign of divergence: it does not count toward recovery.
 *   gate         τ > 1 → rejected, GATE.
 *   continue     otherwise accepted (reason ACCEPTED) with the scheme's α.
 *   recovery     a fix that would be rejected while `rejections` ≥ fusion_max_rejections (consecutive
 *                rejections before it) is accepted with α = 1, var = R (RECOVERY):
 *                SmartLocator's confidence counter, so a diverged scheme comes back. Any accepted fix
 *                clears the count. fusion_max_rejections = 0 means never reject.
 * Floors. Every scheme that predicts is on the caller's floor (`baro_floor`, passed on every fix and
 * pose read; the estimator's barometric floor, renumbered by its start-floor vote, sf_floor_vote.h),
 * read through one function, so a new scheme gets it for free; wifi_only takes the floor of the latest
 * fix (it is the fixes). A fix's floor is not a condition of the judgement: it has voted on the
 * caller's floor already, and its position passes the gate or not like any other. On the gsd trials,
 * whose leave-one-out maps may have no reference point of the right floor within 40 m, all 105 fixes
 * of Trial51 say floor −2 (right on 31) and 50 of Trial21's 52 say −1 (truth −2), while their
 * positions are as good as elsewhere; judging them on the floor as well (as before floors were the caller's) gave
 * kalman 5.25 m mean from the true start over the four trials, against 4.66 m on the gate alone.
 * FLOOR_MISMATCH now means "between floors" (see Control).
 *
 * Audit. Every fix offered to every scheme fills one sf_fix_audit_t, which is the LCM FIX message
 * (lcmtypes/stridefix/fix_t.lcm): the fix, ν, S, τ, α applied (0 when rejected), accepted, reason
 * (sf_fix_reason_*, identical to fix_t.REASON_*), scheme; plus the adaptive terms for analysis. For an
 * initialising fix ν = 0, S = R, τ = 0. TOO_FEW_APS and NO_MAP are the fingerprint matcher's reasons
 * (no position exists), INACCURATE the estimator's for a source whose own accuracy or position is
 * unusable (a GNSS fix beyond gnss_max_accuracy_m): the caller writes those records itself
 * (sf_fusion_audit_refused helps);
 * NOT_INITIALISED is not produced here (a fix always initialises).
 *
 * Bad data (not an error of the caller, counted in the scheme's counters and skipped): a step with a
 * non-finite or negative length or non-finite displacement (`bad_steps`); a fix with a non-finite
 * position, a non-finite or negative accuracy, or an unknown method (`bad_fixes`: state unchanged,
 * audit rejected with reason GATE and τ = +∞, and sf_fusion_fix returns SF_ERANGE so the caller can
 * count it in HEALTH; it does not count toward recovery); an input time before the scheme's latest
 * (`backwards`: Δt taken as 0).
 *
 * Errors: sf_fusion_init returns SF_OK or SF_EINVAL (NULL, scheme outside [0, sf_scheme_count));
 * sf_fusion_init_at SF_OK or SF_EINVAL (non-finite x, y or sigma, negative sigma; state unchanged);
 * sf_fusion_fix SF_OK or SF_ERANGE (bad fix, see above). Everything else cannot fail.
 * Cost: O(1), a few tens of flops and one sqrt per call (the ekf a few hundred, sf_ekf.h; the particle
 * scheme O(N) per call, sf_particle.h). Memory:
 * sizeof(sf_fusion_t) = 528 B per scheme on x86-64 (the sf_ekf_t in every scheme, 408 B, keeps the array
 * uniform; the particle cloud lives outside, one pointer), sf_fix_audit_t 120 B; at most 528 B and 160 B
 * (checked). No heap, no I/O, no
 * clock, no hidden state: the same inputs give bit-identical outputs. */
#ifndef SF_FUSION_H
#define SF_FUSION_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_ekf.h"
#include "sf_params.h"
#include "sf_particle.h"
#include "sf_types.h"

/* Reasons, identical to fix_t.REASON_* in lcmtypes/stridefix/fix_t.lcm. */
enum {
    sf_fix_reason_accepted = 0,
    sf_fix_reason_gate = 1,
    sf_fix_reason_too_few_aps = 2,
    sf_fix_reason_no_map = 3,
    sf_fix_reason_floor_mismatch = 4,
    sf_fix_reason_not_initialised = 5,
    sf_fix_reason_initialised = 6,
    sf_fix_reason_recovery = 7,
    sf_fix_reason_scheme_ignores = 8,
    sf_fix_reason_inaccurate = 9,
    sf_fix_reason_context_off = 10, /* the multi-scheme controller keeps this source off here (sf_controller.h) */
    sf_fix_reason_count = 11
};

/* sf_fusion_init_at's time for a start before any input (the config pose): the scheme's clock starts
 * at its first input, so the time before it (a log's epoch time, say) adds no variance. */
#define SF_FUSION_T_FIRST_INPUT INT64_MIN

/* sf_fusion_step_on_floor's floor when the caller has none: the particle scheme's floors stay. */
#define SF_FUSION_FLOOR_KEEP INT16_MIN

/* σ reported by sf_fusion_pose for a scheme that has no position yet [m]. */
#define SF_FUSION_SIGMA_UNKNOWN_M 1.0e6

/* The audit record of one fix judged by one scheme: the FIX message. */
typedef struct {
    /* the fix as offered */
    int64_t t_us;
    int8_t method;
    double x_m;
    double y_m;
    int16_t floor;
    double accuracy_m;
    int16_t n_ap_used;
    /* the judgement */
    int8_t scheme;
    double innovation_m[2];   /* fix − predicted position [m] */
    double innovation_var_m2; /* S = var + R [m²] */
    double test_ratio;        /* |ν|² / (gate² · S); ≤ 1 passes */
    double alpha;             /* blend weight applied; 0 when not applied */
    bool accepted;
    int8_t reason;            /* sf_fix_reason_* */
    /* adaptive scheme's terms (0 for the others), for analysis */
    double accuracy_factor;
    double drift;
} sf_fix_audit_t;
_Static_assert(sizeof(sf_fix_audit_t) <= 160, "sf_fusion.h promises at most 160 B");

typedef struct {
    int8_t scheme; /* sf_scheme_* */
    bool initialised;
    double x_m;
    double y_m;
    double var_m2;          /* per-axis position variance [m²] */
    int32_t floor_offset;   /* floor = baro_floor + floor_offset (wifi_only: the fix's floor) */
    int64_t t_us;           /* latest input time seen (prediction is up to here) */
    int64_t last_fix_t_us;  /* time of the last accepted fix or initialisation (adaptive drift) */
    int32_t rejections;     /* consecutive rejected fixes (control: recovery) */
    /* counters, never decrease */
    uint32_t steps, bad_steps, fixes, accepted, rejected_gate, rejected_floor, recoveries,
        initialisations, bad_fixes, backwards;
    const sf_fix_model_t *fix_model; /* the site's measured fix model (ekf), caller-owned; NULL: params */
    sf_particle_t *cloud; /* the particle scheme's cloud, caller-owned (sf_fusion_set_cloud); NULL otherwise */
    sf_ekf_t ekf; /* the ekf scheme's filter (bias, scale, fix error, 6×6 covariance, fix model); unused by
                   * the others */
} sf_fusion_t;
_Static_assert(sizeof(sf_fusion_t) <= 528, "sf_fusion.h promises at most 528 B per scheme");

/* An uninitialised scheme. SF_OK, or SF_EINVAL for NULL or an unknown scheme. */
int sf_fusion_init(sf_fusion_t *f, int8_t scheme);

/* Initialises (or re-initialises) at a known pose: position (x_m, y_m), per-axis σ [m] at t_us; floor
 * is wifi_only's (the others are on the caller's floor, baro_floor: see Floors). For truth-initialised
 * runs (the `init` params).
 * SF_OK, or SF_EINVAL (state unchanged) for a non-finite value or a negative sigma. */
int sf_fusion_init_at(sf_fusion_t *f, const sf_params_t *p, int64_t t_us, double x_m, double y_m, int16_t floor,
                      double sigma_m, int16_t baro_floor);

/* One accepted PDR step at t_us: displacement (dx_m, dy_m) in the map frame, its length [m]. Moves
 * every initialised scheme except wifi_only. */
void sf_fusion_step(sf_fusion_t *f, const sf_params_t *p, int64_t t_us, double dx_m, double dy_m, double length_m);

/* The same while the barometer says baro_floor (the particle scheme's floors; SF_FUSION_FLOOR_KEEP:
 * none known). sf_fusion_step is this with SF_FUSION_FLOOR_KEEP. */
void sf_fusion_step_on_floor(sf_fusion_t *f, const sf_params_t *p, int64_t t_us, double dx_m, double dy_m,
                             double length_m, int16_t baro_floor);

/* One absolute fix, judged by this scheme while the barometer says baro_floor; fills *audit (always).
 * SF_OK, or SF_ERANGE for a bad fix (see the header's "Bad data"). */
int sf_fusion_fix(sf_fusion_t *f, const sf_params_t *p, const sf_fix_t *fix, int16_t baro_floor,
                  sf_fix_audit_t *audit);

/* The same, while the caller is or is not between floors (the floor condition of Control). */
int sf_fusion_fix_on_floor(sf_fusion_t *f, const sf_params_t *p, const sf_fix_t *fix, int16_t baro_floor,
                           bool between_floors, sf_fix_audit_t *audit);

/* Overlays the scheme's x_m, y_m, floor, sigma_m (including the time term up to t_us) and scheme on
 * *pose; t_us, heading and step_count are left as the caller set them. Returns whether the scheme is
 * initialised; if not, x = y = 0, floor = baro_floor and sigma = SF_FUSION_SIGMA_UNKNOWN_M. */
bool sf_fusion_pose(const sf_fusion_t *f, const sf_params_t *p, int64_t t_us, int16_t baro_floor, sf_pose_t *pose);

/* The adaptive law, exposed for tests and the analyzer. accuracy factor of a fix by its method (0 for
 * an unknown method), drift after dt_s seconds (0 for dt_s ≤ 0), and α = clamp(sum, 0, 1). */
double sf_fusion_accuracy_factor(const sf_params_t *p, const sf_fix_t *fix);
double sf_fusion_drift(const sf_params_t *p, double dt_s);
double sf_fusion_adaptive_alpha(const sf_params_t *p, const sf_fix_t *fix, double dt_s);

/* The site's measured fix-error model for the ekf scheme (caller-owned, must outlive f; NULL or not
 * valid: the ekf.fix_* parameters). A scheme already started at a known pose takes it at once; every
 * later (re)start too. No effect on the other schemes. */
void sf_fusion_set_fix_model(sf_fusion_t *f, const sf_params_t *p, const sf_fix_model_t *model);

/* The particle scheme's cloud (initialised by sf_particle_init, caller-owned, must outlive f; NULL: none).
 * A scheme already started at a known pose seeds the cloud there at once. No effect on other schemes. */
void sf_fusion_set_cloud(sf_fusion_t *f, const sf_params_t *p, sf_particle_t *cloud);

/* A record for a scan the matcher refused before any position existed (reason TOO_FEW_APS or
 * NO_MAP, or any reason the caller decides): the fix fields from *fix, ν = 0, S = 0, τ = 0, α = 0,
 * rejected. Does not touch the scheme. */
void sf_fusion_audit_refused(const sf_fusion_t *f, const sf_fix_t *fix, int8_t reason, sf_fix_audit_t *audit);

/* Short English text for a reason (fix_t.reason_text); never NULL. */
const char *sf_fix_reason_text(int reason);

/* The scheme registry (one row per pose_t.SCHEME_*, ids and names from sf_schemes.h): the lower-case
 * name of a scheme ("pdr_only", ...; NULL outside [0, sf_scheme_count)); the id of a name, or
 * SF_EINVAL; and whether a scheme has a complete row (for tests: a scheme without one cannot run). */
const char *sf_fusion_scheme_name(int scheme);
int sf_fusion_scheme_from_name(const char *name);
bool sf_fusion_scheme_is_registered(int scheme);

#endif
