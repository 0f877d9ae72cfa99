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
 *                           (the paper's unresolved tie at an entrance), the GNSS side of a tie, else
 *                           the building outline that holds the active scheme's position;
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

#include "sf_cls.h"
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
    sf_ctl_rule_left_port = 6,
    sf_ctl_rule_barometer = 7,
    sf_ctl_rule_lost = 8
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
    bool floor_from_barometer; /* elevator, stairs: the CLS named none or several, the barometer decided */
    bool recalibrated;
    double recal_x_m, recal_y_m;
    bool gnss_on, wifi_on, ble_on;
} sf_context_event_t;

/* What the controller sees of the walk at each update: the active scheme's position (in INIT the
 * scheme every context names when they name one, else controller.init_scheme's, or the PDR track's
 * when that has none), the steps credited so far, and
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

/* Pending CONTEXT events the controller holds between the caller's drains (one update makes at most
 * two: an exit and the re-entry at the same port; when full the oldest is dropped and counted). */
#define SF_CONTROLLER_EVENTS 4

/* The controller's state: caller-owned, no pointer but the attached site (read-only, the caller's).
 * Decisions in detail (the header comment above is the spec):
 *   unique identification  exactly one candidate identified within controller.cls_window_s (after an
 *                          elevator ride: identified since the ride, so the floors passed on the way
 *                          do not count);
 *   near a port            the position within radius + controller.port_margin_m of a port whose
 *                          floors include the controller's floor (the nearest such port);
 *   walking again          controller.elevator_walk_steps steps credited with activity walking after
 *                          sf_activity_elevator was seen in the transition (sf_controller_activity);
 *   staircase's steps      counted from the transition's first step with a stairs activity (the
 *                          walker set foot on the staircase; the approach inside the port's disc
 *                          does not count), from the transition's start when none was classified;
 *   unique floor           (elevator, stairs) the CLS's unique identification; when it names none or
 *                          several, the barometric floor (sf_ctl_motion_t.floor) if the port joins it:
 *                          "with a barometer, vertical displacement gives the floor unambiguously"
 *                          (the paper §III-C, [15]); the event says which (floor_from_barometer);
 *   lost outdoors          (context_lost_s) IN_CONTEXT outdoors without an accurate GNSS fix for that
 *                          long → INIT, the unlimited CLS (rule LOST): a door decided wrong or missed;
 *   missed transition      (floor_from_barometer) IN_CONTEXT in a floor context and near no port, the
 *                          barometric floor held on another floor of the building for
 *                          controller.floor_disagree_s → that floor's context (rule BAROMETER);
 *   stairs recalibration   the endpoint on the new floor: floor_hi's when the new floor is floor_hi,
 *                          else floor_lo's;
 *   door                   the unique identification; a tie that holds the outdoor context identified
 *                          by GNSS goes outdoors (an accurate fix needs open sky; Wi-Fi and BLE carry
 *                          through a doorway); else context_of(the building whose outline holds the
 *                          position, the floor), outside every outline the outdoor context;
 *   floor                  the context's floor (floor and outdoor contexts), the estimator's
 *                          (sf_ctl_motion_t.floor) in INIT and in a building context; the primary
 *                          pose's (sf_controller_pose_floor) is the barometric floor during a stairs or
 *                          elevator transition when that is one of the port's floors (the floor
 *                          changes there, the context only at the exit) and controller.floor_from_barometer.
 * Cost per update O(n_ports + n_contexts) (plus a neighbourhood, sf_cls.h, when a transition begins);
 * per reading the CLS's. Memory: sizeof(sf_controller_t) = 1 440 B on x86-64 (at most 1 536 B,
 * checked): the CLS's evidence (sf_cls_t, 1 048 B) and the event ring (4 × 72 B) are most of it. */
