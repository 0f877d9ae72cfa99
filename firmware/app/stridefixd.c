/* stridefixd — the StrideFix logger daemon.
 *
 * Reads the board's CAN frames (candump -L file, stdin or SocketCAN), decodes and times them
 * (firmware/board/sf_board_rx.h), feeds the estimator core (firmware/core), and writes every raw
 * input message plus STEP, POSE, HEALTH and CONFIG to an LCM event log, optionally publishing live
 * too. Bad input is counted and skipped, never fatal; counts go into HEALTH and the exit summary. */
#define _GNU_SOURCE
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "sf_board_rx.h"
#include "sf_can_input.h"
#include "sf_config.h"
#include "sf_error.h"
#include "sf_lcm_input.h"
#include "sf_lcm_out.h"
#include "sf_params.h"
#include "sf_site.h"
#include "sf_estimator.h"
#include "stridefix_baro_t.h"
#include "stridefix_config_t.h"
#include "stridefix_fix_t.h"
#include "stridefix_gnss_t.h"
#include "stridefix_health_t.h"
#include "stridefix_imu_t.h"
#include "stridefix_mag_t.h"
#include "stridefix_pose_t.h"
#include "stridefix_step_t.h"
#include "stridefix_wifi_scan_t.h"

#ifndef SF_VERSION
#define SF_VERSION "0.0.0"
#endif
#ifndef SF_DBC_SHA256
#define SF_DBC_SHA256 "unknown"
#endif

#define EXIT_USAGE 2
#define LOG_QUEUE_MESSAGES 8192
#define MAX_SETS 64
#define LCMLOG_PREFIX "lcmlog:"

typedef struct {
    const char *input;
    const char *log_path;
    const char *log_dir;
    bool no_log;
    const char *lcm_url;
    const char *site_path;
    const char *fusion;
    char replay_spec[4096];
    const char *config_paths[MAX_SETS];
    int n_configs;
    const char *sets[MAX_SETS];
    int n_sets;
    bool quiet;
    long max_messages;
} options_t;

typedef struct {
    options_t opt;
    sf_params_t params;
    sf_can_input_t in;
    sf_lcm_input_t *lcm_in; /* set when replaying a raw-sensor LCM log instead of CAN frames */
    sf_lcm_out_t *out;
    sf_board_rx_t rx;
    sf_estimator_t est;
    sf_site_store_t site_store;
    sf_site_t site;
    sf_fingerprint_workspace_t ws;
    void *ws_memory;
    uint64_t fixes_published;
    char log_path[4096];
    uint64_t bad_syntax;
    long messages_printed;
    int64_t host_t_us;    /* host time of the frame being handled: every event's log timestamp */
    int64_t board_t_us;   /* latest board time seen */
    int64_t last_health_t_us;
    int64_t last_pose_t_us;
    int16_t last_pose_floor;
    bool config_written;
    double loop_sum_us;
    double loop_max_us;
    uint64_t loop_n;
} daemon_t;

