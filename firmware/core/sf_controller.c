/* sf_controller.c — the multi-scheme controller's state machine (see sf_controller.h; its policy:
 * sf_controller_policy.c; the CLS and the map's geometry: sf_cls.c; the map's check: sf_context_check.c). */
#include "sf_controller.h"

#include <math.h>
#include <stddef.h>

#include "sf_assert.h"
#include "sf_error.h"

void sf_controller_init(sf_controller_t *const c, const sf_params_t *const p)
{
    *c = (sf_controller_t){.init_scheme = (int8_t)p->controller_init_scheme,
                           .state = sf_ctl_init,
                           .context = -1,
                           .floor = (int16_t)p->init_floor,
                           .port = -1,
                           .gnss_good_t_us = INT64_MIN,
                           .context_t_us = INT64_MIN,
                           .disagree_t_us = INT64_MIN};
}

int sf_controller_attach(sf_controller_t *const c, const sf_params_t *const p, const sf_site_t *const site,
                         const char **const what)
{
    if (what != NULL) {
        *what = "ok";
    }
    if (c == NULL || p == NULL || site == NULL) {
        return SF_EINVAL;
    }
    sf_controller_init(c, p);
    const int32_t n = site->contexts.n_contexts;
    if (n == 0) {
        return SF_OK; /* no context map: no controller */
    }
    const int rc = sf_cls_check_map(site, what);
    if (rc != SF_OK) {
        return rc;
    }
    c->site = site;
    /* INIT follows the scheme every context names, when they name one (a one-building site): the site
     * chose it, and a walk whose CLS never identifies a context (a floor without a constellation)
     * keeps it; a map of several schemes starts on controller.init_scheme */
    bool shared = true;
    for (int32_t i = 1; i < n; i++) {
        shared = shared && site->contexts.scheme[i] == site->contexts.scheme[0];
    }
    if (shared) {
        c->init_scheme = (int8_t)site->contexts.scheme[0];
    }
    c->active = p->controller_enabled == 1;
    if (c->active) {
        sf_cls_start(&c->cls, sf_cls_all(&site->contexts)); /* unlimited mode */
    }
    return SF_OK;
}

/* ---- evidence ------------------------------------------------------------------------------------ */

void sf_controller_wifi(sf_controller_t *const c, const sf_params_t *const p, const sf_wifi_scan_t *const scan)
{
    (void)p;
    if (c->active) {
        sf_cls_wifi(&c->cls, &c->site->contexts, scan);
    }
}

void sf_controller_ble(sf_controller_t *const c, const sf_params_t *const p, const sf_ble_scan_t *const scan)
{
    (void)p;
    if (c->active) {
        sf_cls_ble(&c->cls, &c->site->contexts, scan);
    }
}

void sf_controller_gnss(sf_controller_t *const c, const sf_params_t *const p, const int64_t t_us,
                        const double accuracy_m)
{
    if (c->active) {
        sf_cls_gnss(&c->cls, &c->site->contexts, t_us, accuracy_m, p->controller_cls_gnss_accuracy_m);
        if (accuracy_m >= 0.0 && accuracy_m <= p->controller_cls_gnss_accuracy_m && t_us > c->gnss_good_t_us) {
            c->gnss_good_t_us = t_us;
        }
    }
}

static bool at_elevator(const sf_controller_t *const c)
{
    return c->state == sf_ctl_transition && c->site->ports.kind[c->port] == sf_port_elevator;
}

void sf_controller_activity(sf_controller_t *const c, const int64_t t_us, const int8_t activity)
{
    if (c->active && activity == sf_activity_elevator && at_elevator(c)) {
        c->elevator_seen = true;
        c->walk_steps = 0; /* walking again counts from the ride's end */
        c->elevator_t_us = t_us > c->elevator_t_us ? t_us : c->elevator_t_us;
    }
}

/* ---- the state machine --------------------------------------------------------------------------- */

static void push(sf_controller_t *const c, const sf_context_event_t *const ev)
{
    SF_ASSERT(c->ev_n >= 0 && c->ev_n <= SF_CONTROLLER_EVENTS && c->ev_head >= 0 && c->ev_head < SF_CONTROLLER_EVENTS);
    if (c->ev_n == SF_CONTROLLER_EVENTS) { /* full: the oldest goes */
        c->ev_head = (c->ev_head + 1) % SF_CONTROLLER_EVENTS;
        c->ev_n--;
        c->events_dropped++;
    }
    c->events[(c->ev_head + c->ev_n) % SF_CONTROLLER_EVENTS] = *ev;
    c->ev_n++;
}

