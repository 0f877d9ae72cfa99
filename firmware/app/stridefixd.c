/* stridefixd — the StrideFix logger daemon: options, the main loop and the lifecycle.
 * One input (sf_input.h: candump file, stdin, SocketCAN or a raw-sensor LCM log) gives timed samples; each
 * is logged as it came (sf_rx_lcm.h) and fed to the estimator core in one switch (feed()): every absolute
 * source (Wi-Fi, GNSS, BLE, landmark) through publish_fixes, then the controller's CONTEXT events
 * (drain_contexts); steps, poses (which and when: sf_pose_out.h) and fix audits go out through sf_publish.h
 * to an LCM event log and, optionally, live LCM (--speed paces a replay: sf_pace.h). Bad input is counted
 * and skipped, never fatal; counts go into HEALTH and the exit summary. Lifecycle: SIGTERM/SIGINT end the
 * input early (sf_signals.h) and the run closes as at the end of the input; a live input is refused as root
 * (sf_privilege.h); the log's naming, rotation and durability are sf_lcm_out's and sf_log_file's. */
#define _GNU_SOURCE
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "sf_batch.h"
#include "sf_error.h"
#include "sf_estimator.h"
#include "sf_input.h"
#include "sf_lcm_out.h"
#include "sf_log_file.h"
#include "sf_options.h"
#include "sf_params.h"
#include "sf_privilege.h"
#include "sf_publish.h"
#include "sf_rx_lcm.h"
#include "sf_signals.h"
#include "sf_summary.h"
#include "sf_site.h"
#include "sf_particle_mem.h"
#include "sf_pose_out.h"

#ifndef SF_VERSION
#define SF_VERSION "0.0.0"
#endif
#ifndef SF_DBC_SHA256
#define SF_DBC_SHA256 "unknown"
#endif

#define LOG_QUEUE_MESSAGES 8192
#define LOG_NAME_ATTEMPTS 100 /* default names tried before giving up (each one EEXIST) */

typedef struct {
    sf_options_t opt;
    sf_params_t params;
    sf_input_t *in;
    sf_input_item_t item; /* large (a whole scan): here, not on the stack */
    sf_lcm_out_t *out;
    sf_estimator_t est;
    sf_site_t site; /* a view of sf_batch_site's copy */
    sf_fingerprint_workspace_t ws; /* a copy of sf_batch_workspace's, handed back at the end */
    sf_particle_mem_t particle_mem; /* the particle scheme's cloud and the site's wall index */
    char log_path[SF_LOG_FILE_PATH_MAX];
    long messages_printed;
    int64_t host_t_us;  /* log timestamp of the item being handled: every message's */
    int64_t board_t_us; /* latest board time seen */
    int64_t last_health_t_us;
    sf_pose_out_t poses; /* when the poses are due (sf_pose_out.h) */
    bool config_written;
    sf_publish_loop_t loop;
    sf_publish_sources_t sources; /* fixes offered and made, by source */
} daemon_t;

#define WRITES(d, NAME) SF_OPTIONS_WRITES(&(d)->opt, NAME)

/* One bad-input message (file and line where there is one), at most opt.max_messages of them. */
static void complain(daemon_t *const d, const int code)
{
    char text[512];
    if (d->opt.quiet || !sf_input_describe(d->in, code, text, sizeof text)) {
        return;
    }
    if (d->messages_printed < d->opt.max_messages) {
        fprintf(stderr, "stridefixd: %s\n", text);
    } else if (d->messages_printed == d->opt.max_messages) {
        fprintf(stderr, "stridefixd: further bad-input messages suppressed (counts in the summary)\n");
    }
    d->messages_printed++;
}

/* An input whose framing cannot be trusted any more (sf_input_next SF_ECORRUPT): said even with
 * --quiet, since the run then fails. */
static void refuse_rest(const daemon_t *const d)
{
    char text[512];
    if (!sf_input_describe(d->in, SF_ECORRUPT, text, sizeof text)) {
        snprintf(text, sizeof text, "%s: %s", sf_input_name(d->in), sf_strerror(SF_ECORRUPT));
    }
    fprintf(stderr, "stridefixd: %s\n", text);
}

/* CONFIG, once, before the first input item (or at the end of an empty input). */
static void write_config(daemon_t *const d)
{
    if (!d->config_written && WRITES(d, CONFIG)) {
        sf_publish_config(d->out, d->host_t_us, d->board_t_us, &d->params, SF_VERSION, SF_DBC_SHA256);
    }
    d->config_written = true;
}

