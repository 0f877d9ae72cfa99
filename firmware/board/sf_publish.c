/* sf_publish.c — core structs → stridefix LCM messages (see sf_publish.h). */
#include "sf_publish.h"

#include <stdio.h>
#include <string.h>

#include "sf_channels.h"
#include "stridefix_config_t.h"
#include "stridefix_context_t.h"
#include "stridefix_fix_t.h"
#include "stridefix_health_t.h"
#include "stridefix_pose_t.h"
#include "stridefix_step_t.h"

void sf_publish_step(sf_lcm_out_t *const out, const int64_t log_t_us, const sf_step_t *const st)
{
    stridefix_step_t msg = {.t_us = st->t_us,
                            .index = st->index,
                            .length_m = (float)st->length_m,
                            .accel_range_mps2 = (float)st->accel_range_mps2,
                            .period_s = (float)st->period_s,
                            .heading_rad = (float)st->heading_rad,
                            .activity = st->activity,
                            .floor = st->floor};
    SF_LCM_WRITE(out, SF_CHANNEL_STEP, log_t_us, stridefix_step_t, &msg);
}

/* POSE_<SCHEME> by scheme id, generated from pose_t.lcm through lcmtypes/channels.csv. */
static const char *const pose_channels[] = {
#define POSE_CHANNEL(name, id) [id] = SF_CHANNEL_##name,
    SF_CHANNEL_POSE_SCHEMES(POSE_CHANNEL)
#undef POSE_CHANNEL
};
_Static_assert(sizeof pose_channels / sizeof pose_channels[0] == (size_t)sf_scheme_count,
               "one POSE_<SCHEME> channel per fusion scheme");

const char *sf_publish_pose_channel(const int scheme)
{
    return scheme >= 0 && scheme < sf_scheme_count ? pose_channels[scheme] : SF_CHANNEL_POSE;
}

static void write_pose(sf_lcm_out_t *const out, const char *const channel, const int64_t log_t_us,
                       const sf_pose_t *const p)
{
    stridefix_pose_t msg = {.t_us = p->t_us,
                            .x_m = p->x_m,
                            .y_m = p->y_m,
                            .floor = p->floor,
                            .heading_rad = (float)p->heading_rad,
                            .sigma_m = (float)p->sigma_m,
                            .cov_xx_m2 = (float)p->cov_m2[0],
                            .cov_xy_m2 = (float)p->cov_m2[1],
                            .cov_yy_m2 = (float)p->cov_m2[2],
                            .heading_bias_rad = (float)p->heading_bias_rad,
                            .stride_scale = (float)p->stride_scale,
                            .ess = (float)p->ess,
                            .step_count = p->step_count,
                            .scheme = p->scheme};
    SF_LCM_WRITE(out, channel, log_t_us, stridefix_pose_t, &msg);
}

void sf_publish_pose(sf_lcm_out_t *const out, const int64_t log_t_us, const sf_pose_t *const p)
{
    write_pose(out, sf_publish_pose_channel(p->scheme), log_t_us, p);
}

bool sf_publish_primary_of(const sf_estimator_t *const est, const sf_params_t *const p, const bool has_site,
                           sf_pose_t *const pose)
{
    const int only = p->output_scheme;
    if ((only < 0 || only == sf_scheme_controller) && sf_estimator_scheme_pose(est, p, sf_scheme_controller, pose)) {
        return true;
    }
    if (only == sf_scheme_controller) {
        return false; /* --fusion controller: the controller's pose or none */
    }
    const int follow = only >= 0 ? only : has_site ? p->controller_init_scheme : sf_scheme_pdr_only;
    return sf_estimator_scheme_pose(est, p, follow, pose) ||
           (only < 0 && sf_estimator_scheme_pose(est, p, sf_scheme_pdr_only, pose));
}

void sf_publish_primary_pose(sf_lcm_out_t *const out, const int64_t log_t_us, const sf_pose_t *const p)
{
    write_pose(out, SF_CHANNEL_POSE, log_t_us, p);
}

