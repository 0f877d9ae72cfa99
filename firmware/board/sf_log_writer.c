/* sf_log_writer.c — log files over runs of laid-out events: one write per plain run, the rules per
 * event where one applies (see sf_log_writer.h). */
#define _GNU_SOURCE
#include "sf_log_writer.h"

#include <errno.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/statvfs.h>
#include <time.h>

#include "sf_error.h"
#include "sf_log_ring.h"

#define MAX_NAME_ATTEMPTS 1000

static int64_t monotonic_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static void report(const sf_log_writer_t *const w, const char *const fmt, ...)
{
    if (w->cfg->report == NULL) {
        return;
    }
    va_list ap;
    va_start(ap, fmt);
    fprintf(w->cfg->report, "stridefixd: ");
    vfprintf(w->cfg->report, fmt, ap);
    fprintf(w->cfg->report, "\n");
    va_end(ap);
}

/* n events of `bytes` log bytes in all: written, or dropped. */
static void count(sf_log_writer_t *const w, const bool written, const uint64_t n, const uint64_t bytes)
{
    pthread_mutex_lock(&w->lock);
    if (written) {
        w->counters.events += n;
        w->counters.bytes += bytes;
    } else {
        w->counters.drops += n;
        w->counters.drop_bytes += bytes;
        w->write_failed = true;
    }
    pthread_mutex_unlock(&w->lock);
}

/* Tells the start and the end of a failure episode, once each. */
static void episode(sf_log_writer_t *const w, const bool ok, const int err_no)
{
    if (!ok && !w->failing) {
        w->failing = true;
        w->fail_errno = err_no;
        report(w, "%s: writing the log failed: %s; events are dropped and counted until writes succeed again",
               w->file.fd >= 0 ? w->file.part_path : w->first_path, strerror(err_no));
    } else if (ok && w->failing) {
        w->failing = false;
        sf_lcm_out_counters_t c;
        sf_log_writer_counters(w, &c);
        report(w, "%s: logging resumed (%llu events, %llu bytes dropped so far)", w->file.part_path,
               (unsigned long long)c.drops, (unsigned long long)c.drop_bytes);
    }
}

static void close_file(sf_log_writer_t *const w)
{
    char err[2 * SF_LOG_FILE_PATH_MAX + 128];
    w->file_has_header = false;
    if (w->file.fd >= 0 && w->file.offset == 0 && w->write_failed) { /* every write failed: no empty log */
        report(w, "%s: nothing could be written; no log file left", w->file.path);
        sf_log_file_discard(&w->file);
        w->unsynced = false;
        return;
    }
    if (sf_log_file_close(&w->file, err, sizeof err) != SF_OK) {
        report(w, "%s", err);
        pthread_mutex_lock(&w->lock);
        w->write_failed = true;
        pthread_mutex_unlock(&w->lock);
    }
    w->unsynced = false;
}

/* A copy of the header written (w->lock held): an event and its bytes, counted as a copy. */
static void count_header_copy(sf_log_writer_t *const w)
{
    w->counters.events++;
    w->counters.header_copies++;
    w->counters.bytes += SF_LOG_FILE_EVENT_OVERHEAD + strlen(w->header_channel) + w->header_size;
}

/* Opens the next rotated file (skipping names that exist) and writes the header copy into it,
 * stamped timestamp_us. On failure no file is open and errno tells why. */
static int open_next(sf_log_writer_t *const w, const int64_t timestamp_us)
{
    char path[SF_LOG_FILE_PATH_MAX];
    char err[SF_LOG_FILE_PATH_MAX + 128];
    int rc = SF_EIO;
    unsigned index = w->file_index;
    for (int attempt = 0; attempt < MAX_NAME_ATTEMPTS; attempt++) {
        index++;
        if (sf_log_file_rotated_name(path, sizeof path, w->first_path, index) != SF_OK) {
            errno = ENAMETOOLONG;
            return SF_EIO;
        }
        rc = sf_log_file_open(&w->file, path, w->cfg->force, err, sizeof err);
        if (rc == SF_OK || errno != EEXIST) {
            break;
        }
    }
    if (rc != SF_OK) {
        return rc;
    }
    if (w->header_channel != NULL) {
        const int hrc = sf_log_file_write(&w->file, w->header_channel, timestamp_us, w->header_data,
                                          w->header_size);
        if (hrc != SF_OK) { /* a file without its header would not read alone: none at all */
            const int e = errno;
            sf_log_file_discard(&w->file);
            errno = e;
            return hrc;
        }
    }
    w->file_index = index;
    w->file_opened_us = monotonic_us();
    w->unsynced = true;
    w->file_has_header = w->header_channel != NULL;
    pthread_mutex_lock(&w->lock);
    w->counters.files++;
    if (w->header_channel != NULL) {
        count_header_copy(w);
    }
    pthread_mutex_unlock(&w->lock);
    return SF_OK;
}

