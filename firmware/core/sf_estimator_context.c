/* sf_estimator_context.c — the estimator's side of the multi-scheme controller (sf_estimator.h,
 * sf_controller.h): the motion it sees, the source gate, the shared floor on a switch, and the
 * events with their staircase-endpoint fix. */
#include "sf_estimator_internal.h"

#include "sf_fusion.h"

/* The controller's view of the walk: the pose of the scheme it follows; without one, the PDR track
 * when the schemes started at the config pose (no site, or truth-initialised).
 * DEVIATION: sf_controller.h says "or the PDR track's"; with a site and schemes that start at their
 * first fix the PDR track's frame is the config start, which says nothing about ports, so it is not a
 * position then. */
static void motion(const sf_estimator_t *const e, const sf_params_t *const p, const int64_t t_us,
                   sf_ctl_motion_t *const m)
{
    sf_pose_t pose;
    bool has = sf_estimator_scheme_pose(e, p, sf_controller_scheme(&e->controller), &pose);
    if (!has && (e->site == NULL || p->init_use_config_pose != 0)) {
        sf_estimator_pose(e, &pose);
        has = true;
    }
    *m = (sf_ctl_motion_t){.t_us = t_us > e->t_us ? t_us : e->t_us,
                           .has_position = has,
                           .x_m = has ? pose.x_m : 0.0,
                           .y_m = has ? pose.y_m : 0.0,
                           .floor = sf_floor_current(&e->floor),
                           .step_count = e->step_count,
                           .activity = sf_activity_current(&e->activity)};
}

/* The controller now follows another scheme than `from`: the primary pose hands over from where it
 * was (the old scheme's pose with its own fading offset; an update leaves the schemes' poses as they
 * are), without a jump. */
static void hand_over(sf_estimator_t *const e, const sf_params_t *const p, const int from, const int64_t t_us)
{
    sf_pose_t was, now;
    if (sf_controller_active(&e->controller) && sf_estimator_followed_pose(e, p, from, &was) &&
        sf_estimator_scheme_pose(e, p, sf_controller_scheme(&e->controller), &now)) {
        e->handover_t_us = t_us;
        e->handover_dx_m = was.x_m - now.x_m;
        e->handover_dy_m = was.y_m - now.y_m;
    }
}

void sf_estimator_run_controller(sf_estimator_t *const e, const sf_params_t *const p, const int64_t t_us)
{
    sf_controller_t *const c = &e->controller;
    sf_ctl_motion_t m;
    motion(e, p, t_us, &m);
    const uint32_t switches = c->switches;
    const int scheme_before = sf_controller_scheme(c);
    const bool queued = sf_controller_update(c, p, &m);
    if (sf_controller_scheme(c) != scheme_before) {
        hand_over(e, p, scheme_before, m.t_us);
    }
    /* cppcheck-suppress knownConditionTrueFalse ; sf_controller_update counts switches through c */
    if (!queued || c->switches == switches) { /* no event, or none that switched */
        return;
    }
    const bool vertical = c->last_rule == sf_ctl_rule_stairs || c->last_rule == sf_ctl_rule_elevator;
    const bool counting = e->floor.started && !sf_floor_settled(&e->floor, p); /* a barometer mid-climb */
    if (c->last_rule == sf_ctl_rule_barometer || (vertical && (c->last_by_baro || counting))) {
        return; /* the barometer's own floor, or one still counting the climb: a shift would count it twice */
    }
    /* a switch to a context on another floor: every scheme's floor follows the controller's (the body
     * stays where it is, its floor number changes, as when the floor vote renumbers) */
    const int32_t shift = (int32_t)c->floor - (int32_t)sf_floor_current(&e->floor); /* the context's floor */
    sf_floor_shift(&e->floor, shift, false);
    if (e->floor_vote_active) { /* the start-floor vote renumbers with it (sf_floor_vote.h) */
        sf_floor_vote_renumber(&e->floor_vote, shift);
    }
}

bool sf_estimator_context_off(sf_estimator_t *const e, const sf_params_t *const p, const int8_t method, const int64_t t_us,
                              sf_fix_audit_t audits[sf_scheme_count], int *const n)
{
    if (!p->controller_gate_sources || sf_controller_source_on(&e->controller, method)) {
        return false;
    }
    e->context_off++;
    *n = sf_estimator_refuse(e, t_us, method, 0, sf_fix_reason_context_off, audits);
    return true;
}

bool sf_estimator_next_context(sf_estimator_t *const e, const sf_params_t *const p, sf_context_event_t *const ev,
                               sf_fix_t *const fix, bool *const has_fix, sf_fix_audit_t audits[sf_scheme_count],
                               int *const n_audits)
{
    *has_fix = false;
    *n_audits = 0;
    if (!sf_controller_next_event(&e->controller, ev)) {
        return false;
    }
    if (ev->recalibrated) { /* the staircase's endpoint on the new floor: a known position */
        *fix = (sf_fix_t){.t_us = ev->t_us, .method = sf_fix_port, .x_m = ev->recal_x_m, .y_m = ev->recal_y_m,
                          .floor = ev->floor, .accuracy_m = p->controller_recal_sigma_m};
        *has_fix = true;
        *n_audits = sf_estimator_offer_fix(e, p, fix, true, audits);
    }
    return true;
}