static void write_health(daemon_t *const d)
{
    sf_input_counters_t ic;
    sf_input_counters(d->in, &ic);
    sf_estimator_status_t st;
    sf_estimator_status(&d->est, &st);
    if (WRITES(d, HEALTH)) {
        sf_publish_health(d->out, d->host_t_us, d->board_t_us, &ic, &st, &d->sources, &d->loop);
    }
    d->last_health_t_us = d->board_t_us;
}

static void write_pose(daemon_t *const d)
{
    sf_pose_out_write(&d->poses, d->out, d->host_t_us, &d->est, &d->params, &d->opt);
}

/* What one absolute source gave the estimator (sf_estimator_wifi / _gnss / _ble / _landmark): its n
 * FIX audit records (every scheme's verdict on the fix, or why there was none) published, the source
 * counted (offered, and made a fix of), and the POSE written now when there were audits: the fix moved
 * the fused schemes, say so now, not at the next step. */
static void publish_fixes(daemon_t *const d, const int method, const int n, const bool has_fix,
                          const sf_fix_audit_t audits[sf_scheme_count])
{
    d->sources.offered[method]++;
    d->sources.made[method] += has_fix ? 1u : 0u;
    for (int i = 0; i < n; i++) {
        if ((d->params.output_scheme < 0 || audits[i].scheme == d->params.output_scheme) && WRITES(d, FIX)) {
            sf_publish_fix(d->out, d->host_t_us, &audits[i]);
        }
    }
    if (n > 0) {
        write_pose(d);
    }
}

static void on_wifi(daemon_t *const d, const sf_rx_wifi_t *const w)
{
    const sf_wifi_scan_t scan = {.t_us = w->t_us, .n_ap = w->n_ap, .bssid = w->bssid, .rssi_dbm = w->rssi_dbm};
    sf_fix_t fix;
    bool has_fix = false;
    sf_fix_audit_t audits[sf_scheme_count];
    const int n = sf_estimator_wifi(&d->est, &d->params, &scan, &fix, &has_fix, audits);
    publish_fixes(d, sf_fix_wifi, n, has_fix, audits);
}

static void on_gnss(daemon_t *const d, const sf_rx_gnss_t *const g)
{
    const sf_gnss_t in = {
        .t_us = g->t_us, .lat_deg = g->lat_deg, .lon_deg = g->lon_deg, .alt_m = g->alt_m, .accuracy_m = g->accuracy_m};
    sf_fix_t fix;
    bool has_fix = false;
    sf_fix_audit_t audits[sf_scheme_count];
    const int n = sf_estimator_gnss(&d->est, &d->params, &in, &fix, &has_fix, audits);
    publish_fixes(d, sf_fix_gnss, n, has_fix, audits);
}

static void on_ble(daemon_t *const d, const sf_rx_ble_t *const b)
{
    const sf_ble_scan_t scan = {.t_us = b->t_us, .n = b->n, .beacon_id = b->beacon_id, .rssi_dbm = b->rssi_dbm};
    sf_fix_t fix;
    bool has_fix = false;
    sf_fix_audit_t audits[sf_scheme_count];
    const int n = sf_estimator_ble(&d->est, &d->params, &scan, &fix, &has_fix, audits);
    publish_fixes(d, sf_fix_ble, n, has_fix, audits);
}

static void on_landmark(daemon_t *const d, const sf_rx_landmark_t *const l)
{
    const sf_landmark_t in = {.t_us = l->t_us,
                              .landmark_id = l->landmark_id,
                              .x_m = l->x_m,
                              .y_m = l->y_m,
                              .floor = l->floor,
                              .accuracy_m = l->accuracy_m};
    sf_fix_t fix;
    bool has_fix = false;
    sf_fix_audit_t audits[sf_scheme_count];
    const int n = sf_estimator_landmark(&d->est, &d->params, &in, &fix, &has_fix, audits);
    publish_fixes(d, sf_fix_landmark, n, has_fix, audits);
}

