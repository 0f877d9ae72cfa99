/* sf_controller.h — the multi-scheme controller and its coarse localization subsystem (CLS), after
 * Jäger, Süß, Becker, "Multi-Scheme Smartphone Localization with Auto-Adaptive Dead Reckoning"
 * §III-B/C, Fig. 6 (../shared/papers/jaeger-suess-becker-auto-adaptive-dr.md §1.4–1.8).
 *
 * Pure and table-driven over the site's positioning context map (sf_context_map_t, sf_radiomap.h):
 *   INIT        the CLS in unlimited mode (every context a candidate; Wi-Fi, BLE and GNSS all on)
 *               → IN_CONTEXT once exactly one context is identified (rule CLS_UNLIMITED).
 *   IN_CONTEXT  the primary pose follows the context's scheme (its LSD); only the LSD's absolute method
 *               is on (plus landmarks, which override everything); when the active scheme's position
 *               comes within a port of its floor → TRANSITION(port) (rule NEAR_PORT), the CLS in
 *               limited mode over the port's neighbourhood (the port, its floors, the ports linked to
 *               it, the outdoor context when the port leads outdoors).
 *   TRANSITION  exit by the port's kind:
 *                 elevator  walking again after the ride AND the CLS identifies a unique floor;
 *                 stairs    steps since the transition began ≥ the staircase's steps AND a unique floor;
 *                           only if the floor changed, the position is recalibrated to the staircase's
 *                           endpoint on the new floor (a METHOD_PORT fix offered to every scheme);
 *                 door      5 steps (controller.door_steps) since the transition began; the context is
 *                           then the CLS's unique identification, or, when the CLS names none or two
 *                           (the paper's unresolved tie at an entrance), the building outline that
 *                           holds the active scheme's position;
 *               leaving the port's neighbourhood without the rule's evidence keeps the old context
 *               (rule LEFT_PORT); still within the port after an exit re-enters TRANSITION.
 * GPS policy: GNSS is on in the outdoor context, at INIT, and in a transition at a port that leads
 * outdoors; off elsewhere. Wi-Fi / BLE: on where the context's LSD or the CLS needs them.
 *
 * The CLS (no radio map, no fusion): a context is identified by a scan when at least its
 * cdd_min_hits constellation members are heard at their cdd_min_dbm or louder (Wi-Fi, BLE), or by a
 * GNSS fix with accuracy ≤ controller.cls_gnss_accuracy_m (the outdoor context); an identification
 * stays valid for controller.cls_window_s.
 *
 * No heap, no I/O, no clock: inputs carry time; the same inputs give the same events. */
#ifndef SF_CONTROLLER_H
#define SF_CONTROLLER_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_params.h"
#include "sf_radiomap.h"
#include "sf_types.h"

/* States, identical to context_t.STATE_*; rules, identical to context_t.RULE_*. */
enum { sf_ctl_init = 0, sf_ctl_in_context = 1, sf_ctl_transition = 2 };
enum {
    sf_ctl_rule_cls_unlimited = 1,
    sf_ctl_rule_near_port = 2,
    sf_ctl_rule_elevator = 3,
    sf_ctl_rule_stairs = 4,
    sf_ctl_rule_door = 5,
    sf_ctl_rule_left_port = 6
};

/* One CONTEXT message (context_t, field for field). */
typedef struct {
    int64_t t_us;
    int8_t state;
    int16_t context, prev_context; /* −1: none */
    int8_t kind;                   /* sf_context_*, 0: none */
    int16_t building, floor;
    int8_t scheme;  /* the fusion scheme the primary pose follows */
    int8_t method;  /* the absolute method that scheme fuses here (sf_fix_*) */
    int16_t port;   /* −1: none */
    int16_t port_kind;
    int8_t rule;    /* sf_ctl_rule_* */
    bool switched;
    int32_t steps_in_transition;
    int16_t cls_candidates, cls_identified;
    int8_t cls_method;
    int16_t cls_hits;
    bool recalibrated;
    double recal_x_m, recal_y_m;
    bool gnss_on, wifi_on, ble_on;
} sf_context_event_t;

/* What the controller sees of the walk at each update: the active scheme's position (in INIT the
 * controller.init_scheme's, or the PDR track's when that has none), the steps credited so far, and
 * the activity of the latest step (sf_activity_*: elevator while riding, walking again after). */
typedef struct {
    int64_t t_us;
    bool has_position;
    double x_m, y_m;
    int16_t floor;
    int32_t step_count;
    int8_t activity;
} sf_ctl_motion_t;

/* The words of a rule (context_t.rule_text is this plus the evidence): static text. */
const char *sf_controller_rule_text(int rule);

#endif
