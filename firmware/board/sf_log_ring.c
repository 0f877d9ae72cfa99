/* sf_log_ring.c — a byte ring of whole LCM log events (see sf_log_ring.h).
 *
 * Layout: the events run from head to tail; when one does not fit between tail and the end of the
 * buffer it goes to buf[0] and `wrap` marks where the older ones end. tail never catches up with
 * head from behind (a reservation needs one spare byte), so head == tail means empty, and an empty
 * ring starts again at buf[0] (the pages of a ring that is written and drained as fast as it fills
 * stay few: a file replay touches its first batch's worth only). */
#include "sf_log_ring.h"

#include <stdlib.h>
#include <string.h>

#include "sf_error.h"
#include "sf_log_file.h"

int sf_log_ring_init(sf_log_ring_t *const r, const size_t size)
{
    memset(r, 0, sizeof *r);
    r->buf = calloc(size, 1);
    if (r->buf == NULL) {
        return SF_EIO;
    }
    r->size = size;
    r->wrap = size;
    return SF_OK;
}

void sf_log_ring_free(sf_log_ring_t *const r)
{
    free(r->buf);
    memset(r, 0, sizeof *r);
}

uint8_t *sf_log_ring_reserve(sf_log_ring_t *const r, const char *const channel, const size_t channel_len,
                             const int64_t timestamp_us, const size_t size, const uint32_t flags)
{
    const size_t n = SF_LOG_FILE_EVENT_OVERHEAD + channel_len + size;
    if (r->head == r->tail && !r->taking) {
        r->head = r->tail = 0;
        r->wrap = r->size;
    }
    size_t at;
    if (r->tail >= r->head) { /* free: [tail, size) and [0, head) */
        if (r->size - r->tail >= n) {
            at = r->tail;
        } else if (r->head > n) {
            at = 0;
        } else {
            return NULL;
        }
    } else if (r->head - r->tail > n) { /* wrapped: free is [tail, head) */
        at = r->tail;
    } else {
        return NULL;
    }
    uint8_t *const e = r->buf + at;
    sf_log_file_put_header(e, (int64_t)flags, timestamp_us, channel_len, size);
    memcpy(e + SF_LOG_FILE_EVENT_OVERHEAD, channel, channel_len);
    r->res_at = at;
    r->res_bytes = n;
    return e + SF_LOG_FILE_EVENT_OVERHEAD + channel_len;
}

void sf_log_ring_commit(sf_log_ring_t *const r, const bool filled)
{
    if (filled && r->res_bytes > 0) {
        if (r->res_at == 0 && r->tail != 0) {
            r->wrap = r->tail; /* the older events end here; the new one starts the buffer again */
        }
        r->tail = r->res_at + r->res_bytes;
        r->queued++;
    }
    r->res_bytes = 0;
}

size_t sf_log_ring_queued_bytes(const sf_log_ring_t *const r)
{
    size_t start = r->taking ? r->taken_end : r->head;
    if (start == r->wrap && r->tail < start) {
        start = 0;
    }
    return r->tail >= start ? r->tail - start : (r->wrap - start) + r->tail;
}

/* Past k events from p, within [p, end): the position after them, and how many there were in *k. */
static size_t skip(const sf_log_ring_t *const r, size_t p, const size_t end, uint64_t *const k)
{
    uint64_t i = 0;
    while (i < *k && p < end) {
        p += sf_log_file_event_bytes(r->buf + p);
        i++;
    }
    *k = i;
    return p;
}

int sf_log_ring_take(sf_log_ring_t *const r, const uint64_t max_events, sf_log_ring_run_t runs[2],
                     uint64_t *const n_events)
{
    const uint64_t k = max_events < r->queued ? max_events : r->queued;
    *n_events = 0;
    if (k == 0 || r->taking) {
        return 0;
    }
    const bool wrapped = r->tail < r->head;
    const size_t top = wrapped ? r->wrap : r->tail; /* where the run from head ends */
    size_t end;
    int n_runs;
    if (k == r->queued) {
        end = r->tail;
        runs[0] = (sf_log_ring_run_t){r->buf + r->head, top - r->head};
        runs[1] = (sf_log_ring_run_t){r->buf, wrapped ? r->tail : 0};
        n_runs = wrapped ? 2 : 1;
    } else {
        uint64_t first = k;
        const size_t p = skip(r, r->head, top, &first);
        runs[0] = (sf_log_ring_run_t){r->buf + r->head, p - r->head};
        end = p;
        n_runs = 1;
        if (first < k) { /* the rest from buf[0] */
            uint64_t rest = k - first;
            end = skip(r, 0, r->tail, &rest);
            runs[1] = (sf_log_ring_run_t){r->buf, end};
            n_runs = 2;
        }
    }
    if (n_runs == 2 && runs[0].len == 0) { /* head stood at the wrap */
        runs[0] = runs[1];
        n_runs = 1;
    }
    r->queued -= k;
    r->taken_end = end;
    r->taking = true;
    *n_events = k;
    return n_runs;
}

void sf_log_ring_release(sf_log_ring_t *const r)
{
    if (!r->taking) {
        return;
    }
    if (r->taken_end < r->head) {
        r->wrap = r->size; /* the taken runs went past the wrap */
    }
    r->head = r->taken_end;
    r->taking = false;
    if (r->head == r->wrap && r->tail < r->head) { /* the older events are gone: on from buf[0] */
        r->head = 0;
        r->wrap = r->size;
    }
}

uint32_t sf_log_ring_flags(const uint8_t *const event)
{
    return (uint32_t)event[8] << 24 | (uint32_t)event[9] << 16 | (uint32_t)event[10] << 8 | event[11];
}
