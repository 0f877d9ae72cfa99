/* sf_steps.h — step detection from the gravity-aligned vertical acceleration, two detectors.
 *
 * Input. a_v [m/s²]: specific force along the up axis minus g, computed by the caller from the
 * attitude, with its sample time t_us. Any rate from 20 to 200 Hz, uneven spacing and gaps are fine.
 *
 * Model. Every stage is either continuous-time or runs on a uniform internal grid, so the detector
 * means the same thing at every input rate:
 *   1. Two low-passes run at the input rate, each two cascaded first-order sections with the exact
 *      discretisation k = 1 − exp(−dt/τ), τ = 1/(2π f_c) (so uneven dt is handled exactly):
 *      x_pt at steps_pt_lowpass_hz (5 Hz) and x_tp at steps_tp_lowpass_hz (3 Hz, SmartLocator).
 *      They also serve as the anti-alias filter of step 2.
 *   2. Both are resampled by linear interpolation onto a fixed grid of SF_STEPS_RATE_HZ (50 Hz, one
 *      point every 20 000 µs). The detectors below see only this grid. A 20 Hz input is upsampled,
 *      a 200 Hz input downsampled (after the low-pass).
 *   3a. steps_detector = 0, Pan–Tompkins variant (Jäger, Süß, Becker, Eq. 6–7) on x_pt:
 *      d(n) = ¼[2x(n) + x(n−1) − x(n−3) − 2x(n−4)], y(n) = max(d(n), 0), z(n) = (1 + y(n))² − 1.
 *      A step is z(n−1) > z(n−2), z(n−1) ≥ z(n), z(n−1) > θ (the peak over the last three values),
 *      at least steps_refractory_ms after the previous step. The paper leaves the threshold open; θ
 *      adapts as in Pan and Tompkins' QRS detector: SPK and NPK are running levels (gain ⅛) of the
 *      peaks taken as steps and of the other local maxima of z, and
 *          θ = max(steps_pt_threshold, steps_pt_noise_factor · NPK, NPK + steps_pt_adaptive · (SPK − NPK)),
 *      so a slow, soft gait (z peaks ≈ 0.3) and a fast one (≈ 3) are both counted without counting
 *      the fast gait's secondary bumps, nor the sensor noise of a still body (the NPK term). After steps_max_period_ms without a step SPK decays toward
 *      NPK (time constant 1 s), so a slow walk after a fast one is found again; steps_pt_adaptive = 0
 *      gives the fixed threshold steps_pt_threshold. NPK starts at 2 · steps_pt_threshold (the noise
 *      level is not known yet) and learns the real one from the peaks that follow.
 *   4. Both detectors: a detection is a step only if the 3 Hz a_v moved by at least
 *      steps_min_range_mps2 (amax − amin) since the previous step. By Weinberg's law a step of length
 *      L needs a range (L/K)⁴: 0.5 m/s² is a 0.4 m step at K = 0.47, shorter than any walking step,
 *      while a still body's noise and a lift's smooth start move it far less. A refused detection
 *      counts in too_small (and as a noise peak for the adaptive threshold). Because n counts 20 ms
 *      grid points, d is ≈ 40 ms × da_v/dt at every input rate; on a raw 100 Hz stream the same
 *      formula would give half the value and the threshold would mean something else.
 *      DEVIATION: the paper takes the first such peak. Noise makes local maxima of z on the steep swing
 *      rise into a heel strike, and the refractory time then hides the heel strike itself, so the step
 *      time wanders by up to 0.25 s (worst at 20 Hz, where interpolation makes z piecewise). As in the
 *      original Pan–Tompkins QRS detector, a peak is held for the refractory time (steps_refractory_ms,
 *      300 ms) and a higher peak within that time replaces it; the step is reported when the time is
 *      up, so a swing bump just before a heel strike cannot take the heel strike's place. Latency:
 *      ≈ 0.3 s; the count is unchanged.
 *   3b. steps_detector = 1, trough-then-peak (SmartLocator, Couceiro 2017, Eq. 3.4) on x_tp: local
 *      minima are troughs (the lowest one is kept; one older than steps_tp_max_interval_ms is
 *      replaced by any newer one); a local maximum is a step when it comes at most
 *      steps_tp_max_interval_ms after the trough, rises at least steps_tp_min_rise_mps2 above it,
 *      and is at least steps_refractory_ms after the previous step. A step uses up its trough.
 *
 * Thresholds. steps_pt_threshold (0.15) is only the floor of the adaptive θ: z = 0.15 is y ≈ 0.072 m/s²,
 * a smoothed slope of ≈ 1.8 m/s³, about a twelfth of a slow (1.4 Hz) walk's heel strike; above it the
 * NPK terms (steps_pt_noise_factor 2, steps_pt_adaptive 0.1) keep sensor noise out. As a fixed
 * threshold (steps_pt_adaptive = 0, steps_pt_noise_factor = 0; the default was 0.5, y ≈ 0.22 m/s²,
 * ≈ 5.6 m/s³, before the threshold adapted), with 0.1 m/s² rms noise extra steps appeared below ≈ 0.2
 * (20 Hz input) and slow-walk heel strikes were lost above ≈ 2 on the synthetic gait of
 * tests/c/test_steps.c. steps_tp_min_rise_mps2 = 1 m/s² and steps_tp_max_interval_ms = 0.8 s are the
 * thesis's values (person dependent, it says).
 * Tested at 20 Hz ±30 % jitter, 50 Hz ±30 %, 100 Hz and 200 Hz: the same counts. Below 25 Hz a heel
 * strike shorter than the sample spacing can fall between samples; counts held in the tests, timing
 * then wanders by up to 0.25 s.
 *
 * Output per step (sf_step_event_t): t_us = the grid time of the detected extremum (the z peak, or
 * the x_tp peak); it lies at most one grid interval plus one input interval before the sample that
 * reported it. amax/amin = extremes of x_tp (the 3 Hz signal, for both detectors, so one Weinberg K
 * serves both) over the grid points after the previous step's time up to the detecting point, at most
 * SF_STEPS_WINDOW points back. period_s = time since the previous step, or 0 for the first step and for
 * a step more than steps_max_period_ms after the previous one (the start of a walk).
 *
 * Gaps. A sample at or before the previous time is counted in `backwards` and ignored. A gap longer
 * than steps_max_gap_ms is counted in `gaps` and restarts filters, grid and detector (the previous
 * step's time is kept, so the period rule above still applies).
 *
 * Cost: O(1) per grid point and per sample, a few dozen flops (≈ 155 instructions per sample in
 * `stridefix bench perf`); the two low-pass gains' expm1 run only when the interval changes
 * (sf_expm1_memo); the grid loop runs at most steps_max_gap_ms / 20 ms times in one call. Memory:
 * sizeof(sf_steps_t) = 2 464 B on x86-64 (i686 not rechecked; at most 2.5 KiB, checked), the amax/amin ring most of it.
 * No heap, no I/O, no clock. Deterministic: the same inputs give bit-identical events. */