static void usage(FILE *const f)
{
    fprintf(f,
            "Usage: stridefixd --input SPEC [options]\n"
            "StrideFix logger: board CAN frames -> estimator -> LCM log (+ live LCM).\n"
            "\n"
            "Inputs\n"
            "  -i, --input SPEC       board frames: a candump -L file, '-' for stdin, or socketcan:IFACE\n"
            "                         (SocketCAN needs a kernel with AF_CAN), or lcmlog:FILE, a raw-sensor\n"
            "                         LCM log (IMU MAG BARO WIFI GNSS channels) as `stridefix import` writes\n"
            "      --replay FILE      same as --input lcmlog:FILE: replay a raw-sensor log as fast as possible\n"
            "Outputs\n"
            "  -l, --log FILE         LCM event log to write (default: DIR/stridefixd-YYYYmmdd-HHMMSS.lcmlog)\n"
            "  -d, --log-dir DIR      directory for the default log name (default: .)\n"
            "      --no-log           write no log (live publishing only)\n"
            "  -u, --lcm-url URL      also publish live to this LCM URL, e.g. udpm://239.255.76.67:7667?ttl=0\n"
            "Site\n"
            "      --site FILE        site file (floors, map rotation, radio map) from `stridefix radiomap build`:\n"
            "                         enables Wi-Fi fixes and the fusion schemes; without it PDR starts at\n"
            "                         the config pose (init.*)\n"
            "      --fusion MODE      publish one scheme's POSE and FIX: pdr_only, wifi_only, overwrite,\n"
            "                         static, adaptive, kalman; or all (default: every scheme side by side,\n"
            "                         one log compares them all). Same as --set output.scheme=N\n"
            "Configuration\n"
            "  -c, --config FILE      INI file of [section] key = value (every key: --print-config);\n"
            "                         repeatable, later files override earlier ones\n"
            "  -s, --set KEY=VALUE    override one key, e.g. --set stride.weinberg_k=0.5 (repeatable)\n"
            "      --print-config     print every key with its default, range, unit and meaning; exit\n"
            "Messages\n"
            "  -q, --quiet            no per-line bad-input messages (counts still in HEALTH and the summary)\n"
            "      --max-messages N   print at most N bad-input messages (default 20)\n"
            "  -h, --help             this text\n"
            "  -V, --version          version and the DBC it was built from\n"
            "\n"
            "Channels written: IMU MAG BARO WIFI GNSS (inputs), STEP, POSE (one per fusion scheme),\n"
            "FIX (with a site: every scheme's verdict on every Wi-Fi fix), HEALTH (every\n"
            "output.health_period_ms of board time, and at exit), CONFIG (once, first).\n"
            "Exit status: 0 done (bad frames are counted and skipped, not fatal); 1 the log could not be\n"
            "written; 2 bad usage, or an input or config that cannot be read.\n");
}

static void print_config(const sf_params_t *const p)
{
    printf("# stridefixd configuration keys (INI: [section] then key = value)\n");
    const char *section = "";
    for (size_t i = 0; i < sf_param_count; i++) {
        const sf_param_desc_t *const d = &sf_param_table[i];
        if (strcmp(section, d->section) != 0) {
            section = d->section;
            printf("\n[%s]\n", section);
        }
        printf("# %s [%s], range %g .. %g\n%s = %.9g\n", d->text, d->unit, d->min_value, d->max_value, d->name,
               sf_param_get(p, d));
    }
}

