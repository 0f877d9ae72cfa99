/* sf_estimator.h — the pedestrian dead-reckoning estimator: one pure step per input.
 *
 * Pipeline per IMU sample (each stage is its own module; see their headers for the models):
 *   attitude (sf_attitude: complementary or Mahony, magnetometer gated)  → specific force in nav
 *   a_v = f_nav·up − ĝ (ĝ: low-pass of f_nav·up, estimator_gravity_tau_s)
 *   heading (sf_heading: mounting offset from the gait)   activity (sf_activity: a_v variance)
 *   steps (sf_steps: Pan–Tompkins or trough-peak)  → step event
 *   the step is accepted by sf_activity (a body that quiet is not walking: no drift while still; a
 *   lone detection is no walk: the first step of a bout is credited when the second confirms it),
 *   its length is Weinberg's (sf_stride), its direction the walking direction in the map frame, and
 *   the position advances by length·(cos h, sin h).
 * MAG samples pass the online hard-iron calibration (sf_magcal: sphere fit, disturbance gated), and
 * the corrected field goes to the attitude; BARO samples to the floor (sf_floor), whose vertical
 * speed feeds the activity (stairs, elevator).
 *
 * Heading without a magnetometer: the yaw is then relative (it starts at 0), and the walking
 * direction is init_heading_rad + yaw + offset; once a magnetometer sample is accepted the yaw is
 * magnetic and the map rotation applies.
 *
 * Position uncertainty: σ grows by estimator_sigma_per_m per metre walked (stride scale and heading
 * errors make PDR error proportional to distance); absolute fixes (issue 4) will shrink it.
 *
 * No heap, no I/O, no clock, no hidden state: the same inputs give bit-identical outputs.
 * Memory: sizeof(sf_estimator_t) ≈ 4.5 KiB. Cost per IMU sample: a few hundred flops; per MAG sample
 * a few kflop (the sf_magcal solve). */
#ifndef SF_ESTIMATOR_H
#define SF_ESTIMATOR_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_activity.h"
#include "sf_attitude.h"
#include "sf_floor.h"
#include "sf_heading.h"
#include "sf_magcal.h"
#include "sf_params.h"
#include "sf_steps.h"
#include "sf_stride.h"
#include "sf_types.h"

typedef struct {
    sf_attitude_t attitude;
    sf_magcal_t magcal;
    sf_heading_t heading;
    sf_steps_t steps;
    sf_stride_t stride;
    sf_activity_t activity;
    sf_floor_t floor;
    bool started;
    int64_t t_us;        /* newest input time */
    double gravity_mps2; /* ĝ */
    double accel_v_mps2; /* latest a_v */
    double x_m;
    double y_m;
    double heading_rad; /* latest walking direction, map frame */
    double distance_m;  /* walked since start */
    double sigma_m;
    double weinberg_sum; /* Σ range^¼ since the last stride calibration (for absolute fixes) */
    int32_t step_count;
    uint32_t steps_refused; /* detector steps the activity refused (quiet body) */
    sf_step_event_t held_event; /* the held first step of a bout (sf_activity.h) */
} sf_estimator_t;

void sf_estimator_init(sf_estimator_t *est, const sf_params_t *p);

/* Most steps one IMU sample can credit: a bout's held first step and the step that confirms it. */
#define SF_ESTIMATOR_MAX_STEPS 2

/* One IMU sample. Returns how many steps it credited (0..SF_ESTIMATOR_MAX_STEPS) and fills steps[]
 * in order; the position has then moved by each. The first detection of a bout is held until a
 * second one confirms it (sf_activity.h), so a lone jolt never moves the position. */
int sf_estimator_imu(sf_estimator_t *est, const sf_params_t *p, const sf_imu_sample_t *sample,
                     sf_step_t steps[SF_ESTIMATOR_MAX_STEPS]);

/* One magnetometer sample [µT], sensor axes, raw (sf_magcal removes the hard-iron offset). */
void sf_estimator_mag(sf_estimator_t *est, const sf_params_t *p, int64_t t_us, const double field_ut[3]);

/* One barometer sample [Pa]. */
void sf_estimator_baro(sf_estimator_t *est, const sf_params_t *p, int64_t t_us, double pressure_pa);

/* The current pose (time = newest input time). */
void sf_estimator_pose(const sf_estimator_t *est, sf_pose_t *pose);

#endif
