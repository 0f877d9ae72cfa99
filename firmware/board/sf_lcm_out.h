/* sf_lcm_out.h — everything stridefixd says goes through here: an LCM event log on disk and,
 * optionally, live LCM publishing (any URL liblcm accepts: udpm://, file://, memq://).
 *
 * The caller never waits on disk (lcm-logger's design): each message is copied flat into a bounded
 * queue and a writer thread appends it with lcm_eventlog_write_event(), flushing every second. When
 * the queue is full the message is dropped and counted — unless the log was opened with
 * `block_when_full` (replaying a file, where losing data for speed makes no sense), in which case
 * the caller waits for room. Event timestamps are the caller's (host receive time of the frame), so
 * replaying the same input gives the same log. */
#ifndef SF_LCM_OUT_H
#define SF_LCM_OUT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct sf_lcm_out sf_lcm_out_t;

typedef struct {
    uint64_t events;  /* written to the log */
    uint64_t bytes;   /* log bytes written (payload + channel + 28-byte event header) */
    uint64_t drops;   /* dropped: queue full, or a write failed */
    uint64_t publish_errors;
} sf_lcm_out_counters_t;

/* Opens the log (log_path may be NULL: no log) and the live LCM (lcm_url may be NULL: none).
 * queue_capacity is in messages. On failure returns SF_EIO / SF_EINVAL and writes a message. */
int sf_lcm_out_open(sf_lcm_out_t **out, const char *log_path, const char *lcm_url, size_t queue_capacity,
                    bool block_when_full, char *err_text, size_t err_size);

/* Queues one encoded message. SF_OK, SF_EFULL (dropped, counted) or SF_EINVAL. */
int sf_lcm_out_write(sf_lcm_out_t *out, const char *channel, int64_t timestamp_us, const void *data, size_t size);

/* A snapshot of the counters (thread-safe). */
void sf_lcm_out_counters(sf_lcm_out_t *out, sf_lcm_out_counters_t *counters);

/* Drains the queue, closes the log and the LCM, and gives the final counters (final may be NULL).
 * Returns SF_OK or SF_EIO if any write failed. */
int sf_lcm_out_close(sf_lcm_out_t *out, sf_lcm_out_counters_t *final);

/* Encodes an LCM message of generated type T into a stack buffer and writes it. */
#define SF_LCM_WRITE(out, channel, ts_us, T, msg_ptr)                                   \
    do {                                                                                \
        const int sf_size_ = T##_encoded_size(msg_ptr);                                 \
        unsigned char sf_buf_[sf_size_ > 0 ? sf_size_ : 1];                            \
        if (sf_size_ > 0 && T##_encode(sf_buf_, 0, sf_size_, (msg_ptr)) == sf_size_) { \
            (void)sf_lcm_out_write((out), (channel), (ts_us), sf_buf_, (size_t)sf_size_); \
        }                                                                               \
    } while (0)

#endif