void sf_publish_fix(sf_lcm_out_t *const out, const int64_t log_t_us, const sf_fix_audit_t *const a)
{
    stridefix_fix_t msg = {.t_us = a->t_us,
                           .method = a->method,
                           .scheme = a->scheme,
                           .x_m = a->x_m,
                           .y_m = a->y_m,
                           .floor = a->floor,
                           .accuracy_m = (float)a->accuracy_m,
                           .n_ap_used = a->n_ap_used,
                           .innovation_m = {(float)a->innovation_m[0], (float)a->innovation_m[1]},
                           .innovation_var_m2 = (float)a->innovation_var_m2,
                           .test_ratio = (float)a->test_ratio,
                           .alpha = (float)a->alpha,
                           .accuracy_factor = (float)a->accuracy_factor,
                           .drift = (float)a->drift,
                           .accepted = a->accepted,
                           .reason = a->reason,
                           /* DEVIATION: the generated type's string is non-const; encoding only reads it. */
                           .reason_text = (char *)sf_fix_reason_text(a->reason)};
    SF_LCM_WRITE(out, SF_CHANNEL_FIX, log_t_us, stridefix_fix_t, &msg);
}

/* A context in words: "outdoor", "building 1", "floor 2 of building 0"; "none". */
static void context_words(char *const buf, const size_t size, const sf_context_map_t *const map, const int ctx)
{
    if (ctx < 0 || ctx >= map->n_contexts) {
        snprintf(buf, size, "none");
    } else if (map->kind[ctx] == sf_context_outdoor) {
        snprintf(buf, size, "outdoor");
    } else if (map->kind[ctx] == sf_context_building) {
        snprintf(buf, size, "building %d", (int)map->building[ctx]);
    } else {
        snprintf(buf, size, "floor %d of building %d", (int)map->floor[ctx], (int)map->building[ctx]);
    }
}

static const char *method_words(const int method, const int hits, const char **const members)
{
    *members = hits == 1 ? "member" : "members";
    switch (method) {
    case sf_fix_wifi: *members = hits == 1 ? "AP" : "APs"; return "Wi-Fi";
    case sf_fix_ble: *members = hits == 1 ? "beacon" : "beacons"; return "BLE";
    case sf_fix_gnss: *members = "fix"; return "GNSS";
    default: return "none";
    }
}

static const char *port_words(const int kind)
{
    return kind == sf_port_door ? "door" : kind == sf_port_stairs ? "stairs" : kind == sf_port_elevator ? "elevator" : "port";
}

