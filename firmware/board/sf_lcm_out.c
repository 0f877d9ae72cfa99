/* sf_lcm_out.c — bounded queue + writer thread in front of liblcm's event log (see sf_lcm_out.h). */
#define _GNU_SOURCE
#include "sf_lcm_out.h"

#include <unistd.h>

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <lcm/eventlog.h>
#include <lcm/lcm.h>

#include "sf_error.h"

typedef struct {
    char *channel;
    void *data;
    size_t size;
    int64_t timestamp_us;
} item_t;

struct sf_lcm_out {
    lcm_eventlog_t *log;
    lcm_t *lcm;
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
    bool block_when_full;
    bool write_failed;
    sf_lcm_out_counters_t counters;
};

static void *writer_main(void *arg)
{
    sf_lcm_out_t *const out = arg;
    struct timespec last_flush;
    clock_gettime(CLOCK_MONOTONIC, &last_flush);
    pthread_mutex_lock(&out->lock);
    for (;;) {
        while (out->count == 0 && !out->closing) {
            pthread_cond_wait(&out->not_empty, &out->lock);
        }
        if (out->count == 0 && out->closing) {
            break;
        }
        item_t it = out->ring[out->head];
        out->head = (out->head + 1) % out->capacity;
        out->count--;
        pthread_cond_signal(&out->not_full);
        pthread_mutex_unlock(&out->lock);

        lcm_eventlog_event_t ev = {0};
        ev.timestamp = it.timestamp_us;
        ev.channellen = (int32_t)strlen(it.channel);
        ev.channel = it.channel;
        ev.datalen = (int32_t)it.size;
        ev.data = it.data;
        const int rc = lcm_eventlog_write_event(out->log, &ev);
        free(it.channel);
        free(it.data);
        struct timespec now;
        clock_gettime(CLOCK_MONOTONIC, &now);
        if (now.tv_sec > last_flush.tv_sec) { /* a second's worth at most is at risk on power loss */
            fflush(out->log->f);
            (void)fdatasync(fileno(out->log->f));
            last_flush = now;
        }

        pthread_mutex_lock(&out->lock);
        if (rc == 0) {
            out->counters.events++;
            out->counters.bytes += 28u + (uint64_t)ev.channellen + (uint64_t)it.size;
        } else {
            out->counters.drops++;
            out->write_failed = true;
        }
    }
    pthread_mutex_unlock(&out->lock);
    return NULL;
}

int sf_lcm_out_open(sf_lcm_out_t **const result, const char *const log_path, const char *const lcm_url,
                    const size_t queue_capacity, const bool block_when_full, char *const err, const size_t err_size)
{
    if (result == NULL || queue_capacity == 0) {
        return SF_EINVAL;
    }
    sf_lcm_out_t *const out = calloc(1, sizeof *out);
    if (out == NULL) {
        snprintf(err, err_size, "out of memory");
        return SF_EIO;
    }
    out->capacity = queue_capacity;
    out->block_when_full = block_when_full;
    pthread_mutex_init(&out->lock, NULL);
    pthread_cond_init(&out->not_empty, NULL);
    pthread_cond_init(&out->not_full, NULL);
    if (lcm_url != NULL) {
        out->lcm = lcm_create(lcm_url);
        if (out->lcm == NULL) {
            snprintf(err, err_size, "cannot open LCM URL '%s'", lcm_url);
            sf_lcm_out_close(out, NULL);
            return SF_EIO;
        }
    }
    if (log_path != NULL) {
        out->ring = calloc(queue_capacity, sizeof *out->ring);
        out->log = lcm_eventlog_create(log_path, "w");
        if (out->ring == NULL || out->log == NULL) {
            snprintf(err, err_size, "%s: cannot create the LCM log: %s", log_path, strerror(errno));
            sf_lcm_out_close(out, NULL);
            return SF_EIO;
        }
        if (pthread_create(&out->writer, NULL, writer_main, out) != 0) {
            snprintf(err, err_size, "cannot start the log writer thread");
            sf_lcm_out_close(out, NULL);
            return SF_EIO;
        }
        out->writer_started = true;
    }
    *result = out;
    return SF_OK;
}

int sf_lcm_out_write(sf_lcm_out_t *const out, const char *const channel, const int64_t timestamp_us,
                     const void *const data, const size_t size)
{
    if (out == NULL || channel == NULL || (data == NULL && size > 0)) {
        return SF_EINVAL;
    }
    if (out->lcm != NULL && lcm_publish(out->lcm, channel, data, (unsigned)size) != 0) {
        pthread_mutex_lock(&out->lock);
        out->counters.publish_errors++;
        pthread_mutex_unlock(&out->lock);
    }
    if (out->log == NULL) {
        return SF_OK;
    }
    /* Copy outside the lock so the writer is held up as little as possible. */
    item_t it = {strdup(channel), malloc(size > 0 ? size : 1), size, timestamp_us};
    if (it.channel == NULL || it.data == NULL) {
        free(it.channel);
        free(it.data);
        pthread_mutex_lock(&out->lock);
        out->counters.drops++;
        pthread_mutex_unlock(&out->lock);
        return SF_EFULL;
    }
    memcpy(it.data, data, size);
    pthread_mutex_lock(&out->lock);
    while (out->block_when_full && out->count == out->capacity) {
        pthread_cond_wait(&out->not_full, &out->lock);
    }
    if (out->count == out->capacity) {
        out->counters.drops++;
        pthread_mutex_unlock(&out->lock);
        free(it.channel);
        free(it.data);
        return SF_EFULL;
    }
    out->ring[(out->head + out->count) % out->capacity] = it;
    out->count++;
    pthread_cond_signal(&out->not_empty);
    pthread_mutex_unlock(&out->lock);
    return SF_OK;
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
    }
    int rc = out->write_failed ? SF_EIO : SF_OK;
    if (final != NULL) {
        *final = out->counters;
    }
    if (out->log != NULL) {
        if (fflush(out->log->f) != 0) {
            rc = SF_EIO;
        }
        lcm_eventlog_destroy(out->log);
    }
    if (out->lcm != NULL) {
        lcm_destroy(out->lcm);
    }
    free(out->ring);
    pthread_cond_destroy(&out->not_empty);
    pthread_cond_destroy(&out->not_full);
    pthread_mutex_destroy(&out->lock);
    free(out);
    return rc;
}
