/* sf_estimator.h — the pedestrian dead-reckoning estimator: one pure step per input.
 *
 * Pipeline per IMU sample (each stage is its own module; see their headers for the models):
 *   attitude (sf_attitude: complementary or Mahony, magnetometer gated)  → specific force in nav
 *   a_v = f_nav·up − ĝ (ĝ: low-pass of f_nav·up, estimator_gravity_tau_s)
 *   heading (sf_heading: mounting offset from the gait)   activity (sf_activity: a_v variance)
 *   steps (sf_steps: Pan–Tompkins or trough-peak)  → step event
 *   the step is accepted by sf_activity (a body that quiet is not walking: no drift while still; a
 *   phone turning faster than a walker turns, or about two axes at once, is a gesture; a walk that
 *   has not started moves nothing: a bout's detections are credited together when the
 *   activity_bout_steps-th confirms it),
 *   its length is Weinberg's (sf_stride) — on stairs (activity stairs_up/down) the stair's going,
 *   L − 2R by Blondel's rule (2R + G = the level step), R = |vertical speed| × step period the rise —
 *   its direction the walking direction in the map frame, and
 *   the position advances by length·(cos h, sin h).
 * MAG samples pass the online hard-iron calibration (sf_magcal: sphere fit, disturbance gated), and
 * the corrected field goes to the attitude; BARO samples to the floor (sf_floor), whose vertical
 * speed feeds the activity (stairs, elevator).
 *
 * Floors. With a site's floor table, the start floor is a vote (sf_floor_vote.h): the barometer counts
 * the floor changes, every Wi-Fi fix votes for the start floor its floor implies, the building's floors
 * bound what the barometer may count, and the barometric floor is renumbered when the vote moves. That
 * one floor is every scheme's (sf_fusion.h), so a scheme gets it for free; the matcher's floor hint too.
 *
 * Heading without a magnetometer: the yaw is then relative (it starts at 0), and the walking
 * direction is init_heading_rad + yaw + offset; once a magnetometer sample is accepted the yaw is
 * magnetic and the map rotation applies.
 *
 * Stride calibration from fixes (the paper leaves it as future work): between two Kalman-accepted
 * fixes at least stride_min_calib_distance_m of walking apart, over a walk straight enough that the
 * PDR displacement is ≥ stride_calib_straightness × the distance walked, the true distance walked is
 * taken as walked × |Δfix| / |ΔPDR|, and sf_stride_calibrate moves K toward it (gain, per-update
 * clamp and bounds there), so one bad fix cannot wreck it.
 *
 * Absolute fixes: Wi-Fi scans are matched against the site's radio map (sf_fingerprint) and every
 * fix is offered to every fusion scheme of pose_t.SCHEME_* (sf_fusion.h; today pdr_only, wifi_only,
 * overwrite, static, adaptive, kalman, ekf, particle), which all run side by side on the same steps and fixes, so one log
 * compares them all. Each scheme's pose is sf_estimator_scheme_pose; sf_estimator_pose is the PDR
 * track from the config start (σ grows by estimator_sigma_per_m per metre walked).
 *
 * The multi-scheme controller (sf_controller.h), when the site has a context map: every
 * Wi-Fi, BLE and GNSS reading first goes to its CLS raw; a source the controller's policy keeps off
 * then gives sf_scheme_count audits with reason CONTEXT_OFF and no fix (landmarks are never kept off);
 * after each credited step and each absolute-source input the controller steps on the motion of the
 * scheme it follows (its pose; without one the PDR track when the schemes started at the config pose)
 * and the latest activity. Its events come out of sf_estimator_next_context, a stairs recalibration
 * with its METHOD_PORT fix offered to every scheme like a landmark; a switch to a context on another
 * floor renumbers the shared floor to the controller's (sf_floor_shift, as the floor vote does). The
 * controller's primary pose is sf_estimator_scheme_pose(sf_scheme_controller): the pose of the scheme
 * it follows; when it starts to follow another, the old pose minus the new one at that moment is added
 * and fades with controller_handover_s (exp(−age/τ)), its outer product added to the covariance, so the
 * primary pose never jumps at a switch. Without a context map nothing of this changes an output.
 *
 * No heap, no I/O, no clock, no hidden state: the same inputs give bit-identical outputs.
 * Memory: sizeof(sf_estimator_t) = 15 768 B on x86-64 (i686 not rechecked), at most 16 KiB (checked, the
 * cost budget for the core's state without the radio map): the eight schemes are 4 224 B of it (each
 * carries the ekf's 408 B filter), the fingerprint's scan ring 3 568 B (sf_fingerprint_t: the last
 * scans' readings of map APs in a shared pool; the matcher's query scratch is in the caller's
 * workspace, sf_fingerprint.h), the step detector 2 464 B, the controller 1 480 B (sf_controller.h);
 * the particle cloud's arrays (32 kB at 1 000 particles) and the wall index are the caller's
 * (sf_particle.h, sf_wall_grid.h), its header (≤ 128 B) is here (a cloud without walls points at a
 * constant empty grid). Cost (callgrind, x86-64, `stridefix bench perf`'s sensors walk; the sensor
 * modules at -O3, firmware/CMakeLists.txt): ≈ 1 325 instructions per sf_estimator_imu without the
 * particle scheme (the attitude filter ≈ 385 of them, the activity ≈ 175, the steps ≈ 155, the two
 * sample gates ≈ 115, the heading filter ≈ 105 and the yaw's direction ≈ 35; the walking direction's
 * atan2 only when it is read: a step, a POSE), ≈ 935 per sf_estimator_mag (the attitude's
 * magnetometer fusion ≈ 500, sf_magcal ≈ 315), ≈ 410 per sf_estimator_baro (sf_floor ≈ 275):
 * ≈ 1 875 per IMU sample at 100/50/20 Hz, all core work (the cost budget asks ≤ 1 200); a Wi-Fi fix is
 * sf_fingerprint.h's, a particle step
 * sf_particle.h's. */
