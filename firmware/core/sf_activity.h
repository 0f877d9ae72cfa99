/* sf_activity.h — still, walking, stairs up/down, elevator, from steps, a_v variance and the
 * barometric vertical speed.
 *
 * Inputs (each at its own rate, each with its time): a_v [m/s²] (the same signal sf_steps sees) through
 * sf_activity_accel; the step events of sf_steps through sf_activity_step; the vertical speed v [m/s] of
 * sf_floor through sf_activity_vspeed. The class is recomputed at every input and read with
 * sf_activity_current (codes sf_activity_* of sf_types.h, identical to step_t.ACTIVITY_*).
 *
 * Features.
 *   - variance σ² of a_v: exponentially weighted mean and mean square, time constant
 *     activity_var_tau_s, exact for any dt (k = 1 − exp(−dt/τ)); rate-independent.
 *   - stepping: at least activity_min_steps accepted steps in the last activity_step_window_ms
 *     (times kept in a ring of SF_ACTIVITY_STEPS); step rate = steps in the window / window, which
 *     saturates at SF_ACTIVITY_STEPS / window (3.2 steps/s with the default 2.5 s).
 * Rules, in this order (t = the newest input time):
 *   0. |v| > 2 · activity_elevator_vspeed_mps (0.6 m/s: faster than stairs are climbed) → elevator,
 *      and step detections are refused meanwhile (a lift's jerks are not steps)
 *   1. stepping and v >  activity_stairs_vspeed_mps (0.15 m/s)  → stairs_up
 *   2. stepping and v < −activity_stairs_vspeed_mps              → stairs_down
 *   3. stepping                                                  → walking
 *   4. |v| > activity_elevator_vspeed_mps (0.30 m/s)             → elevator (no steps; the variance
 *      is not required to be low: an elevator's start and stop and a fidgeting rider raise it, and the
 *      barometer is the telling cue)
 *   5. no accepted step for activity_still_time_ms and σ² < activity_still_var_m2ps4 → still
 *   6. otherwise: walking while the last step is less than activity_still_time_ms old (a pause in the
 *      gait), else unknown (handling the device without steps).
 * Before any a_v sample the class is unknown.
 *
 * A walk that has not started moves nothing. The first detection after steps_max_period_ms without one
 * starts a bout and is held, not credited; so are the next ones, each between
 * activity_min_step_period_ms (0.4 s, a fast walker's step) and steps_max_period_ms after the one before.
 * When activity_bout_steps detections are held (3 by default: a gait cycle and the step that starts
 * the next; one cycle, 2, let a hand-held phone's handling while standing through in pairs: on the 25
 * ipin2023 walks 214 steps before the walk began, moving a truth-initialised start 3.8 m on average;
 * two cycles, 4, removed more of them but lost real short walks on msindoor site1/F2), all of them are
 * credited at once; a detection that breaks the chain drops the held
 * ones (counted in lone_steps) and starts a new bout. A lone jolt — a lift starting or stopping, a door
 * slammed, the device knocked, the phone picked up and put down — therefore never moves the position,
 * and a real walk loses nothing; its first steps are credited activity_bout_steps − 1 steps late.
 * A walk also keeps its rhythm (step-to-step intervals vary 2–4 % in steady walking, Hausdorff 2005):
 * from the third held detection on, its interval to the one before must lie within 1/(1 + r) … (1 + r)
 * of the held interval before that (r = activity_bout_rhythm, 0.35: room for gait initiation), or the
 * held ones are dropped and a new bout starts with it. A hand fidgeting with the phone while the
 * walker stands makes detections 0.3–1.4 s apart at random; on the ipin2023 logs they started and
 * confirmed bouts before the walk (truth-initialised PDR 5.49 → 4.93 m mean with the rule).
 *
 * Gestures are not steps. A phone waved or turned in the hand (the calibration figure-eights of a
 * phone's magnetometer, handling it while standing) shakes a_v like a walk, but it turns far faster
 * than a walker does. The mean rotation rate |ω| (exponentially weighted like σ², activity_var_tau_s)
 * above activity_max_rotation_radps (π rad/s: a U-turn, the sharpest turn of a walk, takes at least a
 * stride, two steps at the usual ≈ 2 Hz, ≈ 1 s) refuses the detection (counted in rejected_steps and
 * in turning_steps) and ends the bout: the walk must start again after the gesture. Measured on the
 * gsd hand-held walks: ≤ 1.8 rad/s while walking, 3–7 rad/s while waving. A slower wave is caught by
 * how it turns: a walker's device turns about one axis at a time — the vertical in a turn, the
 * shoulder's pendulum axis when swung in the hand — and only sways about the others with the gait,
 * while a figure-eight turns it about two or three axes at once. The EW mean (activity_var_tau_s) of
 * ω ωᵀ (body frame, no attitude needed) has eigenvalues λ1 ≥ λ2 ≥ λ3; √λ2, the RMS rate about the
 * second principal axis (sf_activity_off_axis_radps), above activity_max_off_axis_radps refuses the
 * detection the same way. The bound is the sway's: a sine of amplitude A at the step rate f has RMS
 * rate A·2πf/√2; A = 5° at the fastest step rate, 2.5 Hz (the 0.4 s of activity_min_step_period_ms),
 * gives 0.97 rad/s, rounded to 1.0; at a slower cadence the same sway turns slower, so the bound is
 * scaled by the cadence the detection shows (its interval to the previous detection T, when within
 * activity_min_step_period_ms … steps_max_period_ms: bound × min_period / T; otherwise unscaled).
 * A calibration figure-eight waved slowly (|ω| 1.3–2.3 rad/s, √λ2 0.7–0.9 rad/s, detections 0.6 s
 * apart on the ipin2023 logs) passed the unscaled bound and moved a truth-initialised start by metres
 * before the walk; scaled, ipin2023's truth-initialised PDR went 6.34 → 5.49 m mean and msindoor
 * site1/F2 and site2/F3 gained 0.05–0.15 m. Measured over the second before each detection: gsd walks
 * ≤ 0.69 rad/s, msindoor site2/F3 walks ≤ 0.90 (a phone swung at a walk's start: its tilt rate reached
 * 3 rad/s, about one axis, so a tilt-rate bound refused those steps and this one does not), the gsd
 * gestures that the |ω| rule let through 0.46 (10th percentile), 0.98 (median).
 * DEVIATION: a phone swung in the hand at the arm's pendulum (±45° at 1 Hz is ≈ 3 rad/s) would be
 * refused as well; no data set here has one.
 *
 * False steps while still. sf_activity_step refuses (returns false, counts in `rejected_steps`) a
 * step that comes while σ² < activity_still_var_m2ps4: a body that quiet is not walking, whatever the
 * detector saw. A refused step does not count for the rules above; the estimator must not move the
 * position for it. While the class is still, the estimator also holds the position (zero-velocity).
 *
 * Cost: O(1) per call, O(SF_ACTIVITY_STEPS) when the step window's count changes (a step credited,
 * or the oldest counted one leaving the window: the count is remembered until then), the variance
 * gain's expm1 only when the interval changes (sf_lp_gain), one 3×3 eigenvalue (an acos, two cos)
 * per detection; ≈ 50 instructions per classification in `stridefix bench perf`'s sensors walk
 * (callgrind, x86-64 -O3; ≈ 120 at -O2 counting the window on every call). Memory: sizeof(sf_activity_t) =
 * 344 B on x86-64, at most 344 B (_Static_assert below). No heap, no I/O, no clock. Cannot fail. */
