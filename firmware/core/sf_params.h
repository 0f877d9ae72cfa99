/* sf_params.h — every tunable of the estimator and the daemon, in one place.
 *
 * SF_PARAM_LIST is the single source: each row gives section, name, C type, default, min, max, unit
 * and meaning. From it come the sf_params_t struct (field `<section>_<name>`), the defaults, the
 * range checks, the config-file keys (`[section]` + `name = value`, see firmware/board/sf_config.h)
 * and the CONFIG message echo (key `section.name`). Adding a parameter is adding one row (PX4's
 * params yaml, in C). */
#ifndef SF_PARAMS_H
#define SF_PARAMS_H

#include <stddef.h>
#include <stdint.h>

#include "sf_schemes.h"
#include "sf_types.h"

/* Rows are grouped by concern, one macro per core module, so each module's parameters sit together.
 *        section   name                 type     default  min      max      unit     meaning */
#define SF_PARAMS_INIT(X)                                                                              \
    X(init,   x_m,                 double,  0.0,     -1e6,    1e6,     "m",     "start position x, map frame")  \
    X(init,   y_m,                 double,  0.0,     -1e6,    1e6,     "m",     "start position y, map frame")  \
    X(init,   heading_rad,         double,  0.0,     -7.0,    7.0,     "rad",   "start walking direction, CCW from +x") \
    X(init,   floor,               int32_t, 0,       -20,     200,     "",      "start floor index")            \
    X(init,   use_config_pose,     int32_t, 0,       0,       1,       "",      "1 = every scheme starts at init.x_m/y_m (truth-initialised); 0 = from the first fix (always 1 without a site)") \
    X(init,   sigma_m,             double,  1.0,     0.0,     1e3,     "m",     "position sigma of a config start")

/* sf_sample_gate.h: full scales are the board's sensors' (docs/DESIGN.md: int16, ±16 g, ±2000 °/s);
 * rates are what a human body produces, with a wide margin: walking and running jerk at the trunk
 * stays below ~2500 m/s3, fast wrist rotation below ~400 rad/s2, an elevator changes pressure by
 * ~120 Pa/s; the floors cover sensor noise and irregular sample timing. */
#define SF_PARAMS_GATE(X)                                                                              \
    X(gate, accel_full_scale_mps2, double, 156.9,   1.0,     2000.0,  "m/s2",  "accelerometer full scale: a sample at or beyond it per axis is refused") \
    X(gate, accel_jump_floor_mps2, double, 20.0,    0.0,     4000.0,  "m/s2",  "accelerometer change always allowed between accepted samples") \
    X(gate, accel_rate_max_mps3,   double, 5000.0,  0.0,     1e7,     "m/s3",  "fastest accelerometer change a body produces (jerk), per axis") \
    X(gate, gyro_full_scale_radps, double, 34.9,    0.1,     200.0,   "rad/s", "gyroscope full scale (2000 deg/s)") \
    X(gate, gyro_jump_floor_radps, double, 1.0,     0.0,     400.0,   "rad/s", "gyroscope change always allowed between accepted samples") \
    X(gate, gyro_rate_max_radps2,  double, 1000.0,  0.0,     1e7,     "rad/s2", "fastest angular acceleration a body produces, per axis") \
    X(gate, mag_full_scale_ut,     double, 4900.0,  1.0,     1e5,     "uT",    "magnetometer full scale") \
    X(gate, mag_jump_floor_ut,     double, 100.0,   0.0,     1e5,     "uT",    "magnetometer change always allowed (indoor disturbances are the attitude's to reject)") \
    X(gate, mag_rate_max_ut_s,     double, 10000.0, 0.0,     1e8,     "uT/s",  "fastest magnetometer change accepted, per axis") \
    X(gate, baro_min_pa,           double, 30000.0, 0.0,     2e5,     "Pa",    "lowest plausible pressure (above Everest's summit)") \
    X(gate, baro_max_pa,           double, 120000.0, 0.0,    2e5,     "Pa",    "highest plausible pressure (below any mine's depth)") \
    X(gate, baro_jump_floor_pa,    double, 20.0,    0.0,     1e5,     "Pa",    "pressure change always allowed (noise, door and ventilation transients)") \
    X(gate, baro_rate_max_pa_s,    double, 1000.0,  0.0,     1e7,     "Pa/s",  "fastest pressure change accepted (8x a fast elevator)")

/* sf_gap_bridge.h */
#define SF_PARAMS_GAP(X)                                                                               \
    X(gap,  bridge,                int32_t, 1,       0,       1,       "",      "1 = dead-reckon across an IMU gap the walk went through (bus silence, board reset)") \
    X(gap,  min_s,                 double,  1.0,     0.1,     60.0,    "s",     "IMU gaps at least this long are bridged (shorter ones lose less than two steps)") \
    X(gap,  max_s,                 double,  30.0,    0.0,     600.0,   "s",     "longer gaps are not guessed") \
    X(gap,  walking_s,             double,  2.0,     0.1,     10.0,    "s",     "a step this close before the gap and after it: the walk went on through it")

/* sf_estimator.h */
#define SF_PARAMS_ESTIMATOR(X)                                                                         \
    X(estimator, gravity_tau_s,    double,  2.0,     0.1,     60.0,    "s",     "time constant of the gravity magnitude low-pass (a_v = f_up - g)") \
    X(estimator, sigma_per_m,      double,  0.03,    0.0,     1.0,     "m/m",   "position sigma growth per metre walked (PDR drift)")

