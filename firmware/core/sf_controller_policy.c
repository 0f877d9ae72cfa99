/* sf_controller_policy.c — what the multi-scheme controller says to the rest of the estimator: the
 * rules' words, the scheme the primary pose follows, its floor, and the sources kept on (Jäger et al.
 * Table I and the GPS policy of §III-C; sf_controller.h). The state machine is sf_controller.c.
 * A leaf of it: pure queries on a const sf_controller_t and its site, O(1) but for the port scans
 * (O(ports)); no state of its own and no call into sf_controller.c, which calls these. */
#include "sf_assert.h"
#include "sf_controller.h"

const char *sf_controller_rule_text(const int rule)
{
    switch (rule) {
    case sf_ctl_rule_cls_unlimited: return "CLS unlimited: one context identified";
    case sf_ctl_rule_near_port: return "near port: transition detection begins";
    case sf_ctl_rule_elevator: return "elevator: walking again and a unique floor";
    case sf_ctl_rule_stairs: return "stairs: the staircase's steps and a unique floor";
    case sf_ctl_rule_door: return "door: steps since the transition began";
    case sf_ctl_rule_lost: return "lost: no accurate GNSS fix outdoors, every context searched again";
    case sf_ctl_rule_barometer: return "barometer: the floor changed away from any port";
    case sf_ctl_rule_left_port: return "left the port: the old context stays";
    default: return "unknown rule";
    }
}

/* ---- policy -------------------------------------------------------------------------------------- */

bool sf_controller_active(const sf_controller_t *const c)
{
    return c->active;
}

int sf_controller_scheme(const sf_controller_t *const c)
{
    SF_ASSERT(!c->active || c->context < c->site->contexts.n_contexts);
    return c->active && c->context >= 0 ? c->site->contexts.scheme[c->context] : c->init_scheme;
}

int16_t sf_controller_floor(const sf_controller_t *const c)
{
    return c->floor;
}

/* The building has a stairs or elevator port (a floor change there is the port rules' to see). */
bool sf_controller_has_vertical_port(const sf_controller_t *const c, const int32_t building)
{
    const sf_ports_t *const ports = &c->site->ports;
    for (int32_t q = 0; q < ports->n_ports; q++) {
        if (ports->kind[q] != sf_port_door && c->site->contexts.port_building[q] == building) {
            return true;
        }
    }
    return false;
}

int16_t sf_controller_pose_floor(const sf_controller_t *const c, const sf_params_t *const p, const int16_t baro_floor)
{
    SF_ASSERT(c->state != sf_ctl_transition || (c->port >= 0 && c->port < c->site->ports.n_ports));
    if (c->state == sf_ctl_transition && p->controller_floor_from_barometer &&
        c->site->ports.kind[c->port] != sf_port_door && sf_port_joins(&c->site->ports, c->port, baro_floor)) {
        return baro_floor; /* on the staircase or in the cab the floor changes before the context does */
    }
    const sf_context_map_t *const map = &c->site->contexts;
    if (c->state == sf_ctl_in_context && p->controller_barometer_rule >= 1 && p->controller_floor_from_barometer &&
        map->kind[c->context] == sf_context_floor && !sf_controller_has_vertical_port(c, map->building[c->context]) &&
        sf_cls_context_of(map, map->building[c->context], baro_floor) >= 0) {
        return baro_floor;
    }
    return c->floor;
}

bool sf_controller_source_on(const sf_controller_t *const c, const int method)
{
    if (!c->active || method == sf_fix_landmark || method == sf_fix_port) {
        return true;
    }
    SF_ASSERT(c->site != NULL && c->context < c->site->contexts.n_contexts);
    SF_ASSERT(c->state != sf_ctl_in_context || c->context >= 0);
    const sf_context_map_t *const m = &c->site->contexts;
    if (c->state == sf_ctl_init) {
        return method == sf_fix_gnss || sf_cls_uses(m, c->cls.candidates, method); /* Table I: all on */
    }
    const bool lsd = c->context >= 0 && m->method[c->context] == method;
    const bool outdoor = c->context >= 0 && m->kind[c->context] == sf_context_outdoor;
    if (c->state == sf_ctl_in_context) {
        return lsd || (method == sf_fix_gnss && outdoor);
    }
    /* a transition: the LSD, what the limited CLS needs, GNSS at a port with an outdoor neighbour */
    return lsd || (method == sf_fix_gnss && (outdoor || c->port_outdoor)) || sf_cls_uses(m, c->cls.candidates, method);
}