static int parse_options(const int argc, char **const argv, options_t *const o, sf_params_t *const params)
{
    enum { opt_no_log = 1000, opt_print_config, opt_max_messages, opt_site, opt_fusion, opt_replay };
    static const struct option longs[] = {
        {"input", required_argument, NULL, 'i'},   {"log", required_argument, NULL, 'l'},
        {"log-dir", required_argument, NULL, 'd'}, {"no-log", no_argument, NULL, opt_no_log},
        {"lcm-url", required_argument, NULL, 'u'}, {"config", required_argument, NULL, 'c'},
        {"set", required_argument, NULL, 's'},     {"print-config", no_argument, NULL, opt_print_config},
        {"quiet", no_argument, NULL, 'q'},         {"max-messages", required_argument, NULL, opt_max_messages},
        {"help", no_argument, NULL, 'h'},          {"version", no_argument, NULL, 'V'},
        {"site", required_argument, NULL, opt_site},
        {"fusion", required_argument, NULL, opt_fusion},
        {"replay", required_argument, NULL, opt_replay},
        {NULL, 0, NULL, 0}};
    *o = (options_t){.log_dir = ".", .max_messages = 20};
    bool want_print_config = false;
    int c;
    while ((c = getopt_long(argc, argv, "i:l:d:u:c:s:qhV", longs, NULL)) != -1) {
        switch (c) {
        case 'i': o->input = optarg; break;
        case 'l': o->log_path = optarg; break;
        case 'd': o->log_dir = optarg; break;
        case opt_no_log: o->no_log = true; break;
        case 'u': o->lcm_url = optarg; break;
        case opt_site: o->site_path = optarg; break;
        case opt_fusion: o->fusion = optarg; break;
        case opt_replay: /* the raw-sensor log replay, spelled as the issue asked for it */
            snprintf(o->replay_spec, sizeof o->replay_spec, "%s%s", LCMLOG_PREFIX, optarg);
            o->input = o->replay_spec;
            break;
        case 'c':
            if (o->n_configs == MAX_SETS) {
                fprintf(stderr, "stridefixd: at most %d --config options\n", MAX_SETS);
                return EXIT_USAGE;
            }
            o->config_paths[o->n_configs++] = optarg;
            break;
        case 's':
            if (o->n_sets == MAX_SETS) {
                fprintf(stderr, "stridefixd: at most %d --set options\n", MAX_SETS);
                return EXIT_USAGE;
            }
            o->sets[o->n_sets++] = optarg;
            break;
        case opt_print_config: want_print_config = true; break;
        case 'q': o->quiet = true; break;
        case opt_max_messages: o->max_messages = strtol(optarg, NULL, 10); break;
        case 'h': usage(stdout); exit(0);
        case 'V': printf("stridefixd %s (board.dbc sha256 %s)\n", SF_VERSION, SF_DBC_SHA256); exit(0);
        default: usage(stderr); return EXIT_USAGE;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "stridefixd: unexpected argument '%s' (see --help)\n", argv[optind]);
        return EXIT_USAGE;
    }
    sf_params_default(params);
    char err[512];
    for (int i = 0; i < o->n_configs; i++) {
        if (sf_config_load(o->config_paths[i], params, err, sizeof err) != SF_OK) {
            fprintf(stderr, "stridefixd: %s\n", err);
            return EXIT_USAGE;
        }
    }
    for (int i = 0; i < o->n_sets; i++) {
        if (sf_config_set(o->sets[i], params, err, sizeof err) != SF_OK) {
            fprintf(stderr, "stridefixd: %s\n", err);
            return EXIT_USAGE;
        }
    }
    if (o->fusion != NULL) {
        static const char *const names[] = {"pdr_only", "wifi_only", "overwrite", "static", "adaptive", "kalman"};
        int code = strcmp(o->fusion, "all") == 0 ? -1 : -2;
        for (int i = 0; i < (int)(sizeof names / sizeof names[0]); i++) {
            if (strcmp(o->fusion, names[i]) == 0) {
                code = i;
            }
        }
        if (code == -2) {
            fprintf(stderr, "stridefixd: --fusion %s: expected all, pdr_only, wifi_only, overwrite, static, "
                            "adaptive or kalman\n", o->fusion);
            return EXIT_USAGE;
        }
        params->output_scheme = code;
    }
    if (want_print_config) {
        print_config(params);
        exit(0);
    }
    if (o->input == NULL) {
        fprintf(stderr, "stridefixd: --input is required (see --help)\n");
        return EXIT_USAGE;
    }
    return 0;
}

/* One bad-input message, naming the file and line where there is one. */
static void complain(daemon_t *const d, const char *const what)
{
    if (d->opt.quiet) {
        return;
    }
    if (d->messages_printed < d->opt.max_messages) {
        if (d->in.kind == sf_can_input_file) {
            fprintf(stderr, "stridefixd: %s:%ld: %s: '%.80s'\n", d->in.name, d->in.line_no, what, d->in.line);
        } else {
            fprintf(stderr, "stridefixd: %s: %s\n", d->in.name, what);
        }
    } else if (d->messages_printed == d->opt.max_messages) {
        fprintf(stderr, "stridefixd: further bad-input messages suppressed (counts in the summary)\n");
    }
    d->messages_printed++;
}