/* sf_attitude.h, sf_heading.h */
#define SF_PARAMS_ATTITUDE(X)                                                                          \
    X(attitude, mode,                int32_t, 1,       0,       1,       "",      "0 = complementary (Ramadhan 2016), 1 = Mahony (with gyro bias; the default: better heading in SIL)") \
    X(attitude, tau_s,               double,  0.75,    0.02,    30.0,    "s",     "complementary time constant: alpha = tau/(tau+dt)") \
    X(attitude, mahony_kp,           double,  1.0,     0.0,     20.0,    "1/s",   "Mahony proportional gain on the gravity error") \
    X(attitude, mahony_ki,           double,  0.1,     0.0,     5.0,     "1/s2",  "Mahony integral gain (gyro bias) on the gravity error") \
    X(attitude, mahony_ki_mag,       double,  0.0,     0.0,     5.0,     "1/s2",  "Mahony integral gain (gyro bias) on the magnetometer yaw error; 0: indoors that error is mostly disturbance (steel: 10-40 deg over metres), not bias; the bias is learnt at rest and from gravity") \
    X(attitude, mahony_kp_mag,       double,  1.0,     0.0,     20.0,    "1/s",   "Mahony proportional gain on the magnetometer yaw error") \
    X(attitude, accel_gate_mps2,     double,  2.0,     0.05,    50.0,    "m/s2",  "| |a| - g | above which the accelerometer does not correct tilt") \
    X(attitude, rest_gyro_radps,     double,  0.05,    0.001,   1.0,     "rad/s", "rest: bias-corrected gyro norm below this") \
    X(attitude, rest_accel_mps2,     double,  0.3,     0.01,    5.0,     "m/s2",  "rest: | |a| - g | below this") \
    X(attitude, rest_time_s,         double,  1.0,     0.05,    60.0,    "s",     "rest: both conditions held this long") \
    X(attitude, rest_bias_tau_s,     double,  2.0,     0.05,    100.0,   "s",     "Mahony: gyro-bias low-pass time constant while at rest") \
    X(attitude, gyro_bias_max_radps, double,  0.1,     0.0,     1.0,     "rad/s", "bound on each estimated gyro-bias component") \
    X(attitude, max_gap_ms,          int32_t, 500,     20,      10000,   "ms",    "IMU gap beyond which the gyro is not integrated") \
    X(attitude, mag_field_ut,        double,  48.0,    1.0,     200.0,   "uT",    "expected undisturbed field strength") \
    X(attitude, mag_dip_deg,         double,  60.0,    -90.0,   90.0,    "deg",   "expected dip (inclination), positive downwards") \
    X(attitude, mag_field_tol_ut,    double,  8.0,     0.1,     1e6,     "uT",    "accepted | |m| - field | (huge = rejection off)") \
    X(attitude, mag_dip_tol_deg,     double,  8.0,     0.1,     360.0,   "deg",   "accepted | dip - expected dip | (>= 180 = off)") \
    X(attitude, mag_settle_s,        double,  1.0,     0.0,     60.0,    "s",     "field consistent this long before use after a rejection") \
    X(attitude, mag_acquire_s,       double,  10.0,    0.0,     600.0,   "s",     "first seconds of magnetometer data: field/dip references follow the data (the site's field, unknown a priori); 0 = use mag_field_ut/mag_dip_deg") \
    X(attitude, mag_acquire_gyro_radps, double, 1.0,   0.01,    100.0,   "rad/s", "acquisition uses a sample only while |gyro - bias| is below this: the dip needs the accelerometer's tilt, which calibration gestures (3-7 rad/s) spoil; a walk sways at <= 1 rad/s (sf_activity.h)") \
    X(attitude, mag_reacquire_s,     double,  20.0,    0.0,     3600.0,  "s",     "field/dip out of tolerance this long without a break: acquire the references again (steel disturbs over metres, a few seconds of walking; longer is a changed site field or sensor calibration); 0 = never") \
    X(attitude, mag_learn_tau_s,     double,  60.0,    0.0,     3600.0,  "s",     "learn field/dip from accepted samples (0 = off); bounded to +-tol") \
    X(heading,  map_rotation_deg,    double,  0.0,     -360.0,  360.0,   "deg",   "map heading = ENU heading - rotation (set by the site file)") \
    X(heading,  mount_offset_deg,    double,  0.0,     -180.0,  180.0,   "deg",   "walking direction minus device yaw, until estimated") \
    X(heading,  learn_offset,        int32_t, 1,       0,       1,       "",      "1 = estimate the mounting offset from the gait (body-worn board); 0 = keep mount_offset_deg (a hand-held phone, whose gait estimate wanders: realbench picks per fold from the training walks)") \
    X(heading,  window_steps,        double,  4.0,     1.0,     50.0,    "steps", "memory of the acceleration covariances, in steps") \
    X(heading,  smooth_steps,        double,  6.0,     1.0,     200.0,   "steps", "memory of the circular mean of the offset") \
    X(heading,  min_steps,           int32_t, 10,      1,       1000,    "steps", "good steps before the estimated offset is used") \
    X(heading,  min_resultant,       double,  0.5,     0.0,     1.0,     "",      "mean resultant length of the smoothed offset samples needed to adopt (and keep updating) the estimate") \
    X(heading,  pca_min_ratio,       double,  2.0,     1.0,     1000.0,  "",      "unused since the axis comes from cov(a_h, v_up); kept for configs") \
    X(heading,  min_corr,            double,  0.2,     0.0,     1.0,     "",      "|corr(a_forward, v_up)| for a good step") \
    X(heading,  vz_tau_s,            double,  1.0,     0.1,     20.0,    "s",     "leak of the vertical-velocity integrator")

/* sf_magcal.h */
#define SF_PARAMS_MAGCAL(X)                                                                            \
    X(magcal, enable,              int32_t, 1,       0,       1,       "",      "online hard-iron calibration: 1 = on, 0 = off (field used as measured)") \
    X(magcal, tau_s,               double,  600.0,   10.0,    1e5,     "s",     "memory of the sphere fit (exponential forgetting time constant)") \
    X(magcal, ridge_ut,            double,  0.5,     0.0,     100.0,   "uT",    "ridge prior toward b = 0 on observed directions: weight 4 W ridge^2, shrink ridge^2/(spread^2+ridge^2)") \
    X(magcal, min_spread_ut,       double,  6.0,     0.1,     200.0,   "uT",    "RMS spread of the samples along a direction for it to be observed (180 deg turn: 0.31 H)") \
    X(magcal, max_offset_ut,       double,  30.0,    0.0,     500.0,   "uT",    "bound on |b|: a larger solution is not taken") \
    X(magcal, gate_ut,             double,  5.0,     0.1,     1e6,     "uT",    "use a sample when | |m - b| - R | <= gate (before the first fit: gate + max_offset around attitude.mag_field_ut)") \
    X(magcal, max_rms_ut,          double,  2.0,     0.05,    1e6,     "uT",    "take a fit only when the RMS of |m - b| - R over the memory is below this (before the first fit: restart the memory)")

