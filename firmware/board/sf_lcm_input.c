/* sf_lcm_input.c — raw-sensor LCM log → sf_rx_event_t (see sf_lcm_input.h); the per-channel decode
 * is the kind table of sf_rx_lcm.c, the same one the daemon logs inputs with. */
#include "sf_lcm_input.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <lcm/eventlog.h>

#include "sf_error.h"
#include "sf_file_kind.h"
#include "sf_rx_lcm.h"

struct sf_lcm_input {
    lcm_eventlog_t *log;
    sf_lcm_input_counters_t counters;
};

int sf_lcm_input_open(sf_lcm_input_t **const result, const char *const path, char *const err, const size_t err_size)
{
    sf_lcm_input_t *const in = calloc(1, sizeof *in);
    if (in == NULL) {
        snprintf(err, err_size, "out of memory");
        return SF_EIO;
    }
    const int kind_rc = sf_file_check(path, "LCM log", true, err, err_size);
    if (kind_rc != SF_OK) {
        free(in);
        return kind_rc;
    }
    FILE *const probe = fopen(path, "rb");
    if (probe == NULL) {
        const int e = errno;
        snprintf(err, err_size, "%s: cannot open: %s", path, strerror(e));
        free(in);
        return e == ENOENT ? SF_ENOENT : SF_EIO;
    }
    fclose(probe);
    in->log = lcm_eventlog_create(path, "r");
    if (in->log == NULL) {
        snprintf(err, err_size, "%s: cannot open as an LCM log", path);
        free(in);
        return SF_EIO;
    }
    *result = in;
    return SF_OK;
}

int sf_lcm_input_next(sf_lcm_input_t *const in, sf_rx_event_t *const ev, int64_t *const log_t_us)
{
    for (;;) {
        lcm_eventlog_event_t *const e = lcm_eventlog_read_next_event(in->log);
        if (e == NULL) {
            return 0;
        }
        in->counters.events++;
        const int rc = e->datalen < 0 ? SF_ESYNTAX : sf_rx_lcm_decode(e->channel, e->data, (size_t)e->datalen, ev);
        *log_t_us = e->timestamp;
        lcm_eventlog_free_event(e);
        if (rc == 1) {
            in->counters.used++;
            return 1;
        }
        if (rc < 0) {
            in->counters.decode_errors++;
            return SF_ESYNTAX;
        }
        in->counters.other_channels++;
    }
}

void sf_lcm_input_counters(const sf_lcm_input_t *const in, sf_lcm_input_counters_t *const counters)
{
    *counters = in->counters;
}

void sf_lcm_input_close(sf_lcm_input_t *const in)
{
    if (in != NULL) {
        lcm_eventlog_destroy(in->log);
        free(in);
    }
}