typedef struct {
    const sf_site_t *site; /* NULL: not attached */
    bool active;           /* attached to a context map and controller.enabled */
    int8_t init_scheme;
    int8_t state;          /* sf_ctl_* */
    int16_t context;       /* −1 in INIT */
    int16_t floor;
    int16_t port;          /* the transition's port, −1 outside one */
    bool port_outdoor;     /* the transition's neighbourhood leads outdoors (GNSS on) */
    bool elevator_seen;
    bool on_stairs;
    int64_t gnss_good_t_us;  /* the latest GNSS fix within controller.cls_gnss_accuracy_m */
    int64_t context_t_us;    /* when the state last became IN_CONTEXT */
    int8_t last_rule;        /* the rule of the latest switch */
    bool last_by_baro;       /* ... and whether the barometer decided its floor */
    int64_t disagree_t_us;   /* since when the barometric floor has differed from the context's (INT64_MIN: it agrees) */          /* a stairs step was credited in this transition (sf_activity_stairs_*) */
    int32_t steps_at_start; /* step count when the transition began */
    int32_t steps_at_stairs; /* step count before the transition's first stairs step */
    int32_t walk_steps;     /* walking steps credited since the elevator was last seen */
    int32_t step_count;     /* latest seen */
    int64_t elevator_t_us;  /* the latest elevator activity seen in the transition */
    bool has_t;
    int64_t t_us;           /* latest update */
    sf_cls_t cls;
    double gnss_on_s, wifi_on_s, ble_on_s; /* time with each radio on under the policy [s] */
    uint32_t transitions, switches, recalibrations, events_dropped; /* counters, never decrease */
    int32_t ev_head, ev_n;
    sf_context_event_t events[SF_CONTROLLER_EVENTS];
} sf_controller_t;
_Static_assert(sizeof(sf_controller_t) <= 1536, "sf_controller.h promises at most 1 536 B");

/* Not attached, inactive (every source on, no events), INIT. Cannot fail. */
void sf_controller_init(sf_controller_t *c, const sf_params_t *p);

/* Checks the site's context map (indices in range, kinds, schemes < sf_scheme_count, methods, at
 * most SF_CONTROLLER_MAX_CONTEXTS contexts, outlines of ≥ 3 consecutive vertices, port extras) and
 * attaches it; active when n_contexts > 0 and controller.enabled = 1 (INIT, the CLS searching every
 * context). SF_OK; SF_EINVAL for a NULL argument; SF_ERANGE (*what, may be NULL: a static text naming
 * the first violated invariant) for a bad map, the controller then unattached and inactive. */
int sf_controller_attach(sf_controller_t *c, const sf_params_t *p, const sf_site_t *site, const char **what);

/* The raw readings, for the CLS (recorded only while it searches: INIT and TRANSITION). */
void sf_controller_wifi(sf_controller_t *c, const sf_params_t *p, const sf_wifi_scan_t *scan);
void sf_controller_ble(sf_controller_t *c, const sf_params_t *p, const sf_ble_scan_t *scan);
void sf_controller_gnss(sf_controller_t *c, const sf_params_t *p, int64_t t_us, double accuracy_m);

/* The activity at t_us (every IMU sample may give it; O(1)): an elevator ride in an elevator transition. */
void sf_controller_activity(sf_controller_t *c, int64_t t_us, int8_t activity);

/* One step of the state machine on the walk's motion; the radio-on times grow by the time since the
 * previous update under the policy in force (every radio when inactive). Returns whether events were
 * queued. */
bool sf_controller_update(sf_controller_t *c, const sf_params_t *p, const sf_ctl_motion_t *m);

/* Pops the oldest pending event into *ev; false when none. */
bool sf_controller_next_event(sf_controller_t *c, sf_context_event_t *ev);

/* Policy: whether a source (sf_fix_*) is on now (always when inactive; landmarks and port fixes always). */
bool sf_controller_source_on(const sf_controller_t *c, int method);

/* The scheme the primary pose follows (the context's LSD; controller.init_scheme in INIT), the
 * controller's floor, whether it runs. */
int sf_controller_scheme(const sf_controller_t *c);
int16_t sf_controller_floor(const sf_controller_t *c);
/* Whether the building (index) has a stairs or elevator port. */
bool sf_controller_has_vertical_port(const sf_controller_t *c, int32_t building);
/* The primary pose's floor given the estimator's barometric floor now (see floor above; in a floor
 * context of a building without a stairs or elevator port, with controller.barometer_rule ≥ 1, the
 * barometric floor: nothing else there sees the floor change, the context follows it by BAROMETER). */
int16_t sf_controller_pose_floor(const sf_controller_t *c, const sf_params_t *p, int16_t baro_floor);
bool sf_controller_active(const sf_controller_t *c);

#endif