/* sf_steps.h, sf_stride.h */
#define SF_PARAMS_STEPS(X)                                                                             \
    X(steps,  detector,            int32_t, 0,       0,       1,       "",      "0 = Pan-Tompkins (Jaeger et al.), 1 = trough-then-peak (SmartLocator)") \
    X(steps,  refractory_ms,       int32_t, 300,     100,     2000,    "ms",    "minimum time between two steps (both detectors)") \
    X(steps,  max_gap_ms,          int32_t, 500,     20,      10000,   "ms",    "a_v gap beyond which the filters and the detector restart") \
    X(steps,  max_period_ms,       int32_t, 2000,    500,     2500,    "ms",    "a step later than this after the previous one starts a walk (period 0)") \
    X(steps,  pt_lowpass_hz,       double,  5.0,     1.0,     20.0,    "Hz",    "Pan-Tompkins: low-pass of a_v before the derivative") \
    X(steps,  pt_threshold,        double,  0.15,     0.01,    100.0,   "",      "Pan-Tompkins: lowest threshold on the peak of (1+y)^2-1, y = 50 Hz derivative in m/s2") \
    X(steps,  pt_adaptive,         double,  0.1,    0.0,     1.0,     "",      "Pan-Tompkins: threshold = NPK + this x (SPK - NPK), as in the QRS detector; 0 = fixed") \
    X(steps,  pt_noise_factor,     double,  2,     0.0,     20.0,    "",      "Pan-Tompkins: threshold at least this x NPK (the level of non-step peaks: sensor noise when still)") \
    X(steps,  min_range_mps2,      double,  0.5,     0.0,     20.0,    "m/s2",  "both detectors: smallest a_v range (amax - amin, 3 Hz) over a step") \
    X(steps,  tp_lowpass_hz,       double,  3.0,     0.5,     10.0,    "Hz",    "trough-peak: low-pass of a_v (also the amax/amin signal)") \
    X(steps,  tp_max_interval_ms,  int32_t, 800,     100,     3000,    "ms",    "trough-peak: longest trough-to-peak time") \
    X(steps,  tp_min_rise_mps2,    double,  1.0,     0.05,    20.0,    "m/s2",  "trough-peak: smallest peak minus trough") \
    X(stride, weinberg_k,          double,  0.47,    0.05,    2.0,     "m/(m/s2)^0.25", "Weinberg K: length = K (amax-amin)^(1/4), start value") \
    X(stride, k_min,               double,  0.25,    0.05,    2.0,     "m/(m/s2)^0.25", "lowest K that calibration may reach") \
    X(stride, k_max,               double,  0.80,    0.05,    2.0,     "m/(m/s2)^0.25", "highest K that calibration may reach") \
    X(stride, k_gain,              double,  0.3,     0.0,     1.0,     "",      "fraction of the way K moves toward distance/sum per calibration") \
    X(stride, k_max_change,        double,  0.10,    0.0,     1.0,     "",      "bound on |K_new/K - 1| per calibration") \
    X(stride, min_calib_distance_m, double, 20.0,    1.0,     10000.0, "m",     "shortest fix-to-fix walk used for calibration") \
    X(stride, calib_straightness,  double,  0.9,     0.0,     1.0,     "",      "calibrate only over walks whose PDR displacement is at least this x distance walked") \
    X(stride, calib_enable,        int32_t, 1,       0,       1,       "",      "1 = recalibrate K online from accepted Kalman fixes (needs a site)")

/* sf_activity.h, sf_floor.h, sf_floor_vote.h */
#define SF_PARAMS_ACTIVITY(X)                                                                          \
    X(activity, var_tau_s,         double,  1.0,     0.1,     20.0,    "s",     "time constant of the a_v mean/variance") \
    X(activity, still_var_m2ps4,   double,  0.05,    0.0,     100.0,   "m2/s4", "a_v variance below which the body is quiet (steps rejected)") \
    X(activity, min_step_period_ms, int32_t, 400,    200,     2000,    "ms",    "a detection this soon after a bout's previous held one does not continue it") \
    X(activity, still_time_ms,     int32_t, 2000,    100,     60000,   "ms",    "no step for this long (and quiet) is still") \
    X(activity, step_window_ms,    int32_t, 2500,    500,     10000,   "ms",    "steps counted over this window for the step rate") \
    X(activity, min_steps,         int32_t, 2,       1,       8,       "steps", "steps in the window needed to be walking") \
    X(activity, bout_steps,        int32_t, 3,       2,       8,       "steps", "detections held before a walk is credited: 3 = a gait cycle and the next step. A hand-held phone handled while standing (picked up, turned, the calibration figure-eights) makes detections in pairs, which one cycle (2) credited (ipin2023 truth-initialised PDR mean: 2: 6.79 m, 3: 6.32, 4: 5.68); 4 lost real short walks on msindoor (site1/F2 first-fix controller 4.32 -> 4.64 m)") \
    X(activity, bout_rhythm,       double,  0.35,    0.0,     10.0,    "",      "a held bout continues only when the interval to a detection is within 1/(1+r) .. (1+r) of the held interval before it: steady walking varies 2-4 % step to step (Hausdorff 2005), gait initiation more; handling a phone while standing is arrhythmic; 0 = off") \
    X(activity, max_rotation_radps, double, 3.14159, 0.1,     100.0,   "rad/s", "mean |gyro| above which detections are gestures, not steps: a U-turn takes a walker at least one stride (1 s)") \
    X(activity, max_off_axis_radps, double, 1.0,     0.1,     100.0,   "rad/s", "RMS gyro rate about the second principal axis above which detections are gestures: a walker turns about one axis at a time, the others only sway (5 deg at 2.5 Hz: 0.97 rad/s); at a slower cadence f the bound is this x f / 2.5 Hz, the same 5 deg sway") \
    X(activity, stairs_vspeed_mps, double,  0.15,    0.01,    5.0,     "m/s",   "|baro vertical speed| beyond this while stepping is stairs") \
    X(activity, elevator_vspeed_mps, double, 0.30,   0.01,    10.0,    "m/s",   "|baro vertical speed| beyond this without steps is an elevator") \
    X(floor,  height_m,            double,  3.5,     1.0,     20.0,    "m",     "uniform floor-to-floor height (until a site file gives a table)") \
    X(floor,  height_tau_s,        double,  1.0,     0.05,    30.0,    "s",     "low-pass time constant of the baro height") \
    X(floor,  vspeed_tau_s,        double,  1.0,     0.05,    30.0,    "s",     "low-pass time constant of the vertical speed") \
    X(floor,  hysteresis_m,        double,  0.15,    0.0,     5.0,     "m",     "height beyond the mid-floor boundary before a floor change counts (> 3 sigma of the filtered height)") \
    X(floor,  confirm_ms,          int32_t, 500,     0,       60000,   "ms",    "the new floor must hold this long") \
    X(floor,  settle_vspeed_mps,   double,  0.10,    0.01,    5.0,     "m/s",   "|vertical speed| below which the altimeter may be re-referenced") \
    X(floor,  drift_tau_s,         double,  120.0,   1.0,     1e6,     "s",     "while settled, height relaxes to the floor's height (drift removal)") \
    X(floor,  weather_max_hpa_per_h, double, 3.0,    0.0,     100.0,   "hPa/h", "fastest weather pressure tendency (1 hPa/h is already 'rapid' in aviation, 3 hPa/h a severe storm): leaving a floor closes a height gap up to this x drift_tau_s (0.83 m), a larger one is a pause on the stairs") \
    X(floor,  max_gap_ms,          int32_t, 5000,    100,     600000,  "ms",    "baro gap beyond which the filters restart") \
    X(floor,  vote_margin,         double,  3.0,     0.5,     1000.0,  "fixes", "start-floor vote (sf_floor_vote.h): lead in full-weight agreeing fixes that decides or moves the start floor; 3: a floor classifier right 80 % of the time among 3 floors is then 512 times likelier right than wrong ((0.8/0.1)^3), and one scan never flips") \
    X(floor,  between_reject,      int32_t, 1,       0,       1,       "",      "1 = fixes taken between floors (stairs, a moving lift, a landing half-way up; multi-floor sites) are rejected FLOOR_MISMATCH: a radio map is of floors (SIL tour: such fixes 6.9 m mean error against 1.2 m on the floors; gsd Trial51, open stairs: 4.8 against 4.3 m)")