static void write_config(daemon_t *const d)
{
    enum { n = SF_PARAM_COUNT };
    char keys[n][64];
    char values[n][32];
    char *key_ptrs[n];
    char *value_ptrs[n];
    for (size_t i = 0; i < sf_param_count; i++) {
        snprintf(keys[i], sizeof keys[i], "%s.%s", sf_param_table[i].section, sf_param_table[i].name);
        snprintf(values[i], sizeof values[i], "%.9g", sf_param_get(&d->params, &sf_param_table[i]));
        key_ptrs[i] = keys[i];
        value_ptrs[i] = values[i];
    }
    stridefix_config_t msg = {.t_us = d->board_t_us,
                              .version = (char *)SF_VERSION,
                              .dbc_sha256 = (char *)SF_DBC_SHA256,
                              .n = (int32_t)sf_param_count,
                              .key = key_ptrs,
                              .value = value_ptrs};
    SF_LCM_WRITE(d->out, "CONFIG", d->host_t_us, stridefix_config_t, &msg);
    d->config_written = true;
}

static void write_health(daemon_t *const d)
{
    const sf_rx_counters_t *const c = &d->rx.counters;
    sf_lcm_out_counters_t oc;
    sf_lcm_out_counters(d->out, &oc);
    stridefix_health_t msg = {
        .t_us = d->board_t_us,
        .host_t_us = d->host_t_us,
        .frames_total = (int64_t)(c->frames + d->bad_syntax),
        .frames_ok = (int64_t)c->frames_ok,
        .bad_syntax = (int64_t)d->bad_syntax,
        .unknown_id = (int64_t)c->unknown_id,
        .bad_length = (int64_t)c->bad_length,
        .decode_errors = (int64_t)c->decode_errors,
        .seq_gaps = (int64_t)c->seq_gaps,
        .unsynced = (int64_t)c->unsynced,
        .imu_unpaired = (int64_t)c->imu_unpaired,
        .wifi_incomplete = (int64_t)c->wifi_incomplete,
        .imu_samples = (int64_t)c->imu,
        .mag_samples = (int64_t)c->mag,
        .baro_samples = (int64_t)c->baro,
        .wifi_scans = (int64_t)c->wifi,
        .gnss_fixes = (int64_t)c->gnss,
        .steps = d->est.step_count,
        .mag_rejected = (int64_t)d->est.attitude.mag_rejected,
        .log_events = (int64_t)oc.events,
        .log_bytes = (int64_t)oc.bytes,
        .log_drops = (int64_t)oc.drops,
        .loop_mean_us = d->loop_n > 0 ? (float)(d->loop_sum_us / (double)d->loop_n) : 0.0f,
        .loop_max_us = (float)d->loop_max_us,
    };
    SF_LCM_WRITE(d->out, "HEALTH", d->host_t_us, stridefix_health_t, &msg);
    d->last_health_t_us = d->board_t_us;
}

/* One POSE per fusion scheme that has a position (a scheme waiting for its first fix has none).
 * Without a site there are no fixes, so only pdr_only is published (the others would repeat it). */
static void write_pose(daemon_t *const d)
{
    const int n_schemes = d->est.site != NULL ? sf_scheme_count : sf_scheme_pdr_only + 1;
    for (int scheme = 0; scheme < n_schemes; scheme++) {
        if (d->params.output_scheme >= 0 && scheme != d->params.output_scheme) {
            continue;
        }
        sf_pose_t p;
        if (!sf_estimator_scheme_pose(&d->est, &d->params, scheme, &p)) {
            continue;
        }
        stridefix_pose_t msg = {.t_us = p.t_us,
                                .x_m = p.x_m,
                                .y_m = p.y_m,
                                .floor = p.floor,
                                .heading_rad = (float)p.heading_rad,
                                .sigma_m = (float)p.sigma_m,
                                .step_count = p.step_count,
                                .scheme = p.scheme};
        SF_LCM_WRITE(d->out, "POSE", d->host_t_us, stridefix_pose_t, &msg);
    }
    d->last_pose_t_us = d->est.t_us;
    d->last_pose_floor = sf_floor_current(&d->est.floor);
}

