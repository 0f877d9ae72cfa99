/* sf_log_ring.h — the log queue's memory: one byte ring of whole LCM events, each already laid out
 * as the log file holds it (sf_log_file.h: 28-byte header, channel, data).
 *
 * Why: the queue used to hold a malloc'd copy of every message and its channel (two allocations, two
 * frees and a strdup per message, ~600 instructions), and the writer made one system call per event.
 * Here the caller encodes straight into the ring (sf_log_ring_reserve gives the data's place, with
 * the header and channel written) and the writer hands a run of events to one write
 * (sf_log_file_append), so a message costs no allocation, no copy and a fraction of a system call.
 *
 * Protocol: reserve (room for one event, or NULL when full), fill the data, commit (or cancel); the
 * consumer takes every committed event, or the first max_events of them (one or two contiguous runs:
 * the ring wraps between events, never inside one), writes them, and releases them (their room is
 * free again). One taking at a time. The ring is not thread-safe: its owner locks around reserve,
 * commit, take and release; the fill and the write happen outside the lock, on bytes only one side
 * touches (the reservation is the producer's, the taken runs the consumer's). An event's flags
 * (SF_LOG_RING_HEADER) stay in its event-number field until the writer numbers it.
 *
 * Cost: reserve, commit and release O(1) plus the header and channel bytes; take O(1), or O(events)
 * when limited to fewer than all. Memory: `size` bytes, allocated by init (calloc: pages the events
 * never reach are never touched), freed by sf_log_ring_free. */
#ifndef SF_LOG_RING_H
#define SF_LOG_RING_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define SF_LOG_RING_HEADER 1u /* the event is a header (sf_lcm_out_write_header) */

typedef struct {
    uint8_t *p;
    size_t len;
} sf_log_ring_run_t;

typedef struct {
    uint8_t *buf;
    size_t size;       /* bytes */
    size_t head;       /* first byte not yet released */
    size_t tail;       /* end of the committed events */
    size_t wrap;       /* while the events wrap (tail < head): where the ones before buf[0] end; else size */
    size_t res_at;     /* the reservation in progress: where, and its bytes (0: none) */
    size_t res_bytes;
    size_t taken_end;  /* end of the runs taken and not yet released */
    bool taking;
    uint64_t queued;   /* committed events not yet taken */
} sf_log_ring_t;

/* SF_OK, or SF_EIO (out of memory). */
int sf_log_ring_init(sf_log_ring_t *r, size_t size);
void sf_log_ring_free(sf_log_ring_t *r);

/* Room for one event of `size` data bytes on `channel` (channel_len bytes, no NUL): writes its
 * header (timestamp, lengths, flags in the number field) and channel, and returns where its data
 * goes; NULL when the ring has no room for it now. */
uint8_t *sf_log_ring_reserve(sf_log_ring_t *r, const char *channel, size_t channel_len, int64_t timestamp_us,
                             size_t size, uint32_t flags);

/* The reserved event joins the queue (filled), or is forgotten (not filled). */
void sf_log_ring_commit(sf_log_ring_t *r, bool filled);

/* Takes up to max_events of the queued events, oldest first: fills runs[0..1] and returns how many
 * runs (0 when none queued), with the events' count in *n_events. */
int sf_log_ring_take(sf_log_ring_t *r, uint64_t max_events, sf_log_ring_run_t runs[2], uint64_t *n_events);

/* The taken events' room is free again. */
void sf_log_ring_release(sf_log_ring_t *r);

/* Bytes queued (committed, not yet taken). */
size_t sf_log_ring_queued_bytes(const sf_log_ring_t *r);

/* The flags an event was reserved with (valid until sf_log_file_append numbers it). */
uint32_t sf_log_ring_flags(const uint8_t *event);

#endif
