/* test_controller.c — the multi-scheme controller and its CLS (sf_controller.h, sf_cls.h): one test
 * per transition rule of Jäger, Süß, Becker §III-C (Fig. 6), on a small campus built here:
 *
 *   building A (0): outline (0,0)–(20,20), three floors; Wi-Fi (3 APs per floor, 2 needed at −75 dBm);
 *                   door 0 at (10, 0) r 1.5 m to outdoors, stairs 1 at (5, 15) r 3 m floors 0–1 with
 *                   20 steps (endpoints (3, 15) below, (7, 15) above), elevator 2 at (15, 15) r 1.5 m
 *                   floors 0–2;
 *   building B (1): outline (40,0)–(60,20), one building context with BLE (2 beacons, 1 needed at
 *                   −80 dBm), door 3 at (50, 0) r 1.5 m to outdoors;
 *   outdoors:       context 0, GNSS (a fix at ≤ controller.cls_gnss_accuracy_m identifies it).
 * Contexts: 0 outdoor (ekf, GNSS), 1–3 A floors 0–2 (ekf, Wi-Fi), 4 B (kalman, BLE).
 *
 * GIVEN the controller in a state, WHEN readings and motions arrive, THEN the events (rule, context,
 * floor, evidence, recalibration) and the policy are the paper's. The last test drives the estimator:
 * a source the policy keeps off gives CONTEXT_OFF audits, and the stairs recalibration's METHOD_PORT
 * fix moves the fixed-gain schemes onto the staircase's endpoint. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sf_controller.h"
#include "sf_error.h"
#include "sf_estimator.h"

#define S_US 1000000LL

static const double heights_m[] = {0.0, 3.5, 7.0};
static const int16_t port_kind[] = {sf_port_door, sf_port_stairs, sf_port_elevator, sf_port_door};
static const float port_x[] = {10.0f, 5.0f, 15.0f, 50.0f};
static const float port_y[] = {0.0f, 15.0f, 15.0f, 0.0f};
static const float port_r[] = {1.5f, 3.0f, 1.5f, 1.5f};
static const int16_t port_lo[] = {0, 0, 0, 0};
static const int16_t port_hi[] = {0, 1, 2, 0};
static const int16_t port_building[] = {0, 0, 0, 1};
static const int16_t port_outdoor[] = {1, 0, 0, 1};
static int16_t port_steps[] = {0, 20, 0, 0};
static const float port_lo_x[] = {10.0f, 3.0f, 15.0f, 50.0f};
static const float port_lo_y[] = {0.0f, 15.0f, 15.0f, 0.0f};
static const float port_hi_x[] = {10.0f, 7.0f, 15.0f, 50.0f};
static const float port_hi_y[] = {0.0f, 15.0f, 15.0f, 0.0f};
static const float outline_x[] = {0.0f, 20.0f, 20.0f, 0.0f, 40.0f, 60.0f, 60.0f, 40.0f};
static const float outline_y[] = {0.0f, 0.0f, 20.0f, 20.0f, 0.0f, 0.0f, 20.0f, 20.0f};
static const int16_t outline_building[] = {0, 0, 0, 0, 1, 1, 1, 1};
static const int16_t ctx_kind[] = {sf_context_outdoor, sf_context_floor, sf_context_floor, sf_context_floor,
                                   sf_context_building};
static const int16_t ctx_building[] = {-1, 0, 0, 0, 1};
static const int16_t ctx_floor[] = {0, 0, 1, 2, 0};
static int16_t ctx_scheme[] = {sf_scheme_ekf, sf_scheme_ekf, sf_scheme_ekf, sf_scheme_ekf, sf_scheme_kalman};
static const int16_t ctx_method[] = {sf_fix_gnss, sf_fix_wifi, sf_fix_wifi, sf_fix_wifi, sf_fix_ble};
static const int16_t ctx_cdd_method[] = {sf_fix_gnss, sf_fix_wifi, sf_fix_wifi, sf_fix_wifi, sf_fix_ble};
static const int16_t ctx_min_hits[] = {1, 2, 2, 2, 1};
static const int16_t cdd_context[] = {1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4};
static const int64_t cdd_id[] = {0x101, 0x102, 0x103, 0x201, 0x202, 0x203, 0x301, 0x302, 0x303, 0x401, 0x402};
static const float cdd_min_dbm[] = {-75, -75, -75, -75, -75, -75, -75, -75, -75, -80, -80};

static sf_site_t campus(void)
{
    sf_site_t s = {.lowest_floor = 0, .n_floors = 3, .floor_height_m = heights_m};
    s.ports = (sf_ports_t){.n_ports = 4, .kind = port_kind, .x_m = port_x, .y_m = port_y, .radius_m = port_r,
                           .floor_lo = port_lo, .floor_hi = port_hi};
    s.contexts = (sf_context_map_t){.n_buildings = 2, .n_outline = 8, .outline_x_m = outline_x,
                                    .outline_y_m = outline_y, .outline_building = outline_building,
                                    .port_building = port_building, .port_outdoor = port_outdoor,
                                    .port_steps = port_steps, .port_lo_x_m = port_lo_x, .port_lo_y_m = port_lo_y,
                                    .port_hi_x_m = port_hi_x, .port_hi_y_m = port_hi_y, .n_links = 0,
                                    .n_contexts = 5, .kind = ctx_kind, .building = ctx_building,
                                    .floor = ctx_floor, .scheme = ctx_scheme, .method = ctx_method,
                                    .cdd_method = ctx_cdd_method, .cdd_min_hits = ctx_min_hits, .n_cdd = 11,
                                    .cdd_context = cdd_context, .cdd_id = cdd_id, .cdd_min_dbm = cdd_min_dbm};
    return s;
}

/* ---- readings and motions ------------------------------------------------------------------------ */

typedef struct {
    int64_t bssid[12];
    float rssi[12];
    int n;
} scan_buf_t;

/* Every AP of the floors in mask (bit f: floor f of A) at rssi_dbm; n_per_floor of each floor's three. */
static sf_wifi_scan_t floors_scan(scan_buf_t *const b, const int64_t t_us, const unsigned mask, const int n_per_floor,
                                  const float rssi_dbm)
{
    b->n = 0;
    for (int f = 0; f < 3; f++) {
        for (int k = 0; (mask & (1u << f)) != 0 && k < n_per_floor; k++) {
            b->bssid[b->n] = 0x101 + 0x100 * f + k;
            b->rssi[b->n++] = rssi_dbm;
        }
    }
    return (sf_wifi_scan_t){.t_us = t_us, .n_ap = b->n, .bssid = b->bssid, .rssi_dbm = b->rssi};
}

