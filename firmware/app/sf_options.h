/* sf_options.h — stridefixd's command line: the options, --help, and the effective parameters
 * (defaults, then each --config file, then each --set, then --fusion). --help, --version and
 * --print-config [--json] print and exit 0 from here. */
#ifndef SF_OPTIONS_H
#define SF_OPTIONS_H

#include <stdbool.h>

#include "sf_params.h"

#define SF_OPTIONS_MAX_SETS 64
#define SF_OPTIONS_PATH_MAX 4096 /* a path option's length limit (PATH_MAX): refused, never cut short */

/* The exit-status contract, the same for stridefixd and every `stridefix` command (README "Exit
 * status"; the Python side is stridefix_analyzer/exits.py, a test keeps the two equal). */
#define SF_EXIT_OK 0            /* the input was read and held valid records (bad ones are counted) */
#define SF_EXIT_FAILURE 1       /* a failure while running: the log could not be written, a read error */
#define SF_EXIT_USAGE 2         /* bad usage, or an input or config that cannot be read */
#define SF_EXIT_NOTHING_VALID 3 /* the input was read but held not one valid record */

typedef struct {
    const char *input;
    const char *log_path;
    const char *log_dir;
    bool no_log;
    const char *lcm_url;
    const char *site_path;
    const char *fusion;
    char replay_spec[SF_OPTIONS_PATH_MAX];
    const char *config_paths[SF_OPTIONS_MAX_SETS];
    int n_configs;
    const char *sets[SF_OPTIONS_MAX_SETS];
    int n_sets;
    bool quiet;
    long max_messages;
    bool force;      /* --force: an existing log file may be replaced */
    bool allow_root; /* --allow-root: a live input as root */
} sf_options_t;

/* 0 to run, or the exit status (SF_EXIT_USAGE, with a message on stderr). */
int sf_options_parse(int argc, char **argv, const char *version, const char *dbc_sha256, sf_options_t *o,
                     sf_params_t *params);

#endif
