/* sf_lcm_out.h — everything stridefixd says goes through here: an LCM event log on disk and,
 * optionally, live LCM publishing (any URL liblcm accepts: udpm://, file://, memq://).
 *
 * The caller never waits on disk (lcm-logger's design): each message is encoded flat into a bounded
 * queue — a byte ring of events already in the log's format (sf_log_ring.h), no allocation per
 * message — and a writer thread appends what is queued to the log file (sf_log_file.h: NAME.part,
 * renamed to NAME when closed), every event queued since its last wake-up in one write. When the
 * queue is full (queue_capacity messages, or its bytes: ≥ 1 MiB, 128 B a message) the message is
 * dropped and counted — unless the log was opened with `block_when_full` (replaying a file, where
 * losing data for speed makes no sense), in which case the caller waits for room. Event timestamps
 * are the caller's (host receive time of the frame), so replaying the same input gives the same log.
 *
 * caller_writes (a replay of a regular file, whose reads never wait): no writer thread; the caller's
 * thread writes the queue itself each time SF_LCM_OUT_CALLER_BATCH_BYTES are queued (and at rotate
 * and close), with the same rules, and does the housekeeping after each batch. A file replay used to
 * spend more in the hand-off (a futex wake and wait, a malloc/free pair per message) and in one
 * system call per event than the writing itself; the thread buys nothing there, since the caller
 * would wait for a full queue anyway. A live or stream input (SocketCAN, stdin, a FIFO) keeps the
 * thread: its reads wait, and the log must not wait with them.
 *
 * Durability: with the writer thread, every event is in the kernel as soon as the writer has it (no
 * user-space buffer beyond the queue, so SIGKILL loses only what is still queued, microseconds'
 * worth); with caller_writes, SIGKILL loses at most the batch being gathered (the input file is still
 * there to replay). The writer fdatasyncs at least every fsync_interval_ms (0: after every event,
 * each then written on its own), so power loss loses at most that much.
 *
 * Rotation: by size (a file is closed before an event would take it past rotate_bytes), by age
 * (rotate_s since the file was opened) and on request (sf_lcm_out_rotate, or a change of the counter
 * at rotate_requests, which a SIGHUP handler increments). A closed file gets its final name at once;
 * the next file is opened when the next event comes, and starts with a copy of the header event
 * (sf_lcm_out_write_header: CONFIG) stamped with that event's time, so each file reads alone.
 * Files: the first keeps log_path, the next ones are sf_log_file_rotated_name's (walk.001.lcmlog ..).
 *
 * Disk full, or any failed write: the event is dropped and counted (events and bytes) and the file
 * keeps exactly the events counted as written; the first failure of an episode is reported with
 * its reason on `report` (once, not per event), and so is the first event written after it (logging
 * resumes by itself; sf_log_writer.h: the header copied when the file's own was dropped, no empty
 * file left when nothing could be written). Invariant: events queued = events - header_copies + drops. */
#ifndef SF_LCM_OUT_H
#define SF_LCM_OUT_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

typedef struct sf_lcm_out sf_lcm_out_t;

typedef struct {
    uint64_t events;        /* written to the log files (header copies included) */
    uint64_t bytes;         /* log bytes written (payload + channel + 28-byte event header) */
    uint64_t drops;         /* events dropped: queue full, out of memory, or a write failed */
    uint64_t drop_bytes;    /* the log bytes those events would have taken */
    uint64_t header_copies; /* header events repeated to head a file: rotated, or its own dropped (disk full) */
    uint64_t files;         /* log files opened */
    uint64_t publish_errors;
} sf_lcm_out_counters_t;

typedef struct {
    const char *log_path;          /* NULL: no log */
    const char *lcm_url;           /* NULL: no live publishing */
    size_t queue_capacity;         /* messages, > 0 */
    bool block_when_full;          /* wait for room instead of dropping */
    bool caller_writes;            /* no writer thread: the caller writes each batch (see above) */
    bool force;                    /* replace an existing log file (sf_log_file.h) */
    int32_t fsync_interval_ms;     /* >= 0 */
    uint64_t rotate_bytes;         /* 0: no size rotation */
    int32_t rotate_s;              /* 0: no time rotation */
    const atomic_uint *rotate_requests; /* NULL, or a counter whose change asks for a rotation */
    FILE *report;                  /* where write failures and recoveries are told; NULL: nowhere */
} sf_lcm_out_config_t;

