/* sf_rx_lcm.h — the raw sensor samples as LCM messages, both ways: sf_rx_event_t → IMU, MAG, BARO,
 * WIFI, GNSS, BLE, LANDMARK messages (what stridefixd logs for every input) and back (what a raw-sensor log replay
 * reads, sf_lcm_input.h).
 *
 * One row per SF_RX_KINDS entry (sf_rx_event.h) with its channel, decode and encode, generated from
 * that list: a kind without both functions does not compile, so the CAN path, the replay and the log
 * always carry the same kinds. Cost: one generated LCM encode or decode per call; the encode goes
 * straight into the log queue (sf_lcm_out_reserve; at most 4109 B: a full scan of SF_WIFI_MAX_AP
 * access points). */
#ifndef SF_RX_LCM_H
#define SF_RX_LCM_H

#include <stddef.h>
#include <stdint.h>

#include "sf_lcm_out.h"
#include "sf_rx_event.h"

/* The LCM channel of a kind ("IMU", ...); NULL for sf_rx_none or an unknown kind. */
const char *sf_rx_lcm_channel(sf_rx_kind_t kind);

/* Decodes one logged message. 1 *event filled, 0 the channel is not a sensor input (event untouched),
 * SF_ESYNTAX a sensor channel whose payload does not decode: every count is checked against the
 * payload before the generated decode runs (sf_lcm_walk.h), and trailing bytes are refused; err (if
 * err_size > 0) then holds "<name>: <what>", e.g. "payload: n_ap = 536870912 needs 8589934592 bytes
 * of arrays, 13 left" (name NULL: the channel). A scan longer than SF_WIFI_MAX_AP keeps its first
 * SF_WIFI_MAX_AP access points (the rest cannot be used anyway), a BLE scan longer than
 * SF_BLE_MAX_BEACONS its first SF_BLE_MAX_BEACONS beacons. */
int sf_rx_lcm_decode(const char *channel, const void *data, size_t size, sf_rx_event_t *event, const char *name,
                     char *err, size_t err_size);

/* Writes the event as its message on its channel with log timestamp ts_us; sf_rx_none writes nothing.
 * Drops are counted by sf_lcm_out. */
void sf_rx_lcm_write(sf_lcm_out_t *out, int64_t ts_us, const sf_rx_event_t *event);

#endif