/* firmware/board (sf_board_rx.h): how the CAN decoder turns the BLE_ADV and LANDMARK frames into events
 * (listed just before SF_PARAMS_SOURCES, so that the [ble] keys stay together). */
#define SF_PARAMS_BOARD_INPUT(X)                                                                       \
    X(landmark, accuracy_m,        double,  0.3,     0.01,    100.0,   "m",     "1-sigma position of a LANDMARK frame (the frame has none): an NFC reader's range, a few decimetres") \
    X(ble,    window_ms,           int32_t, 1000,    100,     60000,   "ms",    "BLE advertisements of this much board time (from the window's first) form one scan; a beacon heard several times in it is averaged in dBm")

#define SF_PARAMS_OUTPUT(X)                                                                            \
    X(output, scheme,              int32_t, -1,      -1,      SF_SCHEME_CONTROLLER, "", "fusion scheme published in POSE_<SCHEME> and FIX (POSE: the primary, its copy): -1 = every scheme side by side (and the controller's pose on POSE), else pose_t.SCHEME_* (SCHEME_CONTROLLER: only the controller's POSE)") \
    X(output, pose_period_ms,      int32_t, 100,     10,      60000,   "ms",    "POSE publish period between steps (also on every step and floor change)") \
    X(output, health_period_ms,    int32_t, 1000,    100,     60000,   "ms",    "HEALTH publish period (board time)") \
    X(output, fsync_interval_ms,   int32_t, 1000,    0,       60000,   "ms",    "the log writer fdatasyncs at least this often (0: after every event, one disk sync each: slow): what power loss may cost") \
    X(output, log_rotate_mb,       int32_t, 0,       0,       1000000, "MB",    "start a new log file before one would exceed this size (0: no size rotation)") \
    X(output, log_rotate_s,        int32_t, 0,       0,       604800,  "s",     "start a new log file when one is this old (0: no time rotation; SIGHUP rotates too)")