bool sf_controller_next_event(sf_controller_t *const c, sf_context_event_t *const ev)
{
    SF_ASSERT(c != NULL && ev != NULL);
    SF_ASSERT(c->ev_n >= 0 && c->ev_n <= SF_CONTROLLER_EVENTS && c->ev_head >= 0 && c->ev_head < SF_CONTROLLER_EVENTS);
    if (c->ev_n == 0) {
        return false;
    }
    *ev = c->events[c->ev_head];
    c->ev_head = (c->ev_head + 1) % SF_CONTROLLER_EVENTS;
    c->ev_n--;
    return true;
}

/* The step count the transition's steps count from: the first stairs step's on a staircase, else the
 * transition's start (sf_controller.h, "staircase's steps"). */
static int32_t steps_from(const sf_controller_t *const c)
{
    return c->on_stairs ? c->steps_at_stairs : c->steps_at_start;
}

/* Every field of the event from the state after the change. */
static void emit(sf_controller_t *const c, const sf_ctl_motion_t *const m, const int8_t rule, const int16_t prev,
                 const sf_cls_result_t *const r, const bool recal, const double rx_m, const double ry_m,
                 const bool by_baro)
{
    const sf_context_map_t *const map = &c->site->contexts;
    const int16_t ctx = c->context;
    const sf_context_event_t ev = {
        .t_us = m->t_us,
        .state = c->state,
        .context = ctx,
        .prev_context = prev,
        .kind = (int8_t)(ctx >= 0 ? map->kind[ctx] : 0),
        .building = ctx >= 0 ? map->building[ctx] : -1,
        .floor = c->floor,
        .scheme = (int8_t)sf_controller_scheme(c),
        .method = (int8_t)(ctx >= 0 ? map->method[ctx] : 0),
        .port = c->port,
        .port_kind = c->port >= 0 ? c->site->ports.kind[c->port] : 0,
        .rule = rule,
        .switched = ctx != prev,
        .steps_in_transition = c->state == sf_ctl_transition || rule >= sf_ctl_rule_elevator
                                   ? m->step_count - steps_from(c)
                                   : 0,
        .cls_candidates = r->candidates,
        .cls_identified = r->identified,
        .cls_method = r->method,
        .cls_hits = r->hits,
        .floor_from_barometer = by_baro,
        .recalibrated = recal,
        .recal_x_m = rx_m,
        .recal_y_m = ry_m,
        .gnss_on = sf_controller_source_on(c, sf_fix_gnss),
        .wifi_on = sf_controller_source_on(c, sf_fix_wifi),
        .ble_on = sf_controller_source_on(c, sf_fix_ble),
    };
    c->switches += ev.switched ? 1u : 0u;
    if (ev.switched) { /* the latest switch: its rule, and whether the barometer decided its floor */
        c->last_rule = rule;
        c->last_by_baro = by_baro;
    }
    if (ev.state == sf_ctl_in_context) {
        c->context_t_us = m->t_us;
    }
    push(c, &ev);
}

/* The floor of context ctx, or the estimator's in a building context. */
static int16_t floor_of(const sf_controller_t *const c, const int16_t ctx, const int16_t motion_floor)
{
    SF_ASSERT(ctx >= 0 && ctx < c->site->contexts.n_contexts);
    return c->site->contexts.kind[ctx] == sf_context_building ? motion_floor : c->site->contexts.floor[ctx];
}

static double port_distance_m(const sf_controller_t *const c, const int32_t q, const double x_m, const double y_m)
{
    SF_ASSERT(q >= 0 && q < c->site->ports.n_ports);
    return hypot(x_m - (double)c->site->ports.x_m[q], y_m - (double)c->site->ports.y_m[q]);
}

/* The nearest port of this floor within its radius + margin, or −1. */
static int16_t near_port(const sf_controller_t *const c, const sf_params_t *const p, const double x_m,
                         const double y_m, const int16_t floor)
{
    const sf_ports_t *const ports = &c->site->ports;
    int16_t best = -1;
    double best_excess = INFINITY;
    for (int32_t q = 0; q < ports->n_ports; q++) {
        if (!sf_port_joins(ports, q, floor)) {
            continue;
        }
        const double excess = port_distance_m(c, q, x_m, y_m) - (double)ports->radius_m[q];
        if (excess <= p->controller_port_margin_m && excess < best_excess) {
            best = (int16_t)q;
            best_excess = excess;
        }
    }
    return best;
}

