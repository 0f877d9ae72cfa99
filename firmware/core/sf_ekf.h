/* sf_ekf.h — the `ekf` scheme's math: an error-state Kalman filter over steps, after Mirzababaei &
 * Akbari's closed-loop error-state KF (papers/mirzababaei-akbari-slam-gps-ins-wlpf.md, eqs. 53–59),
 * with the INS replaced by PDR steps and the fixes' correlated error as a state of its own. The control
 * around it (start, floor, gate, recovery, audit) is sf_fusion's, shared with every other scheme; this
 * module is only the filter.
 *
 * Nominal state: position p = (x, y) [m] (kept in sf_fusion_t), heading bias b [rad] added to the
 * walking direction, stride scale s multiplying the step length, and c = (c_x, c_y) [m], the slowly
 * varying part of the fixes' error. Error state δ = [δx, δy, δb, δs, δc_x, δc_y], covariance P (6×6).
 * The floor is a discrete state, handled by sf_fusion like every scheme's.
 *
 * Why c. Consecutive Wi-Fi fixes err alike: scans a few metres apart match the same wrong reference
 * points, and a standing walker gets the same wrong fix again and again. A filter that takes the fixes
 * as independent averages them and becomes sure of a wrong place (on real walks from the true start,
 * every scheme that did so ended worse than PDR alone). So a fix is z = p + c + w: c a Gauss–Markov
 * process in the distance walked (stationary σ_c = ekf_fix_bias_sigma_m per axis, correlation length
 * ℓ = ekf_fix_bias_length_m: it decorrelates as the walker moves, not while they stand), w white. With
 * σ_c = 0 the filter is the plain one. realbench measures σ_c and ℓ on training walks against truth.
 *
 * Propagation per step (length L, walking direction ψ, both from the PDR): with θ = ψ + b,
 *     x += s·L·cos θ,  y += s·L·sin θ,  c ← φ·c,  φ = exp(−s·L / ℓ),
 *     F = I + [[0, 0, −s·L·sin θ, L·cos θ, 0, 0], [0, 0, s·L·cos θ, L·sin θ, 0, 0], 0, 0,
 *              c rows: (φ − 1) on the diagonal],
 *     P ← F P Fᵀ + Q,
 *     Q = rotation(θ)·diag((s·σ_L·L)², (s·L·σ_ψ)²)·rotation(θ)ᵀ on the position block (σ_L the relative
 *         length noise ekf_step_length_sigma, σ_ψ the per-step direction noise ekf_step_heading_sigma_rad),
 *         + ekf_bias_rw_rad2_per_m·L on δb and ekf_scale_rw_per_m·L on δs (random walks per metre
 *         walked: a re-grip or a magnetic disturbance moves the bias while walking, not while standing),
 *         + (1 − φ²)·σ_c² on each δc (keeps c stationary);
 * and per second (standing, missed steps) fusion_q_time_m2_per_s on each position axis.
 *
 * Update per absolute fix z (2-D, H = [I₂ 0 0 I₂]): ν = z − p − c, S = H P Hᵀ + R_w, W = P Hᵀ S⁻¹,
 * δ = W ν, P ← (I − W H) P (I − W H)ᵀ + W R_w Wᵀ (Joseph form, stays symmetric positive), then the
 * closed-loop reset: nominal ← nominal + δ, δ ← 0 (eq. 57; additive errors, so the reset Jacobian is I).
 * The bias is wrapped to (−π, π], the scale clamped to [ekf_scale_min, ekf_scale_max].
 * NIS = νᵀ S⁻¹ ν is χ² with 2 dof; sf_fusion gates it like every scheme (test ratio NIS / gate²).
 *
 * R from the fix-error model: one fix's whole error covariance is F + accuracy_m² · M (symmetric 2×2s):
 * the matcher's accuracy (neighbour spread) is a shape, not a calibrated σ, and on real walks the error
 * hardly follows it (site1/F2: 3.8 m rms per axis at accuracy 2 m, 5.3 m at 6 m), so a floor F that does
 * not scale with it carries most of the error; the white part is R_w = F + accuracy_m² · M − σ_c² I, its
 * eigenvalues floored at ekf_fix_white_share · (the smallest eigenvalue of F + accuracy_m² · M) and
 * fusion_var_min_m2: σ_c is one
 * figure for every fix, so a fix more accurate than most keeps the white share of its own error instead
 * of being taken as c alone (which would make fix-to-fix jitter look like motion). M starts at the
 * prior: the site file's measured model (site_t.fix_cov_per_acc2 and the correlated part, written by
 * realbench from training walks the map never saw), else the parameters ekf_fix_var_x_per_acc2,
 * ekf_fix_cov_xy_per_acc2, ekf_fix_var_y_per_acc2 (default 1 · I = the matcher's word), and learns from accepted fixes' innovations, E[ννᵀ] = H P Hᵀ + R_w, a running mean
 * over the first ekf_r_window fixes and an exponential one after (innovation-based adaptive
 * estimation, Mehra 1970); an innovation beyond nis_max enters clipped onto it. It may only say the
 * fixes are worse than the prior (a disturbed site, a moved access point), never better: M's
 * eigenvalues stay in [the prior's smallest, ekf_r_max] (the prior itself clamped to [ekf_r_min,
 * ekf_r_max]).
 *
 * Start and recovery from a fix: p = z, c = 0, so p's error is −(c + w): P_pp = R_w + σ_c² I,
 * P_cc = σ_c² I, P_pc = −σ_c² I; δb with ekf_init_bias_sigma_rad at the start (the heading bias is
 * unknown: a magnetometer indoors is off by tens of degrees), δs with ekf_init_scale_sigma; a recovery
 * keeps what bias and scale learnt and clears their cross terms. From a known pose (truth-initialised):
 * P_pp as given, c = 0 with σ_c², uncorrelated.
 *
 * Cost: per step ~700 flops (the 6×6 F P Fᵀ) and one sin/cos/exp; per fix ~900 flops. Memory:
 * sizeof(sf_ekf_t) = 408 B on x86-64 and i686 (at most 416 B, checked). No heap, no I/O, no clock. */