/* sf_fingerprint.h */
#define SF_PARAMS_FINGERPRINT(X)                                                                       \
    X(fingerprint, method,         int32_t, 0,       0,       1,       "",      "0 = WkNN (Ramadhan 2016, SmartLocator), 1 = Gaussian naive Bayes (Jaeger et al.)") \
    X(fingerprint, k,              int32_t, 3,       1,       16,      "RPs",   "neighbours averaged: WkNN the k nearest (1/d weights), naive Bayes the k most probable (posterior weights)") \
    X(fingerprint, missing_mode,   int32_t, 0,       0,       1,       "",      "WkNN: 0 = an AP missing on one side takes fill_dbm, 1 = common APs only (RMS over them)") \
    X(fingerprint, fill_dbm,       double,  -100.0,  -150.0,  -30.0,   "dBm",   "level of an AP not heard (WkNN mode 0; naive Bayes: mean of an AP the map lacks at an RP)") \
    X(fingerprint, map_level,      int32_t, 1,       0,       1,       "",      "WkNN map level of an AP at an RP: 1 = mean over all the RP's scans, misses at fill_dbm; 0 = mean of the scans that heard it") \
    X(fingerprint, powed_beta,     double,  1.0,     1.0,     5.0,     "",      "WkNN representation: 1 = dBm above fill_dbm; > 1 = 'powed' |fill|((v - fill)/|fill|)^beta (Torres-Sospedra 2015: e)") \
    X(fingerprint, preselect_aps,  int32_t, 4,       0,       16,      "APs",   "WkNN fill mode on a large map: the partial distance over this many strongest used APs (the nearest few carry the position) ranks the RPs they reach, and only the best-ranked are scored in full; 0 = score every RP sharing an AP") \
    X(fingerprint, preselect_rps,  int32_t, 32,      1,       256,     "RPs",   "pre-selection: this many best-ranked RPs scored in full (about 10 k; 32 cells of 2 m cover a 6 m radius)") \
    X(fingerprint, preselect_min_scans, int32_t, 3,  1,       1000,    "scans", "pre-selection only on maps of at least this many scans per RP (surveyed: an AP heard 70% of the time is missing at 2.7% of RPs after 3 scans, 30% after 1)") \
    X(fingerprint, min_common_aps, int32_t, 2,       1,       64,      "APs",   "WkNN mode 1: fewest APs shared with the scan for an RP to be a candidate") \
    X(fingerprint, min_rssi_dbm,   double,  -90.0,   -150.0,  0.0,     "dBm",   "scan readings weaker than this are ignored") \
    X(fingerprint, min_aps,        int32_t, 3,       1,       64,      "APs",   "fewest usable APs (at least min_rssi_dbm and in the map) for a fix") \
    X(fingerprint, average_scans,  int32_t, 1,       1,       4,       "scans", "query = per-BSSID mean over the last n scans that heard it (SmartLocator: 3)") \
    X(fingerprint, average_max_age_ms, int32_t, 10000, 0,     600000,  "ms",    "scans older than this before the current one are not averaged") \
    X(fingerprint, sigma_floor_db, double,  4.0,     0.1,     50.0,    "dB",    "naive Bayes: lower bound on an RP's RSSI std") \
    X(fingerprint, nb_p_min,       double,  0.05,    0.001,   0.5,     "",      "naive Bayes: detection probability clamped to [p, 1-p]; an AP the map lacks at an RP is heard with p") \
    X(fingerprint, accuracy_floor_m, double, 1.5,    0.0,     100.0,   "m",     "fix accuracy: added in quadrature to the neighbours' spread") \
    X(fingerprint, accuracy_ref_aps, int32_t, 6,     1,       64,      "APs",   "fix accuracy x sqrt(ref / APs used) when fewer APs are used")

/* sf_ble.h, sf_geo.h, sf_estimator.h: the absolute sources besides Wi-Fi. BLE: a phone hears
 * iBeacons down to about −100 dBm; below −95 dBm a reading is at the noise floor and says "far", not
 * how far. GNSS: receivers report 1σ-ish accuracy; indoors it grows to tens of metres, and a fix
 * claiming more than 50 m is no position within a building. */
#define SF_PARAMS_SOURCES(X)                                                                           \
    X(ble,  min_rssi_dbm,          double,  -95.0,   -150.0,  0.0,     "dBm",   "BLE readings weaker than this are ignored") \
    X(ble,  max_range_m,           double,  15.0,    1.0,     100.0,   "m",     "readings the site's path-loss model puts farther than this are not used (at 4-5 dB of shadowing a range is good to a factor ~1.8: beyond ~15 m it no longer says where in a building)") \
    X(ble,  min_beacons,           int32_t, 1,       1,       8,       "beacons", "fewest usable beacons for a BLE fix (one gives a disc about the beacon)") \
    X(ble,  same_floor,            int32_t, 1,       0,       1,       "",      "1 = only beacons on the caller's floor are used (a floor slab attenuates ~15-20 dB, which the model lacks)") \
    X(ble,  min_accuracy_m,        double,  1.0,     0.0,     100.0,   "m",     "lower bound on a BLE fix's accuracy (1 sigma)") \
    X(ble,  position_sigma_m,      double,  3.0,     0.0,     100.0,   "m",     "1 sigma of a beacon's position, added in quadrature to a BLE fix's accuracy (a beacon placed by walks with truth, radiomap/beacons.py, is known to metres; a surveyed table to about 1 m)") \
    X(ble,  floor_vote_range_m,    double,  6.0,     0.0,     50.0,    "m",     "site without BLE constellations: a beacon whose RSSI puts it this near by the site's path-loss model votes for its floor (one slab, 15-20 dB, makes a beacon of another floor read 5-10x farther); 0 = never") \
    X(gnss, use,                   int32_t, 1,       0,       1,       "",      "1 = GNSS fixes are offered to the schemes (the site needs a geo-reference)") \
    X(gnss, max_accuracy_m,        double,  50.0,    0.0,     1e4,     "m",     "GNSS fixes reporting a worse accuracy are not used") \
    X(gnss, accuracy_scale,        double,  1.0,     0.1,     10.0,    "",      "the receiver's reported accuracy times this is the fix's 1 sigma") \
    X(gnss, min_accuracy_m,        double,  1.0,     0.0,     100.0,   "m",     "lower bound on a GNSS fix's accuracy (receivers round and under-report)") \
    X(quality, enable,             int32_t, 1,       0,       1,       "",      "1 = GNSS and BLE fixes are offered with their accuracy times what the walk's Wi-Fi fixes say they deliver (sf_source_quality.h); 0 = as reported") \
    X(quality, ref_max_age_s,      double,  10.0,    0.0,     600.0,   "s",     "a Wi-Fi fix is the reference for this long (the PDR displacement since is added; 10 s of walking drifts less than a fix errs)") \
    X(quality, memory_fixes,       double,  20.0,    1.0,     1e4,     "fixes", "a source's running means span this many comparisons (20 s of 1 Hz GNSS: long enough to average its noise, short enough to follow a walk into a basement)") \
    X(quality, min_fixes,          int32_t, 5,       1,       1000,    "fixes", "comparisons before a source's factor is used") \
    X(quality, max_factor,         double,  10.0,    1.0,     1000.0,  "",      "largest accuracy factor (a source 10x worse than it claims weighs 1 % of its claim)") \
    X(quality, max_rho,            double,  0.95,    0.0,     0.999,   "",      "largest lag-one correlation of a source's errors taken (0.95: 39 fixes count as one)")

