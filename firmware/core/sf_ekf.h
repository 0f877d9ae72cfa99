/* sf_ekf.h — the `ekf` scheme's math: an error-state Kalman filter over steps, after Mirzababaei &
 * Akbari's closed-loop error-state KF (papers/mirzababaei-akbari-slam-gps-ins-wlpf.md, eqs. 53–59),
 * with the INS replaced by PDR steps. The control around it (start, floor, gate, recovery, audit) is
 * sf_fusion's, shared with every other scheme; this module is only the filter.
 *
 * Nominal state: position (x, y) [m] (kept in sf_fusion_t), heading bias b [rad] added to the walking
 * direction, stride scale s multiplying the step length. Error state δ = [δx, δy, δb, δs], covariance
 * P (4×4). The floor is a discrete state, handled by sf_fusion like every scheme's.
 *
 * Propagation per step (length L, walking direction ψ, both from the PDR): with θ = ψ + b,
 *     x += s·L·cos θ,  y += s·L·sin θ,
 *     F = I + [[0, 0, −s·L·sin θ, L·cos θ], [0, 0, s·L·cos θ, L·sin θ], 0, 0],
 *     P ← F P Fᵀ + Q,
 *     Q = rotation(θ)·diag((s·σ_L·L)², (s·L·σ_ψ)²)·rotation(θ)ᵀ on the position block (σ_L the relative
 *         length noise ekf_step_length_sigma, σ_ψ the per-step direction noise ekf_step_heading_sigma_rad),
 *         + ekf_bias_rw_rad2_per_m·L on δb and ekf_scale_rw_per_m·L on δs (random walks per metre
 *         walked: a re-grip or a magnetic disturbance moves the bias while walking, not while standing);
 * and per second (standing, missed steps) fusion_q_time_m2_per_s on each position axis.
 *
 * Update per absolute fix z (2-D, H = [I₂ 0]): ν = z − (x, y), S = P_pos + R, W = P Hᵀ S⁻¹,
 * δ = W ν, P ← (I − W H) P (I − W H)ᵀ + W R Wᵀ (Joseph form, stays symmetric positive), then the
 * closed-loop reset: nominal ← nominal + δ, δ ← 0 (eq. 57; additive errors, so the reset Jacobian is I).
 * The bias is wrapped to (−π, π], the scale clamped to [ekf_scale_min, ekf_scale_max].
 * NIS = νᵀ S⁻¹ ν is χ² with 2 dof; sf_fusion gates it like every scheme (test ratio NIS / gate²).
 *
 * R, a full 2×2, from a fix-error model learnt online: R = accuracy_m² · M, M (symmetric 2×2) the fix
 * error covariance per unit of the matcher's accuracy², because the matcher's accuracy (neighbour
 * spread) is a shape, not a calibrated σ. M starts at the prior (ekf_fix_var_x_per_acc2,
 * ekf_fix_cov_xy_per_acc2, ekf_fix_var_y_per_acc2: the site's fix errors against truth, measured by
 * realbench on training walks the map never saw, or 1 · I = the matcher's word) and learns from the
 * scheme's own innovations, E[ννᵀ] = P_pos + R, i.e. M ≈ mean((ννᵀ − P_pos) / accuracy²), a running
 * mean over the first ekf_r_window fixes and an exponential one after (innovation-based adaptive
 * estimation, Mehra 1970), from accepted fixes only (a diverged track is for the recovery to mend,
 * not for R to absorb); an innovation beyond nis_max would enter clipped onto it. The innovations may only say the fixes are worse than the prior (a disturbed
 * site, a moved access point), never better: fix errors correlated in time (consecutive scans at
 * nearby places match the same wrong reference points) look smaller in the innovations than they
 * are, because the track follows them. So M's eigenvalues stay in [the prior's smallest, ekf_r_max]
 * (the prior itself is clamped to [ekf_r_min, ekf_r_max]).
 *
 * Correlated fixes: consecutive scans at nearby places match the same wrong reference points, so a
 * run of N fixes carries less than N independent ones; an update takes R · ekf_fix_run_factor (the
 * AR(1) factor of the site's fix errors, measured by realbench), while a start or a recovery, which
 * rests on one fix, takes that fix's own R. The gate tests the update's S (with the run's R).
 *
 * Start: from a fix, P_pos = R (one fix's), δb with ekf_init_bias_sigma_rad (the heading bias is unknown: a
 * magnetometer indoors is off by tens of degrees), δs with ekf_init_scale_sigma; after a recovery the
 * position block restarts at R, its cross terms are cleared, bias and scale keep what they learnt.
 *
 * Cost: per step ~150 flops and one sin/cos; per fix ~250 flops. Memory: sizeof(sf_ekf_t) = 184 B on
 * x86-64 and i686 (at most 192 B, checked). No heap, no I/O, no clock. */
