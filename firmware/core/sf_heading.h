/* sf_heading.h — walking direction in the map frame: device yaw + mounting offset − map rotation,
 * with the mounting offset estimated online from the gait.
 *
 * Frames and angles. Nav frame as in sf_attitude.h (x = magnetic east, y = magnetic north, z = up);
 * device yaw is sf_attitude_yaw_rad (body x projected, CCW from +x). The mounting offset is the angle
 * from the device's projected x axis to the walking direction, CCW. The map frame is the nav frame
 * turned by heading_map_rotation_deg: map heading = nav heading − rotation. All headings CCW from +x.
 *
 *   walk_map = wrap(device_yaw + offset − map_rotation)
 *
 * Input. sf_heading_update takes, for every IMU sample, the acceleration rotated into nav
 * (sf_attitude_body_to_nav of the accelerometer's specific force; gravity may be included or removed,
 * the module removes the slow vertical mean itself with a low-pass of time constant 2·vz_tau) and the
 * device yaw at that sample. The horizontal part is turned by −yaw into the device-yaw frame, so the
 * statistics are already relative to the device and stay valid while the walker (and the device with
 * them) turns.
 *
 * Model (estimation of the offset). Per step window (between two sf_heading_on_step calls):
 * dt-weighted first and second moments of the yaw-relative horizontal acceleration a_h (2-D) and of
 * the vertical velocity v_up (a leaky integral, time constant heading_vz_tau_s, of the de-meaned
 * vertical acceleration). Closed windows are summed with a forgetting factor 1 − 1/heading_window_steps.
 * From the sum: the cross-covariance c = cov(a_h, v_up) and the 2×2 covariance C of a_h. The walking
 * axis follows the inverted pendulum: the body is highest at mid-stance, where forward speed is
 * lowest, so forward acceleration is negatively correlated with v_up and e = −c/|c| points forward.
 * The lateral sway (half the step rate, alternating sign from step to step) and centripetal
 * acceleration in turns are uncorrelated with v_up, so they do not bend e — unlike the principal axis
 * of C, which a sway as strong as the fore-aft oscillation (common at the waist) turns by tens of
 * degrees (the first version used PCA + sign and was 74° off on the simulator's gait). The step is
 * "good" when corr(e·a_h, v_up) ≤ −heading_min_corr; the angle of e is then one
 *  * offset sample. Offset samples are smoothed by a circular mean (exponential, memory
 * heading_smooth_steps). The estimate is used ("confident") after heading_min_steps good steps with
 * a mean resultant length ≥ heading_min_resultant; before that the offset is heading_mount_offset_deg.
 * Once confident it stays so; while the resultant is below it the last estimate is held. With
 * heading_learn_offset 0 the estimate is kept (and audited) but never used: on hand-held phones (the
 * msindoor walks) the gait-based offset wandered by 26° median over 10 s spans against 9° with the
 * fixed offset, whose constant part the site's map rotation absorbs.
 *
 * Only detections the activity credits (or holds for a bout) close a window that is used: the estimator
 * discards the window of a refused one (sf_heading_discard_step: a gesture, handling while standing),
 * whose acceleration is no gait. The prior heading_mount_offset_deg should be the device's usual
 * carriage — 0 for a board worn with x forward, 90 for an Android phone held in front (its y axis
 * along the screen towards the top; the gsd and msindoor data sets set it) — since it is used until
 * the estimate is confident.
 *
 * A window counts only if it lasts 0.2–2.0 s and holds ≥ 4 samples (longer: standing between steps,
 * discarded). A sample interval ≤ 0 is skipped; one longer than 0.5 s restarts the vertical filters
 * and the open window (counted in gaps).
 *
 * Cost: O(1) per sample (~40 flops; sf_heading_update adds a sin/cos pair, sf_heading_update_dir
 * none: ≈ 100 instructions), O(1) per step (one atan2, one sqrt); memory
 * sizeof(sf_heading_t) = 320 B on x86-64 (< 400 B, checked). No heap, I/O, clock or hidden
 * state: bit-identical outputs for the same inputs. Functions cannot fail (void); NULL arguments break the
 * contract (SF_ASSERT). */
