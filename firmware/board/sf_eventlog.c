/* sf_eventlog.c — strict LCM event-log reader (see sf_eventlog.h for the format and the checks). */
#include "sf_eventlog.h"

#include <errno.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>

#include "sf_error.h"
#include "sf_lcm_walk.h"

void sf_eventlog_init(sf_eventlog_t *const log, FILE *const f, const char *const name)
{
    memset(log, 0, sizeof *log);
    log->f = f;
    log->name = name;
}

void sf_eventlog_close(sf_eventlog_t *const log)
{
    free(log->data);
    log->data = NULL;
    log->data_cap = 0;
}

static int64_t be64(const uint8_t *const p)
{
    const uint64_t hi = (uint32_t)sf_lcm_be32(p);
    const uint64_t lo = (uint32_t)sf_lcm_be32(p + 4);
    return (int64_t)((hi << 32) | lo);
}

#define NUMBER_UNREAD INT64_MIN /* ev->number before the header is read whole */

/* "<name>: event N at offset X: <what>" ("<name>: at offset X: <what>" in a cut-off header); ends
 * the log unless rc only skips an event. */
static int fail(sf_eventlog_t *const log, const sf_eventlog_event_t *const ev, const int rc, char *const err,
                const size_t err_size, const char *const what)
{
    char where[300];
    if (ev->number == NUMBER_UNREAD) {
        snprintf(where, sizeof where, "%s: at offset %" PRIu64, log->name, ev->offset);
    } else {
        snprintf(where, sizeof where, "%s: event %" PRId64 " at offset %" PRIu64, log->name, ev->number, ev->offset);
    }
    if (rc != SF_ERANGE && rc != SF_ESYNTAX) {
        log->done = 1;
    }
    return sf_lcm_failf(err, err_size, where, rc, "%s", what);
}

/* Reads exactly n bytes into buf: SF_OK, SF_ELENGTH (end of file first) or SF_EIO. */
static int read_exact(sf_eventlog_t *const log, uint8_t *const buf, const size_t n)
{
    if (n == 0) {
        return SF_OK; /* buf may be NULL (an empty event before any data buffer) */
    }
    const size_t got = fread(buf, 1, n, log->f);
    log->offset += got;
    if (got < n) {
        return ferror(log->f) ? SF_EIO : SF_ELENGTH;
    }
    return SF_OK;
}

/* Reads and drops n bytes (an oversized event's data, never held whole): as read_exact. */
static int discard(sf_eventlog_t *const log, size_t n)
{
    uint8_t sink[4096] = {0};
    while (n > 0) {
        const size_t chunk = n < sizeof sink ? n : sizeof sink;
        const int rc = read_exact(log, sink, chunk);
        if (rc != SF_OK) {
            return rc;
        }
        n -= chunk;
    }
    return SF_OK;
}

static int short_read(sf_eventlog_t *const log, const sf_eventlog_event_t *const ev, const int rc,
                      const char *const part, char *const err, const size_t err_size)
{
    char what[200];
    if (rc == SF_EIO) {
        snprintf(what, sizeof what, "read failed in the %s: %s", part, strerror(errno));
    } else {
        snprintf(what, sizeof what, "log ends inside the %s (truncated last event, %" PRIu64 " bytes after its start)",
                 part, log->offset - ev->offset);
    }
    return fail(log, ev, rc, err, err_size, what);
}

int sf_eventlog_next(sf_eventlog_t *const log, sf_eventlog_event_t *const ev, char *const err, const size_t err_size)
{
    memset(ev, 0, sizeof *ev);
    if (log->done) {
        return 0;
    }
    ev->offset = log->offset;
    ev->number = NUMBER_UNREAD;
    uint8_t h[SF_EVENTLOG_HEADER_SIZE];
    const size_t got = fread(h, 1, 1, log->f);
    log->offset += got;
    if (got == 0) {
        log->done = 1;
        return ferror(log->f) ? short_read(log, ev, SF_EIO, "header", err, err_size) : 0;
    }
    int rc = read_exact(log, h + 1, sizeof h - 1);
    if (rc != SF_OK) {
        return short_read(log, ev, rc, "header", err, err_size);
    }
    const uint32_t magic = (uint32_t)sf_lcm_be32(h);
    ev->number = be64(h + 4);
    ev->timestamp_us = be64(h + 12);
    const int32_t channel_len = sf_lcm_be32(h + 20);
    const int32_t data_len = sf_lcm_be32(h + 24);
    char what[200];
    if (magic != SF_EVENTLOG_MAGIC) {
        snprintf(what, sizeof what, "bad magic 0x%08" PRIX32 ", expected 0x%08X: the rest of the log is refused",
                 magic, SF_EVENTLOG_MAGIC);
        return fail(log, ev, SF_ECORRUPT, err, err_size, what);
    }
    if (channel_len < 1 || channel_len > SF_EVENTLOG_MAX_CHANNEL) {
        snprintf(what, sizeof what, "channel length %" PRId32 " outside 1..%d: the rest of the log is refused",
                 channel_len, SF_EVENTLOG_MAX_CHANNEL);
        return fail(log, ev, SF_ECORRUPT, err, err_size, what);
    }
    if (data_len < 0) {
        snprintf(what, sizeof what, "negative data length %" PRId32 ": the rest of the log is refused", data_len);
        return fail(log, ev, SF_ECORRUPT, err, err_size, what);
    }
    rc = read_exact(log, (uint8_t *)log->channel, (size_t)channel_len);
    if (rc != SF_OK) {
        return short_read(log, ev, rc, "channel", err, err_size);
    }
    log->channel[channel_len] = '\0';
    const size_t size = (size_t)data_len;
    if (size > SF_EVENTLOG_MAX_DATA_BYTES) {
        rc = discard(log, size);
        if (rc != SF_OK) {
            return short_read(log, ev, rc, "data", err, err_size);
        }
        snprintf(what, sizeof what, "data length %zu exceeds the limit of %u bytes; skipped", size,
                 SF_EVENTLOG_MAX_DATA_BYTES);
        return fail(log, ev, SF_ERANGE, err, err_size, what);
    }
    if (size > log->data_cap) {
        size_t cap = log->data_cap > 0 ? log->data_cap : 4096u;
        while (cap < size) {
            cap *= 2u;
        }
        uint8_t *const bigger = realloc(log->data, cap);
        if (bigger == NULL) {
            errno = ENOMEM;
            return short_read(log, ev, SF_EIO, "data", err, err_size);
        }
        log->data = bigger;
        log->data_cap = cap;
    }
    rc = read_exact(log, log->data, size);
    if (rc != SF_OK) {
        return short_read(log, ev, rc, "data", err, err_size);
    }
    if (strlen(log->channel) != (size_t)channel_len) {
        return fail(log, ev, SF_ESYNTAX, err, err_size, "channel name holds a NUL byte; skipped");
    }
    ev->channel = log->channel;
    ev->data = log->data;
    ev->data_size = size;
    return 1;
}