/* The FIX audit records of one scan: every scheme's verdict. */
static void on_wifi_fix(daemon_t *const d, const sf_rx_wifi_t *const w)
{
    const sf_wifi_scan_t scan = {.t_us = w->t_us, .n_ap = w->n_ap, .bssid = w->bssid, .rssi_dbm = w->rssi_dbm};
    sf_fix_t fix;
    bool has_fix = false;
    sf_fix_audit_t audits[sf_scheme_count];
    const int n = sf_estimator_wifi(&d->est, &d->params, &scan, &fix, &has_fix, audits);
    for (int i = 0; i < n; i++) {
        const sf_fix_audit_t *const a = &audits[i];
        if (d->params.output_scheme >= 0 && a->scheme != d->params.output_scheme) {
            continue;
        }
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
                               .accepted = a->accepted,
                               .reason = a->reason,
                               .reason_text = (char *)sf_fix_reason_text(a->reason)};
        SF_LCM_WRITE(d->out, "FIX", d->host_t_us, stridefix_fix_t, &msg);
        d->fixes_published++;
    }
    if (n > 0) {
        write_pose(d); /* the fix moved the fused schemes: say so now, not at the next step */
    }
}

static void on_imu(daemon_t *const d, const sf_rx_imu_t *const s)
{
    stridefix_imu_t msg = {.t_us = s->t_us, .seq = s->seq};
    memcpy(msg.accel_mps2, s->accel_mps2, sizeof msg.accel_mps2);
    memcpy(msg.gyro_radps, s->gyro_radps, sizeof msg.gyro_radps);
    SF_LCM_WRITE(d->out, "IMU", d->host_t_us, stridefix_imu_t, &msg);

    sf_imu_sample_t in = {.t_us = s->t_us};
    memcpy(in.accel_mps2, s->accel_mps2, sizeof in.accel_mps2);
    memcpy(in.gyro_radps, s->gyro_radps, sizeof in.gyro_radps);
    sf_step_t steps[SF_ESTIMATOR_MAX_STEPS];
    const int n_steps = sf_estimator_imu(&d->est, &d->params, &in, steps);
    for (int i = 0; i < n_steps; i++) {
        const sf_step_t *const st = &steps[i];
        stridefix_step_t sm = {.t_us = st->t_us,
                               .index = st->index,
                               .length_m = (float)st->length_m,
                               .accel_range_mps2 = (float)st->accel_range_mps2,
                               .period_s = (float)st->period_s,
                               .heading_rad = (float)st->heading_rad,
                               .activity = st->activity,
                               .floor = st->floor};
        SF_LCM_WRITE(d->out, "STEP", d->host_t_us, stridefix_step_t, &sm);
    }
    if (n_steps > 0) {
        write_pose(d);
    } else if (s->t_us - d->last_pose_t_us >= (int64_t)d->params.output_pose_period_ms * 1000 ||
               sf_floor_current(&d->est.floor) != d->last_pose_floor) {
        write_pose(d);
    }
}

