/* sf_types.h — the plain data that flows into and out of the estimator core.
 *
 * Frames and units: sensor axes are the board's; the map frame is x, y in metres with headings
 * counter-clockwise from +x. Times are board time in int64 microseconds, carried by every input: the
 * core never reads a clock. */
#ifndef SF_TYPES_H
#define SF_TYPES_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_schemes.h"

/* One accelerometer + gyroscope sample. */
typedef struct {
    int64_t t_us;
    double accel_mps2[3]; /* specific force, sensor axes */
    double gyro_radps[3]; /* angular rate, sensor axes */
} sf_imu_sample_t;

/* Activity codes, identical to step_t.ACTIVITY_* in lcmtypes/stridefix/step_t.lcm. */
enum {
    sf_activity_unknown = 0,
    sf_activity_still = 1,
    sf_activity_walking = 2,
    sf_activity_stairs_up = 3,
    sf_activity_stairs_down = 4,
    sf_activity_elevator = 5
};

/* Pose schemes: sf_scheme_<name> = pose_t.SCHEME_<NAME>, generated from lcmtypes/stridefix/pose_t.lcm
 * (sf_schemes.h), so the ids have one home. What each scheme does: sf_fusion.h. */
enum {
#define SF_SCHEME_ENUM(name, id) sf_scheme_##name = (id),
    SF_SCHEMES(SF_SCHEME_ENUM)
#undef SF_SCHEME_ENUM
    sf_scheme_count = SF_SCHEME_COUNT,
    /* not a fusion scheme: the controller's primary pose follows the scheme its context selects
     * (sf_controller.h); pose_t.SCHEME_CONTROLLER */
    sf_scheme_controller = SF_SCHEME_CONTROLLER
};

/* One Wi-Fi scan as the core sees it (views into the caller's arrays). */
typedef struct {
    int64_t t_us;
    int32_t n_ap;
    const int64_t *bssid;   /* [n_ap] */
    const float *rssi_dbm;  /* [n_ap] */
} sf_wifi_scan_t;

/* One GNSS receiver fix (gnss_t): WGS-84 position, the receiver's own horizontal accuracy (1σ). The
 * core maps it into the site frame with the site's geo-reference (sf_geo.h). */
typedef struct {
    int64_t t_us;
    double lat_deg;
    double lon_deg;
    double alt_m;      /* above the ellipsoid */
    double accuracy_m; /* 1σ horizontal, as reported */
} sf_gnss_t;

/* One BLE scan window (ble_scan_t; views into the caller's arrays): beacons by 48-bit MAC. */
typedef struct {
    int64_t t_us;
    int32_t n;
    const int64_t *beacon_id; /* [n] */
    const float *rssi_dbm;    /* [n] */
} sf_ble_scan_t;

/* A landmark event (landmark_t): the user is at this known position. */
typedef struct {
    int64_t t_us;
    int32_t landmark_id;
    double x_m;
    double y_m;
    int16_t floor;
    double accuracy_m; /* 1σ */
} sf_landmark_t;

/* Fix methods (the fix's source), identical to fix_t.METHOD_*. */
enum { sf_fix_wifi = 1, sf_fix_gnss = 2, sf_fix_landmark = 3, sf_fix_ble = 4, sf_fix_port = 5 };

/* Whether a fix method is a known position rather than a measurement to doubt: a landmark (the
 * paper's NFC tag) and the controller's staircase-endpoint recalibration (sf_controller.h), which
 * every fusing scheme takes like a landmark (sf_fusion.h, Sources). */
static inline bool sf_fix_is_known_position(const int method)
{
    return method == sf_fix_landmark || method == sf_fix_port;
}

/* An absolute position fix offered to the fusion. */
typedef struct {
    int64_t t_us;
    int8_t method;
    double x_m;
    double y_m;
    int16_t floor;
    double accuracy_m; /* 1σ, horizontal */
    int16_t n_ap_used; /* Wi-Fi: APs of the scan found in the map; BLE: beacons used; else 0 */
} sf_fix_t;

/* One detected step. */
typedef struct {
    int64_t t_us;
    int32_t index; /* first step is 1 */
    double length_m;
    double accel_range_mps2; /* vertical acceleration amax − amin over the step (Weinberg's input) */
    double period_s;         /* time since the previous step */
    double heading_rad;      /* map frame */
    int8_t activity;
    int16_t floor;
} sf_step_t;

/* The estimator's position output. */
typedef struct {
    int64_t t_us;
    double x_m;
    double y_m;
    int16_t floor;
    double heading_rad;
    double sigma_m;
    double cov_m2[3];        /* [xx, xy, yy] map frame */
    double heading_bias_rad; /* ekf, particle: learnt; 0 otherwise */
    double stride_scale;     /* ekf, particle: learnt; 1 otherwise */
    double ess;              /* particle: effective sample size; 0 otherwise */
    int32_t step_count;
    int8_t scheme;
} sf_pose_t;

#endif