#ifndef SF_ESTIMATOR_H
#define SF_ESTIMATOR_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_activity.h"
#include "sf_attitude.h"
#include "sf_ble.h"
#include "sf_controller.h"
#include "sf_fingerprint.h"
#include "sf_floor.h"
#include "sf_floor_vote.h"
#include "sf_source_quality.h"
#include "sf_fusion.h"
#include "sf_gap_bridge.h"
#include "sf_heading.h"
#include "sf_magcal.h"
#include "sf_params.h"
#include "sf_radiomap.h"
#include "sf_sample_gate.h"
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
    sf_floor_vote_t floor_vote; /* the start floor (sf_floor_vote.h); active once a site gives floors */
    sf_source_quality_t quality; /* what GNSS and BLE deliver against the Wi-Fi fixes (sf_source_quality.h) */
    bool floor_vote_active;
    bool started;
    int64_t t_us;        /* newest input time */
    double gravity_mps2; /* ĝ */
    sf_memo_t gravity_decay; /* e^(−dt/τ) of the last IMU interval: one exp per rate change */
    double accel_v_mps2; /* latest a_v */
    double x_m;
    double y_m;
    /* the latest walking direction (map frame) is computed when read (sf_estimator_pose, a step),
     * from what it depends on at the latest IMU sample: the attitude q (its yaw), the heading filter's
     * offset and the map rotation or start heading; heading_rad before the first sample */
    double heading_rad;
    bool heading_from_q;
    bool heading_yaw_absolute;
    double heading_q[4];
    double heading_offset_rad; /* sf_heading_offset_rad */
    double heading_base_rad;   /* heading_map_rotation (yaw absolute) or init_heading [rad] */
    double distance_m;  /* walked since start */
    double sigma_m;
    double weinberg_sum; /* Σ range^¼ since the last stride calibration (for absolute fixes) */
    int32_t step_count;
    uint32_t steps_refused; /* detector steps the activity refused (quiet body) */
    sf_sample_gate_t gates[sf_gate_stream_count];
    sf_gap_bridge_t gap;
    uint32_t samples_refused[4]; /* by sf_gate_verdict_t (index 0 unused) */
    sf_step_event_t held_events[SF_ACTIVITY_BOUT_MAX]; /* the held detections of a bout (sf_activity.h) */
    /* absolute fixes: the site and the matcher's workspace are the caller's */
    const sf_site_t *site;          /* NULL: no site, no Wi-Fi fixes */
    sf_fingerprint_workspace_t *ws; /* prepared for site->radiomap */
    sf_fingerprint_t fingerprint;
    sf_ble_t ble; /* the BLE ranging's counters (sf_ble.h) */
    uint32_t ble_floor_votes; /* loud beacons that voted for their floor */
    uint32_t gnss_offered, gnss_refused, landmarks_refused; /* GNSS fixes seen / refused (no geo-reference
                                                             * counts as offered only), bad landmarks */
    sf_fusion_t fusion[sf_scheme_count]; /* every scheme runs on the same inputs */
    sf_particle_t particles; /* the particle scheme's cloud; its arrays are the caller's (attach_particles) */
    bool has_particles;
    /* online stride calibration: the anchor is the last accepted Kalman fix */
    bool calib_anchor_valid;
    double calib_fix_x_m, calib_fix_y_m;   /* the anchor fix */
    double calib_pdr_x_m, calib_pdr_y_m;   /* the PDR track at the anchor */
    double calib_distance_m;               /* distance walked at the anchor */
    uint32_t stride_calibrations;
    /* the multi-scheme controller: inactive without a site's context map */
    sf_controller_t controller;
    /* the primary pose's hand-over when the controller follows another scheme: the old pose minus the
     * new one at the switch, decaying with controller_handover_s (sf_estimator_scheme_pose) */
    int64_t handover_t_us; /* INT64_MIN: none */
    double handover_dx_m, handover_dy_m;
    uint32_t context_off; /* source inputs the controller's policy kept off (REASON_CONTEXT_OFF) */
} sf_estimator_t;
_Static_assert(sizeof(sf_estimator_t) <= 16 * 1024, "sf_estimator.h promises at most 16 KiB");