#ifndef SF_STEPS_H
#define SF_STEPS_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_math.h"
#include "sf_params.h"

#define SF_STEPS_RATE_HZ 50
#define SF_STEPS_GRID_US (1000000 / SF_STEPS_RATE_HZ)
/* Grid points kept for amax/amin: covers steps_max_period_ms (max 2500 ms) at 50 Hz. */
#define SF_STEPS_WINDOW 128
/* Events found within one call beyond the first wait here (a call can span a gap of many grid points). */
#define SF_STEPS_QUEUE 4
/* Pan–Tompkins search time: a higher z peak this soon after a candidate replaces it (see the model). */
_Static_assert(SF_STEPS_WINDOW * SF_STEPS_GRID_US >= 2500 * 1000, "window must cover steps_max_period_ms");
_Static_assert(1000000 % SF_STEPS_RATE_HZ == 0, "grid interval must be a whole number of µs");

typedef enum { sf_steps_pan_tompkins = 0, sf_steps_trough_peak = 1 } sf_steps_detector_t;

typedef struct {
    int64_t t_us;     /* time of the step (the detected extremum, grid time) */
    double amax_mps2; /* max of the 3 Hz a_v over the step */
    double amin_mps2; /* min of the 3 Hz a_v over the step */
    double period_s;  /* time since the previous step; 0 at the start of a walk */
} sf_step_event_t;

typedef struct {
    bool started;
    int64_t last_t_us;
    double pt1_mps2, pt2_mps2; /* Pan–Tompkins low-pass, two stages */
    double tp1_mps2, tp2_mps2; /* trough-peak low-pass, two stages */
    /* Grid: the next grid time to fill, and the last input (filtered) sample to interpolate from. */
    int64_t next_grid_us;
    int32_t n_grid; /* grid points since the (re)start, saturating */
    /* Pan–Tompkins history: x(n−1..n−4) and z(n−1), z(n−2). */
    double x_hist[4];
    double z1, z2;
    bool cand_valid; /* a peak waiting out the refractory time */
    double cand_z;
    int64_t cand_t_us;
    double spk, npk; /* adaptive threshold: levels of step peaks and of other peaks of z */
    /* trough-peak history: x_tp(n−1), x_tp(n−2), trough */
    double tp_prev1, tp_prev2;
    bool trough_valid;
    double trough_mps2;
    int64_t trough_t_us;
    /* ring of x_tp on the grid, for amax/amin */
    double ring_mps2[SF_STEPS_WINDOW];
    int64_t ring_t_us[SF_STEPS_WINDOW];
    int32_t ring_head; /* index of the newest */
    int32_t ring_count;
    int64_t last_step_t_us; /* INT64_MIN/2 before the first step */
    /* pending events (FIFO) */
    sf_step_event_t queue[SF_STEPS_QUEUE];
    int32_t queue_head, queue_count;
    /* counters, never decrease */
    uint32_t steps;     /* events produced */
    uint32_t too_small; /* detections refused: a_v range over the step below steps_min_range_mps2 */
    uint32_t gaps;      /* restarts after a gap */
    uint32_t backwards; /* samples at or before the previous time, ignored */
    uint32_t dropped;   /* events lost because the queue was full (should stay 0) */
    uint32_t bad;       /* non-finite a_v, ignored */
    /* the two low-pass gains' expm1 for the last interval: once per rate change, not twice a sample */
    sf_memo_t gain_pt, gain_tp;
} sf_steps_t;
_Static_assert(sizeof(sf_steps_t) <= 2560, "sf_steps.h promises at most 2.5 KiB");

/* Clears the state. */
void sf_steps_init(sf_steps_t *s, const sf_params_t *p);

/* Consumes one sample. Returns true and fills *ev with the oldest step not yet reported when there is
 * one (events come out in time order, one per call). */
bool sf_steps_update(sf_steps_t *s, const sf_params_t *p, int64_t t_us, double accel_v_mps2, sf_step_event_t *ev);

#endif