#ifndef SF_ACTIVITY_H
#define SF_ACTIVITY_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_math.h"
#include "sf_params.h"
#include "sf_steps.h"
#include "sf_types.h"

/* Step times kept: the window (max 10 s) at the fastest gait (≈ 3.3 steps/s at 300 ms) would need 34;
 * the rules only need activity_min_steps (≤ 8) of them, so 8 suffice. */
#define SF_ACTIVITY_STEPS 8
_Static_assert(SF_ACTIVITY_STEPS >= 8, "activity_min_steps may be 8");
/* Detections a bout may hold before it is credited: activity_bout_steps is at most 8. */
#define SF_ACTIVITY_BOUT_MAX 8

typedef struct {
    bool started;
    int64_t last_t_us;   /* newest input time */
    int64_t accel_t_us;  /* newest a_v time */
    double mean_mps2;    /* EW mean of a_v */
    double meansq_m2ps4; /* EW mean of a_v² */
    double vspeed_mps;   /* latest baro vertical speed */
    int64_t step_t_us[SF_ACTIVITY_STEPS]; /* ring of accepted step times */
    int32_t step_head, step_count;
    int8_t activity;
    uint32_t accepted_steps, rejected_steps; /* counters, never decrease */
    uint32_t lone_steps;       /* held detections of bouts that were never confirmed */
    int32_t held_n;            /* detections of a bout not yet credited */
    int64_t held_t_us[SF_ACTIVITY_BOUT_MAX];
    bool gyro_started;
    int64_t gyro_t_us;         /* newest |ω| time */
    double rotation_radps;     /* EW mean of |ω| */
    double gyro_moment_r2ps2[6]; /* EW mean of ω ωᵀ (body): xx, yy, zz, xy, xz, yz */
    sf_lp_gain_t var_gain;       /* the a_v and |ω| means' gain for the last dt (one IMU rate: one expm1) */
    uint32_t turning_steps;    /* detections refused as gestures (also in rejected_steps) */
    int64_t last_detection_t_us; /* newest detection that was not refused */
    /* the step-window count remembered (classify runs on every sample; the count changes only when a
     * step is credited or the oldest counted step leaves the window): window_n holds for times in
     * [window_t_us, window_until_us) with activity_step_window_ms = window_ms; window_n < 0 = not known */
    int32_t window_n, window_ms;
    int64_t window_t_us, window_until_us;
} sf_activity_t;
_Static_assert(sizeof(sf_activity_t) <= 344, "sf_activity.h promises at most 344 B");