/* sf_fusion.h */
#define SF_PARAMS_FUSION(X)                                                                            \
    X(fusion, gate_sigma,          double,  3.0,     0.5,     1e3,     "sigma", "innovation gate: reject when |nu|^2 > gate^2 S (2 dof: 3 passes 98.9% of consistent fixes)") \
    X(fusion, max_rejections,      int32_t, 3,       0,       1000,    "fixes", "consecutive rejections after which the next fix is accepted with alpha = 1 and the variance reset (SmartLocator CONF)") \
    X(fusion, static_alpha,        double,  0.5,     0.0,     1.0,     "",      "static scheme blend weight (Jaeger et al. baseline: half-way)") \
    X(fusion, q_step_m2_per_m,     double,  0.2,    0.0,     100.0,   "m2/m",  "position variance added per metre walked; PDR errors are mostly systematic (stride scale, heading bias), so a random walk needs more than the noise: 0.2 chosen on the SIL benches") \
    X(fusion, q_time_m2_per_s,     double,  0.005,   0.0,     100.0,   "m2/s",  "position variance added per second, per axis (missed steps, shuffling)") \
    X(fusion, var_min_m2,          double,  0.01,    1e-6,    1e4,     "m2",    "floor of every scheme position variance (keeps S > 0 and alpha < 1)") \
    X(fusion, acc_wifi_ap1,        double,  2.0,     0.0,     1000.0,  "APs",   "adaptive: Wi-Fi accuracy-factor knot 1, APs used (knots increasing; flat outside)") \
    X(fusion, acc_wifi_ap2,        double,  4.0,     0.0,     1000.0,  "APs",   "adaptive: Wi-Fi knot 2, APs used") \
    X(fusion, acc_wifi_ap3,        double,  6.0,     0.0,     1000.0,  "APs",   "adaptive: Wi-Fi knot 3, APs used") \
    X(fusion, acc_wifi_ap4,        double,  8.0,     0.0,     1000.0,  "APs",   "adaptive: Wi-Fi knot 4, APs used") \
    X(fusion, acc_wifi_val1,       double,  0.1,     0.0,     1.0,     "",      "adaptive: Wi-Fi accuracy factor at knot 1 (placeholder, not a paper value)") \
    X(fusion, acc_wifi_val2,       double,  0.25,    0.0,     1.0,     "",      "adaptive: Wi-Fi accuracy factor at knot 2 (placeholder)") \
    X(fusion, acc_wifi_val3,       double,  0.45,    0.0,     1.0,     "",      "adaptive: Wi-Fi accuracy factor at knot 3 (placeholder)") \
    X(fusion, acc_wifi_val4,       double,  0.6,     0.0,     1.0,     "",      "adaptive: Wi-Fi accuracy factor at knot 4 (placeholder)") \
    X(fusion, acc_wifi_scale,      double,  1.0,     0.0,     1.0,     "",      "adaptive: the Wi-Fi accuracy factors above times this (realbench learns it per fold: with ~100 APs per scan the AP count says little)") \
    X(fusion, acc_gnss_m1,         double,  6.0,     0.0,     1e4,     "m",     "adaptive: GNSS accuracy-factor knot 1, reported accuracy (knots increasing; flat outside)") \
    X(fusion, acc_gnss_m2,         double,  12.0,    0.0,     1e4,     "m",     "adaptive: GNSS knot 2, reported accuracy") \
    X(fusion, acc_gnss_m3,         double,  21.0,    0.0,     1e4,     "m",     "adaptive: GNSS knot 3, reported accuracy") \
    X(fusion, acc_gnss_m4,         double,  30.0,    0.0,     1e4,     "m",     "adaptive: GNSS knot 4, reported accuracy") \
    X(fusion, acc_gnss_val1,       double,  0.8,     0.0,     1.0,     "",      "adaptive: GNSS accuracy factor at knot 1 (placeholder: min(1 - acc/30 m, 0.8))") \
    X(fusion, acc_gnss_val2,       double,  0.6,     0.0,     1.0,     "",      "adaptive: GNSS accuracy factor at knot 2 (placeholder)") \
    X(fusion, acc_gnss_val3,       double,  0.3,     0.0,     1.0,     "",      "adaptive: GNSS accuracy factor at knot 3 (placeholder)") \
    X(fusion, acc_gnss_val4,       double,  0.0,     0.0,     1.0,     "",      "adaptive: GNSS accuracy factor at knot 4 (placeholder)") \
    X(fusion, acc_landmark,        double,  1.0,     0.0,     1.0,     "",      "adaptive: landmark accuracy factor (paper: NFC = 1, overwrite)") \
    X(fusion, drift_per_s,         double,  0.01,    0.0,     10.0,    "1/s",   "adaptive: drift term per second since the last accepted fix (placeholder)") \
    X(fusion, drift_max,           double,  0.5,     0.0,     1.0,     "",      "adaptive: cap of the drift term (placeholder)")