static void on_imu(daemon_t *const d, const sf_rx_imu_t *const s)
{
    sf_imu_sample_t in = {.t_us = s->t_us};
    memcpy(in.accel_mps2, s->accel_mps2, sizeof in.accel_mps2);
    memcpy(in.gyro_radps, s->gyro_radps, sizeof in.gyro_radps);
    sf_step_t steps[SF_ESTIMATOR_MAX_STEPS];
    const int n_steps = sf_estimator_imu(&d->est, &d->params, &in, steps);
    for (int i = 0; i < n_steps && WRITES(d, STEP); i++) {
        sf_publish_step(d->out, d->host_t_us, &steps[i]);
    }
    if (sf_pose_out_due(&d->poses, &d->est, &d->params, n_steps)) {
        write_pose(d);
    }
}

/* The controller's events after an input (sf_estimator_next_context): each CONTEXT, a stairs
 * recalibration's METHOD_PORT audits as FIX, then the POSE. */
static void drain_contexts(daemon_t *const d)
{
    sf_context_event_t ev;
    sf_fix_t fix;
    bool has_fix;
    sf_fix_audit_t audits[sf_scheme_count];
    int n;
    while (sf_estimator_next_context(&d->est, &d->params, &ev, &fix, &has_fix, audits, &n)) {
        if (WRITES(d, CONTEXT)) {
            sf_publish_context(d->out, d->host_t_us, &ev, &d->site, &d->params);
        }
        if (n > 0) {
            publish_fixes(d, sf_fix_port, n, has_fix, audits); /* and the POSE */
        } else {
            write_pose(d);
        }
    }
}

/* The one place where samples reach the estimator, whichever input they came from. No default: a
 * kind added to SF_RX_KINDS without a case here stops the build (-Wswitch, -Werror). */
static void feed(daemon_t *const d, const sf_rx_event_t *const ev)
{
    if (sf_options_channel_on(&d->opt, sf_rx_lcm_channel(ev->kind))) {
        sf_rx_lcm_write(d->out, d->host_t_us, ev); /* the raw input first, as it came */
    }
    switch (ev->kind) {
    case sf_rx_imu:
        d->board_t_us = ev->u.imu.t_us;
        on_imu(d, &ev->u.imu);
        break;
    case sf_rx_mag:
        sf_estimator_mag(&d->est, &d->params, ev->u.mag.t_us, ev->u.mag.field_ut);
        d->board_t_us = ev->u.mag.t_us;
        break;
    case sf_rx_baro:
        sf_estimator_baro(&d->est, &d->params, ev->u.baro.t_us, ev->u.baro.pressure_pa);
        d->board_t_us = ev->u.baro.t_us;
        break;
    case sf_rx_wifi: on_wifi(d, &ev->u.wifi); break;
    case sf_rx_gnss: on_gnss(d, &ev->u.gnss); break;
    case sf_rx_ble: on_ble(d, &ev->u.ble); break;
    case sf_rx_landmark: on_landmark(d, &ev->u.landmark); break;
    case sf_rx_none: break;
    }
    drain_contexts(d);
}

static double monotonic_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec * 1e-3;
}

/* One input item: CONFIG before the first, the sample fed, HEALTH every output.health_period_ms of
 * board time, and the loop timing (of one item in loop.stride: sf_publish.h). */
static void handle(daemon_t *const d, const sf_input_item_t *const item)
{
    d->host_t_us = item->log_t_us;
    write_config(d);
    const bool timed = sf_publish_loop_due(&d->loop);
    const double t0 = timed ? monotonic_us() : 0.0;
    if (item->status < 0) {
        complain(d, item->status);
    } else if (item->event.kind != sf_rx_none) { /* 4 in 10 replay frames: no sample, no controller event */
        feed(d, &item->event);
    }
    if (d->board_t_us - d->last_health_t_us >= (int64_t)d->params.output_health_period_ms * 1000) {
        write_health(d);
    }
    if (timed) {
        sf_publish_loop_add(&d->loop, monotonic_us() - t0);
    }
}

static int run(daemon_t *const d)
{
    int status = 0;
    for (;;) {
        if (sf_signals_stop_requested() != 0) {
            break;
        }
        const int rc = sf_input_next(d->in, &d->item);
        if (rc == 0) {
            break;
        }
        if (rc == SF_EINTR) {
            continue; /* a stop signal is seen at the top */
        }
        if (rc == SF_EIO) {
            fprintf(stderr, "stridefixd: %s: read failed: %s\n", sf_input_name(d->in), strerror(errno));
            status = 1;
            break;
        }
        if (rc == SF_ECORRUPT) {
            refuse_rest(d);
            status = sf_input_nothing_valid(d->in, NULL, 0) ? 0 : 1; /* 0: not a log at all, exit 3 below */
            break;
        }
        if (rc < 0) {
            complain(d, rc);
            continue;
        }
        if (sf_pace_sleep(&d->opt.pace, d->item.log_t_us, sf_signals_stop_requested) == SF_OK) {
            handle(d, &d->item); /* when due (--speed); not after a stop signal: the loop ends at its top */
        }
    }
    sf_signals_input_done();
    write_config(d);
    write_health(d);
    return status;
}

