/* sf_estimator.c — composition of the PDR modules and the multi-scheme controller's step (see
 * sf_estimator.h); the absolute fixes are sf_estimator_fix.c, which calls the step here. */
#include "sf_estimator.h"

#include <math.h>

#include "sf_assert.h"
#include "sf_error.h"
#include "sf_estimator_internal.h"
#include "sf_math.h"

/* Every scheme starts at the config pose (truth-initialised runs, and runs without a site). */
static void start_at_config(sf_estimator_t *const e, const sf_params_t *const p)
{
    for (int s = 0; s < sf_scheme_count; s++) {
        (void)sf_fusion_init_at(&e->fusion[s], p, SF_FUSION_T_FIRST_INPUT, p->init_x_m, p->init_y_m,
                                (int16_t)p->init_floor, p->init_sigma_m, (int16_t)p->init_floor);
    }
}

/* The walls of a cloud attached without a grid: none (constant data, not state: sf_wall_grid_empty's
 * grid, zero everywhere). */
static const sf_wall_grid_t k_no_walls = {0};

void sf_estimator_init(sf_estimator_t *const e, const sf_params_t *const p)
{
    *e = (sf_estimator_t){0};
    sf_attitude_init(&e->attitude);
    sf_magcal_init(&e->magcal, p);
    sf_heading_init(&e->heading, p);
    sf_steps_init(&e->steps, p);
    sf_stride_init(&e->stride, p);
    sf_activity_init(&e->activity, p);
    sf_floor_init(&e->floor, p);
    e->x_m = p->init_x_m;
    e->y_m = p->init_y_m;
    e->heading_rad = p->init_heading_rad;
    sf_fingerprint_init(&e->fingerprint);
    sf_source_quality_init(&e->quality);
    sf_controller_init(&e->controller, p);
    e->handover_t_us = INT64_MIN;
    for (int s = 0; s < sf_scheme_count; s++) {
        (void)sf_fusion_init(&e->fusion[s], (int8_t)s);
    }
    start_at_config(e, p);
}

int sf_estimator_attach_particles(sf_estimator_t *const e, const sf_params_t *const p,
                                  sf_particle_state_t *const states, int16_t *const floors, const int32_t capacity,
                                  const sf_wall_grid_t *const walls)
{
    const int rc = sf_particle_init(&e->particles, p, states, floors, capacity);
    if (rc != SF_OK) {
        return rc;
    }
    sf_particle_set_map(&e->particles, walls != NULL ? walls : &k_no_walls, e->site != NULL ? &e->site->ports : NULL);
    e->has_particles = true;
    sf_fusion_set_cloud(&e->fusion[sf_scheme_particle], p, &e->particles);
    return SF_OK;
}

int sf_estimator_attach_site(sf_estimator_t *const e, const sf_params_t *const p, const sf_site_t *const site,
                             sf_fingerprint_workspace_t *const ws)
{
    if (site == NULL || ws == NULL) {
        return SF_EINVAL;
    }
    int rc = SF_OK;
    if (site->n_floors > 0) {
        rc = sf_floor_set_heights(&e->floor, site->floor_height_m, site->n_floors, site->lowest_floor);
    }
    if (rc == SF_OK && site->radiomap.n_rp > 0) {
        rc = sf_fingerprint_prepare(ws, &site->radiomap, p);
    }
    if (rc == SF_OK) {
        rc = sf_controller_attach(&e->controller, p, site, NULL);
    }
    if (rc != SF_OK) {
        return rc;
    }
    e->site = site;
    e->ws = ws;
    if (site->n_floors > 0) {
        sf_floor_vote_init(&e->floor_vote, site->lowest_floor, site->n_floors, sf_floor_current(&e->floor),
                           p->init_use_config_pose != 0);
        e->floor_vote_active = true;
    }
    if (!p->init_use_config_pose) { /* with a site, schemes start at their first fix */
        for (int s = 0; s < sf_scheme_count; s++) {
            (void)sf_fusion_init(&e->fusion[s], (int8_t)s);
        }
        if (e->has_particles) { /* a cloud attached before the site: unseeded again, with the site's ports */
            e->particles.seeded = false;
            sf_particle_set_map(&e->particles, e->particles.walls, &site->ports);
            sf_fusion_set_cloud(&e->fusion[sf_scheme_particle], p, &e->particles);
        }
    }
    for (int s = 0; s < sf_scheme_count; s++) { /* the ekf's fix-error model, if the site measured one */
        sf_fusion_set_fix_model(&e->fusion[s], p, &site->fix_model);
    }
    return SF_OK;
}