void sf_publish_context(sf_lcm_out_t *const out, const int64_t log_t_us, const sf_context_event_t *const ev,
                        const sf_site_t *const site, const sf_params_t *const params)
{
    const sf_context_map_t *const map = &site->contexts;
    char now[64], id[160], text[320];
    context_words(now, sizeof now, map, ev->context);
    const char *members;
    const char *const by = method_words(ev->cls_method, ev->cls_hits, &members);
    if (ev->floor_from_barometer) {
        snprintf(id, sizeof id, "%s by the barometer (%d of %d candidates identified by the CLS)", now,
                 (int)ev->cls_identified, (int)ev->cls_candidates);
    } else if (ev->cls_method != 0 && ev->cls_identified > 1) {
        snprintf(id, sizeof id, "%s by GNSS (open sky) over the %d identified", now, (int)ev->cls_identified);
    } else if (ev->cls_method != 0) {
        snprintf(id, sizeof id, "%s unique (%s, %d %s)", now, by, (int)ev->cls_hits, members);
    } else {
        snprintf(id, sizeof id, "%d of %d candidates identified", (int)ev->cls_identified, (int)ev->cls_candidates);
    }
    const char *const rule = sf_controller_rule_text(ev->rule);
    int required = 0;
    if (ev->rule == sf_ctl_rule_stairs && ev->port >= 0 && ev->port < site->ports.n_ports) {
        required = map->port_steps[ev->port];
    } else if (ev->rule == sf_ctl_rule_door) {
        required = params->controller_door_steps;
    } else if (ev->rule == sf_ctl_rule_elevator) {
        required = params->controller_elevator_walk_steps;
    }
    switch (ev->rule) {
    case sf_ctl_rule_near_port:
        snprintf(text, sizeof text, "%s: %s port %d, %d candidate contexts", rule, port_words(ev->port_kind),
                 (int)ev->port, (int)ev->cls_candidates);
        break;
    case sf_ctl_rule_stairs:
    case sf_ctl_rule_door:;
        const bool outline = ev->rule == sf_ctl_rule_door && ev->cls_method == 0;
        snprintf(text, sizeof text, "%s: %d of %d steps, %s%s%s", rule, (int)ev->steps_in_transition, required, id,
                 outline ? ": by the outline, " : "", outline ? now : "");
        break;
    case sf_ctl_rule_elevator:
        snprintf(text, sizeof text, "%s: walking again (%d steps), %s", rule, required, id);
        break;
    case sf_ctl_rule_left_port:
        snprintf(text, sizeof text, "%s: %s after %d steps, %s", rule, now, (int)ev->steps_in_transition, id);
        break;
    default: snprintf(text, sizeof text, "%s: %s", rule, id); break;
    }
    if (ev->recalibrated) {
        const size_t used = strlen(text);
        snprintf(text + used, sizeof text - used, ", recalibrated to (%.1f, %.1f)", ev->recal_x_m, ev->recal_y_m);
    }
    stridefix_context_t msg = {.t_us = ev->t_us,
                               .state = ev->state,
                               .context = ev->context,
                               .prev_context = ev->prev_context,
                               .kind = ev->kind,
                               .building = ev->building,
                               .floor = ev->floor,
                               .scheme = ev->scheme,
                               .method = ev->method,
                               .port = ev->port,
                               .port_kind = ev->port_kind,
                               .rule = ev->rule,
                               .rule_text = text,
                               .switched = ev->switched,
                               .steps_in_transition = ev->steps_in_transition,
                               .cls_candidates = ev->cls_candidates,
                               .cls_identified = ev->cls_identified,
                               .cls_method = ev->cls_method,
                               .cls_hits = ev->cls_hits,
                               .floor_from_barometer = ev->floor_from_barometer,
                               .recalibrated = ev->recalibrated,
                               .recal_x_m = ev->recal_x_m,
                               .recal_y_m = ev->recal_y_m,
                               .gnss_on = ev->gnss_on,
                               .wifi_on = ev->wifi_on,
                               .ble_on = ev->ble_on};
    SF_LCM_WRITE(out, SF_CHANNEL_CONTEXT, log_t_us, stridefix_context_t, &msg);
}

void sf_publish_health(sf_lcm_out_t *const out, const int64_t log_t_us, const int64_t board_t_us,
                       const sf_input_counters_t *const in, const sf_estimator_status_t *const est,
                       const sf_publish_sources_t *const src, const sf_publish_loop_t *const loop)
{
    const sf_rx_counters_t *const c = &in->rx;
    sf_lcm_out_counters_t oc;
    sf_lcm_out_counters(out, &oc);
    stridefix_health_t msg = {
        .t_us = board_t_us,
        .host_t_us = log_t_us,
        .frames_total = (int64_t)in->frames_total,
        .frames_ok = (int64_t)c->frames_ok,
        .bad_syntax = (int64_t)in->bad_syntax,
        .unknown_id = (int64_t)c->unknown_id,
        .bad_length = (int64_t)c->bad_length,
        .decode_errors = (int64_t)c->decode_errors,
        .seq_gaps = (int64_t)c->seq_gaps,
        .unsynced = (int64_t)c->unsynced,
        .imu_unpaired = (int64_t)c->imu_unpaired,
        .wifi_incomplete = (int64_t)c->wifi_incomplete,
        .duplicates = (int64_t)c->duplicates,
        .late_samples = (int64_t)c->late,
        .seq_rejected = (int64_t)c->seq_rejected,
        .silences = (int64_t)c->silences,
        .board_restarts = (int64_t)c->board_restarts,
        .board_time_rejected = (int64_t)c->board_time_rejected,
        .board_time_jumps = (int64_t)c->board_time_jumps,
        .samples_out_of_range = est->samples_out_of_range,
        .samples_jumped = est->samples_jumped,
        .samples_out_of_order = est->samples_out_of_order,
        .gaps_bridged = est->gaps_bridged,
        .replay_oversized = (int64_t)in->replay_oversized,
        .replay_truncated = (int64_t)in->replay_truncated,
        .replay_refused = (int64_t)in->replay_refused,
        .imu_samples = (int64_t)c->imu,
        .mag_samples = (int64_t)c->mag,
        .baro_samples = (int64_t)c->baro,
        .wifi_scans = (int64_t)c->wifi,
        .gnss_fixes = (int64_t)c->gnss,
        .ble_scans = (int64_t)c->ble,
        .landmark_events = (int64_t)c->landmark,
        .ble_adverts = (int64_t)c->ble_adverts,
        .ble_dropped = (int64_t)c->ble_dropped,
        .fixes_offered_wifi = (int64_t)src->offered[sf_fix_wifi],
        .fixes_offered_gnss = (int64_t)src->offered[sf_fix_gnss],
        .fixes_offered_ble = (int64_t)src->offered[sf_fix_ble],
        .fixes_offered_landmark = (int64_t)src->offered[sf_fix_landmark],
        .fixes_made_wifi = (int64_t)src->made[sf_fix_wifi],
        .fixes_made_gnss = (int64_t)src->made[sf_fix_gnss],
        .fixes_made_ble = (int64_t)src->made[sf_fix_ble],
        .fixes_made_landmark = (int64_t)src->made[sf_fix_landmark],
        .steps = est->step_count,
        .mag_rejected = (int64_t)est->mag_rejected,
        .context_transitions = (int64_t)est->context_transitions,
        .context_switches = (int64_t)est->context_switches,
        .context_recalibrations = (int64_t)est->context_recalibrations,
        .gnss_on_s = (float)est->gnss_on_s,
        .wifi_on_s = (float)est->wifi_on_s,
        .ble_on_s = (float)est->ble_on_s,
        .log_events = (int64_t)oc.events,
        .log_bytes = (int64_t)oc.bytes,
        .log_drops = (int64_t)oc.drops,
        .log_drop_bytes = (int64_t)oc.drop_bytes,
        .loop_mean_us = loop->n > 0 ? (float)(loop->sum_us / (double)loop->n) : 0.0f,
        .loop_max_us = (float)loop->max_us,
    };
    SF_LCM_WRITE(out, SF_CHANNEL_HEALTH, log_t_us, stridefix_health_t, &msg);
}