#ifndef SF_EKF_H
#define SF_EKF_H

#include <stdint.h>

#include "sf_params.h"

typedef struct {
    double heading_bias_rad; /* b, added to the PDR walking direction */
    double stride_scale;     /* s, multiplies the PDR step length */
    double P[4][4];          /* covariance of [δx, δy, δb, δs] */
    double fix_model[3];     /* M: fix-error covariance per accuracy_m² [xx, xy, yy] */
    double model_floor;      /* smallest eigenvalue M may learn down to: the prior's */
    uint32_t model_fixes;    /* innovations M has learnt from */
} sf_ekf_t;
_Static_assert(sizeof(sf_ekf_t) <= 192, "sf_ekf.h promises at most 192 B");

/* A fresh filter: position covariance pos_cov_m2 = [xx, xy, yy], bias 0 and scale 1 with their
 * initial σ, and the prior fix model. */
void sf_ekf_start(sf_ekf_t *e, const sf_params_t *p, const double pos_cov_m2[3]);

/* After a recovery: position covariance restarts at pos_cov_m2, its cross terms with bias and scale
 * are cleared; bias, scale and the fix model keep what they learnt. */
void sf_ekf_restart_position(sf_ekf_t *e, const double pos_cov_m2[3]);

/* One step of length_m in walking direction heading_rad: fills the displacement d_m = (dx, dy) the
 * nominal position moves by, and propagates P. */
void sf_ekf_step(sf_ekf_t *e, const sf_params_t *p, double length_m, double heading_rad, double d_m[2]);

/* dt_s seconds without a step (dt_s ≤ 0 adds nothing). */
void sf_ekf_time(sf_ekf_t *e, const sf_params_t *p, double dt_s);

/* R = accuracy_m² · M for a fix of that accuracy [xx, xy, yy] (floored at fusion_var_min_m2 per axis):
 * one fix's error (start, recovery). */
void sf_ekf_fix_r(const sf_ekf_t *e, const sf_params_t *p, double accuracy_m, double r_m2[3]);

/* R of an update: sf_ekf_fix_r times ekf_fix_run_factor (a fix in a run of correlated ones). */
void sf_ekf_update_r(const sf_ekf_t *e, const sf_params_t *p, double accuracy_m, double r_m2[3]);

/* S = P_pos + R [xx, xy, yy] and the NIS νᵀ S⁻¹ ν of innovation nu_m. */
double sf_ekf_nis(const sf_ekf_t *e, const double nu_m[2], const double r_m2[3], double s_m2[3]);

/* Learns the fix model from one innovation (before the update), clipped to nis_max. */
void sf_ekf_learn_fix_model(sf_ekf_t *e, const sf_params_t *p, const double nu_m[2], double accuracy_m,
                            double nis_max);

/* The update and the closed-loop reset: fills the position correction dpos_m (the caller moves the
 * nominal position), corrects bias and scale, and returns the mean position gain (W_xx + W_yy) / 2 as
 * the record's α. */
double sf_ekf_update(sf_ekf_t *e, const sf_params_t *p, const double nu_m[2], const double r_m2[3],
                     double dpos_m[2]);

#endif
