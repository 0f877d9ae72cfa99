/* sf_pdr.h — first pedestrian dead reckoning: steps from vertical acceleration, fixed stride,
 * heading from the gyroscope.
 *
 * Model. Gravity is tracked as a first-order low-pass of the specific force (time constant
 * pdr_gravity_tau_s), so "vertical" is the gravity direction whatever way the board is mounted.
 * Vertical acceleration a_v = f·ĝ − |g| is low-passed at pdr_accel_cutoff_hz. A step is the maximum
 * of a_v over an excursion above pdr_step_threshold_mps2, provided pdr_step_min_interval_ms passed
 * since the previous step (the refractory time of the auto-adaptive DR paper's detector). Heading
 * integrates the angular rate about the gravity axis (ω·ĝ), starting at init_heading_rad; each step
 * advances the position by pdr_stride_m along the heading.
 *
 * Not yet (issue 3): stride estimation, gyro bias, magnetometer, activity, floors.
 * Cost: O(1) per sample, a few dozen flops; memory: sizeof(sf_pdr_t) (< 200 bytes). No heap, no I/O. */
#ifndef SF_PDR_H
#define SF_PDR_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_params.h"
#include "sf_types.h"

typedef struct {
    bool started;
    int64_t last_t_us;
    double gravity_mps2[3]; /* low-passed specific force */
    double accel_v_mps2;    /* low-passed vertical acceleration */
    bool above;             /* a_v currently above the threshold */
    double peak_mps2;
    int64_t peak_t_us;
    int64_t last_step_t_us;
    double step_max_mps2; /* extremes of a_v since the previous step */
    double step_min_mps2;
    double heading_rad;
    double x_m;
    double y_m;
    int32_t step_count;
    uint32_t gaps; /* times integration restarted after a gap or a backwards time */
} sf_pdr_t;

/* Starts at the params' init pose. */
void sf_pdr_init(sf_pdr_t *pdr, const sf_params_t *params);

/* Consumes one sample. Returns true and fills *step when this sample completed a step; the
 * position has then already moved. Samples must come in time order; a sample at or before the
 * previous time, or after a gap longer than pdr_max_gap_ms, restarts the filters (counted in gaps). */
bool sf_pdr_update(sf_pdr_t *pdr, const sf_params_t *params, const sf_imu_sample_t *sample, sf_step_t *step);

/* The current pose at time t_us (the time of the last sample). */
void sf_pdr_pose(const sf_pdr_t *pdr, const sf_params_t *params, sf_pose_t *pose);

#endif
