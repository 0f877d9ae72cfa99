/* sf_lcm_out.c — bounded queue + writer thread in front of the log file (sf_log_file.h) and live
 * LCM (see sf_lcm_out.h). The writer thread owns the file: rotation, syncs and failure episodes
 * all happen there; the caller's thread only copies into the queue. */
#define _GNU_SOURCE
#include "sf_lcm_out.h"

#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/statvfs.h>
#include <time.h>

#include <lcm/lcm.h>

#include "sf_error.h"
#include "sf_log_file.h"

#define IDLE_WAKE_US 100000 /* the idle writer looks at syncs and rotation this often */
#define MAX_NAME_ATTEMPTS 1000

typedef struct {
    char *channel;
    void *data;
    size_t size;
    int64_t timestamp_us;
    bool is_header;
} item_t;

struct sf_lcm_out {
    sf_lcm_out_config_t cfg;
    char first_path[SF_LOG_FILE_PATH_MAX];
    lcm_t *lcm;
    /* the writer thread's (the caller's before the thread starts and after it ends) */
    sf_log_file_t file;
    unsigned file_index; /* the current file, or the last one while none is open */
    int64_t file_opened_us;
    int64_t last_sync_us;
    bool unsynced;
    unsigned rotations_seen;
    item_t header; /* copy of the latest header event; channel NULL if none */
    bool failing;  /* inside a write-failure episode */
    int fail_errno; /* why the episode began */
    /* shared, under lock */
    pthread_t writer;
    bool writer_started;
    pthread_mutex_t lock;
    pthread_cond_t not_empty;
    pthread_cond_t not_full;
    item_t *ring;
    size_t capacity;
    size_t head; /* next to write */
    size_t count;
    bool closing;
    uint64_t n_queued;   /* items ever queued */
    uint64_t n_taken;    /* items ever taken by the writer */
    bool rotate_asked;   /* by sf_lcm_out_rotate: after the item n_queued counted then */
    uint64_t rotate_after;
    bool write_failed;
    sf_lcm_out_counters_t counters;
};

static int64_t monotonic_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static uint64_t event_bytes(const char *const channel, const size_t size)
{
    return SF_LOG_FILE_EVENT_OVERHEAD + (uint64_t)strlen(channel) + (uint64_t)size;
}

static void report(const sf_lcm_out_t *const out, const char *const fmt, ...)
{
    if (out->cfg.report == NULL) {
        return;
    }
    va_list ap;
    va_start(ap, fmt);
    fprintf(out->cfg.report, "stridefixd: ");
    vfprintf(out->cfg.report, fmt, ap);
    fprintf(out->cfg.report, "\n");
    va_end(ap);
}

static void count(sf_lcm_out_t *const out, const bool written, const uint64_t bytes)
{
    pthread_mutex_lock(&out->lock);
    if (written) {
        out->counters.events++;
        out->counters.bytes += bytes;
    } else {
        out->counters.drops++;
        out->counters.drop_bytes += bytes;
        out->write_failed = true;
    }
    pthread_mutex_unlock(&out->lock);
}

/* Tells the start and the end of a failure episode, once each. */
static void episode(sf_lcm_out_t *const out, const bool ok, const int err_no)
{
    if (!ok && !out->failing) {
        out->failing = true;
        out->fail_errno = err_no;
        report(out, "%s: writing the log failed: %s; events are dropped and counted until writes succeed again",
               out->file.fd >= 0 ? out->file.part_path : out->first_path, strerror(err_no));
    } else if (ok && out->failing) {
        out->failing = false;
        sf_lcm_out_counters_t c;
        sf_lcm_out_counters(out, &c);
        report(out, "%s: logging resumed (%llu events, %llu bytes dropped so far)", out->file.part_path,
               (unsigned long long)c.drops, (unsigned long long)c.drop_bytes);
    }
}

static void close_file(sf_lcm_out_t *const out)
{
    char err[2 * SF_LOG_FILE_PATH_MAX + 128];
    if (sf_log_file_close(&out->file, err, sizeof err) != SF_OK) {
        report(out, "%s", err);
        pthread_mutex_lock(&out->lock);
        out->write_failed = true;
        pthread_mutex_unlock(&out->lock);
    }
    out->unsynced = false;
}

/* Opens the next rotated file (skipping names that exist) and writes the header copy into it,
 * stamped timestamp_us. On failure no file is open and errno tells why. */
