/* sf_lcm_input.h — replay of a raw-sensor LCM log (IMU, MAG, BARO, WIFI, GNSS channels), the input
 * path for real data sets that the analyzer's importers convert (DESIGN.md data flow).
 *
 * Each event is decoded with the generated stridefix types into the same sf_rx_event_t that the CAN
 * path produces (through the kind table of sf_rx_lcm.h), so the estimator cannot tell the two apart. Other channels (TRUTH, POSE, ...) are
 * skipped and counted. The reader stops at the end of the log, or at its last whole event if the
 * log is truncated. */
#ifndef SF_LCM_INPUT_H
#define SF_LCM_INPUT_H

#include <stddef.h>
#include <stdint.h>

#include "sf_rx_event.h"

typedef struct sf_lcm_input sf_lcm_input_t;

typedef struct {
    uint64_t events;         /* events read */
    uint64_t used;           /* events turned into sf_rx_event_t */
    uint64_t other_channels; /* events of channels that are not sensor inputs */
    uint64_t decode_errors;  /* sensor events whose payload did not decode */
} sf_lcm_input_counters_t;

/* Opens a log. SF_OK, SF_ENOENT or SF_EIO with a message in err_text. */
int sf_lcm_input_open(sf_lcm_input_t **in, const char *path, char *err_text, size_t err_size);

/* Next sensor event: 1 filled (*log_t_us = the event's log timestamp), 0 end of log, SF_ESYNTAX
 * an event that failed to decode (skipped, counted; call again). */
int sf_lcm_input_next(sf_lcm_input_t *in, sf_rx_event_t *event, int64_t *log_t_us);

void sf_lcm_input_counters(const sf_lcm_input_t *in, sf_lcm_input_counters_t *counters);

void sf_lcm_input_close(sf_lcm_input_t *in);

#endif
