/* sf_options.h — stridefixd's command line: the options, --help, and the effective parameters
 * (defaults, then each --config file, then each --set, then --fusion). --help, --version and
 * --print-config [--json] print and exit 0 from here. */
#ifndef SF_OPTIONS_H
#define SF_OPTIONS_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_channels.h"
#include "sf_pace.h"
#include "sf_params.h"

#define SF_OPTIONS_MAX_SETS 64
/* --speed's range: slower than a thousandth of real time or faster than a million times it is a typo
 * (a 5-minute walk would take 3.5 days, or 0.3 ms). */
#define SF_OPTIONS_SPEED_MIN 0.001
#define SF_OPTIONS_SPEED_MAX 1e6
#define SF_OPTIONS_PATH_MAX 4096 /* a path option's length limit (PATH_MAX): refused, never cut short */

/* One bit per LCM channel of SF_CHANNELS (sf_channels.h, from lcmtypes/channels.csv): --channels. */
enum {
#define SF_OPTIONS_CHANNEL_BIT(name, type) sf_options_channel_##name,
    SF_CHANNELS(SF_OPTIONS_CHANNEL_BIT)
#undef SF_OPTIONS_CHANNEL_BIT
        sf_options_channel_count
};
_Static_assert(sf_options_channel_count <= 32, "one bit of sf_options_t.channels per channel");
/* Whether --channels lets channel NAME (of SF_CHANNELS) into the outputs of options *o. */
#define SF_OPTIONS_WRITES(o, NAME) ((((o)->channels >> sf_options_channel_##NAME) & 1u) != 0)

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
    uint32_t channels; /* --channels: bit sf_options_channel_<NAME> set = that channel is written */
    sf_pace_t pace;    /* --speed X: the replay published at X times its recorded pace (sf_pace.h); off
                        * without it (as fast as possible) */
} sf_options_t;

/* 0 to run, or the exit status (SF_EXIT_USAGE, with a message on stderr). */
int sf_options_parse(int argc, char **argv, const char *version, const char *dbc_sha256, sf_options_t *o,
                     sf_params_t *params);

/* Whether --channels lets `channel` through (every channel without the option; NULL: true). */
bool sf_options_channel_on(const sf_options_t *o, const char *channel);

#endif