static void begin_transition(sf_controller_t *const c, const sf_ctl_motion_t *const m, const int16_t q)
{
    SF_ASSERT(q >= 0 && q < c->site->ports.n_ports); /* near_port's, or the port just left */
    c->state = sf_ctl_transition;
    c->port = q;
    c->steps_at_start = m->step_count;
    c->elevator_seen = false;
    c->on_stairs = false;
    c->steps_at_stairs = m->step_count;
    c->walk_steps = 0;
    c->elevator_t_us = INT64_MIN;
    sf_cls_start(&c->cls, sf_cls_neighbourhood(c->site, q, &c->port_outdoor)); /* limited mode */
    c->transitions++;
    sf_cls_result_t r;
    sf_cls_result(&c->cls, INT64_MAX, &r); /* nothing identified yet: the candidates only */
    emit(c, m, sf_ctl_rule_near_port, c->context, &r, false, 0.0, 0.0, false);
}

/* TRANSITION → IN_CONTEXT (rule), with the new context (the old one for LEFT_PORT). */
static void end_transition(sf_controller_t *const c, const sf_params_t *const p, const sf_ctl_motion_t *const m,
                           const int8_t rule, const int16_t to, const sf_cls_result_t *const r, const bool by_baro)
{
    const int16_t prev = c->context;
    const int16_t from_floor = c->floor;
    const int32_t q = c->port;
    SF_ASSERT(c->state == sf_ctl_transition && q >= 0 && q < c->site->ports.n_ports);
    c->context = to;
    c->floor = floor_of(c, to, m->floor);
    c->state = sf_ctl_in_context;
    sf_cls_stop(&c->cls);
    c->port_outdoor = false;
    bool recal = false;
    double rx_m = 0.0, ry_m = 0.0;
    const sf_context_map_t *const map = &c->site->contexts;
    if (rule == sf_ctl_rule_stairs && c->floor != from_floor) { /* only if the floor changed */
        const bool hi = c->floor == c->site->ports.floor_hi[q];
        rx_m = (double)(hi ? map->port_hi_x_m[q] : map->port_lo_x_m[q]);
        ry_m = (double)(hi ? map->port_hi_y_m[q] : map->port_lo_y_m[q]);
        recal = true;
        c->recalibrations++;
    }
    emit(c, m, rule, prev, r, recal, rx_m, ry_m, by_baro);
    c->port = -1;
    /* still at the port after the exit: transition detection again at once (the paper) */
    const double x_m = recal ? rx_m : m->x_m, y_m = recal ? ry_m : m->y_m;
    if (rule != sf_ctl_rule_left_port && (m->has_position || recal)) {
        const bool still = sf_port_joins(&c->site->ports, q, c->floor) &&
                           port_distance_m(c, q, x_m, y_m) <= (double)c->site->ports.radius_m[q] + p->controller_port_margin_m;
        if (still) {
            begin_transition(c, m, (int16_t)q);
        }
    }
}

/* The barometric floor's context (the motion's floor) when controller.floor_from_barometer, the
 * transition's port joins that floor, the limited search has the context, and the CLS identified no
 * context since since_us or identified this one among others (the barometer breaks the tie, it does
 * not overrule a unique identification); −1 otherwise. */
static int16_t baro_context(const sf_controller_t *const c, const sf_params_t *const p, const sf_ctl_motion_t *const m,
                            const sf_cls_result_t *const r, const int64_t since_us)
{
    const int32_t q = c->port;
    if (!p->controller_floor_from_barometer || !sf_port_joins(&c->site->ports, q, m->floor)) {
        return -1;
    }
    const int16_t ctx = sf_cls_context_of(&c->site->contexts, c->site->contexts.port_building[q], m->floor);
    if (ctx < 0 || !sf_cls_searches(&c->cls, ctx)) {
        return -1;
    }
    return r->identified == 0 || sf_cls_identified(&c->cls, ctx, since_us) ? ctx : -1;
}

/* The outdoor context when the CLS identified it by a GNSS fix since since_us, else −1. */
static int16_t gnss_outdoor(const sf_controller_t *const c, const int64_t since_us)
{
    const sf_context_map_t *const map = &c->site->contexts;
    for (int32_t i = 0; i < map->n_contexts && i < SF_CONTROLLER_MAX_CONTEXTS; i++) {
        if (map->kind[i] == sf_context_outdoor && sf_cls_identified(&c->cls, i, since_us) &&
            c->cls.evidence[i].method == sf_fix_gnss) {
            return (int16_t)i;
        }
    }
    return -1;
}

/* IN_CONTEXT outdoors without an accurate GNSS fix for controller.context_lost_s: back to INIT with the
 * unlimited CLS (rule LOST). */