void sf_estimator_init(sf_estimator_t *est, const sf_params_t *p);

/* Most steps one IMU sample can credit: a bout's held detections, the last of which confirms it. */
#define SF_ESTIMATOR_MAX_STEPS SF_ACTIVITY_BOUT_MAX

/* One IMU sample. Returns how many steps it credited (0..SF_ESTIMATOR_MAX_STEPS) and fills steps[]
 * in order; the position has then moved by each. The detections of a bout are held until
 * activity_bout_steps of them confirm it (sf_activity.h), so a jolt or a gesture never moves the position. */
int sf_estimator_imu(sf_estimator_t *est, const sf_params_t *p, const sf_imu_sample_t *sample,
                     sf_step_t steps[SF_ESTIMATOR_MAX_STEPS]);

/* One magnetometer sample [µT], sensor axes, raw (sf_magcal removes the hard-iron offset). */
void sf_estimator_mag(sf_estimator_t *est, const sf_params_t *p, int64_t t_us, const double field_ut[3]);

/* One barometer sample [Pa]. */
void sf_estimator_baro(sf_estimator_t *est, const sf_params_t *p, int64_t t_us, double pressure_pa);

/* The PDR track from the config start (time = newest input time). */
void sf_estimator_pose(const sf_estimator_t *est, sf_pose_t *pose);

/* Gives the estimator a site (floors and radio map; caller-owned, must outlive the estimator) and a
 * workspace sized to its map (sf_fingerprint.h). Call once, right after sf_estimator_init, before any
 * input. Without a site there are no Wi-Fi fixes and every scheme starts at the config pose; with
 * one, schemes start at their first fix unless init_use_config_pose (truth-initialised).
 * The site's context map attaches the controller (sf_controller_attach).
 * SF_OK, or the error of sf_floor_set_heights / sf_fingerprint_prepare / sf_controller_attach (bad site). */
int sf_estimator_attach_site(sf_estimator_t *est, const sf_params_t *p, const sf_site_t *site,
                             sf_fingerprint_workspace_t *ws);

/* Gives the particle scheme its cloud: the caller's arrays for `capacity` particles (states and floors,
 * SF_PARTICLE_BYTES_PER bytes each; the cloud uses min(particle.count, capacity)) and the site's wall
 * index (sf_wall_grid.h, built over site->plan; NULL: no walls). The ports are the attached site's
 * (none without a site: floors change anywhere). Call after sf_estimator_attach_site (if any), before
 * any input; a config start seeds the cloud at once. Without it the particle scheme has no position.
 * SF_OK, or SF_EINVAL (NULL arrays, capacity outside 1..SF_PARTICLE_MAX). */
int sf_estimator_attach_particles(sf_estimator_t *est, const sf_params_t *p, sf_particle_state_t *states,
                                  int16_t *floors, int32_t capacity, const sf_wall_grid_t *walls);

/* One Wi-Fi scan. With a site, matches it and offers the fix to every scheme; fills *fix (when the
 * match succeeded, *has_fix) and one audit per scheme (audits[s] for scheme s), and returns the
 * number of audits (sf_scheme_count), or 0 without a site. A scan with too few usable APs gives
 * audits with reason too_few_aps and no fix. */
int sf_estimator_wifi(sf_estimator_t *est, const sf_params_t *p, const sf_wifi_scan_t *scan, sf_fix_t *fix,
                      bool *has_fix, sf_fix_audit_t audits[sf_scheme_count]);

