/* sf_lcm_out.h — everything stridefixd says goes through here: an LCM event log on disk and,
 * optionally, live LCM publishing (any URL liblcm accepts: udpm://, file://, memq://).
 *
 * The caller never waits on disk (lcm-logger's design): each message is copied flat into a bounded
 * queue and a writer thread appends it to the log file (sf_log_file.h: NAME.part, renamed to NAME
 * when closed). When the queue is full the message is dropped and counted — unless the log was
 * opened with `block_when_full` (replaying a file, where losing data for speed makes no sense), in
 * which case the caller waits for room. Event timestamps are the caller's (host receive time of the
 * frame), so replaying the same input gives the same log.
 *
 * Durability: every event is in the kernel as soon as the writer has it (no user-space buffer, so
 * SIGKILL loses only what is still queued, microseconds' worth); the writer fdatasyncs at least
 * every fsync_interval_ms (0: after every event), so power loss loses at most that much.
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
 * its reason on `report` (once, not per event), and so is the first success after it (logging
 * resumes by itself). Invariant: events queued = events - header_copies + drops. */
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
    uint64_t header_copies; /* header events repeated at the start of a rotated file */
    uint64_t files;         /* log files opened */
    uint64_t publish_errors;
} sf_lcm_out_counters_t;

typedef struct {
    const char *log_path;          /* NULL: no log */
    const char *lcm_url;           /* NULL: no live publishing */
    size_t queue_capacity;         /* messages, > 0 */
    bool block_when_full;          /* wait for room instead of dropping */
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

/* Queues one encoded message. SF_OK, SF_EFULL (dropped, counted) or SF_EINVAL. */
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

/* Encodes an LCM message of generated type T into a stack buffer and gives it to write_fn
 * (sf_lcm_out_write or sf_lcm_out_write_header). */
#define SF_LCM_WRITE_WITH(write_fn, out, channel, ts_us, T, msg_ptr)                     \
    do {                                                                                \
        const int sf_size_ = T##_encoded_size(msg_ptr);                                 \
        unsigned char sf_buf_[sf_size_ > 0 ? sf_size_ : 1];                            \
        if (sf_size_ > 0 && T##_encode(sf_buf_, 0, sf_size_, (msg_ptr)) == sf_size_) { \
            (void)write_fn((out), (channel), (ts_us), sf_buf_, (size_t)sf_size_);       \
        }                                                                               \
    } while (0)

#define SF_LCM_WRITE(out, channel, ts_us, T, msg_ptr) SF_LCM_WRITE_WITH(sf_lcm_out_write, out, channel, ts_us, T, msg_ptr)

#endif