static void on_event(daemon_t *const d, const sf_rx_event_t *const ev)
{
    switch (ev->kind) {
    case sf_rx_imu:
        d->board_t_us = ev->u.imu.t_us;
        on_imu(d, &ev->u.imu);
        break;
    case sf_rx_mag: {
        const sf_rx_mag_t *const s = &ev->u.mag;
        stridefix_mag_t msg = {.t_us = s->t_us, .seq = s->seq};
        memcpy(msg.field_ut, s->field_ut, sizeof msg.field_ut);
        SF_LCM_WRITE(d->out, "MAG", d->host_t_us, stridefix_mag_t, &msg);
        sf_estimator_mag(&d->est, &d->params, s->t_us, s->field_ut);
        d->board_t_us = s->t_us;
        break;
    }
    case sf_rx_baro: {
        const sf_rx_baro_t *const s = &ev->u.baro;
        stridefix_baro_t msg = {.t_us = s->t_us, .seq = s->seq, .pressure_pa = s->pressure_pa,
                                .temperature_degc = s->temperature_degc};
        SF_LCM_WRITE(d->out, "BARO", d->host_t_us, stridefix_baro_t, &msg);
        sf_estimator_baro(&d->est, &d->params, s->t_us, s->pressure_pa);
        d->board_t_us = s->t_us;
        break;
    }
    case sf_rx_wifi: {
        const sf_rx_wifi_t *const s = &ev->u.wifi;
        stridefix_wifi_scan_t msg = {.t_us = s->t_us,
                                     .scan_id = s->scan_id,
                                     .complete = s->complete,
                                     .n_ap = s->n_ap,
                                     .bssid = (int64_t *)s->bssid,
                                     .rssi_dbm = (float *)s->rssi_dbm,
                                     .freq_mhz = (int32_t *)s->freq_mhz};
        SF_LCM_WRITE(d->out, "WIFI", d->host_t_us, stridefix_wifi_scan_t, &msg);
        on_wifi_fix(d, s);
        break;
    }
    case sf_rx_gnss: {
        const sf_rx_gnss_t *const s = &ev->u.gnss;
        stridefix_gnss_t msg = {.t_us = s->t_us, .lat_deg = s->lat_deg, .lon_deg = s->lon_deg,
                                .alt_m = s->alt_m, .accuracy_m = s->accuracy_m};
        SF_LCM_WRITE(d->out, "GNSS", d->host_t_us, stridefix_gnss_t, &msg);
        break;
    }
    case sf_rx_none: break;
    }
}

static void on_bad_frame(daemon_t *const d, const int rc, const sf_can_frame_t *const f)
{
    char what[160];
    switch (rc) {
    case SF_EUNKNOWN_ID:
        snprintf(what, sizeof what, "CAN id 0x%" PRIX32 "%s is not in board.dbc; skipped", f->id,
                 f->extended ? " (extended)" : f->remote ? " (remote)" : "");
        break;
    case SF_ELENGTH:
        snprintf(what, sizeof what, "CAN id 0x%03" PRIX32 " has %u data bytes, board.dbc says 8; skipped", f->id,
                 f->dlc);
        break;
    case SF_ERANGE:
        snprintf(what, sizeof what, "CAN id 0x%03" PRIX32 ": signal out of range or out of sequence; skipped", f->id);
        break;
    default: return; /* unsynced / duplicate samples: counted only, they are expected at start-up */
    }
    complain(d, what);
}

static double monotonic_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec * 1e-3;
}

/* Bookkeeping shared by both input paths, around the handling of one input item. */
static double begin_item(daemon_t *const d, const int64_t host_t_us)
{
    d->host_t_us = host_t_us;
    if (!d->config_written) {
        write_config(d);
    }
    return monotonic_us();
}

static void end_item(daemon_t *const d, const double t0)
{
    if (d->board_t_us - d->last_health_t_us >= (int64_t)d->params.output_health_period_ms * 1000) {
        write_health(d);
    }
    const double dt = monotonic_us() - t0;
    d->loop_sum_us += dt;
    d->loop_n++;
    if (dt > d->loop_max_us) {
        d->loop_max_us = dt;
    }
}

static int run_can(daemon_t *const d, sf_rx_event_t *const ev)
{
    sf_can_frame_t frame;
    for (;;) {
        const int rc = sf_can_input_next(&d->in, &frame);
        if (rc == 0) {
            return 0;
        }
        if (rc == SF_ESYNTAX) {
            d->bad_syntax++;
            complain(d, "not a candump -L line; skipped");
            continue;
        }
        if (rc < 0) {
            fprintf(stderr, "stridefixd: %s: read failed: %s\n", d->in.name, strerror(errno));
            return 1;
        }
        const double t0 = begin_item(d, frame.host_t_us);
        const int r = sf_board_rx_frame(&d->rx, &frame, ev);
        if (r < 0) {
            on_bad_frame(d, r, &frame);
        } else if (r == 1) {
            on_event(d, ev);
        }
        end_item(d, t0);
    }
}

/* Replay of a raw-sensor LCM log: events are already decoded and timed; the counters the CAN path
 * keeps in sf_board_rx are kept here so HEALTH reads the same. */
