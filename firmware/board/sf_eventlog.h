/* sf_eventlog.h — a strict reader of the LCM event-log format, for logs that may be hostile.
 *
 * liblcm's lcm_eventlog_read_next_event (1.3) cannot be made safe: it allocates whatever data length
 * a header declares (an event claiming 1.9 GB maps 1.9 GB), asserts on a long channel, skips any
 * bytes until it finds a magic number, and reports a truncated event, a read error and the end of the
 * log alike as NULL. So the replay reads the format itself. Each event (integers big-endian):
 *
 *     offset  size  field
 *          0     4  magic            0xEDA1DA01
 *          4     8  event number     int64 (not checked: filtered logs skip numbers)
 *         12     8  timestamp        int64, µs
 *         20     4  channel length   int32, 1 … SF_EVENTLOG_MAX_CHANNEL
 *         24     4  data length      int32, ≥ 0
 *         28     c  channel          bytes, no NUL
 *       28+c     d  data
 *
 * What the reader does with a bad event (each with a message "<name>: event N at offset X: <what>"):
 *   - SF_ECORRUPT: the header cannot be trusted to find the next event (bad magic, channel length
 *     outside 1 … SF_EVENTLOG_MAX_CHANNEL, negative data length): the rest of the log is refused
 *     (every later call returns 0).
 *   - SF_ERANGE: data length above SF_EVENTLOG_MAX_DATA_BYTES: the event is skipped without being
 *     held in memory (read and discarded), the next header is checked as usual.
 *   - SF_ESYNTAX: the channel holds a NUL byte: the event is skipped.
 *   - SF_ELENGTH: the log ends inside an event (a truncated last event, as after a crash of the
 *     writer): reported once, then the end of the log.
 *   - SF_EIO: a read failed (errno tells); the end of the log.
 * Memory: one data buffer, grown to the largest event read (≤ SF_EVENTLOG_MAX_DATA_BYTES), freed by
 * sf_eventlog_close. Cost: one fread per field. */
#ifndef SF_EVENTLOG_H
#define SF_EVENTLOG_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#define SF_EVENTLOG_MAGIC 0xEDA1DA01u
#define SF_EVENTLOG_HEADER_SIZE 28
#define SF_EVENTLOG_MAX_CHANNEL 255              /* bytes; LCM itself allows 63 */
#define SF_EVENTLOG_MAX_DATA_BYTES (1u << 20)    /* bytes; the largest raw-sensor event is ~4.1 kB */

typedef struct {
    int64_t number;        /* event number from the header */
    int64_t timestamp_us;  /* log timestamp */
    uint64_t offset;       /* byte offset of the event's header in the log */
    const char *channel;   /* NUL-terminated, valid until the next call */
    const uint8_t *data;   /* data_size bytes, valid until the next call */
    size_t data_size;
} sf_eventlog_event_t;

typedef struct {
    FILE *f;
    const char *name;      /* for messages (not copied) */
    uint64_t offset;       /* bytes consumed */
    int done;              /* end reached, or the rest refused */
    char channel[SF_EVENTLOG_MAX_CHANNEL + 1];
    uint8_t *data;
    size_t data_cap;
} sf_eventlog_t;

/* Starts reading f (not closed by the reader) under name. Cannot fail. */
void sf_eventlog_init(sf_eventlog_t *log, FILE *f, const char *name);

/* Next event: 1 *event filled; 0 end of log; SF_ERANGE, SF_ESYNTAX (event skipped: call again),
 * SF_ELENGTH, SF_EIO (end of log) or SF_ECORRUPT (rest refused), each with a message in err. On a
 * negative code event->number and ->offset name the bad event (number INT64_MIN when the log ends
 * inside its header; the other fields are unset). */
int sf_eventlog_next(sf_eventlog_t *log, sf_eventlog_event_t *event, char *err, size_t err_size);

/* Frees the data buffer (not the FILE). */
void sf_eventlog_close(sf_eventlog_t *log);

#endif