void sf_activity_init(sf_activity_t *a, const sf_params_t *p);

/* One a_v sample [m/s²]. Non-finite values and samples at or before the previous a_v time are ignored. */
void sf_activity_accel(sf_activity_t *a, const sf_params_t *p, int64_t t_us, double accel_v_mps2);

/* One gyroscope sample ω [rad/s] of the device (body axes). Non-finite values and samples at or before
 * the previous one's time are ignored. */
void sf_activity_gyro(sf_activity_t *a, const sf_params_t *p, int64_t t_us, const double gyro_radps[3]);

/* RMS rotation rate about the device's second principal rotation axis [rad/s]: the square root of
 * the middle eigenvalue of the EW mean of ω ωᵀ; 0 before any gyro sample. */
double sf_activity_off_axis_radps(const sf_activity_t *a);

/* One step event. Returns how many steps the estimator should move now: 0 (refused: the body is
 * quiet or turning like a gesture; or held: a detection of a bout not yet confirmed), 1 (this step),
 * or activity_bout_steps (the held detections of the bout, confirmed by this one, which is the last). */
int sf_activity_step(sf_activity_t *a, const sf_params_t *p, const sf_step_event_t *ev);

/* One vertical-speed estimate [m/s] (sf_floor_vertical_speed_mps after a baro sample). */
void sf_activity_vspeed(sf_activity_t *a, const sf_params_t *p, int64_t t_us, double vspeed_mps);

/* The current class (sf_activity_*). */
int8_t sf_activity_current(const sf_activity_t *a);

/* a_v variance [m²/s⁴]. */
double sf_activity_variance_m2ps4(const sf_activity_t *a);

/* Accepted steps per second over the window ending at the newest input. */
double sf_activity_step_rate_hz(const sf_activity_t *a, const sf_params_t *p);

#endif