static void hear_floors(sf_controller_t *const c, const sf_params_t *const p, const int64_t t_us,
                        const unsigned mask)
{
    scan_buf_t b;
    const sf_wifi_scan_t scan = floors_scan(&b, t_us, mask, 3, -60.0f);
    sf_controller_wifi(c, p, &scan);
}

static sf_ctl_motion_t at(const int64_t t_us, const double x_m, const double y_m, const int16_t floor,
                          const int32_t steps, const int8_t activity)
{
    return (sf_ctl_motion_t){.t_us = t_us, .has_position = true, .x_m = x_m, .y_m = y_m, .floor = floor,
                             .step_count = steps, .activity = activity};
}

static int drain(sf_controller_t *const c, sf_context_event_t *const evs, const int max)
{
    int n = 0;
    while (n < max && sf_controller_next_event(c, &evs[n])) {
        n++;
    }
    return n;
}

static void setup(sf_controller_t *const c, sf_params_t *const p, const sf_site_t *const site)
{
    sf_params_default(p);
    p->controller_floor_from_barometer = 0; /* the paper's rules: the CLS alone names the floor */
    assert_int_equal(sf_controller_attach(c, p, site, NULL), SF_OK);
    assert_true(sf_controller_active(c));
}

/* GIVEN INIT, WHEN floor 0's APs are heard at t, THEN IN_CONTEXT(context 1) on the next update. */
static void enter_floor(sf_controller_t *const c, const sf_params_t *const p, const int64_t t_us, const unsigned floor,
                        const double x_m, const double y_m)
{
    hear_floors(c, p, t_us, 1u << floor);
    const sf_ctl_motion_t m = at(t_us, x_m, y_m, 0, 0, sf_activity_walking);
    assert_true(sf_controller_update(c, p, &m));
    sf_context_event_t ev;
    assert_true(sf_controller_next_event(c, &ev));
    assert_int_equal(ev.rule, sf_ctl_rule_cls_unlimited);
    assert_int_equal(ev.context, 1 + (int)floor);
}

/* ---- INIT ---------------------------------------------------------------------------------------- */

static void test_init_needs_a_unique_context(void **state)
{
    (void)state;
    const sf_site_t site = campus();
    sf_controller_t c;
    sf_params_t p;
    setup(&c, &p, &site);
    assert_int_equal(c.state, sf_ctl_init);
    assert_int_equal(sf_controller_scheme(&c), p.controller_init_scheme);
    /* all on at INIT (Table I) */
    assert_true(sf_controller_source_on(&c, sf_fix_gnss) && sf_controller_source_on(&c, sf_fix_wifi) &&
                sf_controller_source_on(&c, sf_fix_ble));
    /* one AP of floor 0 (2 needed): nothing */
    scan_buf_t b;
    sf_wifi_scan_t scan = floors_scan(&b, 1 * S_US, 1u, 1, -60.0f);
    sf_controller_wifi(&c, &p, &scan);
    sf_ctl_motion_t m = at(1 * S_US, 10.0, 10.0, 0, 0, sf_activity_still);
    assert_false(sf_controller_update(&c, &p, &m));
    /* three APs of floor 0 but too weak (−80 < −75 dBm): nothing */
    scan = floors_scan(&b, 2 * S_US, 1u, 3, -80.0f);
    sf_controller_wifi(&c, &p, &scan);
    m.t_us = 2 * S_US;
    assert_false(sf_controller_update(&c, &p, &m));
    /* floor 0 by Wi-Fi and outdoors by a good GNSS fix: two contexts, INIT stays */
    hear_floors(&c, &p, 3 * S_US, 1u);
    sf_controller_gnss(&c, &p, 3 * S_US, 4.0);
    m.t_us = 3 * S_US;
    assert_false(sf_controller_update(&c, &p, &m));
    assert_int_equal(c.state, sf_ctl_init);
    /* an indoor-degraded GNSS fix (12 m > 10 m) identifies nothing; the old ones expire after 3 s */
    hear_floors(&c, &p, 7 * S_US, 1u);
    sf_controller_gnss(&c, &p, 7 * S_US, 12.0);
    m.t_us = 7 * S_US;
    assert_true(sf_controller_update(&c, &p, &m));
    sf_context_event_t ev;
    assert_int_equal(drain(&c, &ev, 1), 1);
    assert_int_equal(ev.rule, sf_ctl_rule_cls_unlimited);
    assert_int_equal(ev.state, sf_ctl_in_context);
    assert_int_equal(ev.context, 1);
    assert_int_equal(ev.prev_context, -1);
    assert_int_equal(ev.kind, sf_context_floor);
    assert_int_equal(ev.building, 0);
    assert_int_equal(ev.floor, 0);
    assert_int_equal(ev.scheme, sf_scheme_ekf);
    assert_int_equal(ev.method, sf_fix_wifi);
    assert_true(ev.switched);
    assert_int_equal(ev.cls_candidates, 5);
    assert_int_equal(ev.cls_identified, 1);
    assert_int_equal(ev.cls_method, sf_fix_wifi);
    assert_int_equal(ev.cls_hits, 3);
    assert_int_equal(ev.port, -1);
    assert_false(ev.gnss_on);
    assert_true(ev.wifi_on);
    assert_false(ev.ble_on);
    assert_int_equal(c.switches, 1);
    /* radio time: 6 s in INIT with every radio on, then Wi-Fi only */
    assert_true(fabs(c.gnss_on_s - 6.0) < 1e-9 && fabs(c.ble_on_s - 6.0) < 1e-9 && fabs(c.wifi_on_s - 6.0) < 1e-9);
    m.t_us = 9 * S_US;
    (void)sf_controller_update(&c, &p, &m);
    assert_true(fabs(c.gnss_on_s - 6.0) < 1e-9 && fabs(c.wifi_on_s - 8.0) < 1e-9);
}

/* ---- NEAR_PORT ----------------------------------------------------------------------------------- */

