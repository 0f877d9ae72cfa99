/* sf_lcm_input.h — replay of a raw-sensor LCM log (IMU, MAG, BARO, WIFI, GNSS channels), the input
 * path for real data sets that the analyzer's importers convert (DESIGN.md data flow).
 *
 * Each event is decoded with the generated stridefix types into the same sf_rx_event_t that the CAN
 * path produces (through the kind table of sf_rx_lcm.h), so the estimator cannot tell the two apart. Other channels (TRUTH, POSE, ...) are
 * skipped and counted. The log may be hostile: it is read by the strict reader of sf_eventlog.h (an
 * event above SF_EVENTLOG_MAX_DATA_BYTES is skipped unread, a header that cannot be trusted refuses
 * the rest of the log, a truncated last event is reported and the events before it are used) and
 * every count in a payload is checked against the event's size before the generated decode runs
 * (sf_rx_lcm_decode). Each bad event has a message naming the log, the event number and offset and,
 * for a payload, the field (sf_lcm_input_error). */
#ifndef SF_LCM_INPUT_H
#define SF_LCM_INPUT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "sf_rx_event.h"

typedef struct sf_lcm_input sf_lcm_input_t;

typedef struct {
    uint64_t events;         /* events read (whole or not) */
    uint64_t used;           /* events turned into sf_rx_event_t */
    uint64_t other_channels; /* events of channels that are not sensor inputs */
    uint64_t decode_errors;  /* bad events, every kind below included */
    uint64_t oversized;      /* events above SF_EVENTLOG_MAX_DATA_BYTES, skipped */
    uint64_t truncated;      /* a last event cut short by the end of the log (0 or 1) */
    uint64_t refused;        /* a header that could not be trusted: the rest of the log refused (0 or 1) */
} sf_lcm_input_counters_t;

/* Opens a log. SF_OK, SF_ENOENT or SF_EIO with a message in err_text. */
int sf_lcm_input_open(sf_lcm_input_t **in, const char *path, char *err_text, size_t err_size);

/* The same on a stream already open (a memory stream in the fuzz harness); the input owns f and
 * closes it (also on failure). name is used in messages. */
int sf_lcm_input_open_stream(sf_lcm_input_t **in, FILE *f, const char *name, char *err_text, size_t err_size);

/* True when the log is read from a regular file (sf_file_is_regular). */
bool sf_lcm_input_is_regular(const sf_lcm_input_t *in);

/* Next sensor event: 1 filled (*log_t_us = the event's log timestamp); 0 end of log; SF_ESYNTAX an
 * event that failed to decode, was too large or was cut short by the end of the log (skipped,
 * counted; call again); SF_ECORRUPT the rest of the log refused (counted; later calls return 0);
 * SF_EIO a read failed (errno tells). */
int sf_lcm_input_next(sf_lcm_input_t *in, sf_rx_event_t *event, int64_t *log_t_us);

/* The message of the latest bad event, "<log>: event N at offset X[ (CHANNEL)]: <what>"; "" if none. */
const char *sf_lcm_input_error(const sf_lcm_input_t *in);

void sf_lcm_input_counters(const sf_lcm_input_t *in, sf_lcm_input_counters_t *counters);

void sf_lcm_input_close(sf_lcm_input_t *in);

#endif