static int run_lcm(daemon_t *const d, sf_rx_event_t *const ev)
{
    sf_rx_counters_t *const c = &d->rx.counters;
    for (;;) {
        int64_t log_t_us = 0;
        const int rc = sf_lcm_input_next(d->lcm_in, ev, &log_t_us);
        if (rc == 0) {
            return 0;
        }
        c->frames++;
        if (rc < 0) {
            c->decode_errors++;
            continue;
        }
        c->frames_ok++;
        c->imu += ev->kind == sf_rx_imu;
        c->mag += ev->kind == sf_rx_mag;
        c->baro += ev->kind == sf_rx_baro;
        c->wifi += ev->kind == sf_rx_wifi;
        c->gnss += ev->kind == sf_rx_gnss;
        const double t0 = begin_item(d, log_t_us);
        on_event(d, ev);
        end_item(d, t0);
    }
}

static int run(daemon_t *const d)
{
    sf_rx_event_t *const ev = malloc(sizeof *ev);
    if (ev == NULL) {
        return 1;
    }
    const int status = d->lcm_in != NULL ? run_lcm(d, ev) : run_can(d, ev);
    free(ev);
    if (!d->config_written) {
        write_config(d);
    }
    write_health(d);
    return status;
}

static void summary(const daemon_t *const d, const sf_lcm_out_counters_t *const out, const double wall_s)
{
    const sf_rx_counters_t *const c = &d->rx.counters;
    const sf_lcm_out_counters_t oc = *out;
    fprintf(stderr,
            "stridefixd: %" PRIu64 " frames (%" PRIu64 " ok): %" PRIu64 " bad syntax, %" PRIu64 " unknown id, %" PRIu64
            " truncated, %" PRIu64 " decode errors, %" PRIu64 " seq gaps, %" PRIu64 " unsynced, %" PRIu64
            " unpaired IMU halves, %" PRIu64 " incomplete scans\n",
            c->frames + d->bad_syntax, c->frames_ok, d->bad_syntax, c->unknown_id, c->bad_length, c->decode_errors,
            c->seq_gaps, c->unsynced, c->imu_unpaired, c->wifi_incomplete);
    fprintf(stderr,
            "stridefixd: %" PRIu64 " IMU, %" PRIu64 " MAG, %" PRIu64 " BARO, %" PRIu64 " WIFI, %" PRIu64
            " GNSS; %d steps; log %s: %" PRIu64 " events, %.2f MB, %" PRIu64 " dropped; %.2f s\n",
            c->imu, c->mag, c->baro, c->wifi, c->gnss, (int)d->est.step_count,
            d->opt.no_log ? "(none)" : d->log_path, oc.events, (double)oc.bytes / 1e6, oc.drops, wall_s);
}

static void default_log_path(daemon_t *const d)
{
    if (d->opt.log_path != NULL) {
        snprintf(d->log_path, sizeof d->log_path, "%s", d->opt.log_path);
        return;
    }
    const time_t now = time(NULL);
    struct tm tm;
    gmtime_r(&now, &tm);
    char name[64];
    strftime(name, sizeof name, "stridefixd-%Y%m%d-%H%M%S.lcmlog", &tm);
    snprintf(d->log_path, sizeof d->log_path, "%s/%s", d->opt.log_dir, name);
}

/* Loads --site: the site's map rotation replaces heading.map_rotation_deg (a fact of the site, not a
 * tuning), and the matcher's workspace is sized to its radio map. The only allocation besides the
 * log queue. */
