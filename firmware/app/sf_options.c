/* sf_options.c — getopt_long over stridefixd's options (see sf_options.h). */
#include "sf_options.h"

#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sf_config.h"
#include "sf_config_print.h"
#include "sf_error.h"
#include "sf_fusion.h"
#include "sf_input.h"

/* The name of a pose_t.SCHEME_* id: a fusion scheme's, or the controller's (not a fusion scheme). */
static const char *pose_scheme_name(const int s)
{
    return s == sf_scheme_controller ? SF_SCHEME_CONTROLLER_NAME : sf_fusion_scheme_name(s);
}

/* The scheme names of pose_t.SCHEME_*, as "a, b, ... or z". */
static void scheme_list(FILE *const f, const char *const last_sep)
{
    for (int s = 0; s <= sf_scheme_controller; s++) {
        fprintf(f, "%s%s", s == 0 ? "" : s == sf_scheme_controller ? last_sep : ", ", pose_scheme_name(s));
    }
}

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
            "      --replay FILE      same as --input lcmlog:FILE: replay a raw-sensor log\n"
            "      --speed X          publish a file or stdin input at X times the pace it was recorded at, by\n"
            "                         its timestamps from the first one (1 = real time, 20 = a 5-minute walk\n"
            "                         in 15 s), e.g. for a live view; X in [%g, %g]. The log is the same\n"
            "                         as without it (default: as fast as possible)\n"
            "Outputs\n"
            "  -l, --log FILE         LCM event log to write (default:\n"
            "                         DIR/stridefixd-YYYYmmdd-HHMMSS-MICROS-PID.lcmlog, UTC); written as\n"
            "                         FILE.part and renamed to FILE when closed; rotated files are\n"
            "                         FILE.001.lcmlog, ... (output.log_rotate_mb, output.log_rotate_s, SIGHUP)\n"
            "  -d, --log-dir DIR      directory for the default log name (default: .)\n"
            "      --force            replace an existing log file (never through a symlink); without it an\n"
            "                         existing FILE or FILE.part is refused (exit 1)\n"
            "      --no-log           write no log (live publishing only; not with --log, --log-dir)\n"
            "      --channels LIST    write only these channels (log and live LCM), comma-separated, e.g.\n"
            "                         FIX,POSE_ADAPTIVE (a replay scored on them alone: less to write and to\n"
            "                         read back); the estimator runs the same (default: every channel)\n"
            "  -u, --lcm-url URL      also publish live to this LCM URL (default: none, nothing leaves the\n"
            "                         process), e.g. udpm://239.255.76.67:7667?ttl=0 (ttl=0: this host only)\n"
            "Privilege\n"
            "      --allow-root       read a live input (socketcan:) as root; refused without it\n"
            "Site\n"
            "      --site FILE        site file (floors, map rotation, radio map) from `stridefix radiomap build`:\n"
            "                         enables Wi-Fi fixes and the fusion schemes; without it PDR starts at\n"
            "                         the config pose (init.*)\n"
            "      --fusion MODE      publish one scheme's POSE and FIX, or all (default: every scheme side by\n"
            "                         side, one log compares them all). Same as --set output.scheme=N.\n"
            "                         Schemes (pose_t.SCHEME_*): ",
            SF_OPTIONS_SPEED_MIN, SF_OPTIONS_SPEED_MAX);
    scheme_list(f, ", ");
    fprintf(f,
            "\n"
            "Configuration\n"
            "  -c, --config FILE      INI file of [section] key = value (every key: --print-config);\n"
            "                         repeatable, later files override earlier ones\n"
            "  -s, --set KEY=VALUE    override one key, e.g. --set stride.weinberg_k=0.5 (repeatable)\n"
            "      --print-config     print every key with its default, range, unit and meaning (INI that\n"
            "                         --config reads back); exit\n"
            "      --json             with --print-config: the parameter table and the schemes as JSON\n"
            "Messages\n"
            "  -q, --quiet            no per-line bad-input messages (counts still in HEALTH and the summary)\n"
            "      --max-messages N   print at most N bad-input messages (default 20)\n"
            "      --batch FILE       (alone) one replay per line of FILE, its options TAB-separated, each run as\n"
            "                         its own; a site file is read once for them all; exit statuses on stdout\n"
            "  -h, --help             this text\n"
            "  -V, --version          version and the DBC it was built from\n"
            "\n"
            "Channels written: IMU MAG BARO WIFI GNSS (inputs), STEP, POSE_<SCHEME> (each fusion\n"
            "scheme's pose: POSE_PDR_ONLY ... POSE_PARTICLE), POSE (the primary pose: the multi-scheme\n"
            "controller's, scheme 8; without an active controller a copy of the --fusion scheme's, else\n"
            "of controller.init_scheme's, else pdr_only's), FIX (with a site: every scheme's verdict on\n"
            "every Wi-Fi fix), HEALTH (every output.health_period_ms of board time, and at exit), CONFIG\n"
            "(first in every log file), CONTEXT (with a site's context map: every change of the\n"
            "multi-scheme controller).\n"
            "Log durability: the writer fdatasyncs every output.fsync_interval_ms (default 1000); on a full\n"
            "disk events are dropped and counted (events and bytes, in HEALTH and the summary), the reason\n"
            "is printed once, and logging resumes when space returns.\n"
            "Signals: SIGTERM, SIGINT stop reading, write a last HEALTH, close and rename the log, print\n"
            "the summary and exit as if the input had ended; SIGHUP closes the log file and starts the next.\n"
            "\n"
            "Exit status (the same for every `stridefix` command):\n"
            "  0  the input was read and held valid frames (bad ones are counted and skipped, not fatal);\n"
            "     also when stopped by SIGTERM or SIGINT\n"
            "  1  a failure while running: the log could not be created, lost events to a failed write\n"
            "     (disk full) or could not be renamed, or reading the input failed\n"
            "  2  bad usage (also a live input as root without --allow-root), or an input, config or site\n"
            "     that cannot be read (missing, or a directory or device where a file is expected)\n"
            "  3  nothing valid in the input: read to its end without one valid frame or sensor event\n");
}