#ifndef SF_HEADING_H
#define SF_HEADING_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_params.h"

/* dt-weighted sums over a window: x, y = yaw-relative horizontal acceleration (m/s²), z = v_up (m/s). */
typedef struct {
    double w_s;
    double sx, sy, sz;
    double sxx, syy, sxy, szz;
    double sxz, syz;
} sf_heading_moments_t;

/* Audit record of the last closed step window. */
typedef struct {
    int64_t t_us;
    bool window_ok;   /* duration and sample count usable */
    bool good;        /* became an offset sample */
    double ratio;     /* λ1/λ2 of the summed covariance */
    double corr;      /* corr(a_forward, v_up) after the sign choice (≤ 0 when resolved) */
    double offset_rad; /* this step's offset sample (axis angle in the yaw frame) */
} sf_heading_step_audit_t;

typedef struct {
    bool started;
    int64_t last_t_us;
    double up_mean_mps2; /* low-passed vertical acceleration (≈ g when gravity is included) */
    double v_up_mps;
    sf_heading_moments_t window; /* open step window */
    int64_t window_start_t_us;
    int32_t window_samples;
    sf_heading_moments_t sum; /* closed windows with forgetting */
    double mean_c, mean_s, mean_w; /* circular mean (exponential) of the offset samples */
    int32_t steps;      /* sf_heading_on_step calls */
    int32_t good_steps;
    bool confident;
    double offset_rad;  /* the estimate; used when confident */
    uint32_t gaps;
    uint32_t time_errors; /* interval ≤ 0 */
    uint32_t invalid;     /* non-finite input: sample skipped */
    uint32_t windows_rejected;
    uint32_t windows_discarded; /* sf_heading_discard_step */
    sf_heading_step_audit_t last_step;
} sf_heading_t;
_Static_assert(sizeof(sf_heading_t) < 400, "sf_heading.h promises less than 400 B");

/* Empty statistics; the offset starts at heading_mount_offset_deg (not confident). */
void sf_heading_init(sf_heading_t *h, const sf_params_t *p);

/* One IMU sample: specific force rotated into nav (m/s², see the header) and the device yaw (rad). */
void sf_heading_update(sf_heading_t *h, const sf_params_t *p, int64_t t_us, const double accel_nav_mps2[3],
                       double device_yaw_rad);

/* The same with the yaw given as its cosine and sine (sf_attitude_yaw_dir), which is all the window
 * needs: the caller that has the attitude saves the sincos. */
void sf_heading_update_dir(sf_heading_t *h, const sf_params_t *p, int64_t t_us, const double accel_nav_mps2[3],
                           double cos_yaw, double sin_yaw);

/* A step was detected at t_us: closes the step window, updates the offset estimate. */
void sf_heading_on_step(sf_heading_t *h, const sf_params_t *p, int64_t t_us);

/* A detection at t_us that is not a step of a walk (the activity refused it: a gesture, handling the
 * device while standing): closes the step window without using it (counted in windows_discarded).
 * The calibration gestures a phone's walk begins with otherwise taught the offset a flipped axis
 * (ipin2023: 170–180° off for the first seconds of the walk). */
void sf_heading_discard_step(sf_heading_t *h, int64_t t_us);

/* Mounting offset in use (rad, (−π, π]): the estimate when confident, else heading_mount_offset_deg. */
double sf_heading_offset_rad(const sf_heading_t *h, const sf_params_t *p);

/* Walking direction in the map frame, CCW from map +x, (−π, π]. */
double sf_heading_walk_rad(const sf_heading_t *h, const sf_params_t *p, double device_yaw_rad);

#endif