/* What the walking direction depends on at this IMU sample (the attitude, the heading offset, the map
 * rotation or start heading): kept, and the direction computed only when read (heading_now), not an
 * atan2 on every sample (≈ 90 instructions of ≈ 1,400). */
static void note_heading(sf_estimator_t *const e, const sf_params_t *const p)
{
    e->heading_from_q = true;
    e->heading_yaw_absolute = e->attitude.yaw_absolute;
    for (int i = 0; i < 4; i++) {
        e->heading_q[i] = e->attitude.q[i];
    }
    e->heading_offset_rad = sf_heading_offset_rad(&e->heading, p);
    e->heading_base_rad = e->attitude.yaw_absolute ? p->heading_map_rotation_deg * (SF_PI / 180.0) : p->init_heading_rad;
}

/* Walking direction in the map frame at the latest IMU sample: sf_heading_walk_rad of the device yaw
 * once the yaw is absolute (the same sums in the same order, so the same double), the configured start
 * heading plus the yaw before. */
static double heading_now(const sf_estimator_t *const e)
{
    if (!e->heading_from_q) {
        return e->heading_rad;
    }
    const double yaw = sf_attitude_q_yaw_rad(e->heading_q);
    if (e->heading_yaw_absolute) {
        return sf_wrap_pi(yaw + e->heading_offset_rad - e->heading_base_rad);
    }
    return sf_wrap_pi(e->heading_base_rad + yaw + e->heading_offset_rad);
}

/* Moves the PDR track and every fusion scheme by one displacement. */
static void advance(sf_estimator_t *const e, const sf_params_t *const p, const int64_t now_us, const double dx_m,
                    const double dy_m, const double length_m)
{
    e->x_m += dx_m;
    e->y_m += dy_m;
    e->distance_m += length_m;
    e->sigma_m += p->estimator_sigma_per_m * length_m;
    const int16_t baro_floor = sf_floor_current(&e->floor); /* the particle scheme's floors */
    for (int s = 0; s < sf_scheme_count; s++) {
        sf_fusion_step_on_floor(&e->fusion[s], p, now_us, dx_m, dy_m, length_m, baro_floor);
    }
}

/* Moves the position by one credited step (and first by the walk a gap hid, sf_gap_bridge.h) and
 * fills its STEP record. */
static void move(sf_estimator_t *const e, const sf_params_t *const p, const sf_step_event_t *const ev,
                 const int64_t now_us, sf_step_t *const step)
{
    /* On stairs the body climbs while it steps, and a stair's going G is what the step advances.
     * Blondel's rule of stair design (2R + G = the level step, 0.63 m in building codes: a rise costs
     * the walker twice its height in stride) turned around gives G = L − 2R, L the walker's own level
     * (Weinberg) step and R = |v|·T the rise of this step from the barometric vertical speed and the
     * step period. Only on the stairs class, whose speed threshold keeps baro noise off level ground. */
    const int8_t activity = sf_activity_current(&e->activity);
    const double heading_rad = heading_now(e);
    const double level_m = sf_stride_length_m(&e->stride, ev);
    const double rise_m = activity == sf_activity_stairs_up || activity == sf_activity_stairs_down
                              ? fabs(sf_floor_vertical_speed_mps(&e->floor)) * ev->period_s
                              : 0.0;
    const double length_m = fmax(level_m - 2.0 * rise_m, 0.0);
    double bridge_m, bridge_heading_rad;
    if (sf_gap_bridge_on_step(&e->gap, p, ev->t_us, heading_rad, &bridge_m, &bridge_heading_rad)) {
        advance(e, p, now_us, bridge_m * cos(bridge_heading_rad), bridge_m * sin(bridge_heading_rad), bridge_m);
        e->calib_anchor_valid = false; /* a guessed distance must not calibrate the stride */
    }
    sf_gap_bridge_note_step(&e->gap, ev->t_us, ev->period_s, length_m, heading_rad);
    e->step_count++;
    /* the calibration sum scaled like the length, so K·sum stays the distance moved */
    e->weinberg_sum += level_m > 0.0 ? sf_stride_weinberg_term(ev) * (length_m / level_m) : 0.0;
    advance(e, p, now_us, length_m * cos(heading_rad), length_m * sin(heading_rad), length_m);

    step->t_us = now_us; /* published when known (causal); ev->t_us is the extremum, earlier */
    step->index = e->step_count;
    step->length_m = length_m;
    step->accel_range_mps2 = sf_stride_range_mps2(ev);
    step->period_s = ev->period_s;
    step->heading_rad = heading_rad;
    step->activity = activity;
    step->floor = sf_floor_current(&e->floor);
}