static int open_next(sf_lcm_out_t *const out, const int64_t timestamp_us)
{
    char path[SF_LOG_FILE_PATH_MAX];
    char err[SF_LOG_FILE_PATH_MAX + 128];
    int rc = SF_EIO;
    unsigned index = out->file_index;
    for (int attempt = 0; attempt < MAX_NAME_ATTEMPTS; attempt++) {
        index++;
        if (sf_log_file_rotated_name(path, sizeof path, out->first_path, index) != SF_OK) {
            errno = ENAMETOOLONG;
            return SF_EIO;
        }
        rc = sf_log_file_open(&out->file, path, out->cfg.force, err, sizeof err);
        if (rc == SF_OK || errno != EEXIST) {
            break;
        }
    }
    if (rc != SF_OK) {
        return rc;
    }
    if (out->header.channel != NULL) {
        const int hrc = sf_log_file_write(&out->file, out->header.channel, timestamp_us, out->header.data,
                                          out->header.size);
        if (hrc != SF_OK) { /* a file without its header would not read alone: none at all */
            const int e = errno;
            sf_log_file_discard(&out->file);
            errno = e;
            return hrc;
        }
    }
    out->file_index = index;
    out->file_opened_us = monotonic_us();
    out->unsynced = true;
    pthread_mutex_lock(&out->lock);
    out->counters.files++;
    if (out->header.channel != NULL) {
        out->counters.events++;
        out->counters.header_copies++;
        out->counters.bytes += event_bytes(out->header.channel, out->header.size);
    }
    pthread_mutex_unlock(&out->lock);
    return SF_OK;
}

/* Keeps a copy of a header event for the files to come (the item keeps its own buffers). */
static void keep_header(sf_lcm_out_t *const out, const item_t *const it)
{
    char *const channel = strdup(it->channel);
    void *const data = malloc(it->size > 0 ? it->size : 1);
    if (channel == NULL || data == NULL) {
        free(channel);
        free(data);
        return; /* the old header (if any) stays */
    }
    memcpy(data, it->data, it->size);
    free(out->header.channel);
    free(out->header.data);
    out->header.channel = channel;
    out->header.data = data;
    out->header.size = it->size;
    out->header.timestamp_us = it->timestamp_us;
    out->header.is_header = true;
}

/* A full disk is not free again because one small event fits its last page (tmpfs: 346 B did, inside
 * one episode): during an ENOSPC/EDQUOT episode writes resume only with 64 KiB free (or unknown). */
static bool room_again(const sf_lcm_out_t *const out)
{
    struct statvfs st;
    if (!out->failing || (out->fail_errno != ENOSPC && out->fail_errno != EDQUOT) || out->file.fd < 0 ||
        fstatvfs(out->file.fd, &st) != 0) {
        return true;
    }
    return (uint64_t)st.f_bavail * (uint64_t)st.f_frsize >= 64u * 1024u;
}

static void write_item(sf_lcm_out_t *const out, const item_t *const it)
{
    if (it->is_header) {
        keep_header(out, it);
    }
    const uint64_t bytes = event_bytes(it->channel, it->size);
    if (out->file.fd >= 0 && out->cfg.rotate_bytes > 0 && out->file.offset > 0 &&
        out->file.offset + bytes > out->cfg.rotate_bytes) {
        close_file(out);
    }
    if (!room_again(out)) {
        count(out, false, bytes); /* still full: dropped, counted, the episode goes on */
        return;
    }
    int rc = out->file.fd >= 0 ? SF_OK : open_next(out, it->timestamp_us);
    if (rc == SF_OK) {
        rc = sf_log_file_write(&out->file, it->channel, it->timestamp_us, it->data, it->size);
    }
    const int e = errno;
    count(out, rc == SF_OK, bytes);
    episode(out, rc == SF_OK, e);
    out->unsynced |= rc == SF_OK;
}

/* Between events: a rotation that was asked for or is due, else a sync that is due. */
static void housekeeping(sf_lcm_out_t *const out, bool rotate)
{
    const int64_t now = monotonic_us();
    if (out->cfg.rotate_requests != NULL) {
        const unsigned seen = atomic_load(out->cfg.rotate_requests);
        rotate |= seen != out->rotations_seen;
        out->rotations_seen = seen;
    }
    if (out->file.fd < 0) {
        return;
    }
    if (rotate || (out->cfg.rotate_s > 0 && now - out->file_opened_us >= (int64_t)out->cfg.rotate_s * 1000000)) {
        close_file(out);
        return;
    }
    if (out->unsynced && now - out->last_sync_us >= (int64_t)out->cfg.fsync_interval_ms * 1000) {
        const bool ok = sf_log_file_sync(&out->file) == SF_OK;
        episode(out, ok, errno);
        out->last_sync_us = now;
        out->unsynced = false;
    }
}