/* A whole-string integer in [min, max] (strtol with the end checked): 0, or SF_EXIT_USAGE with a
 * message naming the option. */
static int parse_long(const char *const option, const char *const text, const long min, const long max,
                      long *const value)
{
    char *end = NULL;
    errno = 0;
    const long v = strtol(text, &end, 10);
    if (end == text || *end != '\0' || errno != 0 || v < min || v > max) {
        fprintf(stderr, "stridefixd: %s '%s': expected an integer in [%ld, %ld]\n", option, text, min, max);
        return SF_EXIT_USAGE;
    }
    *value = v;
    return 0;
}

/* A whole-string finite number in [min, max] (strtod with the end checked): 0, or SF_EXIT_USAGE with
 * a message naming the option. */
static int parse_double(const char *const option, const char *const text, const double min, const double max,
                        double *const value)
{
    char *end = NULL;
    errno = 0;
    const double v = strtod(text, &end);
    if (end == text || *end != '\0' || errno != 0 || !isfinite(v) || v < min || v > max) {
        fprintf(stderr, "stridefixd: %s '%s': expected a number in [%g, %g]\n", option, text, min, max);
        return SF_EXIT_USAGE;
    }
    *value = v;
    return 0;
}

static const char *const channel_names[sf_options_channel_count] = {
#define CHANNEL_NAME(name, type) SF_CHANNEL_##name,
    SF_CHANNELS(CHANNEL_NAME)
#undef CHANNEL_NAME
};

static int channel_index(const char *const name, const size_t len)
{
    for (int i = 0; i < sf_options_channel_count; i++) {
        if (strlen(channel_names[i]) == len && strncmp(channel_names[i], name, len) == 0) {
            return i;
        }
    }
    return -1;
}

bool sf_options_channel_on(const sf_options_t *const o, const char *const channel)
{
    if (channel == NULL) {
        return true;
    }
    const int i = channel_index(channel, strlen(channel));
    return i < 0 || (o->channels >> i & 1u) != 0;
}