#ifndef SF_EKF_H
#define SF_EKF_H

#include <stdint.h>

#include "sf_params.h"
#include "sf_radiomap.h"

enum { SF_EKF_N = 6 }; /* [δx, δy, δb, δs, δc_x, δc_y] */

typedef struct {
    double heading_bias_rad;       /* b, added to the PDR walking direction */
    double stride_scale;           /* s, multiplies the PDR step length */
    double fix_bias_m[2];          /* c, the fixes' correlated error */
    double P[SF_EKF_N][SF_EKF_N];  /* covariance of δ */
    double fix_model[3];           /* M: one fix's error covariance per accuracy_m² [xx, xy, yy] */
    double fix_floor_m2[3];        /* F: the part of it that does not scale with accuracy [m²] */
    double model_floor;            /* smallest eigenvalue M may learn down to: the prior's */
    double bias_sigma_m;           /* σ_c (the site's, or ekf_fix_bias_sigma_m) */
    double bias_length_m;          /* ℓ */
    double white_share;            /* least white share of a fix's variance */
    uint32_t model_fixes;          /* innovations M has learnt from */
} sf_ekf_t;
_Static_assert(sizeof(sf_ekf_t) <= 416, "sf_ekf.h promises at most 416 B");

/* A fresh filter: bias 0 and scale 1 with their initial σ, c = 0 with σ_c, the fix model of the
 * ekf.fix_* parameters; the position block is then set by sf_ekf_restart_at_fix or
 * sf_ekf_restart_known. */
void sf_ekf_start(sf_ekf_t *e, const sf_params_t *p);

/* The site's measured fix model instead of the parameters' (NULL or not valid: nothing changes); c
 * restarts at 0 with the site's σ_c. Call after sf_ekf_start, before the first fix. */
void sf_ekf_use_site_model(sf_ekf_t *e, const sf_params_t *p, const sf_fix_model_t *model);

/* The position taken from a fix whose white R is r_white_m2 = [xx, xy, yy] (start, recovery): c = 0 and
 * the position and c blocks as in the header; bias and scale keep their values and variances. */
void sf_ekf_restart_at_fix(sf_ekf_t *e, const double r_white_m2[3]);

/* The position known with covariance pos_cov_m2 (truth-initialised): c = 0, uncorrelated. */
void sf_ekf_restart_known(sf_ekf_t *e, const double pos_cov_m2[3]);

/* One step of length_m in walking direction heading_rad: fills the displacement d_m = (dx, dy) the
 * nominal position moves by, decays c, and propagates P. */
void sf_ekf_step(sf_ekf_t *e, const sf_params_t *p, double length_m, double heading_rad, double d_m[2]);

/* dt_s seconds without a step (dt_s ≤ 0 adds nothing). */
void sf_ekf_time(sf_ekf_t *e, const sf_params_t *p, double dt_s);

/* The white part R_w = F + accuracy_m² · M − σ_c² I of a fix of that accuracy [xx, xy, yy] (floored as
 * above). */
void sf_ekf_fix_r(const sf_ekf_t *e, const sf_params_t *p, double accuracy_m, double r_white_m2[3]);

/* One fix's whole error covariance F + accuracy_m² · M [xx, xy, yy] (white and correlated parts
 * together): what a filter that does not carry c (the particle scheme) must take as its R. */
void sf_ekf_fix_total(const sf_ekf_t *e, double accuracy_m, double total_m2[3]);

/* In place: the fix's offset z − p (fix minus the nominal position) becomes ν = z − p − c for a fix
 * that carries the correlated error (`correlated`: a Wi-Fi fix), ν = z − p for the other sources
 * (GNSS, BLE, landmark: H = [I 0 0 0], their errors are not the radio map's). */
void sf_ekf_innovation(const sf_ekf_t *e, bool correlated, double nu_m[2]);

/* S = H P Hᵀ + R_w [xx, xy, yy] and the NIS νᵀ S⁻¹ ν (+∞ when S is not positive definite). */
double sf_ekf_nis(const sf_ekf_t *e, bool correlated, const double nu_m[2], const double r_white_m2[3],
                  double s_m2[3]);

/* Learns the fix model from one accepted fix's innovation (before the update), clipped to nis_max. */
void sf_ekf_learn_fix_model(sf_ekf_t *e, const sf_params_t *p, const double nu_m[2], double accuracy_m,
                            double nis_max);

/* The update and the closed-loop reset: fills the position correction dpos_m (the caller moves the
 * nominal position), corrects bias, scale and c, and returns the mean position gain of ν,
 * (W_xx + W_yy) / 2, as the record's α. */
double sf_ekf_update(sf_ekf_t *e, const sf_params_t *p, bool correlated, const double nu_m[2], const double r_white_m2[3],
                     double dpos_m[2]);

#endif