static bool lost_outdoors(sf_controller_t *const c, const sf_params_t *const p, const sf_ctl_motion_t *const m)
{
    SF_ASSERT(c->state == sf_ctl_in_context && c->context >= 0 && c->context < c->site->contexts.n_contexts);
    if (p->controller_context_lost_s <= 0.0 || c->site->contexts.kind[c->context] != sf_context_outdoor) {
        return false;
    }
    const int64_t since_us = c->gnss_good_t_us > c->context_t_us ? c->gnss_good_t_us : c->context_t_us;
    if ((double)(m->t_us - since_us) * 1e-6 < p->controller_context_lost_s) {
        return false;
    }
    const int16_t prev = c->context;
    c->state = sf_ctl_init;
    c->context = -1;
    sf_cls_start(&c->cls, sf_cls_all(&c->site->contexts));
    sf_cls_result_t r;
    sf_cls_result(&c->cls, INT64_MAX, &r);
    emit(c, m, sf_ctl_rule_lost, prev, &r, false, 0.0, 0.0, false);
    return true;
}

/* IN_CONTEXT near no port: a barometric floor of the same building held away from the context's floor
 * for controller.floor_disagree_s means a stairs or elevator transition the position missed (rule
 * BAROMETER); the floor context of that floor follows. */
static void missed_transition(sf_controller_t *const c, const sf_params_t *const p, const sf_ctl_motion_t *const m)
{
    SF_ASSERT(c->state == sf_ctl_in_context && c->context >= 0 && c->context < c->site->contexts.n_contexts);
    const sf_context_map_t *const map = &c->site->contexts;
    const int16_t to = map->kind[c->context] == sf_context_floor && m->floor != c->floor
                           ? sf_cls_context_of(map, map->building[c->context], m->floor)
                           : -1;
    const bool allowed = p->controller_barometer_rule == 2 ||
                         (p->controller_barometer_rule == 1 && !sf_controller_has_vertical_port(c, map->building[c->context]));
    if (!allowed || !p->controller_floor_from_barometer || p->controller_floor_disagree_s <= 0.0 || to < 0 ||
        to == c->context || map->building[to] != map->building[c->context]) {
        c->disagree_t_us = INT64_MIN;
        return;
    }
    if (c->disagree_t_us == INT64_MIN) {
        c->disagree_t_us = m->t_us;
    }
    if ((double)(m->t_us - c->disagree_t_us) * 1e-6 >= p->controller_floor_disagree_s) {
        const int16_t prev = c->context;
        c->context = to;
        c->floor = floor_of(c, to, m->floor);
        c->disagree_t_us = INT64_MIN;
        sf_cls_result_t none = {.unique = -1};
        emit(c, m, sf_ctl_rule_barometer, prev, &none, false, 0.0, 0.0, true);
    }
}

static void transition(sf_controller_t *const c, const sf_params_t *const p, const sf_ctl_motion_t *const m)
{
    const int32_t q = c->port;
    SF_ASSERT(c->state == sf_ctl_transition && q >= 0 && q < c->site->ports.n_ports);
    const int kind = c->site->ports.kind[q];
    const int32_t steps = m->step_count - c->steps_at_start;
    const int32_t stair_steps = m->step_count - steps_from(c);
    const int64_t window_us = (int64_t)(p->controller_cls_window_s * 1e6);
    int64_t since_us = m->t_us - window_us;
    if (kind == sf_port_elevator && c->elevator_seen && c->elevator_t_us >= since_us) {
        since_us = c->elevator_t_us + 1; /* the floors passed during the ride do not count */
    }
    sf_cls_result_t r;
    sf_cls_result(&c->cls, since_us, &r);
    /* a unique floor: the CLS's, else the barometer's when the port joins that floor */
    const int16_t baro = baro_context(c, p, m, &r, since_us);
    const int16_t floor_to = r.unique >= 0 ? r.unique : baro;
    const bool by_baro = r.unique < 0 && baro >= 0;
    if (kind == sf_port_elevator && c->elevator_seen && c->walk_steps >= p->controller_elevator_walk_steps &&
        floor_to >= 0) {
        end_transition(c, p, m, sf_ctl_rule_elevator, floor_to, &r, by_baro);
        return;
    }
    if (kind == sf_port_stairs && stair_steps >= c->site->contexts.port_steps[q] && floor_to >= 0) {
        end_transition(c, p, m, sf_ctl_rule_stairs, floor_to, &r, by_baro);
        return;
    }
    if (kind == sf_port_door && steps >= p->controller_door_steps) {
        int16_t to = r.unique;
        const int64_t fresh_us = m->t_us - (int64_t)(p->controller_cls_gnss_fresh_s * 1e6);
        const int16_t sky = r.identified >= 2 ? gnss_outdoor(c, fresh_us > since_us ? fresh_us : since_us) : -1;
        if (to < 0 && sky >= 0) {
            /* a tie at an entrance with a GNSS fix among it: an accurate GNSS fix needs open sky,
             * while Wi-Fi and BLE carry through a doorway, so the GNSS side wins (the paper leaves the
             * tie open) */
            to = sky;
            r.method = sf_fix_gnss;
            r.hits = c->cls.evidence[sky].hits;
        }
        if (to < 0) { /* none, or a tie without GNSS: the outline that holds us */
            const int32_t b = m->has_position ? sf_cls_building_at(&c->site->contexts, m->x_m, m->y_m) : -1;
            to = sf_cls_context_of(&c->site->contexts, b, c->floor);
            to = to >= 0 ? to : c->context;
        }
        end_transition(c, p, m, sf_ctl_rule_door, to, &r, false);
        return;
    }
    const double leave_m = (double)c->site->ports.radius_m[q] + p->controller_port_margin_m + p->controller_port_leave_m;
    if (m->has_position && port_distance_m(c, q, m->x_m, m->y_m) > leave_m) {
        end_transition(c, p, m, sf_ctl_rule_left_port, c->context, &r, false);
    }
}