/* --channels A,B,...: the bits of the named channels; 0, or SF_EXIT_USAGE naming an unknown one. */
static int parse_channels(const char *const text, uint32_t *const bits)
{
    *bits = 0;
    const char *p = text;
    for (;;) {
        const size_t len = strcspn(p, ",");
        const int i = channel_index(p, len);
        if (i < 0) {
            fprintf(stderr, "stridefixd: --channels: unknown channel '%.*s'; expected one of", (int)len, p);
            for (int k = 0; k < sf_options_channel_count; k++) {
                fprintf(stderr, " %s", channel_names[k]);
            }
            fprintf(stderr, "\n");
            return SF_EXIT_USAGE;
        }
        *bits |= 1u << i;
        if (p[len] == '\0') {
            return 0;
        }
        p += len + 1;
    }
}

/* A path option that fits the daemon's buffers (room_left: what the daemon appends to it). */
static int check_path(const char *const option, const char *const path, const size_t room_left)
{
    if (strlen(path) + room_left >= SF_OPTIONS_PATH_MAX) {
        fprintf(stderr, "stridefixd: %s: a path of %zu characters is longer than the %d this accepts\n", option,
                strlen(path), SF_OPTIONS_PATH_MAX - 1 - (int)room_left);
        return SF_EXIT_USAGE;
    }
    return 0;
}

/* Every path option checked against SF_OPTIONS_PATH_MAX. */
static int check_paths(const sf_options_t *const o)
{
    int rc = 0;
    if (o->input != NULL && o->input != o->replay_spec) {
        rc |= check_path("--input", o->input, 0);
    }
    if (o->log_path != NULL) {
        rc |= check_path("--log", o->log_path, 0);
    }
    rc |= check_path("--log-dir", o->log_dir, 64); /* "/" and the default file name */
    if (o->site_path != NULL) {
        rc |= check_path("--site", o->site_path, 0);
    }
    for (int i = 0; i < o->n_configs; i++) {
        rc |= check_path("--config", o->config_paths[i], 0);
    }
    return rc != 0 ? SF_EXIT_USAGE : 0;
}

/* Applies --config files, --set overrides and --fusion on top of the defaults. */
static int effective_params(const sf_options_t *const o, sf_params_t *const params)
{
    sf_params_default(params);
    char err[512];
    for (int i = 0; i < o->n_configs; i++) {
        if (sf_config_load(o->config_paths[i], params, err, sizeof err) != SF_OK) {
            fprintf(stderr, "stridefixd: %s\n", err);
            return SF_EXIT_USAGE;
        }
    }
    for (int i = 0; i < o->n_sets; i++) {
        if (sf_config_set(o->sets[i], params, err, sizeof err) != SF_OK) {
            fprintf(stderr, "stridefixd: %s\n", err);
            return SF_EXIT_USAGE;
        }
    }
    if (o->fusion != NULL) {
        const int code = strcmp(o->fusion, "all") == 0                      ? -1
                         : strcmp(o->fusion, SF_SCHEME_CONTROLLER_NAME) == 0 ? sf_scheme_controller
                                                                             : sf_fusion_scheme_from_name(o->fusion);
        if (code == SF_EINVAL) {
            fprintf(stderr, "stridefixd: --fusion %s: expected all, ", o->fusion);
            scheme_list(stderr, " or ");
            fprintf(stderr, "\n");
            return SF_EXIT_USAGE;
        }
        params->output_scheme = code;
    }
    return 0;
}

