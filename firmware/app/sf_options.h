/* sf_options.h — stridefixd's command line: the options, --help, and the effective parameters
 * (defaults, then each --config file, then each --set, then --fusion). --help, --version and
 * --print-config [--json] print and exit 0 from here. */
#ifndef SF_OPTIONS_H
#define SF_OPTIONS_H

#include <stdbool.h>

#include "sf_params.h"

#define SF_OPTIONS_MAX_SETS 64
#define SF_EXIT_USAGE 2 /* bad usage, or an input or config that cannot be read */

typedef struct {
    const char *input;
    const char *log_path;
    const char *log_dir;
    bool no_log;
    const char *lcm_url;
    const char *site_path;
    const char *fusion;
    char replay_spec[4096];
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
