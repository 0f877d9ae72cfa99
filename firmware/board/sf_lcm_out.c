/* sf_lcm_out.c — bounded queue + writer in front of the log file (sf_log_file.h) and live LCM (see
 * sf_lcm_out.h). The queue is a byte ring of events already in the file's format (sf_log_ring.h):
 * the caller encodes into it, the writer hands whole runs of it to one write. The writer — the
 * writer thread, or with caller_writes the caller's thread at each batch — owns the file: rotation,
 * syncs and failure episodes all happen there. */
#define _GNU_SOURCE
#include "sf_lcm_out.h"

#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <lcm/lcm.h>

#include "sf_error.h"
#include "sf_log_file.h"
#include "sf_log_ring.h"
#include "sf_log_writer.h"

#define IDLE_WAKE_US 100000 /* the idle writer looks at syncs and rotation this often */

struct sf_lcm_out {
    sf_lcm_out_config_t cfg;
    lcm_t *lcm;
    sf_log_writer_t w; /* the file's side: the writer thread's, or the caller's (caller_writes) */
    bool threaded;     /* a log written by the writer thread (not caller_writes) */
    /* shared, under lock when threaded */
    pthread_t writer;
    bool writer_started;
    pthread_mutex_t lock;
    pthread_cond_t not_empty;
    pthread_cond_t not_full;
    sf_log_ring_t ring;
    bool has_log;
    bool closing;
    uint64_t n_queued;   /* events ever queued */
    uint64_t n_taken;    /* events ever taken by the writer */
    bool rotate_asked;   /* by sf_lcm_out_rotate: after the event n_queued counted then */
    uint64_t rotate_after;
    /* the caller's: the reservation in progress (sf_lcm_out_reserve .. _commit) */
    const char *res_channel;
    uint8_t *res_data;
    size_t res_size;
    bool res_in_ring; /* else in scratch: no log, or dropped from a full queue but still published */
    uint8_t *scratch;
    size_t scratch_cap;
};

static void lock(sf_lcm_out_t *const out)
{
    pthread_mutex_lock(&out->lock);
}

static void unlock(sf_lcm_out_t *const out)
{
    pthread_mutex_unlock(&out->lock);
}

/* The ring's lock: only a writer thread shares it (with caller_writes one thread owns everything). */
static void ring_lock(sf_lcm_out_t *const out)
{
    if (out->threaded) {
        lock(out);
    }
}

static void ring_unlock(sf_lcm_out_t *const out)
{
    if (out->threaded) {
        unlock(out);
    }
}

/* Takes up to max_events (the ring's lock held), writes them (without it) and frees their room. */
static void write_batch(sf_lcm_out_t *const out, const uint64_t max_events)
{
    sf_log_ring_run_t runs[2];
    uint64_t n;
    const int n_runs = sf_log_ring_take(&out->ring, max_events, runs, &n);
    out->n_taken += n;
    if (out->threaded) {
        pthread_cond_signal(&out->not_full); /* a message slot is free */
        unlock(out);
    }
    for (int i = 0; i < n_runs; i++) {
        sf_log_writer_events(&out->w, runs[i].p, runs[i].len);
    }
    ring_lock(out);
    sf_log_ring_release(&out->ring);
    if (out->threaded) {
        pthread_cond_signal(&out->not_full); /* and the bytes */
    }
}

