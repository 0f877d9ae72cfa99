/* sf_magcal.h — online hard-iron calibration of the magnetometer: a sphere fit with exponential
 * forgetting, a ridge prior for the directions the motion does not excite, and disturbance gating.
 *
 * Model. The board measures m = m_true + b in sensor axes [µT]; b is the hard-iron offset (constant,
 * from magnetised parts near the sensor) and |m_true| = F is constant where the field is undisturbed
 * (soft iron, i.e. a scale/skew matrix, is not modelled). Then |m|² = 2 m·b + k with k = F² − |b|²,
 * linear in θ = (b_x, b_y, b_z, k). Each used sample adds the row a = (2m, 1), y = |m|² to the 4×4
 * normal equations A θ = r, after both are multiplied by λ = exp(−δt/τ) (δt since the previous sample,
 * τ = magcal_tau_s): the fit remembers about τ of data and follows a slowly changing offset.
 * W = A[3][3] is the (forgotten) number of samples in memory.
 *
 * Observability (control). Eliminating k leaves 4W·C·b = 2W·cov(m, |m|²), C = the 3×3 covariance of
 * the remembered samples (the "direction covariance", read off A). Only directions along which the
 * samples spread tell anything about b: a walker with a level board turns about the vertical only, the
 * samples lie on a horizontal circle, and the vertical component of b is unobservable. With
 * eigenvalues s₁² ≥ s₂² ≥ s₃² of C (spread_ut = s, RMS µT), a direction is observed when its spread
 * s ≥ magcal_min_spread_ut. A solve needs at least two observed directions (≥ 20 samples in memory):
 * samples spread evenly over an arc of φ about one axis, at horizontal field H, have the smaller
 * in-plane spread H·√(½ + sin φ/(2φ) − (2 sin(φ/2)/φ)²): 0.09 H for 90°, 0.31 H for 180° (7.4 µT at
 * H = 24 µT), 0.71 H for a full turn; the default 6 µT thus asks for about half a turn in memory.
 *
 * Ridge prior. The solve adds ρ_i v_i v_iᵀ to the b block of A (v_i the eigenvectors of C), a prior
 * pulling b toward 0: ρ_i = 4W·magcal_ridge_ut² along observed directions (an observed component with
 * spread s comes out scaled by s²/(s² + ridge²): −0.09 % for a full turn at H = 24 µT with the default
 * 0.5 µT), and
 * ρ_i = 4W·(1000 µT)² along unobserved ones, which pins b·v_i to 0. The strong weight is needed, not
 * a matter of taste: noise of σ µT gives the unobserved axis a spurious spread σ, and the least-squares
 * fit explains it by a sphere centred in the plane of the circle, pulling b·v toward the circle's
 * offset from the origin (≈ −F sin δ = −42 µT for a level board at dip 60°) with weight σ²/(σ² + ρ/4W);
 * a weak isotropic ridge (0.5 µT, σ = 0.3 µT) lets b_z run to about −11 µT (measured: −10.6 µT on the
 * level-turning case of test_magcal.c with the lock removed).
 * A solution is taken when A + ridge is regular (Gaussian elimination with partial pivoting), R² =
 * k + |b|² > 0, |b| ≤ magcal_max_offset_ut, and the fit is consistent: the RMS of |m − b| − R over
 * the memory, ≈ √(Σ(y − aθ)²/W)/(2R) (Σ y² is kept for it), is ≤ magcal_max_rms_ut. Otherwise the
 * previous offset is kept and the reason is recorded. The first taken solution sets valid; valid never
 * goes back to false.
 *
 * Disturbance gating (control). A sample is used only when its corrected magnitude |m − b| (current b)
 * is within tol of the reference radius: before the first solution the reference is
 * attitude_mag_field_ut and tol = magcal_gate_ut + magcal_max_offset_ut (the offset is still unknown,
 * so the gate is wide and mostly catches gross faults); afterwards the reference is the fitted radius
 * R and tol = magcal_gate_ut. A steel column (field ×1.3–1.45) is then rejected. Bootstrap: before the
 * first solution a zone passes the wide gate, and the fit over it is inconsistent; an inconsistent
 * candidate then restarts the memory (sums cleared, restarts counted), so the first solution comes
 * from a stretch of about half a turn without a zone (time-wise RANSAC). After the first solution an
 * inconsistent candidate is only not taken: the memory holds good data. Direction-only disturbances at
 * unchanged strength are not detected here (the attitude's dip test catches some of them downstream).
 *
 * Solve schedule (control). Every used sample enters the normal equations, but the solve (the
 * eigen-decomposition and the elimination, most of a used sample's cost) runs on every
 * SF_MAGCAL_SOLVE_EVERY-th used sample only: 10 Hz at the board's 50 Hz; the ones between are
 * `deferred`, and every audit carries the last solve's spread and observed. The offset in use is then
 * the solve over a memory at most four samples (80 ms at 50 Hz) short of the current one, and those
 * carry a weight ≤ 4δt/magcal_tau_s of it (1.3e-4 at the default 600 s, 8e-3 at the 10 s minimum):
 * the fit is the one a solve on every sample would give up to 80 ms later, a lag of 1e-4 of its own
 * time constant. The first solution and a bootstrap restart come at most four used samples later,
 * against the half turn of samples they need.
 *
 * Time: δt < 0 (time going backwards) skips the sample (by_sample[sf_magcal_time]); the first sample and δt = 0
 * forget nothing. magcal_enable = 0 makes sf_magcal_update return at once: no counters, b stays 0 and
 * sf_magcal_apply is the identity.
 *
 * Limitations: hard iron only (no soft-iron matrix); an offset component along a never-excited
 * direction stays 0 (for a level walker: the vertical; it costs no heading when the board is level);
 * once valid, a large unobserved component makes tilted samples miss the gate, so it is learnt only if
 * it is below about magcal_gate_ut; the prior is toward 0, not toward the previous estimate, so a
 * component learnt during a tumble returns to 0 when the tumble has faded from the memory; once valid
 * there is no recovery if the offset itself jumps by more than the gate (every sample is then gated:
 * watch by_sample[sf_magcal_gated]); a board that never sees half a turn free of disturbance never
 * becomes valid.
 *
 * Cost per used sample: the normal equations' update and, on every SF_MAGCAL_SOLVE_EVERY-th, a 3×3
 * Jacobi eigen-decomposition (≤ 16 sweeps, ~5 in practice) and a 4×4 Gaussian elimination, a few
 * kflop; the forgetting factor's exp only when the interval changes (sf_exp_memo); a gated sample
 * costs two sqrt; forgetting and accumulation are one pass over AᵀA's ten distinct elements: ≈ 315
 * instructions per sf_magcal_update in `stridefix bench perf`'s sensors walk
 * (callgrind, x86-64 -O3). Memory sizeof(sf_magcal_t) = 472 B on x86-64 (i686 not rechecked; < 512 B,
 * checked). No heap, no I/O, no clock, no hidden state: the same
 * inputs give bit-identical outputs. Functions cannot fail (void); NULL arguments are a contract violation
 * (SF_ASSERT). Counters never decrease. */