/* sf_ekf.h: the ekf scheme. Noise figures from the sensors' physics, not fitted to a data set. */
#define SF_PARAMS_EKF(X)                                                                               \
    X(ekf,    step_length_sigma,   double,  0.1,     0.0,     1.0,     "",      "step-length noise per step, relative (Weinberg's model scatters ~10 % step to step)") \
    X(ekf,    step_heading_sigma_rad, double, 0.1,   0.0,     1.0,     "rad",   "walking-direction noise per step (body sway ~6 deg step to step)") \
    X(ekf,    bias_rw_rad2_per_m,  double,  0.002,   0.0,     1.0,     "rad2/m","heading-bias random walk per metre walked (0.45 rad after 100 m: re-grips, magnetic disturbances)") \
    X(ekf,    scale_rw_per_m,      double,  1e-4,    0.0,     1.0,     "1/m",   "stride-scale random walk (variance) per metre walked (0.1 after 100 m: pace changes)") \
    X(ekf,    init_bias_sigma_rad, double,  0.5,     0.0,     3.2,     "rad",   "heading bias sigma at the start: unknown (a magnetometer indoors is off by tens of degrees)") \
    X(ekf,    init_scale_sigma,    double,  0.15,    0.0,     1.0,     "",      "stride-scale sigma at the start (walkers differ by ~15 % from Weinberg's K)") \
    X(ekf,    scale_min,           double,  0.5,     0.1,     1.0,     "",      "smallest stride scale") \
    X(ekf,    scale_max,           double,  2.0,     1.0,     10.0,    "",      "largest stride scale") \
    X(ekf,    fix_var_x_per_acc2,  double,  1.0,     1e-3,    1e3,     "",      "fix-error model prior: variance along x per accuracy_m^2 (1: the matcher's accuracy taken as its sigma; realbench measures it on the training walks)") \
    X(ekf,    fix_var_y_per_acc2,  double,  1.0,     1e-3,    1e3,     "",      "fix-error model prior: variance along y per accuracy_m^2") \
    X(ekf,    fix_cov_xy_per_acc2, double,  0.0,     -1e3,    1e3,     "",      "fix-error model prior: x-y covariance per accuracy_m^2 (kept positive definite)") \
    X(ekf,    fix_floor_xx_m2,     double,  0.0,     0.0,     1e4,     "m2",    "fix-error model: the part of one fix's error variance along x that does not scale with accuracy_m^2 (R = floor + accuracy^2 M)") \
    X(ekf,    fix_floor_yy_m2,     double,  0.0,     0.0,     1e4,     "m2",    "fix-error model: that part along y") \
    X(ekf,    fix_floor_xy_m2,     double,  0.0,     -1e4,    1e4,     "m2",    "fix-error model: that part's x-y covariance") \
    X(ekf,    fix_bias_sigma_m,    double,  0.0,     0.0,     100.0,   "m",     "sigma per axis of the fixes' correlated error c (a state of the filter; 0: independent fixes; realbench measures it on training walks against truth)") \
    X(ekf,    fix_bias_length_m,   double,  10.0,    0.1,     1e4,     "m",     "distance walked over which c decorrelates (exp(-d/l)); realbench measures it; the default is a few radio-map cells") \
    X(ekf,    fix_white_share,     double,  1.0,     0.0,     1.0,     "",      "least share of a fix's own variance that stays white (not in c): R_w >= share * accuracy^2 * M (realbench measures 1 - the correlated share)") \
    X(ekf,    r_window,            int32_t, 30,      0,       100000,  "fixes", "innovations the fix-error model averages (running mean, then exponential); 0 = never learn") \
    X(ekf,    r_min,               double,  0.25,    1e-3,    1e3,     "",      "smallest eigenvalue of the fix-error model per accuracy_m^2 M, prior and learnt") \
    X(ekf,    r_max,               double,  100.0,   1e-3,    1e4,     "",      "largest eigenvalue of the learnt fix-error model (per accuracy_m^2)")

/* sf_particle.h: the particle scheme. Noise figures from the sensors' and the gait's physics, not fitted
 * to a data set; realbench tunes them (the lead's). SF_PARTICLE_MAX is the compile-time capacity. */
#define SF_PARTICLE_MAX 2048
#define SF_PARAMS_PARTICLE(X)                                                                          \
    X(particle, count,             int32_t, 1000,    1,       SF_PARTICLE_MAX, "",  "particles in the cloud (about 1 000 within the per-step cost budget; at most SF_PARTICLE_MAX; the board allocates this many)") \
    X(particle, seed,              int32_t, 1,       0,       2147483647, "",      "seed of the cloud's generator (PCG32): the same seed gives a bit-identical replay") \
    X(particle, length_sigma,      double,  0.08,    0.0,     1.0,     "",      "step-length noise per step, relative (Weinberg's model scatters 5-10 % step to step)") \
    X(particle, heading_sigma_rad, double,  0.05,    0.0,     1.0,     "rad",   "walking-direction noise per step (a few degrees of body sway and gyro noise per step)") \
    X(particle, bias_rw_rad2_per_m, double, 0.0005,  0.0,     1.0,     "rad2/m","heading-bias random walk per metre walked (0.22 rad after 100 m: re-grips, magnetic disturbances)") \
    X(particle, scale_rw_per_m,    double,  1e-4,    0.0,     1.0,     "1/m",   "stride-scale random walk (variance) per metre walked (0.1 after 100 m: pace changes)") \
    X(particle, init_bias_sigma_rad, double, 0.3,    0.0,     3.2,     "rad",   "heading-bias spread of a new cloud (a magnetometer indoors is off by tens of degrees; walls tell which bias fits)") \
    X(particle, init_scale_sigma,  double,  0.1,     0.0,     1.0,     "",      "stride-scale spread of a new cloud (walkers differ by ~10-15 % from Weinberg's K)") \
    X(particle, scale_min,         double,  0.5,     0.1,     1.0,     "",      "smallest stride scale of a particle") \
    X(particle, scale_max,         double,  2.0,     1.0,     10.0,    "",      "largest stride scale of a particle") \
    X(particle, outlier_share,     double,  0.05,    1e-6,    1.0,     "",      "uniform share of a fix's likelihood: one fix lowers no weight by more than 1/share (a few per cent of fingerprint fixes are gross errors)") \
    X(particle, resample_ess_ratio, double, 0.5,     0.0,     1.0,     "",      "systematic resampling when the effective sample size falls below this share of the particles (the usual N/2)") \
    X(particle, recovery_share,    double,  0.25,    0.0,     1.0,     "",      "a recovery (fixes keep landing where no particle is) redraws this share of the cloud around the fix, keeping the rest: one wrong fix after a run of rejections cannot move the whole cloud; 1 = the whole cloud") \
    X(particle, reseed_ess_ratio,  double,  0.01,    0.0,     1.0,     "",      "re-seed around the fix when an update leaves an effective sample size below this share (the cloud no longer samples the posterior)") \
    X(particle, floor_mismatch_weight, double, 0.7,  0.0,     1.0,     "",      "weight factor per step of a particle not on the barometric floor (a flight of ~10 steps: x0.03; a 1-2 step barometer glitch: x0.5)") \
    X(particle, grid_cell_m,       double,  2.0,     0.1,     100.0,   "m",     "wall-index cell side (a room's scale: a 0.7 m step touches 1-3 cells)")

/* sf_controller.h: the multi-scheme controller (Jäger, Süß, Becker §III-C). The door's 5 steps are
 * the paper's; the rest are the gaps the paper leaves (port radius, identification window), set from
 * the walk's physics: a step is ~0.7 m, a scan comes every 1-2 s. */