/* caller_writes: everything queued written now, then the housekeeping a writer thread would do. */
static void flush_in_caller(sf_lcm_out_t *const out, const bool rotate)
{
    write_batch(out, UINT64_MAX);
    sf_log_writer_housekeeping(&out->w, rotate);
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

/* Each wake-up takes every queued event (up to a rotation asked for after some of them) and writes
 * them in one go: in the kernel as soon as the writer has them, one system call per run. */
static void *writer_main(void *arg)
{
    sf_lcm_out_t *const out = arg;
    lock(out);
    for (;;) {
        while (out->ring.queued == 0 && !out->closing) {
            const bool rotate = out->rotate_asked; /* the queue is empty: every event before it is written */
            out->rotate_asked = false;
            unlock(out);
            sf_log_writer_housekeeping(&out->w, rotate);
            lock(out);
            if (out->ring.queued == 0 && !out->closing && !out->rotate_asked) {
                wait_a_while(out);
            }
        }
        if (out->ring.queued == 0 && out->closing) {
            break;
        }
        const bool limited = out->rotate_asked;
        uint64_t max = limited ? out->rotate_after - out->n_taken : UINT64_MAX;
        if (out->cfg.fsync_interval_ms == 0 && max > 1) {
            max = 1; /* a sync after every event, as fsync_interval_ms = 0 promises */
        }
        write_batch(out, max); /* returns with the lock held */
        const bool rotate = limited && out->n_taken >= out->rotate_after;
        out->rotate_asked &= !rotate;
        unlock(out);
        sf_log_writer_housekeeping(&out->w, rotate);
        lock(out);
    }
    unlock(out);
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

/* The ring: room for the queue's messages at ~128 B each, and never less than 1 MiB (so that the
 * largest message, ≤ a quarter of it, always fits). */
static size_t ring_bytes(const size_t queue_capacity)
{
    const size_t min = (size_t)1 << 20;
    return queue_capacity < min / 128 ? min : queue_capacity * 128;
}

/* The first file, the queue and (without caller_writes) the writer thread. */
static int open_log(sf_lcm_out_t *const out, char *const err, const size_t err_size)
{
    const int rc = sf_log_writer_open(&out->w, err, err_size);
    if (rc != SF_OK) {
        return rc;
    }
    out->has_log = true;
    if (sf_log_ring_init(&out->ring, ring_bytes(out->cfg.queue_capacity)) != SF_OK) {
        snprintf(err, err_size, "out of memory for the log queue");
        sf_log_file_discard(&out->w.file);
        return SF_EIO;
    }
    if (out->cfg.caller_writes) {
        return SF_OK;
    }
    if (start_writer(out) != SF_OK) {
        snprintf(err, err_size, "cannot start the log writer thread");
        sf_log_file_discard(&out->w.file);
        return SF_EIO;
    }
    out->writer_started = true;
    out->threaded = true;
    return SF_OK;
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
    sf_log_writer_init(&out->w, &out->cfg);
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
        const int rc = open_log(out, err, err_size);
        if (rc != SF_OK) {
            const int e = errno;
            sf_lcm_out_close(out, NULL);
            errno = e;
            return rc;
        }
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

/* The reservation's place outside the ring (no log, or a message the queue dropped that live LCM
 * still gets): NULL when out of memory. */
static uint8_t *scratch(sf_lcm_out_t *const out, const size_t size)
{
    if (size > out->scratch_cap || out->scratch == NULL) {
        const size_t cap = size > 4096 ? size : 4096;
        uint8_t *const bigger = realloc(out->scratch, cap);
        if (bigger == NULL) {
            return NULL;
        }
        out->scratch = bigger;
        out->scratch_cap = cap;
    }
    out->res_in_ring = false;
    return out->scratch;
}

/* Room in the ring for one event, waiting (block_when_full), writing the queue out (caller_writes)
 * or dropping it (counted) when there is none: the data's place, or NULL. */
static uint8_t *reserve_in_ring(sf_lcm_out_t *const out, const char *const channel, const size_t channel_len,
                                const int64_t timestamp_us, const size_t size, const uint32_t flags)
{
    const uint64_t bytes = SF_LOG_FILE_EVENT_OVERHEAD + (uint64_t)channel_len + size;
    uint8_t *p = NULL;
    ring_lock(out);
    if (bytes <= out->ring.size / 4) { /* larger never fits for sure: dropped */
        for (;;) {
            p = out->ring.queued < out->cfg.queue_capacity
                    ? sf_log_ring_reserve(&out->ring, channel, channel_len, timestamp_us, size, flags)
                    : NULL;
            if (p != NULL || (out->threaded && !out->cfg.block_when_full)) {
                break;
            }
            if (out->threaded) {
                pthread_cond_wait(&out->not_full, &out->lock);
            } else {
                flush_in_caller(out, false); /* then the ring is empty */
            }
        }
    }
    ring_unlock(out);
    if (p == NULL) {
        sf_log_writer_dropped(&out->w, bytes);
    }
    out->res_in_ring = p != NULL;
    return p;
}

void *sf_lcm_out_reserve(sf_lcm_out_t *const out, const char *const channel, const int64_t timestamp_us,
                         const size_t size, const bool is_header)
{
    if (out == NULL || channel == NULL || size > INT32_MAX) {
        return NULL;
    }
    out->res_channel = channel;
    out->res_size = size;
    out->res_data = NULL;
    if (out->has_log) {
        out->res_data = reserve_in_ring(out, channel, strlen(channel), timestamp_us, size,
                                        is_header ? SF_LOG_RING_HEADER : 0u);
    }
    if (out->res_data == NULL && (!out->has_log || out->lcm != NULL)) {
        out->res_data = scratch(out, size > 0 ? size : 1);
    }
    return out->res_data;
}

int sf_lcm_out_commit(sf_lcm_out_t *const out, const bool filled)
{
    if (out == NULL || out->res_data == NULL) {
        return SF_EINVAL;
    }
    const uint8_t *const data = out->res_data;
    out->res_data = NULL;
    if (out->lcm != NULL && filled && lcm_publish(out->lcm, out->res_channel, data, (unsigned)out->res_size) != 0) {
        sf_log_writer_publish_failed(&out->w);
    }
    if (!out->res_in_ring) {
        return !filled ? SF_EINVAL : out->has_log ? SF_EFULL : SF_OK;
    }
    ring_lock(out);
    sf_log_ring_commit(&out->ring, filled);
    out->n_queued += filled ? 1u : 0u;
    if (out->threaded) {
        pthread_cond_signal(&out->not_empty);
    } else if (sf_log_ring_queued_bytes(&out->ring) >= SF_LCM_OUT_CALLER_BATCH_BYTES ||
               out->cfg.fsync_interval_ms == 0) { /* 0: a sync after every event */
        flush_in_caller(out, false);
    }
    ring_unlock(out);
    return filled ? SF_OK : SF_EINVAL;
}

static int write_copy(sf_lcm_out_t *const out, const char *const channel, const int64_t timestamp_us,
                      const void *const data, const size_t size, const bool is_header)
{
    if (out == NULL || channel == NULL || (data == NULL && size > 0)) {
        return SF_EINVAL;
    }
    void *const p = sf_lcm_out_reserve(out, channel, timestamp_us, size, is_header);
    if (p == NULL) {
        return out->has_log ? SF_EFULL : SF_OK; /* no room (counted), or nowhere to go at all */
    }
    if (size > 0) {
        memcpy(p, data, size);
    }
    return sf_lcm_out_commit(out, true);
}

int sf_lcm_out_write(sf_lcm_out_t *const out, const char *const channel, const int64_t timestamp_us,
                     const void *const data, const size_t size)
{
    return write_copy(out, channel, timestamp_us, data, size, false);
}

int sf_lcm_out_write_header(sf_lcm_out_t *const out, const char *const channel, const int64_t timestamp_us,
                            const void *const data, const size_t size)
{
    return write_copy(out, channel, timestamp_us, data, size, true);
}

void sf_lcm_out_rotate(sf_lcm_out_t *const out)
{
    if (out == NULL || !out->has_log) {
        return;
    }
    if (!out->threaded) {
        flush_in_caller(out, true); /* every event before the request written, then the file closed */
        return;
    }
    lock(out);
    out->rotate_asked = true;
    out->rotate_after = out->n_queued;
    pthread_cond_signal(&out->not_empty);
    unlock(out);
}

void sf_lcm_out_counters(sf_lcm_out_t *const out, sf_lcm_out_counters_t *const counters)
{
    sf_log_writer_counters(&out->w, counters);
}

int sf_lcm_out_close(sf_lcm_out_t *const out, sf_lcm_out_counters_t *const final)
{
    if (out == NULL) {
        return SF_OK;
    }
    if (out->writer_started) {
        lock(out);
        out->closing = true;
        pthread_cond_signal(&out->not_empty);
        unlock(out);
        pthread_join(out->writer, NULL);
        out->threaded = false; /* the writer is gone: the file is ours */
    } else if (out->has_log) {
        write_batch(out, UINT64_MAX);
    }
    if (final != NULL) {
        sf_log_writer_counters(&out->w, final);
    }
    const int rc = sf_log_writer_close(&out->w);
    if (out->lcm != NULL) {
        lcm_destroy(out->lcm);
    }
    free(out->scratch);
    sf_log_ring_free(&out->ring);
    pthread_cond_destroy(&out->not_empty);
    pthread_cond_destroy(&out->not_full);
    pthread_mutex_destroy(&out->lock);
    free(out);
    return rc;
}