static void test_near_port_of_its_floor_only(void **state)
{
    (void)state;
    const sf_site_t site = campus();
    sf_controller_t c;
    sf_params_t p;
    setup(&c, &p, &site);
    enter_floor(&c, &p, 1 * S_US, 0, 10.0, 10.0);
    /* far from every port: nothing */
    sf_ctl_motion_t m = at(2 * S_US, 10.0, 10.0, 0, 3, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m));
    /* 3.9 m from the stairs' centre: within radius 3 + margin 1 */
    m = at(3 * S_US, 5.0, 11.1, 0, 5, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    sf_context_event_t ev;
    assert_int_equal(drain(&c, &ev, 1), 1);
    assert_int_equal(ev.rule, sf_ctl_rule_near_port);
    assert_int_equal(ev.state, sf_ctl_transition);
    assert_int_equal(ev.port, 1);
    assert_int_equal(ev.port_kind, sf_port_stairs);
    assert_false(ev.switched);
    assert_int_equal(ev.context, 1);
    assert_int_equal(ev.cls_candidates, 2); /* A floors 0 and 1 */
    assert_int_equal(ev.steps_in_transition, 0);
    assert_int_equal(c.transitions, 1);

    /* on floor 2 the stairs (floors 0–1) are not a port of this floor */
    sf_controller_t c2;
    setup(&c2, &p, &site);
    enter_floor(&c2, &p, 1 * S_US, 2, 10.0, 10.0);
    m = at(2 * S_US, 5.0, 15.0, 2, 1, sf_activity_walking);
    assert_false(sf_controller_update(&c2, &p, &m));
    assert_int_equal(c2.state, sf_ctl_in_context);
    /* but the elevator (floors 0–2) is */
    m = at(3 * S_US, 15.0, 15.0, 2, 2, sf_activity_walking);
    assert_true(sf_controller_update(&c2, &p, &m));
    assert_int_equal(c2.port, 2);
}

/* GIVEN IN_CONTEXT on floor 0 of A (identified at 1 s), WHEN the position is at (x_m, y_m) at 2 s with
 * `steps` credited, THEN one event: NEAR_PORT (drained; the caller's `ev`, if given, gets it). */
static void at_port(sf_controller_t *const c, sf_params_t *const p, const sf_site_t *const site, const double x_m,
                    const double y_m, const int32_t steps, sf_context_event_t *const ev)
{
    setup(c, p, site);
    enter_floor(c, p, 1 * S_US, 0, x_m, y_m - 3.0);
    const sf_ctl_motion_t m = at(2 * S_US, x_m, y_m, 0, steps, sf_activity_walking);
    assert_true(sf_controller_update(c, p, &m));
    sf_context_event_t got[4];
    assert_int_equal(drain(c, got, 4), 1);
    assert_int_equal(got[0].rule, sf_ctl_rule_near_port);
    if (ev != NULL) {
        *ev = got[0];
    }
}

/* ---- ELEVATOR ------------------------------------------------------------------------------------ */

static void ride(sf_controller_t *const c, const int64_t from_us, const int64_t to_us)
{
    for (int64_t t = from_us; t <= to_us; t += S_US / 10) {
        sf_controller_activity(c, t, sf_activity_elevator);
    }
}

static void test_elevator(void **state)
{
    (void)state;
    const sf_site_t site = campus();
    sf_controller_t c;
    sf_params_t p;
    sf_context_event_t ev[4];
    at_port(&c, &p, &site, 15.0, 15.0, 10, &ev[0]);
    assert_int_equal(ev[0].port, 2);
    sf_ctl_motion_t m;
    assert_int_equal(ev[0].cls_candidates, 3);
    /* floor 2 heard before the ride: walking and a "unique floor", but no ride yet → no exit */
    hear_floors(&c, &p, 2500000, 4u);
    m = at(2600000, 15.0, 15.0, 0, 12, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m));
    /* riding 3–6 s, floor 1 passed at 4 s: no exit while riding */
    ride(&c, 3 * S_US, 4 * S_US);
    hear_floors(&c, &p, 4 * S_US, 2u);
    m = at(4 * S_US, 15.0, 15.0, 0, 12, sf_activity_elevator);
    assert_false(sf_controller_update(&c, &p, &m));
    ride(&c, 4 * S_US, 6 * S_US);
    hear_floors(&c, &p, 5500000, 2u); /* floor 1 heard again late in the ride, within the window of the exit */
    /* the door opens on floor 2: heard, but not walking yet → no exit */
    hear_floors(&c, &p, 6500000, 4u);
    m = at(6500000, 15.0, 15.0, 0, 12, sf_activity_still);
    assert_false(sf_controller_update(&c, &p, &m));
    /* one walking step (two needed) → no exit */
    m = at(7 * S_US, 15.0, 14.0, 0, 13, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m));
    /* two walking steps, floor 2 unique since the ride (floor 1's 4 s scan does not count) → exit */
    m = at(7500000, 15.0, 12.0, 0, 14, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    assert_int_equal(drain(&c, ev, 4), 1); /* 3 m from the elevator: no re-entry */
    assert_int_equal(ev[0].rule, sf_ctl_rule_elevator);
    assert_int_equal(ev[0].state, sf_ctl_in_context);
    assert_int_equal(ev[0].context, 3);
    assert_int_equal(ev[0].prev_context, 1);
    assert_int_equal(ev[0].floor, 2);
    assert_true(ev[0].switched);
    assert_false(ev[0].recalibrated);
    assert_int_equal(ev[0].cls_identified, 1);
    assert_int_equal(ev[0].steps_in_transition, 4);
    assert_int_equal(sf_controller_floor(&c), 2);

    /* no unique floor after the ride: floors 1 and 2 heard together → no exit */
    sf_controller_t d;
    at_port(&d, &p, &site, 15.0, 15.0, 0, NULL);
    ride(&d, 3 * S_US, 5 * S_US);
    hear_floors(&d, &p, 6 * S_US, 6u);
    m = at(6 * S_US, 15.0, 13.0, 0, 3, sf_activity_walking);
    assert_false(sf_controller_update(&d, &p, &m));
    assert_int_equal(d.state, sf_ctl_transition);

    /* self-neighbourhood: the ride ends on floor 0 again → the same context, no switch */
    sf_controller_t e;
    at_port(&e, &p, &site, 15.0, 15.0, 0, NULL);
    ride(&e, 3 * S_US, 5 * S_US);
    hear_floors(&e, &p, 6 * S_US, 1u);
    m = at(6 * S_US, 15.0, 12.0, 0, 2, sf_activity_walking);
    assert_true(sf_controller_update(&e, &p, &m));
    assert_int_equal(drain(&e, ev, 4), 1);
    assert_int_equal(ev[0].rule, sf_ctl_rule_elevator);
    assert_int_equal(ev[0].context, 1);
    assert_false(ev[0].switched);
    assert_int_equal(e.switches, 1); /* the first identification only */
}

/* ---- STAIRS -------------------------------------------------------------------------------------- */