/* Opens the log and the live LCM: --log as given, or the first default name in --log-dir that is
 * free (sf_log_file_default_name; a taken name is EEXIST from the O_EXCL open). */
static int open_output(daemon_t *const d, char *const err, const size_t err_size)
{
    sf_lcm_out_config_t cfg = {.log_path = d->opt.no_log ? NULL : d->log_path,
                               .lcm_url = d->opt.lcm_url,
                               .queue_capacity = LOG_QUEUE_MESSAGES,
                               /* Replaying a file: wait for the disk rather than drop. Live SocketCAN: never wait. */
                               .block_when_full = !sf_input_is_live(d->in),
                               /* DEVIATION: STYLE's "queue -> writer thread": a regular file's reads never
                                * wait, and the hand-off cost a replay more than it saved (sf_lcm_out.h). */
                               .caller_writes = sf_input_is_regular_file(d->in),
                               .force = d->opt.force,
                               .fsync_interval_ms = d->params.output_fsync_interval_ms,
                               .rotate_bytes = (uint64_t)d->params.output_log_rotate_mb * 1000000u,
                               .rotate_s = d->params.output_log_rotate_s,
                               .rotate_requests = sf_signals_rotate_requests(),
                               .report = stderr};
    if (d->opt.log_path != NULL) {
        snprintf(d->log_path, sizeof d->log_path, "%s", d->opt.log_path);
        return sf_lcm_out_open_config(&d->out, &cfg, err, err_size);
    }
    struct timespec now;
    clock_gettime(CLOCK_REALTIME, &now);
    int rc = SF_EIO;
    for (unsigned attempt = 0; attempt < LOG_NAME_ATTEMPTS; attempt++) {
        rc = sf_log_file_default_name(d->log_path, sizeof d->log_path, d->opt.log_dir, &now, (long)getpid(), attempt);
        if (rc == SF_OK) {
            rc = sf_lcm_out_open_config(&d->out, &cfg, err, err_size);
        }
        if (rc == SF_OK || d->opt.no_log || errno != EEXIST) {
            break;
        }
    }
    return rc;
}

/* Loads --site and gives it to the estimator: the site's map rotation replaces
 * heading.map_rotation_deg (a fact of the site, not a tuning), and the matcher's workspace is sized
 * to its radio map. */
static int load_site(daemon_t *const d)
{
    char err[512];
    if (sf_batch_site(d->opt.site_path, &d->site, err, sizeof err) != SF_OK) {
        fprintf(stderr, "stridefixd: %s\n", err);
        return -1;
    }
    d->params.heading_map_rotation_deg = d->site.map_rotation_deg;
    if (sf_batch_workspace(&d->site.radiomap, &d->ws) != SF_OK) {
        fprintf(stderr, "stridefixd: out of memory for the radio map workspace\n");
        return -1;
    }
    fprintf(stderr, "stridefixd: site %s: %d floors, %d APs, %d reference points, map rotation %.1f deg\n",
            d->opt.site_path, (int)d->site.n_floors, (int)d->site.radiomap.n_ap, (int)d->site.radiomap.n_rp,
            d->site.map_rotation_deg);
    return 0;
}