/* Opens the first log file and the live LCM. On failure returns SF_EIO / SF_EINVAL and writes a
 * message (errno EEXIST or ELOOP when the log name was taken or a symlink). */
int sf_lcm_out_open_config(sf_lcm_out_t **out, const sf_lcm_out_config_t *config, char *err_text,
                           size_t err_size);

/* sf_lcm_out_open_config with a 1 s fsync interval, no rotation, no --force, reports on stderr. */
int sf_lcm_out_open(sf_lcm_out_t **out, const char *log_path, const char *lcm_url, size_t queue_capacity,
                    bool block_when_full, char *err_text, size_t err_size);

/* Bytes queued that make the caller write them, with caller_writes: ~700 events of a replay, one
 * write of 64 KiB; small enough to stay in the cache, large enough that the system call is noise. */
#define SF_LCM_OUT_CALLER_BATCH_BYTES (64u * 1024u)

/* The place to encode one message of `size` bytes straight into the queue (no copy): fill it, then
 * sf_lcm_out_commit. NULL when the message goes nowhere: the queue is full (dropped and counted)
 * and there is no live LCM, or out of memory, or a bad argument (out or channel NULL, size > 2^31).
 * is_header: as sf_lcm_out_write_header. One reservation at a time, on the caller's thread. */
void *sf_lcm_out_reserve(sf_lcm_out_t *out, const char *channel, int64_t timestamp_us, size_t size, bool is_header);

/* Ends the reservation: filled, the message is published (live LCM) and queued: SF_OK, or SF_EFULL
 * when the queue had dropped it (counted at the reservation); not filled (the encode failed), it is
 * forgotten: SF_EINVAL. */
int sf_lcm_out_commit(sf_lcm_out_t *out, bool filled);

/* Queues one encoded message (a copy of data). SF_OK, SF_EFULL (dropped, counted) or SF_EINVAL. */
int sf_lcm_out_write(sf_lcm_out_t *out, const char *channel, int64_t timestamp_us, const void *data, size_t size);

/* As sf_lcm_out_write, and the message becomes the header that every later rotated file starts with. */
int sf_lcm_out_write_header(sf_lcm_out_t *out, const char *channel, int64_t timestamp_us, const void *data,
                            size_t size);

/* Asks the writer to close the current file (it gets its final name) and start the next. */
void sf_lcm_out_rotate(sf_lcm_out_t *out);

/* A snapshot of the counters (thread-safe). */
void sf_lcm_out_counters(sf_lcm_out_t *out, sf_lcm_out_counters_t *counters);

/* Drains the queue, closes (and renames) the log and the LCM, and gives the final counters (final
 * may be NULL). Returns SF_OK, or SF_EIO if any write, sync or rename failed (reported on `report`). */
int sf_lcm_out_close(sf_lcm_out_t *out, sf_lcm_out_counters_t *final);

/* Encodes an LCM message of generated type T straight into the queue (sf_lcm_out_reserve; is_header
 * as sf_lcm_out_write_header). */
#define SF_LCM_WRITE_AS(is_header, out, channel, ts_us, T, msg_ptr)                                       \
    do {                                                                                                 \
        const int sf_size_ = T##_encoded_size(msg_ptr);                                                  \
        void *const sf_p_ = sf_size_ > 0 ? sf_lcm_out_reserve((out), (channel), (ts_us), (size_t)sf_size_, \
                                                              (is_header))                               \
                                         : NULL;                                                         \
        if (sf_p_ != NULL) {                                                                             \
            (void)sf_lcm_out_commit((out), T##_encode(sf_p_, 0, sf_size_, (msg_ptr)) == sf_size_);       \
        }                                                                                                \
    } while (0)

#define SF_LCM_WRITE(out, channel, ts_us, T, msg_ptr) SF_LCM_WRITE_AS(false, out, channel, ts_us, T, msg_ptr)

#endif