static int load_site(daemon_t *const d)
{
    if (d->opt.site_path == NULL) {
        return 0;
    }
    char err[512];
    if (sf_site_load(d->opt.site_path, &d->site_store, &d->site, err, sizeof err) != SF_OK) {
        fprintf(stderr, "stridefixd: %s\n", err);
        return -1;
    }
    d->params.heading_map_rotation_deg = d->site.map_rotation_deg;
    const size_t n = (size_t)(d->site.radiomap.n_rp > 0 ? d->site.radiomap.n_rp : 1);
    d->ws_memory = calloc(n, SF_FINGERPRINT_WS_BYTES_PER_RP);
    if (d->ws_memory == NULL) {
        fprintf(stderr, "stridefixd: out of memory for the radio map workspace\n");
        return -1;
    }
    unsigned char *m = d->ws_memory;
    d->ws.n_rp = (int32_t)n;
    d->ws.rp_fill_sq_db2 = (double *)(void *)m;
    d->ws.rp_miss_loglik = (double *)(void *)(m + n * sizeof(double));
    d->ws.acc = (double *)(void *)(m + 2 * n * sizeof(double));
    d->ws.n_common = (int32_t *)(void *)(m + 3 * n * sizeof(double));
    d->ws.touched = (int32_t *)(void *)(m + 3 * n * sizeof(double) + n * sizeof(int32_t));
    fprintf(stderr, "stridefixd: site %s: %d floors, %d APs, %d reference points, map rotation %.1f deg\n",
            d->opt.site_path, (int)d->site.n_floors, (int)d->site.radiomap.n_ap, (int)d->site.radiomap.n_rp,
            d->site.map_rotation_deg);
    return 0;
}

static void close_input(daemon_t *const d)
{
    if (d->lcm_in != NULL) {
        sf_lcm_input_close(d->lcm_in);
        d->lcm_in = NULL;
    } else {
        sf_can_input_close(&d->in);
    }
}

int main(int argc, char **argv)
{
    static daemon_t d; /* large (scan buffers): static, not on the stack */
    const int prc = parse_options(argc, argv, &d.opt, &d.params);
    if (prc != 0) {
        return prc;
    }
    char err[512];
    const bool lcm_input = strncmp(d.opt.input, LCMLOG_PREFIX, strlen(LCMLOG_PREFIX)) == 0;
    const int irc = lcm_input ? sf_lcm_input_open(&d.lcm_in, d.opt.input + strlen(LCMLOG_PREFIX), err, sizeof err)
                              : sf_can_input_open(&d.in, d.opt.input, err, sizeof err);
    if (irc != SF_OK) {
        fprintf(stderr, "stridefixd: %s\n", err);
        return EXIT_USAGE;
    }
    default_log_path(&d);
    /* Replaying a file: wait for the disk rather than drop. Live SocketCAN: never wait. */
    const bool block = lcm_input || d.in.kind == sf_can_input_file;
    if (sf_lcm_out_open(&d.out, d.opt.no_log ? NULL : d.log_path, d.opt.lcm_url, LOG_QUEUE_MESSAGES, block, err,
                        sizeof err) != SF_OK) {
        fprintf(stderr, "stridefixd: %s\n", err);
        close_input(&d);
        return 1;
    }
    sf_board_rx_init(&d.rx);
    if (load_site(&d) != 0) {
        close_input(&d);
        (void)sf_lcm_out_close(d.out, NULL);
        return EXIT_USAGE;
    }
    sf_estimator_init(&d.est, &d.params);
    if (d.opt.site_path != NULL) {
        const int rc = sf_estimator_attach_site(&d.est, &d.params, &d.site, &d.ws);
        if (rc != SF_OK) {
            fprintf(stderr, "stridefixd: %s: the site cannot be used: %s\n", d.opt.site_path, sf_strerror(rc));
            close_input(&d);
            (void)sf_lcm_out_close(d.out, NULL);
            return EXIT_USAGE;
        }
    }
    d.last_pose_t_us = INT64_MIN / 2;
    const double t0 = monotonic_us();
    int status = run(&d);
    sf_can_input_close(&d.in);
    sf_lcm_out_counters_t oc;
    if (sf_lcm_out_close(d.out, &oc) != SF_OK) {
        fprintf(stderr, "stridefixd: %s: writing the log failed\n", d.log_path);
        status = 1;
    }
    summary(&d, &oc, (monotonic_us() - t0) * 1e-6);
    sf_site_store_free(&d.site_store);
    free(d.ws_memory);
    return status;
}