static void wait_a_while(sf_lcm_out_t *const out)
{
    struct timespec until;
    clock_gettime(CLOCK_MONOTONIC, &until);
    until.tv_nsec += IDLE_WAKE_US * 1000L;
    until.tv_sec += until.tv_nsec / 1000000000L;
    until.tv_nsec %= 1000000000L;
    (void)pthread_cond_timedwait(&out->not_empty, &out->lock, &until);
}

static void *writer_main(void *arg)
{
    sf_lcm_out_t *const out = arg;
    out->last_sync_us = monotonic_us();
    pthread_mutex_lock(&out->lock);
    for (;;) {
        while (out->count == 0 && !out->closing) {
            const bool rotate = out->rotate_asked; /* the queue is empty: every item before it is written */
            out->rotate_asked = false;
            pthread_mutex_unlock(&out->lock);
            housekeeping(out, rotate);
            pthread_mutex_lock(&out->lock);
            if (out->count == 0 && !out->closing && !out->rotate_asked) {
                wait_a_while(out);
            }
        }
        if (out->count == 0 && out->closing) {
            break;
        }
        const item_t it = out->ring[out->head];
        out->head = (out->head + 1) % out->capacity;
        out->count--;
        out->n_taken++;
        const bool rotate = out->rotate_asked && out->n_taken >= out->rotate_after;
        out->rotate_asked &= !rotate;
        pthread_cond_signal(&out->not_full);
        pthread_mutex_unlock(&out->lock);

        write_item(out, &it);
        free(it.channel);
        free(it.data);
        housekeeping(out, rotate);

        pthread_mutex_lock(&out->lock);
    }
    pthread_mutex_unlock(&out->lock);
    return NULL;
}

/* The writer thread blocks every signal: they go to the caller's thread, whose blocking reads
 * they are meant to interrupt (stridefixd's SIGTERM). */
static int start_writer(sf_lcm_out_t *const out)
{
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &old);
    const int rc = pthread_create(&out->writer, NULL, writer_main, out);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    return rc == 0 ? SF_OK : SF_EIO;
}

static int init_sync(sf_lcm_out_t *const out)
{
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    const int rc = pthread_cond_init(&out->not_empty, &attr);
    pthread_condattr_destroy(&attr);
    pthread_mutex_init(&out->lock, NULL);
    pthread_cond_init(&out->not_full, NULL);
    return rc == 0 ? SF_OK : SF_EIO;
}

int sf_lcm_out_open_config(sf_lcm_out_t **const result, const sf_lcm_out_config_t *const cfg, char *const err,
                           const size_t err_size)
{
    if (result == NULL || cfg == NULL || cfg->queue_capacity == 0 || cfg->fsync_interval_ms < 0 ||
        cfg->rotate_s < 0) {
        return SF_EINVAL;
    }
    sf_lcm_out_t *const out = calloc(1, sizeof *out);
    if (out == NULL) {
        snprintf(err, err_size, "out of memory");
        return SF_EIO;
    }
    out->cfg = *cfg;
    out->capacity = cfg->queue_capacity;
    out->file.fd = -1;
    if (cfg->rotate_requests != NULL) {
        out->rotations_seen = atomic_load(cfg->rotate_requests);
    }
    if (init_sync(out) != SF_OK) {
        free(out);
        snprintf(err, err_size, "cannot set up the log writer's condition variable");
        return SF_EIO;
    }
    if (cfg->lcm_url != NULL) {
        out->lcm = lcm_create(cfg->lcm_url);
        if (out->lcm == NULL) {
            snprintf(err, err_size, "cannot open LCM URL '%s'", cfg->lcm_url);
            sf_lcm_out_close(out, NULL);
            return SF_EIO;
        }
    }
    if (cfg->log_path != NULL) {
        snprintf(out->first_path, sizeof out->first_path, "%s", cfg->log_path);
        out->ring = calloc(cfg->queue_capacity, sizeof *out->ring);
        if (out->ring == NULL) {
            snprintf(err, err_size, "out of memory for the log queue");
            sf_lcm_out_close(out, NULL);
            return SF_EIO;
        }
        const int rc = sf_log_file_open(&out->file, cfg->log_path, cfg->force, err, err_size);
        if (rc != SF_OK) {
            const int e = errno;
            sf_lcm_out_close(out, NULL);
            errno = e;
            return rc;
        }
        out->counters.files = 1;
        out->file_opened_us = monotonic_us();
        if (start_writer(out) != SF_OK) {
            snprintf(err, err_size, "cannot start the log writer thread");
            sf_log_file_discard(&out->file);
            sf_lcm_out_close(out, NULL);
            return SF_EIO;
        }
        out->writer_started = true;
    }
    *result = out;
    return SF_OK;
}

