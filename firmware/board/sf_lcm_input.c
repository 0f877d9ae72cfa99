/* sf_lcm_input.c — raw-sensor LCM log → sf_rx_event_t (see sf_lcm_input.h); the events come from the
 * strict reader of sf_eventlog.c, the per-channel decode is the kind table of sf_rx_lcm.c, the same
 * one the daemon logs inputs with. */
#define _POSIX_C_SOURCE 200809L /* fileno */
#include "sf_lcm_input.h"

#include <errno.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>

#include "sf_error.h"
#include "sf_eventlog.h"
#include "sf_file_kind.h"
#include "sf_rx_lcm.h"

struct sf_lcm_input {
    FILE *f;
    sf_eventlog_t log;
    sf_lcm_input_counters_t counters;
    char name[256];
    char error[512];
};

int sf_lcm_input_open_stream(sf_lcm_input_t **const result, FILE *const f, const char *const name,
                             char *const err, const size_t err_size)
{
    sf_lcm_input_t *const in = calloc(1, sizeof *in);
    if (in == NULL) {
        snprintf(err, err_size, "out of memory");
        fclose(f);
        return SF_EIO;
    }
    in->f = f;
    snprintf(in->name, sizeof in->name, "%s", name);
    sf_eventlog_init(&in->log, f, in->name);
    *result = in;
    return SF_OK;
}

int sf_lcm_input_open(sf_lcm_input_t **const result, const char *const path, char *const err, const size_t err_size)
{
    const int kind_rc = sf_file_check(path, "LCM log", true, err, err_size);
    if (kind_rc != SF_OK) {
        return kind_rc;
    }
    FILE *const f = fopen(path, "rb");
    if (f == NULL) {
        const int e = errno;
        snprintf(err, err_size, "%s: cannot open: %s", path, strerror(e));
        return e == ENOENT ? SF_ENOENT : SF_EIO;
    }
    return sf_lcm_input_open_stream(result, f, path, err, err_size);
}

bool sf_lcm_input_is_regular(const sf_lcm_input_t *const in)
{
    return sf_file_is_regular(fileno(in->f));
}

/* A bad event: counted, its message kept; the code the caller sees. */
static int bad(sf_lcm_input_t *const in, const int rc)
{
    sf_lcm_input_counters_t *const c = &in->counters;
    c->decode_errors++;
    c->oversized += rc == SF_ERANGE;
    c->truncated += rc == SF_ELENGTH;
    c->refused += rc == SF_ECORRUPT;
    return rc == SF_ECORRUPT ? rc : SF_ESYNTAX;
}

int sf_lcm_input_next(sf_lcm_input_t *const in, sf_rx_event_t *const ev, int64_t *const log_t_us)
{
    for (;;) {
        sf_eventlog_event_t e;
        const int r = sf_eventlog_next(&in->log, &e, in->error, sizeof in->error);
        if (r == 0) {
            return 0;
        }
        if (r == SF_EIO) {
            return SF_EIO;
        }
        in->counters.events++;
        if (r < 0) {
            return bad(in, r);
        }
        /* the message names the channel ("WIFI: payload: ..."); the log, event and offset are added on
         * failure only (a snprintf per good event would double the replay's time) */
        char what[400];
        const int rc = sf_rx_lcm_decode(e.channel, e.data, e.data_size, ev, NULL, what, sizeof what);
        *log_t_us = e.timestamp_us;
        if (rc == 1) {
            in->counters.used++;
            return 1;
        }
        if (rc < 0) {
            snprintf(in->error, sizeof in->error, "%s: event %" PRId64 " at offset %" PRIu64 " (%s)%s", in->name,
                     e.number, e.offset, e.channel, what + strlen(e.channel));
            return bad(in, rc);
        }
        in->counters.other_channels++;
    }
}

const char *sf_lcm_input_error(const sf_lcm_input_t *const in)
{
    return in->error;
}

void sf_lcm_input_counters(const sf_lcm_input_t *const in, sf_lcm_input_counters_t *const counters)
{
    *counters = in->counters;
}

void sf_lcm_input_close(sf_lcm_input_t *const in)
{
    if (in != NULL) {
        sf_eventlog_close(&in->log);
        fclose(in->f);
        free(in);
    }
}