/* The open file's missing header (dropped when it was due: a disk full from the start), stamped
 * timestamp_us, before the event that follows it: SF_OK (written, or no header to copy), else the
 * write's failure with errno. */
static int copy_missing_header(sf_log_writer_t *const w, const int64_t timestamp_us)
{
    if (w->file_has_header || w->header_channel == NULL) {
        return SF_OK;
    }
    const int rc = sf_log_file_write(&w->file, w->header_channel, timestamp_us, w->header_data, w->header_size);
    if (rc == SF_OK) {
        w->file_has_header = true;
        pthread_mutex_lock(&w->lock);
        count_header_copy(w);
        pthread_mutex_unlock(&w->lock);
    }
    return rc;
}

static uint32_t be32(const uint8_t *const p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static int64_t event_timestamp_us(const uint8_t *const e)
{
    return (int64_t)((uint64_t)be32(e + 12) << 32 | be32(e + 16));
}

/* Keeps a copy of a header event (laid out in the log format) for the files to come. */
static void keep_header(sf_log_writer_t *const w, const uint8_t *const e)
{
    const size_t channel_len = be32(e + 20);
    const size_t size = be32(e + 24);
    char *const channel = malloc(channel_len + 1);
    void *const data = malloc(size > 0 ? size : 1);
    if (channel == NULL || data == NULL) {
        free(channel);
        free(data);
        return; /* the old header (if any) stays */
    }
    memcpy(channel, e + SF_LOG_FILE_EVENT_OVERHEAD, channel_len);
    channel[channel_len] = '\0';
    memcpy(data, e + SF_LOG_FILE_EVENT_OVERHEAD + channel_len, size);
    free(w->header_channel);
    free(w->header_data);
    w->header_channel = channel;
    w->header_data = data;
    w->header_size = size;
}

/* A full disk is not free again because one small event fits its last page (tmpfs: 346 B did, inside
 * one episode): during an ENOSPC/EDQUOT episode writes resume only with 64 KiB free (or unknown). */
static bool room_again(const sf_log_writer_t *const w)
{
    struct statvfs st;
    if (!w->failing || (w->fail_errno != ENOSPC && w->fail_errno != EDQUOT) || w->file.fd < 0 ||
        fstatvfs(w->file.fd, &st) != 0) {
        return true;
    }
    return (uint64_t)st.f_bavail * (uint64_t)st.f_frsize >= 64u * 1024u;
}

/* Whether the file must be closed before `bytes` more (after `pending` already on their way to it). */
static bool rotation_due(const sf_log_writer_t *const w, const uint64_t pending, const uint64_t bytes)
{
    return w->file.fd >= 0 && w->cfg->rotate_bytes > 0 && w->file.offset + pending > 0 &&
           w->file.offset + pending + bytes > w->cfg->rotate_bytes;
}

/* One event on its own, every rule applied to it: a header is kept, the file rotated by size,
 * opened when none is, a failure counted and told. The event's bytes. */
static size_t write_one(sf_log_writer_t *const w, uint8_t *const e, const bool is_header)
{
    if (is_header) {
        keep_header(w, e);
    }
    const size_t bytes = sf_log_file_event_bytes(e);
    if (rotation_due(w, 0, bytes)) {
        close_file(w);
    }
    if (!room_again(w)) {
        count(w, false, 1, bytes); /* still full: dropped, counted, the episode goes on */
        return bytes;
    }
    int rc = w->file.fd >= 0 ? SF_OK : open_next(w, event_timestamp_us(e));
    if (rc == SF_OK && !is_header) {
        rc = copy_missing_header(w, event_timestamp_us(e));
    }
    if (rc == SF_OK) {
        rc = sf_log_file_append(&w->file, e, bytes, 1);
        w->file_has_header |= rc == SF_OK && is_header;
    }
    const int err_no = errno;
    count(w, rc == SF_OK, 1, bytes);
    episode(w, rc == SF_OK, err_no);
    w->unsynced |= rc == SF_OK;
    return bytes;
}

/* n events that need no rule between them (no header, no rotation, a file open and no episode):
 * one write, or — when it fails — each on its own, so that exactly the events that fit are written
 * and every other one is counted as before. */
static void write_run(sf_log_writer_t *const w, uint8_t *p, size_t len, uint64_t n)
{
    if (n == 0) {
        return;
    }
    if (sf_log_file_append(&w->file, p, len, n) == SF_OK) {
        count(w, true, n, len);
        w->unsynced = true;
        return;
    }
    for (; n > 0; n--) {
        p += write_one(w, p, false);
    }
}

/* The events of one taken run, in runs of plain events cut at each event that needs a rule. */
void sf_log_writer_events(sf_log_writer_t *const w, uint8_t *const p, const size_t len)
{
    size_t run = 0, run_len = 0;
    uint64_t run_n = 0;
    for (size_t at = 0; at < len;) {
        uint8_t *const e = p + at;
        const size_t bytes = sf_log_file_event_bytes(e);
        const bool is_header = (sf_log_ring_flags(e) & SF_LOG_RING_HEADER) != 0;
        if (is_header || w->failing || w->file.fd < 0 || (!w->file_has_header && w->header_channel != NULL) ||
            rotation_due(w, run_len, bytes)) {
            write_run(w, p + run, run_len, run_n);
            write_one(w, e, is_header);
            run = at + bytes;
            run_len = 0;
            run_n = 0;
        } else {
            run_len += bytes;
            run_n++;
        }
        at += bytes;
    }
    write_run(w, p + run, run_len, run_n);
}

/* Between batches: a rotation that was asked for or is due, else a sync that is due. */
void sf_log_writer_housekeeping(sf_log_writer_t *const w, bool rotate)
{
    const int64_t now = monotonic_us();
    if (w->cfg->rotate_requests != NULL) {
        const unsigned seen = atomic_load(w->cfg->rotate_requests);
        rotate |= seen != w->rotations_seen;
        w->rotations_seen = seen;
    }
    if (w->file.fd < 0) {
        return;
    }
    if (rotate || (w->cfg->rotate_s > 0 && now - w->file_opened_us >= (int64_t)w->cfg->rotate_s * 1000000)) {
        close_file(w);
        return;
    }
    if (w->unsynced && now - w->last_sync_us >= (int64_t)w->cfg->fsync_interval_ms * 1000) {
        if (sf_log_file_sync(&w->file) != SF_OK) { /* a failure starts an episode; only a write ends one */
            episode(w, false, errno);
        }
        w->last_sync_us = now;
        w->unsynced = false;
    }
}


void sf_log_writer_init(sf_log_writer_t *const w, const sf_lcm_out_config_t *const cfg)
{
    memset(w, 0, sizeof *w);
    w->cfg = cfg;
    w->file.fd = -1;
    pthread_mutex_init(&w->lock, NULL);
    if (cfg->rotate_requests != NULL) {
        w->rotations_seen = atomic_load(cfg->rotate_requests);
    }
}

int sf_log_writer_open(sf_log_writer_t *const w, char *const err, const size_t err_size)
{
    const sf_lcm_out_config_t *const cfg = w->cfg;
    if (cfg->log_path == NULL) {
        return SF_EINVAL;
    }
    snprintf(w->first_path, sizeof w->first_path, "%s", cfg->log_path);
    const int rc = sf_log_file_open(&w->file, cfg->log_path, cfg->force, err, err_size);
    if (rc != SF_OK) {
        return rc;
    }
    w->counters.files = 1;
    w->file_opened_us = monotonic_us();
    w->last_sync_us = w->file_opened_us;
    return SF_OK;
}

void sf_log_writer_dropped(sf_log_writer_t *const w, const uint64_t bytes)
{
    pthread_mutex_lock(&w->lock);
    w->counters.drops++;
    w->counters.drop_bytes += bytes;
    pthread_mutex_unlock(&w->lock);
}

void sf_log_writer_publish_failed(sf_log_writer_t *const w)
{
    pthread_mutex_lock(&w->lock);
    w->counters.publish_errors++;
    pthread_mutex_unlock(&w->lock);
}

void sf_log_writer_counters(sf_log_writer_t *const w, sf_lcm_out_counters_t *const counters)
{
    pthread_mutex_lock(&w->lock);
    *counters = w->counters;
    pthread_mutex_unlock(&w->lock);
}

int sf_log_writer_close(sf_log_writer_t *const w)
{
    close_file(w);
    const int rc = w->write_failed ? SF_EIO : SF_OK;
    free(w->header_channel);
    free(w->header_data);
    w->header_channel = NULL;
    w->header_data = NULL;
    pthread_mutex_destroy(&w->lock);
    return rc;
}