#define CONFIG_KEY_BYTES 64
#define CONFIG_VALUE_BYTES 32
_Static_assert(SF_PARAM_COUNT * (CONFIG_KEY_BYTES + CONFIG_VALUE_BYTES + 2 * sizeof(char *)) <= 28 * 1024,
               "sf_publish.h promises CONFIG's text within 28 KiB of stack");

void sf_publish_config(sf_lcm_out_t *const out, const int64_t log_t_us, const int64_t board_t_us,
                       const sf_params_t *const params, const char *const version, const char *const dbc_sha256)
{
    enum { n = SF_PARAM_COUNT };
    char keys[n][CONFIG_KEY_BYTES];
    char values[n][CONFIG_VALUE_BYTES];
    char *key_ptrs[n];
    char *value_ptrs[n];
    for (size_t i = 0; i < sf_param_count; i++) {
        snprintf(keys[i], sizeof keys[i], "%s.%s", sf_param_table[i].section, sf_param_table[i].name);
        snprintf(values[i], sizeof values[i], "%.9g", sf_param_get(params, &sf_param_table[i]));
        key_ptrs[i] = keys[i];
        value_ptrs[i] = values[i];
    }
    /* DEVIATION: the generated type's strings are non-const; encoding only reads them. */
    stridefix_config_t msg = {.t_us = board_t_us,
                              .version = (char *)version,
                              .dbc_sha256 = (char *)dbc_sha256,
                              .n = (int32_t)sf_param_count,
                              .key = key_ptrs,
                              .value = value_ptrs};
    /* the header: every rotated log file starts with a copy, so each reads alone */
    SF_LCM_WRITE_AS(true, out, SF_CHANNEL_CONFIG, log_t_us, stridefix_config_t, &msg);
}

bool sf_publish_loop_due(sf_publish_loop_t *const loop)
{
    const bool due = loop->since == 0;
    loop->since = loop->since + 1u >= loop->stride ? 0u : loop->since + 1u;
    return due;
}

void sf_publish_loop_add(sf_publish_loop_t *const loop, const double dt_us)
{
    loop->sum_us += dt_us;
    loop->n++;
    if (dt_us > loop->max_us) {
        loop->max_us = dt_us;
    }
}