/* Everything after the options: open, run, close. The exit status of the run. */
static int serve(daemon_t *const d)
{
    char err[SF_LOG_FILE_PATH_MAX + 256];
    if (sf_privilege_check(d->opt.input, d->opt.allow_root, err, sizeof err) != SF_OK) {
        fprintf(stderr, "stridefixd: %s\n", err);
        return SF_EXIT_USAGE;
    }
    if (sf_signals_install() != SF_OK) {
        fprintf(stderr, "stridefixd: cannot install the signal handlers: %s\n", strerror(errno));
        return 1;
    }
    if (sf_input_open(&d->in, d->opt.input, err, sizeof err) != SF_OK) {
        fprintf(stderr, "stridefixd: %s\n", err);
        return SF_EXIT_USAGE;
    }
    sf_input_configure(d->in, &d->params);
    if (open_output(d, err, sizeof err) != SF_OK) {
        fprintf(stderr, "stridefixd: %s\n", err);
        return 1;
    }
    if (d->opt.site_path != NULL && load_site(d) != 0) {
        return SF_EXIT_USAGE;
    }
    if (d->opt.site_path == NULL && !d->opt.quiet) { /* else a site-less replay looks like a broken estimator */
        fprintf(stderr, "stridefixd: no --site: PDR only, the fused schemes need a site (build one: stridefix site)\n");
    }
    sf_estimator_init(&d->est, &d->params);
    if (d->opt.site_path != NULL) {
        const int rc = sf_estimator_attach_site(&d->est, &d->params, &d->site, &d->ws);
        if (rc != SF_OK) {
            fprintf(stderr, "stridefixd: %s: the site cannot be used: %s\n", d->opt.site_path, sf_strerror(rc));
            return SF_EXIT_USAGE;
        }
    }
    if (sf_particle_mem_alloc(&d->params, d->opt.site_path != NULL ? &d->site : NULL, &d->particle_mem) != SF_OK ||
        sf_estimator_attach_particles(&d->est, &d->params, d->particle_mem.states, d->particle_mem.floors,
                                      d->particle_mem.capacity, &d->particle_mem.walls) != SF_OK) {
        fprintf(stderr, "stridefixd: out of memory for the particle cloud or the wall index\n");
        return 1;
    }
    if (d->opt.site_path != NULL && d->site.plan.n_walls > 0) {
        fprintf(stderr, "stridefixd: site %s: %d walls on %d floors indexed (%zu bytes), %d ports\n",
                d->opt.site_path, (int)d->site.plan.n_walls, (int)d->particle_mem.walls.n_floors,
                d->particle_mem.grid_bytes, (int)d->site.ports.n_ports);
    }
    sf_pose_out_init(&d->poses);
    d->loop.stride = sf_input_is_regular_file(d->in) ? SF_PUBLISH_LOOP_STRIDE_FILE : 1u;
    const double t0 = monotonic_us();
    int status = run(d);
    sf_lcm_out_counters_t oc;
    const int close_rc = sf_lcm_out_close(d->out, &oc);
    d->out = NULL;
    if (close_rc != SF_OK) {
        fprintf(stderr, "stridefixd: %s: the log is incomplete: %" PRIu64 " events (%" PRIu64
                " bytes) dropped by failed writes or a file not finished (reasons above)\n",
                d->log_path, oc.drops, oc.drop_bytes);
        status = 1;
    }
    const int stop_signal = sf_signals_stop_requested();
    if (stop_signal != 0) {
        fprintf(stderr, "stridefixd: stopped by signal %d (%s); the log is closed\n", stop_signal,
                strsignal(stop_signal));
    }
    sf_input_counters_t ic;
    sf_input_counters(d->in, &ic);
    sf_estimator_status_t st;
    sf_estimator_status(&d->est, &st);
    sf_summary_print(stderr, &ic, &st, &d->sources, &oc, d->opt.no_log ? NULL : d->log_path,
                     (monotonic_us() - t0) * 1e-6);
    char why[512];
    if (status == 0 && sf_input_nothing_valid(d->in, why, sizeof why)) {
        fprintf(stderr, "stridefixd: %s\n", why);
        status = SF_EXIT_NOTHING_VALID;
    }
    return status;
}

/* One replay: options, serve, close. */
static int run_once(const int argc, char **const argv)
{
    static daemon_t d; /* large (scan buffers): static, not on the stack; zeroed for every run */
    memset(&d, 0, sizeof d);
    const int prc = sf_options_parse(argc, argv, SF_VERSION, SF_DBC_SHA256, &d.opt, &d.params);
    if (prc != 0) {
        return prc;
    }
    const int status = serve(&d);
    if (d.out != NULL) {
        (void)sf_lcm_out_close(d.out, NULL);
    }
    sf_input_close(d.in); /* only what was opened: never stdin on --replay */
    sf_batch_workspace_keep(&d.ws);
    sf_particle_mem_free(&d.particle_mem);
    return status;
}

int main(int argc, char **argv)
{
    const int status = argc == 3 && strcmp(argv[1], "--batch") == 0 ? sf_batch_run(argv[2], run_once, stdout)
                                                                     : run_once(argc, argv);
    sf_batch_site_free();
    return status;
}