#ifndef SF_MAGCAL_H
#define SF_MAGCAL_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_math.h"
#include "sf_params.h"

/* A solve on every this-many-th used sample: see "Solve schedule" above. */
#define SF_MAGCAL_SOLVE_EVERY 5

/* What happened to one sample (control). */
typedef enum {
    sf_magcal_used = 0,    /* added to the normal equations */
    sf_magcal_invalid = 1, /* non-finite component */
    sf_magcal_time = 2,    /* time went backwards */
    sf_magcal_gated = 3,   /* corrected magnitude outside the gate: disturbed */
    sf_magcal_sample_verdict_count = 4
} sf_magcal_sample_verdict_t;

/* What happened to the solve after a used sample. */
typedef enum {
    sf_magcal_solved = 0,        /* offset updated */
    sf_magcal_not_solved = 1,    /* sample not used: no solve attempted */
    sf_magcal_too_few = 2,       /* fewer than 20 samples in memory */
    sf_magcal_not_spread = 3,    /* fewer than two observed directions */
    sf_magcal_singular = 4,      /* normal equations singular (pivot underflow) */
    sf_magcal_out_of_bound = 5,  /* |b| > magcal_max_offset_ut, or R² ≤ 0 / non-finite */
    sf_magcal_inconsistent = 6,  /* fit residual RMS > magcal_max_rms_ut: a disturbance is in memory */
    sf_magcal_deferred = 7,      /* used, the solve left to the next SF_MAGCAL_SOLVE_EVERY-th used sample */
    sf_magcal_solve_verdict_count = 8
} sf_magcal_solve_verdict_t;