int sf_options_parse(const int argc, char **const argv, const char *const version, const char *const dbc_sha256,
                     sf_options_t *const o, sf_params_t *const params)
{
    enum {
        opt_no_log = 1000,
        opt_print_config,
        opt_max_messages,
        opt_site,
        opt_fusion,
        opt_replay,
        opt_json,
        opt_force,
        opt_allow_root,
        opt_channels,
        opt_speed
    };
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
        {"json", no_argument, NULL, opt_json},
        {"force", no_argument, NULL, opt_force},
        {"allow-root", no_argument, NULL, opt_allow_root},
        {"channels", required_argument, NULL, opt_channels},
        {"speed", required_argument, NULL, opt_speed},
        {NULL, 0, NULL, 0}};
    *o = (sf_options_t){.log_dir = ".", .max_messages = 20, .channels = UINT32_MAX};
    optind = 0; /* getopt_long starts over (GNU: 0 also resets its internal state): parse is re-entrant */
    bool want_print_config = false;
    bool want_json = false;
    bool log_dir_given = false;
    int c;
    while ((c = getopt_long(argc, argv, "i:l:d:u:c:s:qhV", longs, NULL)) != -1) {
        switch (c) {
        case 'i': o->input = optarg; break;
        case 'l': o->log_path = optarg; break;
        case 'd':
            o->log_dir = optarg;
            log_dir_given = true;
            break;
        case opt_no_log: o->no_log = true; break;
        case 'u': o->lcm_url = optarg; break;
        case opt_site: o->site_path = optarg; break;
        case opt_fusion: o->fusion = optarg; break;
        case opt_replay: /* the raw-sensor log replay, spelled as the issue asked for it */
            if (check_path("--replay", optarg, strlen(SF_INPUT_LCMLOG_PREFIX)) != 0) {
                return SF_EXIT_USAGE;
            }
            snprintf(o->replay_spec, sizeof o->replay_spec, "%s%s", SF_INPUT_LCMLOG_PREFIX, optarg);
            o->input = o->replay_spec;
            break;
        case 'c':
            if (o->n_configs == SF_OPTIONS_MAX_SETS) {
                fprintf(stderr, "stridefixd: at most %d --config options\n", SF_OPTIONS_MAX_SETS);
                return SF_EXIT_USAGE;
            }
            o->config_paths[o->n_configs++] = optarg;
            break;
        case 's':
            if (o->n_sets == SF_OPTIONS_MAX_SETS) {
                fprintf(stderr, "stridefixd: at most %d --set options\n", SF_OPTIONS_MAX_SETS);
                return SF_EXIT_USAGE;
            }
            o->sets[o->n_sets++] = optarg;
            break;
        case opt_print_config: want_print_config = true; break;
        case opt_json: want_json = true; break;
        case opt_force: o->force = true; break;
        case opt_allow_root: o->allow_root = true; break;
        case opt_channels:
            if (parse_channels(optarg, &o->channels) != 0) {
                return SF_EXIT_USAGE;
            }
            break;
        case opt_speed: {
            double speed = 0.0;
            if (parse_double("--speed", optarg, SF_OPTIONS_SPEED_MIN, SF_OPTIONS_SPEED_MAX, &speed) != 0) {
                return SF_EXIT_USAGE;
            }
            sf_pace_init(&o->pace, speed);
            break;
        }
        case 'q': o->quiet = true; break;
        case opt_max_messages:
            if (parse_long("--max-messages", optarg, 0, LONG_MAX, &o->max_messages) != 0) {
                return SF_EXIT_USAGE;
            }
            break;
        case 'h': usage(stdout); exit(0);
        case 'V': printf("stridefixd %s (board.dbc sha256 %s)\n", version, dbc_sha256); exit(0);
        default: usage(stderr); return SF_EXIT_USAGE;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "stridefixd: unexpected argument '%s' (see --help)\n", argv[optind]);
        return SF_EXIT_USAGE;
    }
    if (check_paths(o) != 0) {
        return SF_EXIT_USAGE;
    }
    if (o->no_log && (o->log_path != NULL || log_dir_given)) { /* which one was meant cannot be guessed */
        fprintf(stderr, "stridefixd: --no-log contradicts %s (see --help)\n",
                o->log_path != NULL ? "--log" : "--log-dir");
        return SF_EXIT_USAGE;
    }
    if (want_json && !want_print_config) {
        fprintf(stderr, "stridefixd: --json goes with --print-config (see --help)\n");
        return SF_EXIT_USAGE;
    }
    const int prc = effective_params(o, params);
    if (prc != 0) {
        return prc;
    }
    if (want_print_config) {
        (want_json ? sf_config_print_json : sf_config_print_ini)(stdout, params);
        exit(0);
    }
    if (o->input == NULL) {
        fprintf(stderr, "stridefixd: --input is required (see --help)\n");
        return SF_EXIT_USAGE;
    }
    if (sf_pace_on(&o->pace) && sf_input_spec_is_live(o->input)) {
        fprintf(stderr, "stridefixd: --speed: %s is live, already at its own pace (--speed paces a file or stdin)\n",
                o->input);
        return SF_EXIT_USAGE;
    }
    return 0;
}