#define SF_PARAMS_CONTROLLER(X)                                                                        \
    X(controller, enabled,         int32_t, 1,       0,       1,       "",      "1 = the multi-scheme controller runs when the site has a context map (site file v3); 0 = every scheme side by side, every source on") \
    X(controller, init_scheme,     int32_t, sf_scheme_kalman, 0, SF_SCHEME_COUNT - 1, "", "fusion scheme (pose_t.SCHEME_*) the primary pose follows before the CLS identifies a context (INIT) when the site's contexts name more than one scheme (one scheme for all: that one), and POSE's scheme without a context map; kalman: the best fused scheme measured on real hand-held walks (realbench: ipin2023, gsd, site1/F2)") \
    X(controller, door_steps,      int32_t, 5,       1,       100,     "steps", "steps since a door transition began after which it ends (the paper's 5)") \
    X(controller, handover_s,      double,  5.0,     0.0,     600.0,   "s",     "when the primary pose starts to follow another scheme it keeps the old one's position as an offset that decays with this time constant (about six steps), its variance carried with it; 0 = jump") \
    X(controller, elevator_walk_steps, int32_t, 2,   1,       100,     "steps", "walking steps after an elevator ride that say the user walks again (one gait cycle)") \
    X(controller, port_margin_m,   double,  1.0,     0.0,     50.0,    "m",     "a position within a port's radius plus this is near the port (the fused position errs by about a metre there)") \
    X(controller, port_leave_m,    double,  2.0,     0.0,     100.0,   "m",     "beyond radius + margin + this from the port the walker has left it (LEFT_PORT: the old context stays); about three steps") \
    X(controller, cls_window_s,    double,  3.0,     0.1,     600.0,   "s",     "a CLS identification stays valid this long (two Wi-Fi scans or a few BLE windows)") \
    X(controller, cls_gnss_accuracy_m, double, 10.0, 0.0,     1e4,     "m",     "a GNSS fix at or better than this accuracy identifies the outdoor context (open sky 2-5 m on a consumer receiver; the simulator's indoor-degraded GNSS reports >= 12 m)") \
    X(controller, recal_sigma_m,   double,  1.0,     0.01,    100.0,   "m",     "1 sigma of the staircase-endpoint recalibration fix (a flight's landing is about a metre across)") \
    X(controller, floor_from_barometer, int32_t, 1,  0,       1,       "",      "1 = at an elevator or stairs exit the barometric floor decides when the CLS names no floor or several (one of them); 0 = the CLS alone (the paper's literal rule)") \
    X(controller, floor_disagree_s, double, 10.0,    0.0,     3600.0,  "s",     "BAROMETER rule: in a floor context, a barometric floor of the same building held this long away from the context's floor outside any port switches to that floor's context (10 s is a flight, 3 s a ride per floor); 0 = never") \
    X(controller, barometer_rule,  int32_t, 1,       0,       2,       "",      "where the BAROMETER rule applies: 0 never; 1 in buildings without a stairs or elevator port (nothing else sees a floor change there; real-data sites); 2 everywhere (on 3 of 10 campus2 walks the barometric floor itself errs and the rule switched falsely)") \
    X(controller, gate_sources,    int32_t, 0,       0,       1,       "",      "1 = the sources the context keeps off are withheld from every scheme (REASON_CONTEXT_OFF audits: the paper's one method at a time); 0 = every source fused, the policy only accounted (radio on-time): on the gsd trials withholding raised kalman's mean from 4.19 to 6.26 m, on campus2 it changed the controller by 0.01 m") \
    X(controller, context_lost_s,  double,  10.0,    0.0,     3600.0,  "s",     "in the outdoor context, this long without a GNSS fix within cls_gnss_accuracy_m sends the controller back to INIT (the CLS searches every context: the walker is indoors); 0 = never") \
    X(controller, cls_gnss_fresh_s, double, 1.5,     0.0,     600.0,   "s",     "a GNSS identification breaks a tie at a door only this fresh (one 1 Hz receiver period and a half: a walker inside the door gets no accurate fix after it)")

#define SF_PARAM_LIST(X) \
    SF_PARAMS_INIT(X) SF_PARAMS_GATE(X) SF_PARAMS_GAP(X) SF_PARAMS_ESTIMATOR(X) SF_PARAMS_ATTITUDE(X) SF_PARAMS_MAGCAL(X) SF_PARAMS_STEPS(X) \
    SF_PARAMS_ACTIVITY(X) SF_PARAMS_FINGERPRINT(X) SF_PARAMS_BOARD_INPUT(X) SF_PARAMS_SOURCES(X) SF_PARAMS_FUSION(X) SF_PARAMS_EKF(X) SF_PARAMS_PARTICLE(X) SF_PARAMS_OUTPUT(X) \
    SF_PARAMS_CONTROLLER(X)

typedef struct {
#define SF_PARAM_FIELD(sec, name, type, def, lo, hi, unit, text) type sec##_##name;
    SF_PARAM_LIST(SF_PARAM_FIELD)
#undef SF_PARAM_FIELD
} sf_params_t;

/* Number of rows, as a compile-time constant. */
#define SF_PARAM_COUNT_ONE(sec, name, type, def, lo, hi, unit, text) +1
enum { SF_PARAM_COUNT = 0 SF_PARAM_LIST(SF_PARAM_COUNT_ONE) };

typedef enum { sf_param_double, sf_param_int32 } sf_param_kind_t;

/* One row of SF_PARAM_LIST as data, for loaders and for the CONFIG echo. */
typedef struct {
    const char *section;
    const char *name;
    sf_param_kind_t kind;
    size_t offset; /* into sf_params_t */
    double default_value;
    double min_value;
    double max_value;
    const char *unit;
    const char *text;
} sf_param_desc_t;

extern const sf_param_desc_t sf_param_table[];
extern const size_t sf_param_count;

/* Fills every field with its default. */
void sf_params_default(sf_params_t *params);

/* The row for section/name, or NULL. */
const sf_param_desc_t *sf_param_find(const char *section, const char *name);

/* Sets one field; SF_ERANGE when value is outside [min, max] (field unchanged), SF_EINVAL when an
 * int32 field gets a value with a fractional part. */
int sf_param_set(sf_params_t *params, const sf_param_desc_t *desc, double value);

/* Reads one field as a double. */
double sf_param_get(const sf_params_t *params, const sf_param_desc_t *desc);

#endif