/* Audit record of the last sample (the FIX habit). */
typedef struct {
    int64_t t_us;
    double field_ut;       /* measured |m| */
    double corrected_ut;   /* |m − b| with b before this sample */
    double ref_ut;         /* reference radius of the gate */
    double tol_ut;         /* gate half-width */
    double spread_ut[3];   /* RMS spread along the eigen-directions of C, descending (the last solve's) */
    int32_t observed;      /* directions with spread ≥ magcal_min_spread_ut (the last solve's) */
    double candidate_offset_ut[3]; /* solution of this solve (taken or not); 0 when not solved */
    double candidate_radius_ut;    /* √(k + |b|²) of that solution; 0 when not computed */
    double candidate_rms_ut;       /* RMS of |m − b| − R over the memory for that solution */
    bool restarted;                /* this sample's inconsistent fit restarted the memory */
    sf_magcal_sample_verdict_t sample;
    sf_magcal_solve_verdict_t solve;
} sf_magcal_audit_t;

typedef struct {
    /* fusion: forgotten normal equations, θ = (b_x, b_y, b_z, k) */
    double ata[4][4];
    double aty[4];
    double yty; /* Σ y², for the fit residual */
    bool started;
    int64_t last_t_us;
    sf_memo_t forget; /* λ of the last interval (the MAG rate's): one exp per rate change */
    int32_t used_since_solve;    /* used samples since the last solve, < SF_MAGCAL_SOLVE_EVERY */
    double last_spread_ut[3];    /* the last solve's spread and observed, kept in every audit */
    int32_t last_observed;

    /* output */
    bool valid;           /* a solution has been taken */
    double offset_ut[3];  /* b, sensor axes; 0 until valid */
    double radius_ut;     /* fitted |m − b| (F); 0 until valid */

    /* health: counters never decrease */
    uint32_t samples_used;
    uint32_t samples_rejected; /* invalid + time + gated */
    uint32_t by_sample[sf_magcal_sample_verdict_count];
    uint32_t by_solve[sf_magcal_solve_verdict_count];
    uint32_t restarts; /* memory cleared by an inconsistent fit before the first solution */
    sf_magcal_audit_t last;
} sf_magcal_t;
_Static_assert(sizeof(sf_magcal_t) < 512, "sf_magcal.h promises less than 512 B");

/* Empty memory, b = 0, not valid, counters 0. p is read for nothing yet but kept for symmetry with
 * the other modules (and so a future prior can come from the parameters). */
void sf_magcal_init(sf_magcal_t *cal, const sf_params_t *p);

/* One raw magnetometer sample [µT], sensor axes: gate, accumulate, solve (see the header comment). */
void sf_magcal_update(sf_magcal_t *cal, const sf_params_t *p, int64_t t_us, const double field_ut[3]);

/* corrected = field − b. field and corrected may alias. */
void sf_magcal_apply(const sf_magcal_t *cal, const double field_ut[3], double corrected_ut[3]);

#endif