static void test_stairs(void **state)
{
    (void)state;
    const sf_site_t site = campus();
    sf_controller_t c;
    sf_params_t p;
    at_port(&c, &p, &site, 3.0, 15.0, 100, NULL);
    sf_context_event_t ev[4];
    sf_ctl_motion_t m;
    /* 19 of 20 steps with floor 1 unique: no exit */
    hear_floors(&c, &p, 10 * S_US, 2u);
    m = at(10 * S_US, 5.0, 15.0, 0, 119, sf_activity_stairs_up);
    assert_false(sf_controller_update(&c, &p, &m));
    /* 20 steps, but floors 0 and 1 both heard: no unique floor, no exit */
    hear_floors(&c, &p, 11 * S_US, 3u);
    m = at(11 * S_US, 5.0, 15.0, 0, 120, sf_activity_stairs_up);
    assert_false(sf_controller_update(&c, &p, &m));
    /* 22 steps, floor 1 alone → exit to floor 1, recalibrated to the upper endpoint (7, 15) */
    hear_floors(&c, &p, 15 * S_US, 2u);
    m = at(15 * S_US, 6.0, 16.0, 0, 122, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    assert_int_equal(drain(&c, ev, 4), 2);
    assert_int_equal(ev[0].rule, sf_ctl_rule_stairs);
    assert_int_equal(ev[0].context, 2);
    assert_int_equal(ev[0].prev_context, 1);
    assert_int_equal(ev[0].floor, 1);
    assert_true(ev[0].switched);
    assert_true(ev[0].recalibrated);
    assert_true(ev[0].recal_x_m == 7.0 && ev[0].recal_y_m == 15.0);
    assert_int_equal(ev[0].steps_in_transition, 22);
    assert_int_equal(ev[0].port, 1);
    assert_int_equal(c.recalibrations, 1);
    /* the endpoint is still within the staircase's port: transition detection again at once */
    assert_int_equal(ev[1].rule, sf_ctl_rule_near_port);
    assert_int_equal(ev[1].context, 2);
    assert_int_equal(ev[1].steps_in_transition, 0);

    /* up and down again: 20 steps ending on floor 0 → no switch, no recalibration */
    sf_controller_t d;
    at_port(&d, &p, &site, 5.0, 15.0, 0, NULL);
    hear_floors(&d, &p, 20 * S_US, 1u);
    m = at(20 * S_US, 5.0, 15.0, 0, 20, sf_activity_walking);
    assert_true(sf_controller_update(&d, &p, &m));
    assert_int_equal(drain(&d, ev, 4), 2);
    assert_int_equal(ev[0].rule, sf_ctl_rule_stairs);
    assert_int_equal(ev[0].context, 1);
    assert_false(ev[0].switched);
    assert_false(ev[0].recalibrated);
    assert_int_equal(d.recalibrations, 0);
}

/* ---- DOOR ---------------------------------------------------------------------------------------- */

/* Outdoors (a good GNSS fix), then at door 0. */
static void outdoors_at_door(sf_controller_t *const c, sf_params_t *const p, const sf_site_t *const site)
{
    setup(c, p, site);
    sf_controller_gnss(c, p, 1 * S_US, 4.0);
    sf_ctl_motion_t m = at(1 * S_US, 10.0, -10.0, 0, 0, sf_activity_walking);
    assert_true(sf_controller_update(c, p, &m));
    sf_context_event_t ev;
    assert_true(sf_controller_next_event(c, &ev));
    assert_int_equal(ev.context, 0);
    assert_int_equal(ev.cls_method, sf_fix_gnss);
    m = at(2 * S_US, 10.0, -1.0, 0, 0, sf_activity_walking);
    assert_true(sf_controller_update(c, p, &m));
    assert_true(sf_controller_next_event(c, &ev));
    assert_int_equal(ev.rule, sf_ctl_rule_near_port);
    assert_int_equal(ev.port, 0);
    assert_int_equal(ev.cls_candidates, 2); /* A floor 0 and outdoors */
}

static void test_door(void **state)
{
    (void)state;
    const sf_site_t site = campus();
    sf_controller_t c;
    sf_params_t p;
    outdoors_at_door(&c, &p, &site);
    /* 4 steps with floor 0 heard: no exit */
    hear_floors(&c, &p, 3 * S_US, 1u);
    sf_ctl_motion_t m = at(3 * S_US, 10.0, 1.0, 0, 4, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m));
    /* exactly 5 steps → exit, the unique identification: floor 0 of A */
    m = at(3500000, 10.0, 3.5, 0, 5, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    sf_context_event_t ev[4];
    assert_int_equal(drain(&c, ev, 4), 1); /* 3.5 m from the door: no re-entry (1.5 + 1) */
    assert_int_equal(ev[0].rule, sf_ctl_rule_door);
    assert_int_equal(ev[0].context, 1);
    assert_int_equal(ev[0].prev_context, 0);
    assert_int_equal(ev[0].steps_in_transition, 5);
    assert_int_equal(ev[0].cls_method, sf_fix_wifi);
    assert_true(ev[0].switched);
    assert_int_equal(ev[0].scheme, sf_scheme_ekf);

    /* the paper's unresolved tie: GNSS and floor 0 both identified at the entrance → the GNSS side,
     * outdoors, wherever the position is (an accurate fix needs open sky; Wi-Fi carries through a door) */
    for (int inside = 0; inside <= 1; inside++) {
        sf_controller_t d;
        outdoors_at_door(&d, &p, &site);
        hear_floors(&d, &p, 3 * S_US, 1u);
        sf_controller_gnss(&d, &p, 3 * S_US, 4.0);
        m = at(3500000, 10.0, inside ? 3.5 : -3.5, 0, 5, sf_activity_walking);
        assert_true(sf_controller_update(&d, &p, &m));
        assert_int_equal(drain(&d, ev, 4), 1);
        assert_int_equal(ev[0].rule, sf_ctl_rule_door);
        assert_int_equal(ev[0].cls_identified, 2);
        assert_int_equal(ev[0].cls_method, sf_fix_gnss);
        assert_int_equal(ev[0].context, 0);
        assert_false(ev[0].switched);
    }
    /* nothing identified at 5 steps → the outline that holds the position decides */
    for (int inside = 0; inside <= 1; inside++) {
        sf_controller_t d;
        outdoors_at_door(&d, &p, &site);
        m = at(3500000, 10.0, inside ? 3.5 : -3.5, 0, 5, sf_activity_walking);
        assert_true(sf_controller_update(&d, &p, &m));
        assert_int_equal(drain(&d, ev, 4), 1);
        assert_int_equal(ev[0].rule, sf_ctl_rule_door);
        assert_int_equal(ev[0].cls_identified, 0);
        assert_int_equal(ev[0].cls_method, 0);
        assert_int_equal(ev[0].context, inside ? 1 : 0);
        assert_true(ev[0].switched == (inside != 0));
    }
}

/* ---- limited mode -------------------------------------------------------------------------------- */

static void test_limited_mode_ignores_other_contexts(void **state)
{
    (void)state;
    const sf_site_t site = campus();
    sf_controller_t c;
    sf_params_t p;
    at_port(&c, &p, &site, 5.0, 15.0, 0, NULL);
    sf_context_event_t ev[4];
    sf_ctl_motion_t m;
    /* floor 2 (not reachable by these stairs), B's beacons and a good GNSS fix: none are candidates */
    hear_floors(&c, &p, 10 * S_US, 4u);
    const int64_t beacons[] = {0x401, 0x402};
    const float rssi[] = {-50.0f, -50.0f};
    const sf_ble_scan_t ble = {.t_us = 10 * S_US, .n = 2, .beacon_id = beacons, .rssi_dbm = rssi};
    sf_controller_ble(&c, &p, &ble);
    sf_controller_gnss(&c, &p, 10 * S_US, 3.0);
    m = at(10 * S_US, 5.0, 15.0, 0, 25, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m));
    assert_int_equal(c.state, sf_ctl_transition);
    /* floor 1 with floor 2: floor 1 is the one candidate identified → exit there */
    hear_floors(&c, &p, 11 * S_US, 6u);
    m = at(11 * S_US, 5.0, 15.0, 0, 26, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    assert_true(sf_controller_next_event(&c, &ev[0]));
    assert_int_equal(ev[0].rule, sf_ctl_rule_stairs);
    assert_int_equal(ev[0].context, 2);
    assert_int_equal(ev[0].cls_identified, 1);
    assert_int_equal(ev[0].cls_candidates, 2);
}

/* ---- GPS policy ---------------------------------------------------------------------------------- */

static void test_gps_policy(void **state)
{
    (void)state;
    const sf_site_t site = campus();
    sf_controller_t c;
    sf_params_t p;
    setup(&c, &p, &site);
    enter_floor(&c, &p, 1 * S_US, 0, 10.0, 10.0);
    /* indoors: GNSS and BLE off, Wi-Fi (the LSD) on; landmarks and port fixes always */
    assert_false(sf_controller_source_on(&c, sf_fix_gnss));
    assert_true(sf_controller_source_on(&c, sf_fix_wifi));
    assert_false(sf_controller_source_on(&c, sf_fix_ble));
    assert_true(sf_controller_source_on(&c, sf_fix_landmark) && sf_controller_source_on(&c, sf_fix_port));
    /* at the stairs (no outdoor neighbour): GNSS still off */
    sf_ctl_motion_t m = at(2 * S_US, 5.0, 15.0, 0, 0, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    assert_false(sf_controller_source_on(&c, sf_fix_gnss));
    sf_context_event_t ev[4];
    (void)drain(&c, ev, 4);
    assert_false(ev[0].gnss_on);
    /* at the door to outdoors: GNSS on */
    sf_controller_t d;
    outdoors_at_door(&d, &p, &site);
    assert_true(sf_controller_source_on(&d, sf_fix_gnss));
    assert_true(sf_controller_source_on(&d, sf_fix_wifi)); /* A floor 0's CDD */
    assert_false(sf_controller_source_on(&d, sf_fix_ble));
    /* outdoors, away from doors: GNSS only */
    sf_controller_t o;
    setup(&o, &p, &site);
    sf_controller_gnss(&o, &p, 1 * S_US, 4.0);
    m = at(1 * S_US, 30.0, -10.0, 0, 0, sf_activity_walking);
    assert_true(sf_controller_update(&o, &p, &m));
    assert_true(sf_controller_source_on(&o, sf_fix_gnss));
    assert_false(sf_controller_source_on(&o, sf_fix_wifi) || sf_controller_source_on(&o, sf_fix_ble));
    /* building B (BLE): BLE only, and its scheme (kalman) */
    sf_controller_t b;
    setup(&b, &p, &site);
    const int64_t beacons[] = {0x402};
    const float rssi[] = {-70.0f};
    const sf_ble_scan_t ble = {.t_us = 1 * S_US, .n = 1, .beacon_id = beacons, .rssi_dbm = rssi};
    sf_controller_ble(&b, &p, &ble);
    m = at(1 * S_US, 50.0, 10.0, 0, 0, sf_activity_walking);
    assert_true(sf_controller_update(&b, &p, &m));
    assert_int_equal(b.context, 4);
    assert_int_equal(sf_controller_scheme(&b), sf_scheme_kalman);
    assert_true(sf_controller_source_on(&b, sf_fix_ble));
    assert_false(sf_controller_source_on(&b, sf_fix_wifi) || sf_controller_source_on(&b, sf_fix_gnss));
}

/* ---- LEFT_PORT ----------------------------------------------------------------------------------- */

static void test_left_port(void **state)
{
    (void)state;
    const sf_site_t site = campus();
    sf_controller_t c;
    sf_params_t p;
    setup(&c, &p, &site);
    enter_floor(&c, &p, 1 * S_US, 0, 10.0, 10.0);
    sf_ctl_motion_t m = at(2 * S_US, 5.0, 15.0, 0, 0, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    sf_context_event_t ev[4];
    (void)drain(&c, ev, 4);
    /* 5.9 m from the centre: within radius 3 + margin 1 + leave 2 → still in the transition */
    m = at(3 * S_US, 5.0, 9.1, 0, 8, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m));
    /* 6.5 m → left: the old context stays */
    m = at(4 * S_US, 5.0, 8.5, 0, 9, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    assert_int_equal(drain(&c, ev, 4), 1);
    assert_int_equal(ev[0].rule, sf_ctl_rule_left_port);
    assert_int_equal(ev[0].state, sf_ctl_in_context);
    assert_int_equal(ev[0].context, 1);
    assert_int_equal(ev[0].prev_context, 1);
    assert_false(ev[0].switched);
    assert_int_equal(ev[0].steps_in_transition, 9);
    assert_int_equal(c.state, sf_ctl_in_context);
    assert_int_equal(c.port, -1);
}

/* ---- attach -------------------------------------------------------------------------------------- */

static void test_attach_checks_the_map(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_controller_t c;
    const char *what = NULL;
    /* no context map: inactive, every source on, no events */
    sf_site_t none = campus();
    none.contexts = (sf_context_map_t){0};
    assert_int_equal(sf_controller_attach(&c, &p, &none, &what), SF_OK);
    assert_false(sf_controller_active(&c));
    assert_true(sf_controller_source_on(&c, sf_fix_gnss) && sf_controller_source_on(&c, sf_fix_ble));
    const sf_ctl_motion_t m = at(1 * S_US, 5.0, 15.0, 0, 30, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m));
    /* disabled: inactive */
    p.controller_enabled = 0;
    const sf_site_t site = campus();
    assert_int_equal(sf_controller_attach(&c, &p, &site, &what), SF_OK);
    assert_false(sf_controller_active(&c));
    p.controller_enabled = 1;
    /* a scheme that is no fusion scheme */
    ctx_scheme[2] = sf_scheme_controller;
    assert_int_equal(sf_controller_attach(&c, &p, &site, &what), SF_ERANGE);
    assert_string_equal(what, "context_scheme is not a fusion scheme");
    assert_false(sf_controller_active(&c));
    ctx_scheme[2] = sf_scheme_ekf;
    /* stairs without steps */
    port_steps[1] = 0;
    assert_int_equal(sf_controller_attach(&c, &p, &site, &what), SF_ERANGE);
    assert_string_equal(what, "port_steps: > 0 exactly for stairs");
    port_steps[1] = 20;
    /* too many contexts */
    sf_site_t big = campus();
    big.contexts.n_contexts = SF_CONTROLLER_MAX_CONTEXTS + 1;
    assert_int_equal(sf_controller_attach(&c, &p, &big, &what), SF_ERANGE);
    assert_int_equal(sf_controller_attach(&c, &p, &site, &what), SF_OK);
    assert_string_equal(what, "ok");
    assert_string_equal(sf_controller_rule_text(sf_ctl_rule_door), "door: steps since the transition began");
}

/* ---- the estimator ------------------------------------------------------------------------------- */

static void test_estimator_gate_and_port_fix(void **state)
{
    (void)state;
    static sf_estimator_t est;
    static sf_fingerprint_workspace_t ws;
    sf_params_t p;
    sf_params_default(&p);
    p.controller_gate_sources = 1; /* the paper's one method at a time: what is off is withheld */
    p.init_use_config_pose = 1; /* every scheme starts at the foot of the stairs, floor 0 */
    p.init_x_m = 5.0;
    p.init_y_m = 15.0;
    const sf_site_t site = campus();
    sf_estimator_init(&est, &p);
    assert_int_equal(sf_estimator_attach_site(&est, &p, &site, &ws), SF_OK);
    sf_fix_t fix;
    bool has_fix;
    sf_fix_audit_t audits[sf_scheme_count];
    sf_context_event_t ev;
    int n;
    sf_pose_t pose;
    /* INIT: the controller's pose is the init scheme's (ekf), at the config start */
    assert_true(sf_estimator_scheme_pose(&est, &p, sf_scheme_controller, &pose));
    assert_int_equal(pose.scheme, sf_scheme_controller);
    assert_true(pose.x_m == 5.0 && pose.y_m == 15.0);
    /* floor 0 heard (no radio map: no fix, but the CLS hears it) → IN_CONTEXT(1) */
    scan_buf_t b;
    sf_wifi_scan_t scan = floors_scan(&b, 1 * S_US, 1u, 3, -60.0f);
    assert_int_equal(sf_estimator_wifi(&est, &p, &scan, &fix, &has_fix, audits), 0);
    assert_true(sf_estimator_next_context(&est, &p, &ev, &fix, &has_fix, audits, &n));
    assert_int_equal(ev.rule, sf_ctl_rule_cls_unlimited);
    assert_false(has_fix);
    assert_int_equal(n, 0);
    /* the next input: the ekf's position is at the stairs → NEAR_PORT */
    scan = floors_scan(&b, 2 * S_US, 1u, 3, -60.0f);
    (void)sf_estimator_wifi(&est, &p, &scan, &fix, &has_fix, audits);
    assert_true(sf_estimator_next_context(&est, &p, &ev, &fix, &has_fix, audits, &n));
    assert_int_equal(ev.rule, sf_ctl_rule_near_port);
    assert_false(sf_estimator_next_context(&est, &p, &ev, &fix, &has_fix, audits, &n));
    /* GNSS in a stairs transition: off → one CONTEXT_OFF audit per scheme, no fix */
    const sf_gnss_t gnss = {.t_us = 2500000, .lat_deg = 49.0, .lon_deg = 11.0, .accuracy_m = 3.0};
    assert_int_equal(sf_estimator_gnss(&est, &p, &gnss, &fix, &has_fix, audits), sf_scheme_count);
    assert_false(has_fix);
    for (int s = 0; s < sf_scheme_count; s++) {
        assert_int_equal(audits[s].reason, sf_fix_reason_context_off);
        assert_int_equal(audits[s].method, sf_fix_gnss);
        assert_false(audits[s].accepted);
    }
    sf_estimator_status_t st;
    sf_estimator_status(&est, &st);
    assert_int_equal(st.context_off, 1);
    assert_true(st.controller_active);
    assert_int_equal(st.context_transitions, 1);
    /* the flight's 20 steps (the IMU pipeline's steps are test_estimator's) and floor 1 heard */
    est.step_count = 20;
    scan = floors_scan(&b, 12 * S_US, 2u, 3, -60.0f);
    (void)sf_estimator_wifi(&est, &p, &scan, &fix, &has_fix, audits);
    assert_true(sf_estimator_next_context(&est, &p, &ev, &fix, &has_fix, audits, &n));
    assert_int_equal(ev.rule, sf_ctl_rule_stairs);
    assert_true(ev.recalibrated);
    assert_true(has_fix);
    assert_int_equal(fix.method, sf_fix_port);
    assert_int_equal(fix.floor, 1);
    assert_true(fix.x_m == 7.0 && fix.y_m == 15.0 && fix.accuracy_m == p.controller_recal_sigma_m);
    assert_int_equal(n, sf_scheme_count);
    /* the fixed-gain blends take it with α = 1, like a landmark; the Wi-Fi baselines ignore it */
    const int fixed[] = {sf_scheme_overwrite, sf_scheme_static, sf_scheme_adaptive};
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++) {
        assert_true(audits[fixed[i]].accepted);
        assert_true(audits[fixed[i]].alpha == 1.0);
        assert_true(sf_estimator_scheme_pose(&est, &p, fixed[i], &pose));
        assert_true(fabs(pose.x_m - 7.0) < 1e-9 && fabs(pose.y_m - 15.0) < 1e-9);
        assert_int_equal(pose.floor, 1); /* the shared floor followed the controller's */
    }
    assert_int_equal(audits[sf_scheme_wifi_only].reason, sf_fix_reason_scheme_ignores);
    assert_true(audits[sf_scheme_kalman].accepted && audits[sf_scheme_ekf].accepted);
    /* the controller's pose: the ekf's (the context's scheme), scheme 8, floor 1 */
    assert_true(sf_estimator_scheme_pose(&est, &p, sf_scheme_controller, &pose));
    assert_int_equal(pose.scheme, sf_scheme_controller);
    assert_int_equal(pose.floor, 1);
    assert_true(pose.x_m > 5.9 && pose.x_m < 7.0 && fabs(pose.y_m - 15.0) < 1e-6); /* its gain, P ≈ R: half-way */
    sf_estimator_status(&est, &st);
    assert_int_equal(st.floor, 1);
    assert_int_equal(st.context_recalibrations, 1);
    assert_int_equal(st.context_switches, 2);
    /* the re-entry at the staircase follows */
    assert_true(sf_estimator_next_context(&est, &p, &ev, &fix, &has_fix, audits, &n));
    assert_int_equal(ev.rule, sf_ctl_rule_near_port);
    assert_false(has_fix);
}

/* GIVEN the primary pose following the static scheme in INIT, 4 m east of the ekf, WHEN the CLS
 * identifies floor 0 (whose scheme is the ekf), THEN the pose does not jump: it starts where it was and
 * fades into the ekf's with controller.handover_s, the offset in its variance; with 0 it jumps. */
static void test_scheme_switch_hands_over(void **state)
{
    (void)state;
    static sf_estimator_t est;
    static sf_fingerprint_workspace_t ws;
    for (int jump = 0; jump < 2; jump++) {
        sf_params_t p;
        sf_params_default(&p);
        p.init_use_config_pose = 1;
        p.init_x_m = 5.0;
        p.init_y_m = 15.0;
        p.controller_init_scheme = sf_scheme_static; /* the campus's contexts name two schemes */
        p.controller_handover_s = jump ? 0.0 : 5.0;
        const sf_site_t site = campus();
        sf_estimator_init(&est, &p);
        assert_int_equal(sf_estimator_attach_site(&est, &p, &site, &ws), SF_OK);
        est.fusion[sf_scheme_static].x_m = 9.0;
        sf_pose_t pose;
        assert_true(sf_estimator_scheme_pose(&est, &p, sf_scheme_controller, &pose));
        assert_true(fabs(pose.x_m - 9.0) < 1e-9);
        scan_buf_t b;
        sf_fix_t fix;
        bool has_fix;
        sf_fix_audit_t audits[sf_scheme_count];
        sf_wifi_scan_t scan = floors_scan(&b, 1 * S_US, 1u, 3, -60.0f);
        (void)sf_estimator_wifi(&est, &p, &scan, &fix, &has_fix, audits);
        assert_int_equal(sf_controller_scheme(&est.controller), sf_scheme_ekf);
        assert_true(sf_estimator_scheme_pose(&est, &p, sf_scheme_controller, &pose));
        sf_pose_t ekf;
        assert_true(sf_estimator_scheme_pose(&est, &p, sf_scheme_ekf, &ekf));
        if (jump) {
            assert_true(fabs(pose.x_m - 5.0) < 1e-9);
            continue;
        }
        assert_true(fabs(pose.x_m - 9.0) < 1e-9); /* no jump */
        assert_true(fabs(pose.cov_m2[0] - (ekf.cov_m2[0] + 16.0)) < 1e-9);
        /* one time constant later by the estimator's clock (the IMU's, which this test does not feed)
         * the offset is 4/e */
        est.t_us = est.handover_t_us + 5 * S_US;
        assert_true(sf_estimator_scheme_pose(&est, &p, sf_scheme_controller, &pose));
        assert_true(sf_estimator_scheme_pose(&est, &p, sf_scheme_ekf, &ekf));
        assert_true(fabs(pose.x_m - (ekf.x_m + 4.0 * exp(-1.0))) < 1e-9);
        assert_true(fabs(pose.y_m - ekf.y_m) < 1e-9);
    }
}

/* ---- the barometer's floor and the staircase's own steps (our rules, sf_controller.h) -------------- */

/* GIVEN a walker on floor 0 of A who rode the elevator (3–5 s) with controller.floor_from_barometer. */
static void ridden(sf_controller_t *const c, sf_params_t *const p, const sf_site_t *const site)
{
    at_port(c, p, site, 15.0, 15.0, 0, NULL);
    p->controller_floor_from_barometer = 1;
    ride(c, 3 * S_US, 5 * S_US);
}

/* GIVEN an elevator transition with controller.floor_from_barometer = 1, WHEN the ride ends and the user
 * walks again, THEN the barometric floor decides when the CLS identified nothing, breaks a tie it is
 * part of, and never overrules a unique identification. */
static void test_barometer_decides_the_floor(void **state)
{
    (void)state;
    const sf_site_t site = campus();
    sf_context_event_t ev[4];
    sf_controller_t c;
    sf_params_t p;
    /* nothing heard after the ride, the barometer on floor 2 → floor 2, by the barometer */
    ridden(&c, &p, &site);
    sf_ctl_motion_t m = at(6 * S_US, 15.0, 14.0, 2, 1, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m)); /* one walking step: not yet walking again */
    m = at(6500000, 15.0, 12.0, 2, 2, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    assert_int_equal(drain(&c, ev, 4), 1);
    assert_int_equal(ev[0].rule, sf_ctl_rule_elevator);
    assert_int_equal(ev[0].context, 3);
    assert_int_equal(ev[0].floor, 2);
    assert_true(ev[0].floor_from_barometer);
    assert_int_equal(ev[0].cls_identified, 0);

    /* floors 1 and 2 heard together, the barometer on floor 2 → floor 2 (the tie broken) */
    ridden(&c, &p, &site);
    hear_floors(&c, &p, 6 * S_US, 6u);
    m = at(6 * S_US, 15.0, 12.0, 2, 2, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    assert_int_equal(drain(&c, ev, 4), 1);
    assert_int_equal(ev[0].context, 3);
    assert_true(ev[0].floor_from_barometer);
    assert_int_equal(ev[0].cls_identified, 2);

    /* the same tie with the barometer on floor 0 (not among those heard) → no exit */
    ridden(&c, &p, &site);
    hear_floors(&c, &p, 6 * S_US, 6u);
    m = at(6 * S_US, 15.0, 13.0, 0, 2, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m));
    assert_int_equal(c.state, sf_ctl_transition);

    /* floor 1 unique, the barometer on floor 2 → floor 1: the CLS's unique identification wins */
    ridden(&c, &p, &site);
    hear_floors(&c, &p, 6 * S_US, 2u);
    m = at(6 * S_US, 15.0, 12.0, 2, 2, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    assert_int_equal(drain(&c, ev, 4), 1);
    assert_int_equal(ev[0].context, 2);
    assert_false(ev[0].floor_from_barometer);
}

/* GIVEN a stairs transition begun on the approach, WHEN level steps then stairs steps are credited,
 * THEN only the steps from the first stairs step count toward the staircase's 20. */
static void test_stairs_count_from_the_first_stair(void **state)
{
    (void)state;
    const sf_site_t site = campus();
    sf_controller_t c;
    sf_params_t p;
    at_port(&c, &p, &site, 3.0, 15.0, 100, NULL);
    sf_context_event_t ev[4];
    sf_ctl_motion_t m;
    /* 8 level steps inside the port's disc (the approach), floor 1 heard: no exit */
    hear_floors(&c, &p, 5 * S_US, 2u);
    m = at(5 * S_US, 4.0, 15.0, 0, 108, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m));
    /* the first stairs step, then 18 more: 19 on the staircase (27 since the transition began) */
    m = at(6 * S_US, 4.5, 15.0, 0, 109, sf_activity_stairs_up);
    assert_false(sf_controller_update(&c, &p, &m));
    hear_floors(&c, &p, 14 * S_US, 2u);
    m = at(14 * S_US, 5.5, 15.0, 0, 127, sf_activity_stairs_up);
    assert_false(sf_controller_update(&c, &p, &m));
    /* the 20th step on the staircase → exit to floor 1, recalibrated */
    m = at(14500000, 6.0, 15.0, 0, 128, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    assert_true(sf_controller_next_event(&c, &ev[0]));
    assert_int_equal(ev[0].rule, sf_ctl_rule_stairs);
    assert_int_equal(ev[0].context, 2);
    assert_int_equal(ev[0].steps_in_transition, 20);
    assert_true(ev[0].recalibrated);
}

/* GIVEN the outdoor context, WHEN no accurate GNSS fix comes for controller.context_lost_s, THEN LOST:
 * back to INIT with every context searched, and the next unique identification is taken. */
static void test_lost_outdoors(void **state)
{
    (void)state;
    const sf_site_t site = campus();
    sf_controller_t c;
    sf_params_t p;
    setup(&c, &p, &site);
    sf_controller_gnss(&c, &p, 1 * S_US, 4.0);
    sf_ctl_motion_t m = at(1 * S_US, 30.0, -10.0, 0, 0, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    sf_context_event_t ev[4];
    assert_int_equal(drain(&c, ev, 4), 1);
    assert_int_equal(ev[0].context, 0);
    sf_controller_gnss(&c, &p, 2 * S_US, 25.0); /* inaccurate: does not keep the context alive */
    m = at(10 * S_US, 30.0, -10.0, 0, 10, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m)); /* 9 s without an accurate fix */
    m = at(11500000, 30.0, -10.0, 0, 12, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    assert_int_equal(drain(&c, ev, 4), 1);
    assert_int_equal(ev[0].rule, sf_ctl_rule_lost);
    assert_int_equal(ev[0].state, sf_ctl_init);
    assert_int_equal(ev[0].prev_context, 0);
    assert_int_equal(ev[0].context, -1);
    assert_int_equal(ev[0].cls_candidates, 5); /* unlimited: every context */
    assert_true(ev[0].gnss_on && ev[0].wifi_on && ev[0].ble_on);
    hear_floors(&c, &p, 12 * S_US, 1u);
    m = at(12 * S_US, 30.0, -10.0, 0, 13, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    assert_int_equal(drain(&c, ev, 4), 1);
    assert_int_equal(ev[0].rule, sf_ctl_rule_cls_unlimited);
    assert_int_equal(ev[0].context, 1);
}

/* GIVEN a floor context and controller.floor_disagree_s = 10 (off by default), WHEN the barometric
 * floor holds another floor of the building away from every port, THEN after 10 s that floor's context
 * (rule BAROMETER); a disagreement that ends before resets the clock. */
static void test_barometer_missed_transition(void **state)
{
    (void)state;
    const sf_site_t site = campus();
    sf_controller_t c;
    sf_params_t p;
    setup(&c, &p, &site);
    p.controller_floor_from_barometer = 1;
    p.controller_floor_disagree_s = 10.0;
    p.controller_barometer_rule = 2; /* everywhere: the test building has stairs and an elevator */
    enter_floor(&c, &p, 1 * S_US, 0, 10.0, 10.0);
    sf_ctl_motion_t m = at(2 * S_US, 10.0, 10.0, 1, 5, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m));
    m = at(4 * S_US, 10.0, 10.0, 0, 7, sf_activity_walking); /* agrees again: the clock restarts */
    assert_false(sf_controller_update(&c, &p, &m));
    m = at(5 * S_US, 10.0, 10.0, 1, 8, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m));
    m = at(14 * S_US, 10.0, 10.0, 1, 18, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m)); /* 9 s */
    m = at(15 * S_US, 10.0, 10.0, 1, 19, sf_activity_walking);
    assert_true(sf_controller_update(&c, &p, &m));
    sf_context_event_t ev;
    assert_true(sf_controller_next_event(&c, &ev));
    assert_int_equal(ev.rule, sf_ctl_rule_barometer);
    assert_int_equal(ev.prev_context, 1);
    assert_int_equal(ev.context, 2);
    assert_int_equal(ev.floor, 1);
    assert_true(ev.switched && ev.floor_from_barometer);

    /* the default (barometer_rule 1): building A has stairs and an elevator, so their rules alone
     * change its floor, and the primary pose keeps the context's floor */
    setup(&c, &p, &site);
    p.controller_floor_from_barometer = 1;
    enter_floor(&c, &p, 1 * S_US, 0, 10.0, 10.0);
    m = at(2 * S_US, 10.0, 10.0, 1, 5, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m));
    m = at(30 * S_US, 10.0, 10.0, 1, 40, sf_activity_walking);
    assert_false(sf_controller_update(&c, &p, &m));
    assert_int_equal(c.context, 1);
    assert_int_equal(sf_controller_pose_floor(&c, &p, 1), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_needs_a_unique_context),
        cmocka_unit_test(test_near_port_of_its_floor_only),
        cmocka_unit_test(test_elevator),
        cmocka_unit_test(test_stairs),
        cmocka_unit_test(test_door),
        cmocka_unit_test(test_limited_mode_ignores_other_contexts),
        cmocka_unit_test(test_gps_policy),
        cmocka_unit_test(test_left_port),
        cmocka_unit_test(test_attach_checks_the_map),
        cmocka_unit_test(test_estimator_gate_and_port_fix),
        cmocka_unit_test(test_barometer_decides_the_floor),
        cmocka_unit_test(test_stairs_count_from_the_first_stair),
        cmocka_unit_test(test_lost_outdoors),
        cmocka_unit_test(test_barometer_missed_transition),
        cmocka_unit_test(test_scheme_switch_hands_over),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