/* The other absolute sources, each with its own measurement model, offered to every scheme
 * like a Wi-Fi fix, with the same outputs and return value as sf_estimator_wifi (sf_scheme_count
 * audits, or 0 when the source cannot be used at all):
 *   GNSS      mapped into the site frame by the site's geo-reference (sf_geo.h); 1σ = the receiver's
 *             accuracy × gnss_accuracy_scale, floored at gnss_min_accuracy_m; on the caller's floor, no
 *             floor vote. 0 audits without a site, a valid geo-reference or with gnss_use = 0; audits
 *             with reason INACCURATE and no fix for an accuracy beyond gnss_max_accuracy_m or a
 *             position off the plane (sf_geo_to_map's SF_ERANGE).
 *   BLE       ranges to the site's known beacons (sf_ble.h: log-distance path loss) → a position and
 *             accuracy on the caller's floor; first the scan votes for a floor: the one the site's BLE
 *             constellations identify (sf_cls_ble_floor), or without them the nearest known beacon by
 *             the model when within ble_floor_vote_range_m; 0 audits without beacons in the site;
 *             TOO_FEW_APS audits when fewer than ble_min_beacons usable beacons were heard.
 *   GNSS and BLE fixes are offered with their accuracy × the factor the walk's Wi-Fi fixes give their
 *   source (sf_source_quality.h: the variance it delivers against the one it claims, and the
 *   persistence of its errors), unless quality_enable = 0.
 *   landmark  the landmark's own position, floor and accuracy (needs no site); it votes on the floor;
 *             every fusing scheme takes it whatever its gate (α = 1 in the fixed-gain blends,
 *             sf_fusion.h, Sources); INACCURATE audits for a non-finite position or accuracy.
 * A Kalman-accepted Wi-Fi or landmark fix recalibrates the stride (GNSS and BLE err too much for it). */
int sf_estimator_gnss(sf_estimator_t *est, const sf_params_t *p, const sf_gnss_t *gnss, sf_fix_t *fix,
                      bool *has_fix, sf_fix_audit_t audits[sf_scheme_count]);
int sf_estimator_ble(sf_estimator_t *est, const sf_params_t *p, const sf_ble_scan_t *scan, sf_fix_t *fix,
                     bool *has_fix, sf_fix_audit_t audits[sf_scheme_count]);
int sf_estimator_landmark(sf_estimator_t *est, const sf_params_t *p, const sf_landmark_t *landmark,
                          sf_fix_t *fix, bool *has_fix, sf_fix_audit_t audits[sf_scheme_count]);

/* The controller's next pending CONTEXT event (sf_controller.h), false when none. For a stairs
 * recalibration (ev->recalibrated) the METHOD_PORT fix at the endpoint (floor: the new floor, 1σ
 * controller.recal_sigma_m) is offered to every scheme like a landmark (it votes on the floor):
 * *fix, *has_fix and the audits (*n_audits = sf_scheme_count; 0 for any other event). */
bool sf_estimator_next_context(sf_estimator_t *est, const sf_params_t *p, sf_context_event_t *ev, sf_fix_t *fix,
                               bool *has_fix, sf_fix_audit_t audits[sf_scheme_count], int *n_audits);

/* The pose of one scheme; false while that scheme has no position yet (waiting for its first fix).
 * sf_scheme_controller: the pose of the scheme the active controller follows, with scheme =
 * sf_scheme_controller and the controller's floor; false without an active controller. */
bool sf_estimator_scheme_pose(const sf_estimator_t *est, const sf_params_t *p, int scheme, sf_pose_t *pose);

/* What the board layer publishes about the estimator (HEALTH, POSE timing) without reading its
 * internals. */
typedef struct {
    int64_t t_us;          /* newest input time */
    int32_t step_count;    /* steps credited since start */
    int16_t floor;         /* the barometric floor (sf_floor) */
    bool has_site;         /* a site is attached: Wi-Fi fixes and every scheme; else only pdr_only */
    uint32_t mag_rejected; /* magnetometer samples the attitude refused (disturbed field) */
    uint32_t steps_refused; /* detector steps the activity refused (quiet body) */
    uint32_t stride_calibrations;
    uint32_t samples_out_of_range; /* samples refused by sf_sample_gate: not finite or beyond full scale */
    uint32_t samples_jumped;       /* ... faster than a body moves */
    uint32_t samples_out_of_order; /* ... not later than their stream's last accepted sample */
    uint32_t gaps_bridged;         /* IMU gaps the walk went through, dead-reckoned (sf_gap_bridge) */
    uint32_t gnss_offered, gnss_refused; /* GNSS fixes given to the estimator / refused (INACCURATE) */
    uint32_t ble_scans, ble_fixes;       /* BLE windows given (with beacons in the site) / fixes made */
    uint32_t landmarks_refused;          /* landmark events with a non-finite position or accuracy */
    bool controller_active;              /* a context map is attached and controller.enabled */
    uint32_t context_transitions, context_switches, context_recalibrations; /* sf_controller_t counters */
    uint32_t context_off;                /* source inputs kept off by the controller's policy */
    double gnss_on_s, wifi_on_s, ble_on_s; /* each radio's on-time under the policy [s] */
} sf_estimator_status_t;

/* Fills *status; cannot fail. */
void sf_estimator_status(const sf_estimator_t *est, sf_estimator_status_t *status);

#endif