/* Whether a sample passes its stream's gate (sf_sample_gate.h); a refused one is counted by verdict. */
static bool admit(sf_estimator_t *const e, const sf_params_t *const p, const sf_gate_stream_t stream,
                  const int64_t t_us, const double *const value)
{
    const sf_gate_verdict_t v = sf_sample_gate_stream(&e->gates[stream], p, stream, t_us, value);
    if (v != sf_gate_accepted) {
        e->samples_refused[v]++;
        return false;
    }
    return true;
}

int sf_estimator_imu(sf_estimator_t *const e, const sf_params_t *const p, const sf_imu_sample_t *const s,
                     sf_step_t steps[SF_ESTIMATOR_MAX_STEPS])
{
    const sf_gate_verdict_t v = sf_sample_gate_imu(&e->gates[sf_gate_accel], &e->gates[sf_gate_gyro], p, s->t_us,
                                                   s->accel_mps2, s->gyro_radps);
    if (v != sf_gate_accepted) { /* admit's count, for the first gate that refused */
        e->samples_refused[v]++;
        return 0;
    }
    sf_gap_bridge_on_imu(&e->gap, p, e->started ? e->t_us : 0, s->t_us);
    /* the gates refused every non-finite sample (|x| ≤ full scale ≤ DBL_MAX) */
    sf_attitude_update_imu_finite(&e->attitude, p, s->t_us, s->accel_mps2, s->gyro_radps);
    double f_nav[3];
    sf_attitude_body_to_nav(&e->attitude, s->accel_mps2, f_nav);
    if (!e->started) {
        e->gravity_mps2 = f_nav[2];
        e->started = true;
    } else if (s->t_us > e->t_us) {
        const double dt_s = (double)(s->t_us - e->t_us) * 1e-6;
        e->gravity_mps2 += (1.0 - sf_exp_memo(&e->gravity_decay, -dt_s / p->estimator_gravity_tau_s)) * (f_nav[2] - e->gravity_mps2);
    }
    e->t_us = s->t_us;
    const double a_v = f_nav[2] - e->gravity_mps2;
    e->accel_v_mps2 = a_v;

    /* the heading filter reads the yaw's direction (no atan2); the walking direction is kept for
     * when it is read (note_heading) */
    double cos_yaw, sin_yaw;
    sf_attitude_yaw_dir(&e->attitude, &cos_yaw, &sin_yaw);
    sf_heading_update_dir(&e->heading, p, s->t_us, f_nav, cos_yaw, sin_yaw);
    sf_activity_accel(&e->activity, p, s->t_us, a_v);
    sf_activity_gyro(&e->activity, p, s->t_us, s->gyro_radps);
    note_heading(e, p);
    sf_controller_activity(&e->controller, s->t_us, sf_activity_current(&e->activity));

    sf_step_event_t ev;
    if (!sf_steps_update(&e->steps, p, s->t_us, a_v, &ev)) {
        return 0;
    }
    const sf_activity_t *const a = &e->activity;
    const int credited = sf_activity_step(&e->activity, p, &ev);
    if (credited == 0) {
        if (a->held_n > 0 && a->held_t_us[a->held_n - 1] == ev.t_us) {
            e->held_events[a->held_n - 1] = ev; /* a detection of a bout waits for its confirmation */
            sf_heading_on_step(&e->heading, p, s->t_us);
        } else {
            e->steps_refused++;
            sf_heading_discard_step(&e->heading, s->t_us); /* a gesture's window teaches no offset */
        }
        return 0;
    }
    sf_heading_on_step(&e->heading, p, s->t_us);
    SF_ASSERT(credited <= SF_ESTIMATOR_MAX_STEPS);
    for (int i = 0; i < credited - 1; i++) {
        move(e, p, &e->held_events[i], s->t_us, &steps[i]);
    }
    move(e, p, &ev, s->t_us, &steps[credited - 1]);
    sf_estimator_run_controller(e, p, s->t_us);
    return credited;
}

void sf_estimator_mag(sf_estimator_t *const e, const sf_params_t *const p, const int64_t t_us,
                      const double field_ut[3])
{
    if (!admit(e, p, sf_gate_mag, t_us, field_ut)) {
        return;
    }
    sf_magcal_update(&e->magcal, p, t_us, field_ut);
    double corrected_ut[3];
    sf_magcal_apply(&e->magcal, field_ut, corrected_ut);
    sf_attitude_update_mag(&e->attitude, p, t_us, corrected_ut);
}

void sf_estimator_baro(sf_estimator_t *const e, const sf_params_t *const p, const int64_t t_us,
                       const double pressure_pa)
{
    if (!admit(e, p, sf_gate_baro, t_us, &pressure_pa)) {
        return;
    }
    sf_floor_update(&e->floor, p, t_us, pressure_pa);
    if (e->floor_vote_active) {
        bool rereference;
        const int32_t k = sf_floor_vote_baro(&e->floor_vote, sf_floor_current(&e->floor), &rereference);
        sf_floor_shift(&e->floor, k, rereference);
    }
    sf_activity_vspeed(&e->activity, p, t_us, sf_floor_vertical_speed_mps(&e->floor));
}