int sf_lcm_out_open(sf_lcm_out_t **const result, const char *const log_path, const char *const lcm_url,
                    const size_t queue_capacity, const bool block_when_full, char *const err, const size_t err_size)
{
    const sf_lcm_out_config_t cfg = {.log_path = log_path,
                                     .lcm_url = lcm_url,
                                     .queue_capacity = queue_capacity,
                                     .block_when_full = block_when_full,
                                     .fsync_interval_ms = 1000,
                                     .report = stderr};
    return sf_lcm_out_open_config(result, &cfg, err, err_size);
}

static int enqueue(sf_lcm_out_t *const out, const char *const channel, const int64_t timestamp_us,
                   const void *const data, const size_t size, const bool is_header)
{
    if (out == NULL || channel == NULL || (data == NULL && size > 0)) {
        return SF_EINVAL;
    }
    if (out->lcm != NULL && lcm_publish(out->lcm, channel, data, (unsigned)size) != 0) {
        pthread_mutex_lock(&out->lock);
        out->counters.publish_errors++;
        pthread_mutex_unlock(&out->lock);
    }
    if (out->ring == NULL) {
        return SF_OK;
    }
    /* Copy outside the lock so the writer is held up as little as possible. */
    item_t it = {strdup(channel), malloc(size > 0 ? size : 1), size, timestamp_us, is_header};
    pthread_mutex_lock(&out->lock);
    while (it.channel != NULL && it.data != NULL && out->cfg.block_when_full && out->count == out->capacity) {
        pthread_cond_wait(&out->not_full, &out->lock);
    }
    if (it.channel == NULL || it.data == NULL || out->count == out->capacity) {
        out->counters.drops++;
        out->counters.drop_bytes += event_bytes(channel, size);
        pthread_mutex_unlock(&out->lock);
        free(it.channel);
        free(it.data);
        return SF_EFULL;
    }
    memcpy(it.data, data, size);
    out->ring[(out->head + out->count) % out->capacity] = it;
    out->count++;
    out->n_queued++;
    pthread_cond_signal(&out->not_empty);
    pthread_mutex_unlock(&out->lock);
    return SF_OK;
}

int sf_lcm_out_write(sf_lcm_out_t *const out, const char *const channel, const int64_t timestamp_us,
                     const void *const data, const size_t size)
{
    return enqueue(out, channel, timestamp_us, data, size, false);
}

int sf_lcm_out_write_header(sf_lcm_out_t *const out, const char *const channel, const int64_t timestamp_us,
                            const void *const data, const size_t size)
{
    return enqueue(out, channel, timestamp_us, data, size, true);
}

void sf_lcm_out_rotate(sf_lcm_out_t *const out)
{
    if (out == NULL || out->ring == NULL) {
        return;
    }
    pthread_mutex_lock(&out->lock);
    out->rotate_asked = true;
    out->rotate_after = out->n_queued;
    pthread_cond_signal(&out->not_empty);
    pthread_mutex_unlock(&out->lock);
}

void sf_lcm_out_counters(sf_lcm_out_t *const out, sf_lcm_out_counters_t *const counters)
{
    pthread_mutex_lock(&out->lock);
    *counters = out->counters;
    pthread_mutex_unlock(&out->lock);
}

int sf_lcm_out_close(sf_lcm_out_t *const out, sf_lcm_out_counters_t *const final)
{
    if (out == NULL) {
        return SF_OK;
    }
    if (out->writer_started) {
        pthread_mutex_lock(&out->lock);
        out->closing = true;
        pthread_cond_signal(&out->not_empty);
        pthread_mutex_unlock(&out->lock);
        pthread_join(out->writer, NULL);
        close_file(out); /* the writer is gone: the file is ours */
    }
    const int rc = out->write_failed ? SF_EIO : SF_OK;
    if (final != NULL) {
        *final = out->counters;
    }
    if (out->lcm != NULL) {
        lcm_destroy(out->lcm);
    }
    free(out->header.channel);
    free(out->header.data);
    free(out->ring);
    pthread_cond_destroy(&out->not_empty);
    pthread_cond_destroy(&out->not_full);
    pthread_mutex_destroy(&out->lock);
    free(out);
    return rc;
}
