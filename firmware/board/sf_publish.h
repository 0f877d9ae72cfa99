/* sf_publish.h — the estimator's outputs as LCM messages: STEP, POSE_<SCHEME> (each fusion scheme's
 * pose) and POSE (the primary pose), FIX (the audit record), HEALTH (input, estimator, fix-source and
 * log counters) and CONFIG (the effective parameters), CONTEXT (the multi-scheme controller's
 * changes). The raw inputs (IMU, MAG, BARO, WIFI, GNSS, BLE, LANDMARK) are written by sf_rx_lcm.h,
 * from the same kind table the replay reads.
 *
 * Each call converts a core struct into its generated stridefix type and queues it on the log with the
 * caller's log timestamp (the host receive time of the frame being handled, so replaying the same
 * input gives the same log). Cannot fail: a full queue is counted by sf_lcm_out. Cost: one encode
 * straight into the log queue (sf_lcm_out_reserve); CONFIG, once per run, builds its key/value text
 * on the stack: 112 B per key, ≈ 20 KiB for the 185 keys of today (the particle scheme's 15 among
 * them), asserted ≤ 28 KiB (room for the other issue-13 sources' keys; its encoding, about a third of
 * that, goes into the queue). */
#ifndef SF_PUBLISH_H
#define SF_PUBLISH_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_estimator.h"
#include "sf_input.h"
#include "sf_lcm_out.h"
#include "sf_params.h"

/* Absolute fixes by source, indexed by the fix method (sf_fix_*, = fix_t.METHOD_*): events offered
 * to the estimator and the fixes it made of them (HEALTH.fixes_offered_* / fixes_made_*). */
#define SF_PUBLISH_METHOD_SLOTS 6
_Static_assert((int)sf_fix_wifi < SF_PUBLISH_METHOD_SLOTS && (int)sf_fix_gnss < SF_PUBLISH_METHOD_SLOTS &&
                   (int)sf_fix_ble < SF_PUBLISH_METHOD_SLOTS && (int)sf_fix_landmark < SF_PUBLISH_METHOD_SLOTS &&
                   (int)sf_fix_port < SF_PUBLISH_METHOD_SLOTS,
               "one slot per fix method");
typedef struct {
    uint64_t offered[SF_PUBLISH_METHOD_SLOTS];
    uint64_t made[SF_PUBLISH_METHOD_SLOTS];
} sf_publish_sources_t;

/* The main loop's timing, for HEALTH.loop_mean_us / loop_max_us: of one item in stride (0 or 1: every
 * one), the first included. Two clock reads an item cost ~30 ns each here, a tenth of a file replay's
 * CPU (1 M items an hour of walking), so a replay of a regular file times one in
 * SF_PUBLISH_LOOP_STRIDE_FILE (loop_mean_us stays the mean of an item's time, loop_max_us is the
 * sampled items' max); a live bus, a few hundred frames a second, times every item. */
#define SF_PUBLISH_LOOP_STRIDE_FILE 16u
typedef struct {
    double sum_us;
    double max_us;
    uint64_t n;
    unsigned stride;
    unsigned since; /* items since the last timed one */
} sf_publish_loop_t;

/* Whether the item about to be handled is to be timed; counts it. */
bool sf_publish_loop_due(sf_publish_loop_t *loop);
/* The time a timed item took. */
void sf_publish_loop_add(sf_publish_loop_t *loop, double dt_us);

void sf_publish_step(sf_lcm_out_t *out, int64_t log_t_us, const sf_step_t *step);
/* Poses: each fusion scheme's on its own channel POSE_<SCHEME> (sf_publish_pose_channel: POSE_EKF
 * for pose_t.SCHEME_EKF, ...; a scheme outside the fusion schemes, the controller's, on POSE), and the
 * primary pose on POSE (sf_publish_primary_pose, whatever its scheme), so lcm-spy and plotting tools
 * can tell the schemes apart by channel; the scheme field says the same. */
const char *sf_publish_pose_channel(int scheme);
void sf_publish_pose(sf_lcm_out_t *out, int64_t log_t_us, const sf_pose_t *pose);
void sf_publish_primary_pose(sf_lcm_out_t *out, int64_t log_t_us, const sf_pose_t *pose);

/* The primary pose into *pose; false when there is none to publish. It is the multi-scheme
 * controller's (scheme 8: the pose of the scheme its context selects). Without an active controller
 * (no context map, controller.enabled = 0) it is a copy of one scheme's pose, its scheme field naming
 * it: the output.scheme (--fusion) one when a single fusion scheme is chosen, else
 * controller.init_scheme's (the scheme the controller follows before it knows a context), pdr_only's
 * while that has no position and without a site (has_site false). output.scheme = controller: the
 * controller's pose or none. A copy is one more pose per output, the one growth of the log over the
 * single POSE channel of before, which carried the controller's pose too. */
bool sf_publish_primary_of(const sf_estimator_t *est, const sf_params_t *p, bool has_site, sf_pose_t *pose);

/* FIX: every field of the audit, accuracy_factor and drift included (0 unless the adaptive scheme
 * blended the fix). */
void sf_publish_fix(sf_lcm_out_t *out, int64_t log_t_us, const sf_fix_audit_t *audit);

/* CONTEXT: every field of the controller's event; rule_text is sf_controller_rule_text and the
 * evidence in words (steps against the rule's count — the staircase's from the site, door_steps and
 * elevator_walk_steps from the params —, the CLS's identification and its method, the recalibration),
 * e.g. "stairs: the staircase's steps and a unique floor: 22 of 20 steps, floor 1 of building 0 unique
 * (Wi-Fi, 4 APs), recalibrated to (12.0, 3.5)". The text is built on the stack (≤ 320 B). */
void sf_publish_context(sf_lcm_out_t *out, int64_t log_t_us, const sf_context_event_t *ev, const sf_site_t *site,
                        const sf_params_t *params);

/* HEALTH at board time board_t_us; the log counters are read from out. */
void sf_publish_health(sf_lcm_out_t *out, int64_t log_t_us, int64_t board_t_us, const sf_input_counters_t *in,
                       const sf_estimator_status_t *est, const sf_publish_sources_t *sources,
                       const sf_publish_loop_t *loop);

/* CONFIG: every key of sf_param_table as "section.name" with its value (%.9g). */
void sf_publish_config(sf_lcm_out_t *out, int64_t log_t_us, int64_t board_t_us, const sf_params_t *params,
                       const char *version, const char *dbc_sha256);

#endif