/* The radios' on-time over (previous update, now] under the policy in force. */
static void account_radios(sf_controller_t *const c, const int64_t t_us)
{
    if (c->has_t && t_us > c->t_us) {
        const double dt_s = (double)(t_us - c->t_us) * 1e-6;
        c->gnss_on_s += sf_controller_source_on(c, sf_fix_gnss) ? dt_s : 0.0;
        c->wifi_on_s += sf_controller_source_on(c, sf_fix_wifi) ? dt_s : 0.0;
        c->ble_on_s += sf_controller_source_on(c, sf_fix_ble) ? dt_s : 0.0;
    }
    if (!c->has_t || t_us > c->t_us) {
        c->t_us = t_us;
        c->has_t = true;
    }
}

bool sf_controller_update(sf_controller_t *const c, const sf_params_t *const p, const sf_ctl_motion_t *const m)
{
    SF_ASSERT(c != NULL && p != NULL && m != NULL);
    SF_ASSERT(!c->active || c->site != NULL); /* sf_controller_attach turns it on only with a map */
    account_radios(c, m->t_us);
    if (!c->active) {
        return false;
    }
    const int32_t before = c->ev_n + (int32_t)c->events_dropped;
    sf_controller_activity(c, m->t_us, m->activity);
    const int32_t new_steps = m->step_count > c->step_count ? m->step_count - c->step_count : 0;
    c->step_count = m->step_count;
    if (c->elevator_seen && m->activity == sf_activity_walking) {
        c->walk_steps += new_steps;
    }
    if (c->state == sf_ctl_transition && !c->on_stairs && new_steps > 0 &&
        (m->activity == sf_activity_stairs_up || m->activity == sf_activity_stairs_down)) {
        c->on_stairs = true; /* this update's steps are the first on the staircase */
        c->steps_at_stairs = m->step_count - new_steps;
    }
    switch (c->state) {
    case sf_ctl_init: {
        c->floor = m->floor;
        sf_cls_result_t r;
        sf_cls_result(&c->cls, m->t_us - (int64_t)(p->controller_cls_window_s * 1e6), &r);
        if (r.unique >= 0) {
            c->context = r.unique;
            c->floor = floor_of(c, r.unique, m->floor);
            c->state = sf_ctl_in_context;
            sf_cls_stop(&c->cls);
            emit(c, m, sf_ctl_rule_cls_unlimited, -1, &r, false, 0.0, 0.0, false);
        }
        break;
    }
    case sf_ctl_in_context: {
        if (c->site->contexts.kind[c->context] == sf_context_building) {
            c->floor = m->floor;
        }
        if (lost_outdoors(c, p, m)) {
            break;
        }
        const int16_t q = m->has_position ? near_port(c, p, m->x_m, m->y_m, c->floor) : -1;
        if (q >= 0) {
            c->disagree_t_us = INT64_MIN;
            begin_transition(c, m, q);
        } else {
            missed_transition(c, p, m);
        }
        break;
    }
    case sf_ctl_transition: transition(c, p, m); break;
    default: break;
    }
    return c->ev_n + (int32_t)c->events_dropped != before;
}