void sf_estimator_pose(const sf_estimator_t *const e, sf_pose_t *const pose)
{
    pose->t_us = e->t_us;
    pose->x_m = e->x_m;
    pose->y_m = e->y_m;
    pose->floor = sf_floor_current(&e->floor);
    pose->heading_rad = heading_now(e);
    pose->sigma_m = e->sigma_m;
    pose->cov_m2[0] = pose->cov_m2[2] = e->sigma_m * e->sigma_m;
    pose->cov_m2[1] = 0.0;
    pose->heading_bias_rad = 0.0;
    pose->stride_scale = 1.0;
    pose->step_count = e->step_count;
    pose->scheme = sf_scheme_pdr_only;
}

/* The pose of a scheme the controller follows, with the fading hand-over offset of the last switch
 * added (sf_estimator.h); false when the scheme has no pose. */
static bool followed_pose(const sf_estimator_t *const e, const sf_params_t *const p, const int scheme,
                          sf_pose_t *const pose)
{
    if (!sf_estimator_scheme_pose(e, p, scheme, pose)) {
        return false;
    }
    if (e->handover_t_us != INT64_MIN && p->controller_handover_s > 0.0) {
        /* the old scheme's position fades into the new one's; its offset stays in the variance */
        const double age_s = (double)(pose->t_us - e->handover_t_us) * 1e-6;
        const double w = age_s > 0.0 ? exp(-age_s / p->controller_handover_s) : 1.0;
        const double dx = w * e->handover_dx_m, dy = w * e->handover_dy_m;
        pose->x_m += dx;
        pose->y_m += dy;
        pose->cov_m2[0] += dx * dx;
        pose->cov_m2[1] += dx * dy;
        pose->cov_m2[2] += dy * dy;
        pose->sigma_m = sqrt(0.5 * (pose->cov_m2[0] + pose->cov_m2[2]));
    }
    return true;
}

bool sf_estimator_scheme_pose(const sf_estimator_t *const e, const sf_params_t *const p, const int scheme,
                              sf_pose_t *const pose)
{
    if (scheme == sf_scheme_controller) {
        const sf_controller_t *const c = &e->controller;
        if (!sf_controller_active(c) || !followed_pose(e, p, sf_controller_scheme(c), pose)) {
            return false;
        }
        pose->scheme = sf_scheme_controller;
        pose->floor = sf_controller_pose_floor(c, p, sf_floor_current(&e->floor));
        return true;
    }
    if (scheme < 0 || scheme >= sf_scheme_count) {
        return false;
    }
    sf_estimator_pose(e, pose);
    return sf_fusion_pose(&e->fusion[scheme], p, e->t_us, sf_floor_current(&e->floor), pose);
}

/* ---- the multi-scheme controller: the motion it sees, the hand-over, the shared floor on a switch ---- */

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
    if (sf_controller_active(&e->controller) && followed_pose(e, p, from, &was) &&
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

void sf_estimator_status(const sf_estimator_t *const e, sf_estimator_status_t *const status)
{
    *status = (sf_estimator_status_t){.t_us = e->t_us,
                                      .step_count = e->step_count,
                                      .floor = sf_floor_current(&e->floor),
                                      .has_site = e->site != NULL,
                                      .mag_rejected = e->attitude.mag_rejected,
                                      .steps_refused = e->steps_refused,
                                      .stride_calibrations = e->stride_calibrations,
                                      .samples_out_of_range = e->samples_refused[sf_gate_out_of_range],
                                      .samples_jumped = e->samples_refused[sf_gate_jump],
                                      .samples_out_of_order = e->samples_refused[sf_gate_out_of_order],
                                      .gaps_bridged = e->gap.bridged,
                                      .gnss_offered = e->gnss_offered,
                                      .gnss_refused = e->gnss_refused,
                                      .ble_scans = e->ble.scans,
                                      .ble_fixes = e->ble.fixes,
                                      .landmarks_refused = e->landmarks_refused,
                                      .controller_active = sf_controller_active(&e->controller),
                                      .context_transitions = e->controller.transitions,
                                      .context_switches = e->controller.switches,
                                      .context_recalibrations = e->controller.recalibrations,
                                      .context_off = e->context_off,
                                      .gnss_on_s = e->controller.gnss_on_s,
                                      .wifi_on_s = e->controller.wifi_on_s,
                                      .ble_on_s = e->controller.ble_on_s};
}
